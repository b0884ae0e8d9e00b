"""A crane described boom by boom ([[boom]], [[overlap]], [luffing]): the statics against hand
calculations, the shorthand's equivalence, the sliders on any section, the shipped
``crane_hexagonal_4`` and the validation errors a user meets."""

from __future__ import annotations

import copy
import json
import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import quad

from sim_core import SceneError, load_scene, simulate
from sim_core.physics.contact import SpringLaw, solve_micro_motion
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.luffing import luffing_geometry
from sim_core.systems.telescopic.params import TABLE2, Z_C_TABLE2, boom_section
from sim_core.systems.telescopic.schema import params_from_scene, validate_telescopic
from sim_core.validation.closed_form import rigid_luffing_force
from sim_core.systems.telescopic.sliders import slider_geometries


def _scene(raw: dict) -> dict:
    return validate_telescopic(raw, "<test>")


def _properties(A, I, J, m):
    return {"shape": "properties", "A": A, "I_t": I, "I_b": I, "J": J, "mass_per_length": m}


# -- statics against hand calculations ------------------------------------------------------

def test_two_section_tip_deflection_matches_stepped_beam():
    """Static tip deflection of a two-section crane with stiff sliders (rigid contact sections)
    under a tip load P, against the stepped-beam hand calculation.

    Set-up (luffing angle 0, x along the boom): boom 1 of length L1 pinned at x = 0 (the pivot
    D1 on the reference line) and held at x = L_h by a vertical cylinder D2-D3 (a roller: it
    carries no axial force); boom 2 of length L2 with its left end at x = a = L_s > L_h.  Each
    overlap end ties the two sections in position and rotation (Section 6, rigid model), and
    no load acts between them (the cylinder sits before the overlap), so both booms take the
    same cubic deflection there: the overlap [a, L1] bends as one beam of stiffness EI1 + EI2.
    The structure is statically determinate; the unit-load moment is m(x) = (x_tip - L_h) x /
    L_h on [0, L_h] and x_tip - x beyond, and virtual work gives
        delta = P int_0^x_tip m(x)^2 / EI(x) dx,   EI = EI1 on [0, a), EI1 + EI2 on [a, L1],
                                                   EI2 on (L1, x_tip].
    The booms are nearly massless (1e-3 kg/m), so the payload is the only load; the tip
    deflection (4 mm for P = 9.81 kN over 13 m) keeps the geometrically exact model's
    nonlinearity at (delta/L)^2 ~ 1e-7.  The splines converge to the hand value from below
    (0.52 % with 4, 0.34 % with 8 sub-elements per element: boom 2's left end loads boom 1
    inside an element).  Tolerance 1 % (the acceptance tolerance of the own-crane validation)."""
    E, G = 2.1e11, 8.1e10
    L1, L2, a, L_h = 10.0, 9.0, 4.0, 3.0
    I1, I2 = 4.0e-3, 2.5e-3
    raw = {"kind": "telescopic",
           "solver": {"t_end": 1.0},
           "booms": {"luffing_angle_deg": 0.0, "stroke0": a, "n_nodes": 9},
           "boom": [{"length": L1, "E": E, "G": G,
                     "section": _properties(0.03, I1, 2 * I1, 1e-3)},
                    {"length": L2, "E": E, "G": G,
                     "section": _properties(0.02, I2, 2 * I2, 1e-3)}],
           "luffing": {"pivot": [0.0, 0.0], "pivot_on_boom": [0.0, 0.0],
                       "base": [L_h, -2.0], "head_on_boom": [L_h, 0.0]},
           "drive": {"v_max": 0.1, "t_ramp": 1.0, "t_hold_end": 2.0},
           "effects": {"friction": False, "contact_distribution": False, "filtering": False},
           "contact": {"moment_model": "rigid"},     # the rigid contact sections of Section 6
           "payload": {"mass": 0.0}}
    tips = {}
    for m_p in (0.0, 1000.0):
        sc = copy.deepcopy(raw)
        sc["payload"]["mass"] = m_p
        ts = build_telescopic(params_from_scene(_scene(sc)))
        z, _ = initial_equilibrium(ts)
        Q, _ = ts.model.full_state(0.0, z, np.zeros_like(z))
        tips[m_p] = ts.tip(Q)[0]
    delta_model = tips[0.0][2] - tips[1000.0][2]
    P, x_tip = 1000.0 * 9.81, a + L2

    def unit_moment(x):
        return (x_tip - L_h) * x / L_h if x <= L_h else x_tip - x

    def EI(x):
        return E * ((I1 if x <= L1 else 0.0) + (I2 if x >= a else 0.0))

    breaks = sorted({a, L_h, L1})
    delta_hand = P * quad(lambda x: unit_moment(x) ** 2 / EI(x), 0.0, x_tip, points=breaks,
                          epsabs=0.0, epsrel=1e-12, limit=200)[0]
    assert tips[0.0][0] == pytest.approx(x_tip, abs=1e-6)
    assert delta_model == pytest.approx(delta_hand, rel=1e-2)


