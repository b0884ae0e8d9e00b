"""The batched modal ROM (sim_core.vector_rom.VectorROM, sim_core.systems.telescopic.modal_batch):
its kernel against the scalar ModalROM of the v0 env, the compiled kernel against its array
reference, and the coupled pendulum tables against their closed form."""

import numpy as np
import pytest

from sim_core.systems.telescopic.modal import tables_for
from sim_core.systems.telescopic.modal_batch import (
    coupled_tables,
    lumped_coefficients,
)
from sim_core.vector_rom import VectorROM


def test_lumped_coefficients_equal_tables_for():
    """The vectorised bilinear interpolation is tables_for's arithmetic for the modal rows
    (same bits).  The tip's stroke derivative tip_dL is the same at the tabulated angles; between
    them tables_for turns it in the boom's frame while the batch interpolates its global
    components, which shortens the turning vector by at most 1 - cos(7.5 deg) (the 15-degree
    grid's half interval): 0.86 % (lumped_coefficients' docstring); the sag's stroke rate in it
    (its transverse part) is interpolated in cos theta there and in theta here, which adds
    a few tenths of a percent at full stroke: 1.5 % of |tip_dL| is allowed."""
    rng = np.random.default_rng(0)
    m = np.r_[20000.0, 30000.0, rng.uniform(20e3, 30e3, 4)]
    a = np.r_[45.0, 75.0, rng.uniform(45, 75, 4)]
    _, coef, tip_dL = lumped_coefficients(m, a, 4)
    for i in range(len(m)):
        tb = tables_for(m[i], a[i], 4)
        assert np.array_equal(coef[i], tb.coef)
        if a[i] in (45.0, 75.0):
            assert np.array_equal(tip_dL[i], tb.tip_dL)
        else:
            scale = np.linalg.norm(tb.tip_dL, axis=1)
            gap = np.linalg.norm(tip_dL[i] - tb.tip_dL, axis=1)
            assert np.all(gap <= 0.015 * scale)


def _v0_envs(payloads, angles, **kw):
    import gymnasium as gym

    import boom_env  # noqa: F401
    envs = []
    for m, a in zip(payloads, angles):
        e = gym.make("boom_env/TelescopicExtraction-v0", **kw).unwrapped
        e.reset(options={"payload": m, "luffing_angle_deg": a})
        envs.append(e)
    return envs


