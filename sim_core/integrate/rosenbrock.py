"""The Rosenbrock-W method ROS2 at a fixed step with a reused Jacobian (``solver.method = "ROS2"``).

The training integrator of the full telescopic model: few right-hand sides per step, whatever
the stiffness.  ROS2 (Verwer, Spee, Blom & Hundsdorfer 1999, SIAM J. Sci. Comput. 20(4),
Eq. 2.2; gamma = 1 + 1/sqrt(2)) in the W form, for y' = f(t, y), written for the autonomous
system (y, t)' = (f, 1) with the W matrix [[A, a], [0, 0]]:

    (I - gamma h A) k1 = f(t, y) + gamma h a,
    (I - gamma h A) k2 = f(t + h, y + h k1) - 2 k1 - gamma h a,
    y1 = y + h (3/2 k1 + 1/2 k2).

It is second order for *any* matrix A and vector a (a W-method), so the Jacobian may be old:
A and a = df/dt are renewed only every ``jacobian_interval`` seconds of simulated time; with
the exact ones it is L-stable.  Two things lower the order on stiff problems: a stiff
component driven by a time-dependent forcing lags it by O(h) when a is stale (the
Prothero-Robinson test, tests/integrators/test_rosenbrock.py), and the friction law is only C0
at |v| = v_eps.  On the telescopic model between renewals the method is first order
(tests/integrators/test_rosenbrock.py: halving h halves the tip's error).

A is the model's structured state Jacobian (:func:`sim_core.model.state_jacobian.
state_jacobian`) with the friction law's falling branch levelled (:func:`monotone_friction`),
J = [[0, I], [J_zz, J_zv]] for y = (z, z'); a stage solve goes through the velocity block,

    (I - g J_zv - g^2 J_zz) k_v = r_v + g J_zz r_z,   k_z = r_z + g k_v,   g = gamma h,

one n x n LU factorisation per Jacobian and step size; a = df/dt is a forward difference in t
(one right-hand side per Jacobian).  Two right-hand sides per step, and one at each call's
start (the stepper's clock and commands change between calls): the one at a step's end is the
next step's first within a call.

Friction makes the Jacobian switch: near stick the regularised law is a damper mu_s N / v_eps
on the contact coordinates, in sliding it is not.  A step whose end lies on the other side of
the law's slope band than the Jacobian's state (``Model.friction_in_slope_band``) is therefore
repeated in two halves with a fresh Jacobian, down to h / 2**MAX_HALVINGS, where it is taken
as it is.  A step whose right-hand side fails or is not finite is halved the same way, and
beyond that raises :class:`sim_core.errors.SimulationError` with the time and the reason.  A
call's last step is not evaluated at its end (no step uses that right-hand side), so a state
there whose model cannot be solved raises at the next call's start instead.
"""

from __future__ import annotations

import contextlib
import copy
import math

import numpy as np
import scipy.linalg as sla

from sim_core.errors import SimulationError
from sim_core.model.state_jacobian import state_jacobian
from sim_core.physics.contact.sliding_block_contact import FrictionLaw

GAMMA = 1.0 + 1.0 / math.sqrt(2.0)      # Verwer et al. 1999, Eq. 2.2
B1, B2 = 1.5, 0.5                       # y1 = y + h (B1 k1 + B2 k2)
MAX_HALVINGS = 3                        # a repeated step is halved at most this often
FT_STEP = 1e-6                          # s, the difference step of df/dt
#: what a failed model solve raises under _raise_fp (scipy's finite check raises ValueError)
_SOLVE_FAILURES = (ArithmeticError, np.linalg.LinAlgError, ValueError, SimulationError)


def _raise_fp():
    """Floating-point overflow, division by zero and invalid results raise (underflow not)."""
    return np.errstate(over="raise", divide="raise", invalid="raise", under="ignore")


