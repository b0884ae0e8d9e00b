"""Luffing geometry of the telescopic crane (Zhao-Qi-Wang 2024, Section 9, Fig. 13a; the
mounting points and signs of docs/model.md#input-luffing): boom 1 pivots about D1, the luffing cylinder runs
from D2 (on the base) to D3 (on boom 1).

Frames (docs/model.md#input-luffing): global X forward, Z up, Y = Z x X.  Boom-1 left-section components are
(axial e_s, lateral e_t, e_b); at theta = 0 they coincide with (X, Y, Z).  PD rotation
R(theta) = [[cos, 0, -sin], [0, 1, 0], [sin, 0, cos]] maps them to global; theta > 0 lifts the tip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

# --- A2 mounting points (m): global r1 (D1), r2 (D2); boom-1 left-section rbar1 (D1), rbar3 (D3).
R1_DEFAULT = (-0.556, 0.0, 0.350)
R2_DEFAULT = (0.100, 0.0, 0.050)
RBAR1_DEFAULT = (-0.956, 0.0, 0.556)
RBAR3_DEFAULT = (7.250, 0.0, -0.556)


def luffing_rotation(theta: float) -> np.ndarray:
    """PD rotation R(theta) (docs/model.md#input-luffing): boom-1 section components -> global, theta in rad."""
    ct, st = math.cos(theta), math.sin(theta)
    return np.array([[ct, 0.0, -st], [0.0, 1.0, 0.0], [st, 0.0, ct]])


@dataclass(frozen=True)
class LuffingGeometry:
    """Initial (rigid) boom-1 geometry at luffing angle theta; global positions in m.

    rotation: R(theta); origin: boom-1 left-section origin O = r1 - R rbar1; d1, d2, d3: pivot,
    cylinder base, cylinder head; cylinder_length = |D3 - D2|; lever = distance from D1 to the
    line D2-D3; e_s = boom axis direction R e_x.
    """

    theta: float
    rotation: np.ndarray
    origin: np.ndarray
    d1: np.ndarray
    d2: np.ndarray
    d3: np.ndarray
    cylinder_length: float
    lever: float
    e_s: np.ndarray


def luffing_geometry(theta: float, r1: Sequence[float] = R1_DEFAULT,
                     r2: Sequence[float] = R2_DEFAULT, rbar1: Sequence[float] = RBAR1_DEFAULT,
                     rbar3: Sequence[float] = RBAR3_DEFAULT) -> LuffingGeometry:
    """Geometry of Zhao-Qi-Wang 2024 Sec. 9 / docs/model.md#input-luffing: L_cyl = |r1 - r2 + R(rbar3 - rbar1)|.

    theta in rad; r1, r2 global (m); rbar1, rbar3 in boom-1 left-section components (m).
    At theta = 60 deg: L_cyl = 8.147 m, O = (0.4035, 0, 0.8999) m, lever = 0.714 m.
    """
    R = luffing_rotation(theta)
    r1a, r2a = np.asarray(r1, float), np.asarray(r2, float)
    rb1, rb3 = np.asarray(rbar1, float), np.asarray(rbar3, float)
    origin = r1a - R @ rb1                    # D1 is fixed both globally and in the boom
    d3 = origin + R @ rb3
    cyl = d3 - r2a                            # = r1 - r2 + R (rbar3 - rbar1)
    L_cyl = float(np.linalg.norm(cyl))
    lever = float(np.linalg.norm(np.cross(r1a - r2a, cyl / L_cyl)))
    return LuffingGeometry(theta, R, origin, r1a, r2a, d3, L_cyl, lever, R[:, 0].copy())


def cylinder_length(theta: float, r1, r2, rbar1, rbar3) -> tuple[float, float, float]:
    """(L, dL/dtheta, d2L/dtheta2) of the luffing cylinder of the rigid crane at the luffing
    angle theta (rad), m and m/rad: L = |u|, u = r1 - r2 + R(theta)(rbar3 - rbar1) (the
    geometry of :func:`luffing_geometry`), L' = u.u'/L, L'' = (u'.u' + u.u'')/L - (u.u')^2/L^3
    with u' = R'(theta) b, u'' = R''(theta) b = -(R(theta) - diag(0, 1, 0)) b."""
    ct, st = math.cos(theta), math.sin(theta)
    b = np.asarray(rbar3, float) - np.asarray(rbar1, float)
    R = np.array([[ct, 0.0, -st], [0.0, 1.0, 0.0], [st, 0.0, ct]])
    R1 = np.array([[-st, 0.0, -ct], [0.0, 0.0, 0.0], [ct, 0.0, -st]])
    R2 = np.array([[-ct, 0.0, st], [0.0, 0.0, 0.0], [-st, 0.0, -ct]])
    u = np.asarray(r1, float) - np.asarray(r2, float) + R @ b
    u1, u2 = R1 @ b, R2 @ b
    L = float(np.sqrt(u @ u))
    d1 = float(u @ u1) / L
    d2 = float(u1 @ u1 + u @ u2) / L - float(u @ u1) ** 2 / L ** 3
    return L, d1, d2


def cylinder_drive(profile, points):
    """t -> (L, L_dot, L_ddot) of the luffing cylinder that moves the rigid crane along the
    luffing-angle profile theta(t) (rad): L(theta(t)), L' theta_dot, L'' theta_dot^2 +
    L' theta_ddot (chain rule on :func:`cylinder_length`)."""
    def length(t):
        smp = profile.sample(t)
        L, d1, d2 = cylinder_length(float(smp.s), *points)
        return L, d1 * smp.v, d2 * smp.v * smp.v + d1 * smp.a
    return length
