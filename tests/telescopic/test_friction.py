"""Frictional sliding-block contact coupled to the telescopic system (Section 8)."""

import numpy as np
import pytest

from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium


@pytest.fixture(scope="module")
def systems():
    """The friction with its normal load from the slider springs (contact.friction_load =
    "springs": the micro-motion machinery these tests check) and the frictionless system."""
    base = dict(n_nodes=3, E=2.1e12, payload=1000.0)
    ts_f = build_telescopic(TelescopicParams(friction=True, friction_load="springs", **base))
    ts_0 = build_telescopic(TelescopicParams(friction=False, **base))
    z, _ = initial_equilibrium(ts_0)
    # the same rope lengths in both systems (set at the frictionless equilibrium)
    for a, b in zip(ts_f.model.point_effects, ts_0.model.point_effects):
        if hasattr(a, "L0"):
            a.L0 = b.L0
    return ts_f, ts_0, z


def _sliding_state(ts, z, v=0.2):
    """State at the equilibrium configuration with every contact point sliding as in an
    extraction at telescopic speed v (boom 2 at v, boom 3 at 2v relative to boom 1)."""
    m = ts.model
    Q, _ = m.full_state(0.0, z, np.zeros_like(z))
    Qd = np.zeros_like(Q)
    Qd[ts.s2_index[0]], Qd[ts.s2_index[1]] = v, v
    Qd[ts.s3_index[1]], Qd[ts.s3_index[2]] = -v, -v
    return Q, Qd


def test_friction_at_rest_changes_nothing(systems):
    """At rest mu(0) = 0: the frictional model gives the frictionless accelerations."""
    ts_f, ts_0, z = systems
    zd = np.zeros_like(z)
    a_f, lam_f = ts_f.model.accelerations_and_multipliers(0.0, z, zd)
    a_0, lam_0 = ts_0.model.accelerations_and_multipliers(0.0, z, zd)
    np.testing.assert_allclose(lam_f, lam_0, rtol=1e-9, atol=1e-9 * np.max(np.abs(lam_0)))


def test_friction_dissipates_and_balances_the_axial_reaction(systems):
    """While sliding, the friction power is negative (-mu(s_dot) N s_dot per region, Eq. 65), and
    in region I (whose contact coordinate s_2,k carries no elastic force) the axial constraint
    reaction equals the friction resultant mu N - the auxiliary equation Eq. 72 - up to the
    curvature coupling term (booms nearly straight: < 1 %)."""
    ts_f, _, z = systems
    m = ts_f.model
    Q, Qd = _sliding_state(ts_f, z)
    zd = m.reduced_state(0.0, Q, Qd)[1]
    _, lam = m.accelerations_and_multipliers(0.0, z, zd)
    fr = m.multiplier_forces[0]
    dF = fr.forces(0.0, Q, Qd, lam)
    assert dF @ Qd < 0.0
    for name, s_idx, mu, sol in fr.solve_regions(Q, Qd, lam):
        assert abs(mu) == pytest.approx(0.1, abs=1e-12)         # beyond 2 v_eps: mu_dynamic
        assert sol.total_normal_force > 0.0
        if name.startswith("I_"):
            from sim_core.physics.contact.friction import section_reaction
            point = next(p for n_, p, _, _ in fr.regions if n_ == name)
            f_sec, _ = section_reaction(point, Q, lam[ts_f.rows[name + "_point"]],
                                        lam[ts_f.rows[name + "_angles"]], fr.basis)
            assert abs(f_sec[0]) == pytest.approx(abs(mu) * sol.total_normal_force, rel=1e-2)


