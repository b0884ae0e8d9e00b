"""Generalized-α integration of ``M(q) q̈ = f(t, q, v)`` and a scipy ``solve_ivp`` wrapper.

Method
------
Chung–Hulbert generalized-α (J. Chung, G. M. Hulbert, "A time integration algorithm for
structural dynamics with improved numerical dissipation: the generalized-α method",
J. Appl. Mech. 60 (1993) 371–375) in the form of M. Arnold, O. Brüls, "Convergence of the
generalized-α scheme for constrained mechanical systems", Multibody Syst. Dyn. 18 (2007)
185–202, which applies directly to second-order ODEs with configuration-dependent mass::

    M(q_{n+1}) q̈_{n+1} = f(t_{n+1}, q_{n+1}, v_{n+1})
    (1-α_m) a_{n+1} + α_m a_n = (1-α_f) q̈_{n+1} + α_f q̈_n
    q_{n+1} = q_n + h v_n + h² (1/2 - β) a_n + h² β a_{n+1}
    v_{n+1} = v_n + h (1-γ) a_n + h γ a_{n+1}

``q̈`` is the true acceleration, ``a`` the auxiliary "acceleration-like" variable, which
approximates ``q̈(t_n + Δα h)`` with ``Δα = α_m - α_f`` (Arnold & Brüls 2007).
Newton iterations are done on ``x = q̈_{n+1}``; ``q_{n+1}`` and ``v_{n+1}`` are affine in x
with slopes ``β' h²`` and ``γ' h``, ``β' = β (1-α_f)/(1-α_m)``, ``γ' = γ (1-α_f)/(1-α_m)``,
so the iteration matrix is ``S = M + β' h² K + γ' h C`` (Arnold & Brüls 2007).

Error estimator (adaptive mode)
-------------------------------
The auxiliary variable has the asymptotic expansion (insert it into the a-recursion)
``a_n = q̈ + Δα h q⃛ + κ h² q⁗ + O(h³)`` at t_n, ``κ = Δα (α_m - 1/2)``.  Taylor expansion
of the q- and v-updates from exact data then gives the local errors::

    q_{n+1} - q(t_{n+1}) = c_q h³ q⃛ + O(h⁴),   c_q = β + Δα/2 - 1/6  (= 1/12 + Δα²/4)
    v_{n+1} - v(t_{n+1}) = c_v h³ q⁗ + O(h⁴),   c_v = 1/12 - Δα² + Δα (α_m - 1/2)

(both 1/12 for ρ∞ = 1, the trapezoidal rule).  The derivatives are replaced by divided
differences of the true accelerations: ``h q⃛ ≈ q̈_{n+1} - q̈_n`` and
``q⁗ ≈ 2 [(q̈_{n+1} - q̈_n)/h - (q̈_n - q̈_{n-1})/h_{n-1}] / (h + h_{n-1})``::

    e_q = c_q h² (q̈_{n+1} - q̈_n),   e_v = c_v h³ q⁗   (e_v = 0 on the first step)

e_q is the generalized-α analogue of the Newmark estimator of O. C. Zienkiewicz, Y. M. Xie,
"A simple error estimator and adaptive time stepping procedure for dynamic analysis",
Earthq. Eng. Struct. Dyn. 20 (1991) 871–887 (``(β - 1/6) h² Δq̈`` for α = 0); e_v makes the
test cover the velocities too and keeps the estimate from vanishing where q⃛ = 0 (for an
oscillation e_q ∝ sin, e_v ∝ cos).  The norm is scipy's: RMS over the 2n components of
``e / (atol + rtol |y|)``, y = (q, v); a step is accepted when it is ≤ 1, and
``h_new = h · safety · err^(-1/3)`` (local error O(h³)).  The tolerance bounds the error
made per step; the global error of this second-order method is roughly the sum over steps.

``error_estimate="position"`` tests e_q alone, RMS over the n coordinates: the estimator of
Zienkiewicz & Xie (1991), which is what the scene driver uses.  Where the step leaves stiff
modes unresolved (ω h > 1, left to the numerical dissipation of ρ∞ < 1) the divided
difference behind e_v does not fall as h³ but saturates at c_v h Δ²q̈ (the modes'
acceleration amplitude), so an atol in m/s far below their velocity forces steps that
resolve them: on the released cantilever (``cantilever_release``) at rtol 1e-3, atol 1e-5
the velocity term takes 26694 steps (min 1.8e-5 s) where e_q alone takes ~1000 for a tip
error of the same size.

Variable steps: ``a_n`` belongs to the last step ``h_old``; before a step ``h`` it is moved
to ``a_n ← q̈_n + (h / h_old)(a_n - q̈_n)``, the first-order Taylor consequence of
``a_n ≈ q̈(t_n + Δα h)`` (keeps second order on varying grids; without it every step change
injects an O(h) error into ``a``).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass
from typing import Callable, Sequence

import numpy as np
import scipy.linalg as sla
from scipy.integrate import BDF, DOP853, LSODA, RK23, RK45, Radau

from sim_core.errors import SimulationError
from sim_core.integrate.protocol import IntegrationResult, IntegrationStats, SecondOrderSystem

_EPS = float(np.finfo(float).eps)


# -- parameters ------------------------------------------------------------------------------

@dataclass(frozen=True)
class GeneralizedAlphaParameters:
    """Generalized-α coefficients for a spectral radius at infinity ``rho_inf`` ∈ [0, 1]."""

    rho_inf: float
    alpha_m: float
    alpha_f: float
    gamma: float
    beta: float

    @classmethod
    def from_rho_inf(cls, rho_inf: float) -> "GeneralizedAlphaParameters":
        """Chung & Hulbert (1993): α_m = (2ρ∞-1)/(ρ∞+1), α_f = ρ∞/(ρ∞+1),
        γ = 1/2 - α_m + α_f (second order), β = (1 - α_m + α_f)²/4 (optimal dissipation)."""
        rho = float(rho_inf)
        if not 0.0 <= rho <= 1.0:
            raise ValueError(f"rho_inf = {rho_inf!r} outside [0, 1]")
        am = (2.0 * rho - 1.0) / (rho + 1.0)
        af = rho / (rho + 1.0)
        return cls(rho, am, af, 0.5 - am + af, 0.25 * (1.0 - am + af) ** 2)

    @property
    def delta_alpha(self) -> float:
        """Δα = α_m - α_f: a_n ≈ q̈(t_n + Δα h) (Arnold & Brüls 2007)."""
        return self.alpha_m - self.alpha_f

    @property
    def beta_prime(self) -> float:
        """∂q_{n+1}/∂q̈_{n+1} = β' h² (Arnold & Brüls 2007, iteration matrix)."""
        return self.beta * (1.0 - self.alpha_f) / (1.0 - self.alpha_m)

    @property
    def gamma_prime(self) -> float:
        """∂v_{n+1}/∂q̈_{n+1} = γ' h (Arnold & Brüls 2007, iteration matrix)."""
        return self.gamma * (1.0 - self.alpha_f) / (1.0 - self.alpha_m)

    @property
    def error_constant(self) -> float:
        """Local position error constant c_q: e_q = c_q h³ q⃛ (Taylor expansion, see module
        doc); c_q = 1/12 + Δα²/4 (1/12 for ρ∞ = 1, 1/3 for ρ∞ = 0)."""
        return self.beta + 0.5 * self.delta_alpha - 1.0 / 6.0

    @property
    def velocity_error_constant(self) -> float:
        """Local velocity error constant c_v: e_v = c_v h³ q⁗ (module doc);
        c_v = 1/12 - Δα² + Δα (α_m - 1/2) (1/12 for ρ∞ = 1, 7/12 for ρ∞ = 0)."""
        da = self.delta_alpha
        return 1.0 / 12.0 - da * da + da * (self.alpha_m - 0.5)


