"""Compiled (numba) block elimination of the saddle-point system over diagonal blocks of M_r.

The same algorithm as :func:`sim_core.model.saddle_point.kkt_factor_blocks_reference` (the reference and the
fallback): Cholesky of each block A_i = M_r[b_i, b_i] = L_i L_i^T (``Model``: an element's
own coordinates), B_i = [M_r[b_i, r], C[:, b_i]^T], W_i = L_i^-1 B_i (one triangular solve;
A_i^-1 B_i would take two), the Schur complement S = D - sum_i W_i^T W_i of the border
(coordinates in no block and the multipliers; LU with partial pivoting), and with
``refine`` every solve followed by one step of iterative refinement on the whole system (its
residual from the blocks, their border columns and the border rows: the non-zero parts of M_r
only; ``Model.kkt_refine``, off by default: with W = L^-1 B the unrefined residual is at the
whole matrix LU's level).  A right-hand side that is zero on a block, e.g. a unit load on a
border coordinate, skips that block's forward solve.  As one compiled factorisation and one
compiled solve the ~30 LAPACK and numpy calls of the Python version, each with its call
overhead, become two.  LAPACK (dpotrf,
dtrtrs, dgetrf, dgetrs of scipy's ``cython_lapack``) is called through external symbols, as
:mod:`sim_core.physics._effects_numba` calls dsyrk, so the functions stay cacheable.
``tests/telescopic/test_assembly_paths.py`` checks both against the LU of the whole matrix.

Pipelined with the element worker (:func:`kkt_factor_pipelined`, ``Model.kkt_pipeline``): a
block reads only the rows of M_r its element owns, so it can be factored as soon as that
element is added -- while the worker computes the later elements.  At 8 sub-elements the
calling thread finishes its own share (constraint rows, friction maps, point effects) when
five of the six elements are done, factors their blocks while the sixth is computed, and is
left with one block, the border and its LU (benchmarks/telescopic_rhs_speed.py times it).
The border's Schur complement is then summed as (-sum_i W_i^T W_i) + D instead of D - sum_i
(round-off; the tests compare the two paths to 1e-12).
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import numba
from sim_core.model import _assembly_numba as assembly_compiled
from sim_core.model import workers as element_worker
from sim_core.physics.beam import _cardan_numba as cardan_compiled

AVAILABLE = False
if cardan_compiled.AVAILABLE:
    try:
        import llvmlite.binding as _llb
        from numba import types as _types
        from numba.extending import get_cython_function_address as _cython_address

        def _external(name: str, nargs: int):
            sym = f"sim_core_saddle_{name}"
            _llb.add_symbol(sym, _cython_address("scipy.linalg.cython_lapack", name))
            return _types.ExternalFunction(sym, _types.void(*([_types.voidptr] * nargs)))

        _dpotrf = _external("dpotrf", 5)     # uplo, n, a, lda, info
        _dgetrf = _external("dgetrf", 6)     # m, n, a, lda, ipiv, info
        _dgetrs = _external("dgetrs", 9)     # trans, n, nrhs, a, lda, ipiv, b, ldb, info
        _dtrtrs = _external("dtrtrs", 10)    # uplo, trans, diag, n, nrhs, a, lda, b, ldb, info
        AVAILABLE = True
    except Exception:        # pragma: no cover - scipy without cython_lapack
        AVAILABLE = False


def _i32(v):
    a = np.empty(1, dtype=np.int32)
    a[0] = v
    return a


def _chol(A, n):
    """In place: Cholesky factor of the symmetric leading n x n block of the C-ordered square
    A (LAPACK's 'L' of the same buffer, leading dimension A.shape[0]); returns info."""
    uplo = np.array([ord("L")], dtype=np.uint8)
    nn = _i32(n)
    lda = _i32(A.shape[0])
    info = _i32(0)
    _dpotrf(uplo.ctypes, nn.ctypes, A.ctypes, lda.ctypes, info.ctypes)
    return info[0]


def _tri_solve(Af, n, X, transpose):
    """In place: the first n columns of X (nrhs, ldx) C order = the Fortran (ldx, nrhs)
    right-hand sides, solved with the triangle of _chol's factor: L^-1 X, or L^-T X with
    ``transpose`` (A = L L^T; leading dimension Af.shape[0])."""
    nrhs = X.shape[0]
    uplo = np.array([ord("L")], dtype=np.uint8)
    trans = np.array([ord("T") if transpose else ord("N")], dtype=np.uint8)
    diag = np.array([ord("N")], dtype=np.uint8)
    nn = _i32(n)
    nr = _i32(nrhs)
    lda = _i32(Af.shape[0])
    ldx = _i32(X.shape[1])
    info = _i32(0)
    if nrhs > 0:
        _dtrtrs(uplo.ctypes, trans.ctypes, diag.ctypes, nn.ctypes, nr.ctypes, Af.ctypes,
                lda.ctypes, X.ctypes, ldx.ctypes, info.ctypes)


def _workspace(k, L, nr, m, n):
    """(facs, As, Bs, Ws (k, L, .), S (nb, nb) zero, Mrr (nr, n)) of one factorisation."""
    nb = nr + m
    return (np.zeros((k, L, L)), np.zeros((k, L, L)), np.zeros((k, L, nb)), np.zeros((k, L, nb)),
            np.zeros((nb, nb)), np.empty((nr, n)))


def _factor_block(q, Mr, C, blocks, lens, r, facs, As, Bs, Ws, S):
    """Block q: its Cholesky factor A_q = L_q L_q^T, B_q = [Mr[b_q, r], C[:, b_q]^T],
    W_q = L_q^-1 B_q, and S -= W_q^T W_q (= B_q^T A_q^-1 B_q: one triangular solve instead of
    A_q^-1 B_q's two); it reads only the rows b_q of Mr (complete once the element that owns
    them is added).  Returns LAPACK's info (0: positive definite)."""
    nr = r.shape[0]
    m = C.shape[0]
    nb = nr + m
    nq = lens[q]
    A = facs[q]
    for i in range(nq):
        for j in range(nq):
            A[i, j] = Mr[blocks[q, i], blocks[q, j]]
            As[q, i, j] = A[i, j]
    info = _chol(A, nq)
    if info != 0:
        return info
    for i in range(nq):
        bi = blocks[q, i]
        for j in range(nr):
            Bs[q, i, j] = Mr[bi, r[j]]
        for j in range(m):
            Bs[q, i, nr + j] = C[j, bi]
    # only the border columns that touch this block (a constraint row on other beams, a
    # border coordinate not coupled to it: a zero column of B, hence of W = L^-1 B)
    act = np.empty(nb, dtype=np.int64)
    na = 0
    for j in range(nb):
        for i in range(nq):
            if Bs[q, i, j] != 0.0:
                act[na] = j
                na += 1
                break
    L = facs.shape[1]
    Wt = np.zeros((na, L))                   # W^T in C order: the Fortran (L, na) block
    for jj in range(na):
        for i in range(nq):
            Wt[jj, i] = Bs[q, i, act[jj]]
    _tri_solve(A, nq, Wt, False)
    for jj in range(na):
        for i in range(nq):
            Ws[q, i, act[jj]] = Wt[jj, i]
    Wa = Wt[:, :nq].copy()
    P = np.dot(Wa, Wa.T)                     # W^T W on the active columns
    for a in range(na):
        for c in range(na):
            S[act[a], act[c]] -= P[a, c]
    return 0


def _factor_border(Mr, C, r, S, Mrr):
    """S += D (the border block [[Mr[r, r], C[:, r]^T], [C[:, r], 0]]), Mrr = Mr[r, :] (for
    the residual), and the LU of S: (ok, S's LU Fortran, pivots, C^T)."""
    nr = r.shape[0]
    m = C.shape[0]
    nb = nr + m
    n = Mr.shape[0]
    for i in range(nr):
        for j in range(n):
            Mrr[i, j] = Mr[r[i], j]
    for i in range(nr):
        for j in range(nr):
            S[i, j] += Mr[r[i], r[j]]
        for j in range(m):
            S[i, nr + j] += C[j, r[i]]
            S[nr + j, i] += C[j, r[i]]
    St = S.T.copy()                              # C order of S^T = Fortran order of S
    piv = np.zeros(nb, dtype=np.int32)
    nn = _i32(nb)
    info = _i32(0)
    _dgetrf(nn.ctypes, nn.ctypes, St.ctypes, nn.ctypes, piv.ctypes, info.ctypes)
    return info[0] == 0, St, piv, C.T.copy()


def _factor(Mr, C, blocks, lens, r):
    """(ok, factors (k, L, L), B (k, L, nb), W (k, L, nb), S's LU (nb, nb) Fortran, pivots,
    C^T, the blocks (for the residual), Mr's border rows); blocks padded to L (zero rows beyond
    a block's length)."""
    k, L = blocks.shape
    facs, As, Bs, Ws, S, Mrr = _workspace(k, L, r.shape[0], C.shape[0], Mr.shape[0])
    for q in range(k):
        if _factor_block(q, Mr, C, blocks, lens, r, facs, As, Bs, Ws, S) != 0:
            return False, facs, Bs, Ws, S, np.zeros(S.shape[0], dtype=np.int32), C.T.copy(), \
                As, Mrr
    ok, St, piv, CT = _factor_border(Mr, C, r, S, Mrr)
    return ok, facs, Bs, Ws, St, piv, CT, As, Mrr


def _scatter_factor(ctl, start, spins, Mr, Fr, red, sg, IDX, Ms, Fs, block_of, C, blocks,
                    lens, r, facs, As, Bs, Ws, S, failed):
    """Pipelined with the element worker: for elements e = start, ... as the worker publishes
    them (``element_worker``'s progress word in ctl), add (Me, Fe) into (Mr, Fr) and factor the
    block e owns (:func:`_factor_block`), so the blocks are factored while the worker computes
    the later elements.  Returns the next element (E when all are in; less where ``spins``
    rounds passed without it: the caller checks the worker and calls again).  failed[0] = 1
    where a block is not positive definite (the rest is still added, for the caller's
    fallback on the whole matrix)."""
    E = IDX.shape[0]
    for e in range(start, E):
        if not element_worker._wait_progress(ctl, e, spins):
            return e
        assembly_compiled._scatter(Mr, Fr, red, sg, IDX[e], Ms[e], Fs[e], True)
        q = block_of[e]
        if q >= 0 and failed[0] == 0:
            if _factor_block(q, Mr, C, blocks, lens, r, facs, As, Bs, Ws, S) != 0:
                failed[0] = 1
    return E


def _once(facs, Ws, St, piv, blocks, lens, r, F, c):
    """One elimination solve: (z (n, nrhs), mu (m, nrhs)) of [[Mr, C^T], [C, 0]] [z; mu] =
    [F; c]: per block v = L^-1 F_b, the border's g = F_r - sum W^T v, its LU solve w, and
    z_b = L^-T (v - W w) (= A^-1 (F_b - B w))."""
    k, L = blocks.shape
    n, nrhs = F.shape
    nr = r.shape[0]
    m = c.shape[0]
    nb = nr + m
    gt = np.empty((nrhs, nb))                    # g^T: Fortran (nb, nrhs)
    for j in range(nrhs):
        for i in range(nr):
            gt[j, i] = F[r[i], j]
        for i in range(m):
            gt[j, nr + i] = c[i, j]
    us = np.zeros((k, nrhs, L))
    for q in range(k):
        nq = lens[q]
        ut = us[q]
        nonzero = False
        for j in range(nrhs):
            for i in range(nq):
                ut[j, i] = F[blocks[q, i], j]
                if ut[j, i] != 0.0:
                    nonzero = True
        if not nonzero:                          # v = L^-1 0 = 0 (e.g. a unit load on the
            continue                             # border: the friction Newton's columns)
        _tri_solve(facs[q], nq, ut, False)
        gt -= np.dot(ut, Ws[q])                  # (W^T v)^T = v^T W; zero padding
    trans = np.array([ord("N")], dtype=np.uint8)
    nn = _i32(nb)
    nr_ = _i32(nrhs)
    info = _i32(0)
    _dgetrs(trans.ctypes, nn.ctypes, nr_.ctypes, St.ctypes, nn.ctypes, piv.ctypes, gt.ctypes,
            nn.ctypes, info.ctypes)
    z = np.empty((n, nrhs))
    for j in range(nrhs):
        for i in range(nr):
            z[r[i], j] = gt[j, i]
    w = gt.T.copy()
    for q in range(k):
        nq = lens[q]
        Ww = np.dot(Ws[q], w)                    # (L, nrhs)
        ut = us[q]
        for i in range(nq):
            for j in range(nrhs):
                ut[j, i] -= Ww[i, j]
        _tri_solve(facs[q], nq, ut, True)
        for i in range(nq):
            for j in range(nrhs):
                z[blocks[q, i], j] = ut[j, i]
    mu = np.empty((m, nrhs))
    for j in range(nrhs):
        for i in range(m):
            mu[i, j] = gt[j, nr + i]
    return z, mu


def _times_Mr(As, Bs, Mrr, blocks, lens, r, z):
    """Mr z from the blocks, their border columns (Bs[:, :, :nr]) and the border rows Mrr:
    the products of the non-zero parts of Mr only (block-diagonal plus border)."""
    k = blocks.shape[0]
    n, nrhs = z.shape
    nr = r.shape[0]
    out = np.dot(Mrr, z)                         # the border rows
    y = np.zeros((n, nrhs))
    for i in range(nr):
        for j in range(nrhs):
            y[r[i], j] = out[i, j]
    zr = np.empty((nr, nrhs))
    for i in range(nr):
        for j in range(nrhs):
            zr[i, j] = z[r[i], j]
    for q in range(k):
        nq = lens[q]
        zq = np.empty((nq, nrhs))
        for i in range(nq):
            for j in range(nrhs):
                zq[i, j] = z[blocks[q, i], j]
        t = np.dot(np.ascontiguousarray(As[q, :nq, :nq]), zq)
        if nr > 0:
            t += np.dot(np.ascontiguousarray(Bs[q, :nq, :nr]), zr)
        for i in range(nq):
            for j in range(nrhs):
                y[blocks[q, i], j] = t[i, j]
    return y


def _solve(C, CT, facs, Bs, Ws, St, piv, blocks, lens, r, F, c, refine, As, Mrr):
    z, mu = _once(facs, Ws, St, piv, blocks, lens, r, F, c)
    if refine:
        rF = F - _times_Mr(As, Bs, Mrr, blocks, lens, r, z) - np.dot(CT, mu)
        rc = c - np.dot(C, z)
        dz, dmu = _once(facs, Ws, St, piv, blocks, lens, r, rF, rc)
        z = z + dz
        mu = mu + dmu
    return z, mu


if AVAILABLE:
    _jit = numba.njit(cache=True, nogil=True)
    _i32 = _jit(_i32)
    _chol = _jit(_chol)
    _tri_solve = _jit(_tri_solve)
    _workspace = _jit(_workspace)
    _factor_block = _jit(_factor_block)
    _factor_border = _jit(_factor_border)
    _factor_compiled = _jit(_factor)
    _once = _jit(_once)
    _times_Mr = _jit(_times_Mr)
    _solve_compiled = _jit(_solve)
PIPELINE = AVAILABLE and element_worker.AVAILABLE and assembly_compiled.AVAILABLE
if PIPELINE:
    _scatter_factor = _jit(_scatter_factor)


_LAYOUT: list = []          # [(n, the blocks list, its arrays, layout)]: the last one used


def _layout(n, blocks):
    """(padded block table (k, L), block lengths, border coordinates) of ``blocks``; the last
    layout is kept, keyed on the blocks list and its arrays themselves (a model passes the same
    list at every call)."""
    if _LAYOUT:
        n0, ref, arrays, out = _LAYOUT[0]
        if n0 == n and ref is blocks and len(arrays) == len(blocks) \
                and all(a is b for a, b in zip(arrays, blocks)):
            return out
    k = len(blocks)
    lens = np.array([len(b) for b in blocks], dtype=np.int64)
    L = int(lens.max()) if k else 0
    B = np.zeros((k, L), dtype=np.int64)
    mask = np.ones(n, dtype=bool)
    for q, b in enumerate(blocks):
        B[q, :len(b)] = b
        mask[b] = False
    out = (B, lens, np.flatnonzero(mask).astype(np.int64))
    _LAYOUT[:] = [(n, blocks, list(blocks), out)]
    return out


def kkt_factor_blocks(Mr, C, blocks, refine: bool = True):
    """solve(Fr, c_rhs) -> (z_ddot, lambda) as :func:`sim_core.model.saddle_point.kkt_factor_blocks_reference`
    (vectors or matrices of right-hand sides), compiled; None where a block is not positive
    definite or the border's LU is singular (the caller falls back to the whole matrix's LU)."""
    n = Mr.shape[0]
    B, lens, r = _layout(n, blocks)
    Mr = np.ascontiguousarray(Mr, dtype=float)
    C = np.ascontiguousarray(C, dtype=float)
    ok, facs, Bs, Ws, St, piv, CT, As, Mrr = _factor_compiled(Mr, C, B, lens, r)
    if not ok:
        return None
    return _solver(C, CT, facs, Bs, Ws, St, piv, B, lens, r, refine, As, Mrr)


def _solver(C, CT, facs, Bs, Ws, St, piv, B, lens, r, refine, As, Mrr):
    n, m = Mrr.shape[1], C.shape[0]            # Mrr: Mr's border rows (nr, n)

    def solve(Fr, c_rhs):
        F = np.asarray(Fr, dtype=float)
        c = np.asarray(c_rhs, dtype=float)
        vec = F.ndim == 1
        F2 = np.ascontiguousarray(F.reshape(n, -1))
        c2 = np.ascontiguousarray(c.reshape(m, -1))
        z, mu = _solve_compiled(C, CT, facs, Bs, Ws, St, piv, B, lens, r, F2, c2, refine, As,
                                Mrr)
        return (z[:, 0], -mu[:, 0]) if vec else (z, -mu)
    return solve


def kkt_factor_pipelined(Mr, Fr, C, blocks, worker, red, sg, IDX, block_of,
                         refine: bool = True):
    """Add the element batch that ``worker`` (:class:`sim_core.model.workers.
    ElementWorker`) is computing into (Mr, Fr) (reduced map red, sg; element coordinates IDX)
    and factor the saddle-point matrix as :func:`kkt_factor_blocks`, each block as soon as the
    element that owns it (``block_of[e]``: its block, or -1) is published, while the worker
    computes the next ones.  Returns (solve or None, (Ms, Fs)): None where a block is not
    positive definite or the border's LU is singular -- (Mr, Fr) are complete all the same, for
    the whole matrix's LU."""
    n = Mr.shape[0]
    B, lens, r = _layout(n, blocks)
    C = np.ascontiguousarray(C, dtype=float)
    k, L = B.shape
    facs, As, Bs, Ws, S, Mrr = _workspace(k, L, r.shape[0], C.shape[0], n)
    failed = np.zeros(1, dtype=np.int64)
    e, E = 0, IDX.shape[0]
    while e < E:
        e = _scatter_factor(worker.ctl, e, worker.wait_spins, Mr, Fr, red, sg, IDX, worker.Ms,
                            worker.Fs, block_of, C, B, lens, r, facs, As, Bs, Ws, S, failed)
        if e < E:
            worker.wait_element(e)          # checks the worker; raises where it failed
    out = worker.result()                   # the request is complete: collect it
    if failed[0]:
        return None, out
    ok, St, piv, CT = _factor_border(Mr, C, r, S, Mrr)
    if not ok:
        return None, out
    return _solver(C, CT, facs, Bs, Ws, St, piv, B, lens, r, refine, As, Mrr), out