def test_resultant_friction_load_balances_the_axial_reaction(systems):
    """contact.friction_load = "resultant": while sliding, the axial reaction of region I (the
    auxiliary equation Eq. 72) is mu times the transverse contact resultant |(f_t, f_b)| - the
    Coulomb ratio between the constraint force's axial and normal components that Section 9.2
    (4) describes - up to the curvature coupling term (booms nearly straight: < 1 %)."""
    from sim_core.physics.contact.friction import region_multipliers, section_reaction
    _, _, z = systems
    ts = build_telescopic(TelescopicParams(n_nodes=3, E=2.1e12, payload=1000.0, friction=True,
                                           friction_load="resultant"))
    m = ts.model
    Q, Qd = _sliding_state(ts, z)
    zd = m.reduced_state(0.0, Q, Qd)[1]
    _, lam = m.accelerations_and_multipliers(0.0, z, zd)
    fr = m.multiplier_forces[0]
    assert fr.forces(0.0, Q, Qd, lam) @ Qd < 0.0
    for name, point, _, _ in fr.regions:
        if name.startswith("I_"):
            f, _ = section_reaction(point, Q, *region_multipliers(ts, name, Q, lam), fr.basis)
            assert abs(f[0]) == pytest.approx(0.1 * np.hypot(f[1], f[2]), rel=1e-2)


def test_friction_raises_the_telescopic_cylinder_force(systems):
    """Extracting against friction needs more cylinder force than without it (same state)."""
    ts_f, ts_0, z = systems
    forces = []
    for ts in (ts_f, ts_0):
        Q, Qd = _sliding_state(ts, z)
        zd = ts.model.reduced_state(0.0, Q, Qd)[1]
        _, lam = ts.model.accelerations_and_multipliers(0.0, z, zd)
        forces.append(lam[ts.rows["telescopic_cylinder"]][0])
    assert forces[0] > forces[1] * 1.2


def test_friction_flips_sign_between_extraction_and_retraction(systems):
    """Section 8.3: the friction force on a contact coordinate opposes its relative slide, so
    it changes sign when the motion is reversed; the telescopic cylinder then needs more force
    when extracting and less when retracting than without friction (the same state)."""
    ts_f, ts_0, z = systems
    fr = ts_f.model.multiplier_forces[0]
    cyl = {}
    for v in (0.2, -0.2):
        Q, Qd = _sliding_state(ts_f, z, v)
        zd = ts_f.model.reduced_state(0.0, Q, Qd)[1]
        _, lam = ts_f.model.accelerations_and_multipliers(0.0, z, zd)
        dF = fr.forces(0.0, Q, Qd, lam)
        for idx in ts_f.s2_index + ts_f.s3_index[1:]:
            assert dF[idx] * Qd[idx] < 0.0            # opposes the slide
        cyl[v] = lam[ts_f.rows["telescopic_cylinder"]][0]
        Q0, Qd0 = _sliding_state(ts_0, z, v)
        zd0 = ts_0.model.reduced_state(0.0, Q0, Qd0)[1]
        cyl[(v, 0)] = ts_0.model.accelerations_and_multipliers(0.0, z, zd0)[1][
            ts_0.rows["telescopic_cylinder"]][0]
    assert cyl[0.2] > cyl[(0.2, 0)] and cyl[-0.2] < cyl[(-0.2, 0)]


@pytest.mark.parametrize("distribution", [True, False])
def test_multiplier_newton_matches_the_converged_fixed_point(systems, distribution):
    """The friction forces act on the 4 contact coordinates only, so the coupled
    friction-multiplier problem is solved by Newton in those 4 values (Model._multiplier_newton).
    It must give the fixed point's solution (iterated to 1e-13, relative), and - its Jacobian
    being the analytic micro-motion sensitivity - in fewer friction evaluations than the fixed
    point needs for the default 1e-8 (a wrong sensitivity loses the quadratic convergence)."""
    import sim_core.physics.contact.friction as cf

    ts_f, _, z = systems
    m = ts_f.model
    fr = m.multiplier_forces[0]
    saved = (fr.distribution, fr.regions, m.multiplier_tol, m.multiplier_max_iter)
    if not distribution:
        fr.regions = [(n, p, s, None) for n, p, s, _ in fr.regions]
        fr.friction_load = "resultant"
    Q, Qd = _sliding_state(ts_f, z, 0.3)
    zd = m.reduced_state(0.0, Q, Qd)[1]
    calls = []
    values = cf.FrictionAtState.values

    def counted(self, lam, gradient=False):
        calls.append(1)
        return values(self, lam, gradient)

    try:
        cf.FrictionAtState.values = counted
        m.multiplier_newton_compiled = False    # the Python loop: its evaluations are counted
        m.multiplier_newton, m.multiplier_tol, m.multiplier_max_iter = False, 1e-13, 60
        a_ref, lam_ref = m.accelerations_and_multipliers(0.0, z, zd)
        m.multiplier_tol, m.multiplier_max_iter = saved[2:]
        calls.clear()
        m.accelerations_and_multipliers(0.0, z, zd)
        n_fixed = len(calls)
        m.multiplier_newton = True
        calls.clear()
        a, lam = m.accelerations_and_multipliers(0.0, z, zd)
        n_newton = len(calls)
    finally:
        cf.FrictionAtState.values = values
        m.multiplier_newton = True
        m.multiplier_newton_compiled = True
        fr.distribution, fr.regions, m.multiplier_tol, m.multiplier_max_iter = saved
        fr.friction_load = "springs"
    # the friction changes the multipliers by O(10 %): a 1e-9 agreement needs both solves
    assert np.max(np.abs(lam - lam_ref)) < 1e-9 * np.max(np.abs(lam_ref))
    assert np.max(np.abs(a - a_ref)) < 1e-9 * np.max(np.abs(a_ref))
    assert n_newton < n_fixed


