"""Effects: the generalized-force and mass contributions a scene switches on.

Each effect is a small object that adds its share to the element mass matrix and force vector
from the shared per-element kinematics.  The model computes only the kinematic quantities the
listed effects declare in ``needs`` and calls exactly those effects: an effect that is off is
not in the list, so nothing of it is computed (PyElastica-style assembly).

Sign convention: the element equations are  M q_ddot = F,  with F = external - internal -
convective forces.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, ClassVar

import numpy as np

from sim_core.physics.beam.moving_node_beam import PointKinematics, SplineElement


@dataclass
class ElementContext:
    """Everything an effect may read for one element at one instant."""

    t: float
    el: SplineElement
    qe: np.ndarray
    qde: np.ndarray
    kin: PointKinematics
    wl: np.ndarray                 # quadrature weight * sub-element length, m
    conv: dict | None = None       # complex-step convective terms (see Model)


def _gram(J: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """sum_g J_g^T diag(scale_g^2) J_g for J of shape (G, k, n) and scale (G, k) (one BLAS call)."""
    A = (J * scale[:, :, None]).reshape(-1, J.shape[2])
    return A.T @ A


def _gram_stacked(pairs) -> np.ndarray:
    """sum over (J, scale) pairs of _gram(J, scale), as a single BLAS product."""
    G, _, n = pairs[0][0].shape
    k = sum(J.shape[1] for J, _ in pairs)
    A = np.empty((G, k, n), dtype=np.result_type(*(x for p in pairs for x in p)))
    i = 0
    for J, scale in pairs:
        np.multiply(J, scale[:, :, None], out=A[:, i:i + J.shape[1]])
        i += J.shape[1]
    A = A.reshape(G * k, n)
    return A.T @ A


def _jt_v(J: np.ndarray, v: np.ndarray) -> np.ndarray:
    """sum_g J_g^T v_g for J (G, k, n), v (G, k): one matrix-vector product."""
    return v.reshape(-1) @ J.reshape(-1, J.shape[2])


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise a x b for (G, 3) arrays (np.cross has a large fixed cost at this size)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype=np.result_type(a, b))
    a0, a1, a2 = a[:, 0], a[:, 1], a[:, 2]
    b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
    out[:, 0] = a1 * b2 - a2 * b1
    out[:, 1] = a2 * b0 - a0 * b2
    out[:, 2] = a0 * b1 - a1 * b0
    return out


def _offset_jacobian(ctx: ElementContext) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mass-centre offset d = y_c e_t + z_c e_b (docs/model.md#input-sections: rigid offset of
    the mass centre from the reference line, paper Table 2).  Returns (J_c, frame, d_body):

    J_c = J_r + frame^T C J_w, the velocity Jacobian of the mass centre r + d, where C maps the
    section-frame angular velocity (omega_s, omega_t, omega_b) to omega x d in (e_t, e_b, e_s)
    components: omega x d = (-z_c omega_s) e_t + (y_c omega_s) e_b + (z_c omega_t - y_c omega_b) e_s.
    frame (G, 3, 3) rows e_t, e_b, e_s (global); d_body = (y_c, z_c, 0) in (t, b, s) order."""
    sec = ctx.el.section
    kin = ctx.kin
    yc, zc = sec.y_c, sec.z_c
    C = np.array([[-zc, 0.0, 0.0], [yc, 0.0, 0.0], [0.0, zc, -yc]])
    frame = kin.sec.frame
    J_c = kin.J_r + np.einsum("gji,jk,gkn->gin", frame, C, kin.J_w)
    return J_c, frame, np.array([yc, zc, 0.0])


def _offset_convective(frame, d, omega, w_dot):
    """Convective acceleration of the offset (global): d/dt (omega x d) at q_ddot = 0 =
    w_dot x d + omega x (omega x d), evaluated in body components (t, b, s) (the body-frame rate
    of body components of omega equals the inertial one) and rotated to global."""
    w3 = omega[:, [1, 2, 0]]                 # (s, t, b) -> (t, b, s)
    wd3 = w_dot[:, [1, 2, 0]]
    dd = np.broadcast_to(d, w3.shape)
    a_b = _cross(wd3, dd) + _cross(w3, _cross(w3, dd))
    return np.einsum("gji,gj->gi", frame, a_b)


class Effect:
    """Base class: ``needs`` lists kinematic quantities this effect reads."""

    needs: ClassVar[frozenset] = frozenset()
    name: ClassVar[str] = "effect"

    def element_terms(self, ctx: ElementContext, M: np.ndarray | None, F: np.ndarray) -> None:
        raise NotImplementedError


