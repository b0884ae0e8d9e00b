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

The joint rows of the folding manipulator as one compiled program (:class:`JointProgram`, the
reference is the Python closures of :mod:`sim_core.physics.rigid_body` and
:mod:`sim_core.physics.constraints`; ``tests/folding/test_joint_program.py`` compares both).
Every frame once at the complex-step state Q + i h Q_dot (h = 1e-20) on its own columns: a
planar body or the turntable as above, a boom's cross-section frame at a fixed material point
(:func:`sim_core.physics.rigid_body.beam_frame`: the compiled point kernel's r, J_r, J_psi and
section frame, W = [e_s e_t e_b] T J_psi, a rigid offset o = R p with J += [o]x^T W).  Then
each constraint's rows from its frames (complex):

* coincidence  g = r_a - r_b,  G = J_a - J_b                      (constraints.point_coincidence)
* distance     g = |d|, d = r_a - r_b,  G = (d / |d|) (J_a - J_b)  (constraints.distance_driver)
* hinge axis   g = u . n, u = R_b w (w = p_b, q_b), n = R_a c_a,
               G = (u x n) . (W_b - W_a)                          (rigid_body.revolute_axis)
* planar pin   g_k = E_k . d, E = R_plane[:, :2], d = r_a - r_b,
               G_k = E_k . (J_a - J_b) + (E_k x d) . W_plane      (rigid_body.planar_pin)
* prismatic    g = d . e, e = R_a m_a, d = r_b - r_a,
               G = e . (J_b - J_a) + (e x d) . W_a                (rigid_body.prismatic_offset)

The value and G = g_Q are the real parts; the quadratic velocity term g_QQ[Q_dot, Q_dot] =
Im(G(Q + i h Q_dot) Q_dot) / h, as :func:`sim_core.physics.constraints.constraint_terms`.  The
structured Jacobian's constraint columns are forward differences of the same rows
(:meth:`JointProgram.columns`).

The rigid bodies' Newton-Euler blocks (:class:`BodyProgram`, the formulas of
:meth:`sim_core.physics.rigid_body.RigidBody.local`) come from their mass-centre frames at the same
complex-step state in one call: J, W, R the real parts, Jdot Q_dot and Wdot Q_dot the imaginary
parts of J Q_dot and W Q_dot over h.
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba
from sim_core.physics._constraints_numba import (
    cached_program,
    equal_element_tables,
    program_points,
)
from sim_core.physics.beam import _cardan_numba as cardan_compiled
from sim_core.physics.beam import _moving_node_beam_numba as point_compiled
from sim_core.physics.complex_step import COMPLEX_STEP

PLANAR, BEAM = 0, 1                                   # frame kinds
COINCIDENCE, DISTANCE, HINGE_AXIS, PLANAR_PIN, PRISMATIC = 0, 1, 2, 3, 4   # row kinds


def _planar_local(Q, i_phi, iu, iv, it, C0, S0, P0, ax, p, r, J, R, W):
    """Fill r (3,), R (3, 3) and the columns (phi, u, v, theta) of J, W (3, >= 4) of the frame;
    iu < 0: the turntable, whose only column is phi's."""
    phi = Q[i_phi]
    c = np.cos(phi)
    s = np.sin(phi)
    for i in range(3):
        for k in range(3):
            R[i, k] = c * C0[i, k] + s * S0[i, k] + P0[i, k]
        for k in range(4):
            J[i, k] = 0.0
            W[i, k] = 0.0
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
            J[i, 1] = eu
            J[i, 2] = ev
            J[i, 3] = d0 * eu + d1 * ev
            W[i, 3] = n
            R[i, 0] = ct * eu + st * ev
            R[i, 1] = ct * ev - st * eu
    else:
        for i in range(3):
            r[i] = R[i, 0] * p[0] + R[i, 1] * p[1] + R[i, 2] * p[2]
    J[0, 0] = ax[1] * r[2] - ax[2] * r[1]
    J[1, 0] = ax[2] * r[0] - ax[0] * r[2]
    J[2, 0] = ax[0] * r[1] - ax[1] * r[0]
    for i in range(3):
        W[i, 0] = ax[i]