@pytest.mark.parametrize("friction_load", ["springs", "resultant"])
def test_friction_multiplier_gradient_matches_finite_differences(systems, friction_load):
    """dg/dlambda of FrictionAtState (section maps and micro-motion sensitivity, or the
    resultant's direction) vs central differences in every multiplier; step 1e-6 of
    max |lambda|, tolerance 1e-5 of the largest entry (truncation of the C1 spring law and the
    1e-11 solver tolerance are far below)."""
    ts_f, _, z = systems
    if friction_load == "resultant":
        ts_f = build_telescopic(TelescopicParams(n_nodes=3, E=2.1e12, payload=1000.0,
                                                 friction=True, friction_load="resultant"))
    m = ts_f.model
    Q, Qd = _sliding_state(ts_f, z, 0.3)
    zd = m.reduced_state(0.0, Q, Qd)[1]
    _, lam = m.accelerations_and_multipliers(0.0, z, zd)
    at = m.multiplier_forces[0].at_state(0.0, Q, Qd)
    g, dg = at.values(lam, gradient=True)
    h = 1e-6 * np.max(np.abs(lam))
    fd = np.empty_like(dg)
    for j in range(len(lam)):
        e = np.zeros_like(lam)
        e[j] = h
        fd[:, j] = (at.values(lam + e)[0] - at.values(lam - e)[0]) / (2 * h)
    assert np.all(g != 0.0)
    np.testing.assert_allclose(dg, fd, rtol=0, atol=1e-5 * np.abs(dg).max())


def test_compiled_regions_equal_the_region_by_region_values(systems):
    """FrictionAtState.values: all regions in one compiled call (micro_motion_compiled.
    regions_values) give the region-by-region values and gradients of the reference path
    (normal_load per region) within the micro-motion solver's tolerance; without warm starts
    (cold start needed) the compiled call declines and the reference path answers."""
    from sim_core.physics.contact import _sliding_block_contact_numba as micro_motion_compiled
    if not micro_motion_compiled.AVAILABLE:
        pytest.skip("numba not installed")
    ts_f, _, z = systems
    m = ts_f.model
    Q, Qd = _sliding_state(ts_f, z, 0.3)
    zd = m.reduced_state(0.0, Q, Qd)[1]
    _, lam = m.accelerations_and_multipliers(0.0, z, zd)
    fr = m.multiplier_forces[0]
    at = fr.at_state(0.0, Q, Qd)
    assert at._batch is not None
    x0 = {k: v.copy() for k, v in fr._x0.items()}
    g, dg = at.values(lam, gradient=True)
    fr._x0.clear()
    fr._x0.update({k: v.copy() for k, v in x0.items()})
    batch, at._batch = at._batch, None
    g_ref, dg_ref = at.values(lam, gradient=True)
    np.testing.assert_allclose(g, g_ref, rtol=1e-9)
    np.testing.assert_allclose(dg, dg_ref, rtol=0, atol=1e-9 * np.abs(dg_ref).max())
    fr._x0.clear()                                   # cold start: the batch declines
    assert batch(np.asarray(lam, float), fr._x0, True) is None
    at._batch = batch
    g_cold, _ = at.values(lam, gradient=True)
    np.testing.assert_allclose(g_cold, g_ref, rtol=1e-9)


