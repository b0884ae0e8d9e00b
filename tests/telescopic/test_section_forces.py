"""Section forces of the moving-node beam (sim_core.physics.beam.section_forces) against statics.

(a) A cantilever along X under a tip load and under its weight: N, Q_b, M_t along the beam
against the statics of the part beyond each station (docs/model.md#section-forces).  The
deflection is 1e-4 of the length, so the geometric nonlinearity is O(1e-8); the quintic
spline holds the linear and parabolic moment diagrams exactly, so the 0.5 % tolerance is far
above the error.

(b) The paper's three booms at 60 deg with the 25 t payload, contact.moment_model = "couple",
in their static equilibrium: the section forces against the statics of the part of each boom
beyond the station in the deformed configuration, with the model's own contact forces (the
multipliers of the contact regions), the rope forces over their pulleys, the payload and the
weight (Gauss quadrature along the deformed centre line).  A contact point that is not a node
of its element (the inner contact point s_2,k; an outer slider inside a boom's end) puts a kink
into the moment diagram that the quintic spline rounds off over about one sub-element: the
stations closer than two sub-elements to those points are left out of the 2 % check.  Boom 1
is checked beyond its luffing point only, and three sub-elements away from it: the cylinder
head's offset puts a concentrated couple there (a jump of the moment, 1.6 MN m), which the
junction of two elements, C2 in the centre line, spreads over its neighbours (8.6 % of the
boom's largest moment one station away, 2.9 % two stations away, measured).

(c) The chain rule for eps' against the complex step in s.
"""

from __future__ import annotations

import numpy as np
import pytest

from sim_core.model.statics import static_equilibrium
from sim_core.physics.beam.section_forces import (
    beam_section_forces,
    element_section_forces,
    resultants,
)
from sim_core.physics.constraints import material_point
from sim_core.physics.contact.friction import region_multipliers, section_reaction
from sim_core.physics.effects import PointLoad
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.params import TelescopicParams, boom_section
from tests.beam.conftest import RHO, A, L, cantilever

STATIONS = np.linspace(0.0, L, 11)


def _static(m, Q0):
    z0, _ = m.reduced_state(0.0, Q0, np.zeros_like(Q0))
    z = static_equilibrium(m, z0)
    Q, _ = m.full_state(0.0, z, np.zeros_like(z))
    return np.real(Q)


def test_cantilever_tip_load_root_moment_and_shear():
    """Tip load P along -Z: Q_b = P (the load the outer part passes on), M_t = -P (L - s),
    M_t > 0 stretching the top fibres (+e_b = +Z)."""
    P = -100.0
    m, Q0 = cantilever(loads=[PointLoad(0, lambda t: L, lambda t: np.array([0.0, 0.0, P]))])
    F = beam_section_forces(m.beams[0], _static(m, Q0), STATIONS)
    np.testing.assert_allclose(F[:, 2], P, rtol=5e-3)
    np.testing.assert_allclose(F[:, 4], -P * (L - STATIONS), rtol=5e-3, atol=5e-3 * abs(P) * L)
    assert np.abs(F[:, [1, 3, 5]]).max() < 1e-6 * abs(P) * L     # no load across the plane


def test_cantilever_self_weight_root_moment_and_shear():
    """Weight q per length: Q_b = q (L - s), M_t = -q (L - s)^2 / 2."""
    g = np.array([0.0, 0.0, -9.81 * 0.01])
    m, Q0 = cantilever(gravity=g)
    F = beam_section_forces(m.beams[0], _static(m, Q0), STATIONS)
    q = RHO * A * g[2]
    assert F[0, 2] == pytest.approx(q * L, rel=5e-3)
    assert F[0, 4] == pytest.approx(-q * L**2 / 2, rel=5e-3)
    np.testing.assert_allclose(F[:, 4], -q * (L - STATIONS) ** 2 / 2, rtol=5e-3,
                               atol=5e-3 * abs(q) * L**2 / 2)


def test_strain_derivative_matches_complex_step():
    """eps' by the chain rule (deps_dx . x') against the complex step in s of the strains,
    in a bent and twisted state (random coordinates near the straight beam)."""
    m, Q0 = cantilever()
    el = m.beams[0].elements[0]
    rng = np.random.default_rng(3)
    qe = Q0[m.beams[0].index_map[0]] + 1e-2 * rng.standard_normal(el.n_coords) * (
        np.arange(el.n_coords) < el.i_s1)
    s = np.array([0.7, 3.3, 5.0, 8.9])
    F = element_section_forces(el, qe, s)
    h = 1e-20
    sub = el.locate(qe, s)
    eps = el.evaluate(qe, s=s).sec.eps
    eps_p = el.evaluate(qe.astype(complex), s=s + 1j * h, sub=sub).sec.eps.imag / h
    np.testing.assert_allclose(F, resultants(eps, eps_p, el.section.D), rtol=1e-9,
                               atol=1e-9 * np.abs(F).max())


# --- (b) the luffed three-section boom ------------------------------------------------------