@pytest.mark.parametrize("use_compiled", [True, False])
def test_without_sway_the_batch_is_the_v0_plant(use_compiled):
    """payload_swing=False: N cranes of different payloads and angles stepped by one call give
    the v0 env's deflections (ModalROM and its stroke kinematics, one crane at a time) to
    round-off, through velocity saturation and both end stops (bang-bang actions long enough
    to reach v_max and each end)."""
    n = 4
    rng = np.random.default_rng(1)
    m = rng.uniform(20e3, 30e3, n)
    ang = rng.uniform(45, 75, n)
    envs = _v0_envs(m, ang)
    rom = VectorROM(n, payload_swing=False, use_compiled=use_compiled)
    rom.configure(m, ang)
    rom.reset(2.0)
    sat_seen = stop_seen = 0
    worst = 0.0
    for k in range(400):
        a = rng.uniform(-1, 1, n)
        a[0] = 1.0 if (k // 120) % 2 == 0 else -1.0            # to the end stops and back
        a[1] = 1.0 if k < 60 else -0.3
        sat, stop, _ = rom.step(np.clip(a, -1, 1) * 0.25)
        d = rom.tip_deflection()
        sat_seen += sat.sum()
        stop_seen += stop.sum()
        for i, e in enumerate(envs):
            e.step(np.array([a[i]]))
            ref = e._defl
            worst = max(worst, np.max(np.abs(d[i] - ref)) / max(np.max(np.abs(ref)), 1e-9))
            assert rom.stroke[i] == pytest.approx(e.rom.L, abs=1e-12)
            assert rom.stroke_rate[i] == pytest.approx(e.rom.v, abs=1e-12)
    assert sat_seen > 0 and stop_seen > 0
    assert worst < 1e-9


def test_compiled_kernel_equals_array_reference():
    """Tables, steps and outputs of the compiled kernels and the array code (payload sway on,
    per-crane payload, angle and rope; end stops reached)."""
    n = 6
    rng = np.random.default_rng(2)
    cfg = (rng.uniform(20e3, 30e3, n), rng.uniform(45, 75, n), rng.uniform(1, 10, n))
    r1, r2 = VectorROM(n), VectorROM(n, use_compiled=False)
    if not r1._b.compiled:
        pytest.skip("numba not available: only the array reference runs")
    r1.configure(*cfg)
    r2.configure(*cfg)
    assert np.allclose(r1._b.dyn, r2._b.dyn, rtol=1e-12, atol=1e-10)
    assert np.allclose(r1._b.out, r2._b.out, rtol=1e-12, atol=1e-14)
    r1.reset(2.0, sway=(0.01, -0.02))
    r2.reset(2.0, sway=(0.01, -0.02))
    for k in range(300):
        a = rng.uniform(-0.25, 0.25, n)
        a[0] = 0.25 if k < 200 else -0.25
        f1, f2 = r1.step(a), r2.step(a)
        assert np.array_equal(f1[0], f2[0]) and np.array_equal(f1[1], f2[1])
        for x, y in zip(r1.outputs(), r2.outputs()):
            assert np.allclose(x, y, rtol=1e-9, atol=1e-12 * np.max(np.abs(y)))
    assert np.allclose(r1.stroke, r2.stroke, rtol=0, atol=1e-12)


def test_one_lumped_mode_and_pendulum_solve_the_two_dof_secular_equation():
    """n_modes = 1: the coupled tables hold the two roots lambda of
    det(K - lambda M) = (omega^2 - lambda)(m g l - lambda m l^2) - lambda^2 (m l phi_x)^2 = 0
    (modal_batch module docstring), the mode of M_c-norm 1."""
    m, ang, ell = 25000.0, 60.0, 5.0
    L, coef, tip_dL = lumped_coefficients([m], [ang], 1)
    Lr, dyn, out = coupled_tables(coef, tip_dL, L, [m], [ell], refine=1)
    for j in range(len(L)):
        w, px = coef[0, j, 0, 0], coef[0, j, 6, 0]
        b = m * ell * px
        # (w^2 - x)(k - x c) - x^2 b^2 = 0 with k = m g l, c = m l^2
        k, c = m * 9.81 * ell, m * ell ** 2
        roots = np.sort(np.roots([c - b * b, -(k + w * w * c), w * w * k]).real)
        assert np.allclose(np.sort(dyn[0, j, 0, :2] ** 2), roots, rtol=1e-10)
        assert dyn[0, j, 0, 2] == pytest.approx(np.sqrt(9.81 / ell))
    # l -> 0: the pendulum leaves the bending mode at its lumped frequency
    _, dyn0, _ = coupled_tables(coef, tip_dL, L, [m], [1e-4], refine=1)
    assert np.allclose(dyn0[0, :, 0, 0], coef[0, :, 0, 0], rtol=1e-3)


def test_start_sway_is_a_free_pendulum_of_the_right_frequency():
    """reset(sway=...): with the stroke held, the out-of-plane angle swings at sqrt(g / l)
    exactly (its own undamped mode); the in-plane one, released with the booms undeformed,
    swings at the coupled pendulum frequency of the tables: zero crossings once the bending
    part has decayed (released with the booms undeformed, the first bending mode carries 1.4e-3
    rad of the 0.02; at zeta omega = 0.14 1/s it is 2.5e-5 rad after 30 s, which shifts a
    crossing by 2.5e-5 / (0.0183 omega_p) = 1 ms of a 4.2 s period)."""
    ell, L = 4.0, 5.0
    rom = VectorROM(1, dt=0.01)
    rom.configure(25000.0, 60.0, ell)
    rom.reset(L, sway=(0.02, 0.03))
    s0 = rom.sway()[0]
    assert s0[0] == pytest.approx(0.02, rel=1e-9) and s0[1] == pytest.approx(0.03, rel=1e-12)
    assert np.allclose(s0[2:], 0.0, atol=1e-15)
    assert np.allclose(rom.tip_deflection()[0, :2], 0.0, atol=1e-15)
    t, th, ps = [0.0], [0.02], [0.03]
    for k in range(4500):
        rom.step(np.zeros(1))
        s = rom.sway()[0]
        t.append(0.01 * (k + 1))
        th.append(s[0])
        ps.append(s[1])
    t, th, ps = np.array(t), np.array(th), np.array(ps)
    assert np.allclose(ps, 0.03 * np.cos(np.sqrt(9.81 / ell) * t), atol=1e-12)
    late = t > 30.0
    tt, x = t[late], th[late]
    z = np.flatnonzero(np.sign(x[1:]) != np.sign(x[:-1]))
    tz = tt[z] - x[z] * (tt[z + 1] - tt[z]) / (x[z + 1] - x[z])
    period = 2.0 * np.mean(np.diff(tz))
    b = rom._b
    j = int(np.argmin(np.abs(b.grid - L)))
    assert b.grid[j] == pytest.approx(L)
    w_p = b.dyn[0, j, 0, 0]                        # lowest coupled mode: the pendulum
    assert w_p < np.sqrt(9.81 / ell) and w_p > 0.9 * np.sqrt(9.81 / ell)
    # linear interpolation of the crossing times: error ~ (omega dt)^2 / 12 relative
    assert period == pytest.approx(2 * np.pi / w_p, rel=1e-3)


@pytest.mark.parametrize("booms", [3, 5])
def test_one_call_table_formation_is_the_array_formation(booms):
    """coupled_tables_of and normal_loads_refined (one compiled call per reset) form the same
    lumped coefficients, tip-slope gradient, refinement and normal loads as the array functions
    (lumped_coefficients, numpy.gradient, refine_grid, normal_loads): the same operations in the
    same order, so the tables agree to the last bit (table corners and interior points)."""
    from sim_core.systems.telescopic import modal_batch as mb
    from sim_core.systems.telescopic.modal import allowed_ranges
    if not mb.compiled.AVAILABLE:
        pytest.skip("numba not available: only the array path runs")
    (p_lo, p_hi), (a_lo, a_hi), _ = allowed_ranges(n_booms=booms)
    rng = np.random.default_rng(7)
    m = np.concatenate([[p_lo, p_hi, p_lo], rng.uniform(p_lo, p_hi, 20)])
    ang = np.concatenate([[a_lo, a_hi, a_hi], rng.uniform(a_lo, a_hi, 20)])
    ell = rng.uniform(1.0, 10.0, m.size)
    for n_modes, refine in ((3, 4), (1, 1), (4, 3)):
        L, coef, tip = lumped_coefficients(m, ang, n_modes, booms)
        ref = coupled_tables(coef, tip, L, m, ell, mb.GRAVITY, refine, True)
        got = mb.coupled_tables_of(m, ang, ell, n_modes, booms, mb.GRAVITY, refine)
        for x, y in zip(ref, got):
            assert np.array_equal(x, y)
        Lf, nl = mb.normal_loads(m, ang, booms)
        for x, y in zip(mb.refine_grid(Lf, nl, refine), mb.normal_loads_refined(m, ang, booms,
                                                                                refine)):
            assert np.array_equal(x, y)


@pytest.mark.parametrize("friction", [False, True])
def test_fused_step_and_outputs_equal_the_two_calls(friction):
    """VectorROM.step_outputs (one compiled pass) gives what step followed by outputs gives,
    bit for bit, with a start sway on some cranes (every mode moving) and none on the others;
    without a start sway the out-of-plane pendulum stays exactly at rest (it is decoupled and
    unforced: modal_batch module docstring)."""
    n = 8
    rng = np.random.default_rng(3)
    cfg = (rng.uniform(20e3, 30e3, n), rng.uniform(45, 75, n), rng.uniform(1, 10, n))
    r1, r2 = VectorROM(n, friction=friction), VectorROM(n, friction=friction)
    for r in (r1, r2):
        r.configure(*cfg)
        r.reset(2.0)
        r.reset(2.0, envs=[0, 1], sway=(0.02, -0.03))
    for k in range(400):
        a = rng.uniform(-0.25, 0.25, n)
        a[2] = 0.25 if k < 300 else -0.25                 # rate limit and end stop reached
        got = r1.step_outputs(a)
        ref = r2.step(a) + r2.outputs()
        for x, y in zip(got, ref):
            assert np.array_equal(x, y)
        assert np.all(got[4][2:, 1] == 0.0) and np.all(got[4][2:, 3] == 0.0)
    assert np.all(np.abs(r1.sway()[:2, 1]) > 0.0)
    assert np.array_equal(r1.q, r2.q) and np.array_equal(r1.qd, r2.qd)
