"""The saddle-point system of the constrained accelerations,

    [[M_r, C^T], [C, 0]] [z_ddot; -lambda] = [F_r; c],

factored once per right-hand side: by block elimination over the elements' own coordinates
(compiled in :mod:`sim_core.model._saddle_point_numba`; :func:`kkt_factor_blocks_reference` is
its numpy reference) where M_r is block-diagonal in them, else by the LU of the whole matrix.
SIMULTECH 2020 Eq. 8 (the index-1 form with Baumgarte's terms in c).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from sim_core.model import _saddle_point_numba

Vec = np.ndarray


def kkt_factor(Mr: Vec, C: Vec, blocks=None, refine: bool = True):
    """Factor the saddle-point matrix once; returns solve(Fr, c_rhs) -> (z_ddot, lambda)
    (Fr, c_rhs: vectors or matrices of right-hand sides).

    ``blocks``: index arrays of diagonal blocks of Mr that the caller guarantees uncoupled
    (Mr[b_i, b_j] = 0 for i != j; couplings to the coordinates outside every block are allowed),
    e.g. the beams of ``Model`` (``Model._reduced_mass_force_at``).  Then the system is solved
    by block elimination (:func:`kkt_factor_blocks_reference`, compiled in
    :mod:`sim_core.model._saddle_point_numba` where numba is installed); where a block is not
    positive definite, by the LU of the whole matrix (the reference).  ``refine``: the
    compiled elimination's step of iterative refinement (the numpy one always refines)."""
    if blocks is not None:
        solve = (_saddle_point_numba.kkt_factor_blocks(Mr, C, blocks, refine) if _saddle_point_numba.AVAILABLE
                 else kkt_factor_blocks_reference(Mr, C, blocks))
        if solve is not None:
            return solve
    n, m = Mr.shape[0], C.shape[0]
    K = np.zeros((n + m, n + m))
    K[:n, :n] = Mr
    K[:n, n:] = C.T
    K[n:, :n] = C
    lu = sla.lu_factor(K)

    def solve(Fr, c_rhs):
        sol = sla.lu_solve(lu, np.concatenate([Fr, c_rhs]))
        return sol[:n], -sol[n:]
    return solve


def kkt_factor_blocks_reference(Mr: Vec, C: Vec, blocks, refine: bool = True):
    """Block elimination of  [[Mr, C^T], [C, 0]] [z; mu] = [F; c]  over SPD diagonal blocks.

    Unknowns ordered (x_1 .. x_k | w) with x_i = z[b_i] and the border w = (z[r], mu), r the
    coordinates in no block (e.g. the massless contact coordinates).  With A_i = Mr[b_i, b_i]
    (Cholesky), B_i = [Mr[b_i, r], C[:, b_i]^T] and the border block D = [[Mr[r, r], C[:, r]^T],
    [C[:, r], 0]], the Schur complement  S = D - sum_i B_i^T A_i^-1 B_i  (LU with pivoting, the
    size of the border: ~33 for the telescopic scene against 344 for the whole matrix) gives
    w = S^-1 (g - sum_i B_i^T A_i^-1 f_i),  x_i = A_i^-1 (f_i - B_i w).  The elimination is not
    backward stable for ill-conditioned A_i (the filter's mass (h^2/6) K makes cond ~1e11), so
    every solve takes one step of iterative refinement on the whole system, which brings the
    residual to that of the whole-matrix LU (tests/beam/test_nonlinear_constraints.py;
    ``refine=False`` skips it, for that test).
    Only the columns of B_i that are not zero (the constraints that act on body i) enter the
    products.  Returns None where a block is not positive definite."""
    from scipy.linalg import lapack
    n, m = Mr.shape[0], C.shape[0]
    mask = np.ones(n, dtype=bool)
    for b in blocks:
        mask[b] = False
    r = np.flatnonzero(mask)
    facs, Bs, Ys = [], [], []
    nb = len(r) + m
    S = np.zeros((nb, nb))
    S[:len(r), :len(r)] = Mr[np.ix_(r, r)]
    S[:len(r), len(r):] = C[:, r].T
    S[len(r):, :len(r)] = C[:, r]
    for b in blocks:
        c, info = lapack.dpotrf(Mr[np.ix_(b, b)], lower=1, clean=0, overwrite_a=1)
        if info != 0:
            return None                 # not positive definite (a massless body)
        B = np.hstack([Mr[np.ix_(b, r)], C[:, b].T])
        cols = np.flatnonzero(np.any(B != 0.0, axis=0))
        B = B[:, cols]
        Y, info = lapack.dpotrs(c, B, lower=1)
        facs.append(c)
        Bs.append((cols, B))
        Ys.append(Y)
        S[np.ix_(cols, cols)] -= B.T @ Y
    lu, piv, info = lapack.dgetrf(S)
    if info != 0:
        return None

    def once(F, c_rhs):
        g = np.concatenate([F[r], c_rhs])
        us = []
        for b, c, (cols, B) in zip(blocks, facs, Bs):
            u, _ = lapack.dpotrs(c, F[b], lower=1)
            us.append(u)
            g[cols] -= B.T @ u
        w, _ = lapack.dgetrs(lu, piv, g)
        z = np.empty_like(F)
        z[r] = w[:len(r)]
        for b, u, (cols, _), Y in zip(blocks, us, Bs, Ys):
            z[b] = u - Y @ w[cols]
        return z, w[len(r):]

    def solve(Fr, c_rhs):
        Fr = np.asarray(Fr, dtype=float)
        c_rhs = np.asarray(c_rhs, dtype=float)
        z, mu = once(Fr, c_rhs)
        if refine:
            dz, dmu = once(Fr - Mr @ z - C.T @ mu, c_rhs - C @ z)
            z, mu = z + dz, mu + dmu
        return z, -mu
    return solve


def kkt_accelerations(Mr: Vec, Fr: Vec, C: Vec, c_rhs: Vec):
    """Solve the saddle-point system; returns (z_ddot, lambda) with M z_ddot = F + C^T lambda."""
    n, m = Mr.shape[0], C.shape[0]
    K = np.zeros((n + m, n + m))
    K[:n, :n] = Mr
    K[:n, n:] = C.T
    K[n:, :n] = C
    sol = np.linalg.solve(K, np.concatenate([Fr, c_rhs]))
    return sol[:n], -sol[n:]