GEOMETRIES = {
    "low pivot, long lever": {"pivot": [-1.0, 2.6], "pivot_on_boom": [0.0, -0.4],
                              "base": [0.9, 0.3], "head_on_boom": [4.5, -0.45]},
    "pivot on the axis": {"pivot": [0.0, 1.5], "pivot_on_boom": [0.0, 0.0],
                          "base": [1.5, -0.5], "head_on_boom": [3.0, -0.3]},
    "cylinder behind the pivot": {"pivot": [0.5, 2.0], "pivot_on_boom": [-0.5, -0.3],
                                  "base": [-0.8, 0.0], "head_on_boom": [2.5, -0.5]},
}


@pytest.mark.parametrize("geometry", list(GEOMETRIES))
@pytest.mark.parametrize("angle", [20.0, 45.0, 75.0])
def test_luffing_cylinder_force_matches_virtual_work(geometry, angle):
    """Luffing-cylinder force at t = 0 for user mounting points at 20, 45 and 75 deg against the
    virtual-work statics of the rigid crane (closed_form.rigid_luffing_force).  The booms are
    stiff (E = 2.1e14 Pa, 1000 x steel), so the deflection moves the weights' arms by
    ~1e-5 of the reach; ropes and the telescopic cylinder are internal forces and drop out.
    Tolerance 0.5 % (the acceptance tolerance of the own-crane validation)."""
    raw = {"kind": "telescopic", "solver": {"t_end": 1.0},
           "booms": {"luffing_angle_deg": angle, "E": 2.1e14, "n_nodes": 3, "count": 3},
           "luffing": GEOMETRIES[geometry],
           "effects": {"friction": False, "contact_distribution": False},
           "payload": {"mass": 5000.0}}
    p = params_from_scene(_scene(raw))
    ts = build_telescopic(p)
    _, lam = initial_equilibrium(ts)
    force = lam[ts.rows["luffing_cylinder"]][0]
    ref = rigid_luffing_force(p, math.radians(angle), 9.81)
    assert force == pytest.approx(ref, rel=5e-3)       # > 0: the cylinder pushes


# -- the shorthand and the boom-by-boom description -----------------------------------------

def _paper_boom_by_boom() -> dict:
    """The paper's extraction scene written boom by boom: the U sections of Table 1 (outer
    radii; sliders on P1-P3) carrying Table 2's constants (A = m'/rho, I = EI/E, J = GJ/G with
    G = E/2.6: the shorthand's convention) and Table 2's mass centres."""
    raw = load_scene("telescopic_extraction")
    E, rho = raw["booms"]["E"], raw["booms"]["rho"]
    booms = []
    for k, ((EI, GJ, m), z_c) in enumerate(zip(TABLE2, Z_C_TABLE2)):
        booms.append({"length": 10.0, "E": E, "nu": 0.3, "rho": rho,
                      "section": {"shape": "u", "top_arc_centre_y": 0.3,
                                  "top_arc_centre_z": 0.3, "top_arc_radius": 0.09 - 0.02 * k,
                                  "wall": 0.015, "A": m / rho, "I_t": EI / 2.1e11,
                                  "I_b": EI / 2.1e11, "J": GJ / (2.1e11 / 2.6),
                                  "mass_per_length": m, "z_c": z_c}})
    out = {k: v for k, v in raw.items() if k not in ("source",)}
    out["booms"] = {k: v for k, v in raw["booms"].items() if k not in ("length", "count")}
    out["boom"] = booms
    return out


def test_u_crane_boom_by_boom_equals_the_shorthand():
    """The paper's crane described boom by boom builds the shorthand's crane: the beam
    constants, lengths, slider springs and luffing geometry agree to round-off (1e-14), and a
    0.3 s run of the extraction (friction and slider springs on) gives the same outputs to
    1e-9 relative (round-off amplified by the error-controlled steps)."""
    short = load_scene("telescopic_extraction", overrides={"solver.t_end": 0.3,
                                                           "solver.n_output": 4})
    raw = _paper_boom_by_boom()
    raw["solver"] = dict(short["solver"])
    full = _scene(raw)
    ps, pf = params_from_scene(short), params_from_scene(full)
    assert ps.lengths == pf.lengths and ps.luffing == pf.luffing
    for k in range(3):
        a, b = boom_section(k, ps), boom_section(k, pf)
        np.testing.assert_allclose([a.EA, a.GJ, a.EI_t, a.EI_b, a.rhoA, a.J_s, a.J_t, a.J_b],
                                   [b.EA, b.GJ, b.EI_t, b.EI_b, b.rhoA, b.J_s, b.J_t, b.J_b],
                                   rtol=1e-14)
    for gs, gf in zip(slider_geometries(ps), slider_geometries(pf)):
        for a, b in zip(gs, gf):
            np.testing.assert_allclose(a.positions, b.positions, rtol=0, atol=1e-15)
            np.testing.assert_allclose(a.A, b.A, rtol=0, atol=1e-15)
    rs, rf = simulate(short), simulate(full)
    for key in ("tip_position", "telescopic_cylinder_force", "luffing_cylinder_force",
                "slider_contact_forces"):
        scale = np.max(np.abs(rs[key]))
        np.testing.assert_allclose(rf[key], rs[key], rtol=0, atol=1e-9 * scale, err_msg=key)