@pytest.fixture(scope="module")
def crane():
    p = TelescopicParams(moment_model="couple", contact_distribution=False)
    ts = build_telescopic(p)
    z, lam = initial_equilibrium(ts)
    Q, _ = ts.model.full_state(0.0, z, np.zeros_like(z))
    return ts, np.real(Q), lam


def _point_loads(ts, Q, lam):
    """Per boom: (s, r, f, m) of every concentrated load (global components) the statics of
    the module docstring take: contact regions, ropes, payload."""
    m, p = ts.model, ts.params
    basis = m.beams[0].reference_basis
    L = p.lengths
    loads = [[] for _ in range(p.n_booms)]

    def at(k, s, f, mom=np.zeros(3)):
        loads[k].append((s, np.real(m.point(k, s, Q)[0]), f, mom))

    d_in = [o.inner_distance for o in p.overlaps]
    d_out = [o.outer_distance for o in p.overlaps]
    for k in range(p.n_booms - 1):
        # point_coincidence(a, b): the force on b is -lambda, on a +lambda (friction.py)
        for name, (ka, sa), (kb, sb) in (
                (f"I_{k + 1}{k + 2}", (k + 1, d_in[k]), (k, Q[ts.s2_index[k]])),
                (f"II_{k + 1}{k + 2}", (k, L[k] - d_out[k]), (k + 1, Q[ts.s3_index[k + 1]]))):
            lp, la = region_multipliers(ts, name, Q, lam)
            _, m_sec = section_reaction(material_point(m, kb, s_fixed=float(sb)), Q, lp, la,
                                        basis)
            e_t, e_b, e_s = np.real(m.point(kb, float(sb), Q)[1].sec.frame[0])
            mom = m_sec[0] * e_s + m_sec[1] * e_t + m_sec[2] * e_b
            at(kb, float(sb), -lp, mom)
            at(ka, float(sa), lp, -mom)
    at(p.n_booms - 1, L[-1], p.payload * np.array([0.0, 0.0, -p.gravity]))
    # the rope unit of boom 3 (build.py): anchor on boom 1, pulley on boom 2, boom 3's root
    layouts = ([(0, 0.0), (1, L[1] - 1.0), (2, 0.0)], [(0, L[0]), (1, 0.66), (2, 0.0)])
    for rope, layout in zip(ts.ropes[0], layouts):
        T = rope.tension(float(np.real(rope.length(Q)[0])))
        pts = [np.real(f(Q)[0]) for f in rope.points]
        for i, (k, s) in enumerate(layout):
            f = sum(T * (pts[j] - pts[i]) / np.linalg.norm(pts[j] - pts[i])
                    for j in (i - 1, i + 1) if 0 <= j < len(pts))
            loads[k].append((s, pts[i], f, np.zeros(3)))
    return loads


def _statics(ts, Q, k, stations, loads):
    """(N, Q_t, Q_b, T, M_t, M_b) of the part of boom k beyond each station."""
    m, p = ts.model, ts.params
    Lk = p.lengths[k]
    q = boom_section(k, p).rhoA * np.array([0.0, 0.0, -p.gravity])
    xg, wg = np.polynomial.legendre.leggauss(12)
    out = []
    for s in stations:
        r0, kin, _ = m.point(k, s, Q)
        r0 = np.real(r0)
        e_t, e_b, e_s = np.real(kin.sec.frame[0])
        n, mom = np.zeros(3), np.zeros(3)
        for sl, rl, fl, ml in loads[k]:
            if sl > s:
                n += fl
                mom += np.cross(rl - r0, fl) + ml
        # the weight beyond s, segment by segment between the stations (smooth centre line)
        edges = np.append(stations[stations > s], Lk) if s < Lk else []
        lo = s
        for hi in edges:
            if hi <= lo:
                continue
            for x, w in zip(lo + (hi - lo) * (xg + 1) / 2, wg * (hi - lo) / 2):
                n += q * w
                mom += np.cross(np.real(m.point(k, x, Q)[0]) - r0, q * w)
            lo = hi
        out.append([n @ e_s, n @ e_t, n @ e_b, mom @ e_s, mom @ e_t, mom @ e_b])
    return np.array(out)


def test_luffed_three_boom_moment_diagram_against_statics(crane):
    ts, Q, lam = crane
    m, p = ts.model, ts.params
    loads = _point_loads(ts, Q, lam)
    d_out = [o.outer_distance for o in p.overlaps]
    for k in range(p.n_booms):
        Lk = p.lengths[k]
        stations = np.linspace(0.0, Lk, 21)
        off = m.offsets[k]
        F = beam_section_forces(m.beams[k], Q[off:off + m.beams[k].n_coords], stations)
        ref = _statics(ts, Q, k, stations, loads)
        # kinks off the nodes: s_2,k on boom k, boom k's outer slider (module docstring)
        sub = (Lk - Q[ts.s3_index[k]]) / (p.n_nodes - 1)
        kinks = [Q[ts.s2_index[k]]] if k < p.n_booms - 1 else []
        kinks.append(Lk - d_out[k]) if k < p.n_booms - 1 else None
        keep = np.ones(stations.size, dtype=bool)
        if k == 0:           # beyond the luffing point and its cylinder couple
            keep = stations > p.L_h + 3 * sub
        for s_k in kinks:
            keep &= (np.abs(stations - s_k) > 2 * sub) | (s_k >= Lk)
        assert keep.sum() >= 3
        scale = np.abs(ref[:, 4]).max()
        assert np.abs(F[keep, 4] - ref[keep, 4]).max() <= 0.02 * scale, k
        # the shear of the tip boom (no kink off a node) and the lateral components
        if k == p.n_booms - 1:
            # (at the tip the payload is the end load: the statics beyond s = L hold nothing)
            np.testing.assert_allclose(F[:-1, 2], ref[:-1, 2], rtol=0,
                                       atol=0.02 * np.abs(ref[:, 2]).max())
            np.testing.assert_allclose(F[:-1, 0], ref[:-1, 0], rtol=0.02)
        assert np.abs(F[:, [1, 3, 5]]).max() <= 1e-6 * scale