def _planar_frame(Q, i_phi, iu, iv, it, C0, S0, P0, ax, p, r, J, R, W):
    """Fill r (3,), J (3, N), R (3, 3), W (3, N) (J, W zero on entry) of the frame; iu < 0:
    the turntable (no body coordinates)."""
    Jl = np.empty((3, 4), dtype=J.dtype)
    Wl = np.empty((3, 4), dtype=W.dtype)
    _planar_local(Q, i_phi, iu, iv, it, C0, S0, P0, ax, p, r, Jl, R, Wl)
    for i in range(3):
        J[i, i_phi] = Jl[i, 0]
        W[i, i_phi] = Wl[i, 0]
        if iu >= 0:
            J[i, iu] = Jl[i, 1]
            J[i, iv] = Jl[i, 2]
            J[i, it] = Jl[i, 3]
            W[i, it] = Wl[i, 3]


def _frame_local(f, Qc, f_kind, f_idx, f_C, f_ax, f_p, f_s, f_hasoff, el_idx, n, D_all,
                 pow_p, pow_t, bases, i_s1, Rf, Jf, Rot, Wf, FC, FN):
    """Frame f at the complex state Qc into Rf[f] (3,), Rot[f] (3, 3), and Jf[f], Wf[f] (3, L)
    on its columns FC[f, :FN[f]]; returns the finite-check sum."""
    if f_kind[f] == PLANAR:
        iu = f_idx[f, 1]
        _planar_local(Qc, f_idx[f, 0], iu, f_idx[f, 2], f_idx[f, 3], f_C[f, 0], f_C[f, 1],
                      f_C[f, 2], f_ax[f], f_p[f], Rf[f], Jf[f], Rot[f], Wf[f])
        FN[f] = 4 if iu >= 0 else 1
        for k in range(FN[f]):
            FC[f, k] = f_idx[f, k]
        return 0.0
    # BEAM: the section frame of element f_idx[f, 0] at the material point f_s[f]
    e = f_idx[f, 0]
    idx = el_idx[e]
    nq = idx.shape[0]
    qe = np.empty(nq, dtype=np.complex128)
    for k in range(nq):
        qe[k] = Qc[idx[k]]
        FC[f, k] = idx[k]
    FN[f] = nq
    r, _, J_r, J_psi, _, _, frame, tmat, total = _point(qe, f_s[f] + 0.0j, n, D_all, pow_p,
                                                         pow_t, bases[e], i_s1)
    A = np.empty((3, 3), dtype=np.complex128)       # [e_s e_t e_b] tmat (frame rows t, b, s)
    for i in range(3):
        for j in range(3):
            A[i, j] = frame[2, i] * tmat[0, j] + frame[0, i] * tmat[1, j] \
                + frame[1, i] * tmat[2, j]
    for i in range(3):
        for k in range(nq):
            Wf[f, i, k] = A[i, 0] * J_psi[0, k] + A[i, 1] * J_psi[1, k] + A[i, 2] * J_psi[2, k]
            Jf[f, i, k] = J_r[i, k]
        for k in range(3):
            Rot[f, i, k] = frame[k, i]                 # R = frame^T: columns e_t, e_b, e_s
        Rf[f, i] = r[i]
    if f_hasoff[f]:
        p = f_p[f]
        o = np.empty(3, dtype=np.complex128)
        for i in range(3):
            o[i] = Rot[f, i, 0] * p[0] + Rot[f, i, 1] * p[1] + Rot[f, i, 2] * p[2]
        for k in range(nq):                            # J += [[0, o2, -o1], [-o2, 0, o0],
            w0 = Wf[f, 0, k]                           #       [o1, -o0, 0]] W
            w1 = Wf[f, 1, k]
            w2 = Wf[f, 2, k]
            Jf[f, 0, k] += o[2] * w1 - o[1] * w2
            Jf[f, 1, k] += o[0] * w2 - o[2] * w0
            Jf[f, 2, k] += o[1] * w0 - o[0] * w1
        for i in range(3):
            Rf[f, i] += o[i]
    return total


