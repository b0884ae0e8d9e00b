"""Scatter-add of local mass matrices and force vectors into global or reduced arrays.

Every element, point load and point effect contributes a small dense block (Me, Fe) on a few
global coordinates ``idx``.  The reduced system of a model whose null-space basis P only selects
and signs coordinates (the usual boundary conditions that fix single coordinates, see
``model._selection``) is  M_r = P^T M P,  F_r = P^T F:  entry (a, b) of a block goes to
M_r[red[a], red[b]] with the factor sg[a] sg[b], and nothing where a coordinate is eliminated
(red = -1).  The full assembly is the same scatter with red = 0..N-1, sg = 1.

Adding the blocks straight into M_r avoids forming the N x N matrix and taking its sub-matrix,
which at the paper's discretisation would cost about as much as the element kernels
themselves.  The compiled loop is used for real blocks; complex-step states take the numpy
version, which is also the reference (``tests/beam/test_nonlinear_constraints.py``).
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba


def _scatter(M, F, red, sg, idx, Me, Fe, with_mass):
    k = idx.shape[0]
    for a in range(k):
        ra = red[idx[a]]
        if ra < 0:
            continue
        sa = sg[idx[a]]
        F[ra] += sa * Fe[a]
        if with_mass:
            for b in range(k):
                rb = red[idx[b]]
                if rb >= 0:
                    M[ra, rb] += sa * sg[idx[b]] * Me[a, b]


def _scatter_blocks(M, F, red, sg, IDX, Ms, Fs):
    for e in range(IDX.shape[0]):
        _scatter(M, F, red, sg, IDX[e], Ms[e], Fs[e], True)


if AVAILABLE:
    _scatter_compiled = numba.njit(cache=True, nogil=True)(_scatter)
    _scatter = _scatter_compiled                # the callee of _scatter_blocks
    _scatter_blocks_compiled = numba.njit(cache=True, nogil=True)(
        _scatter_blocks)


def scatter_add(M, F, red, sg, idx, Me, Fe) -> None:
    """M[red[a], red[b]] += sg[a] sg[b] Me[a, b] and F[red[a]] += sg[a] Fe[a] over the block's
    coordinates a, b = idx[...] that are kept (red >= 0); M or Me None: the force only.
    ``idx`` must not repeat a coordinate."""
    with_mass = M is not None and Me is not None
    if (AVAILABLE and F.dtype == np.float64 and Fe.dtype == np.float64
            and (not with_mass or (M.dtype == np.float64 and Me.dtype == np.float64))):
        _scatter_compiled(M if with_mass else _NO_MASS, F, red, sg, idx,
                          Me if with_mass else _NO_MASS, Fe, with_mass)
        return
    r = red[idx]
    keep = r >= 0
    r = r[keep]
    s = sg[idx][keep]
    F[r] += s * Fe[keep]
    if with_mass:
        M[np.ix_(r, r)] += np.outer(s, s) * Me[np.ix_(keep, keep)]


_NO_MASS = np.zeros((0, 0))


def scatter_add_blocks(M, F, red, sg, IDX, Ms, Fs) -> bool:
    """scatter_add of E blocks (IDX (E, k), Ms (E, k, k), Fs (E, k)) in one compiled call;
    False (nothing added) where that does not apply (no numba, not float64 arrays)."""
    if not (AVAILABLE and isinstance(Ms, np.ndarray) and isinstance(Fs, np.ndarray)
            and M is not None and M.dtype == np.float64 and F.dtype == np.float64
            and Ms.dtype == np.float64 and Fs.dtype == np.float64):
        return False
    _scatter_blocks_compiled(M, F, red, sg, IDX, Ms, Fs)
    return True