@contextlib.contextmanager
def monotone_friction(model):
    """Within the block every friction law of the model's multiplier forces has mu_d = mu_s:
    mu(v) rises through the stick band |v| <= v_eps and stays at mu_s beyond, without the
    falling branch v_eps < |v| < 2 v_eps (mu_s -> mu_d, docs/model.md#input-friction).

    The W matrix of :class:`RosenbrockW2` is the Jacobian of this model.  On the falling branch
    the law's negative slope gives a contact coordinate a real positive eigenvalue (a growth
    rate (mu_s - mu_d) N / (v_eps M), ~10 1/s for a stage behind the oil column), and ROS2's
    stability function R(z) = (1 - (2 gamma - 1) z) / (1 - gamma z)^2 (gamma^2 - 2 gamma + 1/2
    = 0) has its pole at z = h lambda = 1/gamma ~ 0.59 on the positive real axis, which that
    eigenvalue reaches at h ~ 0.06 s: with the exact Jacobian the step amplifies the branch
    without bound.  Levelled, the branch is integrated as by an explicit method
    (growth e^(h lambda), the physics), and the method keeps its order 2, which holds for any
    W matrix."""
    swapped = []
    for mf in getattr(model, "multiplier_forces", ()):
        law = getattr(mf, "law", None)
        if isinstance(law, FrictionLaw) and law.mu_dynamic != law.mu_static:
            swapped.append((mf, law))
            mf.law = FrictionLaw(law.mu_static, law.mu_static, law.v_eps)
    try:
        yield
    finally:
        for mf, law in swapped:
            mf.law = law