def _frames(Q, Qd, N, f_kind, f_idx, f_C, f_ax, f_p, f_s, f_hasoff, el_idx, n, D_all, pow_p,
            pow_t, bases, i_s1, cstep):
    """Every frame at the complex-step state Q + i cstep Q_dot (_frame_local): (Rf (F, 3), Jf
    (F, 3, L), Rot (F, 3, 3), Wf (F, 3, L), FC (F, L), FN (F,), finite-check sum)."""
    Qc = np.empty(N, dtype=np.complex128)
    for k in range(N):
        Qc[k] = Q[k] + 1j * (cstep * Qd[k])
    F = f_kind.shape[0]
    L = max(el_idx.shape[1], 4)
    Rf = np.empty((F, 3), dtype=np.complex128)
    Rot = np.empty((F, 3, 3), dtype=np.complex128)
    Jf = np.zeros((F, 3, L), dtype=np.complex128)
    Wf = np.zeros((F, 3, L), dtype=np.complex128)
    FC = np.zeros((F, L), dtype=np.int64)
    FN = np.zeros(F, dtype=np.int64)
    total = 0.0
    for f in range(F):
        total += _frame_local(f, Qc, f_kind, f_idx, f_C, f_ax, f_p, f_s, f_hasoff, el_idx, n,
                              D_all, pow_p, pow_t, bases, i_s1, Rf, Jf, Rot, Wf, FC, FN)
    return Rf, Jf, Rot, Wf, FC, FN, total


def _add_row(Gc, row, f, coef, X, FC, FN):
    """Gc[row, FC[f, k]] += coef . X[f, :, k] (coef (3,) complex, X = Jf or Wf)."""
    for k in range(FN[f]):
        Gc[row, FC[f, k]] += coef[0] * X[f, 0, k] + coef[1] * X[f, 1, k] + coef[2] * X[f, 2, k]


def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


def _joint_terms(Q, Qd, N, f_kind, f_idx, f_C, f_ax, f_p, f_s, f_hasoff, el_idx, n, D_all,
                 pow_p, pow_t, bases, i_s1, c_kind, c_f, c_vec, c_row0, m, cstep, rate_part):
    """(g (m,), G (m, N), g_QQ[Q_dot, Q_dot] (m,), g_QQ Q_dot (m, N) or (0, 0), finite-check
    sum) of the joint rows at the real state (Q, Q_dot); see the module docstring."""
    Rf, Jf, Rot, Wf, FC, FN, total = _frames(Q, Qd, N, f_kind, f_idx, f_C, f_ax, f_p, f_s,
                                             f_hasoff, el_idx, n, D_all, pow_p, pow_t, bases,
                                             i_s1, cstep)
    gc = np.zeros(m, dtype=np.complex128)
    Gc = np.zeros((m, N), dtype=np.complex128)
    d = np.empty(3, dtype=np.complex128)
    u = np.empty(3, dtype=np.complex128)
    v = np.empty(3, dtype=np.complex128)
    x = np.empty(3, dtype=np.complex128)
    w = np.empty(3, dtype=np.complex128)
    for c in range(c_kind.shape[0]):
        kind = c_kind[c]
        a, b, pl = c_f[c, 0], c_f[c, 1], c_f[c, 2]
        r0 = c_row0[c]
        if kind == COINCIDENCE or kind == DISTANCE or kind == PLANAR_PIN:
            for i in range(3):
                d[i] = Rf[a, i] - Rf[b, i]
        if kind == COINCIDENCE:
            for i in range(3):
                gc[r0 + i] = d[i]
                for k in range(FN[a]):
                    Gc[r0 + i, FC[a, k]] += Jf[a, i, k]
                for k in range(FN[b]):
                    Gc[r0 + i, FC[b, k]] -= Jf[b, i, k]
        elif kind == DISTANCE:
            nn = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            gc[r0] = nn
            for i in range(3):
                u[i] = d[i] / nn
            _add_row(Gc, r0, a, u, Jf, FC, FN)
            for i in range(3):
                u[i] = -u[i]
            _add_row(Gc, r0, b, u, Jf, FC, FN)
        elif kind == HINGE_AXIS:
            for i in range(3):                         # n = R_a c_a
                v[i] = Rot[a, i, 0] * c_vec[c, 0, 0] + Rot[a, i, 1] * c_vec[c, 0, 1] \
                    + Rot[a, i, 2] * c_vec[c, 0, 2]
            for q in range(2):
                for i in range(3):                     # u = R_b w
                    u[i] = Rot[b, i, 0] * c_vec[c, 1 + q, 0] + Rot[b, i, 1] * c_vec[c, 1 + q, 1] \
                        + Rot[b, i, 2] * c_vec[c, 1 + q, 2]
                gc[r0 + q] = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
                _cross(u, v, x)
                _add_row(Gc, r0 + q, b, x, Wf, FC, FN)
                for i in range(3):
                    x[i] = -x[i]
                _add_row(Gc, r0 + q, a, x, Wf, FC, FN)
        elif kind == PLANAR_PIN:
            for q in range(2):
                for i in range(3):
                    w[i] = Rot[pl, i, q]                # E_q
                gc[r0 + q] = w[0] * d[0] + w[1] * d[1] + w[2] * d[2]
                _add_row(Gc, r0 + q, a, w, Jf, FC, FN)
                for i in range(3):
                    u[i] = -w[i]
                _add_row(Gc, r0 + q, b, u, Jf, FC, FN)
                _cross(w, d, x)
                _add_row(Gc, r0 + q, pl, x, Wf, FC, FN)
        else:                                          # PRISMATIC
            for i in range(3):                         # e = R_a m_a, d = r_b - r_a
                w[i] = Rot[a, i, 0] * c_vec[c, 0, 0] + Rot[a, i, 1] * c_vec[c, 0, 1] \
                    + Rot[a, i, 2] * c_vec[c, 0, 2]
                d[i] = Rf[b, i] - Rf[a, i]
            gc[r0] = w[0] * d[0] + w[1] * d[1] + w[2] * d[2]
            _add_row(Gc, r0, b, w, Jf, FC, FN)
            for i in range(3):
                u[i] = -w[i]
            _add_row(Gc, r0, a, u, Jf, FC, FN)
            _cross(w, d, x)
            _add_row(Gc, r0, a, x, Wf, FC, FN)
    g = np.empty(m)
    G = np.empty((m, N))
    quad = np.empty(m)
    Gr = np.empty((m, N) if rate_part else (0, 0))
    for i in range(m):
        g[i] = gc[i].real
        acc = 0.0j
        for k in range(N):
            acc += Gc[i, k] * Qd[k]
            G[i, k] = Gc[i, k].real
            if rate_part:
                Gr[i, k] = Gc[i, k].imag / cstep
        quad[i] = acc.imag / cstep
        total += g[i] + quad[i]
    return g, G, quad, Gr, total


