"""Stress resultants (section forces) along a moving-node spline beam.

Source: Zhao, Qi, Wang (2024), Sections 3-5.  The element is shear-rigid: its generalized
strains are the axial strain and the three curvatures of the Cardan frame,

    eps = (eps_s, kappa_s, kappa_t, kappa_b),   eps_s = |r'| - 1,  kappa by Eq. 33,

and its constitutive law is the diagonal D = diag(EA, GJ, EI_t, EI_b) of Eq. 36.  The axial
force, the torque and the bending moments follow from the strains:

    N = EA eps_s,   T = GJ kappa_s,   M_t = EI_t kappa_t,   M_b = EI_b kappa_b      (Eq. 36)

The shear forces have no strain in this element (e_s is along r', Eq. 25): they are the
reactions of that constraint and follow from the balance of moments of a slice of the rod
(Antman, "Nonlinear Problems of Elasticity", 2nd ed. 2005, Ch. 8, the balance of moments of
a special Cosserat rod, with the rotary inertia and the distributed couples left out):

    dm/ds + r' x n = 0,   m = T e_s + M_t e_t + M_b e_b,   r' = (1 + eps_s) e_s.

With dm/ds = (M' + kappa x M) in the section frame (kappa the curvature vector of Eq. 33,
d e_i/ds = kappa x e_i) and e_s x e_t = e_b, e_s x e_b = -e_t:

    Q_t = -(M_b' + kappa_s M_t - kappa_t T) / (1 + eps_s)
    Q_b =  (M_t' + kappa_b T - kappa_s M_b) / (1 + eps_s)

M' = D eps' where eps' = (d eps / dx) x' is the chain rule through x = (r', r'', gamma, gamma'),
x' = (r'', r''', gamma', gamma''): the derivative ``deps_dx`` of the section state
(:mod:`sim_core.physics.beam.cardan`) and the third derivative of the quintic spline (Eq. 6).

Sign convention (Antman): n(s), m(s) are the force and moment that the part of the beam beyond
s (larger material coordinate) exerts on the part before it, components in the section frame
(e_t, e_b, e_s) (Eq. 24).  N > 0 is tension; M_t > 0 stretches the fibres at +e_b (the
strain at section point (y, z) is eps_s + kappa_t z - kappa_b y).

What the resultants leave out: the stress filter of the scene's ``filtering`` effect (a
numerical high-frequency filter, not a material stress); in the shear forces, the rotary
inertia of the sections and the distributed couple of a mass-centre offset
(``effects.mass_centre_offset``), which the quasi-static balance of moments above does not
hold.
"""

from __future__ import annotations

import numpy as np

#: component order of the section-force vector (section frame, Antman's convention above)
COMPONENTS = ("N", "Q_t", "Q_b", "T", "M_t", "M_b")
#: units of the components
UNITS = ("N", "N", "N", "N m", "N m", "N m")


def element_section_forces(el, qe: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Section forces (len(s), 6) of one spline element at material coordinates ``s`` (m, inside
    the element) for the element coordinates ``qe``; columns :data:`COMPONENTS`."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    if s.size == 0:
        return np.zeros((0, 6))
    kin = el.evaluate(np.asarray(qe, dtype=float), s=s)
    sec = kin.sec
    # the centre-line and torsion derivatives the evaluation formed: RR[k] = d^k r / ds^k
    # (k = 0..3), TT[k] = d^k gamma / ds^k (k = 0..2)
    st = kin._lazy
    RR, TT = st.RR, st.TT
    x_p = np.concatenate([RR[2], RR[3], TT[1][:, None], TT[2][:, None]], axis=1)
    return resultants(sec.eps, np.einsum("gij,gj->gi", sec.deps_dx, x_p), el.section.D)


def resultants(eps: np.ndarray, eps_p: np.ndarray, D: np.ndarray) -> np.ndarray:
    """(N, Q_t, Q_b, T, M_t, M_b) from the strains ``eps`` (G, 4), their arc-length derivatives
    ``eps_p`` (G, 4) and the constitutive diagonal ``D`` (4,) (module docstring)."""
    S = eps * D                                   # (N, T, M_t, M_b), Eq. 36
    Sp = eps_p * D
    k_s, k_t, k_b = eps[:, 1], eps[:, 2], eps[:, 3]
    N, T, Mt, Mb = S.T
    stretch = 1.0 + eps[:, 0]
    Qt = -(Sp[:, 3] + k_s * Mt - k_t * T) / stretch
    Qb = (Sp[:, 2] + k_b * T - k_s * Mb) / stretch
    return np.stack([N, Qt, Qb, T, Mt, Mb], axis=1)


def beam_section_forces(beam, qb: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Section forces (len(s), 6) of a :class:`~sim_core.physics.beam.moving_node_beam.Beam` at
    material coordinates ``s`` (m, within [0, length]) for the beam coordinates ``qb``.

    A station belongs to the element whose current material interval [s_1, s_n) holds it (the
    last element also takes its end s_n); element ends move with the coordinates (Eq. 5), so
    the element of a station is found at every call."""
    s = np.asarray(s, dtype=float)
    qb = np.real(np.asarray(qb))
    out = np.empty((s.size, 6))
    done = np.zeros(s.size, dtype=bool)
    n_el = len(beam.elements)
    for e, (el, idx) in enumerate(zip(beam.elements, beam.index_map)):
        qe = qb[idx]
        s1, sn = qe[el.i_s1], qe[el.i_sn]
        inside = (s >= s1) & ((s < sn) | ((e == n_el - 1) & (s <= sn)))
        if e == 0:
            inside |= s < s1
        if e == n_el - 1:
            inside |= s > sn
        pick = np.flatnonzero(inside & ~done)
        if pick.size:
            out[pick] = element_section_forces(el, qe, s[pick])
            done[pick] = True
    return out


def model_section_forces(model, Q: np.ndarray, stations) -> np.ndarray:
    """Section forces of every beam of ``model`` at its ``stations`` (a sequence of arrays of
    material coordinates, one per beam, all of the same length n_st): (n_beams, n_st, 6)."""
    Q = np.real(np.asarray(Q))
    return np.stack([beam_section_forces(b, Q[off:off + b.n_coords], st)
                     for b, off, st in zip(model.beams, model.offsets, stations)])