# -- model evaluation ------------------------------------------------------------------------

class _NonFinite(Exception):
    """Raised internally when the model returns NaN/inf or fails numerically."""

    def __init__(self, t: float, reason: str, y: np.ndarray | None = None):
        super().__init__(reason)
        self.t, self.reason, self.y = t, reason, y
        self.t_accepted: float = t               # filled in by the scipy stepping loop
        self.y_accepted: np.ndarray | None = y


class _Evaluator:
    """Counts ``mass_and_force`` calls and checks shapes and finiteness."""

    def __init__(self, system: SecondOrderSystem):
        self.system = system
        self.n = int(system.n)
        self.n_calls = 0
        self.n_tangent = 0
        self.has_tangent = callable(getattr(system, "tangent", None))

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self.n_calls += 1
        try:
            M, f = self.system.mass_and_force(t, q, v)
        except (FloatingPointError, ZeroDivisionError, np.linalg.LinAlgError) as exc:
            raise _NonFinite(t, f"model evaluation failed: {exc}") from None
        M = np.asarray(M, dtype=float)
        f = np.asarray(f, dtype=float)
        if M.shape != (self.n, self.n) or f.shape != (self.n,):
            raise ValueError(f"mass_and_force returned shapes {M.shape}, {f.shape}; "
                             f"expected ({self.n}, {self.n}), ({self.n},)")
        if not (np.isfinite(M).all() and np.isfinite(f).all()):
            raise _NonFinite(t, "non-finite (NaN/inf) mass matrix or force")
        return M, f

    def tangent(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Analytic (K, C) from ``system.tangent``."""
        self.n_tangent += 1
        K, C = self.system.tangent(t, q, v)
        K = np.asarray(K, dtype=float)
        C = np.asarray(C, dtype=float)
        if not (np.isfinite(K).all() and np.isfinite(C).all()):
            raise _NonFinite(t, "non-finite (NaN/inf) tangent matrices")
        return K, C


def _accelerations(M: np.ndarray, f: np.ndarray, t: float) -> np.ndarray:
    """q̈ = M⁻¹ f (Cholesky; LU fallback when M is not numerically SPD)."""
    try:
        return sla.cho_solve(sla.cho_factor(M), f)
    except np.linalg.LinAlgError:
        try:
            return np.linalg.solve(M, f)
        except np.linalg.LinAlgError as exc:
            raise _NonFinite(t, f"singular mass matrix: {exc}") from None


def _fd_tangent(ev: _Evaluator, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray,
                M0: np.ndarray, f0: np.ndarray,
                rel_step: float) -> tuple[np.ndarray, np.ndarray]:
    """Forward differences, column by column, of the residual r(q, v) = M(q) a - f(t, q, v):
    K = ∂r/∂q, C = ∂r/∂v = -∂f/∂v (2n model evaluations; dense).
    Step δ_j = √eps max(|x_j|, 1) balances truncation and cancellation (Dennis & Schnabel, Numerical Methods for
    Unconstrained Optimization and Nonlinear Equations, 1983, Sect. 5.4)."""
    n = ev.n
    r0 = M0 @ a - f0
    K = np.empty((n, n))
    C = np.empty((n, n))
    for j in range(n):
        dq = q.copy()
        dq[j] += rel_step * max(abs(q[j]), 1.0)
        d = dq[j] - q[j]                     # exactly representable step
        M, f = ev(t, dq, v)
        K[:, j] = (M @ a - f - r0) / d
    for j in range(n):
        dv = v.copy()
        dv[j] += rel_step * max(abs(v[j]), 1.0)
        d = dv[j] - v[j]
        M, f = ev(t, q, dv)
        C[:, j] = (M @ a - f - r0) / d
    return K, C


def finite_difference_tangent(system: SecondOrderSystem, t: float, q: np.ndarray,
                              v: np.ndarray, a: np.ndarray | None = None, *,
                              rel_step: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(K, C) of ``system`` at (t s, q, v) by forward differences of the residual
    ``M(q) a - f(t, q, v)``; ``a`` defaults to ``M⁻¹ f`` (the consistent acceleration).

    This is the Jacobian used by :func:`integrate_generalized_alpha` when the system has no
    ``tangent`` method.  Units: K in N/m (per coordinate unit), C in N s/m.
    """
    ev = _Evaluator(system)
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    M0, f0 = ev(t, q, v)
    a = _accelerations(M0, f0, t) if a is None else np.asarray(a, dtype=float)
    return _fd_tangent(ev, t, q, v, a, M0, f0, math.sqrt(_EPS) if rel_step is None else rel_step)


# -- helpers ---------------------------------------------------------------------------------

def _split_atol(atol: float | Sequence[float] | np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """atol scalar, (n,) (same for q and v) or (2n,) ([q, v]) -> (atol_q, atol_v)."""
    arr = np.asarray(atol, dtype=float)
    if arr.ndim == 0:
        arr = np.full(2 * n, float(arr))
    elif arr.shape == (n,):
        arr = np.concatenate([arr, arr])
    elif arr.shape != (2 * n,):
        raise ValueError(f"atol must be a scalar, shape ({n},) or ({2 * n},); got {arr.shape}")
    if np.any(arr < 0):
        raise ValueError("atol must be non-negative")
    return arr[:n], arr[n:]


def _rms(x: np.ndarray) -> float:
    """Root mean square, scaled so that huge entries do not overflow."""
    m = float(np.max(np.abs(x))) if x.size else 0.0
    if m == 0.0 or not math.isfinite(m):
        return m
    return m * float(np.sqrt(np.mean((x / m) ** 2)))


def _check_t_eval(t_eval: Sequence[float] | np.ndarray | None, t0: float,
                  t1: float) -> np.ndarray | None:
    if t_eval is None:
        return None
    te = np.asarray(t_eval, dtype=float).ravel()
    if te.size and (np.any(np.diff(te) < 0) or te[0] < t0 or te[-1] > t1):
        raise ValueError(f"t_eval must be sorted and inside t_span = [{t0}, {t1}]")
    return te


def _hermite(s: float, h: float, y0: tuple[np.ndarray, ...],
             y1: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, v, q̈) at t0 + s h, s ∈ [0, 1]: q from the cubic Hermite on (q, v), v from the
    cubic Hermite on (v, q̈) and q̈ its derivative.  Each interpolant uses only first-derivative
    data, so the O(h³) inconsistency between the step data of a second-order method is not
    amplified by 1/h² (as it would be in a quintic's second derivative); errors are O(h³) in
    q, v and O(h²) in q̈, matching the method.  (Hermite dense output: Hairer, Nørsett &
    Wanner, Solving ODEs I, Sect. II.6.)"""
    q0, v0, a0 = y0
    q1, v1, a1 = y1
    h00, h10 = (2 * s - 3) * s * s + 1, ((s - 2) * s + 1) * s
    h01, h11 = (3 - 2 * s) * s * s, (s - 1) * s * s
    d00, d10, d01, d11 = 6 * s * (s - 1), (3 * s - 4) * s + 1, 6 * s * (1 - s), (3 * s - 2) * s
    q = h00 * q0 + h * h10 * v0 + h01 * q1 + h * h11 * v1
    v = h00 * v0 + h * h10 * a0 + h01 * v1 + h * h11 * a1
    a = (d00 * v0 + d01 * v1) / h + d10 * a0 + d11 * a1
    return q, v, a


class _Output:
    """Collects (t, q, v, q̈) at every step or at t_eval (cubic Hermite, see _hermite)."""

    def __init__(self, t_eval: np.ndarray | None, t0: float, state: tuple[np.ndarray, ...]):
        self.t_eval = t_eval
        self.ts: list[float] = []
        self.ys: list[tuple[np.ndarray, ...]] = []
        self.k = 0
        if t_eval is None:
            self._add(t0, state)
        else:
            while self.k < len(t_eval) and t_eval[self.k] <= t0:
                self._add(float(t_eval[self.k]), state)
                self.k += 1

    def _add(self, t: float, state: tuple[np.ndarray, ...]) -> None:
        self.ts.append(t)
        self.ys.append(tuple(np.array(x, copy=True) for x in state))

    def step(self, t0: float, y0: tuple[np.ndarray, ...], t1: float, y1: tuple[np.ndarray, ...],
             last: bool) -> None:
        if self.t_eval is None:
            self._add(t1, y1)
            return
        te, h = self.t_eval, t1 - t0
        while self.k < len(te) and (te[self.k] <= t1 or last):
            s = (te[self.k] - t0) / h
            self._add(float(te[self.k]), y1 if s >= 1.0 else _hermite(s, h, y0, y1))
            self.k += 1

    def arrays(self, n: int) -> tuple[np.ndarray, ...]:
        if not self.ys:
            e = np.empty((0, n))
            return np.asarray(self.ts), e, e.copy(), e.copy()
        q, v, a = (np.array([y[i] for y in self.ys]) for i in range(3))
        return np.asarray(self.ts), q, v, a


# -- generalized-α stepper -------------------------------------------------------------------

@dataclass
class _Step:
    """Converged Newton result of one step attempt."""

    q: np.ndarray
    v: np.ndarray
    qdd: np.ndarray
    a: np.ndarray
    n_iter: int
    rate: float


class _GeneralizedAlpha:
    """State, Jacobian cache and Newton solver of the generalized-α method
    (Arnold & Brüls 2007 form of Chung & Hulbert 1993)."""

    def __init__(self, ev: _Evaluator, params: GeneralizedAlphaParameters, t0: float,
                 q0: np.ndarray, v0: np.ndarray, rtol: float, atol_q: np.ndarray,
                 atol_v: np.ndarray, newton_tol: float, max_newton_iter: int,
                 use_tangent: bool, fd_rel_step: float, stats: IntegrationStats):
        self.ev, self.p, self.stats = ev, params, stats
        self.rtol, self.atol_q, self.atol_v = rtol, atol_q, atol_v
        self.newton_tol, self.max_iter = newton_tol, max_newton_iter
        self.use_tangent = use_tangent and ev.has_tangent
        self.fd_rel_step = fd_rel_step
        self.position_only = False                    # error test on e_q alone (module doc)
        self.t, self.q, self.v = t0, q0.copy(), v0.copy()
        M0, f0 = ev(t0, self.q, self.v)
        self.M, self.f = M0, f0                       # at the accepted state (FD base point)
        self.qdd = _accelerations(M0, f0, t0)
        # Arnold & Brüls (2007): a_0 = q̈_0 keeps second order in q and v.
        self.a = self.qdd.copy()
        self.h_a: float | None = None                 # step that a_n belongs to
        self.qdd_prev: np.ndarray | None = None       # q̈_{n-1} for the velocity estimate
        self.h_prev = 0.0                             # t_n - t_{n-1}, s
        self.step_index = 0
        self.K: np.ndarray | None = None
        self.C: np.ndarray | None = None
        self.jac_index = -1                           # step_index where (K, C) were formed
        self.jac_version = 0
        self.eta = 1.0                                # Newton convergence-rate memory
        self._lu: tuple | None = None
        self._lu_key: tuple | None = None
        self._lu_M: np.ndarray | None = None

    # Jacobian --------------------------------------------------------------------------------
    @property
    def jac_current(self) -> bool:
        return self.K is not None and self.jac_index == self.step_index

    def invalidate_jacobian(self) -> None:
        """Force a Jacobian refresh before the next step (poor Newton contraction)."""
        self.K = self.C = None
        self.jac_index = -1

    def refresh_jacobian(self) -> None:
        """(K, C) at the last accepted state: analytic ``tangent`` or finite differences."""
        if self.use_tangent:
            self.K, self.C = self.ev.tangent(self.t, self.q, self.v)
        else:
            self.K, self.C = _fd_tangent(self.ev, self.t, self.q, self.v, self.qdd,
                                         self.M, self.f, self.fd_rel_step)
        self.jac_index = self.step_index
        self.jac_version += 1
        self.stats.n_jacobian_evaluations += 1

    def _factor(self, M: np.ndarray, h: float) -> tuple:
        """LU of S = M + β' h² K + γ' h C (reused while h, K, C and M are unchanged)."""
        key = (h, self.jac_version)
        if self._lu is not None and key == self._lu_key and np.array_equal(M, self._lu_M):
            return self._lu
        S = M + (self.p.beta_prime * h * h) * self.K + (self.p.gamma_prime * h) * self.C
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            lu = sla.lu_factor(S, check_finite=False)
        d = np.abs(np.diag(lu[0]))
        if not np.isfinite(d).all() or d.min() <= _EPS * max(d.max(), 1e-300):
            raise _NonFinite(self.t + h, "singular Newton iteration matrix")
        self.stats.n_lu += 1
        self._lu, self._lu_key, self._lu_M = lu, key, M.copy()
        return lu

    # one step --------------------------------------------------------------------------------
    def shifted_a(self, h: float) -> np.ndarray:
        """a_n moved to step h: a_n ≈ q̈(t_n + Δα h) => a ← q̈_n + (h/h_old)(a - q̈_n)."""
        if self.h_a is None or h == self.h_a:
            return self.a
        return self.qdd + (h / self.h_a) * (self.a - self.qdd)

    def newton(self, h: float) -> _Step | None:
        """Solve M(q) x = f(t+h, q, v) for x = q̈_{n+1}, q = q_base + β'h² x,
        v = v_base + γ'h x (Arnold & Brüls 2007 corrector; Chung & Hulbert 1993 scheme).
        Modified Newton with the stopping test η‖Δ‖ ≤ tol, η = θ/(1-θ) from the contraction
        rate θ, and early divergence detection, as in RADAU5 / scipy's Radau (Hairer &
        Wanner, Solving ODEs II, Sect. IV.8).  None if it fails to converge."""
        p, q, v, qdd = self.p, self.q, self.v, self.qdd
        a_n = self.shifted_a(h)
        c = 1.0 / (1.0 - p.alpha_m)
        a_const = c * (p.alpha_f * qdd - p.alpha_m * a_n)        # a_{n+1} = a_const + c(1-α_f) x
        q_base = q + h * v + h * h * ((0.5 - p.beta) * a_n + p.beta * a_const)
        v_base = v + h * ((1.0 - p.gamma) * a_n + p.gamma * a_const)
        bq, bv = p.beta_prime * h * h, p.gamma_prime * h
        wq = self.atol_q + self.rtol * np.abs(q)
        wv = self.atol_v + self.rtol * np.abs(v)
        x = qdd.copy()                                            # predictor q̈_{n+1} = q̈_n
        eta = max(self.eta, _EPS) ** 0.8
        dnorm_old, rate = None, 0.0
        for k in range(self.max_iter):
            self.stats.n_newton_iterations += 1
            try:
                M, f = self.ev(self.t + h, q_base + bq * x, v_base + bv * x)
                if k == 0:
                    lu = self._factor(M, h)
            except _NonFinite:
                return None
            dx = -sla.lu_solve(lu, M @ x - f, check_finite=False)
            if not np.isfinite(dx).all():
                return None
            # weights floored at the roundoff level of q = q_base + β'h² x (stiff systems)
            fq = wq + 10.0 * _EPS * (np.abs(q_base) + np.abs(bq * x))
            fv = wv + 10.0 * _EPS * (np.abs(v_base) + np.abs(bv * x))
            dnorm = _rms(np.concatenate([bq * dx / fq, bv * dx / fv]))
            x = x + dx
            if dnorm_old is not None and dnorm_old > 0.0:
                rate = dnorm / dnorm_old
                if rate >= 1.0 or rate ** (self.max_iter - k) / (1.0 - rate) * dnorm > self.newton_tol:
                    return None
                eta = rate / (1.0 - rate)
            if dnorm == 0.0 or eta * dnorm <= self.newton_tol:
                self.eta = eta
                a1 = a_const + c * (1.0 - p.alpha_f) * x
                return _Step(q_base + bq * x, v_base + bv * x, x, a1, k + 1, rate)
            dnorm_old = dnorm
        return None

    def error_norm(self, h: float, step: _Step) -> float:
        """RMS over (q, v) of e / (atol + rtol |y|) with e_q = c_q h² (q̈_{n+1} - q̈_n) and
        e_v = c_v h³ q⁗ from divided differences (module doc)."""
        d1 = (step.qdd - self.qdd) / h                            # ≈ q⃛
        e_q = self.p.error_constant * h ** 3 * d1
        wq = self.atol_q + self.rtol * np.maximum(np.abs(self.q), np.abs(step.q))
        if self.position_only:                                    # Zienkiewicz & Xie (1991)
            return _rms(e_q / wq)
        wv = self.atol_v + self.rtol * np.maximum(np.abs(self.v), np.abs(step.v))
        if self.qdd_prev is None:
            e_v = np.zeros_like(e_q)
        else:
            d0 = (self.qdd - self.qdd_prev) / self.h_prev
            e_v = self.p.velocity_error_constant * h ** 3 * 2.0 * (d1 - d0) / (h + self.h_prev)
        return _rms(np.concatenate([e_q / wq, e_v / wv]))

    def accept(self, h: float, step: _Step) -> None:
        self.qdd_prev, self.h_prev = self.qdd, h
        self.t += h
        self.q, self.v, self.qdd, self.a, self.h_a = step.q, step.v, step.qdd, step.a, h
        self.step_index += 1
        self.M = self.f = None   # re-evaluated lazily for the next FD Jacobian

    def ensure_base(self) -> None:
        """Evaluate (M, f) at the accepted state if an FD Jacobian needs it."""
        if self.M is None and not self.use_tangent:
            self.M, self.f = self.ev(self.t, self.q, self.v)

    @property
    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.q, self.v, self.qdd

    def last_state(self) -> np.ndarray:
        return np.concatenate([self.q, self.v])


def _initial_step(ga: _GeneralizedAlpha, span: float, h_max: float) -> float:
    """Starting step (Hairer, Nørsett & Wanner, Solving ODEs I, Sect. II.4, as in scipy's
    ``select_initial_step``) for y = (q, v), y' = (v, q̈), order 2."""
    y = np.concatenate([ga.q, ga.v])
    f0 = np.concatenate([ga.v, ga.qdd])
    scale = np.concatenate([ga.atol_q, ga.atol_v]) + ga.rtol * np.abs(y)
    d0, d1 = _rms(y / scale), _rms(f0 / scale)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, h_max, span)
    n = ga.ev.n
    y1 = y + h0 * f0
    try:
        M, f = ga.ev(ga.t + h0, y1[:n], y1[n:])
        f1 = np.concatenate([y1[n:], _accelerations(M, f, ga.t + h0)])
    except _NonFinite:
        return 1e-3 * h0
    d2 = _rms((f1 - f0) / scale) / h0
    if max(d1, d2) <= 1e-15:
        h1 = max(1e-6, 1e-3 * h0)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 3.0)
    return min(100.0 * h0, h1, h_max, span)


