"""Your own operation: drive profiles for every actuator, luffing while telescoping and a payload
that swings on its hoist rope, against hand calculations."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sim_core import SceneError, load_scene, simulate
from sim_core.integrate.driver import integrate
from sim_core.physics.drive_profiles import CubicSmoothstepSchedule, TableProfile, TrapezoidProfile
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.luffing import cylinder_length
from sim_core.systems.telescopic.params import LuffingSpec
from sim_core.systems.telescopic.schema import params_from_scene
from sim_core.validation.closed_form import rigid_luffing_force


HOLD = {"drive.profile": "table", "drive.table": [[0.0, 2.0], [1.0, 2.0]]}   # stages held


# -- profiles --------------------------------------------------------------------------------

@pytest.mark.parametrize("j_max", [None, 0.5])
def test_trapezoid_profile_limits_and_travel(j_max):
    """The trapezoid moves exactly its travel, never exceeds v_max and a_max (nor j_max), and
    its rate and acceleration are the derivatives of its stroke (central differences at
    h = 1e-4 s: error O(h^2 j) below 1e-7 where the acceleration is continuous; within h of a
    jump of the unlimited-jerk profile's acceleration the error is at most a_max h / 2)."""
    p = TrapezoidProfile(travel=6.0, v_max=0.5, a_max=0.2, j_max=j_max, s0=2.0, t_start=1.0)
    t = np.linspace(0.0, p.t_end + 1.0, 40001)
    smp = p.sample(t)
    assert smp.s[-1] == pytest.approx(8.0, abs=1e-12) and smp.s[0] == 2.0
    assert np.max(np.abs(smp.v)) <= 0.5 * (1 + 1e-12)
    assert np.max(np.abs(smp.a)) <= 0.2 * (1 + 1e-12)
    if j_max is not None:
        assert np.max(np.abs(smp.j)) <= j_max * (1 + 1e-12)
    h = 1e-4
    tc = t[(t > 0.5) & (t < p.t_end + 0.5)]
    v_fd = (p.stroke(tc + h) - p.stroke(tc - h)) / (2 * h)
    assert np.max(np.abs(v_fd - p.rate(tc))) < (1e-7 if j_max else 0.2 * h / 2)
    if j_max is not None:                     # a is continuous: its derivative check too
        a_fd = (p.rate(tc + h) - p.rate(tc - h)) / (2 * h)
        assert np.max(np.abs(a_fd - p.accel(tc))) < j_max * h / 2   # at the jerk's jumps


def test_short_trapezoid_is_triangular():
    """A travel too short to reach v_max: the peak rate is sqrt(travel a_max) (triangle)."""
    p = TrapezoidProfile(travel=0.1, v_max=0.5, a_max=0.2)
    assert p.v_peak == pytest.approx(math.sqrt(0.1 * 0.2), rel=1e-12)
    assert p.stroke(p.t_end) == pytest.approx(0.1, abs=1e-14)


def test_table_profile_is_c1_with_exact_extremes():
    """The table's interpolant passes through the samples, its rate is continuous at every
    sample (one-sided differences agree to O(h)), it holds before and after the table, and
    its reported largest |v| and |a| equal those of a dense sampling (to the sampling's
    resolution)."""
    t = np.array([0.0, 1.0, 2.5, 4.0, 6.0, 7.0])
    s = np.array([2.0, 2.1, 3.0, 4.2, 4.9, 5.0])
    p = TableProfile(t, s)
    np.testing.assert_allclose(p.stroke(t), s, rtol=0, atol=1e-14)
    h = 1e-7
    left, right = p.rate(t[1:-1] - h), p.rate(t[1:-1] + h)
    np.testing.assert_allclose(left, right, atol=1e-5)
    assert p.rate(-1.0) == 0.0 and p.stroke(10.0) == 5.0 and p.rate(7.0 - 1e-9) == \
        pytest.approx(0.0, abs=1e-6)
    tt = np.linspace(0, 7, 700001)
    assert p.max_rate == pytest.approx(np.max(np.abs(p.rate(tt))), rel=1e-6)
    assert p.max_accel == pytest.approx(np.max(np.abs(p.accel(tt))), rel=1e-4)


def test_cylinder_length_derivatives_match_differences():
    """dL/dtheta of the luffing cylinder (luffing.cylinder_length) against the central
    difference of L, and d2L/dtheta2 against the central difference of the analytic dL/dtheta
    (step 1e-5 rad: truncation O(h^2) ~ 1e-10, round-off eps L / h ~ 2e-10 relative)."""
    pts = LuffingSpec().points()
    for th in (0.2, 0.7, 1.2):
        _, d1, d2 = cylinder_length(th, *pts)
        h = 1e-5
        Lp, Lm = cylinder_length(th + h, *pts)[0], cylinder_length(th - h, *pts)[0]
        assert d1 == pytest.approx((Lp - Lm) / (2 * h), rel=1e-7)
        d1p, d1m = cylinder_length(th + h, *pts)[1], cylinder_length(th - h, *pts)[1]
        assert d2 == pytest.approx((d1p - d1m) / (2 * h), rel=1e-7)


# -- drive profiles in scenes ----------------------------------------------------------------

def test_table_profile_reproduces_the_cubic_run():
    """A [drive] table sampled from the cubic schedule every 0.25 s reproduces the cubic run.
    The stroke differs by the interpolation error e = max |s_table - s_cubic| (8.7e-5 m: the
    monotone Hermite interpolant's O(h^3) error); the tip by the rigid kinematics' 2 e (boom 3
    moves twice the stroke) plus the booms' elastic response to the interpolant's acceleration
    error.  Convergence study (dt = 1, 0.5, 0.25 s: tip difference / e = 2.0, 5.8, 5.1): the
    tip stays within 8 e."""
    c = CubicSmoothstepSchedule(v_max=0.5, t_ramp=4.0, t_hold_end=12.0, s0=2.0)
    tt = np.arange(0.0, 16.0 + 1e-9, 0.25)
    table = [[float(a), float(b)] for a, b in zip(tt, c.stroke(tt))]
    base = {"booms.n_nodes": 3, "effects.friction": False, "effects.contact_distribution": False,
            "solver.t_end": 4.0, "solver.n_output": 41}
    r_cubic = simulate(load_scene("telescopic_extraction", overrides=base))
    r_table = simulate(load_scene("telescopic_extraction",
                                  overrides={**base, "drive.profile": "table", "drive.table": table}))
    t = np.linspace(0.0, 4.0, 4001)
    e = float(np.max(np.abs(TableProfile(tt, c.stroke(tt)).stroke(t) - c.stroke(t))))
    ds = np.max(np.abs(r_cubic["piston_stroke"] - r_table["piston_stroke"]))
    dtip = np.max(np.linalg.norm(r_cubic["tip_position"] - r_table["tip_position"], axis=1))
    assert ds <= e + 1e-6                      # the prescribed stroke, to the constraint's drift
    assert dtip <= 8 * e


def test_drive_table_from_csv_relative_to_the_scene(tmp_path):
    """A CSV stroke history next to the scene file replays: the run's piston stroke follows
    the table (to the constraint's drift), and the table's first row sets booms.stroke0."""
    (tmp_path / "stroke.csv").write_text("time_s,stroke_m\n0,2.5\n1,2.6\n2,2.9\n3,3.0\n")
    scene = (Path(__file__).parents[2] / "sim_core/scenes/telescopic_extraction.toml").read_text()
    scene = scene.replace('direction = "extraction"',
                          'direction = "extraction"\nprofile = "table"\ntable_file = "stroke.csv"')
    scene = scene.replace("stroke0 = 2.0\n", "")
    (tmp_path / "replay.toml").write_text(scene)
    sc = load_scene(str(tmp_path / "replay.toml"),
                    overrides={"booms.n_nodes": 3, "effects.friction": False,
                               "effects.contact_distribution": False, "solver.t_end": 3.0,
                               "solver.n_output": 7})
    assert sc["booms"]["stroke0"] == 2.5
    res = simulate(sc)
    prof = params_from_scene(sc).drive_profile
    np.testing.assert_allclose(res["piston_stroke"] + 2.5, prof.stroke(res.t), atol=1e-6)


@pytest.mark.parametrize("overrides, words", [
    ({"luffing_drive.profile": "cubic", "luffing_drive.travel": 20.0,
      "luffing_drive.t_hold_end": 4.0, "luffing_drive.max_rate": 2.0},
     ["luffing_drive", "luffing cylinder", "rate of 5 deg/s", "t = ", "max_rate = 2"]),
    ({"drive.profile": "trapezoid", "drive.travel": 6.0, "drive.a_max": 0.3,
      "drive.max_accel": 0.2}, ["drive", "telescopic cylinder", "0.3 m/s^2", "max_accel"]),
    ({"luffing_drive.profile": "cubic", "luffing_drive.travel": 30.0,
      "luffing_drive.t_hold_end": 8.0}, ["luffing_drive", "between 60 and 90 deg", "[0, 85]"]),
    ({"drive.profile": "table", "drive.table": [[0.0, 2.0], [0.0, 3.0]]},
     ["drive.table", "does not increase"]),
    ({"hoist.length": 5.0}, ["effects.payload_swing = false"]),
    ({"drive.profile": "trapezoid", "drive.travel": 6.0}, ["drive.a_max", "missing"]),
])
def test_actuator_errors_name_the_actuator_and_time(overrides, words):
    with pytest.raises(SceneError) as info:
        load_scene("telescopic_extraction", overrides=overrides)
    msg = str(info.value)
    assert all(w in msg for w in words), msg


# -- luffing while telescoping ---------------------------------------------------------------

def test_luffing_cylinder_force_along_a_slow_luffing_motion():
    """The luffing cylinder moves the crane from 40 to 50 deg on the cubic schedule (10 deg,
    2 s ramps, hold to 6 s) with nearly rigid booms (E = 2.1e12 Pa).  While the luffing rate is
    constant (t >= 2.5 s: the ramp's vibration decayed by the stress filter) the angular
    acceleration is zero and the centrifugal forces act through the pivot, so the cylinder
    force is the rigid crane's virtual-work statics at the profile's angle
    (closed_form.rigid_luffing_force) within 1 % (the booms' deflection moves the weights'
    arms by ~0.1 %).  In the ramps the d'Alembert moment of the angular acceleration adds its
    3-4 %: the force is not compared there."""
    sc = load_scene("telescopic_extraction", overrides={
        **HOLD, "booms.n_nodes": 3, "booms.E": 2.1e12, "effects.friction": False,
        "effects.contact_distribution": False, "booms.luffing_angle_deg": 40.0,
        "luffing_drive.profile": "cubic", "luffing_drive.travel": 10.0,
        "luffing_drive.t_ramp": 2.0, "luffing_drive.t_hold_end": 6.0,
        "solver.t_end": 5.5, "solver.n_output": 12})
    p = params_from_scene(sc)
    res = simulate(sc)
    assert not res.suspect
    for tk, F, th in zip(res.t, res["luffing_cylinder_force"], res["luffing_angle"]):
        th_rigid = float(p.luffing_profile.sample(tk).s)
        assert th == pytest.approx(th_rigid, abs=math.radians(0.1))     # the booms' sag
        if tk >= 2.5:
            assert F == pytest.approx(rigid_luffing_force(p, th_rigid, 9.81), rel=1e-2)


# -- the payload on the hoist rope -----------------------------------------------------------

def test_pendulum_period_of_the_payload_on_the_hoist_rope():
    """Payload (25 t) and hook (0.8 t) on a 5 m rope of EA = 2e8 N below the tip of the nearly
    rigid crane (E = 2.1e12 Pa), swinging across the luffing plane at small amplitude (2 cm/s
    start: 1.5e-3 rad).  The rope carries T = (m_p + m_h) g and stretches to
    l = L0 (1 + (m_p + m_h) g / EA); a sideways swing x is pulled back by T x / l, so
    omega^2 = T / ((m_p + m_h) l) = g / l: the period is 2 pi sqrt(l / g) with the hook's mass
    entering through the stretch only (it moves with the payload).  The booms' lateral
    compliance lengthens it by ~0.2 % (the tip moves with the swing).  Tolerance 0.5 %."""
    L0, EA, m_p, m_h = 5.0, 2e8, 25000.0, 800.0
    sc = load_scene("telescopic_extraction", overrides={
        **HOLD, "booms.n_nodes": 3, "booms.E": 2.1e12, "effects.friction": False,
        "effects.contact_distribution": False, "effects.payload_swing": True,
        "hoist.length": L0, "hoist.EA": EA, "hoist.hook_mass": m_h, "payload.mass": m_p})
    ts = build_telescopic(params_from_scene(sc))
    m = ts.model
    z, _ = initial_equilibrium(ts)
    Q, _ = m.full_state(0.0, z, 0 * z)
    ip = int(ts.hoist.bottom.coords(Q)[0])
    l_static = np.linalg.norm(np.real(Q[ip:ip + 3] - ts.tip(Q)[0]))
    assert l_static == pytest.approx(L0 * (1 + (m_p + m_h) * 9.81 / EA), rel=1e-6)
    Qd = np.zeros(m.n_coords)
    Qd[ip + 1] = 0.02                                       # across the luffing plane
    z, zd = m.reduced_state(0.0, Q, Qd)
    T_ref = 2 * math.pi * math.sqrt(l_static / 9.81)
    t, ys, _ = integrate(m, np.concatenate([z, zd]), 1.15 * T_ref,
                         {"rtol": 1e-8, "atol": 1e-10, "n_output": 600, "method": "auto"})
    n = m.n_dof
    y = np.array([np.real(m.full_state(tk, yk[:n], yk[n:])[0][ip + 1]
                          - ts.tip(m.full_state(tk, yk[:n], yk[n:])[0])[0][1])
                  for tk, yk in zip(t, ys)])
    k = np.nonzero((y[1:-1] > 0) != (y[2:] > 0))[0] + 1
    crossings = [t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i]) for i in k]
    assert crossings[1] == pytest.approx(T_ref, rel=5e-3)


