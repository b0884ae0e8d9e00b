"""Typed errors of sim_core."""

from __future__ import annotations

import numpy as np


class SceneError(ValueError):
    """Invalid scene input; the message names the field, the value and the allowed range."""


class SimulationError(RuntimeError):
    """A solve failed.

    Attributes
    ----------
    t : float
        Simulated time of the failure, s.
    step : float | None
        Last attempted step size, s.
    reason : str
        Human-readable cause.
    last_state : numpy.ndarray | None
        Last good state vector.
    """

    def __init__(self, t: float, reason: str, step: float | None = None,
                 last_state: np.ndarray | None = None):
        self.t = float(t)
        self.step = step
        self.reason = reason
        self.last_state = last_state
        msg = f"simulation failed at t = {self.t:.6g} s: {reason}"
        if step is not None:
            msg += f" (step {step:.3g} s)"
        super().__init__(msg)