def _fail(ga: _GeneralizedAlpha, reason: str, h: float | None) -> SimulationError:
    return SimulationError(ga.t, reason, step=h, last_state=ga.last_state())


def integrate_generalized_alpha(
        system: SecondOrderSystem, t_span: tuple[float, float], q0: np.ndarray, v0: np.ndarray,
        *, rho_inf: float = 0.8, h: float | None = None, rtol: float = 1e-6,
        atol: float | Sequence[float] | np.ndarray = 1e-8,
        t_eval: Sequence[float] | np.ndarray | None = None, h0: float | None = None,
        h_min: float | None = None, h_max: float | None = None, max_steps: int = 100_000,
        newton_tol: float | None = None, max_newton_iter: int = 8, use_tangent: bool = True,
        jac_refresh_rate: float = 0.3, refresh_on_reject: bool = True,
        max_newton_failures: int = 10, safety: float = 0.9, fac_min: float = 0.2,
        fac_max: float = 5.0, fd_rel_step: float | None = None,
        error_estimate: str = "position_velocity",
        callback: Callable[[float, float, np.ndarray, np.ndarray], None] | None = None,
        checkpoint: Callable[[Callable[[], dict]], None] | None = None,
        resume: dict | None = None, on_resume: Callable[[], None] | None = None
        ) -> IntegrationResult:
    """Integrate ``M(q) q̈ = f(t, q, v)`` with the generalized-α method.

    Parameters
    ----------
    system : SecondOrderSystem
        Model with ``n`` and ``mass_and_force``; its ``tangent`` (K, C) is used for the Newton
        matrix when present and ``use_tangent``, otherwise K, C come from forward differences
        of the residual (2n evaluations), reused across steps (modified Newton) and refreshed
        when the contraction rate exceeds ``jac_refresh_rate``, on Newton failure, and (if
        ``refresh_on_reject``) on error-test rejection.
    t_span : (t0, t1), s, t1 > t0.
    q0, v0 : initial coordinates and velocities (n,).
    rho_inf : spectral radius at infinity ρ∞ ∈ [0, 1] (1: no numerical dissipation).
    h : fixed step (s).  Given -> fixed-step mode: ``ceil((t1-t0)/h)`` equal steps of size
        ≤ h, no error control (rtol/atol only set the Newton stopping test).
    rtol, atol : tolerances as in scipy; atol scalar, (n,) (q and v alike) or (2n,) ([q, v]).
    t_eval : output times (sorted, inside t_span), cubic-Hermite interpolated from the step
        data (q, v, q̈); None: every step.
    h0, h_min, h_max : first, smallest and largest step (s) of the adaptive mode.
        Defaults: estimated; max(10 eps |t|, 1e-12 (t1-t0)); t1 - t0.
    max_steps : largest number of accepted steps (adaptive mode).
    newton_tol : stopping tolerance of the scaled Newton increment (scipy Radau default).
    max_newton_iter : iterations per attempt; ``max_newton_failures`` consecutive failed
        attempts (each followed by a step cut ×1/4) raise SimulationError.
    safety, fac_min, fac_max : step controller h_new = h clip(safety err^(-1/3), fac_min, fac_max).
    error_estimate : "position_velocity" (e_q and e_v over the 2n components) or "position"
        (e_q over the n coordinates, Zienkiewicz & Xie 1991); module doc.
    callback : called as ``callback(t, h, q, v)`` after every accepted step (s, s, state);
        it may raise SimulationError (a wall-clock budget, a stall), which ends the run.
    checkpoint : called as ``checkpoint(state)`` after every accepted step (after
        ``callback``) that is not the last; ``state()`` returns the whole integration state
        (:func:`_loop_state`: the method's state, Jacobian and LU cache, statistics, outputs
        so far and the step loop's controller memory: numbers, lists, tuples, dicts and
        arrays only), for a checkpoint file.
    resume : such a state: the integration continues from it and takes the steps the
        uninterrupted run takes (bit-identical outputs); ``on_resume()`` is called once it
        is restored, before the first step (the caller puts back what the restored
        construction's model evaluation changed, e.g. the model's warm starts).

    A SimulationError (or KeyboardInterrupt) raised during the steps carries the outputs
    reached so far as
    ``exc.partial_output = (t, q, v, q̈)`` and the statistics as ``exc.partial_stats``.

    Raises
    ------
    SimulationError
        Step below h_min, repeated Newton divergence, NaN/inf in the model, max_steps.
    """
    t0, t1 = float(t_span[0]), float(t_span[1])
    if not t1 > t0:
        raise ValueError(f"t_span must be increasing, got {t_span}")
    ev = _Evaluator(system)
    n = ev.n
    q0 = np.asarray(q0, dtype=float).reshape(n)
    v0 = np.asarray(v0, dtype=float).reshape(n)
    te = _check_t_eval(t_eval, t0, t1)
    atol_q, atol_v = _split_atol(atol, n)
    if rtol <= 0:
        raise ValueError("rtol must be positive")
    params = GeneralizedAlphaParameters.from_rho_inf(rho_inf)
    stats = IntegrationStats(method=f"generalized-alpha(rho_inf={params.rho_inf:g})")
    if newton_tol is None:          # scipy's Radau choice
        newton_tol = max(10.0 * _EPS / rtol, min(0.03, rtol ** 0.5))
    try:
        ga = _GeneralizedAlpha(ev, params, t0, q0, v0, rtol, atol_q, atol_v, newton_tol,
                               max_newton_iter, use_tangent,
                               math.sqrt(_EPS) if fd_rel_step is None else fd_rel_step, stats)
    except _NonFinite as exc:
        raise SimulationError(t0, f"initial state: {exc.reason}",
                              last_state=np.concatenate([q0, v0])) from None
    if error_estimate not in ("position_velocity", "position"):
        raise ValueError(f"error_estimate = {error_estimate!r}: 'position_velocity' or 'position'")
    ga.position_only = error_estimate == "position"
    out = _Output(te, t0, ga.state)
    loop = None
    if resume is not None:
        loop = _restore_loop_state(resume, ga, out, stats)
        if on_resume is not None:
            on_resume()
    try:
        if h is not None:
            _run_fixed(ga, out, t1, float(h), jac_refresh_rate, callback, checkpoint, loop)
        else:
            span = t1 - t0
            h_min = max(10 * _EPS * max(abs(t0), abs(t1)), 1e-12 * span) if h_min is None else h_min
            h_max = span if h_max is None else min(h_max, span)
            ctl = _Controller(safety, fac_min, fac_max, h_min, h_max, max_steps,
                              max_newton_failures, jac_refresh_rate, refresh_on_reject)
            _run_adaptive(ga, out, t1, ctl, h0, callback, checkpoint, loop)
    except (SimulationError, KeyboardInterrupt) as exc:
        stats.n_force_evaluations = ev.n_calls
        exc.partial_output = out.arrays(n)
        exc.partial_stats = stats
        raise
    stats.n_force_evaluations = ev.n_calls
    ts, q, v, a = out.arrays(n)
    return IntegrationResult(ts, q, v, a, stats)


