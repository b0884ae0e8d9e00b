"""Actuator limits of the stepping API (sim_core.Simulation(scene, limits=...)): the limits come
from the scene's actuator tables, a command beyond them raises ActuatorLimitError before the
step (limits="raise") or is held to them (limits="clip": acceleration cut, rate held, inelastic
end stop), and the clipped motion is the exact kinematics of a drive at its limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim_core import Command, Simulation, load_scene
from sim_core.errors import ActuatorLimitError
from sim_core.systems.telescopic.schema import params_from_scene
from sim_core.systems.telescopic.stepping import ActuatorLimits, actuator_limits, limited

FAST = {"booms.n_nodes": 3, "effects.contact_distribution": False, "effects.friction": False}
HOLD = {"drive.profile": "table", "drive.table": [[0.0, 2.0], [1.0, 2.0]]}
DEG = math.pi / 180.0


def test_limits_come_from_the_actuator_tables():
    """crane_lift_and_slew: the slew's acceleration limit is its trapezoid's a_max (1.5 deg/s^2,
    the scene states no max_accel) and its rate limit max_rate (12 deg/s); the luffing drive's
    are max_accel and max_rate (1, 3 deg/s); the hoist's rate max_rate (1 m/s) and its
    acceleration, stated nowhere, the largest max_accel a scene may state (20 m/s^2); the end
    stops are the tables' position ranges (luffing [0, 85] deg, hoist >= 0.1 m) and the stage
    length 0 < L_s < 10 m - the 0.3 m slider."""
    sc = load_scene("crane_lift_and_slew")
    p = params_from_scene(sc)
    lim = {k: actuator_limits(sc, p, k) for k in ("telescopic", "luffing", "slew", "hoist")}
    assert (lim["slew"].accel, lim["slew"].rate) == pytest.approx((1.5 * DEG, 12.0 * DEG))
    assert "a_max" in lim["slew"].sources[0] and "max_rate" in lim["slew"].sources[1]
    assert (lim["luffing"].accel, lim["luffing"].rate) == pytest.approx((1.0 * DEG, 3.0 * DEG))
    assert (lim["luffing"].lo, lim["luffing"].hi) == pytest.approx((0.0, 85.0 * DEG))
    assert (lim["hoist"].accel, lim["hoist"].rate, lim["hoist"].lo) == pytest.approx(
        (20.0, 1.0, 0.1))
    assert (lim["telescopic"].lo, lim["telescopic"].hi) == pytest.approx((0.0, 9.7))


def _modal(**over):
    return load_scene("telescopic_extraction_rl",
                      overrides={"drive.max_rate": 0.3, "drive.max_accel": 0.5, **over})


def test_raise_names_the_actuator_value_and_range_and_leaves_the_state():
    """limits="raise" (the default): a command beyond the acceleration limit, one whose rate
    passes the rate limit within the step, and a rate jump away from 0 raise before the step,
    with the actuator, the quantity, the value and the allowed range; the simulation stays
    where it was."""
    sim = Simulation(_modal())
    before = sim.save_state()
    cases = [(2.0, 1.0, "acceleration", 2.0, (-0.5, 0.5)),
             (0.5, 1.0, "rate", 0.5, (-0.3, 0.3)),
             (Command(((0.1, 0.1, 0.05),)), 0.1, "rate jump", 0.05, (-0.01, 0.0))]
    for cmd, dt, quantity, value, allowed in cases:
        with pytest.raises(ActuatorLimitError) as info:
            sim.advance(dt, {"telescopic": cmd})
        e = info.value
        assert (e.actuator, e.quantity) == ("telescopic", quantity)
        assert e.value == pytest.approx(value) and e.allowed == pytest.approx(allowed)
        assert "'telescopic'" in str(e) and f"{allowed[0]:.6g}" in str(e)
        assert sim.t == 0.0
        assert sim.save_state()["L"] == before["L"] and sim.save_state()["v"] == before["v"]


def test_clip_cuts_the_acceleration_and_holds_the_rate():
    """limits="clip": 2 m/s^2 commanded for 1 s with a_max 0.5 m/s^2 and v_max 0.3 m/s: the
    stage accelerates at 0.5 until 0.3 m/s (0.6 s), then runs at 0.3 m/s, L = L0 + v^2 / (2 a)
    + v (1 - v / a) exactly; the clipped limits are recorded."""
    sim = Simulation(_modal(), limits="clip")
    sim.advance(1.0, {"telescopic": 2.0})
    L, v, a = sim.outputs(["actuators"])["actuators"]["telescopic"]
    assert (L, v, a) == pytest.approx((2.0 + 0.09 / 1.0 + 0.3 * 0.4, 0.3, 0.0), abs=1e-12)
    assert sim.clipped == {"telescopic": ("acceleration", "rate")}
    sim.advance(0.1, {"telescopic": 0.0})
    assert sim.clipped == {}


def test_clip_stops_at_the_end_stop_and_leaves_it_on_command():
    """Driven into the far end of the modal tables' stroke range the stage stops there at rate
    0 (an inelastic stop), stays while the command pushes on, and leaves it when the command
    reverses."""
    sim = Simulation(_modal(), limits="clip")
    hi = sim.limits["telescopic"].hi
    sim.advance(30.0, {"telescopic": 0.5})
    L, v, _ = sim.outputs(["actuators"])["actuators"]["telescopic"]
    assert (L, v) == pytest.approx((hi, 0.0), abs=1e-9)
    assert "position" in sim.clipped["telescopic"]
    sim.advance(1.0)                              # still pushing: held
    assert sim.outputs(["actuators"])["actuators"]["telescopic"][:2] == pytest.approx(
        (hi, 0.0), abs=1e-9)
    sim.advance(0.2, {"telescopic": -0.5})       # away from the stop: moves off
    L, v, _ = sim.outputs(["actuators"])["actuators"]["telescopic"]
    assert (L, v) == pytest.approx((hi - 0.5 * 0.5 * 0.04, -0.1), abs=1e-9)
    assert sim.clipped == {}


def _states(s, v, pieces, n=50):
    """(position, rate) sampled within every piece and after its jump (exact kinematics)."""
    out = [(s, v)]
    for a, tau, jump in pieces:
        for x in np.linspace(0.0, tau, n)[1:]:
            out.append((s + v * x + 0.5 * a * x * x, v + a * x))
        s, v = s + v * tau + 0.5 * a * tau * tau, v + a * tau + jump
        out.append((s, v))
    return np.array(out)


def test_clipped_motion_stays_within_every_limit():
    """Random piecewise commands (accelerations to 3 x the limit, jumps of either sign, 0-2 s
    pieces) from random states within the limits: the clipped pieces keep |a| <= A, |v| <= V
    and lo <= s <= hi at every sample (to round-off), jumps only towards 0, the same total
    duration; a command within the limits comes back unchanged."""
    lim = ActuatorLimits(0.5, 0.3, 1.0, 4.0, "m", ("a", "v", "s"))
    rng = np.random.default_rng(7)
    for _ in range(300):
        s, v = rng.uniform(1.0, 4.0), rng.uniform(-0.3, 0.3)
        pieces = [(rng.uniform(-1.5, 1.5), rng.uniform(0.0, 2.0),
                   rng.uniform(-0.2, 0.2) * (rng.random() < 0.3)) for _ in range(3)]
        out, hit = limited("x", lim, s, v, pieces, clip=True)
        assert sum(p[1] for p in out) == pytest.approx(sum(p[1] for p in pieces), abs=1e-12)
        assert all(abs(a) <= 0.5 + 1e-12 for a, _, _ in out)
        sv = _states(s, v, out)
        assert np.all(np.abs(sv[:, 1]) <= 0.3 + 1e-9)
        assert np.all((sv[:, 0] >= 1.0 - 1e-9) & (sv[:, 0] <= 4.0 + 1e-9))
        rate = v
        for a, tau, jump in out:                  # jumps only stop
            v_end = rate + a * tau
            assert abs(v_end + jump) <= abs(v_end) + 1e-12 and (v_end + jump) * v_end >= 0
            rate = v_end + jump
        if not hit:
            assert out == [p for p in pieces if p[1] > 0 or p[2] != 0]
        else:
            with pytest.raises(ActuatorLimitError):
                limited("x", lim, s, v, pieces, clip=False)


def _slewing(**over):
    return load_scene("telescopic_extraction", overrides={
        **FAST, **HOLD, "slew_drive.profile": "hold", "slew_drive.max_accel": 3.0,
        "slew_drive.max_rate": 6.0, **over})


def test_full_model_slew_beyond_its_limit():
    """The full model with a slewing drive limited to 3 deg/s^2: 20 deg/s^2 raises (the issue's
    case) and nothing moves; with limits="clip" the turntable turns at 3 deg/s^2: the slew
    actuator's (angle, rate, acceleration) after 0.1 s are (A t^2 / 2, A t, A) exactly."""
    sc = _slewing()
    sim = Simulation(sc)
    with pytest.raises(ActuatorLimitError, match=r"slew.*0\.349066.*0\.0523599"):
        sim.advance(0.05, {"slew": 20.0 * DEG})
    assert sim.t == 0.0 and sim.outputs(["actuators"])["actuators"]["slew"] == (0.0, 0.0, 0.0)
    sim = Simulation(sc, limits="clip")
    sim.advance(0.1, {"slew": 20.0 * DEG})
    A = 3.0 * DEG
    assert sim.outputs(["actuators"])["actuators"]["slew"] == pytest.approx(
        (0.5 * A * 0.01, A * 0.1, A), abs=1e-15)
    assert sim.clipped == {"slew": ("acceleration",)}