class RosenbrockW2:
    """ROS2 at the fixed step ``h`` (s) on a model's reduced first-order system, the structured
    Jacobian renewed every ``jacobian_interval`` s of simulated time (module docstring).

    ``advance(t0, y, dt)`` integrates from the model time ``t0`` over ``dt`` in
    ceil(dt / h) equal steps of at most h and returns the state; the integrator keeps its
    Jacobian between calls, so consecutive calls (a stepper's control steps) share it.
    ``stats``: accepted steps, right-hand sides and Jacobians so far.  ``state()`` /
    ``restore(state)`` save and put back all that the future steps depend on.  ``model``:
    ``rhs(t, y)`` and ``n_dof`` (y = (z, z'), 2 n_dof long), optionally
    ``friction_in_slope_band(t, z, z')`` and ``multiplier_forces``; ``jacobian(model, t, y)``:
    dy'/dy (default the structured one)."""

    def __init__(self, model, h: float, jacobian_interval: float, jacobian=state_jacobian):
        if not (math.isfinite(h) and h > 0.0):
            raise ValueError(f"solver.h = {h!r}: must be a step > 0 s")
        if not (math.isfinite(jacobian_interval) and jacobian_interval >= 0.0):
            raise ValueError(f"solver.jacobian_interval = {jacobian_interval!r}: must be >= 0 s")
        self.model, self.h, self.interval = model, float(h), float(jacobian_interval)
        self.n = int(model.n_dof)
        self._jacobian = jacobian
        self.stats = {"n_steps": 0, "n_rhs": 0, "n_jacobians": 0}
        self.age = math.inf              # simulated time since the Jacobian, s
        self.band = None                 # friction_in_slope_band at the Jacobian's state
        self.Jzz = self.Jzv = None
        self.ft = 0.0                    # df/dt at the Jacobian's state
        self._lu = self._lu_g = None
        self._t_fail = 0.0               # the model time of the call, for the error's time

    # -- the pieces ------------------------------------------------------------------------
    def rhs(self, t: float, y: np.ndarray) -> np.ndarray | None:
        """f(t, y), or None where the model's solve fails or the result is not finite."""
        self.stats["n_rhs"] += 1
        try:
            with _raise_fp():
                f = self.model.rhs(t, y)
        except _SOLVE_FAILURES:
            return None
        return f if np.all(np.isfinite(f)) else None

    def renew(self, t: float, y: np.ndarray, f: np.ndarray) -> None:
        """A fresh structured Jacobian at (t, y), of the model with the friction law's falling
        branch levelled (:func:`monotone_friction`), the friction regime it holds for, and
        the time derivative df/dt (a forward difference over FT_STEP from f = f(t, y))."""
        n = self.n
        try:
            with monotone_friction(self.model), _raise_fp():
                J = self._jacobian(self.model, t, y)
        except _SOLVE_FAILURES as exc:
            raise SimulationError(self._t_fail + t, "ROS2: the Jacobian failed "
                                  f"({type(exc).__name__}: {exc})", step=self.h,
                                  last_state=y) from None
        if not np.all(np.isfinite(J)):
            raise SimulationError(self._t_fail + t, "ROS2: the Jacobian is not finite",
                                  step=self.h, last_state=y)
        self.stats["n_jacobians"] += 1
        f_dt = self.rhs(t + FT_STEP, y)
        self.ft = 0.0 if f_dt is None else (f_dt - f) / FT_STEP
        self.Jzz, self.Jzv = J[n:, :n].copy(), J[n:, n:].copy()
        self.band = self._band(t, y)
        self.age, self._lu_g = 0.0, None

    def _band(self, t: float, y: np.ndarray):
        f = getattr(self.model, "friction_in_slope_band", None)
        return None if f is None else f(t, y[:self.n], y[self.n:])

    def solve(self, r: np.ndarray, g: float) -> np.ndarray:
        """k of (I - g A) k = r through the velocity block (module docstring)."""
        n = self.n
        if self._lu_g != g:
            self._lu = sla.lu_factor(np.eye(n) - g * self.Jzv - g * g * self.Jzz,
                                     check_finite=False)
            self._lu_g = g
        kv = sla.lu_solve(self._lu, r[n:] + g * (self.Jzz @ r[:n]), check_finite=False)
        return np.concatenate([r[:n] + g * kv, kv])

    def _try(self, t: float, y: np.ndarray, h: float, f0: np.ndarray, last: bool):
        """One ROS2 step: (y1, f(t + h, y1), whether y1 lies across the friction's slope band
        from the state of an old Jacobian), or None where a right-hand side fails or y1 is
        not finite.  ``last``: the call's last step, whose f(t + h, y1) no step uses (the
        next call starts on its own clock and commands): None in its place."""
        g = GAMMA * h
        gft = g * self.ft
        k1 = self.solve(f0 + gft, g)
        f = self.rhs(t + h, y + h * k1)
        if f is None:
            return None
        k2 = self.solve(f - 2.0 * k1 - gft, g)
        y1 = y + h * (B1 * k1 + B2 * k2)
        if not np.all(np.isfinite(y1)):
            return None
        f1 = None if last else self.rhs(t + h, y1)
        if f1 is None and not last:
            return None
        # the friction's regime changed under an old Jacobian: a fresh one
        crossed = self.age > 0.0 and self._band(t + h, y1) != self.band
        return y1, f1, crossed

    def _step(self, t: float, y: np.ndarray, h: float, f0: np.ndarray, depth: int = 0,
              last: bool = False):
        out = self._try(t, y, h, f0, last)
        if out is not None and (not out[2] or depth >= MAX_HALVINGS):
            self.stats["n_steps"] += 1
            self.age += h
            return out[:2]
        if depth >= MAX_HALVINGS:
            raise SimulationError(self._t_fail + t, "ROS2 failed: the step's right-hand side "
                                  "failed or was not finite at h / "
                                  f"{2 ** depth:g} with a fresh Jacobian",
                                  step=h, last_state=y)
        self.renew(t, y, f0)
        ym, fm = self._step(t, y, h / 2.0, f0, depth + 1)
        return self._step(t + h / 2.0, ym, h / 2.0, fm, depth + 1, last)

    # -- stepping ------------------------------------------------------------------------------
    def advance(self, t0: float, y: np.ndarray, dt: float, t_report: float = 0.0) -> np.ndarray:
        """The state at t0 + dt from y at the model time t0 (ceil(dt / h) equal steps); a
        failure raises SimulationError at ``t_report`` + the model time where it failed."""
        self._t_fail = float(t_report)
        y = np.asarray(y, dtype=float).copy()
        f = self.rhs(t0, y)
        if f is None:          # the state the previous call's last step reached is unsolvable
            raise SimulationError(t_report + t0, "ROS2: the right-hand side at the step's "
                                  "start failed or is not finite", step=self.h, last_state=y)
        k = max(1, math.ceil(dt / self.h - 1e-9))
        h = dt / k
        for j in range(k):
            t = t0 + j * h
            if self.age >= self.interval - 1e-12:
                self.renew(t, y, f)
            y, f = self._step(t, y, h, f, last=j == k - 1)
        return y

    # -- checkpoints ---------------------------------------------------------------------------
    def state(self) -> dict:
        """All that the future steps depend on (the Jacobian, its age and regime, counters)."""
        return copy.deepcopy({"age": self.age, "band": self.band, "Jzz": self.Jzz,
                              "Jzv": self.Jzv, "ft": self.ft, "stats": self.stats})

    def restore(self, state: dict) -> None:
        st = copy.deepcopy(state)
        self.age, self.band = float(st["age"]), st["band"]
        self.Jzz, self.Jzv, self.ft, self.stats = st["Jzz"], st["Jzv"], st["ft"], st["stats"]
        self._lu_g = None