def test_section_reaction_maps_closed_form_equals_the_inverse():
    """The closed-form T^-T of section_reaction_maps (det T = cos beta) against the frame of
    cardan_frame and numpy's inverse, at random angles and a random orthonormal basis, for 3
    and 2 angle rows; a complex-step state takes the inverse path."""
    from sim_core.physics.contact.friction import _section_reaction_maps_inv, section_reaction_maps
    rng = np.random.default_rng(7)
    basis, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    for _ in range(20):
        psi = rng.uniform(-1.2, 1.2, size=3)

        def point(Q, psi=psi):
            return None, None, psi, None
        for n in (3, 2):
            Lf, Lm = section_reaction_maps(point, None, basis, n)
            Lf0, Lm0 = _section_reaction_maps_inv(psi, basis, n)
            np.testing.assert_allclose(Lf, Lf0, rtol=0, atol=1e-14)
            np.testing.assert_allclose(Lm, Lm0, rtol=1e-13, atol=1e-13)
    psi_c = psi + 1e-20j

    def point_c(Q):
        return None, None, psi_c, None
    Lf, Lm = section_reaction_maps(point_c, None, basis, 3)
    assert np.iscomplexobj(Lm)


@pytest.mark.parametrize("v", [0.2, 0.004, -0.05])
def test_compiled_multiplier_newton_equals_the_python_loop(systems, v):
    """The friction-multiplier Newton in one compiled call (FrictionAtState.newton,
    micro_motion_compiled.multiplier_newton) against the Python loop of
    Model._multiplier_newton, sliding (|v| > 2 v_eps), in the stick band and backwards: the
    same operations, so the same accelerations and multipliers to round-off (both warm-start
    the micro-motions from the same solutions)."""
    from sim_core.physics.contact import _sliding_block_contact_numba as micro_motion_compiled
    if not micro_motion_compiled.AVAILABLE:
        pytest.skip("numba not installed")
    ts_f, _, z = systems
    m = ts_f.model
    Q, Qd = _sliding_state(ts_f, z, v)
    zd = m.reduced_state(0.0, Q, Qd)[1]
    fr = m.multiplier_forces[0]
    m.accelerations_and_multipliers(0.0, z, zd)          # warm starts at this state
    x0 = {k: x.copy() for k, x in fr._x0.items()}
    g_warm = m._g_warm
    calls = []
    newton = type(m.multiplier_forces[0].at_state(0.0, Q, Qd)).newton

    def counted(self, *a):
        out = newton(self, *a)
        calls.append(out is not None)
        return out
    try:
        type(m.multiplier_forces[0].at_state(0.0, Q, Qd)).newton = counted
        a, lam = m.accelerations_and_multipliers(0.0, z, zd)
        fr._x0.clear()
        fr._x0.update(x0)
        m._g_warm = g_warm                               # and the same multiplier start
        m.multiplier_newton_compiled = False
        a_ref, lam_ref = m.accelerations_and_multipliers(0.0, z, zd)
    finally:
        type(m.multiplier_forces[0].at_state(0.0, Q, Qd)).newton = newton
        m.multiplier_newton_compiled = True
    assert calls == [True]                               # the compiled path was taken
    np.testing.assert_allclose(lam, lam_ref, rtol=0, atol=1e-12 * np.max(np.abs(lam_ref)))
    np.testing.assert_allclose(a, a_ref, rtol=0, atol=1e-12 * np.max(np.abs(a_ref)))