def test_shorthand_of_five_sections_gets_slider_springs():
    """The shorthand crane of five sections takes contact_distribution: its sliders bear on the
    U family's arcs, the contact circle half the gap inside each outer boom's inner face."""
    sc = load_scene("telescopic_extraction_5", overrides={"effects.contact_distribution": True})
    p = params_from_scene(sc)
    geoms = slider_geometries(p)
    assert len(geoms) == 4
    for k, (inner, outer) in enumerate(geoms):
        from sim_core.systems.telescopic.params import family_radius
        r_o = family_radius(k, 5)
        assert inner.arcs[0, 2] == pytest.approx(r_o - 0.015 - 0.0025, abs=1e-15)
        assert inner.k_t == -1 and outer.k_t == 1


# -- sliders on faces ------------------------------------------------------------------------

@pytest.mark.parametrize("direction_deg", [-90.0, 0.0, 30.0, 90.0, 150.0])
def test_hexagon_sliders_carry_any_transverse_load(direction_deg):
    """The springs on a hexagon's six faces carry a transverse contact force in any direction:
    the micro-motion solve (Eqs. 59-71) returns springs whose forces balance the load (Eqs.
    67-68: the springs' resultant on the section equals the constraint reaction f_c they
    replace) to 1e-6 of the load, and only springs on faces towards the load are compressed."""
    sc = load_scene("crane_hexagonal_4")
    inner, _ = slider_geometries(params_from_scene(sc))[0]
    spring = SpringLaw(1e9, 1e-6)
    th = math.radians(direction_deg)
    f_c = 5e4 * np.array([0.0, math.cos(th), math.sin(th)])
    sol = solve_micro_motion(inner, spring, f_c, np.zeros(3))
    np.testing.assert_allclose(sol.force_on_section, f_c, rtol=0, atol=1e-6 * 5e4)
    loaded = sol.normal_force > 1e-3 * np.max(sol.normal_force)
    # inner region (k_t = -1): a compressed spring pushes the section along its normal n, so
    # the loaded springs' normals point along the force on the section
    n = inner.normals[loaded][:, 1:]
    assert np.all(n @ f_c[1:] > 0)


# -- the shipped scene -----------------------------------------------------------------------

def test_crane_hexagonal_4_describe_json():
    """`boom-sim describe crane_hexagonal_4 --json`: every boom's length and section constants
    in SI units and the luffing lever.  The hexagon's area is exact (6 t (W - t) tan 30 deg
    ... for a regular hexagon of width across flats W: A = 2 sqrt(3) (W^2 - (W - 2t)^2) / 4
    ... ) within the mesh's 1e-6; its J is the St. Venant constant, below the polar moment."""
    out = subprocess.run([sys.executable, "-m", "sim_core.cli", "describe", "crane_hexagonal_4",
                          "--json"], capture_output=True, text=True, check=True)
    d = json.loads(out.stdout)
    assert [b["length"] for b in d["booms"]] == [12.0, 11.5, 11.0, 10.5]
    for b, (W, t) in zip(d["booms"], [(0.8, 0.008), (0.744, 0.007), (0.69, 0.006),
                                      (0.638, 0.006)]):
        A = math.sqrt(3) / 2 * (W ** 2 - (W - 2 * t) ** 2)     # hexagon area sqrt(3)/2 W^2
        assert b["A"] == pytest.approx(A, rel=1e-6)
        assert b["mass_per_length"] == pytest.approx(7850.0 * A, rel=1e-6)
        assert b["I_t"] == pytest.approx(b["I_b"], rel=1e-6)     # regular hexagon: isotropic
        assert 0.8 < b["J"] / (b["I_t"] + b["I_b"]) < 1.0
        assert b["y_c"] == 0.0 and b["z_c"] == 0.0
        for key in ("A", "I_t", "I_b", "J", "mass_per_length", "y_c", "z_c"):
            assert key in b
    assert d["luffing_lever"] == pytest.approx(2.278, abs=1e-3)
    assert len(d["overlaps"]) == 3


