"""A failed solve keeps the outputs up to the failure (issue: clean failure handling)."""

import numpy as np
import pytest

from sim_core import SimulationError, load_scene, simulate
from sim_core.model import Model


def test_failure_attaches_partial_result(monkeypatch):
    original = Model.rhs

    def failing_rhs(self, t, y):
        out = original(self, t, y)
        if t > 0.003:
            out = out * np.nan          # a blow-up after a few output times
        return out

    monkeypatch.setattr(Model, "rhs", failing_rhs)
    sc = load_scene("beam_through_sleeve", overrides={
        "solver.t_end": 0.01, "solver.n_output": 11, "effects.filtering": False,
        "beams.0.n_nodes": 5, "initial.static_equilibrium": False})
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
    sc = load_scene("beam_through_sleeve", overrides={
        "solver.t_end": 0.01, "solver.n_output": 11, "effects.filtering": False,
        "beams.0.n_nodes": 5, "initial.static_equilibrium": False})
    res = simulate(sc)
    assert res.error is None and len(res.t) == 11
    # 3 injected failures; the later stages of a failed step start from its huge derivatives and
    # fail too (counted), but every such step is rejected
    assert res.stats["n_failed_rhs"] >= 3
    assert np.all(np.isfinite(res["tip_position"]))
