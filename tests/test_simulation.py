"""The stepping API (sim_core.Simulation, sim_core.Command): stepping reproduces a run (full
model and modal ROM), commands drive the actuators exactly (accelerations and segment histories
with rate jumps), and a restored state repeats the run to round-off."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from sim_core import Command, SceneError, Simulation, load_scene, simulate

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


@pytest.mark.parametrize("solver", [{}, {"solver.method": "ROS2", "solver.jacobian_interval": 0.1}],
                         ids=["RK45", "ROS2"])
def test_restored_state_repeats_the_run(solver):
    """save_state after three commanded steps, four more steps; restore (through pickle) and
    the same four steps give the same state bit for bit: the snapshot holds the time, the
    integrated state, every drive's segment and the friction's warm starts (with ROS2 also its
    Jacobian, renewed inside the four steps)."""
    sc = load_scene("telescopic_extraction", overrides={**FAST, "effects.friction": True,
                                                        **solver})
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
    with pytest.raises(SceneError, match="effects.flexible = false"):
        Simulation(load_scene("telescopic_extraction", overrides={"effects.flexible": False}))


def test_segments_command_drives_the_stages_through_a_rate_jump():
    """A Command of two segments within one step, the second ending in a rate jump -v1 (an
    inelastic stop) at the step's end: the stage length follows the segments' kinematics (to
    the constraint's drift, 1e-6 m) and the actuator then holds its length at rate 0.  The
    model's velocity still has v1 along the drive: the drive constraint's Baumgarte
    stabilisation (xi = 10 1/s, second seed Eq. 8) brings the stroke back, an excursion below
    that of the critically damped e'' + 2 xi e' + xi^2 e = 0 from e'(0) = v1, max v1 / (xi e),
    decaying to 1e-8 m within 1 s."""
    sc = load_scene("telescopic_extraction", overrides=FAST)
    sim = Simulation(sc)
    a, t1, t2 = 0.4, 0.03, 0.02
    v1 = a * t1
    sim.advance(t1 + t2, {"telescopic": Command(((a, t1, 0.0), (0.0, t2, -v1)))})
    s = 0.5 * a * t1 ** 2 + v1 * t2
    out = sim.outputs()
    assert out["piston_stroke"] == pytest.approx(s, abs=1e-6)
    assert out["actuators"]["telescopic"] == pytest.approx((2.0 + s, 0.0, 0.0), abs=1e-12)
    err = []
    for _ in range(20):                            # no command: the actuator holds at rate 0
        sim.advance(0.05)
        out = sim.outputs()
        assert out["actuators"]["telescopic"] == pytest.approx((2.0 + s, 0.0, 0.0), abs=1e-12)
        err.append(abs(out["piston_stroke"] - s))
    assert max(err) <= v1 / (10.0 * math.e)
    assert err[-1] < 1e-8


def test_light_outputs_equal_the_full_outputs():
    """outputs(names) of the tip (the cheap path) equals the full outputs' entries."""
    sim = Simulation(load_scene("telescopic_extraction", overrides=FAST))
    sim.advance(0.05, {"telescopic": 0.2})
    full, light = sim.outputs(), sim.outputs(["tip_position", "tip_velocity", "actuators"])
    assert set(light) == {"tip_position", "tip_velocity", "actuators"}
    for k in ("tip_position", "tip_velocity"):
        np.testing.assert_array_equal(light[k], full[k])
    assert light["actuators"] == full["actuators"]
    with pytest.raises(KeyError, match="no_such_output"):
        sim.outputs(["no_such_output"])


def test_modal_stepping_without_commands_reproduces_the_rom_run():
    """The modal ROM scene stepped at its output interval without commands follows its cubic
    schedule on the same piecewise-constant mean accelerations as simulate: the same tip
    deflection and stroke to round-off (the step times accumulate differently: 1e-12)."""
    sc = load_scene("telescopic_extraction_rl")
    res = simulate(sc)
    sim = Simulation(sc)
    assert sim.actuators == ("telescopic",)
    dt = res.t[1] - res.t[0]
    defl, stroke = [sim.outputs()["tip_deflection"]], [sim.outputs()["piston_stroke"]]
    for _ in range(len(res.t) - 1):
        sim.advance(dt)
        out = sim.outputs()
        defl.append(out["tip_deflection"])
        stroke.append(out["piston_stroke"])
    scale = np.max(np.abs(res["tip_deflection"]))
    np.testing.assert_allclose(defl, res["tip_deflection"], rtol=0, atol=1e-12 * scale + 1e-15)
    np.testing.assert_allclose(stroke, res["piston_stroke"], rtol=0, atol=1e-12)


def test_modal_rate_jump_is_the_modal_impulse():
    """A stroke rate jump dv in the ROM jumps the modal rates by -Gamma(L_s) dv (the impulse of
    q'' = -Gamma a) and leaves the modal coordinates: two runs that differ only by the jump at
    the end of the same segment differ by exactly that."""
    sc = load_scene("telescopic_extraction_rl")
    outs = []
    for jump in (0.0, -0.05):
        sim = Simulation(sc)
        sim.advance(0.2, {"telescopic": Command(((0.25, 0.2, jump),))})
        outs.append(sim.outputs())
    from sim_core.rom import tables_for
    L = outs[0]["actuators"]["telescopic"][0]
    gamma = tables_for(25000.0, 60.0, 3).coefficients(L)[2]
    np.testing.assert_array_equal(outs[1]["modal_coordinates"], outs[0]["modal_coordinates"])
    np.testing.assert_allclose(outs[1]["modal_rates"] - outs[0]["modal_rates"],
                               -gamma * -0.05, rtol=1e-12, atol=0)
    assert outs[1]["actuators"]["telescopic"][1] == pytest.approx(0.05 - 0.05, abs=1e-15)


def test_modal_restored_state_repeats_the_run():
    sim = Simulation(load_scene("telescopic_extraction_rl"))
    sim.advance(0.5, {"telescopic": 0.2})
    snap = pickle.loads(pickle.dumps(sim.save_state()))
    for _ in range(3):
        sim.advance(0.05, {"telescopic": Command(((-0.1, 0.02, 0.0), (0.1, 0.03, 0.0)))})
    first = sim.outputs()
    sim.restore_state(snap)
    for _ in range(3):
        sim.advance(0.05, {"telescopic": Command(((-0.1, 0.02, 0.0), (0.1, 0.03, 0.0)))})
    again = sim.outputs()
    for k in ("tip_deflection", "modal_coordinates", "modal_rates"):
        np.testing.assert_array_equal(first[k], again[k])
    assert first["actuators"] == again["actuators"]


def test_command_end_replaces_round_off_only():
    """Command.end puts the caller's state in place where it agrees with the segments to
    round-off, and refuses a state the segments do not reach."""
    sim = Simulation(load_scene("telescopic_extraction_rl"))
    L = 2.0 + 0.5 * 0.2 * 0.05 ** 2
    sim.advance(0.05, {"telescopic": Command(((0.2, 0.05, 0.0),), end=(L + 1e-15, 0.01))})
    assert sim.outputs()["actuators"]["telescopic"][:2] == (L + 1e-15, 0.01)
    with pytest.raises(ValueError, match="end position"):
        sim.advance(0.05, {"telescopic": Command(((0.0, 0.05, 0.0),), end=(L + 0.01, 0.01))})


@pytest.mark.parametrize("segments, end, words", [
    ((), None, ["at least one"]),
    (((0.1, -1.0, 0.0),), None, ["duration = -1.0"]),
    (((0.1, math.inf, 0.0), (0.0, 1.0, 0.0)), None, ["inf only for the last"]),
    (((math.nan, 1.0, 0.0),), None, ["finite"]),
    (((0.1, 1.0),), None, ["three numbers"]),
    (((0.1, 1.0, 0.0),), (1.0,), ["end = (1.0,)"]),
])
def test_bad_commands_are_refused(segments, end, words):
    with pytest.raises(ValueError) as info:
        Command(segments, end)
    assert all(w in str(info.value) for w in words)


def test_public_modules_stay_light():
    """sim_core's public modules import neither the RL stack nor Ray."""
    import subprocess
    import sys
    code = ("import json, sys\nimport sim_core.rom, sim_core.profiles, sim_core.commands\n"
            "print(json.dumps([m for m in ('torch', 'gymnasium', 'ray') if m in sys.modules]))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "[]"