def _joint_columns(Q, Qd, Qdd, lam, b0, bd, bdd, xi1, xi2, cols, steps, N, f_kind, f_idx,
                   f_C, f_ax, f_p, f_s, f_hasoff, el_idx, n, D_all, pow_p, pow_t, bases, i_s1,
                   c_kind, c_f, c_vec, c_row0, m, cstep):
    """Forward-difference columns j in ``cols`` (steps ``steps``) of r1 = G^T lambda (N,) and
    r2 = G Q_ddot - (b_ddot - g_QQ[Q_dot, Q_dot] - 2 xi1 (G Q_dot - b_dot) - xi2^2 (g - b))
    (m,), the Python constraint pieces' formulas of sim_core.model.state_jacobian:
    (dR1 (N, ncols), dR2 (m, ncols), finite-check sum).  Every column re-evaluates all frames
    and rows (~35 us at the folding manipulator's 18 frames and 30 rows)."""
    args = (N, f_kind, f_idx, f_C, f_ax, f_p, f_s, f_hasoff, el_idx, n, D_all, pow_p, pow_t,
            bases, i_s1, c_kind, c_f, c_vec, c_row0, m, cstep, False)
    g0, G0, q0, _, total = _joint_terms_compiled(Q, Qd, *args)
    r2_0 = np.empty(m)
    for i in range(m):
        gq = 0.0
        gd = 0.0
        for k in range(N):
            gq += G0[i, k] * Qdd[k]
            gd += G0[i, k] * Qd[k]
        r2_0[i] = gq - (bdd[i] - q0[i] - 2.0 * xi1 * (gd - bd[i]) - xi2 * xi2 * (g0[i] - b0[i]))
    ncol = cols.shape[0]
    dR1 = np.zeros((N, ncol))
    dR2 = np.zeros((m, ncol))
    Qx = Q.copy()
    for jj in range(ncol):
        j = cols[jj]
        h = steps[jj]
        x = Q[j]
        Qx[j] = x + h
        g1, G1, q1, _, t1 = _joint_terms_compiled(Qx, Qd, *args)
        Qx[j] = x
        total += t1
        for i in range(m):
            li = lam[i] / h
            gq = 0.0
            gd = 0.0
            for k in range(N):
                dR1[k, jj] += li * (G1[i, k] - G0[i, k])
                gq += G1[i, k] * Qdd[k]
                gd += G1[i, k] * Qd[k]
            r2 = gq - (bdd[i] - q1[i] - 2.0 * xi1 * (gd - bd[i]) - xi2 * xi2 * (g1[i] - b0[i]))
            dR2[i, jj] = (r2 - r2_0[i]) / h
    return dR1, dR2, total


