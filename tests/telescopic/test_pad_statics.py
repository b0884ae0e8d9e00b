"""Pad reactions, root bending moment and tip deflection of a crane described boom by boom
([[boom]], [[overlap]]) with the default slider-moment model, against two-pad statics.

Two-pad statics (the design calculation of a telescopic boom):

* each overlap of booms k and k+1 is a two-pad support of boom k+1: the outer boom's pad A at
  x_A = x_k + L_k - d_out (``outer_slider_distance`` inside boom k's right end) and the inner
  boom's pad B at x_B = x_{k+1} + d_in (``inner_slider_distance`` from boom k+1's left end);
  a pad carries a force normal to the boom and no moment (a pin);
* x along the undeformed boom axis from boom 1's left end, x_k = (k - 1) L_s: every stage of
  the synchronized drive at the stroke L_s = ``booms.stroke0``;
* the loads normal to the boom: the weight per length m'_k g cos(theta) of every boom, the
  payload m_p g cos(theta) at the tip (on the reference line, like every axial force, so the
  axial components bend nothing at first order);
* the stack is statically determinate from the tip down: boom N's loads give its two pad
  forces (moment about B, then the force sum), boom N-1 takes them reversed with its own
  weight, and so on to boom 1;
* root bending moment: boom 1's bending moment at the luffing cylinder's head (x = L_h), from
  everything outboard of it;
* tip deflection: relative to boom 1's section at the cylinder head (boom 1 clamped there: the
  pivot and cylinder compliance of the mounting left out), by the unit-load method,
  delta = sum_k int M_k m_k / (E I_k) dx over each boom's extent beyond x = L_h, M_k and m_k the
  bending moments of boom k under the loads and under a unit tip load, both from the same
  two-pad statics (Euler-Bernoulli: the spline element has no shear strain, its constitutive
  diagonal is diag(EA, GJ, EI_t, EI_b), Eq. 36, sim_core.physics.beam.moving_node_beam; the
  pads are rigid in the model's kinematics, the slider springs distribute the reactions
  without moving the booms, so there is no pad compliance to add).

What the statics leave out bounds the tolerance.  The model is geometrically exact: the axial
loads (m g sin(theta) of every boom and the payload, carried by the ropes and the cylinder)
act on the deflected booms, which adds a second-order moment of relative size about
2 tan(theta) delta / L (delta the tip deflection, L the length beyond the cylinder head): at
most 2.2 % at the test's configurations (60 deg, 5 m: delta = 0.136 m over 21.3 m), and the
model's pads exceed the statics by 0.3-2.2 % in step with it.  With the booms 100 times
stiffer the term vanishes and the pads and the root moment agree to 0.1 %
(test_the_statics_are_exact_in_the_stiff_limit), so the statics themselves are exact.  The
splines of n_nodes = 3 give the tip deflection 0.3 % low there (every inner pad outboard of
the cylinder head, where the clamped-head reference holds).  3 % covers the second-order term
with the mesh error; a more slender crane, or a steeper boom, needs second-order statics.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest


def _moment(x, loads, dist) -> np.ndarray:
    """Bending moment about e_t (N m) at positions x of a boom from the loads outboard of x:
    point loads (x_i, F_i) and distributed loads (a, b, q), F and q normal to the boom, N and
    N/m, positive along e_b.  A force F at x_i > x turns the section at x by -(x_i - x) F
    about e_t (e_s x e_b = -e_t)."""
    x = np.asarray(x, dtype=float)
    M = np.zeros_like(x)
    for xi, F in loads:
        M -= np.where(xi > x, (xi - x) * F, 0.0)
    for a, b, q in dist:
        lo = np.clip(x, a, b)
        M -= q * (b - lo) * (0.5 * (b + lo) - x)
    return M


def two_pad_statics(lengths, mass_per_length, EI, d_in, d_out, L_s, L_h, theta, payload,
                    g=9.81, n_grid=4001) -> dict:
    """Two-pad statics of a telescopic boom (module docstring), SI units, theta in rad.

    Returns ``pads`` (N-1, 2): the force normal to the boom (N, along e_b) that the outer pad
    (on boom k, at its right end) and the inner pad (on boom k+1, at its left end) of overlap k
    put on the inner boom; ``root_moment``: boom 1's bending moment about e_t at x = L_h (N m);
    ``tip_deflection``: the tip's displacement against e_b relative to boom 1's section at
    x = L_h (m, downward positive)."""
    N = len(lengths)
    x0 = [k * L_s for k in range(N)]

    def solve(weight: bool, tip_load: float):
        loads = [[] for _ in range(N)]
        dist = [[(x0[k], x0[k] + lengths[k], -mass_per_length[k] * g * math.cos(theta))]
                if weight else [] for k in range(N)]
        loads[-1].append((x0[-1] + lengths[-1], -tip_load))
        pads = np.zeros((N - 1, 2))
        for k in range(N - 1, 0, -1):            # boom k (0-based) on the pads of overlap k-1
            xA, xB = x0[k - 1] + lengths[k - 1] - d_out[k - 1], x0[k] + d_in[k - 1]
            V = sum(F for _, F in loads[k]) + sum(q * (b - a) for a, b, q in dist[k])
            M_B = sum(F * (xi - xB) for xi, F in loads[k]) + sum(
                q * (b - a) * (0.5 * (a + b) - xB) for a, b, q in dist[k])
            RA = -M_B / (xA - xB)
            RB = -V - RA
            pads[k - 1] = RA, RB
            loads[k] += [(xA, RA), (xB, RB)]
            loads[k - 1] += [(xA, -RA), (xB, -RB)]
        return pads, loads, dist

    pads, loads, dist = solve(True, payload * g * math.cos(theta))
    _, unit, _ = solve(False, 1.0)
    delta = 0.0
    for k in range(N):
        a = L_h if k == 0 else x0[k]
        x = np.linspace(a, x0[k] + lengths[k], n_grid)
        M = _moment(x, loads[k], dist[k])
        m = _moment(x, unit[k], [])
        delta += np.trapezoid(M * m, x) / EI[k]
    root = float(_moment(np.array([L_h]), loads[0], [(L_h, b, q) for a, b, q in dist[0]])[0])
    return {"pads": pads, "root_moment": root, "tip_deflection": delta}


# -- the model at its static equilibrium ----------------------------------------------------

def _box(width, height, wall):
    return {"shape": "box", "width": width, "height": height, "wall": wall,
            "corner_radius": 0.04}


#: A four-section box crane described boom by boom (not a shipped scene): each inner section
#: is its outer boom's inside less a 20 mm pad on every side; the luffing cylinder's head
#: 2.5 m along boom 1, inboard of every inner pad at the test's extensions.
CRANE = {
    "kind": "telescopic", "name": "pad_statics_box_4",
    "solver": {"t_end": 0.02, "n_output": 2},
    "booms": {"luffing_angle_deg": 60.0, "stroke0": 3.0, "n_nodes": 3, "E": 2.1e11,
              "rho": 7850.0},
    "boom": [{"length": 10.0, "nu": 0.3, "section": _box(0.700, 0.900, 0.010)},
             {"length": 9.6, "nu": 0.3, "section": _box(0.640, 0.840, 0.009)},
             {"length": 9.2, "nu": 0.3, "section": _box(0.582, 0.782, 0.008)},
             {"length": 8.8, "nu": 0.3, "section": _box(0.526, 0.726, 0.008)}],
    "overlap": [{"slider_width": 0.25, "inner_slider_distance": 0.15,
                 "outer_slider_distance": 0.20, "radial_gap": 0.020}] * 3,
    "luffing": {"pivot": [-1.0, 2.6], "pivot_on_boom": [0.0, -0.4], "base": [0.9, 0.3],
                "head_on_boom": [2.5, -0.45]},
    "drive": {"v_max": 0.01, "t_ramp": 0.5, "t_hold_end": 1.0},
    "payload": {"mass": 5000.0},
}


def five_section_crane() -> dict:
    """A five-section box crane described boom by boom: booms 11.0 to 9.4 m, the base section
    0.76 x 1.0 m with 10 mm walls, each inner section its outer boom's inside less a 20 mm pad
    on every side (walls 9, 8, 7, 7 mm), a 6 t payload; otherwise the four-section CRANE."""
    raw = copy.deepcopy(CRANE)
    raw["name"] = "pad_statics_box_5"
    w, h, booms = 0.76, 1.0, []
    for k, t in enumerate((0.010, 0.009, 0.008, 0.007, 0.007)):
        booms.append({"length": 11.0 - 0.4 * k, "nu": 0.3, "section": _box(w, h, t)})
        w, h = w - 2 * (t + 0.020), h - 2 * (t + 0.020)
    raw["boom"] = booms
    raw["overlap"] = [dict(CRANE["overlap"][0]) for _ in range(4)]
    raw["payload"] = {"mass": 6000.0}
    return raw


def model_statics(sc: dict) -> dict:
    """The static equilibrium of a validated scene (build_telescopic, initial_equilibrium) read
    as the
    statics above: the pads' forces on the inner booms (sliders.overlap_pads, along e_b),
    boom 1's bending moment about e_t at the cylinder head from the loads outboard of it (its
    weight and the reversed pad forces and couples, at the contact points' material
    coordinates), and the tip's displacement against e_b in the frame of boom 1's section at
    the head.  Returns the statics' inputs as well (``inputs``)."""
    from sim_core.physics.beam.cardan import cardan_frame
    from sim_core.physics.constraints import material_point
    from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
    from sim_core.systems.telescopic.schema import params_from_scene
    from sim_core.systems.telescopic.sliders import overlap_pads

    p = params_from_scene(sc)
    ts = build_telescopic(p)
    m = ts.model
    z, lam = initial_equilibrium(ts)
    Q, Qd = m.full_state(0.0, z, np.zeros_like(z))
    F, C, faces = overlap_pads(ts.contact, ts.contact.solve_regions(Q, Qd, lam))
    b1, ov1, L_h = p.booms[0], p.overlaps[0], p.L_h
    q1 = -b1.mass_per_length * p.gravity * math.cos(math.radians(p.luffing_angle_deg))
    root = -0.5 * q1 * (b1.length - L_h) ** 2
    # overlap 1's pads on boom 1: the outer pad at L_1 - d_out, the inner pad at s_2,1
    for j, s in enumerate((b1.length - ov1.outer_distance, float(np.real(Q[ts.s2_index[0]])))):
        if s > L_h:
            root += (s - L_h) * F[0, j, 1] - C[0, j, 0]
    head = material_point(m, 0, s_fixed=L_h)(Q)
    frame = np.real(cardan_frame(*head[2]) @ m.beams[0].reference_basis.T)   # e_t, e_b, e_s
    rel = frame @ (np.real(ts.tip(Q)[0]) - np.real(head[0]))
    inputs = dict(lengths=[b.length for b in p.booms],
                  mass_per_length=[b.mass_per_length for b in p.booms],
                  EI=[b.E * b.I_t for b in p.booms],
                  d_in=[o.inner_distance for o in p.overlaps],
                  d_out=[o.outer_distance for o in p.overlaps], L_s=p.stroke0, L_h=L_h,
                  theta=math.radians(p.luffing_angle_deg), payload=p.payload, g=p.gravity)
    return {"pads": F[:, :, 1], "couples": C[:, :, 0], "spring_sum": float(np.nansum(faces)),
            "root_moment": root,
            "tip_deflection": -rel[1], "moment_model": p.moment_model, "inputs": inputs}


