"""The integration driver: a model's reduced first-order system y = (z, z_dot) from t = 0 to
t_end with RK45, BDF or both switched by stiffness (``solver.method``), a wall-clock budget,
stall detection and partial results.  It knows the model's protocol (``rhs``, ``n_dof``, the
structured Jacobian), never a scene.
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.integrate import BDF, RK45

from sim_core import run_control
from sim_core.checkpoint import object_state, restore_object_state
from sim_core.errors import (
    ElementEvaluationError,
    RunInterrupted,
    SimulationError,
    StalledIntegration,
    WallBudgetExhausted,
)
from sim_core.integrate import _generalized_alpha_numba as ga_numba
from sim_core.integrate.bdf import (
    BDF_NEWTON_ITERATIONS,
    RefreshedJacobian,
    SecondOrderNewtonLU,
    bdf_newton_limit,
)
from sim_core.integrate.checks import check_result, result_checks
from sim_core.integrate.generalized_alpha import GeneralizedAlphaParameters, integrate_generalized_alpha
from sim_core.integrate.rosenbrock import RosenbrockW2
from sim_core.integrate.switching import MethodSwitch
from sim_core.model.model import Model
from sim_core.model.state_jacobian import REL_STEP, state_jacobian
from sim_core.physics import _effects_numba as ec
from sim_core.scene.fields import INTEGRATORS


class _CountingRHS:
    """Wraps model.rhs: counts evaluations.  A stage evaluation that fails (overflow, singular
    KKT matrix, non-finite accelerations) is a *recoverable* failure, as in SUNDIALS: the stage
    returns huge derivatives so that the error estimate rejects the step and RK45 retries with a
    smaller one.  After ``max_failures`` consecutive failed evaluations, or if an accepted state
    is non-finite (checked by the caller), it raises SimulationError with the time and reason."""

    BIG = 1e100
    max_failures = 40

    def __init__(self, model):
        self.model = model
        self.nfev = 0
        self.jac_cost = 0.0          # structured Jacobians, in right-hand-side equivalents
        self.n_jacobians = 0         # structured Jacobians
        self.n_refreshes = 0         # their non-smooth columns refreshed (RefreshedJacobian)
        self.last_t = 0.0
        self.failures = 0
        self.n_failed = 0
        self.last_reason = ""

    def __call__(self, t, y):
        self.nfev += 1
        self.last_t = t
        reason = None
        try:
            with np.errstate(over="raise", divide="raise", invalid="raise", under="ignore"):
                out = self.model.rhs(t, y)
            if not np.all(np.isfinite(out)):
                reason = "non-finite accelerations"
        except (FloatingPointError, np.linalg.LinAlgError) as exc:
            reason = f"non-finite or singular dynamics: {exc}"
        except ElementEvaluationError as exc:       # on the worker thread or this one
            reason = exc.reason
        except (ZeroDivisionError, OverflowError) as exc:
            reason = f"element or constraint evaluation failed: {type(exc).__name__}: {exc}"
        if reason is None:
            self.failures = 0
            return out
        return self._failed(t, y, reason)

    @property
    def cost(self) -> float:
        """Model work so far in right-hand-side evaluations (Jacobians included)."""
        return self.nfev + self.jac_cost

    def jacobian(self, t, y):
        """Structured Jacobian (:mod:`sim_core.model.state_jacobian`) for BDF, its cost counted."""
        try:
            with np.errstate(over="raise", divide="raise", invalid="raise", under="ignore"):
                J, cost = state_jacobian(self.model, t, y, return_cost=True)
            if not np.all(np.isfinite(J)):
                raise FloatingPointError("non-finite Jacobian entries")
        except (FloatingPointError, np.linalg.LinAlgError, ZeroDivisionError, OverflowError,
                ElementEvaluationError) as exc:
            why = exc.reason if isinstance(exc, SimulationError) else exc
            raise SimulationError(t, f"Jacobian evaluation failed: {why}", last_state=y) from None
        self.jac_cost += cost
        self.n_jacobians += 1
        return J

    def _failed(self, t, y, reason):
        self.failures += 1
        self.n_failed += 1
        self.last_reason = reason
        if self.failures > self.max_failures:
            raise SimulationError(t, f"{reason} ({self.failures} consecutive failed stage "
                                     "evaluations; step size could not recover)", last_state=y)
        return np.full(len(y), self.BIG)


class StallMonitor:
    """Raises :class:`StalledIntegration` when the run cannot finish at the pace of its last
    ``window`` accepted steps:

    * their mean step is below ``t_end / max_steps`` (a pace at which the whole run would take
      more than ``max_steps`` steps), or
    * with a wall-clock budget ``budget`` (s): the integration has run for at least
      ``min_budget_share`` of it and the remaining simulated time, at the window's pace in
      simulated seconds per wall second, would take more than ``overrun`` times the budget
      left (the run's: ``spent`` counts the statics before the integration too) -- the
      budget would run out anyway, so the run stops now, naming the stall, instead of at
      the budget.

    Why these numbers.  ``max_steps`` = 1e6 is ~400 times the shipped scenes' step counts (the
    paper's extraction: 2477 steps for 20 s, its retraction 11311) and 10 min to hours of wall
    time at 0.1-1 ms per model evaluation.  Healthy runs do shorten their steps at events
    (friction sticking and slipping, contact changes), but for tens of steps: the paper run's
    smallest step is 5e-6 s (2.5e-7 t_end), while its shortest mean over 1000 accepted steps
    is 8.8e-3 s (4.4e-4 t_end, 440 times the floor; ``min_window_mean_step_s`` in the
    statistics); a mean over ``window`` = 1000 accepted steps ignores such dips and still
    fires within about 1000 steps of a collapse.  The budget test
    starts after 10 % of the budget (the pace of the first steps, compiled code loading and
    the initial transient, is no guide) and asks for a threefold overrun, so that a run whose
    pace recovers later (a stiff stretch that ends) is not stopped: the stalls it is for are
    ten to a hundred times too slow (the 2-sub-element rod drawn through the sleeve without
    the stress filter, BDF at rtol 1e-4: steps of ~1e-5 s against 8 s to go, 0.65 s simulated
    in 120 s of wall time).  The last step of a run (cut to land on t_end) is not
    monitored."""

    window = 1000
    max_steps = 1e6
    min_budget_share = 0.1
    overrun = 3.0

    def __init__(self, t_end: float, window: int | None = None, max_steps: float | None = None,
                 budget: float | None = None, wall0: float | None = None, spent=None):
        self.window = int(window or self.window)
        self.max_steps = float(max_steps or self.max_steps)
        self.t_end = float(t_end)
        self.floor = self.t_end / self.max_steps
        self.budget = budget
        self.wall0 = time.perf_counter() if wall0 is None else wall0
        # wall seconds of the budget spent (the run's, run_control.RunBudget.elapsed: the
        # statics before the integration count); default: since wall0
        self.spent = spent if spent is not None else (lambda: time.perf_counter() - self.wall0)
        self.times = np.zeros(self.window)       # t after each of the last accepted steps
        self.walls = np.zeros(self.window)       # wall clock then
        self.k = 0
        self.slowest = math.inf          # smallest window mean step so far, s

    def update(self, solver) -> None:
        """Call after every accepted step that is not the last one."""
        i = self.k % self.window
        t_old = self.times[i] if self.k >= self.window else 0.0
        wall_old = self.walls[i] if self.k >= self.window else self.wall0
        now = time.perf_counter()
        self.times[i], self.walls[i] = solver.t, now
        self.k += 1
        n = min(self.k, self.window)
        if self.k >= self.window:
            mean = (solver.t - t_old) / n
            self.slowest = min(self.slowest, mean)
            if mean < self.floor:
                self._raise(solver, "integration stalled", mean, n,
                            f"below t_end / {self.max_steps:.0e} = {self.floor:.3g} s")
        # the test starts once the integration itself has run for 10 % of the budget (its
        # first steps are no guide to its pace); the budget left is the run's
        if self.budget is not None and now - self.wall0 >= self.min_budget_share * self.budget:
            spent = self.spent()
            pace = (solver.t - t_old) / max(now - wall_old, 1e-9)   # simulated s per wall s
            need = (self.t_end - solver.t) / max(pace, 1e-300)
            left = self.budget - spent
            if 0.0 < left < need / self.overrun:       # (spent: the budget's own error)
                self._raise(solver, "integration too slow for its wall-clock budget",
                            (solver.t - t_old) / n, n,
                            f"a pace at which the remaining {self.t_end - solver.t:.3g} s would "
                            f"take ~{need:.3g} s of wall time, more than {self.overrun:g} x the "
                            f"{left:.3g} s left of solver.max_wall_s = {self.budget:g} s",
                            "either the steps are too short (")

    def _raise(self, solver, what: str, mean: float, n: int, why: str, lead: str = "("):
        rest = self.t_end - solver.t
        hint = ("stiff or non-smooth dynamics the method cannot follow at this tolerance: try "
                "another solver.method or rtol, or the stress filter)")
        if lead != "(":
            hint += " or the budget is too small for this scene"
        raise StalledIntegration(
            solver.t, f"{what}: the last {n} accepted steps averaged {mean:.3g} s "
            f"(~{rest / max(mean, 1e-300):.2g} more steps to t_end), {why}; {lead}{hint}",
            mean_step=mean, window=n, step=solver.t - solver.t_old, last_state=solver.y)


def integrate(model, y0: np.ndarray, t_end: float, sol: dict, progress=None, checkpoint=None):
    """Integrate model.rhs from t = 0 with dense output at ``sol["n_output"]`` equally spaced
    times.  ``sol["method"]``:

    * ``"RK45"`` (default): scipy's explicit Dormand-Prince pair — cheapest per step while the
      step size is set by accuracy;
    * ``"BDF"``: scipy's variable-order BDF — for stiff runs (sticking friction, stiff contact).
      Its Jacobian (``sol["jacobian"]``): ``"structured"`` (default for :class:`sim_core.model.model.
      Model`) by implicit differentiation with local differences (:mod:`sim_core.
      state_jacobian`, ~1/6 of the cost at the paper's discretisation), or
      ``"finite_difference"``: scipy's differences of the whole right-hand side (one model.rhs
      per state per Jacobian);
    * ``"generalized_alpha"``: the implicit second-order method (:func:`integrate_alpha`),
      error-controlled by rtol/atol, or at the fixed step ``sol["h"]`` where given — for beam
      models without friction switching, where the explicit step is stability-limited by the
      stiffest bending mode;
    * ``"ROS2"``: the Rosenbrock-W method at the fixed step ``sol["h"]`` with the structured
      Jacobian renewed every ``sol["jacobian_interval"]`` s (:func:`integrate_ros2`) — the
      training integrator: few right-hand sides per step, error not controlled;
    * ``"auto"``: RK45 and BDF alternate as :class:`MethodSwitch` decides (RK45 -> BDF when
      :class:`StiffnessDetector` finds the step stability-limited, back to RK45 after a
      stretch whose length adapts to which method was cheaper; with a model's
      ``friction_in_slope_band``, BDF only while it is True); the statistics record the
      number of switches, the first switch to BDF and the stiffness alarms that kept RK45.

    Returns (t, y, stats); raises SimulationError with the time, step and last good state on
    failure or non-finite values, :class:`~sim_core.errors.WallBudgetExhausted` when the run's
    wall-clock budget is spent (the ambient :class:`sim_core.run_control.RunBudget`: the whole
    run's ``solver.max_wall_s``, statics included; outside a run ``sol["max_wall_s"]`` from the
    integration's start), :class:`~sim_core.errors.RunInterrupted` on Ctrl-C (the budget's
    interrupt flag, or KeyboardInterrupt), and :class:`StalledIntegration` where the
    steps cannot finish the run (:class:`StallMonitor`: within ``sol["stall_max_steps"]``
    steps, default 1e6, or the budget); the outputs reached so far are attached, so a
    budgeted, stalled or interrupted run still yields a partial result.  The statistics
    include rtol, atol, the shortest mean step over the stall monitor's window and, for a
    :class:`sim_core.model.model.Model`, its element worker's governor
    (:meth:`sim_core.model.workers.Governor.summary`).

    ``checkpoint``: a :class:`sim_core.checkpoint.Checkpointer` or None.  Where it holds a
    checkpoint of this path the run continues from it (:func:`_restore_scipy`); after every
    accepted step that is not the last, once its interval is due, the whole state is written
    (:func:`_scipy_snapshot`: scipy's solver object without its callables, the method
    switch, the stall monitor, the counters, the outputs so far and the model's warm
    starts), so a resumed run takes the same steps and its result is bit-identical."""
    method = sol.get("method", "RK45")
    if method not in INTEGRATORS:
        raise ValueError(f"solver.method = {method!r}: must be one of {INTEGRATORS}")
    if method == "generalized_alpha":
        return integrate_alpha(model, y0, t_end, sol, progress, checkpoint)
    if method == "ROS2":
        return integrate_ros2(model, y0, t_end, sol, progress, checkpoint)
    t_eval = np.linspace(0.0, t_end, sol["n_output"])
    rhs = _CountingRHS(model)
    kwargs = {"max_step": sol["max_step"]} if "max_step" in sol else {}
    rb = run_control.for_solver(sol.get("max_wall_s"))      # the run's deadline
    wall0 = time.perf_counter()
    tol = {"rtol": sol["rtol"], "atol": sol["atol"]}

    structured = sol.get("jacobian", "structured") == "structured" and isinstance(model, Model)

    steps = []
    stretch = {}              # the current BDF stretch's RefreshedJacobian

    def make(cls, t0, y):
        if cls is BDF and structured:
            stretch["jac"] = RefreshedJacobian(rhs)
            s = cls(rhs, t0, y, t_end, jac=stretch["jac"], **tol, **kwargs)
            stretch["jac"].watch(s)
            newton = SecondOrderNewtonLU(s)             # Newton matrix by its Schur complement
            s.lu, s.solve_lu = newton.lu, newton.solve_lu
            return s
        return cls(rhs, t0, y, t_end, **tol, **kwargs)

    saved = checkpoint.take("scipy") if checkpoint is not None else None
    if saved is None:
        solver = make(BDF if method == "BDF" else RK45, 0.0, y0)
    else:                     # a fresh solver of the saved class; its state follows below
        solver = make(BDF if saved["solver_class"] == "BDF" else RK45, saved["solver"]["t"],
                      np.array(saved["solver"]["y"], dtype=float))
    # at a BDF stretch's end a fresh Jacobian tells whether RK45 could take BDF's steps; where
    # it costs less than the RK45 trial it replaces (~100 evaluations): the structured one
    # (through the stretch's RefreshedJacobian: its friction columns refreshed, where the
    # stiffness of a sticking contact is; the stress filter's eigenvalue pair is constant), or
    # finite differences of a small system
    probe = structured or len(y0) <= 100
    fresh = (lambda s: stretch["jac"](s.t, s.y)) if structured else (lambda s: s.jac(s.t, s.y))
    n = len(y0) // 2
    in_band = getattr(model, "friction_in_slope_band", None)
    band = (lambda t, y: in_band(t, y[:n], y[n:])) if in_band is not None else None
    switch = MethodSwitch(rhs, fresh_jacobian=fresh if probe else None, stiff_friction=band) \
        if method == "auto" else None
    njev = 0                  # Jacobians of BDF solvers already replaced by a switch
    nlu = 0                   # and their LU factorisations of the Newton matrix
    newton_limit = bdf_newton_limit(sol.get("bdf_newton_iterations", BDF_NEWTON_ITERATIONS))
    ys = [y0]
    k_out = 1
    stall = StallMonitor(t_end, sol.get("stall_window"), sol.get("stall_max_steps"),
                         rb.max_wall_s, wall0, spent=rb.elapsed)
    if saved is not None:
        ys, k_out, steps, njev = list(saved["ys"]), int(saved["k_out"]), list(saved["steps"]), \
            int(saved["njev"])
        nlu = int(saved.get("nlu", 0))
        wall0 = time.perf_counter() - float(saved["wall_s"])
        rb.credit(float(saved["wall_s"]))
        _restore_scipy(saved, solver, stretch.get("jac") if isinstance(solver, BDF) else None,
                       switch, stall, rhs, model, wall0)

    def snapshot():
        return {**_scipy_snapshot(solver, stretch.get("jac") if isinstance(solver, BDF) else None,
                                  switch, stall, rhs, model, ys, k_out, steps, njev,
                                  time.perf_counter() - wall0), "nlu": nlu}

    def stats():
        wall = time.perf_counter() - wall0
        # the smallest accepted step, not counting the last one of a finished run: the solver
        # cuts that one to land on t_end, so its length is set by where t_end falls, not by the
        # dynamics (a run whose steps collapse elsewhere still shows it)
        inner = steps[:-1] if solver.status == "finished" and len(steps) > 1 else steps
        out = {"wall_time_s": wall, "n_steps": len(steps), "n_rhs": int(rhs.nfev),
               "n_failed_rhs": int(rhs.n_failed),
               "min_step_s": float(min(inner)) if inner else 0.0,
               "max_step_s": float(max(steps)) if steps else 0.0,
               "method": method, "real_time_factor": t_end / max(wall, 1e-12),
               "rtol": float(np.max(sol["rtol"])), "atol": float(np.max(sol["atol"]))}
        if math.isfinite(stall.slowest):    # the shortest mean step over StallMonitor's window
            out["min_window_mean_step_s"] = float(stall.slowest)
        if isinstance(model, Model) and "_governor" in model.__dict__:
            out.update(model.governor().summary())
        if method != "RK45":
            if structured:      # whole ones, their work in right-hand sides (element
                # evaluations / elements), and refreshes of their non-smooth columns (their
                # right-hand sides are in n_rhs)
                out["n_jacobians"] = rhs.n_jacobians
                out["jacobian_cost_rhs"] = float(rhs.jac_cost)
                out["n_jacobian_refreshes"] = rhs.n_refreshes
            else:
                out["n_jacobians"] = njev + int(getattr(solver, "njev", 0))
            # LU factorisations of BDF's Newton matrix (scipy's nlu, RefreshedJacobian's included)
            out["n_lu"] = nlu + int(getattr(solver, "nlu", 0))
        if switch is not None:
            out["n_method_switches"] = len(switch.switches)
            out["n_bdf_kept"] = switch.kept_bdf     # stretch ends without a hand-back trial
            out["n_rk45_kept"] = switch.kept_rk45   # stiffness alarms outside the friction band
            out["first_switch_to_bdf_s"] = switch.switches[0][0] if switch.switches else -1.0
            out["last_switch_s"] = switch.switches[-1][0] if switch.switches else -1.0
        if checkpoint is not None:
            out.update(checkpoint.stats())
        return out

    try:
        while solver.status == "running":
            if isinstance(solver, BDF):
                with newton_limit:
                    msg = solver.step()
                if structured:
                    stretch["jac"].after_step()
            else:
                msg = solver.step()
            if solver.status == "failed" or not np.all(np.isfinite(solver.y)):
                why = (f" after {rhs.failures} failed stage evaluations ({rhs.last_reason})"
                       if rhs.failures else "")
                name = "BDF" if isinstance(solver, BDF) else "RK45"
                raise SimulationError(solver.t, f"{name} failed: {msg}{why}", step=solver.step_size,
                                      last_state=solver.y)
            steps.append(solver.t - solver.t_old)
            if solver.status == "running":
                stall.update(solver)
            if k_out < len(t_eval) and t_eval[k_out] <= solver.t:
                dense = solver.dense_output()
                while k_out < len(t_eval) and t_eval[k_out] <= solver.t:
                    ys.append(dense(t_eval[k_out]))
                    k_out += 1
            if progress is not None:
                progress(solver.t, time.perf_counter() - wall0)
            if solver.status == "running":      # the run's budget and Ctrl-C
                rb.check("integration", solver.t, solver.step_size, solver.y)
            if switch is not None and solver.status == "running":
                old = solver
                solver = switch.after_step(solver, make)
                if solver is not old:
                    njev += int(getattr(old, "njev", 0))
                    nlu += int(getattr(old, "nlu", 0))
            if checkpoint is not None and solver.status == "running" and checkpoint.due():
                checkpoint.save("scipy", solver.t, snapshot())
    except KeyboardInterrupt:              # Ctrl-C keeps what was computed, like a budget
        exc = RunInterrupted(solver.t, "integration", step=solver.step_size,
                             last_state=solver.y, how="KeyboardInterrupt")
        exc.partial = (t_eval[:len(ys)], np.array(ys), stats())
        raise exc from None
    except SimulationError as exc:
        # keep what was computed: the caller turns it into a partial Result (exc.result)
        exc.partial = (t_eval[:len(ys)], np.array(ys), stats())
        raise
    return t_eval[:len(ys)], np.array(ys), stats()


# -- checkpoints (sim_core.checkpoint) -------------------------------------------------------

def warm_starts(model) -> dict:
    """The model's state between right-hand sides that the next one starts from: the
    multiplier Newton's last solution (``Model._multiplier_newton``) and every multiplier
    force's warm start (the friction regions' micro-motions, ``ContactFriction._x0``).  The
    converged values depend on them only to the Newton's stopping error, but a bit-identical
    resume needs them."""
    out = {"g": getattr(model, "__dict__", {}).get("_g_warm")}
    for k, mf in enumerate(getattr(model, "multiplier_forces", ())):
        if hasattr(mf, "_x0"):
            out[f"x0_{k}"] = mf._x0
    return out


def restore_warm_starts(model, warm: dict) -> None:
    """Put back :func:`warm_starts`."""
    if hasattr(model, "__dict__"):
        if warm.get("g") is None:
            model.__dict__.pop("_g_warm", None)
        else:
            model.__dict__["_g_warm"] = warm["g"]
    for k, mf in enumerate(getattr(model, "multiplier_forces", ())):
        if f"x0_{k}" in warm:
            mf._x0 = dict(warm[f"x0_{k}"])


_RHS_SKIP = ("model",)
_SWITCH_SKIP = ("rhs", "fresh_jacobian", "stiff_friction", "detector")
_JAC_SKIP = ("rhs", "solver", "cols")


def _stall_state(stall: StallMonitor) -> dict:
    """A stall monitor's window, its wall clocks relative to the run's start."""
    return {"times": stall.times, "walls": stall.walls - stall.wall0, "k": stall.k,
            "slowest": stall.slowest}


def _restore_stall(stall: StallMonitor, st: dict, wall0: float) -> None:
    """Put back :func:`_stall_state` for a run whose wall clock starts at ``wall0``."""
    stall.times[:] = st["times"]
    stall.walls[:] = st["walls"] + wall0
    stall.wall0, stall.k, stall.slowest = wall0, int(st["k"]), st["slowest"]


def _scipy_snapshot(solver, jac, switch, stall, rhs, model, ys, k_out, steps, njev,
                    wall_s) -> dict:
    """The state of :func:`integrate` after an accepted step (a checkpoint's body): scipy's
    solver without its callables (t, y, step size, error history; RK45's stages and last
    derivative; BDF's difference array, order, Jacobian, its LU and Newton tolerance), the
    BDF stretch's :class:`RefreshedJacobian`, the :class:`MethodSwitch` with its detector,
    the stall monitor's window (wall clocks relative to the run's start), the counters, the
    outputs so far and the model's warm starts."""
    return {"solver_class": "BDF" if isinstance(solver, BDF) else "RK45",
            "solver": object_state(solver, ("I",)),      # BDF's identity: the fresh one's
            "jac": object_state(jac, _JAC_SKIP) if jac is not None else None,
            "switch": None if switch is None else {
                **object_state(switch, _SWITCH_SKIP), "detector": vars(switch.detector)},
            "stall": _stall_state(stall),
            "rhs": object_state(rhs, _RHS_SKIP), "warm": warm_starts(model),
            "ys": np.array(ys), "k_out": k_out, "steps": list(steps), "njev": njev,
            "wall_s": wall_s}


def _restore_scipy(saved: dict, solver, jac, switch, stall, rhs, model, wall0: float) -> None:
    """Put a :func:`_scipy_snapshot` back onto fresh objects (the solver made at the saved t
    and y, whose own callables stay).  The counters and warm starts go last: building the
    fresh solver evaluated the model."""
    restore_object_state(solver, saved["solver"])
    if jac is not None and saved["jac"] is not None:
        restore_object_state(jac, saved["jac"])
    if switch is not None and saved["switch"] is not None:
        st = dict(saved["switch"])
        restore_object_state(switch.detector, st.pop("detector"))
        restore_object_state(switch, st)
    _restore_stall(stall, saved["stall"], wall0)
    restore_object_state(rhs, saved["rhs"])
    restore_warm_starts(model, saved["warm"])


def run_with_partial(integrate, collect, check=None):
    """integrate() -> (t, y, stats); collect(t, y, stats, error) -> Result.  On a
    SimulationError the outputs up to the failure are collected and attached as exc.result.
    A finished run is checked (:func:`check_result`; ``check(result)``: the scene kind's own
    checks, a dict as :func:`result_checks` returns): the verdict goes into its statistics,
    and a gross failure raises :class:`SuspectResult` with the result attached."""
    try:
        ts, ys, st = integrate()
    except SimulationError as exc:
        part = getattr(exc, "partial", None)
        if part is not None and len(part[0]):
            exc.result = collect(*part, str(exc))
        raise
    res = collect(ts, ys, st, None)
    # the result's own checks evaluate it again: not where the run's budget is spent
    late = run_control.current().exceeded("outputs", float(res.t[-1]) if len(res.t) else 0.0)
    if late is not None:
        res.error = str(late)
        late.result = res
        raise late
    checks = result_checks(res)
    if check is not None:
        try:
            checks.update(check(res))
        except (WallBudgetExhausted, RunInterrupted) as exc:   # the checks' loops check it
            res.error = str(exc)
            exc.result = res
            raise
    return check_result(res, checks)


class StructuredTangent:
    """A model as the SecondOrderSystem of :func:`integrate_generalized_alpha` with its tangent
    from the structured state Jacobian (:func:`sim_core.model.state_jacobian.state_jacobian`):
    dz_ddot/dz = -M^-1 K and dz_ddot/dz_dot = -M^-1 C, so K = -M J_zz and C = -M J_zv."""

    def __init__(self, model):
        self.model = model
        self.n = model.n_dof

    def mass_and_force(self, t, q, v):
        return self.model.mass_and_force(t, q, v)

    def tangent(self, t, q, v):
        n = self.model.n_dof
        J = state_jacobian(self.model, t, np.concatenate([q, v]))
        M, _ = self.model.mass_and_force(t, q, v)
        return -M @ J[n:, :n], -M @ J[n:, n:]


def integrate_alpha(model, y0: np.ndarray, t_end: float, sol: dict, progress=None,
                    checkpoint=None):
    """Generalized-alpha (Chung & Hulbert 1993; Arnold & Bruels 2007) from y0 = (z0, z_dot0)
    at t = 0 with outputs at ``sol["n_output"]`` equally spaced times; the contract of
    :func:`integrate`.  Solver keys: ``rho_inf`` (spectral radius at infinity, [0, 1]),
    ``newton_atol`` (m, the position error the Newton iteration may leave per step) and

    * ``h`` given (s): the fixed-step method, each output interval cut into equal steps of at
      most h (:func:`_alpha_fixed`);
    * no ``h``: error-controlled steps (:func:`_alpha_adaptive`) from ``rtol``/``atol``, with
      the optional largest step ``h_max`` (s).

    Where :meth:`sim_core.model.model.Model.element_loop_plan` covers the model, the steps run
    in compiled calls (:mod:`sim_core.integrate._generalized_alpha_numba`) with the tangent
    formed once and reused across steps; otherwise the numpy method
    (:func:`integrate_generalized_alpha`) with the structured tangent.  The wall budget
    ``max_wall_s`` and the progress callback are served between compiled calls (or after
    every numpy step); a failed Newton iteration, a step below its floor, a stall or the
    budget raise SimulationError (StalledIntegration for a stall) with the outputs so far.

    ``checkpoint`` (:class:`sim_core.checkpoint.Checkpointer` or None): the compiled paths
    write the whole loop state between compiled calls (accelerations, auxiliary
    accelerations, iteration matrix, tangent, step controller, counters, outputs), the numpy
    path after accepted steps (:func:`integrate_generalized_alpha`'s ``checkpoint``), and both
    resume from it bit-identically."""
    if sol.get("h") is None:
        return _alpha_adaptive(model, y0, t_end, sol, progress, checkpoint)
    return _alpha_fixed(model, y0, t_end, sol, progress, checkpoint)


def _alpha_fixed(model, y0: np.ndarray, t_end: float, sol: dict, progress=None,
                 checkpoint=None):
    """Generalized-alpha at the fixed step ``sol["h"]`` (:func:`integrate_alpha`); checkpoints
    after whole output intervals."""
    n = model.n_dof
    t_eval = np.linspace(0.0, t_end, sol["n_output"])
    h, rho = float(sol["h"]), float(sol.get("rho_inf", 0.9))
    newton_atol = float(sol.get("newton_atol", 1e-8))
    rb = run_control.for_solver(sol.get("max_wall_s"))      # the run's deadline
    wall0 = time.perf_counter()
    p = GeneralizedAlphaParameters.from_rho_inf(rho)
    plan = model.element_loop_plan() if isinstance(model, Model) else None
    ys = [np.array(y0, dtype=float)]
    counts = np.zeros(6, dtype=np.int64)       # steps, residuals, Newton its, tangents, LUs, fails
    h_used = []

    def stats():
        wall = time.perf_counter() - wall0
        return {"wall_time_s": wall, "n_steps": int(counts[0]), "n_rhs": int(counts[1]),
                "n_newton_iterations": int(counts[2]), "n_jac": int(counts[3]),
                "n_lu": int(counts[4]), "n_newton_failures": int(counts[5]),
                "min_step_s": min(h_used) if h_used else h, "max_step_s": max(h_used) if h_used else h,
                "method": "generalized_alpha", "rho_inf": rho, "h": h,
                "newton_atol": newton_atol, "compiled": plan is not None,
                "real_time_factor": float(t_eval[len(ys) - 1]) / max(wall, 1e-12),
                **(checkpoint.stats() if checkpoint is not None else {})}

    def fail(t, reason, step):
        exc = SimulationError(t, reason, step=step, last_state=ys[-1])
        exc.partial = (t_eval[:len(ys)], np.array(ys), stats())
        return exc

    if plan is None:
        saved = checkpoint.take("alpha_numpy_fixed") if checkpoint is not None else None
        if saved is not None:
            wall0 = time.perf_counter() - float(saved["wall_s"])
            rb.credit(float(saved["wall_s"]))

        def hook(get):
            if checkpoint.due():
                st = get()
                checkpoint.save("alpha_numpy_fixed", float(st["ga"]["t"]), {
                    "ga": st, "warm": warm_starts(model), "wall_s": time.perf_counter() - wall0})

        def each_step(t, hh, q, v):        # the run's budget and Ctrl-C after every step
            if t < t_end:
                rb.check("integration", t, hh, np.concatenate([q, v]))

        try:
            r = integrate_generalized_alpha(
                StructuredTangent(model), (0.0, t_end), y0[:n], y0[n:], h=h, rho_inf=rho,
                atol=newton_atol, t_eval=t_eval, callback=each_step,
                checkpoint=hook if checkpoint is not None else None,
                resume=saved["ga"] if saved is not None else None,
                on_resume=(lambda: restore_warm_starts(model, saved["warm"])) if saved else None)
        except SimulationError as exc:
            part = getattr(exc, "partial_output", None)       # the outputs reached
            exc.partial = ((part[0], np.hstack([part[1], part[2]]), stats()) if part is not None
                           and len(part[0]) else (t_eval[:1], np.array(ys), stats()))
            raise
        st = r.stats
        counts[:] = (st.n_steps, st.n_force_evaluations, st.n_newton_iterations,
                     st.n_jacobian_evaluations, st.n_lu, st.n_newton_failures)
        h_used.append(h)
        ys = list(np.hstack([r.q, r.v]))
        if progress is not None:
            progress(t_end, time.perf_counter() - wall0)
        return t_eval, np.array(ys), stats()

    q, v = np.array(y0[:n], dtype=float), np.array(y0[n:], dtype=float)
    saved = checkpoint.take("alpha_fixed") if checkpoint is not None else None
    if saved is None:
        qdd, a = _initial_accelerations(plan, q, v)
        Sinv, qdd_prev, carry = np.empty((n, n)), qdd.copy(), np.array([0.0, 1.0])
        out = np.empty((2, n)), np.empty((2, n)), np.empty((2, n))
        k0 = 1
    else:                          # the loop state after output interval k0 - 1
        q, v, qdd, a, Sinv, qdd_prev, carry = (np.array(saved[x], dtype=float) for x in (
            "q", "v", "qdd", "a", "Sinv", "qdd_prev", "carry"))
        out = tuple(np.array(x, dtype=float) for x in saved["out"])
        counts[:] = saved["counts"]
        ys, h_used, k0 = list(saved["ys"]), list(saved["h_used"]), int(saved["k"])
        wall0 = time.perf_counter() - float(saved["wall_s"])
        rb.credit(float(saved["wall_s"]))
    chunk = 1                  # steps per compiled call, grown to ~0.05 s of wall time
    for k in range(k0, len(t_eval)):
        span = t_eval[k] - t_eval[k - 1]
        m = max(1, math.ceil(span / h * (1.0 - 1e-12)))
        hh = span / m
        h_used.append(hh)
        # the interval's m steps in calls of ``chunk`` steps, sized to ~0.05 s of wall time,
        # so the budget is served within an interval too (the loop state carries over from
        # call to call: the steps are those of one call)
        i = 0
        while i < m:
            c = min(m - i, chunk)
            tic = time.perf_counter()
            try:
                code, done = ga_numba.run_steps(
                    q, v, qdd, a, c, hh, p.alpha_m, p.alpha_f, p.beta, p.gamma, newton_atol, 8,
                    0.3, REL_STEP, c, 0.0, plan.Qp, plan.rows, plan.sgn, plan.eidx, plan.red,
                    plan.sg, *plan.kernel_args, ec.NO_ACC, *out, counts, Sinv, qdd_prev, carry)
            except _KERNEL_ERRORS as exc:
                raise fail(float(t_eval[k - 1] + i * hh), "generalized-alpha: the element "
                           f"evaluation failed ({type(exc).__name__}: {exc}); reduce solver.h",
                           hh) from None
            if code != ga_numba.OK or not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
                raise fail(float(t_eval[k - 1] + (i + done) * hh), "generalized-alpha: the "
                           "Newton iteration failed with a fresh tangent (or the state is not "
                           "finite); reduce solver.h", hh)
            i += c
            chunk = max(1, min(10 ** 6, int(0.05 * c / max(time.perf_counter() - tic, 1e-9))))
            if i < m:
                exc = rb.exceeded("integration", float(t_eval[k - 1] + i * hh), hh,
                                  np.concatenate([q, v]))
                if exc is not None:
                    exc.partial = (t_eval[:len(ys)], np.array(ys), stats())
                    raise exc
        ys.append(np.concatenate([q, v]))
        if progress is not None:
            progress(float(t_eval[k]), time.perf_counter() - wall0)
        if k < len(t_eval) - 1:
            exc = rb.exceeded("integration", float(t_eval[k]), hh, ys[-1])
            if exc is not None:
                exc.partial = (t_eval[:len(ys)], np.array(ys), stats())
                raise exc
        if checkpoint is not None and k < len(t_eval) - 1 and checkpoint.due():
            checkpoint.save("alpha_fixed", float(t_eval[k]), {
                "q": q, "v": v, "qdd": qdd, "a": a, "Sinv": Sinv, "qdd_prev": qdd_prev,
                "carry": carry, "out": out, "counts": counts, "ys": np.array(ys),
                "h_used": list(h_used), "k": k + 1, "wall_s": time.perf_counter() - wall0})
    return t_eval, np.array(ys), stats()


def integrate_ros2(model, y0: np.ndarray, t_end: float, sol: dict, progress=None,
                   checkpoint=None):
    """ROS2 (:class:`sim_core.integrate.rosenbrock.RosenbrockW2`) at the fixed step
    ``sol["h"]``: each output interval in equal steps of at most h, the Jacobian renewed every
    ``sol["jacobian_interval"]`` s; the wall budget and checkpoints after whole output
    intervals (a resumed run takes the same steps with the same Jacobian)."""
    t_eval = np.linspace(0.0, t_end, sol["n_output"])
    rb = run_control.for_solver(sol.get("max_wall_s"))      # the run's deadline
    wall0 = time.perf_counter()
    ros = RosenbrockW2(model, float(sol["h"]), float(sol["jacobian_interval"]))
    ys, k0 = [np.array(y0, dtype=float)], 1
    saved = checkpoint.take("ros2") if checkpoint is not None else None
    if saved is not None:
        ys, k0 = list(saved["ys"]), int(saved["k"])
        ros.restore(saved["ros2"])
        restore_warm_starts(model, saved["warm"])
        wall0 = time.perf_counter() - float(saved["wall_s"])
        rb.credit(float(saved["wall_s"]))

    def stats():
        wall = time.perf_counter() - wall0
        return {"wall_time_s": wall, **ros.stats, "method": "ROS2", "h": ros.h,
                "jacobian_interval": ros.interval,
                "real_time_factor": float(t_eval[len(ys) - 1]) / max(wall, 1e-12),
                **(checkpoint.stats() if checkpoint is not None else {})}

    def fail(exc: SimulationError) -> SimulationError:
        exc.partial = (t_eval[:len(ys)], np.array(ys), stats())
        return exc

    for k in range(k0, len(t_eval)):
        try:
            ys.append(ros.advance(float(t_eval[k - 1]), ys[-1], float(t_eval[k] - t_eval[k - 1])))
        except SimulationError as exc:
            raise fail(exc) from None
        except KeyboardInterrupt:
            raise fail(RunInterrupted(float(t_eval[k - 1]), "integration", step=ros.h,
                                      last_state=ys[-1], how="KeyboardInterrupt")) from None
        if progress is not None:
            progress(float(t_eval[k]), time.perf_counter() - wall0)
        if k < len(t_eval) - 1:                # the run's budget and Ctrl-C
            exc = rb.exceeded("integration", float(t_eval[k]), ros.h, ys[-1])
            if exc is not None:
                raise fail(exc)
        if checkpoint is not None and k < len(t_eval) - 1 and checkpoint.due():
            checkpoint.save("ros2", float(t_eval[k]), {
                "ys": np.array(ys), "k": k + 1, "ros2": ros.state(), "warm": warm_starts(model),
                "wall_s": time.perf_counter() - wall0})
    return t_eval, np.array(ys), stats()


class _StepPace:
    """The stall test of :class:`StallMonitor` for step loops that report between calls:
    after each call with (accepted steps so far, t), the mean step over the last ``window``
    or more accepted steps below t_end / max_steps raises :class:`StalledIntegration`."""

    def __init__(self, t_end: float, window: int, max_steps: float):
        self.t_end, self.window = float(t_end), int(window)
        self.floor = self.t_end / float(max_steps)
        self.marks = [(0, 0.0)]                    # (accepted steps, t) after each call
        self.slowest = math.inf

    def update(self, steps: int, t: float, step: float, state: np.ndarray) -> None:
        self.marks.append((int(steps), float(t)))
        back = [m for m in self.marks if m[0] <= steps - self.window]
        if not back:
            return
        n0, t0 = back[-1]
        self.marks = self.marks[self.marks.index(back[-1]):]
        n, mean = steps - n0, (t - t0) / (steps - n0)
        self.slowest = min(self.slowest, mean)
        if mean < self.floor and t < self.t_end:
            raise StalledIntegration(
                t, f"integration stalled: the last {n} accepted steps averaged {mean:.3g} s "
                f"(~{(self.t_end - t) / max(mean, 1e-300):.2g} more steps to t_end), below "
                f"t_end / {self.t_end / self.floor:.0e} = {self.floor:.3g} s; (dynamics the "
                "error-controlled generalized-alpha cannot follow at this tolerance: loosen "
                "solver.rtol/atol, or give a fixed solver.h)", mean_step=mean, window=n,
                step=step, last_state=state)


# error control of generalized-alpha without a fixed h (_alpha_adaptive)
ALPHA_SAFETY, ALPHA_FAC_MIN, ALPHA_FAC_MAX = 0.9, 0.2, 5.0
ALPHA_FLOOR = 1e-12          # smallest step / t_end


def _alpha_adaptive(model, y0: np.ndarray, t_end: float, sol: dict, progress=None,
                    checkpoint=None):
    """Error-controlled generalized-alpha (:func:`integrate_alpha` without ``h``).

    The local error estimate is the position one of
    :mod:`sim_core.integrate.generalized_alpha`, e_q = c_q h^2 (q_ddot_{n+1} - q_ddot_n),
    c_q = beta + delta_alpha / 2 - 1/6: the Newmark estimator of Zienkiewicz & Xie (1991),
    (beta - 1/6) h^2 delta q_ddot, with generalized-alpha's constant.  Its RMS over the
    coordinates, weighted by atol + rtol max(|q_n|, |q_{n+1}|) (m; scipy's norm), accepts a
    step at <= 1; h_new = h clip(0.9 err^(-1/3), 0.2, 5) times Gustafsson's predictive
    factor (<= 1; the numpy reference's controller), no growth right after a rejection,
    h kept for a proposed factor in [1, 1.2) (RADAU5: Hairer & Wanner, Solving ODEs II,
    Sect. IV.8), at most ``h_max``.  The velocity estimate of the numpy reference is left out:
    for modes the step leaves unresolved (their dissipation is rho_inf's job) it saturates at
    ~h times their acceleration amplitude and, against an atol in m/s, forces steps that
    resolve them (module doc of :mod:`sim_core.integrate.generalized_alpha`).

    Compiled path: the tangent (M, K, C) is formed at the start, after a Newton failure and
    where Newton contracts slowly, and kept apart from the inverse iteration matrix, so a new
    h costs one n x n inverse (a few us at 16-34 DOF, against ~12-40 us a step), never a
    tangent (~0.7 ms).  First step: the h at which e_q would reach the tolerance if the
    accelerations changed by their own size, (c_q RMS(q_ddot_0 / w))^(-1/2), at most
    t_end / 100 and h_max; the error test corrects it within a few rejections.  Outputs: the
    step's cubic Hermite interpolants (q from q, v; v from v, q_ddot), O(h^3) like the step.

    A step below 1e-12 t_end (``ALPHA_FLOOR``) raises SimulationError; a mean step below
    t_end / ``stall_max_steps`` (1e6) over 1000 accepted steps raises StalledIntegration
    (the rule of :class:`StallMonitor`); calls return every 1000 steps for the budget and
    the checkpoints."""
    n = model.n_dof
    t_eval = np.linspace(0.0, t_end, sol["n_output"])
    rho = float(sol.get("rho_inf", 0.9))
    rtol, atol = float(sol["rtol"]), float(sol["atol"])
    newton_atol = float(sol.get("newton_atol", 0.1 * atol))
    h_max = min(float(sol.get("h_max", t_end)), t_end)
    h_min = ALPHA_FLOOR * t_end
    rb = run_control.for_solver(sol.get("max_wall_s"))      # the run's deadline
    window = int(sol.get("stall_window") or StallMonitor.window)
    pace = _StepPace(t_end, window, sol.get("stall_max_steps") or StallMonitor.max_steps)
    wall0 = time.perf_counter()
    p = GeneralizedAlphaParameters.from_rho_inf(rho)
    plan = model.element_loop_plan() if isinstance(model, Model) else None
    Y = np.empty((len(t_eval), 2 * n))
    Y[0] = y0
    k_out = 1
    counts = np.zeros(8, dtype=np.int64)   # steps, residuals, Newton its, tangents, inverses,
    #                                        failed Newton attempts, rejected steps
    hs = np.array([0.0, 0.0, 0.0, 0.0, math.inf, 0.0, 0.0])
    state = {"y": np.array(y0, dtype=float)}

    def stats():
        wall = time.perf_counter() - wall0
        out = {"wall_time_s": wall, "n_steps": int(counts[0]), "n_rejected": int(counts[6]),
               "n_rhs": int(counts[1]), "n_newton_iterations": int(counts[2]),
               "n_jac": int(counts[3]), "n_lu": int(counts[4]),
               "n_newton_failures": int(counts[5]),
               "min_step_s": float(hs[4]) if math.isfinite(hs[4]) else float(hs[5]),
               "max_step_s": float(hs[5]), "method": "generalized_alpha",
               "step_control": "error", "rtol": rtol, "atol": atol, "rho_inf": rho,
               "h_max": h_max, "newton_atol": newton_atol, "compiled": plan is not None,
               "real_time_factor": float(hs[0]) / max(wall, 1e-12)}
        if math.isfinite(pace.slowest):
            out["min_window_mean_step_s"] = float(pace.slowest)
        if checkpoint is not None:
            out.update(checkpoint.stats())
        return out

    def fail(reason, step, cls=SimulationError, **kw):
        exc = cls(float(hs[0]), reason, step=step, last_state=state["y"], **kw)
        exc.partial = (t_eval[:k_out], Y[:k_out].copy(), stats())
        return exc

    def check_budget():                    # the run's budget and Ctrl-C
        if hs[0] < t_end:
            exc = rb.exceeded("integration", float(hs[0]), float(hs[2]), state["y"])
            if exc is not None:
                exc.partial = (t_eval[:k_out], Y[:k_out].copy(), stats())
                raise exc

    if plan is None:
        return _alpha_adaptive_numpy(model, y0, t_end, sol, progress, t_eval, p, rtol, atol,
                                     h_max, h_min, rb, window, wall0, checkpoint)

    q, v = np.array(y0[:n], dtype=float), np.array(y0[n:], dtype=float)
    qdd, a = _initial_accelerations(plan, q, v)
    w0 = atol + rtol * np.abs(q)
    acc = math.sqrt(float(np.mean((qdd / w0) ** 2)))
    hs[1] = max(h_min, min(h_max, 0.01 * t_end,
                           (p.error_constant * acc) ** -0.5 if acc > 0 else t_end))
    Mr, Kr, Cr, Sinv = (np.empty((n, n)) for _ in range(4))
    carry = np.array([0.0, 1.0, 0.0])
    saved = checkpoint.take("alpha_adaptive") if checkpoint is not None else None
    if saved is not None:          # the loop state after a compiled call
        for name, arr in (("q", q), ("v", v), ("qdd", qdd), ("a", a), ("hs", hs), ("Y", Y),
                          ("counts", counts), ("Mr", Mr), ("Kr", Kr), ("Cr", Cr),
                          ("Sinv", Sinv), ("carry", carry)):
            arr[...] = saved[name]
        k_out = int(saved["k_out"])
        state["y"] = np.concatenate([q, v])
        pace.marks, pace.slowest = [tuple(m) for m in saved["pace_marks"]], saved["pace_slowest"]
        wall0 = time.perf_counter() - float(saved["wall_s"])
        rb.credit(float(saved["wall_s"]))
    try:
        while True:
            try:
                code, k_out = ga_numba.run_adaptive(
                    q, v, qdd, a, hs, t_eval, k_out, window, p.alpha_m, p.alpha_f, p.beta,
                    p.gamma, p.error_constant, rtol, atol, ALPHA_SAFETY, ALPHA_FAC_MIN,
                    ALPHA_FAC_MAX, h_min, h_max, t_end, newton_atol, 8, 0.3, REL_STEP, plan.Qp,
                    plan.rows, plan.sgn, plan.eidx, plan.red, plan.sg, *plan.kernel_args,
                    ec.NO_ACC, Y, counts, Mr, Kr, Cr, Sinv, carry)
            except _KERNEL_ERRORS as exc:
                raise fail(f"generalized-alpha: the element evaluation failed "
                           f"({type(exc).__name__}: {exc}); tighten solver.rtol/atol",
                           float(hs[1])) from None
            state["y"] = np.concatenate([q, v])
            if code == ga_numba.NEWTON_FAILED:
                raise fail("generalized-alpha: the state is not finite after a converged "
                           "Newton iteration; tighten solver.rtol/atol", float(hs[1]))
            if code == ga_numba.STEP_TOO_SMALL:
                raise fail(f"generalized-alpha: the error-controlled step fell to "
                           f"{hs[1]:.3g} s, below its floor {ALPHA_FLOOR:g} t_end = {h_min:.3g} s "
                           f"(error test or Newton failures at this state; loosen "
                           f"solver.rtol/atol = {rtol:g}/{atol:g})", float(hs[1]))
            pace.update(int(counts[0]), float(hs[0]), float(hs[2]), state["y"])
            if progress is not None:
                progress(float(hs[0]), time.perf_counter() - wall0)
            if code == ga_numba.OK:
                break
            check_budget()
            if checkpoint is not None and checkpoint.due():
                checkpoint.save("alpha_adaptive", float(hs[0]), {
                    "q": q, "v": v, "qdd": qdd, "a": a, "hs": hs, "Y": Y, "counts": counts,
                    "Mr": Mr, "Kr": Kr, "Cr": Cr, "Sinv": Sinv, "carry": carry,
                    "k_out": k_out, "pace_marks": list(pace.marks),
                    "pace_slowest": pace.slowest, "wall_s": time.perf_counter() - wall0})
    except StalledIntegration as exc:
        exc.partial = (t_eval[:k_out], Y[:k_out].copy(), stats())
        raise
    except KeyboardInterrupt:              # Ctrl-C keeps what was computed, like a budget
        raise fail("integration", float(hs[2]), RunInterrupted,
                   how="KeyboardInterrupt") from None
    return t_eval, Y, stats()


def _alpha_adaptive_numpy(model, y0, t_end, sol, progress, t_eval, p, rtol, atol, h_max,
                          h_min, budget, window, wall0, checkpoint=None):
    """The numpy path of :func:`_alpha_adaptive`: :func:`integrate_generalized_alpha` with the
    structured tangent, the position estimate and the same floor; the stall monitor, the
    run's budget (``budget``: a :class:`sim_core.run_control.RunBudget`), the progress
    callback and the checkpoints after every accepted step."""
    n = model.n_dof
    stall = StallMonitor(t_end, window, sol.get("stall_max_steps"), budget.max_wall_s, wall0,
                         spent=budget.elapsed)
    shim = type("Step", (), {})()
    shim.t = shim.t_old = 0.0
    saved = checkpoint.take("alpha_numpy_adaptive") if checkpoint is not None else None
    if saved is not None:
        wall0 = time.perf_counter() - float(saved["wall_s"])
        budget.credit(float(saved["wall_s"]))
        _restore_stall(stall, saved["stall"], wall0)
        shim.t, shim.t_old = saved["shim"]
        shim.y = np.array(saved["shim_y"], dtype=float)

    def hook(get):
        if checkpoint.due():
            st = get()
            checkpoint.save("alpha_numpy_adaptive", float(st["ga"]["t"]), {
                "ga": st, "stall": _stall_state(stall), "shim": (shim.t, shim.t_old),
                "shim_y": shim.y, "warm": warm_starts(model),
                "wall_s": time.perf_counter() - wall0})

    def each_step(t, h, q, v):
        shim.t_old, shim.t, shim.y = shim.t, t, np.concatenate([q, v])
        if t < t_end:
            stall.update(shim)
            budget.check("integration", t, h, shim.y)
        if progress is not None:
            progress(t, time.perf_counter() - wall0)

    def stats(st):
        wall = time.perf_counter() - wall0
        out = {"wall_time_s": wall, "n_steps": int(st.n_steps),
               "n_rejected": int(st.n_rejected or 0), "n_rhs": int(st.n_force_evaluations),
               "n_newton_iterations": int(st.n_newton_iterations),
               "n_jac": int(st.n_jacobian_evaluations), "n_lu": int(st.n_lu),
               "n_newton_failures": int(st.n_newton_failures or 0),
               "min_step_s": float(st.min_step) if st.n_steps else 0.0,
               "max_step_s": float(st.max_step) if st.n_steps else 0.0,
               "method": "generalized_alpha", "step_control": "error", "rtol": rtol,
               "atol": atol, "rho_inf": p.rho_inf, "h_max": h_max,
               "newton_atol": float(sol.get("newton_atol", 0.1 * atol)), "compiled": False,
               "real_time_factor": float(shim.t) / max(wall, 1e-12)}
        if math.isfinite(stall.slowest):
            out["min_window_mean_step_s"] = float(stall.slowest)
        if checkpoint is not None:
            out.update(checkpoint.stats())
        return out

    try:
        r = integrate_generalized_alpha(
            StructuredTangent(model), (0.0, t_end), y0[:n], y0[n:], rho_inf=p.rho_inf,
            rtol=rtol, atol=atol, t_eval=t_eval, h_min=h_min, h_max=h_max,
            max_steps=2 ** 62, safety=ALPHA_SAFETY, fac_min=ALPHA_FAC_MIN,
            fac_max=ALPHA_FAC_MAX, error_estimate="position", callback=each_step,
            checkpoint=hook if checkpoint is not None else None,
            resume=saved["ga"] if saved is not None else None,
            on_resume=(lambda: restore_warm_starts(model, saved["warm"])) if saved else None)
    except (SimulationError, KeyboardInterrupt) as exc:
        ts, q, v, _ = getattr(exc, "partial_output", (t_eval[:1], y0[None, :n], y0[None, n:], None))
        st = getattr(exc, "partial_stats", None)
        if isinstance(exc, KeyboardInterrupt):  # Ctrl-C keeps what was computed, like a budget
            err = RunInterrupted(shim.t, "integration", last_state=getattr(shim, "y", y0),
                                 how="KeyboardInterrupt")
        else:
            err = exc
        err.partial = (np.asarray(ts), np.hstack([q, v]),
                       stats(st) if st is not None else {"method": "generalized_alpha"})
        if err is exc:
            raise
        raise err from None
    return t_eval, np.hstack([r.q, r.v]), stats(r.stats)


def _initial_accelerations(plan, q, v):
    """(z_ddot(0), a_0) of the compiled generalized-alpha loops: z_ddot = M^-1 f at (q, v) with
    the plan's constant selecting constraints, and the auxiliary acceleration a_0 = z_ddot(0)
    (Arnold & Bruels 2007)."""
    n = len(q)
    try:
        M0, _, _, f0 = ga_numba.mass_tangent(*_lifted(plan, q, v, np.zeros(n)), REL_STEP,
                                             plan.eidx, plan.red, plan.sg, n, *plan.kernel_args,
                                             ec.NO_ACC)
        qdd = np.linalg.solve(M0, f0)
    except _KERNEL_ERRORS as exc:          # a degenerate element at the initial state
        raise ElementEvaluationError(0.0, f"initial accelerations: {type(exc).__name__}: "
                                     f"{exc}", last_state=np.concatenate([q, v])) from None
    if not np.all(np.isfinite(qdd)):
        raise ElementEvaluationError(0.0, "initial accelerations: not finite",
                                     last_state=np.concatenate([q, v]))
    return qdd, qdd.copy()


# what a compiled element kernel raises at a degenerate state (an element collapsed to zero
# length, a singular mass matrix): the compiled loops turn it into a typed SimulationError
_KERNEL_ERRORS = (ZeroDivisionError, OverflowError, FloatingPointError, np.linalg.LinAlgError)


def _lifted(plan, z, zd, zdd):
    """Full (Q, Q_dot, Q_ddot) of reduced values through the plan's selection."""
    N = len(plan.Qp)
    Q, Qd, Qdd = np.empty(N), np.empty(N), np.empty(N)
    ga_numba.lift(np.asarray(z, float), plan.Qp, plan.rows, plan.sgn, Q)
    ga_numba.lift(np.asarray(zd, float), np.zeros(N), plan.rows, plan.sgn, Qd)
    ga_numba.lift(np.asarray(zdd, float), np.zeros(N), plan.rows, plan.sgn, Qdd)
    return Q, Qd, Qdd