def _body_blocks(Q, Qd, N, f_kind, f_idx, f_C, f_ax, f_p, f_s, f_hasoff, el_idx, n, D_all,
                 pow_p, pow_t, bases, i_s1, b_mass, b_I, b_g, with_mass, cstep):
    """Newton-Euler blocks of B rigid bodies whose mass-centre frames are the frames 0..B-1
    (sim_core.physics.rigid_body.RigidBody.local): on each frame's columns (nc = FN[b])
        Me = m J^T J + W^T I_g W,  Fe = J^T m (g - Jdot Qd) - W^T (I_g Wdot Qd + w x I_g w),
    I_g = R I_b R^T, w = W Qd, Jdot Qd and Wdot Qd the imaginary parts of the frame's Jacobians
    at Q + i h Qd times Qd, over h.  Returns (cols (B, L), ncols (B,), Me (B, L, L), Fe (B, L))."""
    _, Jf, Rot, Wf, FC, FN, _ = _frames(Q, Qd, N, f_kind, f_idx, f_C, f_ax, f_p, f_s, f_hasoff,
                                        el_idx, n, D_all, pow_p, pow_t, bases, i_s1, cstep)
    L = Jf.shape[2]
    B = b_mass.shape[0]
    Me = np.zeros((B, L, L))
    Fe = np.zeros((B, L))
    J = np.empty((3, L))
    W = np.empty((3, L))
    R = np.empty((3, 3))
    Ig = np.empty((3, 3))
    acc = np.empty(3)
    wdot = np.empty(3)
    om = np.empty(3)
    Iom = np.empty(3)
    for b in range(B):
        nc = FN[b]
        m = b_mass[b]
        for i in range(3):
            a = 0.0
            wd = 0.0
            o = 0.0
            for k in range(nc):
                qd = Qd[FC[b, k]]
                J[i, k] = Jf[b, i, k].real
                W[i, k] = Wf[b, i, k].real
                a += Jf[b, i, k].imag * qd
                wd += Wf[b, i, k].imag * qd
                o += W[i, k] * qd
            acc[i] = a / cstep
            wdot[i] = wd / cstep
            om[i] = o
            for j in range(3):
                R[i, j] = Rot[b, i, j].real
        for i in range(3):                             # I_g = R I_b R^T
            for j in range(3):
                v = 0.0
                for k in range(3):
                    for q in range(3):
                        v += R[i, k] * b_I[b, k, q] * R[j, q]
                Ig[i, j] = v
        for i in range(3):
            Iom[i] = Ig[i, 0] * om[0] + Ig[i, 1] * om[1] + Ig[i, 2] * om[2]
        t = np.empty(3)                                # I_g Wdot Qd + w x I_g w
        t[0] = Ig[0, 0] * wdot[0] + Ig[0, 1] * wdot[1] + Ig[0, 2] * wdot[2] \
            + om[1] * Iom[2] - om[2] * Iom[1]
        t[1] = Ig[1, 0] * wdot[0] + Ig[1, 1] * wdot[1] + Ig[1, 2] * wdot[2] \
            + om[2] * Iom[0] - om[0] * Iom[2]
        t[2] = Ig[2, 0] * wdot[0] + Ig[2, 1] * wdot[1] + Ig[2, 2] * wdot[2] \
            + om[0] * Iom[1] - om[1] * Iom[0]
        f = np.empty(3)
        for i in range(3):
            f[i] = m * (b_g[b, i] - acc[i])
        for k in range(nc):
            v = 0.0
            for i in range(3):
                v += J[i, k] * f[i] - W[i, k] * t[i]
            Fe[b, k] = v
            if with_mass:
                for q in range(nc):
                    v = 0.0
                    for i in range(3):
                        v += m * J[i, k] * J[i, q]
                        for j in range(3):
                            v += W[i, k] * Ig[i, j] * W[j, q]
                    Me[b, k, q] = v
    return FC, FN, Me, Fe