@pytest.mark.parametrize("v", [0.2, 0.004, -0.05])
def test_compiled_resultant_newton_equals_the_python_loop(systems, v):
    """friction_load = "resultant" (the scenes' default): the friction-multiplier Newton in one
    compiled call (micro_motion_compiled.resultant_newton) against the Python loop of
    Model._multiplier_newton from the same warm start, sliding, in the stick band and
    backwards: the same operations, so the same accelerations and multipliers to round-off;
    and its g(lambda), dg/dlambda equal FrictionAtState.values' resultant branch."""
    from sim_core.physics.contact import _sliding_block_contact_numba as micro_motion_compiled
    if not micro_motion_compiled.AVAILABLE:
        pytest.skip("numba not installed")
    _, ts_0, z = systems
    ts = build_telescopic(TelescopicParams(n_nodes=3, E=2.1e12, payload=1000.0, friction=True,
                                           friction_load="resultant"))
    for a, b in zip(ts.model.point_effects, ts_0.model.point_effects):
        if hasattr(a, "L0"):
            a.L0 = b.L0
    m = ts.model
    Q, Qd = _sliding_state(ts, z, v)
    zd = m.reduced_state(0.0, Q, Qd)[1]
    m.accelerations_and_multipliers(0.0, z, zd)
    g_warm = m._g_warm
    at = m.multiplier_forces[0].at_state(0.0, Q, Qd)
    assert at._resultant is not None
    try:
        a, lam = m.accelerations_and_multipliers(0.0, z, zd)
        m._g_warm = g_warm
        m.multiplier_newton_compiled = False
        a_ref, lam_ref = m.accelerations_and_multipliers(0.0, z, zd)
    finally:
        m.multiplier_newton_compiled = True
    np.testing.assert_allclose(lam, lam_ref, rtol=0, atol=1e-12 * np.max(np.abs(lam_ref)))
    np.testing.assert_allclose(a, a_ref, rtol=0, atol=1e-12 * np.max(np.abs(a_ref)))
    g, dg = micro_motion_compiled.resultant_values(lam, *at._resultant)
    g_ref, dg_ref = at.values(lam, gradient=True)
    np.testing.assert_allclose(g, g_ref, rtol=1e-14, atol=0)
    np.testing.assert_allclose(dg, dg_ref, rtol=0, atol=1e-14 * np.max(np.abs(dg_ref)))


@pytest.mark.parametrize("compiled", [True, False])
def test_multiplier_newton_warm_start(systems, compiled):
    """The multiplier Newton warm-started from the last solution (Model.multiplier_warm_start)
    gives the cold start's solution to within its stopping rule (a last step below
    multiplier_tol relative to max |lambda|; the Newton's error after that step is of the order
    of its square, so 10 x multiplier_tol is a safe bound), and at a nearby state (a stage of a
    step: the velocities 1e-3 relative apart) it needs fewer friction evaluations than from 0."""
    ts_f, _, z = systems
    m = ts_f.model
    Q, Qd = _sliding_state(ts_f, z, 0.2)
    zd = m.reduced_state(0.0, Q, Qd)[1]
    calls = []
    cls = type(m.multiplier_forces[0].at_state(0.0, Q, Qd))
    values = cls.values

    def counted(self, *a, **k):
        calls.append(1)
        return values(self, *a, **k)
    m.multiplier_newton_compiled = compiled
    try:
        cls.values = counted
        m.accelerations_and_multipliers(0.0, z, zd)           # the warm start at this state
        zd2 = zd * (1 + 1e-3)
        m.multiplier_warm_start = False
        calls.clear()
        a0, lam0 = m.accelerations_and_multipliers(0.0, z, zd2)
        n_cold = len(calls)
        m.accelerations_and_multipliers(0.0, z, zd)
        m.multiplier_warm_start = True
        calls.clear()
        a1, lam1 = m.accelerations_and_multipliers(0.0, z, zd2)
        n_warm = len(calls)
    finally:
        cls.values = values
        m.multiplier_newton_compiled = True
        m.multiplier_warm_start = True
    scale = np.max(np.abs(lam0))
    np.testing.assert_allclose(lam1, lam0, rtol=0, atol=10 * m.multiplier_tol * scale)
    if not compiled:            # the compiled loop evaluates the forces inside one call
        assert n_warm < n_cold, (n_warm, n_cold)