_GA_SKIP = ("ev", "p", "stats")


def _loop_state(ga: _GeneralizedAlpha, out: _Output, loop: dict) -> dict:
    """The whole state of a step loop after an accepted step: the method's numbers and arrays
    (state, accelerations, auxiliary accelerations, Jacobian, LU cache, Newton rate memory),
    the evaluation counters, the statistics, the outputs so far and the loop's own memory
    ``loop`` (step controller)."""
    return {"ga": {k: v for k, v in vars(ga).items() if k not in _GA_SKIP},
            "ev": {"n_calls": ga.ev.n_calls, "n_tangent": ga.ev.n_tangent},
            "stats": asdict(ga.stats), "out": {"ts": list(out.ts), "ys": list(out.ys),
                                               "k": out.k}, "loop": dict(loop)}


def _restore_loop_state(state: dict, ga: _GeneralizedAlpha, out: _Output,
                        stats: IntegrationStats) -> dict:
    """Put a :func:`_loop_state` back onto fresh objects; returns the loop's memory."""
    for k, v in state["ga"].items():
        setattr(ga, k, v)
    ga.ev.n_calls, ga.ev.n_tangent = state["ev"]["n_calls"], state["ev"]["n_tangent"]
    for k, v in state["stats"].items():
        setattr(stats, k, v)
    out.ts, out.ys, out.k = list(state["out"]["ts"]), list(state["out"]["ys"]), state["out"]["k"]
    return dict(state["loop"])


