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
    assert exc.t > 0.003
    res = exc.result
    assert res.error and "non-finite" in res.error
    assert 1 <= len(res.t) < 11 and res.t[-1] <= exc.t
    assert np.all(np.isfinite(res["tip_position"]))
