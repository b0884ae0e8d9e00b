"""The stepping API (sim_core.Simulation): stepping reproduces a run, commands drive the
actuators exactly, and a restored state repeats the run to round-off."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from sim_core import SceneError, Simulation, load_scene, simulate

FAST = {"booms.n_nodes": 3, "effects.contact_distribution": False}


def test_stepping_without_commands_reproduces_the_run():
    """Ten steps of 0.1 s on the scene's own profiles end where one run of 1 s ends: each step
    restarts the error-controlled integrator, so the two differ by the solver's tolerance
    (rtol 1e-6 of the tip's 15 m, 1.5e-5 m), not more."""
    sc = load_scene("telescopic_extraction", overrides={**FAST, "solver.t_end": 1.0})
    sim = Simulation(sc)
    for _ in range(10):
        sim.advance(0.1)
    assert sim.t == pytest.approx(1.0, abs=1e-12)
    out, res = sim.outputs(), simulate(sc)
    np.testing.assert_allclose(out["tip_position"], res["tip_position"][-1], rtol=0,
                               atol=1.5e-5)
    assert out["piston_stroke"] == pytest.approx(res["piston_stroke"][-1], abs=1e-6)


def test_a_command_drives_the_stages_on_its_acceleration():
    """Commanded accelerations a1 then a2 of the telescopic stages, each held over its steps:
    the stage length follows s0 + v t + a t^2 / 2 piece by piece with the rate continuous
    (the drive is a constraint: the stroke output equals it to the constraint's drift, 1e-6 m),
    and the actuator reports the commanded acceleration."""
    sc = load_scene("telescopic_extraction", overrides=FAST)
    sim = Simulation(sc)
    a1, a2, dt = 0.2, -0.1, 0.05
    for _ in range(4):
        sim.advance(dt, {"telescopic": a1})
    T1 = 4 * dt
    for _ in range(3):
        sim.advance(dt, {"telescopic": a2})
    T2 = 3 * dt
    s = 0.5 * a1 * T1 ** 2 + a1 * T1 * T2 + 0.5 * a2 * T2 ** 2
    out = sim.outputs()
    assert out["piston_stroke"] == pytest.approx(s, abs=1e-6)
    pos, rate, acc = out["actuators"]["telescopic"]
    assert (pos - 2.0, rate, acc) == pytest.approx((s, a1 * T1 + a2 * T2, a2), abs=1e-12)


def test_restored_state_repeats_the_run():
    """save_state after three commanded steps, four more steps; restore (through pickle) and
    the same four steps give the same state bit for bit: the snapshot holds the time, the
    integrated state, every drive's segment and the friction's warm starts."""
    sc = load_scene("telescopic_extraction", overrides={**FAST, "effects.friction": True})
    sim = Simulation(sc)
    for _ in range(3):
        sim.advance(0.05, {"telescopic": 0.2})
    snap = pickle.loads(pickle.dumps(sim.save_state()))
    for _ in range(4):
        sim.advance(0.05, {"telescopic": -0.1})
    first = sim.outputs()
    sim.restore_state(snap)
    assert sim.t == pytest.approx(0.15, abs=1e-15)
    for _ in range(4):
        sim.advance(0.05, {"telescopic": -0.1})
    again = sim.outputs()
    for key in ("tip_position", "telescopic_cylinder_force", "luffing_cylinder_force"):
        np.testing.assert_array_equal(first[key], again[key])


def test_luffing_and_hoist_commands():
    """A luffing acceleration raises the boom (the luffing angle grows by about the commanded
    a t^2 / 2: the booms' sag changes a little with the angle, 0.05 deg) and a hoist command
    shortens the rope of the swinging payload; the actuators list names what the scene has."""
    sc = load_scene("telescopic_extraction", overrides={
        **FAST, "effects.payload_swing": True, "drive.profile": "table",
        "drive.table": [[0.0, 2.0], [1.0, 2.0]]})
    sim = Simulation(sc)
    assert set(sim.actuators) == {"telescopic", "luffing", "hoist"}
    th0 = sim.outputs()["luffing_angle"]
    a = math.radians(4.0)                       # rad/s^2
    for _ in range(5):
        sim.advance(0.1, {"luffing": a, "hoist": -0.4})
    out = sim.outputs()
    assert out["luffing_angle"] - th0 == pytest.approx(0.5 * a * 0.25, abs=math.radians(0.05))
    assert out["actuators"]["hoist"][0] == pytest.approx(10.0 - 0.5 * 0.4 * 0.25, abs=1e-12)


@pytest.mark.parametrize("call, error, words", [
    (lambda s: s.advance(0.1, {"slew": 1.0}), KeyError, ["slew", "telescopic"]),
    (lambda s: s.advance(0.0), ValueError, ["dt = 0.0"]),
    (lambda s: s.advance(0.1, {"telescopic": float("nan")}), ValueError, ["finite"]),
])
def test_bad_commands_name_the_problem(call, error, words):
    sim = Simulation(load_scene("telescopic_extraction", overrides=FAST))
    with pytest.raises(error) as info:
        call(sim)
    assert all(w in str(info.value) for w in words)


def test_kinds_without_a_stepper_say_so():
    with pytest.raises(SceneError, match="stepping API"):
        Simulation(load_scene("cantilever_release"))
    with pytest.raises(SceneError, match="full model"):
        Simulation(load_scene("telescopic_extraction_rl"))