def _record_step(stats: IntegrationStats, h: float) -> None:
    stats.n_steps += 1
    stats.min_step = h if not stats.min_step <= h else stats.min_step
    stats.max_step = h if not stats.max_step >= h else stats.max_step


def _run_fixed(ga: _GeneralizedAlpha, out: _Output, t1: float, h_req: float,
               jac_refresh_rate: float, callback=None, checkpoint=None,
               loop: dict | None = None) -> None:
    """Fixed-step mode: N = ceil(span/h) equal steps, Newton failure or NaN -> SimulationError.
    ``checkpoint``, ``loop``: :func:`integrate_generalized_alpha`'s checkpoint hook and the
    restored loop memory (the grid's start, step count and the next step's index)."""
    if not h_req > 0:
        raise ValueError(f"fixed step h must be positive, got {h_req}")
    if loop is None:
        t0 = ga.t
        n_steps = max(1, math.ceil((t1 - t0) / h_req * (1.0 - 1e-12)))
        i0 = 0
    else:
        t0, n_steps, i0 = loop["t0"], loop["n_steps"], loop["i"]
    h = (t1 - t0) / n_steps
    for i in range(i0, n_steps):
        if ga.K is None:
            ga.ensure_base()
            _jac(ga, h)
        step = ga.newton(h)
        if step is None and not ga.jac_current:
            ga.ensure_base()
            _jac(ga, h)
            step = ga.newton(h)
        if step is None:
            ga.stats.n_newton_failures += 1
            raise _fail(ga, "Newton iteration did not converge or the model returned NaN/inf "
                        "(fixed-step mode)", h)
        y0, tp = ga.state, ga.t
        ga.accept(h, step)
        ga.t = t1 if i == n_steps - 1 else t0 + (i + 1) * h      # no drift of t
        _record_step(ga.stats, h)
        out.step(tp, y0, ga.t, ga.state, last=i == n_steps - 1)
        if step.n_iter > 2 and step.rate > jac_refresh_rate:
            ga.invalidate_jacobian()
        if callback is not None:
            callback(ga.t, h, ga.q, ga.v)
        if checkpoint is not None and i < n_steps - 1:
            checkpoint(lambda: _loop_state(ga, out, {"t0": t0, "n_steps": n_steps, "i": i + 1}))


