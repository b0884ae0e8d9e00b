"""Cardan-angle cross-section frames, generalized strains and their derivatives.

Source: Zhao, Qi, Wang (2024), Section 5: Eq. 24 (Cardan matrix, first axis g1, third axis
e_s), Eq. 25 (e_s along r'), Eqs. 26-27 (alpha, beta from r'), Eqs. 28-31 (rotation axes and
angular velocity), Eq. 33 (curvatures), eps_s = |r'| - 1.

All functions are vectorized over a leading axis of points and are complex-step safe (no abs,
no arctan2, no branch on values), so that convective terms can be formed by complex-step
directional differentiation of analytic Jacobians.

Angles are measured in a reference basis G = [g1 g2 g3] (columns, global components) chosen per
beam so that e_s never approaches g1 (the singular direction of the Cardan sequence).  With
w = G^T r':  e_s = (sin b, -sin a cos b, cos a cos b) in the G basis, hence
    alpha = atan2(-w2, w3),  beta = atan(w1 / sqrt(w2^2 + w3^2)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim_core.physics.beam import _cardan_numba as _compiled


def _atan2(y, x):
    """Complex-safe atan2 by the half-angle formula (valid away from the cut at angle +-pi)."""
    rho = np.sqrt(x * x + y * y)
    return 2.0 * np.arctan(y / (rho + x))


@dataclass
class SectionState:
    """Section kinematics at a set of points (leading axis G).

    eps : (G, 4) generalized strains (eps_s, kappa_s, kappa_t, kappa_b), 1, 1/m, 1/m, 1/m.
    deps_dx : (G, 4, 8) derivative w.r.t. x = (r'(3), r''(3), gamma, gamma').
    angles : (G, 3) Cardan angles (alpha, beta, gamma), rad.
    dpsi_drp : (G, 2, 3) derivative of (alpha, beta) w.r.t. r' (global components).
    tmat : (G, 3, 3) map from (alpha, beta, gamma) rates to angular velocity in section frame
        components (omega_s, omega_t, omega_b) (Eq. 31 / Appendix A).
    frame : (G, 3, 3) rows e_t, e_b, e_s in global components.
    psi_prime : (G, 3) (alpha', beta', gamma'), 1/m.
    """

    eps: np.ndarray
    deps_dx: np.ndarray
    angles: np.ndarray
    dpsi_drp: np.ndarray
    tmat: np.ndarray
    frame: np.ndarray
    psi_prime: np.ndarray | None = None   # (G, 3) arc-length derivatives (alpha', beta', gamma')


def cardan_frame(alpha, beta, gamma) -> np.ndarray:
    """Rows (e_t, e_b, e_s) in the reference basis, Eq. 24 (local = R @ global)."""
    ca, sa = np.cos(alpha), np.sin(alpha)
    cb, sb = np.cos(beta), np.sin(beta)
    cg, sg = np.cos(gamma), np.sin(gamma)
    r = np.empty(np.shape(alpha) + (3, 3), dtype=np.result_type(alpha, beta, gamma, float))
    r[..., 0, 0] = cb * cg
    r[..., 0, 1] = ca * sg + sa * sb * cg
    r[..., 0, 2] = sa * sg - ca * sb * cg
    r[..., 1, 0] = -cb * sg
    r[..., 1, 1] = ca * cg - sa * sb * sg
    r[..., 1, 2] = sa * cg + ca * sb * sg
    r[..., 2, 0] = sb
    r[..., 2, 1] = -sa * cb
    r[..., 2, 2] = ca * cb
    return r


def section_state(rp: np.ndarray, rpp: np.ndarray, gam: np.ndarray, gamp: np.ndarray,
                  basis: np.ndarray) -> SectionState:
    """Strains, frames and derivatives from r' (G,3), r'' (G,3), gamma (G,), gamma' (G,): the
    compiled loop of :mod:`sim_core.physics.beam._cardan_numba` where numba is installed, otherwise
    :func:`section_state_numpy` (the reference; same formulas)."""
    if _compiled.AVAILABLE:
        return SectionState(*_compiled.section_state_arrays(rp, rpp, gam, gamp, basis))
    return section_state_numpy(rp, rpp, gam, gamp, basis)


def section_state_numpy(rp: np.ndarray, rpp: np.ndarray, gam: np.ndarray, gamp: np.ndarray,
                        basis: np.ndarray) -> SectionState:
    """Strains, frames and derivatives from r' (G,3), r'' (G,3), gamma (G,), gamma' (G,).

    ``basis`` is the reference basis G (3x3, columns g1, g2, g3 in global components).

    With w = G^T r', v = G^T r'' (reference-basis components), a = w2^2 + w3^2, rho = sqrt(a),
    |w| = sqrt(w1^2 + a):
        alpha = atan2(-w2, w3), beta = atan(w1 / rho)                         (Eqs. 26-27)
        grad alpha = (0, -w3, w2) / a,  grad beta = (rho, -w1 w2/rho, -w1 w3/rho) / |w|^2
        alpha' = grad alpha . v,  beta' = grad beta . v
    and the curvatures of Eq. 33.  The Hessian-vector products d(alpha')/dw = H_alpha v and
    d(beta')/dw = H_beta v are written out (no (G, 3, 3) Hessians are formed).
    """
    w = rp @ basis           # components of r' in the reference basis
    v = rpp @ basis          # components of r''
    w1, w2, w3 = w[:, 0], w[:, 1], w[:, 2]
    v1, v2, v3 = v[:, 0], v[:, 1], v[:, 2]
    a = w2 * w2 + w3 * w3
    rho = np.sqrt(a)
    n2 = w1 * w1 + a
    nrm = np.sqrt(n2)
    ia = 1.0 / a
    irho = rho * ia
    in2 = 1.0 / n2

    alpha = 2.0 * np.arctan(-w2 / (rho + w3))     # Eq. 26, _atan2(-w2, w3)
    beta = np.arctan(w1 * irho)                   # Eq. 27 (arcsin(w1/|w|), same angle)
    sb, cb = w1 / nrm, rho / nrm
    ca, sa = w3 * irho, -w2 * irho                # cos, sin of alpha
    cg, sg = np.cos(gam), np.sin(gam)

    G = w.shape[0]
    dt = w.dtype
    # gradients of alpha, beta w.r.t. w: g_ab[:, 0] = grad alpha, g_ab[:, 1] = grad beta
    #   grad alpha = (0, -w3, w2) / a,  grad beta = (e1 - c w) / rho,  c = w1 / |w|^2
    c = w1 * in2
    g_ab = np.empty((G, 2, 3), dtype=dt)
    ga, gb = g_ab[:, 0], g_ab[:, 1]
    ga[:, 0] = 0.0
    ga[:, 1] = -w3 * ia
    ga[:, 2] = w2 * ia
    np.multiply(w, (-c * irho)[:, None], out=gb)
    gb[:, 0] = rho * in2
    q23 = w2 * v2 + w3 * v3
    u = w1 * v1 + q23                             # w . v
    ap = (w2 * v3 - w3 * v2) * ia                 # alpha'
    bp = (a * v1 - w1 * q23) * (irho * in2)       # beta'
    # Hessian-vector products d(alpha')/dw = H_alpha v, d(beta')/dw = H_beta v:
    #   d alpha'/dw = ((0, v3, -v2) - 2 alpha' (0, w2, w3)) / a
    #   d beta'/dw  = k1 w + k2 v + k3 e1
    t2 = (ap + ap) * ia
    dap = np.empty((G, 3), dtype=dt)
    dap[:, 0] = 0.0
    dap[:, 1] = v3 * ia - t2 * w2
    dap[:, 2] = -(v2 * ia + t2 * w3)
    uin = u * in2 * irho
    bia = bp * ia
    dbp = w * (2.0 * c * uin - bia)[:, None]
    dbp += v * (-c * irho)[:, None]
    dbp[:, 0] += bia * w1 - uin

    # strains: eps_s = |r'| - 1, curvatures by Eq. 33
    eps = np.empty((G, 4), dtype=dt)
    eps[:, 0] = nrm - 1.0
    eps[:, 1] = sb * ap + gamp
    eps[:, 2] = cb * cg * ap + sg * bp
    eps[:, 3] = -cb * sg * ap + cg * bp

    # derivatives w.r.t. (w, v) in the reference basis, rows eps_s, kappa_s, kappa_t, kappa_b
    dref = np.empty((G, 4, 2, 3), dtype=dt)
    dref[:, 0, 0] = w * (1.0 / nrm)[:, None]
    dref[:, 0, 1] = 0.0
    dref[:, 1, 0] = (cb * ap)[:, None] * gb + sb[:, None] * dap
    dref[:, 1, 1] = sb[:, None] * ga
    p1 = np.empty((G, 2, 3), dtype=dt)            # (d/dw, d/dv) of cb alpha'
    p1[:, 0] = cb[:, None] * dap - (sb * ap)[:, None] * gb
    p1[:, 1] = cb[:, None] * ga
    p2 = np.empty((G, 2, 3), dtype=dt)            # (d/dw, d/dv) of beta'
    p2[:, 0] = dbp
    p2[:, 1] = gb
    cg3, sg3 = cg[:, None, None], sg[:, None, None]
    dref[:, 2] = cg3 * p1 + sg3 * p2
    dref[:, 3] = cg3 * p2 - sg3 * p1
    d = np.empty((G, 4, 8), dtype=dt)
    d[:, :, 0:6] = (dref.reshape(8 * G, 3) @ basis.T).reshape(G, 4, 6)
    d[:, 0:2, 6] = 0.0
    d[:, 2, 6] = eps[:, 3]                        # d kappa_t / d gamma = kappa_b
    d[:, 3, 6] = -eps[:, 2]
    d[:, :, 7] = 0.0
    d[:, 1, 7] = 1.0

    dpsi = (g_ab.reshape(2 * G, 3) @ basis.T).reshape(G, 2, 3)

    tmat = np.zeros((G, 3, 3), dtype=dt)           # Eq. 31
    tmat[:, 0, 0] = sb
    tmat[:, 0, 2] = 1.0
    tmat[:, 1, 0] = cb * cg
    tmat[:, 1, 1] = sg
    tmat[:, 2, 0] = -cb * sg
    tmat[:, 2, 1] = cg

    # Cardan frame (Eq. 24) from the direction cosines already at hand: rows e_t, e_b, e_s with
    # e_t = cg u1 + sg u2, e_b = -sg u1 + cg u2, u1 = (cb, sa sb, -ca sb), u2 = (0, ca, sa)
    fref = np.empty((G, 3, 3), dtype=dt)
    u1x, u1y, u1z = cb, sa * sb, -ca * sb
    fref[:, 0, 0] = cg * u1x
    fref[:, 0, 1] = cg * u1y + sg * ca
    fref[:, 0, 2] = cg * u1z + sg * sa
    fref[:, 1, 0] = -sg * u1x
    fref[:, 1, 1] = cg * ca - sg * u1y
    fref[:, 1, 2] = cg * sa - sg * u1z
    fref[:, 2, 0] = sb
    fref[:, 2, 1] = -sa * cb
    fref[:, 2, 2] = ca * cb
    frame = (fref.reshape(3 * G, 3) @ basis.T).reshape(G, 3, 3)
    angles = np.empty((G, 3), dtype=np.result_type(alpha, gam))
    angles[:, 0] = alpha
    angles[:, 1] = beta
    angles[:, 2] = gam
    psi_prime = np.empty((G, 3), dtype=np.result_type(ap, gamp))
    psi_prime[:, 0] = ap
    psi_prime[:, 1] = bp
    psi_prime[:, 2] = gamp
    return SectionState(eps, d, angles, dpsi, tmat, frame, psi_prime)
