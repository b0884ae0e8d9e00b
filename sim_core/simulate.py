"""Run a scene: assemble the model, integrate, collect outputs into a :class:`Result`.

First integrator (issue 2): scipy ``solve_ivp`` RK45 on the first-order reduced system, with
the stress filter of the second seed (Eq. 53) as an effect when the scene switches it on.
"""

from __future__ import annotations

import math
import time

import numpy as np
import scipy.linalg as sla
from scipy.integrate import BDF, RK45

from .assemble import build_model
from .drive_profiles import sleeve_motion
from .errors import ElementEvaluationError, SimulationError, StalledIntegration, SuspectResult
from .model import Model
from .result import Result
from .scene import SOLVER_METHODS
from .statics import static_equilibrium

# Newton iterations per BDF step before scipy's BDF renews its Jacobian (scipy's default 4).
# scipy reads the limit from a module constant of its private module scipy.integrate._ivp.bdf
# (unchanged since scipy 1.0); integrate() raises it only around its own BDF steps
# (_bdf_newton_limit) and restores it after each.  Why: the structured Jacobian costs ~45
# right-hand sides at the paper's discretisation, while a Newton iteration with the stale one
# costs one, so a slower but converging iteration is cheaper than a new Jacobian (fewer
# Jacobians on the paper's extraction run); the step sizes are still set by the error test.
BDF_NEWTON_ITERATIONS = 8


class SecondOrderNewtonLU:
    """Newton-matrix factorisation for scipy's BDF on a first-order form y = (z, v) of a
    second-order system, y' = (v, a(t, z, v)): the Jacobian is [[0, I], [A_z, A_v]], so BDF's
    Newton matrix I - c J = [[I, -c I], [-c A_z, I - c A_v]] is eliminated to its Schur
    complement S = I - c A_v - c^2 A_z (n x n): one LU of size n instead of 2n (1/8 of the
    flops; 0.7 instead of 5.2 ms at the paper's 313 coordinates), and per solve
    x2 = S^-1 (b2 + c A_z b1), x1 = b1 + c x2.  The structure is checked on the matrix itself
    (the identity and -c I blocks exactly, as the structured Jacobian gives them); any other
    matrix (e.g. finite-difference Jacobians, whose dv/dv is not exactly I) takes the LU of
    the whole matrix.  Installed as the solver's ``lu`` / ``solve_lu`` (its public
    attributes); counts its factorisations in the solver's ``nlu``."""

    def __init__(self, solver):
        self.solver = solver
        self.n = solver.n // 2
        self.eye = np.eye(self.n)

    def lu(self, A):
        self.solver.nlu += 1
        n, eye = self.n, self.eye
        if 2 * n == A.shape[0] and n > 0:
            c = -A[0, n]
            if np.array_equal(A[:n, :n], eye) and np.array_equal(A[:n, n:], -c * eye):
                A21 = A[n:, :n].copy()                          # -c A_z
                S = A[n:, n:] + c * A21                         # A22 - A21 A12
                return ("schur", sla.lu_factor(S, overwrite_a=True), A21, c)
        return ("full", sla.lu_factor(A, overwrite_a=True))

    def solve_lu(self, LU, b):
        if LU[0] == "full":
            return sla.lu_solve(LU[1], b, overwrite_b=True)
        _, f, A21, c = LU
        n = self.n
        x2 = sla.lu_solve(f, b[n:] - A21 @ b[:n])
        return np.concatenate([b[:n] + c * x2, x2])


class _bdf_newton_limit:
    """Context: scipy's BDF Newton iteration limit set to ``n`` (no-op where scipy has no
    such constant), restored on exit."""

    def __init__(self, n: int):
        import scipy.integrate._ivp.bdf as bdf_module
        self.module, self.n = bdf_module, int(n)

    def __enter__(self):
        self.old = getattr(self.module, "NEWTON_MAXITER", None)
        if self.old is not None:
            self.module.NEWTON_MAXITER = self.n
        return self

    def __exit__(self, *exc):
        if self.old is not None:
            self.module.NEWTON_MAXITER = self.old
        return False


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
        """Structured Jacobian (:mod:`sim_core.state_jacobian`) for BDF, its cost counted."""
        from .state_jacobian import state_jacobian
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


