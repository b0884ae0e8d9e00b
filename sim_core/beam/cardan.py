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
    """Strains, frames and derivatives from r' (G,3), r'' (G,3), gamma (G,), gamma' (G,).

    ``basis`` is the reference basis G (3x3, columns g1, g2, g3 in global components).
    """
    w = rp @ basis           # components of r' in the reference basis
    w2v = rpp @ basis        # components of r''
    w1, w2, w3 = w[:, 0], w[:, 1], w[:, 2]
    a = w2 * w2 + w3 * w3
    rho = np.sqrt(a)
    n2 = w1 * w1 + a
    nrm = np.sqrt(n2)

    alpha = _atan2(-w2, w3)                       # Eq. 26
    beta = np.arctan(w1 / rho)                    # Eq. 27 (arcsin(w1/|w|), same angle)
    sb, cb = w1 / nrm, rho / nrm
    cg, sg = np.cos(gam), np.sin(gam)

    G = w.shape[0]
    dt = w.dtype
    # gradients of alpha, beta w.r.t. w
    ga = np.zeros((G, 3), dtype=dt)
    ga[:, 1] = -w3 / a
    ga[:, 2] = w2 / a
    vb = np.stack([rho, -w1 * w2 / rho, -w1 * w3 / rho], axis=1)
    gb = vb / n2[:, None]
    # Hessians
    ha = np.zeros((G, 3, 3), dtype=dt)
    a2 = a * a
    ha[:, 1, 1] = 2.0 * w2 * w3 / a2
    ha[:, 1, 2] = ha[:, 2, 1] = (w3 * w3 - w2 * w2) / a2
    ha[:, 2, 2] = -2.0 * w2 * w3 / a2
    dvb = np.zeros((G, 3, 3), dtype=dt)
    rho3 = rho ** 3
    dvb[:, 0, 1] = w2 / rho
    dvb[:, 0, 2] = w3 / rho
    dvb[:, 1, 0] = -w2 / rho
    dvb[:, 1, 1] = -w1 / rho + w1 * w2 * w2 / rho3
    dvb[:, 1, 2] = w1 * w2 * w3 / rho3
    dvb[:, 2, 0] = -w3 / rho
    dvb[:, 2, 1] = w1 * w2 * w3 / rho3
    dvb[:, 2, 2] = -w1 / rho + w1 * w3 * w3 / rho3
    hb = dvb / n2[:, None, None] - 2.0 * vb[:, :, None] * w[:, None, :] / (n2 * n2)[:, None, None]

    ap = np.einsum("gi,gi->g", ga, w2v)        # alpha'
    bp = np.einsum("gi,gi->g", gb, w2v)        # beta'
    dap_dw = np.einsum("gij,gj->gi", ha, w2v)
    dbp_dw = np.einsum("gij,gj->gi", hb, w2v)
    dsb_dw = cb[:, None] * gb
    dcb_dw = -sb[:, None] * gb

    # strains: eps_s = |r'| - 1, curvatures by Eq. 33
    eps = np.empty((G, 4), dtype=dt)
    eps[:, 0] = nrm - 1.0
    eps[:, 1] = sb * ap + gamp
    eps[:, 2] = cb * cg * ap + sg * bp
    eps[:, 3] = -cb * sg * ap + cg * bp

    d = np.zeros((G, 4, 8), dtype=dt)
    # w.r.t. w (converted to r' below), w'' (to r''), gamma, gamma'
    dw = np.zeros((G, 4, 3), dtype=dt)
    dww = np.zeros((G, 4, 3), dtype=dt)
    dw[:, 0] = w / nrm[:, None]
    dw[:, 1] = dsb_dw * ap[:, None] + sb[:, None] * dap_dw
    dww[:, 1] = sb[:, None] * ga
    dw[:, 2] = cg[:, None] * (dcb_dw * ap[:, None] + cb[:, None] * dap_dw) + sg[:, None] * dbp_dw
    dww[:, 2] = (cb * cg)[:, None] * ga + sg[:, None] * gb
    dw[:, 3] = -sg[:, None] * (dcb_dw * ap[:, None] + cb[:, None] * dap_dw) + cg[:, None] * dbp_dw
    dww[:, 3] = -(cb * sg)[:, None] * ga + cg[:, None] * gb
    d[:, :, 0:3] = dw @ basis.T
    d[:, :, 3:6] = dww @ basis.T
    d[:, 2, 6] = -cb * sg * ap + cg * bp
    d[:, 3, 6] = -cb * cg * ap - sg * bp
    d[:, 1, 7] = 1.0

    dpsi = np.stack([ga @ basis.T, gb @ basis.T], axis=1)

    tmat = np.zeros((G, 3, 3), dtype=dt)           # Eq. 31
    tmat[:, 0, 0] = sb
    tmat[:, 0, 2] = 1.0
    tmat[:, 1, 0] = cb * cg
    tmat[:, 1, 1] = sg
    tmat[:, 2, 0] = -cb * sg
    tmat[:, 2, 1] = cg

    frame = cardan_frame(alpha, beta, gam) @ basis.T
    angles = np.stack([alpha, beta, gam], axis=1)
    psi_prime = np.stack([ap, bp, gamp], axis=1)
    return SectionState(eps, d, angles, dpsi, tmat, frame, psi_prime)