def test_slack_hoist_rope_is_not_a_crash():
    """Lowering faster than the payload can fall (the rope's length grows at 12 m/s for 0.5 s
    from the tip of a held crane) leaves the rope slack: it carries no force while the payload
    falls freely, and the run goes on (no exception, the result passes its checks)."""
    sc = load_scene("telescopic_extraction", overrides={
        **HOLD, "booms.n_nodes": 3, "effects.friction": False,
        "effects.contact_distribution": False, "effects.payload_swing": True,
        "hoist.length": 5.0, "hoist_drive.profile": "table",
        "hoist_drive.table": [[0.0, 5.0], [0.1, 5.6], [0.5, 10.4], [0.6, 11.0]],
        "solver.t_end": 1.0, "solver.n_output": 21})
    res = simulate(sc)
    assert res.error is None and not res.suspect
    assert np.min(res["hoist_rope_force"]) == 0.0             # slack at some output time
    assert res["hoist_rope_force"][0] > 0.0


# -- the energy audit with every actuator moving ---------------------------------------------

@pytest.fixture(scope="module")
def moving_audit():
    """The paper's scene (friction on, 2 sub-elements per spline element) with the telescopic
    cylinder, the luffing cylinder (+2 deg), the slewing drive (+3 deg) and the hoist (10 ->
    9.9 m) all moving in the same 0.15 s window, the payload swinging on its rope, a 25 m/s
    wind with a height profile blowing at 60 deg to the luffing plane; the works integrated as
    extra states (energy_audit.run_energy_audit) at rtol 1e-6."""
    from sim_core.systems.telescopic.energy_audit import run_energy_audit
    sc = load_scene("telescopic_extraction", overrides={
        "booms.n_nodes": 3, "drive.t_ramp": 0.5, "drive.t_hold_end": 0.6,
        "luffing_drive.profile": "cubic", "luffing_drive.travel": 2.0,
        "luffing_drive.t_ramp": 0.1, "luffing_drive.t_hold_end": 0.2,
        "slew_drive.profile": "cubic", "slew_drive.travel": 3.0,
        "slew_drive.t_ramp": 0.1, "slew_drive.t_hold_end": 0.2,
        "effects.payload_swing": True, "hoist_drive.profile": "table",
        "hoist_drive.table": [[0.0, 10.0], [0.2, 9.9]],
        "effects.wind": True, "wind.speed": 25.0, "wind.direction_deg": 60.0,
        "wind.exponent": 0.14})
    ts = build_telescopic(params_from_scene(sc))
    z, _ = initial_equilibrium(ts)
    return run_energy_audit(ts, np.concatenate([z, 0 * z]), 0.15, rtol=1e-6, atol=1e-7,
                            n_output=16)