def _jac(ga: _GeneralizedAlpha, h: float) -> None:
    try:
        ga.refresh_jacobian()
    except _NonFinite as exc:
        raise _fail(ga, f"Jacobian: {exc.reason}", h) from None


@dataclass
class _Controller:
    """Step-size control settings of the adaptive mode."""

    safety: float
    fac_min: float
    fac_max: float
    h_min: float
    h_max: float
    max_steps: int
    max_newton_failures: int
    jac_refresh_rate: float
    refresh_on_reject: bool

    def floor(self, t: float) -> float:
        """Smallest allowed step at time t (s): h_min, and never below 10 eps |t|."""
        return max(self.h_min, 10.0 * _EPS * abs(t))

    def factor(self, err: float, n_iter: int, max_iter: int, allow_growth: bool,
               predictive: float = 1.0) -> float:
        """h_new/h = safety err^(-1/3) (local error O(h³)); the safety factor is lowered
        after slow Newton convergence and ``predictive`` (≤ 1) is Gustafsson's predictive
        factor, both as in RADAU5 / scipy's Radau (Hairer & Wanner, Solving ODEs II, IV.8)."""
        safety = self.safety * (2 * max_iter + 1) / (2 * max_iter + n_iter)
        fac = self.fac_max if err == 0.0 else safety * min(1.0, predictive) * err ** (-1.0 / 3.0)
        fac = min(fac, self.fac_max if allow_growth else 1.0)
        if 1.0 <= fac < 1.2:                   # hysteresis: keep h (and the LU) unchanged
            fac = 1.0
        return max(self.fac_min, fac)


