"""A payload that swings on the hoist rope (effect ``payload_swing``), SI units.

The payload and the hook are one point mass m = m_payload + m_hook on three coordinates of
their own, the global position r_p (a spherical pendulum whose suspension point is the boom
tip): M += m I on r_p, F += m g (:class:`HangingMass`).  The hoist rope joins the boom tip r_t
and r_p as an elastic, massless, tension-only rope of unstretched length L0(t), which the hoist
drive changes (hoisting and lowering): with l = |r_p - r_t|,

    T = (EA / L0) ramp(l - L0),   F_p -= T (r_p - r_t) / l,   F_tip += T (r_p - r_t) / l,

the same C1 ramp over ``slack_width`` as the telescoping ropes
(:class:`sim_core.physics.point_effects.RopeDrive`, Zhao-Qi-Wang 2024 Section 9): a slack rope
carries nothing and the payload falls freely until the rope is taut again.  The rope's strain
energy is U = (EA / (2 L0)) (l - L0)^2 in its stiff branch; while L0 changes, the hoist does
the work  W = int dU/dL0 L0_dot dt  (:meth:`HoistRope.hoist_power`), which the energy audit
books beside the other works.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from sim_core.physics.point_effects import path_length, ramp_energy, ramp_tension

__all__ = ["free_point", "HangingMass", "HoistRope"]


def free_point(index: int, n_coords: int):
    """Point function Q -> (r, dr/dQ, psi, dpsi/dQ) of a point whose global position is the
    coordinates Q[index:index + 3] (m); no orientation (psi = 0)."""
    cols = np.arange(index, index + 3)
    J = np.zeros((3, n_coords))
    J[:, cols] = np.eye(3)
    J.setflags(write=False)
    zero3, zeroJ = np.zeros(3), np.zeros((3, n_coords))

    def f(Q):
        return Q[index:index + 3], J, zero3, zeroJ
    f.coords = lambda Q: cols
    return f


@dataclass
class HangingMass:
    """The payload with its hook: a point mass ``mass`` (kg) on the coordinates
    ``index .. index + 2`` (its global position, m); M += m I, F += m g."""

    index: int
    mass: float
    gravity: np.ndarray | None = None
    name: str = "payload"
    time_invariant = True                    # local() does not depend on t

    def coords(self, Q):
        return np.arange(self.index, self.index + 3)

    def velocity_coords(self, Q):
        return np.zeros(0, dtype=int)

    def local(self, t, Q, Qd, mass=True):
        f = np.zeros(3) if self.gravity is None else self.mass * np.asarray(self.gravity, float)
        return self.coords(Q), (self.mass * np.eye(3) if mass else None), f

    def add(self, t, Q, Qd, M, F):
        idx, Me, Fe = self.local(t, Q, Qd, M is not None)
        F[idx] += Fe
        if M is not None:
            M[np.ix_(idx, idx)] += Me

    def energy(self, Q, Qd) -> float:
        """Kinetic and gravity energy, J (zero height at Z = 0)."""
        r, v = Q[self.index:self.index + 3], Qd[self.index:self.index + 3]
        g = np.zeros(3) if self.gravity is None else np.asarray(self.gravity, float)
        return float(np.real(0.5 * self.mass * (v @ v) - self.mass * (r @ g)))


@dataclass
class HoistRope:
    """The hoist rope from the boom tip ``top`` to the payload ``bottom`` (point functions),
    axial stiffness EA (N), unstretched length ``length(t)`` -> (L0, L0_dot, L0_ddot) (m)."""

    top: Callable
    bottom: Callable
    EA: float
    length: Callable
    slack_width: float = 1e-6
    name: str = "hoist_rope"
    takes_time = True                        # local(t, ...) reads L0(t): callers pass t

    @property
    def points(self):
        return (self.top, self.bottom)

    def coords(self, Q):
        from sim_core.physics.constraints import dependencies
        return dependencies(self.points, Q)

    def velocity_coords(self, Q):
        return np.zeros(0, dtype=int)

    def span(self, Q):
        """(l, dl/dQ): the distance tip-payload, m, and its gradient."""
        return path_length(self.points, Q)

    def tension(self, ell: float, t: float) -> float:
        """T (N) at span ell (m) and time t: tension-only with a C1 ramp over slack_width."""
        L0 = self.length(t)[0]
        return ramp_tension(self.EA / L0, ell - L0, self.slack_width)

    def local(self, t, Q, Qd, mass=True):
        f = np.zeros(3) if self.gravity is None else self.mass * np.asarray(self.gravity, float)
        return self.coords(Q), (self.mass * np.eye(3) if mass else None), f

    def add(self, t, Q, Qd, M, F):
        idx, Me, Fe = self.local(t, Q, Qd, M is not None)
        F[idx] += Fe
        if M is not None:
            M[np.ix_(idx, idx)] += Me

    def energy(self, Q, Qd) -> float:
        """Kinetic and gravity energy, J (zero height at Z = 0)."""
        r, v = Q[self.index:self.index + 3], Qd[self.index:self.index + 3]
        g = np.zeros(3) if self.gravity is None else np.asarray(self.gravity, float)
        return float(np.real(0.5 * self.mass * (v @ v) - self.mass * (r @ g)))


@dataclass
class HoistRope:
    """The hoist rope from the boom tip ``top`` to the payload ``bottom`` (point functions),
    axial stiffness EA (N), unstretched length ``length(t)`` -> (L0, L0_dot, L0_ddot) (m)."""

    top: Callable
    bottom: Callable
    EA: float
    length: Callable
    slack_width: float = 1e-6
    name: str = "hoist_rope"
    takes_time = True                        # local(t, ...) reads L0(t): callers pass t

    @property
    def points(self):
        return (self.top, self.bottom)

    def coords(self, Q):
        from sim_core.physics.constraints import dependencies
        return dependencies(self.points, Q)

    def velocity_coords(self, Q):
        return np.zeros(0, dtype=int)

    def span(self, Q):
        """(l, dl/dQ): the distance tip-payload, m, and its gradient."""
        return path_length(self.points, Q)

    def tension(self, ell: float, t: float) -> float:
        """T (N) at span ell (m) and time t: tension-only with a C1 ramp over slack_width."""
        L0 = self.length(t)[0]
        k = self.EA / L0
        x = (ell - L0) / self.slack_width
        if x <= 0:
            return 0.0
        if x >= 1:
            return k * (ell - L0 - 0.5 * self.slack_width)
        return k * self.slack_width * 0.5 * x * x

    def local(self, t, Q, Qd, mass=True):
        ell, grad = self.span(Q)
        grad = np.real(grad)
        idx = np.flatnonzero(grad)
        return idx, None, -self.tension(float(np.real(ell)), t) * grad[idx]

    def add(self, t, Q, Qd, M, F):
        idx, _, Fe = self.local(t, Q, Qd, M is not None)
        F[idx] += Fe

    def energy(self, Q, t: float) -> float:
        """Strain energy U (J): the integral of the tension over the span from slack."""
        ell = float(np.real(self.span(Q)[0]))
        L0 = self.length(t)[0]
        return float(ramp_energy(self.EA / L0, ell - L0, self.slack_width))

    def hoist_power(self, Q, t: float) -> float:
        """dU/dL0 * L0_dot (W): the power the hoist feeds into the rope while it changes the
        unstretched length (complex-step derivative of U in L0)."""
        L0, L0d, _ = self.length(t)
        if L0d == 0.0:
            return 0.0
        ell = float(np.real(self.span(Q)[0]))
        h = 1e-20 * L0
        L = L0 + 1j * h
        return float(np.imag(ramp_energy(self.EA / L, ell - L, self.slack_width)) / h * L0d)