def test_energy_audit_closes_with_luffing_slewing_swing_and_wind(moving_audit):
    """E = booms' T + U + V + the swinging payload's kinetic and gravity energy + the ropes'
    strain energy changes by the work of the constraints on the booms (telescopic and luffing
    cylinders: lambda b'(t); the turntable: -lambda . g_phi phi_dot), of the hoist
    (dU/dL0 L0_dot) and of the wind (F_wind . Q_dot), less friction and filter dissipation, to the solver tolerance (rtol times
    the energy exchanged); and that constraint work is the actuators' work (drive_work: every
    actuator's own power), to the same tolerance."""
    a = moving_audit
    scale = (np.max(np.abs(a["energy"] - a["energy"][0])) + np.max(np.abs(a["drive_work"]))
             + np.max(np.abs(a["friction_work"])) + np.max(np.abs(a["filter_work"])))
    tol = 1e-6 * scale
    assert np.max(np.abs(a["residual"])) <= tol
    assert np.max(np.abs(a["constraint_work"] - a["drive_work"])) <= tol
    # the check can fail: the actuators' work is far above the tolerance
    assert np.max(np.abs(a["residual"] + a["drive_work"])) > 100 * tol


# -- slewing ---------------------------------------------------------------------------------

def test_constant_slewing_sway_and_radial_reaction():
    """The nearly rigid crane (E = 2.1e12 Pa, 60 deg, stages held) slews up to omega = 0.1 rad/s
    (an S-curve ramp of 6 s) with the payload and hook (25.5 t) on a 2 m rope, then at constant
    rate.  Seen from the turntable the payload is a conical pendulum: its steady sway outwards
    from the vertical is tan(beta) = omega^2 R_p / g (centrifugal force m omega^2 R_p against
    the weight, R_p the payload's distance from the slew axis); and the turntable holds the
    crane against the centrifugal forces of the booms and the payload, a horizontal inward
    force sum m_i omega^2 r_i (the booms' mass centres on their axes at the rigid geometry,
    the payload at R_p).  The ramp leaves a pendulum oscillation that the Coriolis force splits
    into the frequencies Omega_0 -+ omega (Omega_0 = sqrt(g / l)); the steady values are the
    offsets of a least-squares fit of the offset plus those two sinusoids (frequencies free)
    over 1.2 pendulum periods.  The turntable's vertical force balances the weight (a check of
    the force's reading, 1e-4: the payload's bounce is not averaged out).  Tolerance 1 % each
    (measured ~2e-4: the booms' deflection)."""
    from scipy.optimize import curve_fit

    from sim_core.systems.telescopic.luffing import luffing_geometry
    from sim_core.systems.telescopic.params import boom_section
    w, ramp, L0, g = 0.1, 6.0, 2.0, 9.81
    sc = load_scene("telescopic_extraction", overrides={
        **HOLD, "booms.n_nodes": 3, "booms.E": 2.1e12, "effects.friction": False,
        "effects.contact_distribution": False, "effects.payload_swing": True,
        "hoist.length": L0, "slew_drive.profile": "trapezoid", "slew_drive.travel": 200.0,
        "slew_drive.v_max": math.degrees(w), "slew_drive.a_max": math.degrees(w) / (0.75 * ramp),
        "slew_drive.j_max": math.degrees(w) / (0.75 * ramp) / (0.25 * ramp)})
    p = params_from_scene(sc)
    ts = build_telescopic(p)
    m = ts.model
    z, _ = initial_equilibrium(ts)
    m_hang = p.payload + p.hook_mass
    period = 2 * math.pi * math.sqrt(L0 * (1 + m_hang * g / p.hoist_EA) / g)
    t_end = ramp + 1.2 * period
    t, ys, _ = integrate(m, np.concatenate([z, 0 * z]), t_end,
                         {"rtol": 1e-7, "atol": 1e-9, "n_output": 300, "method": "auto"})
    n = m.n_dof
    ip = int(ts.hoist.bottom.coords(None)[0])
    cyl = next(c for c in m.nonlinear if c.name == "luffing_cylinder")
    tt, sway, R_p, F_in, F_z = [], [], [], [], []
    for tk, y in zip(t, ys):
        if tk < ramp:
            continue
        Q, _ = m.full_state(tk, y[:n], y[n:])
        _, lam = m.accelerations_and_multipliers(tk, y[:n], y[n:])
        phi = float(np.real(Q[ts.i_phi]))
        u = np.array([math.cos(phi), math.sin(phi), 0.0])
        d = np.real(Q[ip:ip + 3] - ts.tip(Q)[0])
        r3, r2 = (np.real(pt(Q)[0]) for pt in cyl.points)
        # the turntable's force on the crane: the pivot rows and the cylinder's force at D3
        F = lam[ts.rows["pivot"]] + lam[ts.rows["luffing_cylinder"]][0] * (r3 - r2) / \
            np.linalg.norm(r3 - r2)
        tt.append(tk)
        sway.append(math.atan2(d @ u, -d[2]))
        R_p.append(float(np.real(Q[ip:ip + 2]) @ u[:2]))
        F_in.append(-float(np.real(F) @ u))
        F_z.append(float(np.real(F[2])))
    tt = np.array(tt)
    geo = luffing_geometry(math.radians(60.0), *p.luffing.points())
    masses = [p.lengths[k] * boom_section(k, p).rhoA for k in range(3)]
    mr = sum(mk * (geo.origin + (k * p.stroke0 + 0.5 * p.lengths[k]) * geo.e_s)[0]
             for k, mk in enumerate(masses))
    Rp = float(np.mean(R_p))
    O0 = 2 * math.pi / period

    def two_modes(t, c, a1, b1, a2, b2, o1, o2):
        return (c + a1 * np.cos(o1 * t) + b1 * np.sin(o1 * t) + a2 * np.cos(o2 * t)
                + b2 * np.sin(o2 * t))

    def steady(y):
        y = np.asarray(y)
        popt, _ = curve_fit(two_modes, tt, y, p0=[y.mean(), 0, 0, 0, 0, O0 - w, O0 + w],
                            maxfev=20000)
        return popt[0]

    assert steady(sway) == pytest.approx(math.atan(w * w * Rp / g), rel=1e-2)
    assert steady(F_in) == pytest.approx((mr + m_hang * Rp) * w * w, rel=1e-2)
    # vertical: the weight, up to the payload's vertical oscillation (second order in the sway)
    assert np.mean(F_z) == pytest.approx((sum(masses) + m_hang) * g, rel=1e-4)


