"""A failed solve keeps the outputs up to the failure (issue: clean failure handling)."""

import numpy as np
import pytest

from sim_core import SimulationError, load_scene, simulate
from sim_core.model.model import Model


def _short_sleeve_scene() -> dict:
    """0.01 s of the sleeve scene, 11 outputs, 4 sub-elements, unfiltered, from rest, on RK45
    (the right-hand-side failures below are the explicit method's)."""
    return load_scene("beam_through_sleeve", overrides={
        "solver.method": "RK45", "solver.t_end": 0.01, "solver.n_output": 11,
        "effects.filtering": False,
        "beams.0.n_nodes": 5, "initial.static_equilibrium": False})


def test_failure_attaches_partial_result(monkeypatch):
    original = Model.rhs

    def failing_rhs(self, t, y):
        out = original(self, t, y)
        if t > 0.003:
            out = out * np.nan          # a blow-up after a few output times
        return out

    monkeypatch.setattr(Model, "rhs", failing_rhs)
    sc = _short_sleeve_scene()
    with pytest.raises(SimulationError) as info:
        simulate(sc)
    exc = info.value
    # the steps towards the blow-up are rejected until the step size underflows just before it
    assert exc.t == pytest.approx(0.003, abs=1e-6)
    res = exc.result
    assert res.error and "non-finite" in res.error
    assert 1 <= len(res.t) < 11 and res.t[-1] <= exc.t + 1e-12
    assert np.all(np.isfinite(res["tip_position"]))


def test_failed_stage_evaluation_is_retried_with_a_smaller_step(monkeypatch):
    """A stage evaluation that fails (overflow, NaN) rejects the step instead of aborting: RK45
    retries with a smaller step, and the run completes with the failures counted."""
    original = Model.rhs
    fails = {"left": 3}

    def flaky_rhs(self, t, y):
        out = original(self, t, y)
        if t > 0.003 and fails["left"] > 0:
            fails["left"] -= 1
            return out * np.nan
        return out

    monkeypatch.setattr(Model, "rhs", flaky_rhs)
    sc = _short_sleeve_scene()
    res = simulate(sc)
    assert res.error is None and len(res.t) == 11
    # 3 injected failures; the later stages of a failed step start from its huge derivatives and
    # fail too (counted), but every such step is rejected
    assert res.stats["n_failed_rhs"] >= 3
    assert np.all(np.isfinite(res["tip_position"]))


def test_wall_clock_budget_stops_with_a_partial_result(monkeypatch, tmp_path):
    """solver.max_wall_s: the run stops once the budget is spent, with the typed error naming
    the budget and the outputs reached so far (saved by the CLI, exit status 3)."""
    import time

    from sim_core.cli import main
    from sim_core.result import Result
    original = Model.rhs

    def slow_rhs(self, t, y):
        time.sleep(0.002)               # a deterministic wall-clock cost per evaluation
        return original(self, t, y)

    monkeypatch.setattr(Model, "rhs", slow_rhs)
    over = {"solver.method": "RK45", "solver.t_end": 0.01, "solver.n_output": 11,
            "effects.filtering": False,
            "beams.0.n_nodes": 5, "initial.static_equilibrium": False,
            "solver.max_wall_s": 0.05}
    with pytest.raises(SimulationError) as info:
        simulate(load_scene("beam_through_sleeve", overrides=over))
    exc = info.value
    assert "max_wall_s" in exc.reason and 0.0 < exc.t < 0.01
    assert exc.result is not None and len(exc.result.t) < 11
    sets = [a for k, v in over.items()
            for a in ("--set", f"{k}={str(v).lower() if isinstance(v, bool) else v}")]
    code = main(["run", "beam_through_sleeve", *sets, "--out", str(tmp_path), "--quiet"])
    assert code == 3
    part = Result.load(tmp_path / "result.npz")
    assert part.error and "max_wall_s" in part.error


def test_wall_clock_budget_is_validated():
    from sim_core.errors import SceneError
    for name in ("beam_through_sleeve", "telescopic_extraction", "folding_boom"):
        with pytest.raises(SceneError, match="max_wall_s"):
            load_scene(name, overrides={"solver.max_wall_s": -1.0})


def test_ctrl_c_stops_with_a_partial_result(monkeypatch):
    """Ctrl-C (KeyboardInterrupt inside a right-hand side) ends the run like a budget: a typed
    SimulationError saying so, at the time reached, with the outputs computed so far."""
    original = Model.rhs

    def interrupted_rhs(self, t, y):
        if t > 0.004:
            raise KeyboardInterrupt
        return original(self, t, y)

    monkeypatch.setattr(Model, "rhs", interrupted_rhs)
    sc = _short_sleeve_scene()
    with pytest.raises(SimulationError) as info:
        simulate(sc)
    exc = info.value
    assert "KeyboardInterrupt" in exc.reason and exc.t <= 0.004 + 1e-12
    res = exc.result
    assert res.error and "interrupted" in res.error
    assert 1 <= len(res.t) < 11 and res.t[-1] <= 0.004 + 1e-12
    assert np.all(np.isfinite(res["tip_position"]))
