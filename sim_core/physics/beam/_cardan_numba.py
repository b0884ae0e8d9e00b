"""Compiled (numba) loop of :func:`sim_core.physics.beam.cardan.section_state` over the points.

The numpy version in :mod:`sim_core.physics.beam.cardan` is the reference (and the fallback where numba
is not installed); this is the same algebra written point by point, so that one element's 40
quadrature points cost one compiled loop instead of ~100 small numpy operations (the section
state is a sizeable share of a right-hand side: ``benchmarks/profile_rhs.py``).
Source of the formulas: Zhao, Qi, Wang (2024), Section 5, Eqs. 24-33 (see ``cardan.py``).
Compiled once per dtype (float64 for the kinematics, complex128 for the complex-step convective
terms; only operations that are analytic in the complex plane are used, as in ``cardan.py``).
``tests/beam/test_cardan_compiled.py`` checks it against the numpy version for both dtypes.
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba


def _kernel(rp, rpp, gam, gamp, basis, eps, d, dpsi, tmat, frame, angles, psi_prime):
    G = rp.shape[0]
    w = np.empty(3, dtype=rp.dtype)
    v = np.empty(3, dtype=rp.dtype)
    ga = np.empty(3, dtype=rp.dtype)
    gb = np.empty(3, dtype=rp.dtype)
    dap = np.empty(3, dtype=rp.dtype)
    dbp = np.empty(3, dtype=rp.dtype)
    dref = np.empty((4, 2, 3), dtype=rp.dtype)
    fref = np.empty((3, 3), dtype=rp.dtype)
    for g in range(G):
        for j in range(3):                 # reference-basis components of r', r''
            w[j] = rp[g, 0] * basis[0, j] + rp[g, 1] * basis[1, j] + rp[g, 2] * basis[2, j]
            v[j] = rpp[g, 0] * basis[0, j] + rpp[g, 1] * basis[1, j] + rpp[g, 2] * basis[2, j]
        w1, w2, w3 = w[0], w[1], w[2]
        v1, v2, v3 = v[0], v[1], v[2]
        a = w2 * w2 + w3 * w3
        rho = np.sqrt(a)
        n2 = w1 * w1 + a
        nrm = np.sqrt(n2)
        ia = 1.0 / a
        irho = rho * ia
        in2 = 1.0 / n2
        alpha = 2.0 * np.arctan(-w2 / (rho + w3))          # Eq. 26
        beta = np.arctan(w1 * irho)                         # Eq. 27
        sb, cb = w1 / nrm, rho / nrm
        ca, sa = w3 * irho, -w2 * irho
        cg, sg = np.cos(gam[g]), np.sin(gam[g])
        c = w1 * in2
        ga[0] = 0.0
        ga[1] = -w3 * ia
        ga[2] = w2 * ia
        for j in range(3):
            gb[j] = w[j] * (-c * irho)
        gb[0] = rho * in2
        q23 = w2 * v2 + w3 * v3
        u = w1 * v1 + q23
        ap = (w2 * v3 - w3 * v2) * ia                       # alpha'
        bp = (a * v1 - w1 * q23) * (irho * in2)             # beta'
        t2 = (ap + ap) * ia
        dap[0] = 0.0
        dap[1] = v3 * ia - t2 * w2
        dap[2] = -(v2 * ia + t2 * w3)
        uin = u * in2 * irho
        bia = bp * ia
        for j in range(3):
            dbp[j] = w[j] * (2.0 * c * uin - bia) + v[j] * (-c * irho)
        dbp[0] += bia * w1 - uin
        # strains (Eq. 33)
        e2 = cb * cg * ap + sg * bp
        e3 = -cb * sg * ap + cg * bp
        eps[g, 0] = nrm - 1.0
        eps[g, 1] = sb * ap + gamp[g]
        eps[g, 2] = e2
        eps[g, 3] = e3
        for j in range(3):
            dref[0, 0, j] = w[j] / nrm
            dref[0, 1, j] = 0.0
            dref[1, 0, j] = cb * ap * gb[j] + sb * dap[j]
            dref[1, 1, j] = sb * ga[j]
            p10 = cb * dap[j] - sb * ap * gb[j]
            p11 = cb * ga[j]
            dref[2, 0, j] = cg * p10 + sg * dbp[j]
            dref[2, 1, j] = cg * p11 + sg * gb[j]
            dref[3, 0, j] = cg * dbp[j] - sg * p10
            dref[3, 1, j] = cg * gb[j] - sg * p11
        for r in range(4):
            for blk in range(2):
                for k in range(3):
                    d[g, r, 3 * blk + k] = (dref[r, blk, 0] * basis[k, 0]
                                            + dref[r, blk, 1] * basis[k, 1]
                                            + dref[r, blk, 2] * basis[k, 2])
        d[g, 0, 6] = 0.0
        d[g, 1, 6] = 0.0
        d[g, 2, 6] = e3
        d[g, 3, 6] = -e2
        d[g, 0, 7] = 0.0
        d[g, 1, 7] = 1.0
        d[g, 2, 7] = 0.0
        d[g, 3, 7] = 0.0
        for k in range(3):
            dpsi[g, 0, k] = ga[0] * basis[k, 0] + ga[1] * basis[k, 1] + ga[2] * basis[k, 2]
            dpsi[g, 1, k] = gb[0] * basis[k, 0] + gb[1] * basis[k, 1] + gb[2] * basis[k, 2]
        tmat[g, 0, 0] = sb                                   # Eq. 31
        tmat[g, 0, 1] = 0.0
        tmat[g, 0, 2] = 1.0
        tmat[g, 1, 0] = cb * cg
        tmat[g, 1, 1] = sg
        tmat[g, 1, 2] = 0.0
        tmat[g, 2, 0] = -cb * sg
        tmat[g, 2, 1] = cg
        tmat[g, 2, 2] = 0.0
        u1x, u1y, u1z = cb, sa * sb, -ca * sb                # Eq. 24, rows e_t, e_b, e_s
        fref[0, 0] = cg * u1x
        fref[0, 1] = cg * u1y + sg * ca
        fref[0, 2] = cg * u1z + sg * sa
        fref[1, 0] = -sg * u1x
        fref[1, 1] = cg * ca - sg * u1y
        fref[1, 2] = cg * sa - sg * u1z
        fref[2, 0] = sb
        fref[2, 1] = -sa * cb
        fref[2, 2] = ca * cb
        for i in range(3):
            for k in range(3):
                frame[g, i, k] = (fref[i, 0] * basis[k, 0] + fref[i, 1] * basis[k, 1]
                                  + fref[i, 2] * basis[k, 2])
        angles[g, 0] = alpha
        angles[g, 1] = beta
        angles[g, 2] = gam[g]
        psi_prime[g, 0] = ap
        psi_prime[g, 1] = bp
        psi_prime[g, 2] = gamp[g]


def _allocate_and_run(rp, rpp, gam, gamp, basis):
    """(eps, d, angles, dpsi, tmat, frame, psi_prime) in the dtype of rp (callable from other
    compiled functions)."""
    G = rp.shape[0]
    dt = rp.dtype
    eps = np.empty((G, 4), dtype=dt)
    d = np.empty((G, 4, 8), dtype=dt)
    dpsi = np.empty((G, 2, 3), dtype=dt)
    tmat = np.empty((G, 3, 3), dtype=dt)
    frame = np.empty((G, 3, 3), dtype=dt)
    angles = np.empty((G, 3), dtype=dt)
    psi_prime = np.empty((G, 3), dtype=dt)
    _compiled(rp, rpp, gam, gamp, basis, eps, d, dpsi, tmat, frame, angles, psi_prime)
    return eps, d, angles, dpsi, tmat, frame, psi_prime


def _length_powers(ell):
    """l**(-4 .. 2) in the dtype of l: the powers of the sub-element length in the spline basis
    rows (moving_node_beam, SplineElement.evaluate)."""
    il = 1.0 / ell
    il2 = il * il
    out = np.zeros(7) + 0.0 * ell                 # the dtype of l (float or complex)
    out[0] = il2 * il2
    out[1] = il2 * il
    out[2] = il2
    out[3] = il
    out[4] = 1.0
    out[5] = ell
    out[6] = ell * ell
    return out


if AVAILABLE:
    _compiled = numba.njit(cache=True, nogil=True)(_kernel)
    section_state_compiled = numba.njit(cache=True, nogil=True)(_allocate_and_run)
    length_powers = numba.njit(cache=True, nogil=True)(_length_powers)


def check_finite(total, what: str) -> None:
    """numpy's floating-point error handling for the compiled kernels, which compute silently:
    where numpy is set to raise on invalid operations or overflow (``np.errstate``, as the
    integrator's right-hand side is: a blown-up stage is rejected, not fatal), a non-finite
    result (``total``: a sum of the kernel's outputs, non-finite if any is) raises
    FloatingPointError; elsewhere it propagates as numpy's NaN would."""
    if not np.isfinite(total):
        err = np.geterr()
        if err["invalid"] == "raise" or err["over"] == "raise":
            raise FloatingPointError(f"non-finite {what} (compiled kernel)")


def section_state_arrays(rp, rpp, gam, gamp, basis):
    """(eps, deps_dx, angles, dpsi_drp, tmat, frame, psi_prime) as in ``cardan.section_state``,
    in the common dtype of the inputs (float64 or complex128)."""
    dt = np.result_type(rp, rpp, gam, gamp, float)
    rp = np.ascontiguousarray(rp, dtype=dt)
    rpp = np.ascontiguousarray(rpp, dtype=dt)
    gam = np.ascontiguousarray(gam, dtype=dt)
    gamp = np.ascontiguousarray(gamp, dtype=dt)
    basis = np.ascontiguousarray(basis, dtype=float)
    eps, d, angles, dpsi, tmat, frame, psi_prime = section_state_compiled(rp, rpp, gam, gamp,
                                                                         basis)
    check_finite(d.sum() + frame.sum(), "section state")     # d: strains' derivatives
    return eps, d, angles, dpsi, tmat, frame, psi_prime