def test_paper_scene_describe_json_gives_the_paper_lever():
    """The paper's luffing geometry: lever 0.714 m about D1 at 60 deg (docs/model.md#input-
    luffing), and the shorthand's Table 2 constants."""
    out = subprocess.run([sys.executable, "-m", "sim_core.cli", "describe",
                          "telescopic_extraction", "--json"], capture_output=True, text=True,
                         check=True)
    d = json.loads(out.stdout)
    assert d["luffing_lever"] == pytest.approx(0.714, abs=5e-4)
    assert d["booms"][0]["mass_per_length"] == 318.86
    assert d["booms"][0]["I_t"] * 2.1e11 == pytest.approx(7.22e8, rel=1e-12)


# -- validation errors -----------------------------------------------------------------------

def _hex_raw() -> dict:
    sc = load_scene("crane_hexagonal_4")
    raw = {k: v for k, v in sc.items() if k != "source"}
    raw["boom"] = [{"length": b["length"], "E": b["E"], "G": b["G"], "rho": b["rho"],
                    "section": {k: v for k, v in b["section"].items()
                                if k not in ("constants", "method")}} for b in sc["boom"]]
    raw["overlap"] = [{"slider_width": o["slider_width"],
                       "inner_slider_distance": o["inner_slider_distance"],
                       "outer_slider_distance": o["outer_slider_distance"],
                       "radial_gap": o["radial_gap"]} for o in sc["overlap"]]
    raw["solver"] = {k: v for k, v in sc["solver"].items() if k != "jacobian"}
    raw["booms"] = {k: v for k, v in sc["booms"].items() if k != "L_h"}
    return raw


@pytest.mark.parametrize("edit, words", [
    (lambda r: r["overlap"][2].update(slider_width=4.0),
     ["overlap[2].slider_width = 4", "shortest overlap", "allowed"]),
    (lambda r: r["boom"][1]["section"].update(width_across_flats=0.79),
     ["boom[1].section does not fit inside boom[0].section", "radial_gap", "allowed"]),
    (lambda r: r["overlap"][0].update(bears_on=["face_9"]),
     ["overlap[0].bears_on", "'face_9'", "face_1"]),
    (lambda r: r["overlap"][0].update(bears_on=["face_1", "face_2"]),
     ["overlap[0].bears_on", "unsupported"]),
    (lambda r: r["boom"][3].update(length=9.0),
     ["boom[3].length = 9", "allowed"]),
    (lambda r: r["boom"][0]["section"].update(wall=-0.01), ["boom[0].section.wall"]),
    (lambda r: r["luffing"].update(head_on_boom=[13.0, -0.45]),
     ["luffing.head_on_boom[0] = 13", "(0, 12)"]),
    (lambda r: r["booms"].update(length=10.0), ["booms.length", "[[boom]]"]),
    (lambda r: r["boom"][2]["section"].update(shape="properties"),
     ["boom[2].section"]),
])
def test_user_crane_errors_name_the_field_and_range(edit, words):
    raw = _hex_raw()
    edit(raw)
    with pytest.raises(SceneError) as info:
        _scene(raw)
    msg = str(info.value)
    assert all(w in msg for w in words), msg


def test_properties_section_refuses_slider_springs():
    """A boom given by its constants alone has no contour for the slider springs."""
    raw = _hex_raw()
    raw["boom"][2]["section"] = _properties(0.014, 9e-4, 1.6e-3, 111.6)
    with pytest.raises(SceneError, match="contact_distribution"):
        _scene(raw)
    raw["effects"]["contact_distribution"] = False
    sc = _scene(raw)
    assert sc["boom"][2]["section"]["constants"]["J"] == 1.6e-3


@pytest.mark.slow
def test_crane_hexagonal_4_full_extraction():
    """The shipped user crane through its whole 20 s extraction: every stage reaches its
    6 m stroke (the cubic schedule's travel v_max t_hold_end, 1 -> 7 m), the
    run passes its own checks (constraint violation and energy balance, Result.suspect), and
    the slider springs of every region carry load at the end (the sections rest on their
    sliders: a compressed spring in every region)."""
    res = simulate(load_scene("crane_hexagonal_4"))
    assert not res.suspect, res.failed_checks
    assert res.t[-1] == pytest.approx(20.0)
    # the cylinders' stages (1-2 and 3-4) to the constraint's drift; the rope unit's stage
    # (2-3) to the change of the ropes' stretch, below their static stretch T L / EA
    # ~ 80 kN x 20 m / 1e8 N = 16 mm
    stroke = res["stage_stroke"][-1]
    np.testing.assert_allclose(stroke[[0, 2]], 6.0, atol=1e-6)
    assert stroke[1] == pytest.approx(6.0, abs=0.02)
    sf = res["slider_contact_forces"][-1]                 # (regions, springs), N
    assert sf.shape[0] == 6
    assert np.all(np.nanmax(sf, axis=1) > 0.0)
