"""Quintic spline interpolation (Zhao-Qi-Wang 2024 Eqs. 6-15): exactness and continuity."""

import numpy as np
import pytest

from sim_core.physics.beam.spline import spline_basis, xi_powers


def _eval(n, coeffs, s1, sn, s):
    """r(s) of a scalar field from scaled-free coefficients [r_1..r_n, r'_1, r'_n, r''_1, r''_n]."""
    b = spline_basis(n)
    ell = (sn - s1) / (n - 1)
    sub = np.clip(np.floor((s - s1) / ell).astype(int), 0, n - 2)
    xi = (s - s1) / ell - sub
    out = []
    for k in range(5):
        phi = np.einsum("gm,gma->ga", xi_powers(xi, k, 5), b.pos_coeffs[sub]) * ell ** b.pos_powers
        out.append(phi @ coeffs / ell ** k)
    return out


@pytest.mark.parametrize("n", [2, 3, 5, 9])
def test_quintic_polynomials_reproduced_exactly(n, rng):
    c = rng.normal(size=6)
    p = np.polynomial.Polynomial(c)
    s1, sn = 0.7, 3.1
    nodes = np.linspace(s1, sn, n)
    coeffs = np.concatenate([p(nodes), [p.deriv()(s1), p.deriv()(sn), p.deriv(2)(s1), p.deriv(2)(sn)]])
    s = np.linspace(s1, sn, 57)
    vals = _eval(n, coeffs, s1, sn, s)
    for k in range(4):
        np.testing.assert_allclose(vals[k], p.deriv(k)(s), rtol=1e-10, atol=1e-10 * np.max(np.abs(p.deriv(k)(s))))


def test_spline_is_C4_at_inner_nodes(rng):
    n, s1, sn = 7, 0.0, 2.0
    coeffs = rng.normal(size=n + 4)
    ell = (sn - s1) / (n - 1)
    inner = s1 + ell * np.arange(1, n - 1)
    d = 1e-9
    left = _eval(n, coeffs, s1, sn, inner - d)
    right = _eval(n, coeffs, s1, sn, inner + d)
    for k in range(5):   # r, r', r'', r''' and r'''' continuous (fifth-order spline, Eq. 12-13)
        scale = 1 + np.max(np.abs(left[k]))
        np.testing.assert_allclose(left[k], right[k], atol=1e-6 * scale)


def test_interpolation_error_falls_at_sixth_order():
    f = np.sin
    errs = []
    for n in (3, 5, 9, 17):
        s1, sn = 0.0, 3.0
        nodes = np.linspace(s1, sn, n)
        coeffs = np.concatenate([f(nodes), [np.cos(s1), np.cos(sn), -np.sin(s1), -np.sin(sn)]])
        s = np.linspace(s1, sn, 401)
        errs.append(np.max(np.abs(_eval(n, coeffs, s1, sn, s)[0] - f(s))))
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    # quintic spline: O(l^6) interpolation error
    assert np.all(rates[1:] > 5.5), rates