class RefreshedJacobian:
    """BDF's Jacobian callable for one BDF stretch: the structured Jacobian, or -- when Newton
    fails with the one BDF has -- that Jacobian with its non-smooth columns refreshed.

    The friction law mu(v) (SCENARIOS A6, the paper's mu sign(s_dot) of Eq. 65) is only C0 at
    |v| = v_eps and its slope changes sign on the smoothstep branch; it enters the Jacobian
    only through the columns of the contact coordinates' rates
    (:meth:`sim_core.model.Model.nonsmooth_rate_columns`).  When a contact crosses a branch
    those few columns jump while the rest changes smoothly with the state, and scipy's BDF,
    which asks for a new Jacobian whenever Newton fails with the one it has, got a whole one
    each time (~60 ms at the paper's discretisation).  Here the first request of a stretch
    gets the whole Jacobian; a later one gets the last whole one with those columns'
    acceleration rows re-differenced from the right-hand side (forward differences, exactly
    representable steps: 1 + k evaluations for k columns, ~5 ms; the velocity rows keep the
    exact identity columns, so :class:`SecondOrderNewtonLU` keeps its Schur complement).
    When Newton did not converge with a refreshed Jacobian either (BDF halved that step and
    factored again: :meth:`after_step` sees a second factorisation within the step), the rest
    of it is stale too, and the next request gets a whole one.  Newton's convergence decides
    only the cost: BDF's error test still sets the steps.  Measured on the paper's stick-in
    (BDF from 15.3 to 16.0 s): the same 287 steps and 72 factorisations, 14 whole Jacobians ->
    1 whole + 13 refreshes, the final state within 1.5e-10 of the run with whole ones,
    2.25 -> 1.86 s; reusing the Jacobian without the refresh instead: 3703 steps."""

    def __init__(self, rhs: "_CountingRHS"):
        self.rhs = rhs
        self.solver = None                       # set by watch(); its nlu counts factorisations
        self.J = None                            # the last whole Jacobian (refreshed in place)
        self.pending = None                      # factorisations when the last refresh was made
        self.stale = False                       # Newton failed with a refreshed Jacobian
        self.cols = np.asarray(rhs.model.nonsmooth_rate_columns(), dtype=int)

    def watch(self, solver) -> None:
        """The BDF solver whose factorisations (``nlu``) tell whether a refresh sufficed."""
        self.solver = solver

    def after_step(self) -> None:
        """Call after each accepted step: a refresh in that step followed by more than one
        factorisation means Newton failed with it (BDF halves h and factors again)."""
        if self.pending is not None and self.solver is not None:
            self.stale = self.solver.nlu - self.pending > 1
        self.pending = None

    def __call__(self, t, y):
        if self.J is None or len(self.cols) == 0 or self.stale or self.solver is None:
            return self.whole(t, y)
        self.pending = self.solver.nlu
        return self._refresh(t, y)

    def whole(self, t, y):
        """The whole structured Jacobian at (t, y) (also the stretch's new base)."""
        self.J = self.rhs.jacobian(t, y)
        self.stale = False
        self.pending = None
        return self.J.copy()

    def _refresh(self, t, y):
        n = len(y) // 2
        failed = self.rhs.n_failed
        f0 = self.rhs(t, y)
        yy = y.copy()
        cols = np.empty((n, len(self.cols)))
        for k, j in enumerate(self.cols):
            x = y[j]
            e = (x + 1e-7 * max(1.0, abs(x))) - x          # exactly representable step
            yy[j] = x + e
            cols[:, k] = (self.rhs(t, yy)[n:] - f0[n:]) / e
            yy[j] = x
        if self.rhs.n_failed != failed:     # a failed evaluation (its placeholder values):
            return self.whole(t, y)         # the whole Jacobian, which raises the typed error
        self.J[n:, self.cols] = cols
        self.rhs.n_refreshes += 1
        return self.J.copy()


class StiffnessDetector:
    """Stiffness detection of Dormand-Prince (Hairer, Nørsett, Wanner, *Solving Ordinary
    Differential Equations I*, 2nd ed., Sec. II.10, code DOPRI5): after every accepted step the
    two stages evaluated at c = 1 give the local Lipschitz estimate

        rho = ||k7 - k6|| / ||y_new - g6||,   g6 = y_old + h sum_j a_6j k_j,

    and h rho approximates |h lambda| of the dominant eigenvalue.  RK45's stability boundary on
    the negative real axis is about 3.3; when h rho > 3.25 on ``n_stiff`` accepted steps
    without ``n_reset`` non-stiff steps in between, the step size is limited by stability, not
    accuracy — the problem is stiff there."""

    def __init__(self, n_stiff: int = 15, n_reset: int = 6, bound: float = 3.25):
        self.n_stiff, self.n_reset, self.bound = n_stiff, n_reset, bound
        self.stiff = 0
        self.non_stiff = 0
        self.last_h_rho = 0.0

    def update(self, solver) -> bool:
        """Call after an accepted step of a scipy RK45 solver; True once the problem is stiff."""
        h = solver.t - solver.t_old
        K = solver.K
        g6 = solver.y_old + h * (K[:5].T @ solver.A[5, :5])
        den = np.linalg.norm(solver.y - g6)
        h_rho = h * np.linalg.norm(K[6] - K[5]) / den if den > 0.0 else 0.0
        self.last_h_rho = float(h_rho)
        if h_rho > self.bound:
            self.non_stiff = 0
            self.stiff += 1
        else:
            self.non_stiff += 1
            if self.non_stiff >= self.n_reset:
                self.stiff = 0
        return self.stiff >= self.n_stiff


