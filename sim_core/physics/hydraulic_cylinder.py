"""A hydraulic cylinder driven through its oil column: the compliance between a flow-commanded
piston and the stage it moves (scene switch ``effects.oil_column``, table ``[oil_column]``).

Without it the telescopic cylinder is a rheonomic constraint: the stage length l(Q) between the
cylinder's two points equals the commanded length L(t) exactly, so the stages cannot stick and
slip on their sliders (the friction only changes the cylinder force).  With it the pump's flow
commands the piston, and the stage follows through the compressible oil.  Linearised about the
static pressure p_0 (Merritt, *Hydraulic Control Systems*, 1967, Sec. 5.2, the hydraulic spring):
the chamber of volume V = A (l + l_0) (piston area A, dead length l_0 of oil in the hoses and
the cylinder's end) with bulk modulus beta is fed the flow A L'(t) and gives up A l', so

    p - p_0 = (beta / V) A (L - l)    and    F = F_0 + k_h (L - l) + c_h (L' - l'),

k_h = beta A / (l + l_0) (N/m), F_0 = p_0 A the static force that holds the load at rest
(read from the constrained static equilibrium, so the column starts uncompressed at the
commanded length), c_h = 2 zeta_h sqrt(k_h M_s) the valve and leakage losses as a damping ratio
zeta_h on the stroke mass M_s (the stages' and payload's rigid-body mass on the stroke,
:func:`sim_core.systems.telescopic.friction_table.stroke_mass`).  F > 0 pushes the two points
apart (the sign of the constraint's multiplier it replaces): the generalized force is
F dl/dQ.  These are the ROM's stroke-friction equations (``sim_core.systems.telescopic.
modal_batch``, Stroke friction), here acting on the full model's booms, whose own slider
friction (Section 8.3) then makes them stick and slip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from sim_core.physics.constraints import dependencies
from sim_core.physics.point_effects import path_length


@dataclass
class OilColumn:
    """The cylinder between ``points`` (two point functions; l(Q) their distance, m) driven
    through its oil column (module docstring): ``command(t)`` -> (L, L', L'') the piston's
    commanded length (m, m/s, m/s^2); ``kA`` = beta A (N); ``dead_length`` l_0 (m);
    ``zeta`` the damping ratio on ``stroke_mass`` M_s (kg); ``F0`` the static force (N)."""

    points: Sequence[Callable]
    command: Callable
    kA: float
    dead_length: float
    zeta: float
    stroke_mass: float
    F0: float = 0.0
    name: str = "oil_column"
    takes_time = True                # local(t, ...) reads the command L(t): callers pass t

    def coords(self, Q):
        return dependencies(self.points, Q)

    def velocity_coords(self, Q):
        """The damping reads l' = dl/dQ . Q': the rates of the points' coordinates."""
        return self.coords(Q)

    def stiffness(self, ell: float) -> float:
        """k_h = beta A / (l + l_0), N/m."""
        return self.kA / (ell + self.dead_length)

    def damping(self, ell: float) -> float:
        """c_h = 2 zeta sqrt(k_h M_s), N s/m."""
        return 2.0 * self.zeta * math.sqrt(self.stiffness(ell) * self.stroke_mass)

    def state(self, t, Q, Qd):
        """(l, l', F, dl/dQ) at time t: the stage length (m), its rate (m/s), the cylinder
        force (N, positive pushing the points apart) and the length's gradient."""
        ell, grad = path_length(self.points, Q)
        ell = float(np.real(ell))
        grad = np.real(grad)
        rate = float(grad @ np.real(Qd))
        L, Ld, _ = self.command(t)
        F = self.F0 + self.stiffness(ell) * (L - ell) + self.damping(ell) * (Ld - rate)
        return ell, rate, F, grad

    def force(self, t, Q, Qd) -> float:
        """The cylinder force F (N) at (t, Q, Q')."""
        return self.state(t, Q, Qd)[2]

    def power(self, t, Q, Qd) -> float:
        """F l' (W): the power the cylinder feeds into the booms."""
        _, rate, F, _ = self.state(t, Q, Qd)
        return F * rate

    def local(self, t, Q, Qd, mass=True):
        """(idx, None, F dl/dQ on idx): the coordinates of the two points."""
        _, _, F, grad = self.state(t, Q, Qd)
        idx = np.flatnonzero(grad)
        return idx, None, F * grad[idx]

    def add(self, t, Q, Qd, M, F):
        idx, _, Fe = self.local(t, Q, Qd, M is not None)
        F[idx] += Fe