if AVAILABLE:
    _jit = numba.njit(cache=True, nogil=True)
    _planar_local = _jit(_planar_local)
    _planar_frame = _jit(_planar_frame)
    _point = point_compiled.compiled_point
    _frame_local = _jit(_frame_local)
    _frames = _jit(_frames)
    _add_row = _jit(_add_row)
    _cross = _jit(_cross)
    _joint_terms_compiled = _jit(_joint_terms)
    _joint_columns_compiled = _jit(_joint_columns)
    _body_blocks_compiled = _jit(_body_blocks)


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


_KINDS = {"coincidence": COINCIDENCE, "distance": DISTANCE, "hinge_axis": HINGE_AXIS,
          "planar_pin": PLANAR_PIN, "prismatic": PRISMATIC}


def _frame_tables(obj, N, model, frames):
    """Set the frame tables of ``frames`` (planar or beam specs; N coordinates) and the element
    tables of ``model`` (None: planar frames only, empty tables) on ``obj``: the arguments of
    _frame_local."""
    obj.N = int(N)
    if model is None:
        obj.n, obj.i_s1 = 2, 0
        obj.D_all = np.zeros((1, 6, 1))
        obj.pow_p = np.zeros((1, 1), dtype=np.int64)
        obj.pow_t = np.zeros((1, 1), dtype=np.int64)
        obj.bases = np.zeros((0, 3, 3))
        obj.el_idx = np.zeros((0, 4), dtype=np.int64)
        first = np.zeros(1, dtype=np.int64)
    else:
        els = [el for b in model.beams for el in b.elements]
        el0 = els[0]
        obj.n, obj.i_s1 = int(el0.n), int(el0.i_s1)
        obj.D_all = np.ascontiguousarray(el0.D_all, dtype=float)
        obj.pow_p = np.ascontiguousarray(el0.pow_p, dtype=np.int64)
        obj.pow_t = np.ascontiguousarray(el0.pow_t, dtype=np.int64)
        obj.bases = np.ascontiguousarray(np.stack([el.G for el in els]), dtype=float)
        obj.el_idx = np.stack([np.asarray(off + imap, dtype=np.int64)
                               for b, off in zip(model.beams, model.offsets)
                               for imap in b.index_map])
        first = np.cumsum([0] + [len(b.elements) for b in model.beams])
    F = len(frames)
    obj.frames = frames
    obj.f_kind = np.zeros(F, dtype=np.int64)
    obj.f_idx = np.full((F, 4), -1, dtype=np.int64)
    obj.f_C = np.zeros((F, 3, 3, 3))
    obj.f_ax = np.zeros((F, 3))
    obj.f_p = np.zeros((F, 3))
    obj.f_s = np.zeros(F)
    obj.f_hasoff = np.zeros(F, dtype=np.bool_)
    for i, f in enumerate(frames):
        spec = f.spec
        if spec[0] == "planar":
            _, _, cols, C0, S0, P0, ax, p = spec
            obj.f_kind[i] = PLANAR
            obj.f_idx[i] = cols
            obj.f_C[i] = (C0, S0, P0)
            obj.f_ax[i] = ax
            obj.f_p[i] = p
        else:                                    # ("beam", model, ibeam, s, p or None)
            _, _, ibeam, s, p = spec
            obj.f_kind[i] = BEAM
            obj.f_idx[i, 0] = first[ibeam]
            obj.f_s[i] = s
            if p is not None:
                obj.f_p[i] = p
                obj.f_hasoff[i] = True


