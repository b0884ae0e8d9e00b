"""Compiled (numba) kinematics of one material point of a spline element.

Constraint rows, ropes and contact sections evaluate single points of the booms (a contact
point, a pivot, a rope anchor) several times per right-hand side, for the real state and for
the complex-step state of the quadratic velocity terms: ~30 point evaluations per telescopic
right-hand side, each ~100 small numpy operations through ``SplineElement.evaluate`` (over a
third of the right-hand side at 8 sub-elements in a run, py-spy).  This is the same algebra for
one point as one compiled function: the spline basis rows at xi (Eqs. 5, 10-11, Appendix A
tables), r and its derivatives, the section state (Eqs. 24-33, :mod:`cardan_compiled`), the
material Jacobians J_r = dr/dQ|_s and J_psi = d(alpha, beta, gamma)/dQ|_s.
``SplineElement.evaluate`` stays the reference; ``tests/beam/test_point_compiled.py`` checks
that both agree for real and complex-step states.
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba
from sim_core.physics.beam import _cardan_numba as cardan_compiled


def _point(qe, s, n, D_all, pow_p, pow_t, basis, i_s1):
    """(r, rp, J_r (3, nq), J_psi (3, nq), angles, psi_prime, frame, tmat) at material s."""
    dt = qe.dtype
    na = n + 4
    npos = 3 * na
    nq = qe.shape[0]
    s1 = qe[i_s1]
    sn = qe[i_s1 + 1]
    ell = (sn - s1) / (n - 1)                                        # Eq. 5
    sub = int(np.floor((s.real - s1.real) / ell.real))               # SplineElement.locate
    sub = min(max(sub, 0), n - 2)
    xi = (s - s1) / ell - sub                                        # Eq. 10
    nrow = D_all.shape[2]
    rows = np.zeros(nrow, dtype=dt)
    p_xi = 1.0 + 0.0 * xi
    for p in range(6):                                               # sum_p xi^p D[sub, p]
        for k in range(nrow):
            rows[k] += p_xi * D_all[sub, p, k]
        p_xi = p_xi * xi
    lpow = cardan_compiled.length_powers(ell)
    X = np.empty((7, na), dtype=dt)
    for i in range(7):
        for a in range(na):
            X[i, a] = rows[i * na + a] * lpow[pow_p[i, a]]
    Y = np.empty((5, 2 * n), dtype=dt)
    off = 7 * na
    for i in range(5):
        for a in range(2 * n):
            Y[i, a] = rows[off + i * 2 * n + a] * lpow[pow_t[i, a]]
    RR = np.zeros((7, 3), dtype=dt)                                  # r, r', r'', r''', d/dl
    for i in range(7):
        for a in range(na):
            for j in range(3):
                RR[i, j] += X[i, a] * qe[3 * a + j]
    TT = np.zeros(5, dtype=dt)                                       # gamma, gamma', ...
    for i in range(5):
        for a in range(2 * n):
            TT[i] += Y[i, a] * qe[npos + a]
    frac = (sub + xi) / (n - 1)
    ds0, ds1 = 1.0 - frac, frac                                      # ds/d(s_1, s_n) at xi
    dl0, dl1 = -1.0 / (n - 1), 1.0 / (n - 1)                         # dl/d(s_1, s_n)

    eps, d, angles, dpsi, tmat, frame, psi_prime = cardan_compiled.section_state_compiled(
        RR[1:2].copy(), RR[2:3].copy(), TT[0:1].copy(), TT[1:2].copy(), basis)

    J_r = np.zeros((3, nq), dtype=dt)
    for j in range(3):
        for a in range(na):
            J_r[j, 3 * a + j] = X[0, a]
        J_r[j, i_s1] = RR[4, j] * dl0 - RR[1, j] * ds0
        J_r[j, i_s1 + 1] = RR[4, j] * dl1 - RR[1, j] * ds1
    J_psi = np.zeros((3, nq), dtype=dt)
    for i in range(2):
        for a in range(na):
            for j in range(3):
                J_psi[i, 3 * a + j] = dpsi[0, i, j] * X[1, a]
        # d(alpha, beta)/dl at fixed xi and (alpha, beta)' from dr'/dl and r''
        c_l = dpsi[0, i, 0] * RR[5, 0] + dpsi[0, i, 1] * RR[5, 1] + dpsi[0, i, 2] * RR[5, 2]
        c_s = dpsi[0, i, 0] * RR[2, 0] + dpsi[0, i, 1] * RR[2, 1] + dpsi[0, i, 2] * RR[2, 2]
        J_psi[i, i_s1] = c_l * dl0 - c_s * ds0
        J_psi[i, i_s1 + 1] = c_l * dl1 - c_s * ds1
    for a in range(2 * n):
        J_psi[2, npos + a] = Y[0, a]
    J_psi[2, i_s1] = TT[3] * dl0 - TT[1] * ds0
    J_psi[2, i_s1 + 1] = TT[3] * dl1 - TT[1] * ds1
    total = 0.0                      # finiteness check of the outputs (check_finite)
    for i in range(3):
        total += (RR[0, i].real + RR[0, i].imag + angles[0, i].real + angles[0, i].imag
                  + frame[0, 2, i].real)
        for k in range(nq):
            total += J_r[i, k].real + J_r[i, k].imag + J_psi[i, k].real + J_psi[i, k].imag
    return (RR[0].copy(), RR[1].copy(), J_r, J_psi, angles[0].copy(), psi_prime[0].copy(),
            frame[0].copy(), tmat[0].copy(), total)


def _point_local(Q, idx, s, o_sec, n, D_all, pow_p, pow_t, basis, i_s1):
    """(r, J_r (3, nq), angles, J_psi (3, nq), r', psi', finite-check sum) of a material point
    on its element's coordinates Q[idx]: _point with the rigid offset o_sec (axial, lateral,
    vertical; empty: none) in the section frame; J_r, J_psi = d/dQ[idx] at fixed s, r', psi'
    = d/ds (the column of a moving point's coordinate).  The same algebra as the Python of
    :func:`sim_core.physics.constraints.material_point` (its reference path)."""
    dt = Q.dtype
    nq = idx.shape[0]
    qe = np.empty(nq, dtype=dt)
    for k in range(nq):
        qe[k] = Q[idx[k]]
    r, rp, J_r, J_psi, angles, psi_prime, frame, tmat, total = _point(
        qe, s, n, D_all, pow_p, pow_t, basis, i_s1)
    if o_sec.shape[0] == 3:              # frame rows e_t, e_b, e_s; tmat columns (s, t, b)
        o = o_sec[1] * frame[0] + o_sec[2] * frame[1] + o_sec[0] * frame[2]
        R = np.empty((3, 3), dtype=dt)   # R = frame[[2, 0, 1]].T @ tmat
        for i in range(3):
            for j in range(3):
                R[i, j] = frame[2, i] * tmat[0, j] + frame[0, i] * tmat[1, j] \
                    + frame[1, i] * tmat[2, j]
        ox = np.zeros((3, 3), dtype=dt)  # J += (R dpsi) x o = ox R dpsi
        ox[0, 1] = o[2]
        ox[0, 2] = -o[1]
        ox[1, 0] = -o[2]
        ox[1, 2] = o[0]
        ox[2, 0] = o[1]
        ox[2, 1] = -o[0]
        oxR = np.dot(ox, R)
        J_r = J_r + np.dot(oxR, J_psi)
        rp = rp + np.dot(oxR, psi_prime)
        r = r + o
    return r, J_r, angles, J_psi, rp, psi_prime, total


def _point_full(Q, idx, s_index, s, o_sec, N, n, D_all, pow_p, pow_t, basis, i_s1):
    """(r, dr/dQ (3, N), angles, dangles/dQ (3, N), finite-check sum) of a material point on
    the full coordinates: :func:`_point_local` scattered, with the moving point's s column
    (s_index >= 0)."""
    dt = Q.dtype
    nq = idx.shape[0]
    r, J_r, angles, J_psi, rp, psi_prime, total = _point_local(
        Q, idx, s, o_sec, n, D_all, pow_p, pow_t, basis, i_s1)
    J = np.zeros((3, N), dtype=dt)
    Jp = np.zeros((3, N), dtype=dt)
    for i in range(3):
        for k in range(nq):
            J[i, idx[k]] = J_r[i, k]
            Jp[i, idx[k]] = J_psi[i, k]
        if s_index >= 0:
            J[i, s_index] += rp[i]
            Jp[i, s_index] += psi_prime[i]
    return r, J, angles, Jp, total


if AVAILABLE:
    _compiled_point = numba.njit(cache=True, nogil=True)(_point)
    _point = _compiled_point                   # the callee of _point_local
    compiled_point = _compiled_point           # the callee of _rigid_body_numba's beam frames
    compiled_point_local = numba.njit(cache=True, nogil=True)(_point_local)
    _point_local = compiled_point_local       # the callee of _point_full
    _compiled_point_full = numba.njit(cache=True, nogil=True)(_point_full)


def point_kinematics(el, qe, s):
    """(r, r', J_r, J_psi, (alpha, beta, gamma), psi', frame, tmat) of element ``el`` at the
    material coordinate s (real or complex-step; qe real or complex)."""
    dt = np.result_type(qe, s, float)
    qe = np.ascontiguousarray(qe, dtype=dt)
    *out, total = _compiled_point(qe, dt.type(s), el.n, el.D_all, el.pow_p, el.pow_t, el.G,
                                  el.i_s1)
    cardan_compiled.check_finite(total, "point kinematics")
    return tuple(out)


_NO_OFFSET = np.zeros(0)


def point_full(el, Q, idx, s_index, s, o_sec, N):
    """(r, dr/dQ (3, N), (alpha, beta, gamma), d(alpha, beta, gamma)/dQ (3, N)) of element
    ``el`` (global coordinates ``idx``) at the material coordinate s (real or complex-step), with
    the rigid offset o_sec (None: none) and the moving point's coordinate s_index (None: a
    fixed material point); one compiled call (see _point_full)."""
    dt = np.result_type(Q, s, float)
    Q = np.ascontiguousarray(Q, dtype=dt)
    r, J, angles, Jp, total = _compiled_point_full(
        Q, idx, -1 if s_index is None else int(s_index), dt.type(s),
        _NO_OFFSET if o_sec is None else o_sec, int(N), el.n, el.D_all, el.pow_p, el.pow_t,
        el.G, el.i_s1)
    cardan_compiled.check_finite(total, "point kinematics")
    return r, J, angles, Jp
