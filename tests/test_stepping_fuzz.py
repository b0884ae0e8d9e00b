"""Fuzz of the stepping API's input (sim_core.Simulation): wrong types and shapes, NaN, inf,
huge values, unknown actuator and output names, bad dt, malformed snapshots and scenes.  Every
one ends in a typed error (sim_core.errors: CommandError and its UnknownNameError and
ActuatorLimitError, SceneError) within a wall budget, and leaves the simulation as it was;
advance's wall-clock budget ends a long integration with a SimulationError (the time reached,
the reason) within the budget plus a margin."""

from __future__ import annotations

import time

import numpy as np
import pytest

from sim_core import Command, SceneError, Simulation, SimulationError, load_scene
from sim_core.errors import ActuatorLimitError, CommandError, UnknownNameError

FAST = {"booms.n_nodes": 3, "effects.contact_distribution": False, "effects.friction": False}
HOLD = {"drive.profile": "table", "drive.table": [[0.0, 2.0], [1.0, 2.0]]}
NAN, INF = float("nan"), float("inf")
#: wall time of a refused call, s: it is refused before any integration (Python checks only);
#: generous for a loaded 2-core CI machine
REFUSE_S = 2.0
#: the margin past the budget: the budget is checked after every integrator step (RK45) or
#: right-hand side (ROS2); a step of the 3-node model takes milliseconds, the rest is the
#: caller's overhead and a loaded machine
BUDGET_MARGIN_S = 1.0


@pytest.fixture(scope="module")
def full():
    return Simulation(load_scene("telescopic_extraction", overrides={**FAST, **HOLD}))


@pytest.fixture(scope="module")
def modal():
    return Simulation("telescopic_extraction_rl")


BAD_DT = [0, 0.0, -1.0, NAN, INF, -INF, "0.1", None, True, [0.1], complex(0.1),
          np.array([0.1])]
BAD_COMMANDS = [
    ([0.1], CommandError), ((0.1,), CommandError), ("telescopic", CommandError),
    (5, CommandError), ({"telescopic": "fast"}, CommandError),
    ({"telescopic": None}, CommandError), ({"telescopic": NAN}, CommandError),
    ({"telescopic": INF}, CommandError), ({"telescopic": -INF}, CommandError),
    ({"telescopic": [0.1]}, CommandError), ({"telescopic": True}, CommandError),
    ({"telescopic": 1e6}, ActuatorLimitError), ({"telescopic": -1e300}, ActuatorLimitError),
    ({"telescopic": Command(((1e6, 0.01, 0.0),))}, ActuatorLimitError),
    ({"telescopic": Command(((0.0, 0.01, 1e3),))}, ActuatorLimitError),
    ({"nope": 0.1}, UnknownNameError), ({1: 0.1}, UnknownNameError),
    ({None: 0.0}, UnknownNameError), ({"slew": 0.1}, UnknownNameError),
]
BAD_BUDGETS = [-1.0, 0.0, NAN, "1", True]


def _refused(sim, call, error):
    """call(sim) raises ``error`` within REFUSE_S and leaves the time and the state."""
    before = sim.save_state()
    t0 = time.perf_counter()
    with pytest.raises(error) as info:
        call(sim)
    assert time.perf_counter() - t0 < REFUSE_S
    after = sim.save_state()
    assert after["t"] == before["t"]
    for k in ("y", "L", "v", "q", "qd"):
        if k in before:
            np.testing.assert_array_equal(after[k], before[k])
    assert str(info.value)
    return info.value


@pytest.mark.parametrize("which", ["full", "modal"])
def test_bad_advance_input_is_refused(which, request):
    sim = request.getfixturevalue(which)
    for dt in BAD_DT:
        e = _refused(sim, lambda s: s.advance(dt), CommandError)
        assert "dt =" in str(e)
    for commands, error in BAD_COMMANDS:
        e = _refused(sim, lambda s: s.advance(0.05, commands), error)
        assert isinstance(e, ValueError)
        if error is UnknownNameError:
            assert isinstance(e, KeyError) and "telescopic" in str(e)
    for budget in BAD_BUDGETS:
        e = _refused(sim, lambda s: s.advance(0.05, max_wall_s=budget), CommandError)
        assert "max_wall_s" in str(e)