class JointProgram:
    """The frame and row tables of a joint list (see the module docstring); build with
    :func:`joint_program_for`."""

    def __init__(self, model, frames, cons):
        _frame_tables(self, model.n_coords, model, frames)
        where = {id(f): i for i, f in enumerate(frames)}
        K = len(cons)
        self.m = int(sum(c.m for c in cons))
        self.c_kind = np.zeros(K, dtype=np.int64)
        self.c_f = np.full((K, 3), -1, dtype=np.int64)
        self.c_vec = np.zeros((K, 3, 3))
        self.c_row0 = np.zeros(K, dtype=np.int64)
        row = 0
        for k, c in enumerate(cons):
            kind, vecs, fs = c.joint_program
            self.c_kind[k] = _KINDS[kind]
            self.c_f[k, :len(fs)] = [where[id(f)] for f in fs]
            for j, vec in enumerate(vecs):
                self.c_vec[k, j] = vec
            self.c_row0[k] = row
            row += c.m

    def terms(self, Q, Qd, rate_part: bool = False):
        """(g (m,) without the targets b, G = g_Q (m, N), g_QQ[Q_dot, Q_dot] (m,), and with
        ``rate_part`` g_QQ Q_dot (m, N), else None) at the real state (Q, Q_dot); the interface
        of :meth:`sim_core.physics._constraints_numba.ConstraintProgram.terms`."""
        Q = np.ascontiguousarray(Q, dtype=float)
        Qd = np.ascontiguousarray(Qd, dtype=float)
        g, G, quad, Gr, total = _joint_terms_compiled(Q, Qd, *self._args(), bool(rate_part))
        cardan_compiled.check_finite(total, "joint rows")
        return g, G, quad, (Gr if rate_part else None)

    def _args(self):
        return (self.N, self.f_kind, self.f_idx, self.f_C, self.f_ax, self.f_p, self.f_s,
                self.f_hasoff, self.el_idx, self.n, self.D_all, self.pow_p, self.pow_t,
                self.bases, self.i_s1, self.c_kind, self.c_f, self.c_vec, self.c_row0, self.m,
                COMPLEX_STEP)

    def dependencies(self, Q) -> np.ndarray:
        """(F, N) bool: the coordinates each frame depends on at Q (its ``coords``)."""
        deps = np.zeros((len(self.frames), self.N), dtype=np.bool_)
        for i, f in enumerate(self.frames):
            deps[i, f.coords(Q)] = True
        return deps

    def columns(self, Q, Qd, Qdd, lam, b0, bd, bdd, xi1, xi2, cols, steps, deps=None):
        """Forward-difference columns ``cols`` (steps ``steps``) of G^T lambda (N, ncols) and of
        the acceleration-level rows (m, ncols), see _joint_columns; the interface of
        :meth:`sim_core.physics._constraints_numba.ConstraintProgram.columns` (``deps`` unused:
        every column re-evaluates all frames)."""
        f = np.ascontiguousarray
        dR1, dR2, total = _joint_columns_compiled(
            f(Q, dtype=float), f(Qd, dtype=float), f(Qdd, dtype=float), f(lam, dtype=float),
            f(b0, dtype=float), f(bd, dtype=float), f(bdd, dtype=float), float(xi1),
            float(xi2), f(cols, dtype=np.int64), f(steps, dtype=float), *self._args())
        cardan_compiled.check_finite(total, "joint rows")
        return dR1, dR2


def joint_program_for(cons) -> JointProgram | None:
    """The compiled program of a joint list (cached on its first constraint, rebuilt when the
    list changes), or None where it does not cover the list: numba missing, a constraint
    without ``joint_program``, a frame without a planar or beam ``spec``, frames of more than one
    model, a beam of more than one element, or elements with unequal tables."""
    return cached_program(cons, "_joint_program", _build)


def _build(cons):
    found = program_points(cons, "joint_program", ("planar", "beam"), "beam")
    if found is None:
        return None
    frames, model = found
    if any(len(b.elements) != 1 for b in model.beams) or not equal_element_tables(model):
        return None
    return JointProgram(model, frames, cons)


class BodyProgram:
    """The Newton-Euler blocks of rigid bodies whose mass-centre frames are planar (body or
    turntable) frames, in one compiled call (see _body_blocks); built by
    :meth:`sim_core.physics.rigid_body.CompiledRigidBodies.build`."""

    def __init__(self, N, frames, masses, inertias, gravities):
        _frame_tables(self, N, None, frames)
        self.b_mass = np.asarray(masses, dtype=float)
        self.b_I = np.ascontiguousarray(inertias, dtype=float)
        self.b_g = np.ascontiguousarray(gravities, dtype=float)

    def blocks(self, Q, Qd, mass: bool = True):
        """(cols (B, 4), ncols (B,), Me (B, 4, 4), Fe (B, 4)) at the real state (Q, Q_dot)."""
        return _body_blocks_compiled(
            np.ascontiguousarray(Q, dtype=float), np.ascontiguousarray(Qd, dtype=float),
            self.N, self.f_kind, self.f_idx, self.f_C, self.f_ax, self.f_p, self.f_s,
            self.f_hasoff, self.el_idx, self.n, self.D_all, self.pow_p, self.pow_t, self.bases,
            self.i_s1, self.b_mass, self.b_I, self.b_g, bool(mass), COMPLEX_STEP)
