"""Compiled frames of the bodies in the slewing luffing plane: the kernel of
:func:`sim_core.physics.rigid_body.planar_body_frame` and
:func:`sim_core.physics.rigid_body.turntable_frame` (their numpy code is the reference; the tests
compare both in ``tests/folding/test_rigid_body_paths.py``).

The kinematics of the module docstring of :mod:`sim_core.physics.rigid_body`:

    S = cos(phi) C0 + sin(phi) S0 + P0            (= S(phi) B0, Rodrigues)
    r = S [(u, v, 0) + Rz(theta) p],  R = S Rz(theta),
    J_u, J_v = S e1, S e2,  J_theta = S dRz/dtheta p,  J_phi = a x r,
    W_phi = a,  W_theta = S e3;

for the turntable (no body coordinates) r = S p, R = S and only the phi columns.  Real or
complex-step states (the complex step carries d/dQ . Q_dot through every line).
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba


def _planar_frame(Q, i_phi, iu, iv, it, C0, S0, P0, ax, p, r, J, R, W):
    """Fill r (3,), J (3, N), R (3, 3), W (3, N) (J, W zero on entry) of the frame; iu < 0:
    the turntable (no body coordinates)."""
    phi = Q[i_phi]
    c = np.cos(phi)
    s = np.sin(phi)
    for i in range(3):
        for k in range(3):
            R[i, k] = c * C0[i, k] + s * S0[i, k] + P0[i, k]
    if iu >= 0:
        th = Q[it]
        ct = np.cos(th)
        st = np.sin(th)
        a0 = Q[iu] + (ct * p[0] - st * p[1])
        a1 = Q[iv] + (st * p[0] + ct * p[1])
        d0 = -st * p[0] - ct * p[1]
        d1 = ct * p[0] - st * p[1]
        for i in range(3):
            eu = R[i, 0]
            ev = R[i, 1]
            n = R[i, 2]
            r[i] = a0 * eu + a1 * ev + p[2] * n
            J[i, iu] = eu
            J[i, iv] = ev
            J[i, it] = d0 * eu + d1 * ev
            W[i, it] = n
            R[i, 0] = ct * eu + st * ev
            R[i, 1] = ct * ev - st * eu
    else:
        for i in range(3):
            r[i] = R[i, 0] * p[0] + R[i, 1] * p[1] + R[i, 2] * p[2]
    J[0, i_phi] = ax[1] * r[2] - ax[2] * r[1]
    J[1, i_phi] = ax[2] * r[0] - ax[0] * r[2]
    J[2, i_phi] = ax[0] * r[1] - ax[1] * r[0]
    for i in range(3):
        W[i, i_phi] = ax[i]


if AVAILABLE:
    _planar_frame = numba.njit(cache=True, nogil=True)(_planar_frame)


def planar_frame(Q, n_coords, i_phi, iu, iv, it, C0, S0, P0, ax, p):
    """(r, J, R, W) of a planar body (iu >= 0) or turntable (iu = -1) frame at Q (float64 or
    complex128), by the compiled loop where numba is on (else the same loop in Python)."""
    dt = np.result_type(Q, float)
    Q = np.ascontiguousarray(Q, dtype=dt)
    r = np.empty(3, dtype=dt)
    R = np.empty((3, 3), dtype=dt)
    J = np.zeros((3, n_coords), dtype=dt)
    W = np.zeros((3, n_coords), dtype=dt)
    _planar_frame(Q, i_phi, iu, iv, it, C0, S0, P0, ax, p, r, J, R, W)
    return r, J, R, W
