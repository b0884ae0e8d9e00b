"""Stroke friction of the v1 plant (sim_core.systems.telescopic.modal_batch, Stroke friction):
breakaway, slip against an independent integration, the energy balance, stick-slip, and the
normal-load tables against the full model."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from sim_core.systems.telescopic import friction_table
from sim_core.vector_rom import VectorROM

M, ANG, ELL = 25000.0, 60.0, 5.0


def _rom(dt, L0=2.0, **kw):
    rom = VectorROM(1, dt=dt, friction=True, **kw)
    rom.configure(M, ANG, ELL)
    rom.reset(L0)
    return rom


def _hydraulics(rom, L):
    f = rom.friction
    kh = f["kA"] / (L + f["l0"])
    Ms = rom._b.Ms[0]
    return kh, 2 * f["zeta_h"] * np.sqrt(kh * Ms), Ms


def test_breakaway_when_the_oil_column_force_reaches_mu_s_N():
    """Piston accelerating at a from rest: the stage stays exactly where it is while
    F_h(t) = k_h a t^2 / 2 + c_h a t < mu_s N and leaves when it reaches it (the root of the
    quadratic; the step size does not matter: the events are exact)."""
    a, L0 = 0.05, 2.0
    for dt in (0.05, 0.013):
        rom = _rom(dt, L0)
        N = rom.normal_load()[0]
        kh, ch, _ = _hydraulics(rom, L0)
        lim = rom.friction["mu_static"] * N
        tb = (-ch * a + np.sqrt((ch * a) ** 2 + 2 * kh * a * lim)) / (kh * a)
        t = 0.0
        while t + dt < tb - 1e-9:
            rom.step(np.array([a]))
            t += dt
            assert rom.stroke[0] == L0 and rom.stroke_rate[0] == 0.0 and rom.stuck[0]
            assert rom.piston_stroke[0] == pytest.approx(L0 + 0.5 * a * t * t, abs=1e-12)
        rom.step(np.array([a]))
        assert not rom.stuck[0] and rom.stroke_rate[0] > 0.0 and rom.stroke[0] > L0


def test_slip_follows_the_slip_equation_until_the_stage_sticks_again():
    """After the breakaway the stage obeys M_s L'' = k_h (x_c - L) + c_h (x_c' - L')
    - mu_k N sign(L') with k_h, c_h, N functions of L: an independent integration (scipy
    Radau, tight tolerances, N interpolated on the ROM's grid like the kernel) of the first
    slip phase, until L' returns to zero.  The kernel freezes k_h, c_h, N over each piece (one
    1 ms step here): first order in the step, the stroke moves < 0.5 mm per step, k_h and N
    change by < 0.03 % over it, so the histories agree to ~1e-4 of the motion."""
    a, L0, dt = 0.05, 2.0, 0.001
    rom = _rom(dt, L0)
    f = rom.friction
    Ms = rom._b.Ms[0]
    grid, ntab = rom._b.grid, rom._b.ntab[0]
    N0 = rom.normal_load()[0]
    kh0 = f["kA"] / (L0 + f["l0"])
    ch0 = 2 * f["zeta_h"] * np.sqrt(kh0 * Ms)
    lim = f["mu_static"] * N0
    tb = (-ch0 * a + np.sqrt((ch0 * a) ** 2 + 2 * kh0 * a * lim)) / (kh0 * a)

    def piston(t):                                 # +a for 1 s, -a for 1 s, then at rest
        t1, t2 = min(t, 1.0), min(max(t - 1.0, 0.0), 1.0)
        return (L0 + 0.5 * a * t1 * t1 + a * t2 - 0.5 * a * t2 * t2, a * t1 - a * t2)

    def rhs(t, y):
        kh = f["kA"] / (y[0] + f["l0"])
        ch = 2 * f["zeta_h"] * np.sqrt(kh * Ms)
        N = np.interp(y[0], grid, ntab)
        xc, vc = piston(t)
        return [y[1], (kh * (xc - y[0]) + ch * (vc - y[1]) - f["mu_dynamic"] * N) / Ms]

    def stopped(t, y):
        return y[1] if t > tb + 1e-6 else 1.0
    stopped.terminal = True
    ref = solve_ivp(rhs, (tb, tb + 5.0), [L0, 0.0], method="Radau", rtol=1e-11, atol=1e-13,
                    dense_output=True, events=stopped, max_step=0.01, first_step=1e-4)
    t_stick = ref.t[-1]
    assert t_stick < tb + 5.0                      # the stage does stick again
    t, worst, span = 0.0, 0.0, 0.0
    stuck_at = None
    for k in range(int((t_stick + 0.2) / dt)):
        rom.step(np.array([a if k < 1000 else (-a if k < 2000 else 0.0)]))
        t += dt
        if tb + dt < t < t_stick - dt:
            y = ref.sol(t)
            worst = max(worst, abs(rom.stroke[0] - y[0]))
            span = max(span, abs(y[0] - L0))
            assert not rom.stuck[0]
        if stuck_at is None and t > tb + dt and rom.stuck[0]:
            stuck_at = t
    print(f"slip phase {tb:.3f}..{t_stick:.3f} s, stroke {span * 1e3:.2f} mm, max diff "
          f"{worst * 1e6:.3f} um")
    assert worst < 1e-4 * span
    assert stuck_at == pytest.approx(t_stick, abs=dt)


def test_friction_work_balances_the_energy_of_the_stage():
    """Energy of the stage: the oil column's work on it equals its kinetic energy change plus
    the friction work mu_k N |dL| summed by the kernel over the slip pieces (exact), for a
    start, a stick-slip phase at low piston speed and a stop; the oil column's work int F_h L'
    dt by the trapezoidal rule on 1 ms steps (error O(dt^2) ~ 1e-5 relative)."""
    dt = 0.001
    rom = _rom(dt, 2.0)
    f = rom.friction
    Ms = rom._b.Ms[0]
    W_h, t = 0.0, 0.0

    def force():
        L = rom.stroke[0]
        kh = f["kA"] / (L + f["l0"])
        ch = 2 * f["zeta_h"] * np.sqrt(kh * Ms)
        return kh * (rom.piston_stroke[0] - L) + ch * (rom.piston_rate[0] - rom.stroke_rate[0])
    F0, v0 = force(), rom.stroke_rate[0]
    n_stick = 0
    for k in range(6000):
        a = 0.02 if k < 500 else (0.0 if k < 4000 else -0.02)
        rom.step(np.array([a]))
        F1, v1 = force(), rom.stroke_rate[0]
        W_h += 0.5 * (F0 * v0 + F1 * v1) * dt
        F0, v0 = F1, v1
        n_stick += int(rom.stuck[0])
    KE = 0.5 * Ms * rom.stroke_rate[0] ** 2
    Wf = rom.friction_work[0]
    print(f"oil column work {W_h:.1f} J, friction work {Wf:.1f} J, KE {KE:.1f} J")
    assert Wf > 0 and n_stick > 100
    assert W_h == pytest.approx(Wf + KE, rel=1e-4)


def test_stick_slip_at_low_piston_speed():
    """A piston creeping at 5 mm/s: the stages alternate between sticking (rate exactly zero)
    and slipping (the classic stick-slip of a compliant drive with mu_s > mu_k) and keep up
    with the piston on average."""
    dt = 0.002
    rom = _rom(dt, 3.0)
    v_c = 0.005
    ramp = int(round(v_c / 0.05 / dt))
    stuck, rates = [], []
    for k in range(10000):
        rom.step(np.array([0.05 if k < ramp else 0.0]))
        stuck.append(rom.stuck[0])
        rates.append(rom.stroke_rate[0])
    stuck = np.array(stuck[ramp:])
    rates = np.array(rates[ramp:])
    switches = np.count_nonzero(np.diff(stuck.astype(int)) != 0)
    assert switches >= 6                                  # several stick-slip cycles
    assert np.all(rates[stuck] == 0.0)
    assert np.max(rates) > 2 * v_c                        # slips overshoot the piston speed
    lag = rom.piston_stroke[0] - rom.stroke[0]
    kh, _, _ = _hydraulics(rom, rom.stroke[0])
    assert abs(lag) <= rom.friction["mu_static"] * rom.normal_load()[0] / kh * 1.05


def test_normal_load_tables_reproduce_the_full_model():
    """One entry of the shipped table rebuilt from the full model's static equilibrium (the
    build's own function at one stroke) equals the file's (the data are reproducible)."""
    from dataclasses import replace

    from sim_core.systems.telescopic import modal
    r = friction_table.load(3)
    ia = int(np.flatnonzero(np.isclose(r["angles"], 60.0))[0])
    ip = int(np.flatnonzero(np.isclose(r["payloads"], 25000.0))[0])
    j = int(np.argmin(np.abs(r["L_grid"] - modal.STROKE_REF)))
    base = modal.table_params(3)
    p = replace(base, payload=25000.0, luffing_angle_deg=60.0, n_nodes=modal.N_NODES,
                friction=False, contact_distribution=False, friction_load="resultant")
    rope_L0 = modal.reference_rope_lengths(p, modal.STROKE_REF)
    ts, z, lam = modal.equilibrium_at(p, r["L_grid"][j], rope_L0)
    loads = friction_table.region_loads(ts, z, lam)
    assert np.allclose(loads, r["N_regions"][ia, ip, j], rtol=1e-6)
    # order of magnitude: the overlaps carry the boom-normal weight of booms 2..N and payload
    # (m g cos(theta) = 123 kN for 25 t at 60 deg) several times over (lever arms of the
    # overlaps), never less than it
    assert r["N_total"][ia, ip, j] > 25000.0 * 9.81 * np.cos(np.radians(60.0))
    assert friction_table.stroke_mass(r["boom_masses"], 25000.0) == pytest.approx(114.6e3,
                                                                                  rel=1e-3)


# -- the full model's regularised law (friction_law="regularised") ----------------------------

def test_regularised_law_against_an_independent_integration():
    """friction_law="regularised": M_s L'' = k_h (x_c - L) + c_h (x_c' - L') - N mu(L'), mu the
    full model's law (FrictionLaw: the damper mu_s v / v_eps, the cubic blend, mu_k): scipy
    Radau at tight tolerances (N interpolated on the ROM's grid like the kernel) against the
    kernel's trapezoidal steps (5 ms) on a piston history that crosses the stick band many
    times (slow pushes, faster strokes, stops).  The kernel freezes k_h, c_h, N over a step and
    its law has a kink at v_eps: the step study in the next test gives errors ~1e-5 m, so the
    strokes agree to 1e-4 m."""
    from sim_core.physics.contact.sliding_block_contact import FrictionLaw
    dt = 0.05
    rom = _rom(dt, 3.0, friction_law="regularised")
    f = rom.friction
    law = FrictionLaw(f["mu_static"], f["mu_dynamic"], f["v_eps"])
    Ms = rom._b.Ms[0]
    grid, ntab = rom._b.grid, rom._b.ntab[0]
    # 10 s: pairs of 0.5 s pushes +a, -a (the piston at rest after each pair, at most 0.125 m/s,
    # within 0.6 m of its start), every third pair slow (peak 6 mm/s, inside the band)
    a_pair = np.random.default_rng(3).uniform(-0.25, 0.25, 10)
    a_pair[::3] *= 0.05
    acc = np.concatenate([np.repeat([a, -a], 10) for a in a_pair])
    x, v = 3.0, 0.0
    ys = [np.array([3.0, 0.0])]
    for a in acc:                          # the piston's exact kinematics (no limits reached)
        def rhs(t, y, a=a, x=x, v=v):
            kh = f["kA"] / (y[0] + f["l0"])
            ch = 2 * f["zeta_h"] * np.sqrt(kh * Ms)
            xc, vc = x + v * t + 0.5 * a * t * t, v + a * t
            N = np.interp(y[0], grid, ntab)
            return [y[1], (kh * (xc - y[0]) + ch * (vc - y[1]) - N * law.mu(float(y[1]))) / Ms]
        sol = solve_ivp(rhs, (0.0, dt), ys[-1], method="Radau", rtol=1e-11, atol=1e-13)
        ys.append(sol.y[:, -1])
        x, v = x + v * dt + 0.5 * a * dt * dt, v + a * dt
    L = [rom.stroke[0]]
    for a in acc:
        rom.step(np.array([a]))
        L.append(rom.stroke[0])
    ref = np.array(ys)
    assert np.max(np.abs(rom.piston_stroke[0] - x)) < 1e-12
    assert np.any(np.abs(ref[:, 1]) < f["v_eps"]) and np.any(np.abs(ref[:, 1]) > 2 * f["v_eps"])
    worst = np.max(np.abs(np.array(L) - ref[:, 0]))
    print(f"stroke {np.ptp(ref[:, 0]):.3f} m, max diff {worst * 1e6:.2f} um")
    assert worst < 1e-4


def test_regularised_step_converges():
    """The trapezoidal step of the regularised law (modal_batch.CREEP_STEP, 5 ms) on 30 s of a
    piston history through the stick band with the payload swinging: against 1/16 of the step,
    its stroke and tip-deflection errors fall with the step (at least 1.8 times per halving:
    between first order, at the law's kink at v_eps, and second) and at 5 ms they are below a
    tenth of the success tolerances (stroke 5 mm, deflection 1 cm)."""
    from sim_core.systems.telescopic import modal_batch as mb
    acc = np.random.default_rng(3).uniform(-0.25, 0.25, 30)
    acc[::3] *= 0.05
    h0 = mb.CREEP_STEP

    def run(h, monkey):
        monkey.setattr(mb, "CREEP_STEP", h)
        rom = _rom(0.05, 4.0, friction_law="regularised")
        L, d = [], []
        for k in range(600):
            d.append(rom._b.step_outputs(np.array([acc[k // 20]]))[3][0, :2].copy())
            L.append(rom.stroke[0])
        return np.array(L), np.array(d)

    with pytest.MonkeyPatch.context() as mp:
        ref = run(h0 / 16, mp)
        err = []
        for h in (h0, h0 / 2, h0 / 4):
            L, d = run(h, mp)
            err.append((np.max(np.abs(L - ref[0])), np.max(np.abs(d - ref[1]))))
    err = np.array(err)
    print("errors (stroke, deflection) at h, h/2, h/4:", err.tolist())
    assert np.all(err[:-1] > 1.8 * err[1:])
    assert err[0, 0] < 5e-4 and err[0, 1] < 1e-3


def test_regularised_law_creeps_where_coulomb_sticks():
    """A piston at 2 mm/s, a fifth of v_eps: with the regularised law the stages never stand
    still; they follow at the piston's rate behind the lag (v_p / v_eps) mu_s N / k_h (the
    column force k_h e balancing the damper mu_s N v_p / v_eps), approached on the time scale
    (mu_s N / v_eps) / k_h < 1 s, so after 6 s to the trapezoidal step's error (~1e-5
    relative) and the approach's remainder e^-6: 0.5 %.  The Coulomb law holds them still
    until the piston leads by mu_s N / k_h."""
    v_p, T = 0.002, 6.0
    runs = {}
    for law in ("coulomb", "regularised"):
        rom = _rom(0.05, 2.0, friction_law=law)
        rom.step(np.array([v_p / 0.05]))
        rates = []
        for _ in range(int(T / 0.05)):
            rom.step(np.array([0.0]))
            rates.append(rom.stroke_rate[0])
        runs[law] = (rom, np.array(rates))
    rom, rates = runs["regularised"]
    L = rom.stroke[0]
    kh, _, _ = _hydraulics(rom, L)
    f = rom.friction
    e_creep = (v_p / f["v_eps"]) * f["mu_static"] * rom.normal_load()[0] / kh
    assert np.all(rates > 0.0) and rom.stuck[0]          # in the band, never held
    assert rates[-1] == pytest.approx(v_p, rel=0.005)
    assert rom.piston_stroke[0] - L == pytest.approx(e_creep, rel=0.005)
    rom_c, rates_c = runs["coulomb"]
    assert np.all(rates_c[:60] == 0.0)                   # held for the first 3 s


def test_compiled_law_is_the_full_models_law():
    """The kernel's mu(v) and d mu / dv are FrictionLaw's (the full model's reference) on both
    sides of the stick band, through the blend and beyond, to round-off (away from the kink
    |v| = v_eps, where the reference's slope is one-sided from above)."""
    from sim_core.physics.contact.sliding_block_contact import FrictionLaw
    from sim_core.systems.telescopic import _modal_batch_numba as kernel
    law = FrictionLaw(0.15, 0.1, 0.01)
    v = np.concatenate([np.linspace(-0.05, 0.05, 1001), [0.0, 0.0099, -0.0101, 0.03]])
    v = v[np.abs(np.abs(v) - law.v_eps) > 1e-12]
    got = np.array([kernel._mu_regularised(float(x), 0.15, 0.1, 0.01) for x in v])
    assert np.allclose(got[:, 0], law.mu(v), rtol=1e-14, atol=1e-16)
    assert np.allclose(got[:, 1], law.dmu_dv(v), rtol=1e-12, atol=1e-12)


def test_regularised_law_takes_the_full_models_coefficients():
    """The ROM's v_eps default is the paper scene's (the full model's law), as are mu_s, mu_k."""
    from sim_core import load_scene
    from sim_core.systems.telescopic import modal_batch as mb
    c = load_scene("telescopic_extraction")["contact"]
    rom = _rom(0.05, friction_law="regularised")
    assert (rom.friction["v_eps"], rom.friction["mu_static"], rom.friction["mu_dynamic"]) \
        == (mb.V_EPS, c["mu_static"], c["mu_dynamic"]) and mb.V_EPS == c["v_eps"]


def test_friction_law_is_checked():
    with pytest.raises(ValueError, match="friction_law"):
        VectorROM(1, friction=True, friction_law="viscous")
    with pytest.raises(ValueError, match="v_eps"):
        VectorROM(1, friction=True, friction_law="regularised", v_eps=0.0)
    with pytest.raises(ValueError, match="friction_law"):
        VectorROM(1, friction=False, friction_law=None)