def test_result_carries_section_outputs(crane):
    """The whole-run outputs: shapes, stations, the stresses' link to the forces, utilisation
    at the default f_y."""
    from sim_core.physics.section_stress import OUTLINE_POINTS, stress_table, von_mises
    from sim_core.systems.telescopic.build import SECTION_STATIONS, _section_outputs, \
        boom_cross_section
    ts, Q, lam = crane
    n = ts.model.n_dof
    z, _ = ts.model.reduced_state(0.0, Q, np.zeros_like(Q))
    y = np.concatenate([z, np.zeros_like(z)])
    out = _section_outputs(ts, np.array([0.0, 0.1]), [y, y])
    N = ts.params.n_booms
    assert out["section_forces"].shape == (2, N, SECTION_STATIONS, 6)
    assert out["section_stress"].shape == (2, N, SECTION_STATIONS, OUTLINE_POINTS, 2)
    assert out["section_utilisation"].shape == (2, N, SECTION_STATIONS)
    assert len(y) == 2 * n
    k = N - 1
    table = stress_table(boom_cross_section(ts.params, k))
    sigma = table.sigma @ out["section_forces"][0, k, 5]
    np.testing.assert_allclose(out["section_stress"][0, k, 5, :, 0], sigma)
    vm = von_mises(out["section_stress"][0, k, 5, :, 0], out["section_stress"][0, k, 5, :, 1])
    assert out["section_utilisation"][0, k, 5] == pytest.approx(vm.max() / ts.params.f_y)


# --- the whole run: result, VTK export, report, scene key ----------------------------------

@pytest.fixture(scope="module")
def short_run():
    """A short telescopic extraction (3 booms with 3 nodes, 3 output times; about 3 s)."""
    from sim_core import load_scene, simulate
    return simulate(load_scene("telescopic_extraction", overrides={
        "booms.n_nodes": 3, "solver.t_end": 0.2, "solver.n_output": 3,
        "material.f_y": 690e6}))


def test_run_exports_and_reports_the_section_forces(short_run, tmp_path):
    import meshio

    from sim_core.report import STRENGTH_CLASS, write_report
    from sim_core.vtk_export import export_vtk
    res = short_run
    F, U = res["section_forces"], res["section_utilisation"]
    st = res["section_stations"]
    assert F.shape[:3] == U.shape and np.isfinite(U).all() and (U > 0).all()
    # a payload of 25 t on a luffed boom bends boom 3 most next to its outer contact point
    assert np.abs(F[..., 4]).max() > 1e5
    pvd = export_vtk(res, tmp_path / "vtk")
    mesh = meshio.read(sorted((pvd.parent / "frames").iterdir())[-1])
    on = mesh.point_data["boom"] >= 0
    lines = res["geometry_centre_lines"]
    N, P = lines.shape[1:3]
    moment = mesh.point_data["section_moment"][on].reshape(N, P, 3)
    for k in range(N):
        s_pts = np.linspace(0.0, st[k, -1], P)
        np.testing.assert_allclose(moment[k, :, 1], np.interp(s_pts, st[k], F[-1, k, :, 4]),
                                   rtol=1e-12, atol=1e-9 * np.abs(F[..., 4]).max())
    util = mesh.point_data["section_utilisation"][on].reshape(N, P)
    np.testing.assert_allclose(util[:, 0], U[-1, :, 0])
    page = write_report(res, tmp_path / "report.html").read_text()
    assert page.count(f'class="{STRENGTH_CLASS}"') == 2 and 'id="strength"' in page


def test_yield_strength_sets_the_utilisation(short_run):
    from sim_core.physics.section_stress import von_mises
    res = short_run
    vm = von_mises(res["section_stress"][..., 0], res["section_stress"][..., 1]).max(axis=-1)
    np.testing.assert_allclose(res["section_utilisation"], vm / 690e6)


@pytest.mark.parametrize("value", [5e7, 3e9, "S355"])
def test_yield_strength_outside_its_range_names_the_field(value):
    from sim_core import SceneError, load_scene
    with pytest.raises(SceneError, match=r"material\.f_y"):
        load_scene("telescopic_extraction", overrides={"material.f_y": value})