class Inertia(Effect):
    """Translational and rotary inertia with material accelerations (Eq. 34, 2nd and 3rd terms).

    M += int rhoA J_r^T J_r + J_w^T J J_w ds;
    F -= int rhoA J_r^T (J_r)^. q_dot + J_w^T (J (J_w)^. q_dot + omega x J omega) ds.
    """

    needs = frozenset({"convective"})
    name = "inertia"

    def element_terms(self, ctx, M, F):
        sec = ctx.el.section
        kin, wl = ctx.kin, ctx.wl
        Jd = sec.J
        J_w = kin.J_w
        if sec.has_offset:
            # mass centre offset from the reference line (docs/model.md#input-sections / paper
            # Table 2): the translational terms use the mass-centre Jacobian and acceleration
            J_r, frame, d = _offset_jacobian(ctx)
        else:
            J_r = kin.J_r
        if M is not None:
            M += _gram_stacked([(J_r, np.sqrt(wl * sec.rhoA)[:, None].repeat(3, axis=1)),
                                (J_w, np.sqrt(wl[:, None] * Jd))])
        if ctx.conv is not None:
            omega = J_w @ ctx.qde
            rot = Jd * ctx.conv["w_dot"] + _cross(omega, Jd * omega)
            a = ctx.conv["a"]
            if sec.has_offset:
                a = a + _offset_convective(frame, d, omega, ctx.conv["w_dot"])
            F -= _jt_v(J_r, (wl * sec.rhoA)[:, None] * a)
            F -= _jt_v(J_w, wl[:, None] * rot)


class Elasticity(Effect):
    """Internal forces as the gradient of the strain energy (Eq. 34 first term, Eq. 36).

    F -= sum_g w [ l B_xi^T D eps + W dl/dq ];  see moving_node_beam for why the energy form.
    """

    needs = frozenset({"strains"})
    name = "elasticity"

    def element_terms(self, ctx, M, F):
        el, kin, wl = ctx.el, ctx.kin, ctx.wl
        D = el.section.D
        eps = kin.sec.eps
        sigma = eps * D
        F -= _jt_v(kin.B_xi, wl[:, None] * sigma)
        W = 0.5 * np.einsum("gi,gi->g", sigma, eps)
        total = np.dot(el.q_w, W)            # dU/dl at fixed xi
        inv = 1.0 / (el.n - 1)
        F[el.i_s1] += total * inv     # dl/ds_1 = -1/(n-1), with the minus of F -= ...
        F[el.i_sn] -= total * inv


class StressFilter(Effect):
    """High-frequency filtering of the internal stress (SIMULTECH 2020, Eq. 53).

    sigma_bar = sigma + (h/2) sigma_dot + (h^2/6) sigma_ddot with material rates:
    adds (h^2/6) int B_s^T D B_s ds to the mass matrix and the damping-like forces
    (h/2) int B_s^T D eps_dot ds + (h^2/6) int B_s^T D (B_s)^. q_dot ds.
    """

    needs = frozenset({"strains", "material_strain", "convective"})
    name = "filtering"

    def __init__(self, h: float):
        if not (h > 0 and np.isfinite(h)):
            raise ValueError(f"filtering.h = {h!r}: must be > 0 (0 switches the effect off)")
        self.h = float(h)

    def element_terms(self, ctx, M, F):
        D = ctx.el.section.D
        B = ctx.kin.B_s
        h = self.h
        if M is not None:
            M += _gram(B, np.sqrt((h * h / 6.0) * ctx.wl[:, None] * D))
        eps_dot = B @ ctx.qde
        extra = D * (0.5 * h * eps_dot + (h * h / 6.0) * ctx.conv["eps_ddot"])
        F -= _jt_v(B, ctx.wl[:, None] * extra)


class Gravity(Effect):
    """Distributed weight: F += int rhoA J_r^T g ds."""

    name = "gravity"

    def __init__(self, g: np.ndarray):
        self.g = np.asarray(g, dtype=float)

    def element_terms(self, ctx, M, F):
        # weight at the mass centre: with an offset (docs/model.md#input-sections) the mass-centre
        # Jacobian
        J = _offset_jacobian(ctx)[0] if ctx.el.section.has_offset else ctx.kin.J_r
        F += _jt_v(J, (ctx.wl * ctx.el.section.rhoA)[:, None] * self.g)


@dataclass
class PointLoad:
    """A force (and optional moment, section-frame components) at a material point.

    ``s_of_t`` gives the material coordinate of the loaded point (constant for a material
    point, a function of time for a moving load, e.g. Fryba's force at s = c t).  Force and
    moment are functions of time returning (3,) arrays (global force, section-frame moment).
    Virtual power: delta(dr/dt|_s) . f + delta omega . m  (Section 7).
    """

    beam: int
    s_of_t: Callable[[float], float]
    force: Callable[[float], np.ndarray]
    moment: Callable[[float], np.ndarray] | None = None
    name: ClassVar[str] = "point_load"


def effect_parameters(effects, section):
    """Keyword arguments of :func:`sim_core.physics._effects_numba.element_mass_force` for a model's effect list and a beam
    section (``Inertia``, ``Elasticity``, ``StressFilter``, ``Gravity`` only; a section with a
    mass-centre offset is not covered).  Raises ValueError otherwise."""
    if section.has_offset:
        raise ValueError("mass-centre offset (y_c, z_c) is not covered by the compiled element")
    kw = dict(rhoA=section.rhoA, Jrot=section.J, D=section.D, h=0.0, g=np.zeros(3),
              inertia=False, elasticity=False)
    seen = set()
    for eff in effects:
        kind = type(eff)
        if kind not in (Inertia, Elasticity, StressFilter, Gravity) or kind in seen:
            raise ValueError(f"effect {kind.__name__} (or a second one of its kind) is not "
                             "covered by the compiled element")
        seen.add(kind)
        if kind is Inertia:
            kw["inertia"] = True
        elif kind is Elasticity:
            kw["elasticity"] = True
        elif kind is StressFilter:
            kw["h"] = eff.h
        else:
            kw["g"] = np.asarray(eff.g, dtype=float)
    return kw