def spectral_radius(J, iterations: int = 40) -> float:
    """Estimate of the spectral radius of a square matrix (1/s for an ODE Jacobian) by power
    iteration from a fixed start vector: the geometric mean of the growth over the last half of
    the iterations, which also settles for a dominant complex pair (whose single-step ratios
    oscillate).  A rough estimate, enough to compare a step with RK45's stability boundary;
    0 for None or an empty matrix."""
    if J is None or J.shape[0] == 0:
        return 0.0
    J = J.toarray() if hasattr(J, "toarray") else np.asarray(J)
    x = 1.0 + 0.1 * np.cos(np.arange(J.shape[0]))      # deterministic, not an eigenvector
    x /= np.linalg.norm(x)
    logs = []
    for _ in range(iterations):
        x = J @ x
        n = np.linalg.norm(x)
        if not np.isfinite(n) or n == 0.0:
            return 0.0 if n == 0.0 else math.inf
        logs.append(math.log(n))
        x /= n
    return math.exp(float(np.mean(logs[iterations // 2:])))


class StallMonitor:
    """Raises :class:`StalledIntegration` when the run cannot finish at the pace of its last
    ``window`` accepted steps:

    * their mean step is below ``t_end / max_steps`` (a pace at which the whole run would take
      more than ``max_steps`` steps), or
    * with a wall-clock budget ``budget`` (s): at least ``min_budget_share`` of it is spent and
      the remaining simulated time, at the window's pace in simulated seconds per wall second,
      would take more than ``overrun`` times the budget left -- the budget would run out
      anyway, so the run stops now, naming the stall, instead of at the budget.

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
                 budget: float | None = None, wall0: float | None = None):
        self.window = int(window or self.window)
        self.max_steps = float(max_steps or self.max_steps)
        self.t_end = float(t_end)
        self.floor = self.t_end / self.max_steps
        self.budget = budget
        self.wall0 = time.perf_counter() if wall0 is None else wall0
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
        if self.budget is not None and now - self.wall0 >= self.min_budget_share * self.budget:
            pace = (solver.t - t_old) / max(now - wall_old, 1e-9)   # simulated s per wall s
            need = (self.t_end - solver.t) / max(pace, 1e-300)
            left = self.budget - (now - self.wall0)
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


class MethodSwitch:
    """``solver.method = "auto"``: RK45 while it is cheaper, BDF while the problem is stiff.

    RK45 -> BDF when :class:`StiffnessDetector` reports a stability-limited step; RK45's cost
    over its last ``window`` accepted steps is recorded.  BDF runs ``bdf_steps`` accepted steps,
    then hands back to RK45 (a trial: if the problem is still stiff the detector switches again
    after its 15 steps) -- unless BDF paid off and its step h is still beyond RK45's
    stability, h rho(J) > ``stay_factor`` x 3.25 with rho(J) the spectral radius
    (:func:`spectral_radius`) of a fresh Jacobian (``fresh_jacobian(solver)``; BDF's own may
    be stale, it is renewed only when Newton fails; with the structured Jacobian, the last
    whole one with its friction columns refreshed, :class:`RefreshedJacobian`): then BDF goes
    on with that Jacobian for a
    stretch twice as long, without the trial, which would cost ~15 stability-limited RK45
    steps (90+ evaluations) to learn what the Jacobian already says.  Each BDF stretch is
    judged against the RK45 stretch before it (cost = model evaluations per simulated second,
    BDF's Jacobians included): when
    BDF was cheaper, its next stretch is twice as long (up to ``max_bdf_steps``); when it was
    dearer (e.g. sticking friction that changes regime every few steps, so BDF recomputes its
    Jacobian almost every step), its next stretch is halved and RK45
    ignores the detector for a cool-down that doubles with every such loss.  Costs are counted
    in model evaluations, not wall time, so a run is reproducible.  ``switches`` lists (t s,
    method switched to)."""

    def __init__(self, rhs: "_CountingRHS", window: int = 30, bdf_steps: int = 40,
                 max_bdf_steps: int = 5000, stay_factor: float = 2.0, fresh_jacobian=None):
        self.rhs = rhs
        self.fresh_jacobian = fresh_jacobian      # solver -> Jacobian at its state, or None
        self.window = window
        self.bdf_steps, self.min_bdf_steps, self.max_bdf_steps = bdf_steps, bdf_steps, max_bdf_steps
        self.detector = StiffnessDetector()
        self.recent: list[tuple[float, float]] = []    # (t, model work) after accepted steps
        self.start: tuple[float, float] = (0.0, 0.0)   # at the start of the current stretch
        self.rk45_cost = math.inf
        self.cool_down = 0
        self.last_loss_cool_down = 0
        self.n_bdf = 0
        self.switches: list[tuple[float, str]] = []
        self.stay_factor = stay_factor
        self.kept_bdf = 0              # stretch ends where BDF stayed (no hand-back trial)
        self.last_bdf_h_rho = 0.0

    @staticmethod
    def _cost(a: tuple[float, float], b: tuple[float, float]) -> float:
        return (b[1] - a[1]) / (b[0] - a[0]) if b[0] > a[0] else math.inf

    def after_step(self, solver, make):
        """Call after every accepted step; returns the solver to continue with (``make(cls,
        t, y)`` builds a new one)."""
        now = (float(solver.t), self.rhs.cost)
        if isinstance(solver, RK45):
            self.recent = (self.recent + [now])[-self.window - 1:]
            if self.cool_down > 0:
                self.cool_down -= 1
                return solver
            if not self.detector.update(solver):
                return solver
            self.rk45_cost = self._cost(self.recent[0], now)
            self.n_bdf = 0
            new, name = make(BDF, solver.t, solver.y), "BDF"
        else:
            self.n_bdf += 1
            if self.n_bdf < self.bdf_steps:
                return solver
            if self._cost(self.start, now) < self.rk45_cost:          # BDF paid off
                self.bdf_steps = min(2 * self.bdf_steps, self.max_bdf_steps)
                self.last_loss_cool_down = 0
                # no hand-back trial while RK45 could not take BDF's steps: its stable step
                # is bound / rho, rho the spectral radius of a fresh Jacobian (BDF's own may be
                # stale: it is renewed only when Newton fails), which BDF then keeps
                J = self.fresh_jacobian(solver) if self.fresh_jacobian is not None else None
                h_rho = solver.h_abs * spectral_radius(J)
                self.last_bdf_h_rho = h_rho
                if h_rho > self.stay_factor * self.detector.bound:
                    solver.J, solver.LU = J, None       # the next step factors I - c J anew
                    self.n_bdf = 0
                    self.kept_bdf += 1
                    self.start = (now[0], self.rhs.cost)
                    return solver
            else:                                                      # RK45 was cheaper
                self.bdf_steps = max(self.bdf_steps // 2, self.min_bdf_steps)
                self.last_loss_cool_down = min(max(2 * self.last_loss_cool_down, 100), 10000)
                self.cool_down = self.last_loss_cool_down
            self.detector = StiffnessDetector()
            self.recent = [now]
            new, name = make(RK45, solver.t, solver.y), "RK45"
        self.start = now
        self.switches.append((float(solver.t), name))
        return new


def integrate(model, y0: np.ndarray, t_end: float, sol: dict, progress=None):
    """Integrate model.rhs from t = 0 with dense output at ``sol["n_output"]`` equally spaced
    times.  ``sol["method"]``:

    * ``"RK45"`` (default): scipy's explicit Dormand-Prince pair — cheapest per step while the
      step size is set by accuracy;
    * ``"BDF"``: scipy's variable-order BDF — for stiff runs (sticking friction, stiff contact).
      Its Jacobian (``sol["jacobian"]``): ``"structured"`` (default for :class:`sim_core.model.
      Model`) by implicit differentiation with local differences (:mod:`sim_core.
      state_jacobian`, ~1/6 of the cost at the paper's discretisation), or
      ``"finite_difference"``: scipy's differences of the whole right-hand side (one model.rhs
      per state per Jacobian);
    * ``"auto"``: RK45 and BDF alternate as :class:`MethodSwitch` decides (RK45 -> BDF when
      :class:`StiffnessDetector` finds the step stability-limited, back to RK45 after a
      stretch whose length adapts to which method was cheaper); the statistics record the
      number of switches and the first switch to BDF.

    Returns (t, y, stats); raises SimulationError with the time, step and last good state on
    failure or non-finite values, when the optional wall-clock budget ``sol["max_wall_s"]`` (s)
    is exhausted, or on Ctrl-C (KeyboardInterrupt), and :class:`StalledIntegration` where the
    steps cannot finish the run (:class:`StallMonitor`: within ``sol["stall_max_steps"]``
    steps, default 1e6, or the budget); the outputs reached so far are attached, so a
    budgeted, stalled or interrupted run still yields a partial result.  The statistics
    include rtol, atol, the shortest mean step over the stall monitor's window and, for a
    :class:`sim_core.model.Model`, its element worker's governor
    (:meth:`sim_core.beam.element_worker.Governor.summary`)."""
    method = sol.get("method", "RK45")
    if method not in SOLVER_METHODS:
        raise ValueError(f"solver.method = {method!r}: must be one of {SOLVER_METHODS}")
    t_eval = np.linspace(0.0, t_end, sol["n_output"])
    rhs = _CountingRHS(model)
    kwargs = {"max_step": sol["max_step"]} if "max_step" in sol else {}
    budget = sol.get("max_wall_s")
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

    solver = make(BDF if method == "BDF" else RK45, 0.0, y0)
    # at a BDF stretch's end a fresh Jacobian tells whether RK45 could take BDF's steps; where
    # it costs less than the RK45 trial it replaces (~100 evaluations): the structured one
    # (through the stretch's RefreshedJacobian: its friction columns refreshed, where the
    # stiffness of a sticking contact is; the stress filter's eigenvalue pair is constant), or
    # finite differences of a small system
    probe = structured or len(y0) <= 100
    fresh = (lambda s: stretch["jac"](s.t, s.y)) if structured else (lambda s: s.jac(s.t, s.y))
    switch = MethodSwitch(rhs, fresh_jacobian=fresh if probe else None) \
        if method == "auto" else None
    njev = 0                  # Jacobians of BDF solvers already replaced by a switch
    newton_limit = _bdf_newton_limit(sol.get("bdf_newton_iterations", BDF_NEWTON_ITERATIONS))
    ys = [y0]
    k_out = 1
    stall = StallMonitor(t_end, sol.get("stall_window"), sol.get("stall_max_steps"), budget,
                         wall0)

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
        if switch is not None:
            out["n_method_switches"] = len(switch.switches)
            out["n_bdf_kept"] = switch.kept_bdf     # stretch ends without a hand-back trial
            out["first_switch_to_bdf_s"] = switch.switches[0][0] if switch.switches else -1.0
            out["last_switch_s"] = switch.switches[-1][0] if switch.switches else -1.0
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
            if budget is not None and solver.status == "running" \
                    and time.perf_counter() - wall0 > budget:
                raise SimulationError(solver.t, f"wall-clock budget solver.max_wall_s = {budget:g} s "
                                      f"exhausted (last step {solver.step_size:.3g} s)",
                                      step=solver.step_size, last_state=solver.y)
            if switch is not None and solver.status == "running":
                old = solver
                solver = switch.after_step(solver, make)
                if solver is not old:
                    njev += int(getattr(old, "njev", 0))
    except KeyboardInterrupt:              # Ctrl-C keeps what was computed, like a budget
        exc = SimulationError(solver.t, "interrupted by the user (KeyboardInterrupt)",
                              step=solver.step_size, last_state=solver.y)
        exc.partial = (t_eval[:len(ys)], np.array(ys), stats())
        raise exc from None
    except SimulationError as exc:
        # keep what was computed: the caller turns it into a partial Result (exc.result)
        exc.partial = (t_eval[:len(ys)], np.array(ys), stats())
        raise
    return t_eval[:len(ys)], np.array(ys), stats()


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
    checks = result_checks(res)
    if check is not None:
        checks.update(check(res))
    return check_result(res, checks)


# -- result checks ---------------------------------------------------------------------------

# Energy balance (beam scenes): max_t |E(t) - E(0) - W(t)| over the exchanged energy E_x (see
# beam_energy_check).  Motion amplitudes scale with the square root of the energy, so a
# relative energy error e is an amplitude error of about e / 2: 0.02 ~ 1 % (suspect), 0.2 ~
# 10 % (not a solution: SuspectResult).  Healthy runs stay orders of magnitude below: the
# 10 m cantilever released under gravity (2 sub-elements, RK45, 2 s) 1e-8 at rtol 1e-4 and
# 2.3e-6 at rtol 1e-3, its tip within 1.4e-5 m of the modal solution; a run whose
# error control let a stiff mode grow (rtol 3e-3) is dominated by that mode's energy: 0.61,
# tip 1.1 m off.  (The ratio cannot exceed ~1 without work W: E_x bounds the drift.)
ENERGY_SUSPECT = 0.02
ENERGY_FAIL = 0.2
# E_x is at least this fraction of the stored energy (max T + max U): a run at rest (a static
# equilibrium, exchanging ~1e-10 of it) is judged against the energy it holds, not against
# its round-off-sized exchanges (the cantilever at its static equilibrium: drift 4e-11 U at
# rtol 1e-6, 5e-8 U at rtol 1e-3)
STORED_FLOOR = 1e-3
# Constraint violation (outputs named constraint_violation, m): a multiple of the integration
# tolerance at the structure's length scale, capped at a fraction of that scale
CONSTRAINT_TOL_FACTOR = 100.0
CONSTRAINT_SUSPECT_FRACTION = 0.01
CONSTRAINT_FAIL_FRACTION = 0.1


def _verdict(value: float, limit: float, fail: float, what: str) -> dict:
    """One check: ``value`` against the suspect ``limit`` and the ``fail`` limit."""
    value = float(value)
    return {"value": value, "limit": float(limit), "fail_limit": float(fail),
            "ok": bool(value <= limit), "gross": bool(value > fail), "what": what}


def result_checks(res: Result) -> dict:
    """The checks every scene kind's result allows: the constraint violation where the result
    has one (``constraint_violation``, m, of nonlinear constraints held by Baumgarte
    stabilisation).  Its limit: CONSTRAINT_TOL_FACTOR (atol + rtol L), L the structure's size
    (the largest |tip_position|, else 1 m), at most CONSTRAINT_SUSPECT_FRACTION L.  The
    violation is driven by the integration error (each position accurate to about atol +
    rtol |q| per step, |q| <= L) and damped by the stabilisation within ~1/xi = 0.1 s, so it
    stays within a few tolerances (the paper runs: 4.6e-8 m, 2.3e-7 m at n_nodes 9 and 3, with
    atol + rtol L ~ 2e-5 m); a hundredfold is a solution that left its constraints.  Above
    CONSTRAINT_FAIL_FRACTION L (10 % of the structure) it raises."""
    out = {}
    if "constraint_violation" in res and len(res.t):
        cv = np.asarray(res["constraint_violation"], dtype=float)
        L = 1.0
        if "tip_position" in res:
            L = max(float(np.max(np.linalg.norm(np.reshape(res["tip_position"],
                                                           (len(res.t), -1))[:, :3], axis=1))),
                    1e-3)
        rtol, atol = res.stats.get("rtol"), res.stats.get("atol")
        limit = CONSTRAINT_SUSPECT_FRACTION * L
        if rtol is not None and atol is not None:
            limit = min(CONSTRAINT_TOL_FACTOR * (atol + rtol * L), limit)
        value = float(np.max(np.abs(cv))) if cv.size else 0.0
        if not np.isfinite(value):
            value = math.inf
        out["constraint_violation"] = _verdict(
            value, limit, CONSTRAINT_FAIL_FRACTION * L,
            f"largest constraint violation, m or rad (structure size {L:.3g} m)")
    return out


def check_result(res: Result, checks: dict) -> Result:
    """Record the checks in ``res.stats`` (``checks``: name -> verdict; ``suspect``: whether
    any failed; ``failed_checks``: their names) and raise :class:`SuspectResult` (the result
    attached as ``.result``, its ``error`` set) where one failed grossly."""
    failed = [k for k, c in checks.items() if not c["ok"]]
    res.stats["checks"] = checks
    res.stats["suspect"] = bool(failed)
    res.stats["failed_checks"] = failed
    gross = {k: c for k, c in checks.items() if c["gross"]}
    if gross:
        t = float(res.t[-1]) if len(res.t) else 0.0
        why = "; ".join(f"{k} = {c['value']:.3g} > {c['fail_limit']:.3g} ({c['what']})"
                        for k, c in gross.items())
        exc = SuspectResult(t, f"the result fails its own checks: {why}", gross)
        res.error = str(exc)
        exc.result = res
        raise exc
    return res


def telescopic_energy_check(ts, res: Result) -> dict:
    """Energy balance of a telescopic run's result (``res["state"]``: the integrated states at
    the output times): E = booms' T + U + V, payload and rope strain energy
    (:func:`sim_core.energy_audit.mechanical_energy`) against the telescopic cylinder's work
    W = int lambda_cyl b'(t) dt (its prescribed stroke rate; trapezoidal rule over the outputs,
    the power from one right-hand side per output).  Friction and the stress filter only take
    energy out and the other constraint rows do no work on the constraint manifold
    (:mod:`sim_core.energy_audit`), so only growth is checked: max_t (E - E(0) - W) over the
    exchanged energy ptp(E) + ptp(W), against ENERGY_SUSPECT and ENERGY_FAIL plus the
    quadrature error of W.  Empty where the result has no states."""
    from .energy_audit import AuditedSystem, mechanical_energy
    if not len(res.t) or "state" not in res:
        return {}
    ts_, Y = np.asarray(res.t, dtype=float), np.asarray(res["state"])
    audit = AuditedSystem(ts, ("drive_work",))
    n = audit.n
    E = np.array([mechanical_energy(ts, t, y[:n], y[n:2 * n]) for t, y in zip(ts_, Y)])
    P = np.array([audit.powers(t, y[:n], y[n:2 * n])[1][0] for t, y in zip(ts_, Y)])
    W = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(ts_))])
    quad = 0.0
    if len(ts_) >= 3:
        tc, Pc = ts_[::2], P[::2]
        Wc = np.concatenate([[0.0], np.cumsum(0.5 * (Pc[1:] + Pc[:-1]) * np.diff(tc))])
        quad = float(np.max(np.abs(Wc - W[::2])))
    scale = max(float(np.ptp(E) + np.ptp(W)), 1e-12 * float(np.max(np.abs(E))), 1e-300)
    value = float(np.max(E - E[0] - W)) / scale
    if not np.isfinite(value):
        value = math.inf
    q = quad / scale
    return {"energy_balance": _verdict(
        value, ENERGY_SUSPECT + q, ENERGY_FAIL + q,
        f"energy growth / exchanged energy (E = T + U + V + payload + ropes, W: drive; E_x = "
        f"{scale:.3g} J, quadrature {q:.2g})")}


def _kinetic_density(model, ibeam: int, s: float, t: float, y: np.ndarray) -> float:
    """Kinetic energy per unit material length at material point s of beam ``ibeam``, J/m:
    (rhoA |v|^2 + w . J w) / 2 with the material velocity v and angular velocity w (section
    components), as :meth:`sim_core.model.Model.energies` integrates it."""
    n = model.n_dof
    Q, Qd = model.full_state(t, y[:n], y[n:])
    _, kin, idx = model.point(ibeam, s, Q)
    v = np.real(kin.J_r[0] @ Qd[idx])
    w = np.real(kin.J_w[0] @ Qd[idx])
    sec = model.beams[ibeam].elements[0].section
    return 0.5 * float(sec.rhoA * np.dot(v, v) + np.dot(w * w, sec.J))


def beam_energy_check(model, scene: dict, res: Result) -> dict:
    """Energy balance of a beam scene's result at its output times: E = T + U + V (kinetic,
    strain, gravity, J, ``energy_*`` outputs) plus the potential -f . r of every point load
    that is fixed (speed 0, on from t = 0), against the energy W(t) fed in, integrated by the
    trapezoidal rule over the outputs:

    * prescribed motions: the constraints' power lambda . b'(t) (lambda the reactions, b' the
      constraints' rates: the sleeves' flow of material coordinates);
    * material crossing a sleeve end at rate s' carries its kinetic energy density e_T
      (:func:`_kinetic_density`) into or out of the modelled part: -s' e_T at a left end,
      +s' e_T at a right end.  The inertia forces are those of the material points (virtual
      power, Zhao-Qi-Wang 2024 Eq. 34), so the flux of kinetic energy with the material is
      not in lambda . b'; the elastic and gravity forces are gradients of U(Q) and V(Q), whose
      limits are coordinates, so their fluxes are (measured on beam_through_sleeve at rtol
      1e-6: the balance without the flux is off by 3.85 J/s = rhoA |s'|^3 / 2, with it
      closed to 6e-6 of E_x);
    * moving or switched point loads: f . v at the loaded material point.

    Without the stress filter every other force is conservative, so E(t) - E(0) - W(t) = 0 up
    to the integration error; with it the filter only takes energy out (beyond its mass-like
    term's small store), so only growth is checked.  The value is
    max_t |E - E(0) - W| (growth: max_t of E - E(0) - W) over the exchanged energy E_x =
    ptp(T) + ptp(U) + ptp(V) + ptp(W), at least STORED_FLOOR (max T + max U); the limits are
    ENERGY_SUSPECT and ENERGY_FAIL plus the quadrature error of W (its trapezoid on every
    second output against all outputs), over E_x.  Healthy runs stay far below the limits (the
    released cantilever: 1e-9 at rtol 1e-6, 2.3e-6 at rtol 1e-3; beam_through_sleeve: no
    growth)."""
    if not len(res.t) or "state" not in res:
        return {}
    ts = np.asarray(res.t, dtype=float)
    n = model.n_dof
    Y = np.asarray(res["state"])
    T, U, V = (np.asarray(res[k], dtype=float) for k in
               ("energy_kinetic", "energy_strain", "energy_gravity"))
    V = V.copy()
    P = np.zeros(len(ts))                         # power fed in, W
    fed = []
    moving = [c for c in model.constraints if not c.constant]
    if moving:
        P += np.array([float(np.dot(np.real(res["reactions"][k]), model._b(t, 1)))
                       for k, t in enumerate(ts)])
        fed.append("prescribed motion")
    for bc in scene.get("boundary", []):
        if bc["kind"] != "sleeve" or bc["speed"] == 0.0:
            continue
        # material crossing a sleeve end carries its kinetic energy density across the
        # modelled part's boundary (the strain and gravity densities are in lambda . b')
        bps = scene["beams"][bc["beam"]]["breakpoints"]
        s0, sign = (bps[0], -1.0) if bc["end"] == "left" else (bps[-1], 1.0)
        motion = sleeve_motion(bc, s0)
        for k, (t, y) in enumerate(zip(ts, Y)):
            s_b, rate, _ = motion(t)
            P[k] += sign * rate * _kinetic_density(model, bc["beam"], s_b, t, y)
        if "material flow" not in fed:
            fed.append("material flow")
    for pl_scene, pl in zip(scene.get("point_loads", []), model.point_loads):
        if pl_scene["speed"] == 0.0 and pl_scene["start"] <= 0.0:
            for k, (t, y) in enumerate(zip(ts, Y)):
                Q, _ = model.full_state(t, y[:n], y[n:])
                r, _, _ = model.point(pl.beam, pl.s_of_t(t), Q)
                V[k] -= float(np.dot(np.asarray(pl.force(t), float), np.real(r)))
        else:
            for k, (t, y) in enumerate(zip(ts, Y)):
                _, v, _ = model.point_motion(pl.beam, pl.s_of_t(t), t, y[:n], y[n:])
                P[k] += float(np.dot(np.asarray(pl.force(t), float), np.real(v)))
            fed.append("point load")
    W = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(ts))])
    quad = 0.0
    if fed and len(ts) >= 3:
        tc, Pc = ts[::2], P[::2]
        Wc = np.concatenate([[0.0], np.cumsum(0.5 * (Pc[1:] + Pc[:-1]) * np.diff(tc))])
        quad = float(np.max(np.abs(Wc - W[::2])))
    E = T + U + V
    resid = E - E[0] - W
    scale = float(np.ptp(T) + np.ptp(U) + np.ptp(V) + np.ptp(W))
    scale = max(scale, STORED_FLOOR * float(np.max(T) + np.max(U)), 1e-300)
    dissipative = bool(scene.get("effects", {}).get("filtering"))
    value = float(np.max(resid)) if dissipative else float(np.max(np.abs(resid)))
    value = value / scale if np.isfinite(value) else math.inf
    q = quad / scale
    what = ("energy growth" if dissipative else "energy drift") + \
        " / exchanged energy (E = T + U + V" + (", W: " + ", ".join(fed) if fed else "") + \
        f"; E_x = {scale:.3g} J" + (f", quadrature {q:.2g}" if fed else "") + ")"
    return {"energy_balance": _verdict(value, ENERGY_SUSPECT + q, ENERGY_FAIL + q, what)}


def simulate(scene: dict, progress=None) -> Result:
    """Integrate a validated scene (see :func:`sim_core.load_scene`) and return a Result.

    Outputs: ``tip_position``, ``tip_velocity``, ``tip_acceleration`` (right end of the last
    beam, material point s = L), ``energy_kinetic``, ``energy_strain``, ``energy_gravity`` (J),
    ``element_ends`` (material coordinates of all breakpoints, m) and ``reactions`` (one column
    per constraint row, N or N m).

    Every finished run checks its own result (:func:`run_with_partial`): the beam scenes'
    energy balance (:func:`beam_energy_check`) and, where the result has one, the constraint
    violation (:func:`result_checks`).  The verdicts are in ``result.stats`` (``checks``,
    ``suspect``, ``failed_checks``; ``Result.suspect``, ``Result.suspect_note()``); a gross
    failure raises :class:`sim_core.errors.SuspectResult` with the result attached.
    """
    if scene.get("kind") == "telescopic":
        from .telescopic import simulate_telescopic
        from .telescopic_scene import params_from_scene
        sol = scene["solver"]
        if scene.get("model", {}).get("reduction") == "modal":
            from .modal_telescopic import simulate_modal
            res = simulate_modal(params_from_scene(scene), scene["model"]["n_modes"],
                                 sol["t_end"], sol["n_output"])
            res.scene = scene
            return res
        res = simulate_telescopic(params_from_scene(scene), progress=progress, solver=sol)
        res.scene = scene
        return res
    if scene.get("kind") == "folding":
        from .folding import simulate_folding
        from .folding_scene import params_from_scene as folding_params
        sol = scene["solver"]
        res = simulate_folding(folding_params(scene), progress=progress, solver=sol)
        res.scene = scene
        return res
    model, Q0, Qd0 = build_model(scene)
    sol = scene["solver"]
    z0, zd0 = model.reduced_state(0.0, Q0, Qd0)
    if scene["initial"]["static_equilibrium"]:
        z0 = static_equilibrium(model, z0)
    y0 = np.concatenate([z0, zd0])
    return run_with_partial(lambda: integrate(model, y0, sol["t_end"], sol, progress),
                            lambda ts, ys, stats, err: _beam_result(model, scene, ts, ys, stats, err),
                            lambda res: beam_energy_check(model, scene, res))


def _beam_result(model, scene, ts, ys, stats, error) -> Result:
    """The beam scene's outputs at the output times.  An output state where the model cannot
    be evaluated (non-finite or singular dynamics, a failed element batch: a dense-output
    state far off the solution) ends the outputs there; for a finished run (``error`` None)
    that raises SimulationError at its time with the outputs before it attached."""
    n = model.n_dof
    g = np.array(scene["gravity"]["g"]) if scene["effects"]["gravity"] else None
    last = len(model.beams) - 1
    L = model.beams[last].length
    out: dict[str, list] = {k: [] for k in ("tip_position", "tip_velocity", "tip_acceleration",
                                            "energy_kinetic", "energy_strain", "energy_gravity",
                                            "element_ends", "reactions")}
    failure = None
    for t, y in zip(ts, ys):
        z, zd = y[:n], y[n:]
        try:
            with np.errstate(over="raise", divide="raise", invalid="raise", under="ignore"):
                zdd = model.accelerations(t, z, zd)
                r, v, a = model.point_motion(last, L, t, z, zd, zdd)
                Q, Qd = model.full_state(t, z, zd)
                en = model.energies(t, Q, Qd, g)
                reac = model.reactions(t, z, zd)
            if not (np.all(np.isfinite(zdd)) and np.all(np.isfinite(reac))
                    and np.isfinite(en["T"] + en["U"] + en["V"])):
                raise FloatingPointError("non-finite accelerations, reactions or energies")
        except (ValueError, ArithmeticError, np.linalg.LinAlgError,
                ElementEvaluationError) as exc:
            failure = (float(t), exc)
            break
        out["tip_position"].append(r)
        out["tip_velocity"].append(v)
        out["tip_acceleration"].append(a)
        out["energy_kinetic"].append(en["T"])
        out["energy_strain"].append(en["U"])
        out["energy_gravity"].append(en["V"])
        out["element_ends"].append([Q[off + b.s_coord(k)] for b, off in zip(model.beams, model.offsets)
                                    for k in range(len(b.breakpoints))])
        out["reactions"].append(reac)
    k = len(out["tip_position"])
    outputs = {name: np.real(np.array(v, dtype=float)) for name, v in out.items()}
    outputs["state"] = np.asarray(ys)[:k]
    stats["n_dof"] = int(n)
    res = Result(np.asarray(ts)[:k], outputs, stats, scene, error)
    if failure is not None and error is None:
        t, cause = failure
        why = cause.reason if isinstance(cause, SimulationError) else \
            f"{type(cause).__name__}: {cause}"
        exc = SimulationError(t, "the model cannot be evaluated at the integrated state of this "
                                 f"output time ({why}): the solution left the model's domain "
                                 "(steps far too large for its dynamics; tighten solver.rtol)",
                              last_state=np.asarray(ys)[k])
        res.error = str(exc)
        exc.result = res
        raise exc
    return res