# -- wind, the effect plug-in ----------------------------------------------------------------

def test_cross_wind_reaction_is_the_drag_on_the_exposed_booms():
    """A uniform wind U = 20 m/s across the luffing plane on the paper's crane at rest: the
    turntable's lateral reaction (pivot and luffing cylinder) equals the total drag 1/2 rho C_d U^2 sum_k b_k
    l_k, with b_k the U section's height z_a + r_k + R_k (the contour's extent across the
    flow: 0.78 / 0.74 / 0.70 m) and l_k the exposed length (boom 1 whole, 10 m; booms 2 and 3
    beyond their outer neighbour, L_s = 2 m each; the rest is shielded).  Static equilibrium
    balances the forces exactly; the booms' small twist and sway change the projected width at
    second order (measured 2.6e-4).  Tolerance 1e-3."""
    U, rho, cd = 20.0, 1.225, 1.2
    sc = load_scene("telescopic_extraction", overrides={
        "booms.n_nodes": 3, "effects.wind": True, "wind.speed": U, "effects.friction": False,
        "effects.contact_distribution": False})
    ts = build_telescopic(params_from_scene(sc))
    z, lam = initial_equilibrium(ts)
    Q, _ = ts.model.full_state(0.0, z, 0 * z)
    drag = 0.5 * rho * cd * U * U * (0.78 * 10.0 + 0.74 * 2.0 + 0.70 * 2.0)
    # the turntable's force on the crane: the pivot and the luffing cylinder, whose 3.3 MN
    # turn sideways with the booms' sway (D3 moves ~0.4 mm across: ~170 N of the reaction)
    cyl = next(c for c in ts.model.nonlinear if c.name == "luffing_cylinder")
    r3, r2 = (np.real(pt(Q)[0]) for pt in cyl.points)
    F = lam[ts.rows["pivot"]] + lam[ts.rows["luffing_cylinder"]][0] * (r3 - r2) / \
        np.linalg.norm(r3 - r2)
    assert -F[1] == pytest.approx(drag, rel=1e-3)


def test_wind_without_a_kernel_says_so_once():
    """The wind has no compiled element kernel: the run warns once and its stats name it."""
    sc = load_scene("telescopic_extraction", overrides={
        **HOLD, "booms.n_nodes": 3, "effects.wind": True, "effects.friction": False,
        "effects.contact_distribution": False, "solver.t_end": 0.05, "solver.n_output": 3})
    with pytest.warns(RuntimeWarning, match="wind has no compiled element kernel") as record:
        res = simulate(sc)
    assert sum("compiled element kernel" in str(w.message) for w in record) == 1
    assert res.stats["uncompiled_effects"] == ["wind"]