@pytest.mark.parametrize("which", ["full", "modal"])
def test_bad_outputs_and_snapshots_are_refused(which, request):
    sim = request.getfixturevalue(which)
    for names, error in (("tip_position", CommandError), (5, CommandError),
                         (["nope"], UnknownNameError), ([1], UnknownNameError),
                         ([None], UnknownNameError)):
        _refused(sim, lambda s: s.outputs(names), error)
    good = sim.save_state()
    other = (Simulation("telescopic_extraction_rl") if which == "full" else None)
    bad = [{}, None, [], "state", 5, {"t": 0.0},
           {**good, "t": NAN}, {**good, "t": -1.0}, {**good, "t": "x"}]
    if which == "full":
        bad += [{**good, "y": good["y"][:-1]}, {**good, "y": np.full_like(good["y"], NAN)},
                {**good, "y": "x"}, {**good, "drives": {"nope": None}},
                {**good, "drives": {"telescopic": (0.0, 1.0)}},
                {**good, "drives": {"telescopic": (0.0, NAN, 0.0, Command.accelerate(0.1))}},
                {**good, "drives": [None]}, {**good, "stats": 5},
                other.save_state()]
    else:
        bad += [{**good, "q": good["q"][:-1]}, {**good, "L": INF}, {**good, "qd": "x"},
                {**good, "command": 0.1}]
    for state in bad:
        e = _refused(sim, lambda s: s.restore_state(state), CommandError)
        assert "state" in str(e)
    sim.restore_state(good)                       # a good snapshot still restores


def test_bad_commands_objects_are_refused():
    for segments, end in (("abc", None), (5, None), (((NAN, 1.0, 0.0),), None),
                          (((1.0, INF, 0.0), (0.0, 1.0, 0.0)), None),
                          (((1.0, 1.0, 0.0),), "x"), (((1.0, 1.0, 0.0),), (0.0, NAN)),
                          ((("a", 1.0, 0.0),), None), ([[1.0, -1.0, 0.0]], None)):
        with pytest.raises(CommandError):
            Command(segments, end)


def test_bad_scenes_are_refused():
    """A scene name is loaded (load_scene); anything that is no scene is refused with a typed
    error saying what is expected."""
    assert Simulation("telescopic_extraction_rl").actuators == ("telescopic",)
    for scene, error in ((5, CommandError), (None, CommandError), ([], CommandError),
                         ({}, SceneError), ({"kind": "telescopic"}, CommandError),
                         ("no_such_scene", SceneError), ({"kind": "spaceship"}, SceneError)):
        t0 = time.perf_counter()
        with pytest.raises(error):
            Simulation(scene)
        assert time.perf_counter() - t0 < REFUSE_S
    with pytest.raises(CommandError, match="limits"):
        Simulation("telescopic_extraction_rl", limits="off")


def test_huge_command_with_clip_ends_within_its_budget(full):
    """limits="clip": 1e6 m/s^2 is cut to the stages' limit; the step either completes or ends
    in a SimulationError within its 5 s budget (plus the margin)."""
    sim = Simulation(full.scene, limits="clip")
    t0 = time.perf_counter()
    try:
        sim.advance(0.02, {"telescopic": 1e6}, max_wall_s=5.0)
    except SimulationError:
        pass
    assert time.perf_counter() - t0 < 5.0 + BUDGET_MARGIN_S
    assert sim.clipped == {"telescopic": ("acceleration",)} or sim.t == 0.0


@pytest.mark.parametrize("solver", [{}, {"solver.method": "ROS2", "solver.jacobian_interval": 0.1}],
                         ids=["RK45", "ROS2"])
def test_advance_ends_within_its_wall_budget(solver, full):
    """A 5 s advance (seconds of wall time at this mesh) with max_wall_s = 0.3 s ends in a
    SimulationError naming the budget, at a simulated time inside the step, within the budget
    plus the margin, and leaves the simulation at the step's start: a repeat of the first
    0.05 s gives the state it would have given."""
    sim = full if not solver else Simulation(load_scene(
        "telescopic_extraction", overrides={**FAST, **HOLD, **solver}))
    start = sim.save_state()
    t0 = time.perf_counter()
    with pytest.raises(SimulationError, match="budget") as info:
        sim.advance(5.0, {"telescopic": 0.1}, max_wall_s=0.3)
    assert time.perf_counter() - t0 < 0.3 + BUDGET_MARGIN_S
    assert start["t"] <= info.value.t <= start["t"] + 5.0
    assert sim.t == start["t"]
    np.testing.assert_array_equal(sim.save_state()["y"], start["y"])
    assert sim.save_state()["drives"] == start["drives"]
    sim.advance(0.05, {"telescopic": 0.1})
    assert sim.outputs(["actuators"])["actuators"]["telescopic"][:2] == pytest.approx(
        (2.0 + 0.5 * 0.1 * 0.05 ** 2, 0.1 * 0.05), abs=1e-12)
    sim.restore_state(start)
