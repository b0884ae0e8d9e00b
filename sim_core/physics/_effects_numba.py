"""Compiled (numba) element mass matrix and force vector of the telescopic effect set.

``Model.element_mass_force(Model.element_context(t, el, qe, qde))`` with the effects Inertia
(mass centre on the reference line, y_c = z_c = 0), Elasticity, StressFilter(h) and Gravity(g)
of :mod:`sim_core.physics.effects` costs ~100 small numpy operations per element (a real
``SplineElement.evaluate``, a complex-step one for the convective terms, the lazily formed
Jacobians J_r, J_w, B_xi, B_s and the effect sums: at 9 nodes, 40 Gauss points and 59
coordinates the call overhead dominates).  This is the same algebra as one compiled pass over
the quadrature points:

* kinematics at the Gauss points (Zhao, Qi, Wang (2024), Sections 3-5): spline basis rows with
  the powers of the sub-element length l (Eqs. 5, 10-11, cached tables of the element), r and
  its s-derivatives, the section state (Eqs. 24-33, the compiled kernel of
  :mod:`cardan_compiled`), the material Jacobians at fixed s: J_r = dr/dQ|_s, the angular
  velocity Jacobian J_w = T dpsi/dQ|_s (Eqs. 30-31) and the strain Jacobians B_xi (fixed xi)
  and B_s (fixed s, material);
* convective terms (J_r)^. q_dot, (J_w)^. q_dot, (B_s)^. q_dot at fixed s by complex-step
  differentiation (as ``Model.element_context``: state qe + i h qde, the same material points
  s, whose xi then carries the perturbation), contracted with q_dot without forming the complex
  Jacobians; the same :mod:`cardan_compiled` kernel compiled for complex128;
* virtual power of the effects (Eq. 34): inertia M += int rhoA J_r^T J_r + J_w^T J J_w ds,
  F -= int rhoA J_r^T a + J_w^T (J w_dot + omega x J omega) ds; elastic force as the gradient
  of the strain energy (Eqs. 35-36: F -= sum w [l B_xi^T D eps + W dl/dQ]); the stress filter of
  the SIMULTECH 2020 paper (Eq. 53): M += (h^2/6) int B_s^T D B_s ds, F -= int B_s^T D ((h/2) eps_dot +
  (h^2/6) (B_s)^. q_dot) ds; gravity F += int rhoA J_r^T g ds.

With inertia or the filter the kinematics are evaluated once, at the complex-step state: the
real parts are the real kinematics (to O(h^2) = 1e-40 relative), so no separate real pass is
made.  The mass matrix is one BLAS product A^T A of the weighted Jacobian rows J_w and B_s of
all points stacked into a (G k, n_coords) matrix (k = 3 for the rotary inertia, + 4 for the
filter) plus the translational part sum w rhoA J_r^T J_r formed in its Kronecker structure
(J_r = X_0 (x) I_3 on the position coefficients: a (n+4) x (n+4) sum instead of 3 rows per
point in the product, the other rows scaled in place for it); the force one matrix-vector
product of the stacked unweighted rows (J_r, J_w, B_s) with the per-row loads.

The numpy path (``Model.element_mass_force``) stays the reference and the fallback where numba
is not installed (``AVAILABLE`` is False then); ``tests/beam/test_element_compiled.py`` checks
that both agree to round-off.
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba
from sim_core.physics.beam import _cardan_numba as cardan_compiled
from sim_core.physics.complex_step import COMPLEX_STEP

_NO_ACC = np.zeros(0)
NO_ACC = _NO_ACC             # "no accelerations" for the kernels' qdde argument


def _centre_line(qe, X, Y, n, basis):
    """RR (G, 7, 3): r, r', r'', r''' and d/dl at fixed xi of r, r', r''; TT (G, 5): gamma,
    gamma', gamma'' and d/dl of gamma, gamma'; and the section state of cardan_compiled."""
    G = X.shape[0]
    na = n + 4
    npos = 3 * na
    nt = 2 * n
    dt = X.dtype
    RR = np.zeros((G, 7, 3), dtype=dt)
    TT = np.zeros((G, 5), dtype=dt)
    for g in range(G):
        for i in range(7):
            r0 = RR[g, i, 0]
            r1 = RR[g, i, 1]
            r2 = RR[g, i, 2]
            for a in range(na):
                x = X[g, i, a]
                r0 += x * qe[3 * a]
                r1 += x * qe[3 * a + 1]
                r2 += x * qe[3 * a + 2]
            RR[g, i, 0] = r0
            RR[g, i, 1] = r1
            RR[g, i, 2] = r2
        for i in range(5):
            acc = TT[g, i]
            for a in range(nt):
                acc += Y[g, i, a] * qe[npos + a]
            TT[g, i] = acc
    rp = np.empty((G, 3), dtype=dt)
    rpp = np.empty((G, 3), dtype=dt)
    gam = np.empty(G, dtype=dt)
    gamp = np.empty(G, dtype=dt)
    for g in range(G):
        for j in range(3):
            rp[g, j] = RR[g, 1, j]
            rpp[g, j] = RR[g, 2, j]
        gam[g] = TT[g, 0]
        gamp[g] = TT[g, 1]
    eps, d, _, dpsi, tmat, _, _ = cardan_compiled.section_state_compiled(rp, rpp, gam, gamp,
                                                                         basis)
    return RR, TT, eps, d, dpsi, tmat


def _strain_arguments(RR, TT, g, x_l, x_p):
    """The l-derivatives x_l and s-derivatives x_p of (r', r'', gamma, gamma') at point g (the
    arguments of the strain derivatives d = d eps / d x, moving_node_beam._kin_B)."""
    for j in range(3):
        x_l[j] = RR[g, 5, j]
        x_l[3 + j] = RR[g, 6, j]
        x_p[j] = RR[g, 2, j]
        x_p[3 + j] = RR[g, 3, j]
    x_l[6] = TT[g, 3]
    x_l[7] = TT[g, 4]
    x_p[6] = TT[g, 1]
    x_p[7] = TT[g, 2]


def _complex_kinematics(qe, qde, cstep, n, q_phi, q_psi, q_drows, q_pos, pow_p, pow_t, basis,
                        i_s1):
    """The Gauss-point kinematics at the complex-step state qe + i h qde at the fixed material
    s (Model.element_context): (X, Y, ds, RR, TT, eps, d, dpsi, tmat), complex; their real
    parts are the real kinematics (to O(h^2) = 1e-40 relative), their imaginary parts / h the
    rates the convective terms need (_convective_rates).
    The basis rows at the complex xi of a Gauss point: xi = (s - s_1)/l - sub (Eq. 10) has the
    real part of the point's tables (q_phi, q_psi before the powers of l) and
    Im xi = -(Im s_1 + chi Im l)/Re l (to O(h^2), chi = sub + xi), so rows(xi) = rows +
    i Im(xi) d rows/d xi (q_drows) exactly in double precision for the step h = 1e-20."""
    G = q_pos.shape[0]
    na = n + 4
    nt = 2 * n
    nq = qe.shape[0]
    qc = np.empty(nq, dtype=np.complex128)
    for k in range(nq):
        qc[k] = qe[k] + 1j * (cstep * qde[k])
    ellr = (qe[i_s1 + 1] - qe[i_s1]) / (n - 1)
    s1 = qc[i_s1]
    ell = (qc[i_s1 + 1] - s1) / (n - 1)                               # Eq. 5
    lpow = cardan_compiled.length_powers(ell)
    X = np.empty((G, 7, na), dtype=np.complex128)
    Y = np.empty((G, 5, nt), dtype=np.complex128)
    ds = np.empty((G, 2), dtype=np.complex128)
    for g in range(G):
        xi_im = -(s1.imag + q_pos[g] * ell.imag) / ellr               # Im xi (Eq. 10)
        for i in range(7):
            for a in range(na):
                k = i * na + a
                X[g, i, a] = (q_phi[g, i, a] + 1j * (xi_im * q_drows[g, k])) \
                    * lpow[pow_p[i, a]]
        off = 7 * na
        for i in range(5):
            for a in range(nt):
                k = off + i * nt + a
                Y[g, i, a] = (q_psi[g, i, a] + 1j * (xi_im * q_drows[g, k])) \
                    * lpow[pow_t[i, a]]
        frac = (q_pos[g] + 1j * xi_im) / (n - 1)
        ds[g, 0] = 1.0 - frac
        ds[g, 1] = frac
    RR, TT, eps, d, dpsi, tmat = _centre_line(qc, X, Y, n, basis)
    return X, Y, ds, RR, TT, eps, d, dpsi, tmat


def _convective_rates(qde, cstep, n, X, Y, ds, RR, TT, eps, d, dpsi, tmat, i_s1, with_strain):
    """Material convective terms at the Gauss points from _complex_kinematics:
    a = (J_r)^. q_dot (G, 3), w_dot = (J_w)^. q_dot (G, 3), eps_ddot = (B_s)^. q_dot (G, 4)
    (zeros unless with_strain), by complex step in q along q_dot at the fixed material s; and
    the real parts of the same sums, omega = J_w q_dot (G, 3) and eps_dot = B_s q_dot (G, 4)
    (to O(h^2) = 1e-40 relative)."""
    G = X.shape[0]
    na = n + 4
    npos = 3 * na
    nt = 2 * n
    dl0 = -1.0 / (n - 1)
    dl1 = 1.0 / (n - 1)
    qs0 = qde[i_s1]
    qs1 = qde[i_s1 + 1]
    a_out = np.empty((G, 3))
    w_out = np.empty((G, 3))
    e_out = np.zeros((G, 4))
    om = np.empty((G, 3))               # the real parts: omega = J_w q_dot, eps_dot = B_s q_dot
    ed = np.zeros((G, 4))
    u0 = np.empty(3, dtype=np.complex128)
    u1 = np.empty(3, dtype=np.complex128)
    u2 = np.empty(3, dtype=np.complex128)
    pdot = np.empty(3, dtype=np.complex128)
    x_l = np.empty(8, dtype=np.complex128)
    x_p = np.empty(8, dtype=np.complex128)
    for g in range(G):
        u0[:] = 0.0
        u1[:] = 0.0
        u2[:] = 0.0
        for a in range(na):
            x0 = X[g, 0, a]
            x1 = X[g, 1, a]
            x2 = X[g, 2, a]
            for j in range(3):
                v = qde[3 * a + j]
                u0[j] += x0 * v
                u1[j] += x1 * v
                u2[j] += x2 * v
        t0 = 0.0j
        t1 = 0.0j
        for a in range(nt):
            v = qde[npos + a]
            t0 += Y[g, 0, a] * v
            t1 += Y[g, 1, a] * v
        ds0 = ds[g, 0]
        ds1 = ds[g, 1]
        for j in range(3):                                            # J_r q_dot
            acc = (u0[j] + (RR[g, 4, j] * dl0 - RR[g, 1, j] * ds0) * qs0
                   + (RR[g, 4, j] * dl1 - RR[g, 1, j] * ds1) * qs1)
            a_out[g, j] = acc.imag / cstep
        for i in range(2):                                            # (alpha, beta)^. at fixed s
            c_l = (dpsi[g, i, 0] * RR[g, 5, 0] + dpsi[g, i, 1] * RR[g, 5, 1]
                   + dpsi[g, i, 2] * RR[g, 5, 2])
            c_s = (dpsi[g, i, 0] * RR[g, 2, 0] + dpsi[g, i, 1] * RR[g, 2, 1]
                   + dpsi[g, i, 2] * RR[g, 2, 2])
            pdot[i] = (dpsi[g, i, 0] * u1[0] + dpsi[g, i, 1] * u1[1] + dpsi[g, i, 2] * u1[2]
                       + (c_l * dl0 - c_s * ds0) * qs0 + (c_l * dl1 - c_s * ds1) * qs1)
        pdot[2] = (t0 + (TT[g, 3] * dl0 - TT[g, 1] * ds0) * qs0
                   + (TT[g, 3] * dl1 - TT[g, 1] * ds1) * qs1)
        for i in range(3):                                            # J_w q_dot = T psi^.
            acc = tmat[g, i, 0] * pdot[0] + tmat[g, i, 1] * pdot[1] + tmat[g, i, 2] * pdot[2]
            w_out[g, i] = acc.imag / cstep
            om[g, i] = acc.real
        if with_strain:                                               # B_s q_dot
            _strain_arguments(RR, TT, g, x_l, x_p)
            for r in range(4):
                cl = 0.0j
                cp = 0.0j
                for k in range(8):
                    cl += d[g, r, k] * x_l[k]
                    cp += d[g, r, k] * x_p[k]
                acc = (d[g, r, 0] * u1[0] + d[g, r, 1] * u1[1] + d[g, r, 2] * u1[2]
                       + d[g, r, 3] * u2[0] + d[g, r, 4] * u2[1] + d[g, r, 5] * u2[2]
                       + d[g, r, 6] * t0 + d[g, r, 7] * t1
                       + (cl * dl0 - cp * ds0) * qs0 + (cl * dl1 - cp * ds1) * qs1)
                e_out[g, r] = acc.imag / cstep
                ed[g, r] = acc.real
    return a_out, w_out, e_out, om, ed



def _mass_force(qe, qde, n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w, q_pos, q_drows, basis,
                i_s1, rhoA, Jrot, D, h, grav, inertia, elasticity, gravity, needs_mass, cstep,
                qdde):
    """(Me (nq, nq) or (0, 0), Fe (nq,)) of one element; see element_mass_force.  A non-empty
    ``qdde`` subtracts Me qdde from Fe through the rows (Me = sum_rows w c J^T J)."""
    G = q_phi.shape[0]
    na = n + 4
    npos = 3 * na
    nt = 2 * n
    nq = qe.shape[0]
    filt = h > 0.0
    strains = elasticity or filt
    s1 = qe[i_s1]
    ell = (qe[i_s1 + 1] - s1) / (n - 1)                               # Eq. 5
    lpow = cardan_compiled.length_powers(ell)
    X = np.empty((G, 7, na))
    Y = np.empty((G, 5, nt))
    for g in range(G):
        for i in range(7):
            for a in range(na):
                X[g, i, a] = q_phi[g, i, a] * lpow[pow_p[i, a]]
        for i in range(5):
            for a in range(nt):
                Y[g, i, a] = q_psi[g, i, a] * lpow[pow_t[i, a]]
    conv = inertia or filt
    if conv:
        # one complex pass: its real parts are the real kinematics (no second, real pass)
        cx = _complex_kinematics(qe, qde, cstep, n, q_phi, q_psi, q_drows, q_pos, pow_p, pow_t,
                                 basis, i_s1)
        RR = np.ascontiguousarray(cx[3].real)
        TT = np.ascontiguousarray(cx[4].real)
        eps = np.ascontiguousarray(cx[5].real)
        d = np.ascontiguousarray(cx[6].real)
        dpsi = np.ascontiguousarray(cx[7].real)
        tmat = np.ascontiguousarray(cx[8].real)
    else:
        RR, TT, eps, d, dpsi, tmat = _centre_line(qe, X, Y, n, basis)
    dl = np.empty(2)
    dl[0] = -1.0 / (n - 1)
    dl[1] = 1.0 / (n - 1)
    wl = np.empty(G)
    for g in range(G):
        wl[g] = q_w[g] * ell

    # rows per point: J_r in its structure (X_0 (x) I_3 on the position coefficients, Jrs on
    # the s_1, s_n columns), the stacked rows Jm: J_w (0:3), B_s (3:7)
    K = 7 if strains else 3
    Jm = np.zeros((G, K, nq))
    Jrs = np.empty((G, 3, 2))
    cp_ds = np.zeros((G, 4, 2))          # B_xi - B_s on the s_1, s_n columns: eps' ds/dchi
    chi = np.empty((3, 2))
    A3 = np.empty((3, 3))
    x_l = np.empty(8)
    x_p = np.empty(8)
    for g in range(G):
        for j in range(3):                                            # J_r, s columns
            for c in range(2):
                Jrs[g, j, c] = RR[g, 4, j] * dl[c] - RR[g, 1, j] * q_ds[g, c]
        for i in range(2):                                            # d(alpha, beta)/dchi|_s
            c_l = (dpsi[g, i, 0] * RR[g, 5, 0] + dpsi[g, i, 1] * RR[g, 5, 1]
                   + dpsi[g, i, 2] * RR[g, 5, 2])
            c_s = (dpsi[g, i, 0] * RR[g, 2, 0] + dpsi[g, i, 1] * RR[g, 2, 1]
                   + dpsi[g, i, 2] * RR[g, 2, 2])
            for c in range(2):
                chi[i, c] = c_l * dl[c] - c_s * q_ds[g, c]
        for c in range(2):
            chi[2, c] = TT[g, 3] * dl[c] - TT[g, 1] * q_ds[g, c]
        for i in range(3):                                            # J_w (Eqs. 30-31)
            for j in range(3):
                A3[i, j] = tmat[g, i, 0] * dpsi[g, 0, j] + tmat[g, i, 1] * dpsi[g, 1, j]
            for a in range(na):
                x1 = X[g, 1, a]
                Jm[g, i, 3 * a] = A3[i, 0] * x1
                Jm[g, i, 3 * a + 1] = A3[i, 1] * x1
                Jm[g, i, 3 * a + 2] = A3[i, 2] * x1
            for a in range(nt):
                Jm[g, i, npos + a] = tmat[g, i, 2] * Y[g, 0, a]
            for c in range(2):
                Jm[g, i, i_s1 + c] = (tmat[g, i, 0] * chi[0, c] + tmat[g, i, 1] * chi[1, c]
                                      + tmat[g, i, 2] * chi[2, c])
        if strains:                                                   # B_s
            _strain_arguments(RR, TT, g, x_l, x_p)
            for r in range(4):
                for a in range(na):
                    x1 = X[g, 1, a]
                    x2 = X[g, 2, a]
                    for j in range(3):
                        Jm[g, 3 + r, 3 * a + j] = d[g, r, j] * x1 + d[g, r, 3 + j] * x2
                for a in range(nt):
                    Jm[g, 3 + r, npos + a] = d[g, r, 6] * Y[g, 0, a] + d[g, r, 7] * Y[g, 1, a]
                cl = 0.0
                cp = 0.0
                for k in range(8):
                    cl += d[g, r, k] * x_l[k]
                    cp += d[g, r, k] * x_p[k]
                for c in range(2):
                    cp_ds[g, r, c] = cp * q_ds[g, c]
                    Jm[g, 3 + r, i_s1 + c] = cl * dl[c] - cp_ds[g, r, c]

    # per-row loads vr (J_r), vm (Jm): Fe = vr . J_r + vm . Jm (one matrix-vector product) +
    # the dl/dQ energy terms; cm: the mass constant of each Jm row (0: not in the mass)
    cm = np.zeros(K)
    for i in range(3):
        cm[i] = Jrot[i] if inertia else 0.0
    if strains:
        for r in range(4):
            cm[3 + r] = (h * h / 6.0) * D[r] if filt else 0.0
    if conv:
        acc_c, wdot_c, eddot_c, om_c, ed_c = _convective_rates(
            qde, cstep, n, cx[0], cx[1], cx[2], cx[3], cx[4], cx[5], cx[6], cx[7], cx[8], i_s1,
            filt)
    vr = np.zeros((G, 3))
    vm = np.zeros((G, K))
    Fe_extra = np.zeros(nq)
    total = 0.0
    omega = np.empty(3)
    jw = np.empty(3)
    for g in range(G):
        mr = wl[g] * rhoA
        if inertia:
            for j in range(3):
                vr[g, j] -= mr * acc_c[g, j]
            for i in range(3):              # J_w q_dot (the rates' real part)
                omega[i] = om_c[g, i]
                jw[i] = Jrot[i] * om_c[g, i]
            vm[g, 0] -= wl[g] * (Jrot[0] * wdot_c[g, 0] + omega[1] * jw[2] - omega[2] * jw[1])
            vm[g, 1] -= wl[g] * (Jrot[1] * wdot_c[g, 1] + omega[2] * jw[0] - omega[0] * jw[2])
            vm[g, 2] -= wl[g] * (Jrot[2] * wdot_c[g, 2] + omega[0] * jw[1] - omega[1] * jw[0])
        if gravity:
            for j in range(3):
                vr[g, j] += mr * grav[j]
        if elasticity:
            W = 0.0
            for r in range(4):
                sig = eps[g, r] * D[r]
                vm[g, 3 + r] -= wl[g] * sig
                W += 0.5 * sig * eps[g, r]
                for c in range(2):                                    # B_xi = B_s + eps' ds/dchi
                    Fe_extra[i_s1 + c] -= wl[g] * sig * cp_ds[g, r, c]
            total += q_w[g] * W                                       # dU/dl at fixed xi
        if filt:
            for r in range(4):              # B_s q_dot (the rates' real part)
                vm[g, 3 + r] -= wl[g] * D[r] * (0.5 * h * ed_c[g, r]
                                                + (h * h / 6.0) * eddot_c[g, r])
        if qdde.shape[0] > 0:           # - Me qdde = - sum_rows (w c) J^T (J qdde)
            if inertia and rhoA != 0.0:
                for j in range(3):
                    acc = Jrs[g, j, 0] * qdde[i_s1] + Jrs[g, j, 1] * qdde[i_s1 + 1]
                    for a in range(na):
                        acc += X[g, 0, a] * qdde[3 * a + j]
                    vr[g, j] -= wl[g] * rhoA * acc
            for i in range(K):
                if cm[i] != 0.0:
                    acc = 0.0
                    for k in range(nq):
                        acc += Jm[g, i, k] * qdde[k]
                    vm[g, i] -= wl[g] * cm[i] * acc
    Fe = np.dot(vm.reshape(G * K), Jm.reshape(G * K, nq))
    for g in range(G):                  # vr . J_r in its structure
        for a in range(na):
            x0 = X[g, 0, a]
            for j in range(3):
                Fe[3 * a + j] += vr[g, j] * x0
        for c in range(2):
            Fe[i_s1 + c] += vr[g, 0] * Jrs[g, 0, c] + vr[g, 1] * Jrs[g, 1, c] \
                + vr[g, 2] * Jrs[g, 2, c]
    for k in range(nq):
        Fe[k] += Fe_extra[k]
    if elasticity:
        inv = 1.0 / (n - 1)
        Fe[i_s1] += total * inv       # dl/ds_1 = -1/(n-1), with the minus of F -= ...
        Fe[i_s1 + 1] -= total * inv

    if not needs_mass or not (inertia or filt):
        if needs_mass:
            return np.zeros((nq, nq)), Fe
        return np.zeros((0, 0)), Fe
    # mass: Me = A^T A with the weighted rows sqrt(w c) Jm of all points (one BLAS product; the
    # rows scaled in place where every c is non-zero, else the rows of a non-zero c copied
    # out, e.g. J_t = J_b = 0), plus the translational sum w rhoA J_r^T J_r formed in the
    # structure of J_r (_add_translational_mass)
    km = 0
    for i in range(K):
        if cm[i] != 0.0:
            km += 1
    if km == K:
        for g in range(G):
            for i in range(K):
                wi = np.sqrt(wl[g] * cm[i])
                for k in range(nq):
                    Jm[g, i, k] *= wi
        Me = _gram(Jm.reshape(G * K, nq))
    else:
        A = np.empty((G, km, nq))
        for g in range(G):
            q = 0
            for i in range(K):
                if cm[i] != 0.0:
                    wi = np.sqrt(wl[g] * cm[i])
                    for k in range(nq):
                        A[g, q, k] = Jm[g, i, k] * wi
                    q += 1
        Me = _gram(A.reshape(G * km, nq))
    if inertia and rhoA != 0.0:
        _add_translational_mass(Me, Jrs, X, wl, rhoA, na, i_s1)
    return Me, Fe


def _add_translational_mass(Me, Jrs, X, wl, rhoA, na, i_s1):
    """Me += sum_g w_g rhoA J_r^T J_r, with J_r = X_0 (x) I_3 on the position coefficients
    (J_r[g, j, 3 a + j] = X[g, 0, a]) and the s columns Jrs[g, j, c]: the (na, na) sum
    sum_g w rhoA X_0 X_0^T on the diagonal of every 3 x 3 block, the position-s and s-s
    couplings from the s columns (the same sums as the product, grouped)."""
    G = X.shape[0]
    K0 = np.zeros((na, na))
    Ks = np.zeros((na, 3, 2))
    Kss = np.zeros((2, 2))
    for g in range(G):
        c = wl[g] * rhoA
        for a in range(na):
            xa = c * X[g, 0, a]
            for b in range(na):
                K0[a, b] += xa * X[g, 0, b]
            for j in range(3):
                for cc in range(2):
                    Ks[a, j, cc] += xa * Jrs[g, j, cc]
        for cc in range(2):
            for dd in range(2):
                acc = 0.0
                for j in range(3):
                    acc += Jrs[g, j, cc] * Jrs[g, j, dd]
                Kss[cc, dd] += c * acc
    for a in range(na):
        for b in range(na):
            v = K0[a, b]
            for j in range(3):
                Me[3 * a + j, 3 * b + j] += v
        for j in range(3):
            for cc in range(2):
                v = Ks[a, j, cc]
                Me[3 * a + j, i_s1 + cc] += v
                Me[i_s1 + cc, 3 * a + j] += v
    for cc in range(2):
        for dd in range(2):
            Me[i_s1 + cc, i_s1 + dd] += Kss[cc, dd]


def _mass_force_batch(QE, QDE, n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w, q_pos, q_drows,
                      bases, i_s1, rhoAs, Jrots, Ds, h, grav, inertia, elasticity, gravity, cstep,
                      no_acc):
    """_mass_force of E elements with the same tables (rows of QE, QDE; per element the
    reference basis, rhoA, Jrot, D): (Me (E, nq, nq), Fe (E, nq)) in one call."""
    E, nq = QE.shape
    Ms = np.empty((E, nq, nq))
    Fs = np.empty((E, nq))
    for e in range(E):
        M, F = _compiled_mass_force(QE[e], QDE[e], n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w,
                                    q_pos, q_drows, bases[e], i_s1, rhoAs[e], Jrots[e],
                                    Ds[e], h, grav, inertia, elasticity, gravity, True, cstep,
                                    no_acc)
        Ms[e] = M
        Fs[e] = F
    return Ms, Fs


def _differences_batch(QE, QDE, QDDE, HQ, HQD, n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w, q_pos,
                       q_drows, bases, i_s1, rhoAs, Jrots, Ds, h, grav, inertia,
                       elasticity, gravity, cstep, no_acc, rates):
    """Forward differences of E elements (the structured Jacobian's element columns,
    sim_core.model.state_jacobian): per element d(F - M qdd)/dq and dF/dq_dot (nq, nq), steps HQ,
    HQD (exactly representable), the same kernel calls as the one-by-one path.  ``rates``
    False: the dF/dq_dot columns are left zero (the statics' tangent needs none)."""
    E, nq = QE.shape
    DP = np.empty((E, nq, nq))
    DR = np.zeros((E, nq, nq))
    for e in range(E):
        qe = QE[e].copy()
        qde = QDE[e].copy()
        args = (n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w, q_pos, q_drows, bases[e], i_s1,
                rhoAs[e], Jrots[e], Ds[e], h, grav, inertia, elasticity, gravity, False, cstep)
        R0 = _compiled_mass_force(qe, qde, *args, QDDE[e])[1]
        F0 = _compiled_mass_force(qe, qde, *args, no_acc)[1]
        for j in range(nq):
            x = qe[j]
            qe[j] = x + HQ[e, j]
            R = _compiled_mass_force(qe, qde, *args, QDDE[e])[1]
            qe[j] = x
            for i in range(nq):
                DP[e, i, j] = (R[i] - R0[i]) / HQ[e, j]
            if not rates:
                continue
            x = qde[j]
            qde[j] = x + HQD[e, j]
            F = _compiled_mass_force(qe, qde, *args, no_acc)[1]
            qde[j] = x
            for i in range(nq):
                DR[e, i, j] = (F[i] - F0[i]) / HQD[e, j]
    return DP, DR


def _gram_dot(A):
    """A^T A (numba's np.dot, BLAS gemm)."""
    return np.dot(A.T, A)


def _gram_syrk(A):
    """A^T A by BLAS dsyrk (half the products of gemm) on the C-ordered (m, nq) A, i.e. the
    Fortran-ordered A^T: C = A^T (A^T)^T, upper triangle in Fortran order = lower in C order."""
    m, nq = A.shape
    C = np.zeros((nq, nq))
    uplo = np.array([ord("U")], dtype=np.uint8)
    trans = np.array([ord("N")], dtype=np.uint8)
    nn = np.array([nq], dtype=np.int32)
    kk = np.array([m], dtype=np.int32)
    alpha = np.ones(1)
    beta = np.zeros(1)
    if m > 0:
        _dsyrk(uplo.ctypes, trans.ctypes, nn.ctypes, kk.ctypes, alpha.ctypes, A.ctypes,
               nn.ctypes, beta.ctypes, C.ctypes, nn.ctypes)
    for i in range(nq):
        for j in range(i + 1, nq):
            C[i, j] = C[j, i]
    return C


_SYRK = False
if AVAILABLE:
    # dsyrk of scipy's BLAS (the library numba's np.dot uses) as an external symbol, so that the
    # compiled functions stay cacheable; np.dot (gemm) where it cannot be found
    try:
        import llvmlite.binding as _llb
        from numba import types as _types
        from numba.extending import get_cython_function_address as _cython_address

        _llb.add_symbol("sim_core_element_dsyrk",
                        _cython_address("scipy.linalg.cython_blas", "dsyrk"))
        _dsyrk = _types.ExternalFunction("sim_core_element_dsyrk",
                                         _types.void(*([_types.voidptr] * 10)))
        _SYRK = True
    except Exception:        # pragma: no cover - scipy without cython_blas
        _SYRK = False


if AVAILABLE:
    _jit = numba.njit(cache=True, nogil=True)
    _strain_arguments = _jit(_strain_arguments)
    _centre_line = _jit(_centre_line)
    _complex_kinematics = _jit(_complex_kinematics)
    _convective_rates = _jit(_convective_rates)
    _gram = _jit(_gram_syrk if _SYRK else _gram_dot)
    _add_translational_mass = _jit(_add_translational_mass)
    _compiled_mass_force = _jit(_mass_force)
    _compiled_mass_force_batch = _jit(_mass_force_batch)
    _compiled_differences_batch = _jit(_differences_batch)
    # the kernels called from other compiled loops (integrate/_generalized_alpha_numba.py)
    mass_force_kernel = _compiled_mass_force
    mass_force_batch_kernel = _compiled_mass_force_batch
    differences_batch_kernel = _compiled_differences_batch


def element_mass_force(el, qe, qde, rhoA, Jrot, D, h=0.0, g=None, inertia=True,
                       elasticity=True, needs_mass=True, cstep=COMPLEX_STEP, qdde=None):
    """Element mass matrix (or None) and force vector, M q_ddot = F, of spline element ``el``
    (a ``SplineElement``) at the real state (qe, qde), for the effects

    * Inertia (``inertia``; mass per length ``rhoA``, rotary inertia ``Jrot`` = (J_s, J_t, J_b)
      per length, mass centre on the reference line),
    * Elasticity (``elasticity``; ``D`` = (EA, GJ, EI_t, EI_b)),
    * StressFilter(h) (``h`` > 0; 0 = off; also uses ``D``),
    * Gravity(g) (``g`` (3,) global, None or zeros = off),

    i.e. the totals of ``Model.element_mass_force(Model.element_context(t, el, qe, qde))`` with
    those effects.  ``needs_mass=False`` returns (None, Fe) (the mass products are skipped).
    ``qdde`` (nq,): returns (None, Fe - Me qdde), the product formed through the weighted rows
    without the mass matrix (the structured Jacobian's element columns).
    Raises RuntimeError if numba is not installed (use the Model path then).
    """
    if not AVAILABLE:
        raise RuntimeError("numba is not installed: use Model.element_mass_force")
    if el.tables_key[0] is not el.q_xi or el.tables_key[1] is not el.q_sub:
        el.basis_tables()
    qe = np.ascontiguousarray(qe, dtype=float)
    qde = np.ascontiguousarray(qde, dtype=float)
    grav = np.zeros(3) if g is None else np.ascontiguousarray(g, dtype=float)
    if qdde is not None:
        needs_mass = False
    Me, Fe = _compiled_mass_force(
        qe, qde, el.n, el.q_phi, el.q_psi, el.pow_p, el.pow_t, el.q_ds_dchi, el.q_w,
        el.q_pos, el.q_drows, el.G, el.i_s1, float(rhoA),
        np.ascontiguousarray(Jrot, dtype=float), np.ascontiguousarray(D, dtype=float),
        float(h), grav, bool(inertia), bool(elasticity), bool(np.any(grav != 0.0)),
        bool(needs_mass), float(cstep),
        _NO_ACC if qdde is None else np.ascontiguousarray(qdde, dtype=float))
    cardan_compiled.check_finite(Fe.sum() + (Me.sum() if needs_mass else 0.0),
                                 "element mass matrix or forces")
    return (Me if needs_mass else None), Fe


_TABLES = ("q_phi", "q_psi", "pow_p", "pow_t", "q_ds_dchi", "q_w", "q_pos", "q_drows")


class ElementBatch:
    """Mass matrices and forces of several elements in one compiled call (nogil: it can run on
    a second thread while the caller evaluates the constraint rows, ``Model``).  Valid for
    elements with equal basis tables (the same nodes and Gauss points) and the same effect set;
    :meth:`plan` returns None otherwise.  ``kws``: per element the effect arguments of
    :func:`element_mass_force` (``Model._compiled_effects``)."""

    def __init__(self, elements, kws):
        el0 = elements[0]
        self.key = tuple(id(el.q_xi) for el in elements) + tuple(id(el.q_sub) for el in elements)
        self.tables = tuple(getattr(el0, name) for name in _TABLES)
        self.n, self.i_s1 = el0.n, el0.i_s1
        self.bases = np.ascontiguousarray(np.stack([el.G for el in elements]), dtype=float)
        self.rhoAs = np.array([float(kw["rhoA"]) for kw in kws])
        self.Jrots = np.ascontiguousarray(np.stack([kw["Jrot"] for kw in kws]), dtype=float)
        self.Ds = np.ascontiguousarray(np.stack([kw["D"] for kw in kws]), dtype=float)
        self.inertia = bool(kws[0]["inertia"])
        self.elasticity = bool(kws[0]["elasticity"])

    @staticmethod
    def plan(elements, kws) -> "ElementBatch | None":
        if not AVAILABLE or not elements or any(kw is None for kw in kws):
            return None
        for el in elements:
            if el.tables_key[0] is not el.q_xi or el.tables_key[1] is not el.q_sub:
                el.basis_tables()
        el0 = elements[0]
        for el in elements[1:]:
            if el.n != el0.n or el.i_s1 != el0.i_s1 or not all(
                    np.array_equal(getattr(el, name), getattr(el0, name)) for name in _TABLES):
                return None
        flags = {(kw["inertia"], kw["elasticity"], kw["h"]) for kw in kws}
        gs = {tuple(np.asarray(kw["g"], float)) for kw in kws}
        if len(flags) != 1 or len(gs) != 1:
            return None
        return ElementBatch(elements, kws)

    def valid(self, elements) -> bool:
        """The elements' Gauss points are still those of the plan."""
        return self.key == (tuple(id(el.q_xi) for el in elements)
                            + tuple(id(el.q_sub) for el in elements))

    def element_arguments(self, element: int | None = None) -> tuple:
        """The batch kernels' per-plan arguments after the states: (n, the basis tables, the
        reference bases, i_s1, rhoA, Jrot, D per element) -- also the element worker's
        (:mod:`sim_core.model.workers`); ``element``: that one element's rows of the
        per-element tables."""
        e = slice(None) if element is None else slice(element, element + 1)
        return (self.n, *self.tables, self.bases[e], self.i_s1, self.rhoAs[e], self.Jrots[e],
                self.Ds[e])

    def __call__(self, QE, QDE, h, g, cstep=COMPLEX_STEP):
        """(Me (E, nq, nq), Fe (E, nq)) at the rows of QE, QDE (real, C-contiguous).  No
        finite check here (it reads numpy's error state, which is per thread): the caller
        checks with ``cardan_compiled.check_finite``."""
        grav = np.ascontiguousarray(g, dtype=float)
        return _compiled_mass_force_batch(
            QE, QDE, *self.element_arguments(), float(h), grav, self.inertia, self.elasticity,
            bool(np.any(grav != 0.0)), float(cstep), _NO_ACC)

    def differences(self, QE, QDE, QDDE, HQ, HQD, h, g, cstep=COMPLEX_STEP, element=None,
                    rates=True):
        """(d(F - M qdd)/dq, dF/dq_dot) (E, nq, nq) of every element by forward differences
        with the steps HQ, HQD (E, nq) at the rows of QE, QDE, QDDE (no finite check here,
        as in __call__); ``element``: the rows are this one element's alone (E = 1);
        ``rates`` False: dF/dq_dot left zero."""
        grav = np.ascontiguousarray(g, dtype=float)
        return _compiled_differences_batch(
            QE, QDE, QDDE, HQ, HQD, *self.element_arguments(element), float(h), grav,
            self.inertia, self.elasticity, bool(np.any(grav != 0.0)), float(cstep), _NO_ACC,
            bool(rates))
