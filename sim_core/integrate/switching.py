"""Switching between RK45 and BDF by stiffness detection (the ``"auto"`` method).

RK45 runs while its step is set by accuracy; when :class:`StiffnessDetector` finds the step
limited by stability, :class:`MethodSwitch` hands over to BDF, and back to RK45 when the
spectral radius of a fresh Jacobian (:func:`spectral_radius`) says the explicit method's
stability region holds the step again.  Where the model tells whether its friction law is in
its stiff slope band (``Model.friction_in_slope_band``), BDF runs only while it is.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import BDF, RK45


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
    method switched to).

    ``stiff_friction(t, y)`` (optional; None: no such information): whether the model's
    friction law is in its slope band, the stiffness BDF is for.  While it is False a detector
    alarm keeps RK45 (counted in ``kept_rk45``): the stiffness is then the stress filter's
    eigenvalue pair, where BDF's longer steps leave a global error on the oscillating payload
    and booms far above RK45's at the same tolerance (benchmarks/results/
    tolerance_accuracy.md); and a BDF step that ends with it False hands back to RK45."""

    def __init__(self, rhs, window: int = 30, bdf_steps: int = 40,
                 max_bdf_steps: int = 5000, stay_factor: float = 2.0, fresh_jacobian=None,
                 stiff_friction=None):
        self.rhs = rhs
        self.fresh_jacobian = fresh_jacobian      # solver -> Jacobian at its state, or None
        self.stiff_friction = stiff_friction      # (t, y) -> bool or None, or None
        self.kept_rk45 = 0             # detector alarms without stiff friction (RK45 kept)
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

    def _friction_stiff(self, solver) -> bool:
        """Whether BDF may run at the solver's state: the model's friction is in its slope
        band (``stiff_friction``; True without that information)."""
        if self.stiff_friction is None:
            return True
        stiff = self.stiff_friction(solver.t, solver.y)
        return True if stiff is None else bool(stiff)

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
            if not self._friction_stiff(solver):
                self.detector = StiffnessDetector()
                self.kept_rk45 += 1
                return solver
            self.rk45_cost = self._cost(self.recent[0], now)
            self.n_bdf = 0
            new, name = make(BDF, solver.t, solver.y), "BDF"
        elif not self._friction_stiff(solver):      # every contact slides: back to RK45
            self.detector = StiffnessDetector()
            self.recent = [now]
            new, name = make(RK45, solver.t, solver.y), "RK45"
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
