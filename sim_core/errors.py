"""Typed errors of sim_core."""

from __future__ import annotations

import numpy as np


class SceneError(ValueError):
    """Invalid scene input; the message names the field, the value and the allowed range."""


class CommandError(ValueError):
    """A bad call of the stepping API (:class:`sim_core.Simulation`): a scene, a step dt, a
    command, a state snapshot or an output name; the message names the argument, the value and
    what is allowed."""


class UnknownNameError(CommandError, KeyError):
    """A name the simulation does not have: an actuator in ``advance``'s commands or an output in
    ``outputs(names)``; the message lists the names it has."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class ActuatorLimitError(CommandError):
    """A command that would drive an actuator beyond its scene limit (acceleration, rate or end
    stop) under ``Simulation(scene, limits="raise")``.

    Attributes
    ----------
    actuator : str
        The actuator ("telescopic", "luffing", "slew" or "hoist").
    quantity : str
        "acceleration", "rate", "position" or "rate jump".
    value : float
        The commanded value (SI: m, m/s, m/s^2 or rad, rad/s, rad/s^2).
    allowed : tuple[float, float]
        The allowed range of that quantity, same unit.
    """

    def __init__(self, message: str, actuator: str, quantity: str, value: float,
                 allowed: tuple[float, float]):
        self.actuator, self.quantity = actuator, quantity
        self.value, self.allowed = float(value), (float(allowed[0]), float(allowed[1]))
        super().__init__(message)


class ResultFormatError(ValueError):
    """A result file (``result.npz``) that :meth:`sim_core.result.Result.load` cannot read: not a
    result file, truncated or corrupted, or written in a result format this version does not
    read.  The message is one line, ``PATH: what is wrong``.

    Attributes
    ----------
    path : str
        The file.
    problem : str
        What is wrong with it.
    """

    def __init__(self, path, problem: str):
        self.path = str(path)
        self.problem = " ".join(str(problem).split())
        super().__init__(f"{self.path}: {self.problem}")


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


class ElementEvaluationError(SimulationError):
    """The element batch (mass matrices and forces) could not be evaluated at a state: the
    compiled kernel divided by zero or met a non-finite value (e.g. a state far off the
    solution, where a sub-element has collapsed).  Raised on the calling thread also where the
    batch ran on the element worker thread; the integrator treats it as a failed stage
    evaluation (the step is rejected and retried smaller)."""


class StalledIntegration(SimulationError):
    """The integration stopped making progress: its accepted steps stayed so short that the
    rest of the run would take more steps than any run is allowed, or more wall time than its
    budget leaves (see :class:`sim_core.integrate.driver.StallMonitor`).

    Attributes
    ----------
    mean_step : float
        Mean accepted step over the monitored window, s.
    window : int
        Accepted steps in that window.
    """

    def __init__(self, t: float, reason: str, mean_step: float, window: int, step=None,
                 last_state=None):
        self.mean_step = float(mean_step)
        self.window = int(window)
        super().__init__(t, reason, step=step, last_state=last_state)


class SuspectResult(SimulationError):
    """A finished run failed its own result checks (:func:`sim_core.integrate.driver.check_result`) by
    so much that its outputs are not a solution of the model: e.g. its energy grew far beyond
    what the integration tolerance allows while nothing fed energy in.  The result is attached
    as ``.result`` (its ``error`` set), as for a failed solve.

    Attributes
    ----------
    checks : dict
        The failed checks: name -> {"value": ..., "limit": ..., "what": ...}.
    """

    def __init__(self, t: float, reason: str, checks: dict, last_state=None):
        self.checks = dict(checks)
        super().__init__(t, reason, last_state=last_state)


class WallBudgetExhausted(SimulationError):
    """The run spent its wall-clock budget ``solver.max_wall_s`` (:class:`sim_core.run_control.
    RunBudget`: one deadline for the statics, the integration, the outputs, the figures and
    the report).  The outputs reached so far are attached as ``.result`` where there are any.

    Attributes
    ----------
    budget_s : float
        The budget, s.
    phase : str
        The phase that found it spent: ``statics``, ``integration``, ``outputs``,
        ``figures`` or ``report``.
    elapsed_s : float
        Wall seconds spent when it was found, s.
    """

    def __init__(self, t: float, budget_s: float, phase: str, elapsed_s: float, step=None,
                 last_state=None):
        self.budget_s = float(budget_s)
        self.phase = str(phase)
        self.elapsed_s = float(elapsed_s)
        super().__init__(t, f"wall-clock budget solver.max_wall_s = {self.budget_s:g} s "
                            f"exhausted during the {self.phase} ({self.elapsed_s:.3g} s spent)",
                         step=step, last_state=last_state)


class RunInterrupted(SimulationError):
    """The user interrupted the run (Ctrl-C: SIGINT, or KeyboardInterrupt in Python); the
    outputs reached so far are attached as ``.result`` where there are any.

    Attributes
    ----------
    phase : str
        The phase it stopped in (as :class:`WallBudgetExhausted`).

    ``how`` (the message's): ``Ctrl-C`` (the command line's SIGINT handler) or
    ``KeyboardInterrupt`` (raised in Python code of the run).
    """

    def __init__(self, t: float, phase: str, step=None, last_state=None, how: str = "Ctrl-C"):
        self.phase = str(phase)
        super().__init__(t, f"interrupted by the user ({how}) during the {self.phase}",
                         step=step, last_state=last_state)
