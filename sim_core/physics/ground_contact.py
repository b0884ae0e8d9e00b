"""A ground under the hoisted payload (effect ``ground``): unilateral contact, SI units.

The payload and hook of :mod:`sim_core.physics.hoist` are one point mass at the global position
r_p = Q[index:index + 3].  The ground is the horizontal plane Z = ``height`` (m, the crane's
global frame, Z up).  With the penetration d = height - Z_p (m) and its rate d_dot = -Z_p_dot,
the ground pushes the payload up with

    S(d) = ramp(k, d, w)                        spring: 0 for d <= 0, k d^2 / (2 w) on the
                                                 first w of penetration, k (d - w/2) beyond
    N    = max(0, S(d) + c sigma(d) d_dot)      sigma(d) = clip(d / w, 0, 1)

a Kelvin-Voigt penalty (stiffness k, N/m; damping c, N s/m) whose spring starts with the same
C1 ramp as the ropes (:func:`sim_core.physics.point_effects.ramp_tension`, Zhao-Qi-Wang 2024
Section 9) and whose damper fades in with the spring over the ramp width, so the force is
continuous when the payload touches down or lifts off.  The clamp at zero keeps the contact
from pulling (no adhesion): the linear Kelvin-Voigt model's "sticking" force on separation
(Gilardi & Sharf 2002, Mech. Mach. Theory 37, Section 3.1; Hunt & Crossley 1975, J. Appl.
Mech. 42, who remove it with a damper proportional to the penetration).

Energy: the spring stores U(d) = ramp_energy(k, d, w) (J); the damper and the clamp take out
P_diss = (N - S) d_dot >= 0 (W): with the clamp off it is c sigma d_dot^2, with the clamp on
N = 0 < S + c sigma d_dot needs d_dot < 0, so -S d_dot > 0 (the stored energy released while
separating faster than the spring relaxes is lost, not returned).

The force acts on Z_p only (no friction on the ground).  A payload resting on the ground with a
slack rope then has no horizontal stiffness, so the static equilibrium is solved with a
horizontal spring of stiffness ``lateral`` (N/m) that holds the payload at ``anchor`` (x, y),
m: it is on only while the statics are solved (:func:`resting_equilibrium`) and its force is
zero at the equilibrium, where the payload stands at the anchor; then the payload is moved
right below the deflected tip, which changes no force while the rope is slack.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim_core.physics.point_effects import ramp_energy, ramp_tension

__all__ = ["GroundContact", "resting_penetration", "resting_equilibrium"]


@dataclass
class GroundContact:
    """The ground plane Z = ``height`` (m) under the point mass on the coordinates ``index ..
    index + 2`` (its global position, m): stiffness ``stiffness`` (N/m), damping ``damping``
    (N s/m), ramp width ``width`` (m)."""

    index: int
    height: float
    stiffness: float
    damping: float
    width: float = 1e-4
    name: str = "ground"
    lateral: float = 0.0                     # N/m, statics only (module docstring)
    anchor: tuple = (0.0, 0.0)               # m, (x, y) the statics' lateral spring holds
    time_invariant = True                    # local() does not depend on t

    def coords(self, Q):
        return np.arange(self.index, self.index + 3)

    def velocity_coords(self, Q):
        """The damper reads the payload's vertical rate."""
        return np.arange(self.index, self.index + 3)

    def penetration(self, Q, Qd=None) -> tuple[float, float]:
        """(d, d_dot): the payload's depth below the ground, m, and its rate, m/s."""
        z = float(np.real(Q[self.index + 2]))
        zd = 0.0 if Qd is None else float(np.real(Qd[self.index + 2]))
        return self.height - z, -zd

    def spring(self, d: float) -> float:
        """S(d), N: the C1-ramp penalty spring."""
        return float(ramp_tension(self.stiffness, d, self.width))

    def normal_force(self, d: float, d_dot: float) -> float:
        """N(d, d_dot) >= 0, N: the spring and the faded-in damper, clamped at zero."""
        if d <= 0.0:
            return 0.0
        sigma = min(d / self.width, 1.0)
        return max(0.0, self.spring(d) + self.damping * sigma * d_dot)

    def force(self, Q, Qd) -> float:
        """The ground's upward force on the payload, N (the output payload_ground_force)."""
        return self.normal_force(*self.penetration(Q, Qd))

    def energy(self, Q) -> float:
        """Strain energy of the ground spring, J."""
        d, _ = self.penetration(Q)
        return float(ramp_energy(self.stiffness, d, self.width))

    def dissipation(self, Q, Qd) -> float:
        """P_diss = (N - S) d_dot >= 0, W: the power the damper and the clamp take out."""
        d, dd = self.penetration(Q, Qd)
        return (self.normal_force(d, dd) - self.spring(d)) * dd

    def local(self, t, Q, Qd, mass=True):
        idx = self.coords(Q)
        Fe = np.zeros(3)
        Fe[2] = self.force(Q, Qd)
        if self.lateral:
            Fe[:2] = -self.lateral * (np.real(Q[self.index:self.index + 2])
                                      - np.asarray(self.anchor, float))
        return idx, None, Fe

    def add(self, t, Q, Qd, M, F):
        idx, _, Fe = self.local(t, Q, Qd, M is not None)
        F[idx] += Fe


def resting_penetration(ground: GroundContact, weight: float) -> float:
    """The penetration d (m) at which the ground spring carries ``weight`` (N >= 0):
    S(d) = weight on the ramp (d = sqrt(2 w W / k)) or beyond it (d = W / k + w / 2)."""
    k, w = ground.stiffness, ground.width
    if weight <= 0.0:
        return 0.0
    if weight <= 0.5 * k * w:
        return float(np.sqrt(2.0 * w * weight / k))
    return weight / k + 0.5 * w


def resting_equilibrium(ts, t: float, solve):
    """The static equilibrium (z, lambda) of a telescopic system whose payload may rest on the
    ground: ``solve(ts, t)`` (the system's statics) with the lateral spring of
    :class:`GroundContact` on, anchored below the boom tip; where the hoist rope carries load
    at that equilibrium the rope, not the spring, holds the payload sideways, so the statics
    are solved again without the spring."""
    g = ts.ground
    m = ts.model
    r_tip = np.real(ts.tip(ts.Q0)[0])
    g.anchor = (float(r_tip[0]), float(r_tip[1]))
    g.lateral = g.stiffness
    try:
        z, lam = solve(ts, t)
    finally:
        g.lateral = 0.0
    Q, _ = m.full_state(t, z, np.zeros_like(z))
    ell = float(np.real(ts.hoist.span(Q)[0]))
    if ts.hoist.tension(ell, t) > 0.0:
        return solve(ts, t)
    # the rope is slack: nothing acts on the payload sideways, so it may stand right below the
    # deflected tip, where the rope is vertical when it tightens.  The payload's coordinates
    # are in no linear constraint, so the shift dQ lies in the range of the orthonormal
    # null-space basis P (Q = A^+ b + P z) and dz = P^T dQ moves them alone
    dQ = np.zeros(m.n_coords)
    i = g.index
    dQ[i:i + 2] = np.real(ts.tip(Q)[0])[:2] - np.real(Q[i:i + 2])
    return np.asarray(z, dtype=float) + m.P.T @ dQ, lam
