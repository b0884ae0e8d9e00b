"""Quintic spline interpolation of the moving-node beam element.

Source: Zhao, Qi, Wang (2024), Section 4, Eqs. 6-15 and Appendix A.

A spline element on [s_1, s_n] has n equally spaced nodes (n - 1 sub-elements of length
l = (s_n - s_1)/(n - 1), Eq. 5).  Its position coefficients are the node positions r_1..r_n and
the end derivatives r'_1, r'_n, r''_1, r''_n.  Inside each sub-element the centroid line is the
quintic Hermite interpolation of Eq. 6 in the element coordinate xi in [0, 1]; the derivatives
r'_k, r''_k at the inner nodes are *not* coordinates: they follow from the fifth-order spline
conditions (continuity of r''' and r'''' at every inner node, Eqs. 12-15).

We work with the scaled derivatives d = l r', e = l^2 r''.  In these variables the spline
conditions do not depend on l, so the map from (r_1..r_n, d_1, d_n, e_1, e_n) to the local
Hermite data of every sub-element is a constant matrix, computed once per n and cached (this
replaces the tridiagonal matrices A, B, C of Appendix A).  The physical coefficients are then
recovered with the powers p_a of l: r(xi) = sum_a phi_a(xi) l**p_a q_a with p_a = 0 for node
positions, 1 for end slopes and 2 for end curvatures.

Torsion (Eq. 19) uses cubic Hermite interpolation of the nodal torsion angles gamma_k and their
arc-length derivatives gamma'_k at every node (both are coordinates).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

# Monomial coefficients (rows: xi**0 .. xi**5) of the quintic Hermite basis on [0, 1] for the
# local data [r_i, r_i+1, d_i, d_i+1, e_i, e_i+1] (Eq. 7 written in scaled derivatives).
_QUINTIC = np.array([
    # r_i   r_i+1  d_i   d_i+1  e_i    e_i+1
    [1.0,   0.0,   0.0,  0.0,   0.0,   0.0],   # xi^0
    [0.0,   0.0,   1.0,  0.0,   0.0,   0.0],   # xi^1
    [0.0,   0.0,   0.0,  0.0,   0.5,   0.0],   # xi^2
    [-10.0, 10.0, -6.0, -4.0,  -1.5,   0.5],   # xi^3
    [15.0, -15.0,  8.0,  7.0,   1.5,  -1.0],   # xi^4
    [-6.0,   6.0, -3.0, -3.0,  -0.5,   0.5],   # xi^5
])

# Cubic Hermite basis for torsion (Eq. 20) on local data [g_i, g_i+1, l*g'_i, l*g'_i+1].
_CUBIC = np.array([
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [-3.0, 3.0, -2.0, -1.0],
    [2.0, -2.0, 1.0, 1.0],
])


def monomial_derivative(coeffs: np.ndarray, order: int) -> np.ndarray:
    """Monomial coefficients (rows = powers of xi) of the ``order``-th xi-derivative."""
    c = np.array(coeffs, dtype=float)
    for _ in range(order):
        deg = c.shape[0]
        c = c[1:] * np.arange(1, deg)[:, None]
        c = np.vstack([c, np.zeros((1, c.shape[1]))])
    return c


@dataclass(frozen=True)
class SplineBasis:
    """Constant interpolation matrices of a spline element with ``n_nodes`` nodes.

    Attributes
    ----------
    n_nodes : int
        Number of nodes n (n - 1 sub-elements).
    pos_coeffs : ndarray (n_sub, 6, n + 4)
        Monomial coefficients in xi of the position basis of every sub-element with respect to
        the scaled coefficients [r_1..r_n, d_1, d_n, e_1, e_n].
    pos_powers : ndarray (n + 4,)
        Powers of the sub-element length l that turn scaled into physical coefficients.
    tor_coeffs : ndarray (n_sub, 4, 2 n)
        Monomial coefficients of the torsion basis w.r.t. [g_1..g_n, l g'_1 .. l g'_n].
    tor_powers : ndarray (2 n,)
    """

    n_nodes: int
    pos_coeffs: np.ndarray
    pos_powers: np.ndarray
    tor_coeffs: np.ndarray
    tor_powers: np.ndarray

    @property
    def n_sub(self) -> int:
        return self.n_nodes - 1


def _spline_local_maps(n: int) -> np.ndarray:
    """Local Hermite data of every sub-element as a linear map of the n + 4 known coefficients.

    Returns E with shape (n - 1, 6, n + 4).  The inner-node scaled derivatives d_k, e_k are
    eliminated with the fifth-order spline conditions (Eqs. 12-15): r''' and r'''' continuous
    at every inner node.
    """
    n_known = n + 4
    n_unknown = 2 * (n - 2)
    n_all = n_known + n_unknown

    # index of each scaled quantity in the "all" vector [known; unknown]
    def d_idx(k: int) -> int:
        if k == 0:
            return n
        if k == n - 1:
            return n + 1
        return n_known + (k - 1)

    def e_idx(k: int) -> int:
        if k == 0:
            return n + 2
        if k == n - 1:
            return n + 3
        return n_known + (n - 2) + (k - 1)

    local_all = np.zeros((n - 1, 6, n_all))
    for i in range(n - 1):
        for col, idx in enumerate((i, i + 1, d_idx(i), d_idx(i + 1), e_idx(i), e_idx(i + 1))):
            local_all[i, col, idx] = 1.0
    if n_unknown == 0:
        return local_all[:, :, :n_known]

    d3 = monomial_derivative(_QUINTIC, 3)
    d4 = monomial_derivative(_QUINTIC, 4)
    ones = np.ones(6)
    zero = np.zeros(6)
    zero[0] = 1.0
    rows = []
    for k in range(1, n - 1):  # inner node k between sub-elements k-1 and k
        for dmat in (d3, d4):
            left = ones @ dmat @ local_all[k - 1]   # value at xi = 1 of sub-element k - 1
            right = zero @ dmat @ local_all[k]      # value at xi = 0 of sub-element k
            rows.append(left - right)
    cond = np.array(rows)
    a_k = cond[:, :n_known]
    a_u = cond[:, n_known:]
    unknown_of_known = -np.linalg.solve(a_u, a_k)          # (n_unknown, n_known)
    full = np.vstack([np.eye(n_known), unknown_of_known])  # (n_all, n_known)
    return local_all @ full


@lru_cache(maxsize=None)
def spline_basis(n_nodes: int) -> SplineBasis:
    """Cached :class:`SplineBasis` for an element with ``n_nodes`` >= 2 nodes."""
    if n_nodes < 2:
        raise ValueError(f"n_nodes = {n_nodes}: a spline element needs at least 2 nodes")
    n = n_nodes
    local = _spline_local_maps(n)                         # (n-1, 6, n+4)
    pos_coeffs = np.einsum("ml,ilk->imk", _QUINTIC, local)
    pos_powers = np.array([0] * n + [1, 1, 2, 2], dtype=float)

    tor = np.zeros((n - 1, 4, 2 * n))
    for i in range(n - 1):
        sel = np.zeros((4, 2 * n))
        sel[0, i] = sel[1, i + 1] = 1.0
        sel[2, n + i] = sel[3, n + i + 1] = 1.0
        tor[i] = _CUBIC @ sel
    tor_powers = np.array([0] * n + [1] * n, dtype=float)
    for arr in (pos_coeffs, pos_powers, tor, tor_powers):
        arr.setflags(write=False)
    return SplineBasis(n, pos_coeffs, pos_powers, tor, tor_powers)


def xi_powers(xi: np.ndarray, order: int, degree: int) -> np.ndarray:
    """Rows [d^order/dxi^order xi^m for m = 0..degree] for every xi (complex-safe).

    Returns shape (len(xi), degree + 1).
    """
    xi = np.asarray(xi)
    out = np.zeros(xi.shape + (degree + 1,), dtype=np.result_type(xi, float))
    for m in range(order, degree + 1):
        fac = 1.0
        for j in range(order):
            fac *= m - j
        out[..., m] = fac * xi ** (m - order)
    return out