def _crane(angle_deg: float, stroke: float, contact=None, **booms) -> dict:
    """The test crane, validated, at a luffing angle and stroke (and other [booms] keys)."""
    from sim_core.systems.telescopic.schema import validate_telescopic
    raw = copy.deepcopy(CRANE)
    raw["booms"].update(luffing_angle_deg=angle_deg, stroke0=stroke, **booms)
    if contact:
        raw["contact"] = contact
    return validate_telescopic(raw, "<test>")


def _rel(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) / np.asarray(b) - 1.0)))


# -- the default moment model ---------------------------------------------------------------

def test_the_default_moment_model_is_couple_boom_by_boom_and_rigid_for_the_shorthand():
    from sim_core import load_scene
    from sim_core.systems.telescopic.schema import CONTACT, validate_telescopic
    assert validate_telescopic(copy.deepcopy(CRANE), "<test>")["contact"]["moment_model"] \
        == "couple"
    assert load_scene("telescopic_extraction_5")["contact"]["moment_model"] == "rigid"
    raw = copy.deepcopy(CRANE)
    raw["contact"] = {"moment_model": "rigid"}          # a stated model wins
    assert validate_telescopic(raw, "<test>")["contact"]["moment_model"] == "rigid"
    field = next(f for f in CONTACT.fields if f.key == "moment_model")
    assert "couple" in field.default_shown() and "[[boom]]" in field.default_shown()