def _run_adaptive(ga: _GeneralizedAlpha, out: _Output, t1: float, ctl: _Controller,
                  h0: float | None, callback=None, checkpoint=None,
                  loop: dict | None = None) -> None:
    """Adaptive mode: error test on (e_q, e_v) (module doc), rejection, Newton-failure cuts
    (×1/4), Jacobian refresh on Newton failure / slow contraction / rejection.  Controller
    and starting step after Hairer, Nørsett & Wanner, Solving ODEs I, Sect. II.4, with the
    RADAU5 refinements of Hairer & Wanner, Solving ODEs II, Sect. IV.8.  ``checkpoint``,
    ``loop``: :func:`integrate_generalized_alpha`'s checkpoint hook and the restored loop
    memory (next step, failure count, rejection flag, predictive controller's memory)."""
    stats = ga.stats
    if loop is None:
        h = _initial_step(ga, t1 - ga.t, ctl.h_max) if h0 is None else float(h0)
        h = min(max(h, ctl.h_min), ctl.h_max)
        failures = 0
        rejected_last = False
        h_old = err_old = None              # last accepted step and its error (predictive control)
    else:
        h, failures, rejected_last = loop["h"], loop["failures"], loop["rejected_last"]
        h_old, err_old = loop["h_old"], loop["err_old"]
    while ga.t < t1:
        if stats.n_steps >= ctl.max_steps:
            raise _fail(ga, f"max_steps = {ctl.max_steps} reached", h)
        last = ga.t + h >= t1 - ctl.h_min
        h_try = t1 - ga.t if last else h
        if ga.K is None:
            ga.ensure_base()
            _jac(ga, h_try)
        step = ga.newton(h_try)
        if step is None:
            if not ga.jac_current:
                ga.ensure_base()
                _jac(ga, h_try)
                continue
            stats.n_rejected += 1
            stats.n_newton_failures += 1
            failures += 1
            if failures >= ctl.max_newton_failures:
                raise _fail(ga, f"Newton iteration diverged or the model returned NaN/inf in "
                            f"{failures} consecutive attempts", h_try)
            h = 0.25 * h_try
            if h < ctl.floor(ga.t):
                raise _fail(ga, f"step size {h:.3g} s below h_min = {ctl.floor(ga.t):.3g} s "
                            f"(Newton failure / NaN)", h)
            rejected_last = True
            continue
        err = ga.error_norm(h_try, step)
        if not math.isfinite(err):
            raise _fail(ga, "non-finite error estimate", h_try)
        if err > 1.0:
            stats.n_rejected += 1
            stats.n_error_rejections += 1
            h = h_try * ctl.factor(err, step.n_iter, ga.max_iter, allow_growth=False)
            if h < ctl.floor(ga.t):
                raise _fail(ga, f"step size {h:.3g} s below h_min = {ctl.floor(ga.t):.3g} s "
                            f"(error test, err = {err:.3g})", h)
            if ctl.refresh_on_reject and not ga.jac_current:
                ga.ensure_base()
                _jac(ga, h)
            rejected_last = True
            continue
        failures = 0
        y0, tp = ga.state, ga.t
        ga.accept(h_try, step)
        if last:
            ga.t = t1
        _record_step(stats, h_try)
        out.step(tp, y0, ga.t, ga.state, last=last)
        if step.n_iter > 2 and step.rate > ctl.jac_refresh_rate:
            ga.invalidate_jacobian()                       # slow contraction: refresh next step
        if callback is not None:
            callback(ga.t, h_try, ga.q, ga.v)
        pred = 1.0 if h_old is None or err == 0.0 else (h_try / h_old) * (err_old / err) ** (1 / 3)
        h = min(ctl.h_max, h_try * ctl.factor(err, step.n_iter, ga.max_iter,
                                              allow_growth=not rejected_last, predictive=pred))
        h_old, err_old = h_try, max(err, 1e-10)
        rejected_last = False
        if h < ctl.floor(ga.t) and ga.t < t1:
            raise _fail(ga, f"step size {h:.3g} s below h_min = {ctl.floor(ga.t):.3g} s "
                        f"(error control)", h)
        if checkpoint is not None and ga.t < t1:
            checkpoint(lambda: _loop_state(ga, out, {
                "h": h, "failures": failures, "rejected_last": rejected_last, "h_old": h_old,
                "err_old": err_old}))


# -- scipy wrapper ---------------------------------------------------------------------------

_SCIPY_METHODS = {"RK23": RK23, "RK45": RK45, "DOP853": DOP853, "Radau": Radau, "BDF": BDF,
                  "LSODA": LSODA}


