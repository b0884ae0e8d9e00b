"""Compiled (numba) Newton iteration of the micro-motion solve (paper Eqs. 59-71).

The same damped Newton method as the Python loop of
:func:`sim_core.physics.contact.sliding_block_contact.solve_micro_motion` (stiffness floor kappa in the
Newton matrix only, the compression change capped at 4 max(delta_max, eps), Armijo
back-tracking on |S R|^2, convergence on max |S R| <= tol or the round-off floor of the sums),
written as one compiled loop: the friction Newton solves the four regions' micro-motions a few
times per right-hand side, and each Python iteration was ~20 small numpy calls.  The Python
loop stays as the reference and the fallback without numba;
``tests/contact/test_sliding_block_contact.py`` checks that both give the same solution.
The 5 x 5 Newton systems are solved inline (:func:`_solve5`, Gaussian elimination with partial
pivoting) and the products A x written as loops: numba's ``np.linalg.solve`` copies and calls
LAPACK for every system, which costs more than the solve itself at this size.

Returns (x, status, iterations, max |S R|, delta, f, f', R, z) with z = J^-T A^T f' the load
sensitivity at the solution (zeros unless converged).  Status codes: 0 converged, 1 singular Newton matrix, 2 line search failed, 3 no convergence in
max_iter iterations (the caller raises ContactSolveError with the reason).
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba

_ARMIJO = 1e-4
_EPS = float(np.finfo(float).eps)


def _spring(delta, k0, inv_eps, f, fp):
    """Eqs. 62-63 with the cubic transition (SpringLaw.force_and_tangent), in place."""
    for i in range(delta.shape[0]):
        x = min(max(delta[i] * inv_eps, 0.0), 1.0)
        kx2 = k0 * (x * x)              # the order of SpringLaw.force_and_tangent
        f[i] = kx2 * (3.0 - 2.0 * x) * delta[i]
        fp[i] = kx2 * (9.0 - 8.0 * x)


def _residual(GT, c5, S, f, R, SR):
    phi = 0.0
    err = 0.0
    for r in range(5):
        acc = c5[r]
        for i in range(f.shape[0]):
            acc += GT[r, i] * f[i]
        R[r] = acc
        SR[r] = S[r] * acc
        phi += SR[r] * SR[r]
        err = max(err, abs(SR[r]))
    return phi, err


def _newton_matrix(A, GT, kappa_GA, fp, Jm):
    """J = G^T diag(f') A + kappa (A^T A + mu Bf^T A), in place (the solver's Newton matrix);
    the springs off their stiff branch (f' = 0: open) add nothing and are skipped."""
    n = A.shape[0]
    for r in range(5):
        for c in range(5):
            Jm[r, c] = kappa_GA[r, c]
    for i in range(n):
        w = fp[i]
        if w == 0.0:
            continue
        for r in range(5):
            gw = GT[r, i] * w
            for c in range(5):
                Jm[r, c] += gw * A[i, c]


def _solve5(Jm, b, transpose):
    """x = Jm^-1 b (or Jm^-T b) of a 5 x 5 system by Gaussian elimination with partial
    pivoting on a copy (numpy's LAPACK solve, without its call overhead); NaN where a pivot is
    zero (the caller treats a non-finite step as a singular Newton matrix)."""
    M = np.empty((5, 6))
    for r in range(5):
        for c in range(5):
            M[r, c] = Jm[c, r] if transpose else Jm[r, c]
        M[r, 5] = b[r]
    for k in range(5):
        p = k
        big = abs(M[k, k])
        for r in range(k + 1, 5):
            if abs(M[r, k]) > big:
                big = abs(M[r, k])
                p = r
        if big == 0.0:
            return np.full(5, np.nan)
        if p != k:
            for c in range(k, 6):
                tmp = M[k, c]
                M[k, c] = M[p, c]
                M[p, c] = tmp
        for r in range(k + 1, 5):
            f = M[r, k] / M[k, k]
            if f != 0.0:
                for c in range(k + 1, 6):
                    M[r, c] -= f * M[k, c]
    x = np.empty(5)
    for k in range(4, -1, -1):
        acc = M[k, 5]
        for c in range(k + 1, 5):
            acc -= M[k, c] * x[c]
        x[k] = acc / M[k, k]
    return x


def _matvec(A, x, out):
    """out = A x for A (n, 5), in place."""
    for i in range(A.shape[0]):
        acc = 0.0
        for c in range(5):
            acc += A[i, c] * x[c]
        out[i] = acc


def _sensitivity(A, GT, kappa_GA, fp):
    """z = (J + kappa)^-T A^T f' at the solution: d(sum f)/dc = -z
    (ContactSolution.normal_load_gradient); zero where no spring is on its stiff branch."""
    n = A.shape[0]
    rhs = np.zeros(5)
    for c in range(5):
        for i in range(n):
            rhs[c] += A[i, c] * fp[i]
    if not np.any(rhs != 0.0):
        return rhs
    Jm = np.empty((5, 5))
    _newton_matrix(A, GT, kappa_GA, fp, Jm)
    return _solve5(Jm, rhs, True)


def _newton(A, GT, kappa_GA, c5, S, x, k0, eps, tol, load_scale, max_iter):
    n = A.shape[0]
    inv_eps = 1.0 / eps
    delta = np.empty(n)
    _matvec(A, x, delta)
    f = np.empty(n)
    fp = np.empty(n)
    R = np.empty(5)
    SR = np.empty(5)
    _spring(delta, k0, inv_eps, f, fp)
    phi, err = _residual(GT, c5, S, f, R, SR)
    row_scale = 0.0
    for r in range(5):
        for i in range(n):
            row_scale = max(row_scale, abs(S[r] * GT[r, i]))
    x_n = np.empty(5)
    f_n = np.empty(n)
    fp_n = np.empty(n)
    R_n = np.empty(5)
    SR_n = np.empty(5)
    Jm = np.empty((5, 5))
    dd = np.empty(n)
    delta_n = np.empty(n)
    it = 0
    while True:
        if err <= tol:
            return x, 0, it, err, delta, f, fp, R, _sensitivity(A, GT, kappa_GA, fp)
        floor = 64.0 * _EPS * (row_scale * f.sum() + load_scale)
        if err <= floor:
            return x, 0, it, err, delta, f, fp, R, _sensitivity(A, GT, kappa_GA, fp)
        if it == max_iter:
            return x, 3, it, err, delta, f, fp, R, np.zeros(5)
        _newton_matrix(A, GT, kappa_GA, fp, Jm)
        d = _solve5(Jm, -R, False)
        if not np.isfinite(d @ d):
            return x, 1, it, err, delta, f, fp, R, np.zeros(5)
        _matvec(A, d, dd)
        step_max = np.abs(dd).max()
        cap = 4.0 * max(delta.max(), eps)
        s = 1.0 if step_max <= cap else cap / step_max
        accepted = False
        for _ in range(60):
            for j in range(5):
                x_n[j] = x[j] + s * d[j]
            _matvec(A, x_n, delta_n)
            _spring(delta_n, k0, inv_eps, f_n, fp_n)
            phi_n, err_n = _residual(GT, c5, S, f_n, R_n, SR_n)
            if phi_n <= (1.0 - 2.0 * _ARMIJO * s) * phi:
                accepted = True
                break
            s *= 0.5
        if not accepted:
            if err <= 1e3 * floor:
                return x, 0, it, err, delta, f, fp, R, _sensitivity(A, GT, kappa_GA, fp)
            return x, 2, it, err, delta, f, fp, R, np.zeros(5)
        x = x_n.copy()
        delta[:] = delta_n
        f[:] = f_n
        fp[:] = fp_n
        R[:] = R_n
        SR[:] = SR_n
        phi, err = phi_n, err_n
        it += 1


def _regions_values(lam, Lf, Lm, rp, ra, mu, A, AT, BfT, AtA, BftA, Lr, X0, k0, eps, kappa,
                    rtol, max_iter, gradient):
    """The friction Newton's values of R contact regions in one call (contact_friction.
    FrictionAtState.values; Zhao-Qi-Wang 2024 Eqs. 59-71 and 65): per region the section load
    c = (f_t, f_b, m_s, m_t, m_b) from the multipliers (f = Lf lam[rp], m = Lm lam[ra]), the
    micro-motion Newton of :func:`newton` from X0[q] and g_q = -mu_q N_q, N_q = sum f_ij, with
    dg_q/dlam from the load sensitivity z (dN/dc = -z).  Returns (g (R,), dg (R, m), X (R, 5),
    status (R,)): status 0 solved; 1-3 the Newton's failures; 4 X0[q] compresses no spring (a
    cold start is needed); 5 a non-finite load.  The caller re-solves regions with status != 0
    on the reference path (which cold-starts or raises the typed error)."""
    R = mu.shape[0]
    m = lam.shape[0]
    na = Lm.shape[2]
    g = np.zeros(R)
    dg = np.zeros((R, m))
    X = np.zeros((R, 5))
    status = np.zeros(R, dtype=np.int64)
    for q in range(R):
        f_c = np.zeros(3)
        m_c = np.zeros(3)
        for i in range(3):
            for j in range(3):
                f_c[i] += Lf[q, i, j] * lam[rp[q, j]]
            for j in range(na):
                m_c[i] += Lm[q, i, j] * lam[ra[q, j]]
        c5 = np.array([f_c[1], f_c[2], m_c[0], m_c[1], m_c[2]])
        if not (np.all(np.isfinite(c5)) and np.isfinite(f_c[0]) and np.isfinite(mu[q])):
            status[q] = 5
            continue
        Lrq = Lr[q]
        S = np.array([1.0, 1.0, Lrq, Lrq, Lrq])
        load_scale = max(abs(c5[0]), abs(c5[1]), Lrq * abs(c5[2]), Lrq * abs(c5[3]),
                         Lrq * abs(c5[4]))
        if load_scale == 0.0:
            continue                    # no load: N = 0, g = 0, dg = 0, the rest position
        GT = AT[q] + mu[q] * BfT[q]
        kap = kappa * (AtA[q] + mu[q] * BftA[q])
        x = X0[q].copy()
        if not (np.all(np.isfinite(x)) and (A[q] @ x).max() > 0.0):
            status[q] = 4
            continue
        x, st, it, err, delta, f, fp, Rr, z = newton(A[q], GT, kap, c5, S, x, k0, eps,
                                                      rtol * load_scale, load_scale, max_iter)
        if st != 0:
            status[q] = st
            continue
        X[q] = x
        g[q] = -mu[q] * f.sum()
        if gradient and mu[q] != 0.0:   # dN/dc = -z
            for j in range(3):
                dg[q, rp[q, j]] = mu[q] * (z[0] * Lf[q, 1, j] + z[1] * Lf[q, 2, j])
            for j in range(na):
                dg[q, ra[q, j]] = mu[q] * (z[2] * Lm[q, 0, j] + z[3] * Lm[q, 1, j]
                                           + z[4] * Lm[q, 2, j])
    return g, dg, X, status


def _newton_step(lam0, L, g, r, dg, lam, tol):
    """One step of the friction-multiplier Newton (``Model._multiplier_newton``): the step of
    (I - (dg/dlam) L) step = -r from g; (g_new, lambda at g_new, True) where it changes lambda
    by less than ``tol`` relative to max(max |lambda|, 1) (converged: the step is taken),
    else (g_new, lam0 + L g_new, False)."""
    step = np.linalg.solve(np.eye(L.shape[1]) - np.dot(dg, L), -r)
    g_new = g + step
    dlam = np.dot(L, step)
    if np.max(np.abs(dlam)) < tol * max(np.max(np.abs(lam + dlam)), 1.0):
        return g_new, lam + dlam, True
    return g_new, lam0 + np.dot(L, g_new), False


def _multiplier_newton(lam0, L, Lf, Lm, rp, ra, mu, A, AT, BfT, AtA, BftA, Lr, X0, k0, eps,
                       kappa, rtol, max_iter_mm, tol, max_iter, g0):
    """The friction-multiplier Newton of ``sim_core.model.model.Model._multiplier_newton`` in one
    compiled call, for one multiplier force whose regions all take :func:`regions_values`:
    r(g) = g - g(lam0 + L g) = 0 by Newton with the matrix I - (dg/dlam) L, the fixed-point
    step where a Newton step does not reduce max |r|, stop when a step changes lambda by less
    than ``tol`` relative to max(max |lambda|, 1).  The same operations in the same order as
    the Python loop, from g = g0 (the caller's warm start).  Returns (g, X (the micro-motions
    to warm-start from), ok); ok False where a region needs the reference path (status != 0):
    the caller then runs the Python loop."""
    def values(lam, X):
        return regions_values(lam, Lf, Lm, rp, ra, mu, A, AT, BfT, AtA, BftA, Lr, X, k0, eps,
                              kappa, rtol, max_iter_mm, True)

    g = g0.copy()
    lam = lam0 + np.dot(L, g)
    gv, dg, X, st = values(lam, X0)
    if st.any():
        return g, X0, False
    r = g - gv
    for _ in range(max_iter):
        g_new, lam_new, done = newton_step(lam0, L, g, r, dg, lam, tol)
        if done:
            g = g_new
            break
        gv_new, dg_new, Xn, st = values(lam_new, X)
        if st.any():
            return g, X0, False
        X = Xn
        r_new = g_new - gv_new
        if np.max(np.abs(r_new)) > np.max(np.abs(r)):          # safeguard: fixed-point step
            g_new = gv.copy()
            lam_new = lam0 + np.dot(L, g_new)
            gv_new, dg_new, Xn, st = values(lam_new, X)
            if st.any():
                return g, X0, False
            X = Xn
            r_new = g_new - gv_new
        g, lam, gv, dg, r = g_new, lam_new, gv_new, dg_new, r_new
    return g, X, True


def _resultant_values(lam, Lf, rp, mu):
    """(g (k,), dg/dlambda (k, m)) of friction regions whose normal load is the transverse
    resultant (``friction_load = "resultant"``): f_c = Lf_r lambda[rp_r], N = |(f_t, f_b)|,
    g_r = -mu_r N, dg_r/dlambda[rp_r] = -mu_r (f_t, f_b) / N . Lf_r[1:3] (zero at N = 0) -- the
    resultant branch of ``FrictionAtState.values``.  Lf (k, 3, p), rp (k, p) multiplier rows."""
    k, p = rp.shape
    g = np.empty(k)
    dg = np.zeros((k, lam.shape[0]))
    for r in range(k):
        ft = 0.0
        fb = 0.0
        for j in range(p):
            ft += Lf[r, 1, j] * lam[rp[r, j]]
            fb += Lf[r, 2, j] * lam[rp[r, j]]
        N = np.hypot(ft, fb)
        g[r] = -mu[r] * N
        if N > 0.0:
            for j in range(p):
                dg[r, rp[r, j]] = -mu[r] * (ft * Lf[r, 1, j] + fb * Lf[r, 2, j]) / N
    return g, dg


def _resultant_newton(lam0, L, Lf, rp, mu, tol, max_iter, g0):
    """The friction-multiplier Newton of ``Model._multiplier_newton`` in one compiled call for
    regions with the resultant normal load (:func:`resultant_values`): the same iteration as
    :func:`multiplier_newton` (Newton on r(g) = g - g(lam0 + L g) with I - (dg/dlam) L, the
    fixed-point step where max |r| grows, stop when a step changes lambda by less than ``tol``
    relative to max(max |lambda|, 1)) from g0; returns g."""
    g = g0.copy()
    lam = lam0 + np.dot(L, g)
    gv, dg = resultant_values(lam, Lf, rp, mu)
    r = g - gv
    for _ in range(max_iter):
        g_new, lam_new, done = newton_step(lam0, L, g, r, dg, lam, tol)
        if done:
            g = g_new
            break
        gv_new, dg_new = resultant_values(lam_new, Lf, rp, mu)
        r_new = g_new - gv_new
        if np.max(np.abs(r_new)) > np.max(np.abs(r)):          # safeguard: fixed-point step
            g_new = gv.copy()
            lam_new = lam0 + np.dot(L, g_new)
            gv_new, dg_new = resultant_values(lam_new, Lf, rp, mu)
            r_new = g_new - gv_new
        g, lam, gv, dg, r = g_new, lam_new, gv_new, dg_new, r_new
    return g


if AVAILABLE:            # the callees first: numba resolves the globals when newton compiles
    _spring = numba.njit(cache=True, nogil=True)(_spring)
    _residual = numba.njit(cache=True, nogil=True)(_residual)
    _newton_matrix = numba.njit(cache=True, nogil=True)(_newton_matrix)
    _solve5 = numba.njit(cache=True, nogil=True)(_solve5)
    _matvec = numba.njit(cache=True, nogil=True)(_matvec)
    _sensitivity = numba.njit(cache=True, nogil=True)(_sensitivity)
    newton = numba.njit(cache=True, nogil=True)(_newton)
    regions_values = numba.njit(cache=True, nogil=True)(_regions_values)
    newton_step = numba.njit(cache=True, nogil=True)(_newton_step)
    multiplier_newton = numba.njit(cache=True, nogil=True)(_multiplier_newton)
    resultant_values = numba.njit(cache=True, nogil=True)(_resultant_values)
    resultant_newton = numba.njit(cache=True, nogil=True)(_resultant_newton)