# -- pads, root moment and tip deflection against the statics -------------------------------

@pytest.mark.parametrize("angle_deg", [30.0, 60.0])
@pytest.mark.parametrize("stroke", [3.0, 5.0])
def test_default_crane_matches_two_pad_statics(angle_deg, stroke):
    """Pad reactions, root bending moment and tip deflection of the four-section box crane
    with default settings within 3 % of two-pad statics (module docstring), at 30 and 60 deg
    and every stage out 3 and 5 m; the pads carry no couple (a pin each)."""
    mo = model_statics(_crane(angle_deg, stroke))
    st = two_pad_statics(**mo["inputs"])
    assert mo["moment_model"] == "couple"
    assert _rel(mo["pads"], st["pads"]) < 0.03, (mo["pads"], st["pads"])
    assert _rel(mo["root_moment"], st["root_moment"]) < 0.03
    assert _rel(mo["tip_deflection"], st["tip_deflection"]) < 0.03
    # the couples across the pads: the micro-motion solve's residual, not a load path
    assert np.max(np.abs(mo["couples"])) < 1e-6 * np.max(np.abs(st["pads"]))


def test_five_section_crane_matches_two_pad_statics():
    """The five-section box crane with default settings at 45 deg, every stage 4 m out: pads,
    root moment and tip deflection within 3 % of two-pad statics (second-order term
    2 tan(theta) delta / L = 2 x 0.19 m / 22.9 m = 1.7 %, measured 2.0 % on the pads)."""
    from sim_core.systems.telescopic.schema import validate_telescopic
    raw = five_section_crane()
    raw["booms"].update(luffing_angle_deg=45.0, stroke0=4.0)
    mo = model_statics(validate_telescopic(raw, "<test>"))
    st = two_pad_statics(**mo["inputs"])
    assert mo["moment_model"] == "couple"
    assert _rel(mo["pads"], st["pads"]) < 0.03, (mo["pads"], st["pads"])
    assert _rel(mo["root_moment"], st["root_moment"]) < 0.03
    assert _rel(mo["tip_deflection"], st["tip_deflection"]) < 0.03