def integrate_scipy(system: SecondOrderSystem, t_span: tuple[float, float], q0: np.ndarray,
                    v0: np.ndarray, method: str = "Radau", rtol: float = 1e-6,
                    atol: float | Sequence[float] | np.ndarray = 1e-8,
                    t_eval: Sequence[float] | np.ndarray | None = None, *,
                    use_tangent: bool = True, max_step: float = np.inf,
                    first_step: float | None = None) -> IntegrationResult:
    """Integrate the first-order form y = (q, v), y' = (v, M⁻¹ f) with the solvers behind
    scipy's ``solve_ivp`` ("Radau", "BDF", "RK45"; also "RK23", "DOP853", "LSODA"), stepped
    directly (as solve_ivp does) so that a failure reports the last accepted time.
    Sources: P. Virtanen et al., "SciPy 1.0", Nat. Methods 17 (2020) 261–272 (Radau IIA of
    Hairer & Wanner, NDF/BDF of Shampine & Reichelt 1997, RK45 of Dormand & Prince 1980).

    For implicit methods the analytic Jacobian ``[[0, I], [-M⁻¹K, -M⁻¹C]]`` is passed when the
    system has ``tangent`` (and ``use_tangent``); otherwise scipy differences numerically.
    Output at ``t_eval`` comes from scipy's dense output of each step; q̈ at the outputs is
    ``M⁻¹ f`` (extra model evaluations, counted in ``stats.extra["n_output_evaluations"]``).
    atol as in :func:`integrate_generalized_alpha`.  scipy failures and NaN/inf raise
    SimulationError at the last accepted time.
    """
    t0, t1 = float(t_span[0]), float(t_span[1])
    if not t1 > t0:
        raise ValueError(f"t_span must be increasing, got {t_span}")
    if method not in _SCIPY_METHODS:
        raise ValueError(f"method {method!r} not in {sorted(_SCIPY_METHODS)}")
    ev = _Evaluator(system)
    n = ev.n
    y0 = np.concatenate([np.asarray(q0, float).reshape(n), np.asarray(v0, float).reshape(n)])
    te = _check_t_eval(t_eval, t0, t1)
    atol_q, atol_v = _split_atol(atol, n)
    rhs, jac = _first_order(ev, use_tangent and method in ("Radau", "BDF", "LSODA"))
    kwargs: dict = {"rtol": rtol, "atol": np.concatenate([atol_q, atol_v]), "max_step": max_step}
    if first_step is not None:
        kwargs["first_step"] = first_step
    if jac is not None:
        kwargs["jac"] = jac
    try:
        solver = _SCIPY_METHODS[method](rhs, t0, y0, t1, **kwargs)
        ts, ys, steps = _scipy_steps(solver, te, t0, y0)
    except _NonFinite as exc:
        raise SimulationError(exc.t_accepted, f"scipy {method}: {exc.reason} "
                              f"(evaluation at t = {exc.t:.6g} s)",
                              last_state=exc.y_accepted) from None
    n_solver_calls = ev.n_calls
    Y = np.array(ys).reshape(len(ts), 2 * n)
    try:
        A = np.array([rhs(t, y)[n:] for t, y in zip(ts, Y)]).reshape(len(ts), n)
    except _NonFinite as exc:
        raise SimulationError(exc.t, f"output accelerations: {exc.reason}",
                              last_state=exc.y) from None
    stats = IntegrationStats(
        method=f"scipy-{method}", n_steps=len(steps), n_rejected=None, n_newton_iterations=None,
        n_jacobian_evaluations=int(solver.njev), n_force_evaluations=n_solver_calls,
        n_lu=int(solver.nlu), min_step=float(steps.min()) if steps.size else float("nan"),
        max_step=float(steps.max()) if steps.size else float("nan"), n_error_rejections=None,
        n_newton_failures=None, nfev=int(solver.nfev), njev=int(solver.njev), nlu=int(solver.nlu),
        extra={"n_output_evaluations": ev.n_calls - n_solver_calls,
               "n_tangent_evaluations": ev.n_tangent})
    return IntegrationResult(np.asarray(ts, float), Y[:, :n].copy(), Y[:, n:].copy(), A, stats)


def _scipy_steps(solver, te: np.ndarray | None, t0: float,
                 y0: np.ndarray) -> tuple[list[float], list[np.ndarray], np.ndarray]:
    """Step a scipy OdeSolver to its end; returns output times, states (every step or at
    ``te`` from the dense output) and the accepted step sizes.  Raises _NonFinite (with the
    last accepted time/state attached) or SimulationError."""
    steps: list[float] = []
    ts: list[float] = []
    ys: list[np.ndarray] = []
    k = 0
    if te is None:
        ts.append(t0)
        ys.append(y0.copy())
    else:
        while k < len(te) and te[k] <= t0:
            ts.append(float(te[k]))
            ys.append(y0.copy())
            k += 1
    while solver.status == "running":
        t_acc, y_acc = solver.t, solver.y.copy()
        try:
            msg = solver.step()
        except _NonFinite as exc:
            exc.t_accepted, exc.y_accepted = t_acc, y_acc
            raise
        if solver.status == "failed" or not np.isfinite(solver.y).all():
            raise SimulationError(t_acc, f"scipy {type(solver).__name__} failed: "
                                  f"{msg or 'non-finite state'}", step=solver.step_size,
                                  last_state=y_acc)
        steps.append(solver.t - solver.t_old)
        if te is None:
            ts.append(solver.t)
            ys.append(solver.y.copy())
            continue
        last = solver.status == "finished"
        if k < len(te) and (te[k] <= solver.t or last):
            dense = solver.dense_output()
            while k < len(te) and (te[k] <= solver.t or last):
                ts.append(float(te[k]))
                ys.append(solver.y.copy() if te[k] >= solver.t else dense(te[k]))
                k += 1
    return ts, ys, np.asarray(steps)


def _first_order(ev: _Evaluator, with_jac: bool) -> tuple[Callable, Callable | None]:
    """RHS y' = (v, M⁻¹ f) and, from ``tangent``, J = [[0, I], [-M⁻¹K, -M⁻¹C]]."""
    n = ev.n

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        if not np.isfinite(y).all():
            raise _NonFinite(t, "non-finite state", y.copy())
        try:
            M, f = ev(t, y[:n], y[n:])
            return np.concatenate([y[n:], _accelerations(M, f, t)])
        except _NonFinite as exc:
            exc.y = y.copy()
            raise

    if not (with_jac and ev.has_tangent):
        return rhs, None

    def jac(t: float, y: np.ndarray) -> np.ndarray:
        try:
            M, _ = ev(t, y[:n], y[n:])
            K, C = ev.tangent(t, y[:n], y[n:])
        except _NonFinite as exc:
            exc.y = y.copy()
            raise
        J = np.zeros((2 * n, 2 * n))
        J[:n, n:] = np.eye(n)
        J[n:, :n] = -np.linalg.solve(M, K)
        J[n:, n:] = -np.linalg.solve(M, C)
        return J

    return rhs, jac
