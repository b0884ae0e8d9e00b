"""Compiled (numba) Newton iteration of the micro-motion solve (paper Eqs. 59-71).

The same damped Newton method as the Python loop of
:func:`sim_core.contact.sliding_block_contact.solve_micro_motion` (stiffness floor kappa in the
Newton matrix only, the compression change capped at 4 max(delta_max, eps), Armijo
back-tracking on |S R|^2, convergence on max |S R| <= tol or the round-off floor of the sums),
written as one compiled loop: the friction Newton solves the four regions' micro-motions a few
times per right-hand side, and each Python iteration was ~20 small numpy calls.  The Python
loop stays as the reference and the fallback without numba;
``tests/contact/test_sliding_block_contact.py`` checks that both give the same solution.

Returns (x, status, iterations, max |S R|, delta, f, f', R, z) with z = J^-T A^T f' the load
sensitivity at the solution (zeros unless converged).  Status codes: 0 converged, 1 singular Newton matrix, 2 line search failed, 3 no convergence in
max_iter iterations (the caller raises ContactSolveError with the reason).
"""

from __future__ import annotations

import numpy as np

try:
    import numba
except ImportError:          # pragma: no cover - numba is a dependency; the Python loop remains
    numba = None

AVAILABLE = numba is not None
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
    """J = G^T diag(f') A + kappa (A^T A + mu Bf^T A), in place (the solver's Newton matrix)."""
    n = A.shape[0]
    for r in range(5):
        for c in range(5):
            acc = kappa_GA[r, c]
            for i in range(n):
                acc += GT[r, i] * fp[i] * A[i, c]
            Jm[r, c] = acc


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
    return np.linalg.solve(Jm.T.copy(), rhs)


def _newton(A, GT, kappa_GA, c5, S, x, k0, eps, tol, load_scale, max_iter):
    n = A.shape[0]
    inv_eps = 1.0 / eps
    delta = A @ x
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
        try:
            d = np.linalg.solve(Jm, -R)
        except Exception:  # noqa: BLE001 - numba raises a generic LinAlgError here
            return x, 1, it, err, delta, f, fp, R, np.zeros(5)
        if not np.isfinite(d @ d):
            return x, 1, it, err, delta, f, fp, R, np.zeros(5)
        dd = A @ d
        step_max = np.abs(dd).max()
        cap = 4.0 * max(delta.max(), eps)
        s = 1.0 if step_max <= cap else cap / step_max
        accepted = False
        for _ in range(60):
            for j in range(5):
                x_n[j] = x[j] + s * d[j]
            delta_n = A @ x_n
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
        delta = delta_n
        f[:] = f_n
        fp[:] = fp_n
        R[:] = R_n
        SR[:] = SR_n
        phi, err = phi_n, err_n
        it += 1


if AVAILABLE:            # the callees first: numba resolves the globals when newton compiles
    _spring = numba.njit(cache=True, nogil=True)(_spring)
    _residual = numba.njit(cache=True, nogil=True)(_residual)
    _newton_matrix = numba.njit(cache=True, nogil=True)(_newton_matrix)
    _sensitivity = numba.njit(cache=True, nogil=True)(_sensitivity)
    newton = numba.njit(cache=True, nogil=True)(_newton)
