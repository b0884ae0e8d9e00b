"""The drives' forces and torques of the stepping API's outputs against statics and the energy
balance, and the documented sign convention of the sway (docs/stepping.md) against a
sway-damping controller written from it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim_core import Simulation, load_scene
from sim_core.systems.telescopic.energy_audit import AuditedSystem, mechanical_energy
from sim_core.systems.telescopic.schema import params_from_scene
from sim_core.validation.closed_form import rigid_luffing_force, static_luffing_forces

FAST = {"booms.n_nodes": 3, "effects.contact_distribution": False, "effects.friction": False}
HOLD = {"drive.profile": "table", "drive.table": [[0.0, 2.0], [1.0, 2.0]]}
G = 9.81


def test_held_crane_forces_meet_the_statics():
    """The crane held at rest (no command: every drive holds) carries its weight: the luffing
    cylinder force is the moment of the booms' and payload's weight about the pivot D1 over the
    cylinder's lever (closed_form.rigid_luffing_force, positive pushing), the telescopic
    cylinder force m2 g sin(theta) + 2 T with the rope tension T = (m3 + m_p) g sin(theta)
    (docs/model.md#check-static-luffing, positive pushing).  The flexible booms' sag moves the
    weights' arms: the documented 2 % of the flexible check.  The hoisted payload's rope
    carries (m_p + m_hook) g: the rope's tension at rest, to the equilibrium solve's
    tolerance (1e-6)."""
    sc = load_scene("telescopic_extraction", overrides={**FAST, **HOLD})
    p = params_from_scene(sc)
    sim = Simulation(sc)
    sim.advance(0.1)
    out = sim.outputs()
    th = math.radians(sc["booms"]["luffing_angle_deg"])
    assert out["luffing_cylinder_force"] == pytest.approx(rigid_luffing_force(p, th, G),
                                                          rel=2e-2)
    ref = static_luffing_forces(th, sc["booms"]["stroke0"], p.payload, g=G)
    assert out["telescopic_cylinder_force"] == pytest.approx(ref.telescopic_force, rel=2e-2)
    assert out["drive_forces"][0] == out["telescopic_cylinder_force"]

    sc = load_scene("telescopic_extraction", overrides={**FAST, **HOLD,
                                                        "effects.payload_swing": True})
    sim = Simulation(sc)
    sim.advance(0.05)
    weight = (sc["payload"]["mass"] + sc["hoist"]["hook_mass"]) * G
    assert sim.outputs(["hoist_rope_force"])["hoist_rope_force"] == pytest.approx(
        weight, rel=1e-6)


def _energy_and_filter_power(sim):
    """(mechanical energy J, the stress filter's power W) at the current state (the model's
    clock put at the current time, as outputs() does)."""
    impl = sim._impl
    ts, n = impl.ts, impl.ts.model.n_dof
    clock = impl.clock[0]
    impl.clock[0] = impl.t
    try:
        z, zd = impl.y[:n], impl.y[n:]
        E = mechanical_energy(ts, 0.0, z, zd)
        _, (P,) = AuditedSystem(ts, ("filter_work",)).powers(0.0, z, zd)
    finally:
        impl.clock[0] = clock
    return E, P


def test_slew_torque_does_the_work_of_the_slewing():
    """Slewing from rest at 5 deg/s^2 for 0.4 s with every other drive held and friction off:
    the only external work is the slewing drive's, so the change of the mechanical energy
    (kinetic, strain, gravity, ropes, payload) equals int (slew_torque phi' + P_filter) dt
    (the stress filter's power, the only other term of the energy audit).  Trapezoidal rule on
    0.02 s samples of power histories carrying the booms' lateral vibration (f <~ 3 Hz):
    relative error <= (2 pi f dt)^2 / 12 ~ 1 % of the work; the slew torque is positive while
    it accelerates phi up."""
    sim = Simulation(load_scene("telescopic_extraction", overrides={
        **FAST, **HOLD, "slew_drive.profile": "hold"}))
    alpha, dt = math.radians(5.0), 0.02
    E0, Pf = _energy_and_filter_power(sim)
    t, P = [0.0], [Pf]
    torque = []
    for _ in range(20):
        sim.advance(dt, {"slew": alpha})
        out = sim.outputs(["slew_torque", "actuators"])
        torque.append(out["slew_torque"])
        E, Pf = _energy_and_filter_power(sim)
        t.append(sim.t)
        P.append(out["slew_torque"] * out["actuators"]["slew"][1] + Pf)
    work = np.trapezoid(P, t)
    assert min(torque) > 0.0
    assert E - E0 == pytest.approx(work, rel=1e-2)


def test_the_payload_lags_the_accelerated_tip():
    """The sign convention itself (docs/stepping.md): from rest, a slew acceleration drives
    the tip along +w and an extension of the stages drives it along +u; the payload on its
    rope lags behind, so sway_angle[1] (towards +w) and sway_angle[0] (towards +u) and their
    rates turn negative.  Half a second is a quarter of the 1 m rope's period: the pendulum
    has not swung back."""
    sc = load_scene("telescopic_extraction", overrides={
        **FAST, **HOLD, "effects.payload_swing": True, "hoist.length": 1.0,
        "slew_drive.profile": "hold"})
    for name, axis in (("slew", 1), ("telescopic", 0)):
        sim = Simulation(sc)
        sim.advance(0.25, {name: math.radians(10.0) if name == "slew" else 0.2})
        out = sim.outputs(["sway_angle", "sway_rate"])
        assert out["sway_angle"][axis] < -1e-4 and out["sway_rate"][axis] < -1e-4
        assert abs(out["sway_angle"][1 - axis]) < 0.1 * abs(out["sway_angle"][axis])


@pytest.mark.slow
def test_sway_damping_from_the_documented_sign_reduces_the_sway():
    """docs/stepping.md: the tip moves along +w as the slew angle grows, and sway_angle[1] is
    positive towards +w, so the slew acceleration +k sway_rate[1] damps the sway across the
    luffing plane (a pendulum whose suspension accelerates by a_s = +c alpha' gets the damping
    c / l).  A 1 m rope (period 2 s) set swinging by a slew pulse, then 1 s of feedback at a
    0.1 s control step: with
    +k the swing's energy (1/2 alpha'^2 + (g/l)(1 - cos alpha), per unit l^2) falls, with -k
    (the sign error of the issue) it grows; k = 0.3 rad/s^2 per rad/s at the tip radius of
    ~7 m gives c ~ 2 m/s^2 per rad/s, a damping ratio c / (2 l omega) ~ 0.3: the energy's
    factor over 1 s, exp(-2 zeta omega t) ~ 0.15, is far from 1 either way."""
    sim = Simulation(load_scene("telescopic_extraction", overrides={
        **FAST, **HOLD, "effects.payload_swing": True, "hoist.length": 1.0,
        "slew_drive.profile": "hold"}))
    a = math.radians(10.0)
    for cmd in (a, -a):                              # a slew pulse: the payload swings
        sim.advance(0.2, {"slew": cmd})
    sim.advance(0.05, {"slew": 0.0})
    start = sim.save_state()

    def swing():
        out = sim.outputs(["sway_angle", "sway_rate"])
        al, rate = out["sway_angle"][1], out["sway_rate"][1]
        return 0.5 * rate ** 2 + G * (1.0 - math.cos(al))

    e0 = swing()
    assert e0 > 1e-5                                 # it swings: > 1e-3 rad/s
    ratio = {}
    for k in (0.3, -0.3):
        sim.restore_state(start)
        for _ in range(10):                          # a 0.1 s control step
            rate = sim.outputs(["sway_rate"])["sway_rate"][1]
            sim.advance(0.1, {"slew": k * rate})
        ratio[k] = swing() / e0
    assert ratio[0.3] < 0.5 < 2.0 < ratio[-0.3]