def test_the_statics_are_exact_in_the_stiff_limit():
    """With booms 100 times stiffer (booms.E) the second-order term drops to ~0.02 %: the
    pads and the root moment agree with the statics to 0.1 %, at the test's worst case."""
    mo = model_statics(_crane(60.0, 5.0, E=2.1e13))
    st = two_pad_statics(**mo["inputs"])
    assert _rel(mo["pads"], st["pads"]) < 1e-3, (mo["pads"], st["pads"])
    assert _rel(mo["root_moment"], st["root_moment"]) < 1e-3


def test_the_rigid_model_misses_the_pad_reactions():
    """The rigid moment model (Section 6 as printed) ties the bending angles of an overlap's
    two contact sections: the overlap's moment goes partly into couples across the pads, and
    the pad forces fall far below the statics (by 30 % or more on this crane)."""
    mo = model_statics(_crane(60.0, 5.0, contact={"moment_model": "rigid"}))
    st = two_pad_statics(**mo["inputs"])
    assert np.max(np.abs(mo["couples"])) > 1e4                  # N m
    assert _rel(mo["pads"], st["pads"]) > 0.3


# -- the outputs and the figure -------------------------------------------------------------

def test_pad_outputs_of_a_run():
    """pad_forces (n, overlaps, 2, 2), pad_couples and pad_face_forces (n, overlaps, 2, 8: the
    box's four faces and four corners) in the whole-run result; at t = 0 the pads of the
    statics, and at every output the contact regions' reactions; the patch sums are
    compressive and add up to at least the force they make (equal where every loaded spring
    pushes along the force: the corners' springs are inclined to it)."""
    from sim_core import simulate
    sc = _crane(60.0, 3.0)
    res = simulate(sc)
    n = len(res.t)
    assert res["pad_forces"].shape == (n, 3, 2, 2)
    assert res["pad_couples"].shape == (n, 3, 2, 2)
    assert res["pad_face_forces"].shape == (n, 3, 2, 8)
    mo = model_statics(sc)
    np.testing.assert_allclose(res["pad_forces"][0, :, :, 1], mo["pads"], rtol=1e-6)
    # the springs' sums are the contact regions' transverse reactions: region II's on the
    # inner boom's section (the outer pad), region I's on the outer boom's (the inner pad,
    # reversed), to the micro-motion solve's tolerance
    cpf = res["contact_point_forces"][:, :, :, 1:3]          # (n, overlaps, [I, II], (t, b))
    scale = np.max(np.abs(res["pad_forces"]))
    np.testing.assert_allclose(res["pad_forces"][:, :, 0], cpf[:, :, 1], atol=1e-6 * scale)
    np.testing.assert_allclose(res["pad_forces"][:, :, 1], -cpf[:, :, 0], atol=1e-6 * scale)
    faces = res["pad_face_forces"][0]
    assert np.all(faces >= 0.0)
    size = np.linalg.norm(res["pad_forces"][0], axis=-1)
    assert np.all(np.nansum(faces, axis=-1) >= size * (1.0 - 1e-9))


