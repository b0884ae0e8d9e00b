"""Effects of the telescopic scene switched off: each must agree with the full model where
physics says it should (issue "Scenes and effects"), and the rigid limit must balance energy."""

import math

import numpy as np
import pytest

from sim_core.physics.constraints import material_point
from sim_core.physics.contact.friction import ContactFriction, section_reaction
from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.rigid import RigidTelescopic
from sim_core.validation.closed_form import luffing_geometry, rigid_tip_kinematics, static_luffing_forces

PAPER = dict(E=2.1e11, payload=25000.0)
THETA = math.radians(60.0)


def _rigid(**kw):
    p = TelescopicParams(flexible=False, **{**PAPER, **kw})
    return RigidTelescopic(p), p


# ----------------------------------------------------------------------------- rigid limit
def test_rigid_inextensible_tip_follows_eqs_74_76():
    """Inextensible rope: boom 3 moves exactly twice the piston stroke (Eqs. 74-76)."""
    rig, p = _rigid(rope_elasticity=False)
    res = rig.simulate(16.0, 161)
    tip0 = res["tip_position"][0][[0, 2]]
    ref = rigid_tip_kinematics(res.t, rig.schedule, THETA, tip0)
    np.testing.assert_allclose(res["tip_position"][:, 0], ref.x, atol=1e-12)
    np.testing.assert_allclose(res["tip_position"][:, 2], ref.z, atol=1e-12)
    np.testing.assert_allclose(res["tip_velocity"][:, 2], ref.vz, atol=1e-12)
    np.testing.assert_allclose(res["tip_acceleration"][:, 0], ref.ax, atol=1e-12)


def test_rigid_static_forces_match_moment_balance():
    """At rest the rigid model's forces are those of docs/model.md#check-static-luffing
    (independent closed-form code path)."""
    for elastic in (False, True):
        rig, p = _rigid(rope_elasticity=elastic)
        res = rig.simulate(0.5, 3)                      # schedule starts at rest: a(0) = 0
        ref = static_luffing_forces(THETA, p.stroke0, p.payload, z_c=(0.0, 0.0, 0.0))
        assert res["luffing_cylinder_force"][0] == pytest.approx(ref.luffing_force, rel=1e-9)
        assert res["telescopic_cylinder_force"][0] == pytest.approx(ref.telescopic_force, rel=1e-9)


@pytest.mark.parametrize("elastic", [False, True])
def test_rigid_energy_balance(elastic):
    """Work of the telescopic cylinder = change of kinetic + gravity (+ rope strain) energy.
    The luffing cylinder does no work (fixed length) and sliding is frictionless.  Trapezoidal
    quadrature on 4001 samples of smooth (C1) histories: relative error ~ (dt/T)^2 ~ 1e-7;
    RK45 at rtol 1e-10 for the rope dof.  Tolerance 1e-5 of the work."""
    rig, p = _rigid(rope_elasticity=elastic)
    res = rig.simulate(16.0, 4001, rtol=1e-10, atol=1e-12)
    t = res.t
    sch = rig.schedule
    v2 = np.array([sch.rate(tk) for tk in t])
    a2 = np.array([sch.stroke(tk) for tk in t])
    work = np.trapezoid(res["telescopic_cylinder_force"] * v2, t)
    e = luffing_geometry(THETA).e_s
    g = 9.81
    m2, m3 = rig.masses[1], rig.masses[2] + p.payload
    # boom 3 + payload move with the tip; boom 2 with the piston
    v3 = res["tip_velocity"] @ e
    a3 = (res["tip_position"] - res["tip_position"][0]) @ e + 2 * p.stroke0
    kin = 0.5 * m2 * v2 ** 2 + 0.5 * m3 * v3 ** 2
    pot = (m2 * a2 + m3 * a3) * g * math.sin(THETA)
    energy = kin + pot
    if elastic:
        T = res["rope_tension"]
        energy = energy + sum(0.5 * Ti ** 2 * L0 / rig.EA for Ti, L0 in
                              zip(T.T, (rig.Le, rig.Lr)))
    assert energy[-1] - energy[0] == pytest.approx(work, rel=1e-5)
    assert work > 0.0


# ----------------------------------------------------------------------------- flexible model
@pytest.fixture(scope="module")
def equilibria():
    base = dict(n_nodes=3, **PAPER)
    out = {}
    for key, kw in (("full", {}), ("no_torsion", dict(torsion=False)),
                    ("rigid_rope", dict(rope_elasticity=False))):
        ts = build_telescopic(TelescopicParams(**base, **kw))
        out[key] = (ts, *initial_equilibrium(ts))
    return out


def _tip(entry):
    ts, z, _ = entry
    Q, _ = ts.model.full_state(0.0, z, np.zeros_like(z))
    return ts.tip(Q)[0]


def test_torsion_off_changes_nothing_in_the_plane(equilibria):
    """The scene is symmetric about the luffing plane: no load twists the booms, so holding the
    torsion angles at zero gives the same equilibrium (to the Newton tolerance, 1e-7 of the
    force scale) with 102 fewer coordinates."""
    ts_f, z_f, lam_f = equilibria["full"]
    ts_n, z_n, lam_n = equilibria["no_torsion"]
    assert ts_n.model.n_dof < ts_f.model.n_dof
    np.testing.assert_allclose(_tip(equilibria["no_torsion"]), _tip(equilibria["full"]), atol=1e-7)
    for name in ("luffing_cylinder", "telescopic_cylinder"):
        assert lam_n[ts_n.rows[name]][0] == pytest.approx(lam_f[ts_f.rows[name]][0], rel=1e-6)


