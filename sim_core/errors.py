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


class NoStaticEquilibrium(SimulationError):
    """The static equilibrium does not exist at the full load: the equilibrium path in the load
    factor (the weight scaled by lambda) turns back at a limit point (fold) below 1.

    Attributes
    ----------
    load_factor_max : float
        Largest load factor on the traced equilibrium path (the limit load / the full load).
    path : list[tuple[float, float]]
        (load factor, scaled displacement from the unloaded state) of the traced points.
    """

    def __init__(self, t: float, load_factor_max: float, path, reason: str | None = None):
        self.load_factor_max = float(load_factor_max)
        self.path = list(path)
        super().__init__(t, reason or (
            "no static equilibrium: the equilibrium path under the weight turns back at a limit "
            f"point at {self.load_factor_max:.3g} x the full weight (load continuation)"))