def test_the_pad_figure_labels_every_pad(tmp_path, monkeypatch):
    """A crane described boom by boom gets pad_forces.png, one row per overlap with the lines
    "overlap k outer pad" and "overlap k inner pad", in place of the spring-by-spring figure;
    the [booms] shorthand keeps the paper's Fig. 26 (slider_contact_forces.png)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sim_core.result import Result
    from sim_core.systems.telescopic import plots

    n = 5
    t = np.linspace(0.0, 1.0, n)
    out = {"pad_forces": np.ones((n, 2, 2, 2)) * [[[1.0], [-1.0]]] * 1e5,
           "pad_couples": np.zeros((n, 2, 2, 2)),
           "pad_face_forces": np.ones((n, 2, 2, 8)),
           "slider_contact_forces": np.ones((n, 4, 16))}
    figs = []
    orig = plots.save_figure
    monkeypatch.setattr(plots, "save_figure",
                        lambda fig, path: (figs.append((fig, path.name)), orig(fig, path))[1])
    monkeypatch.setattr(plt, "close", lambda fig=None: None)
    names = [p.name for p in plots.plot_telescopic(
        Result(t, out, {}, {"kind": "telescopic", "boom": [{}] * 3}), tmp_path)]
    assert names == ["pad_forces.png"]
    fig = figs[0][0]
    labels = {ln.get_label() for ax in fig.axes for ln in ax.get_lines()}
    for k in (1, 2):
        for pad in ("outer", "inner"):
            assert f"overlap {k} {pad} pad, f_b" in labels
    shorthand = [p.name for p in plots.plot_telescopic(
        Result(t, out, {}, {"kind": "telescopic", "booms": {"count": 3}}), tmp_path)]
    assert shorthand == ["pad_forces.png", "slider_contact_forces.png"]
    monkeypatch.undo()
    for fig, _ in figs:
        plt.close(fig)