def test_inextensible_rope_carries_the_closed_form_tension(equilibria):
    """rope_elasticity = false: the rope multiplier is the rope tension T = (m3 + m_p) g sin th
    (docs/model.md#check-static-luffing; the flexible booms' small rotations change it by
    < 0.5 %, the tolerance of the existing static-luffing test), and the elastic rope gives the
    same equilibrium up to its stretch (T L0 / EA ~ 2 mm along the axis)."""
    ts, z, lam = equilibria["rigid_rope"]
    T = -lam[ts.rows["rope"]][0]
    ref = static_luffing_forces(THETA, 2.0, PAPER["payload"], z_c=(0.0, 0.0, 0.0))
    assert T == pytest.approx(ref.rope_tension, rel=5e-3)
    ts_f, z_f, lam_f = equilibria["full"]
    assert (lam[ts.rows["luffing_cylinder"]][0]
            == pytest.approx(lam_f[ts_f.rows["luffing_cylinder"]][0], rel=5e-3))
    stretch = ref.rope_tension * 20.0 / 1e8
    assert np.linalg.norm(_tip(equilibria["rigid_rope"]) - _tip(equilibria["full"])) < 2 * stretch


def test_resultant_normal_load_bounds_the_spring_sum(equilibria):
    """contact_distribution = false takes the friction normal load as |(f_t, f_b)| of the contact
    resultant.  The radial springs' forces lie in the section plane and sum (with the moment
    equations) to that resultant, so by the triangle inequality sum |f_i| >= |sum f_i|: the
    resultant load is a lower bound of the paper's spring sum (Eq. 65)."""
    ts, z, lam = equilibria["full"]
    Q, _ = ts.model.full_state(0.0, z, np.zeros_like(z))
    Qd = np.zeros_like(Q)
    p = ts.params
    dist = ContactFriction(ts, p.mu_static, p.mu_dynamic, p.v_eps, p.spring_k0, p.spring_eps)
    res = ContactFriction(ts, p.mu_static, p.mu_dynamic, p.v_eps, distribution=False)
    for (name, _, _, sol), (_, _, _, N) in zip(dist.solve_regions(Q, Qd, lam),
                                               res.solve_regions(Q, Qd, lam)):
        assert 0.0 < N <= sol.total_normal_force * (1 + 1e-9), name
        # and the spring forces do reproduce the transverse resultant (equivalence equations)
        point = next(pt for n_, pt, _, _ in dist.regions if n_ == name)
        f_c, _ = section_reaction(point, Q, lam[ts.rows[name + "_point"]],
                                  lam[ts.rows[name + "_angles"]], dist.basis)
        assert np.hypot(*sol.force_on_section[1:]) == pytest.approx(N, rel=1e-6)


def test_friction_off_equals_mu_zero():
    """friction = false and friction = true with mu = 0 integrate the same equations: the runs
    agree to the integrators' global error (both at rtol 1e-8 here: < 1e-9 m on a 0.05 s window
    where the tip moves ~1e-6 m)."""
    base = dict(n_nodes=3, E=2.1e12, payload=1000.0, contact_distribution=False)
    from sim_core.systems.telescopic.build import simulate_telescopic
    r0 = simulate_telescopic(TelescopicParams(friction=False, **base), 0.05, 6, rtol=1e-8, atol=1e-10)
    r1 = simulate_telescopic(TelescopicParams(friction=True, mu_static=0.0, mu_dynamic=0.0, **base),
                             0.05, 6, rtol=1e-8, atol=1e-10)
    assert r0.error is None and r1.error is None
    np.testing.assert_allclose(r1["tip_position"], r0["tip_position"], atol=1e-9)
    np.testing.assert_allclose(r1["telescopic_cylinder_force"], r0["telescopic_cylinder_force"],
                               rtol=1e-6)


def test_frictionless_contact_carries_no_axial_force(equilibria):
    """Without friction nothing resists a relative slide: the contact coordinates carry no
    generalized force (Section 7: eta = 0; Eq. 72 with mu = 0), i.e. r' . f + psi' . lambda_psi
    = 0.  The axial force f_s is then only the curvature coupling psi' . lambda_psi (the contact
    moment times the boom curvature), below 1 % of the transverse force for these nearly straight
    booms (measured 2e-4); in region II the junction node's coordinate also carries the
    discretisation-level elastic flux of the moving node, under the same bound."""
    ts, z, lam = equilibria["full"]
    m = ts.model
    Q, _ = m.full_state(0.0, z, np.zeros_like(z))
    basis = m.beams[0].reference_basis
    for k in range(ts.params.n_booms - 1):
        for name, point in ((f"I_{k + 1}{k + 2}", material_point(m, k, s_index=ts.s2_index[k])),
                            (f"II_{k + 1}{k + 2}",
                             material_point(m, k + 1, s_index=ts.s3_index[k + 1]))):
            f, _ = section_reaction(point, Q, lam[ts.rows[name + "_point"]],
                                    lam[ts.rows[name + "_angles"]], basis)
            assert abs(f[0]) <= 1e-2 * np.hypot(f[1], f[2]), (name, f)
