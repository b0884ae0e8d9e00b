"""Nonlinear (holonomic) constraints with Lagrange multipliers and Baumgarte stabilization.

A constraint is  g(Q) - b(t) = 0  with m rows acting on a subset of the coordinates.  The
model solves the index-1 form at acceleration level,

    [ M_r   C^T ] [ z_ddot ]   [ F_r                                              ]
    [ C     0   ] [ -lambda] = [ b_ddot - g_QQ[Q_dot, Q_dot] - g_Q Q_ddot_p
                                 - 2 xi1 (g_Q Q_dot - b_dot) - xi2^2 (g - b)    ]

with C = g_Q P (second seed, Eq. 8: Phi_ddot + 2 xi1 Phi_dot + xi2^2 Phi = 0).  The quadratic
velocity term g_QQ[Q_dot, Q_dot] is the complex-step derivative of g_Q(Q + i h Q_dot) Q_dot.
The position-level violation |g - b| is reported as an output so drift is visible.

Zhao-Qi-Wang 2024 Section 6 (Constraints I and II: centroids coincide, Cardan angles agree)
are built with :func:`point_coincidence` and :func:`angle_coincidence` from material points
whose arc-length coordinate may itself be a state variable (the inner contact point s_2,k).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .beam import point_compiled

Vec = np.ndarray


@dataclass
class NonlinearConstraint:
    """Rows g(Q) - b(t) = 0.

    ``evaluate(Q)`` returns (g (m,), g_Q (m, N)) and must be complex-step safe in Q.
    ``target`` returns (b, b_dot, b_ddot) at time t (rheonomic drives); None means b = 0.
    """

    name: str
    m: int
    evaluate: Callable[[Vec], tuple[Vec, Vec]]
    target: Callable[[float], tuple[Vec, Vec, Vec]] | None = None
    # the point functions g is built from; they say which coordinates g depends on, so the
    # structured Jacobian (sim_core.state_jacobian) differentiates only those. None: unknown
    # (every coordinate is differenced)
    points: tuple | None = None

    def coords(self, Q: Vec) -> np.ndarray | None:
        """Coordinates g depends on at Q (None: possibly all)."""
        return None if self.points is None else dependencies(self.points, Q)

    def b(self, t: float):
        if self.target is None:
            z = np.zeros(self.m)
            return z, z, z
        return tuple(np.atleast_1d(np.asarray(x, float)) for x in self.target(t))


_H = 1e-20


def dependencies(points, Q: Vec) -> np.ndarray | None:
    """Union of the coordinates the point functions depend on at Q; None if one of them does not
    say (a point function may carry ``coords(Q)``, as :func:`material_point`'s do)."""
    sets = []
    for p in points:
        c = getattr(p, "coords", None)
        if c is None:
            return None
        sets.append(np.asarray(c(Q), dtype=int))
    return np.unique(np.concatenate(sets)) if sets else np.zeros(0, dtype=int)


def constraint_terms(cons: list[NonlinearConstraint], t: float, Q: Vec, Qd: Vec):
    """Stacked (violation Phi, Jacobian g_Q, velocity violation Phi_dot, b_ddot - g_QQ[Qd,Qd]);
    empty rows (and a 0 x N Jacobian) without constraints."""
    if not cons:
        e = np.zeros(0)
        return e, np.zeros((0, len(Q))), e, e
    phis, jacs, dphis, rhs = [], [], [], []
    Qc = Q + 1j * _H * Qd                  # one complex state: the point caches serve all rows
    for c in cons:
        g, J = c.evaluate(Q)
        _, Jc = c.evaluate(Qc)
        quad = (Jc @ Qd).imag / _H
        b, bd, bdd = c.b(t)
        phis.append(np.real(g) - b)
        jacs.append(np.real(J))
        dphis.append(np.real(J) @ Qd - bd)
        rhs.append(bdd - quad)
    return (np.concatenate(phis), np.vstack(jacs), np.concatenate(dphis), np.concatenate(rhs))


def kkt_factor(Mr: Vec, C: Vec):
    """LU-factor the saddle-point matrix once; returns solve(Fr, c_rhs) -> (z_ddot, lambda)."""
    import scipy.linalg as sla
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


def kkt_accelerations(Mr: Vec, Fr: Vec, C: Vec, c_rhs: Vec):
    """Solve the saddle-point system; returns (z_ddot, lambda) with M z_ddot = F + C^T lambda."""
    n, m = Mr.shape[0], C.shape[0]
    K = np.zeros((n + m, n + m))
    K[:n, :n] = Mr
    K[:n, n:] = C.T
    K[n:, :n] = C
    sol = np.linalg.solve(K, np.concatenate([Fr, c_rhs]))
    return sol[:n], -sol[n:]


def material_point(model, ibeam: int, s_fixed: float | None = None, s_index: int | None = None,
                   offset=None):
    """Function Q -> (r (3,), dr/dQ (3, N), psi (3,), dpsi/dQ (3, N)) of a point of a beam.

    The point is the material point s_fixed, or the spatial point whose material coordinate is
    the generalized coordinate Q[s_index] (e.g. the inner contact point s_2,k, Section 5-6):
    d r/dQ = dr/dQ|_s + r' ds/dQ  (Eq. 1 in coordinates).  Complex-step safe.
    ``offset`` (axial, lateral, vertical) in m is a rigid offset in the section frame
    (e_s, e_t, e_b), e.g. the luffing pivot D1 and cylinder head D3 (Section 9, Fig. 13a):
    r_o = r + o_s e_s + o_t e_t + o_b e_b,  dr_o = dr + delta_phi x o  (delta_phi = frame^T dw).
    """
    key = (ibeam, None if s_fixed is None else float(s_fixed), s_index,
           None if offset is None else tuple(float(x) for x in offset))
    cache = model.__dict__.setdefault("_material_points", {})
    if key in cache:                       # one function (and one evaluation cache) per point
        return cache[key]
    o_sec = None if offset is None else np.asarray(offset, float)
    beam = model.beams[ibeam]
    off = int(model.offsets[ibeam])
    N = model.n_coords

    # [(coordinates, their values, result)] for the last real and the last complex state; keyed
    # on the coordinates the point depends on, so a state that differs elsewhere (another
    # body's coordinate perturbed for a Jacobian column) reuses the evaluation
    memo: list = []

    def f(Q):
        cols = coords(Q)
        key = (cols.tobytes(), Q[cols].tobytes())     # exact: the same coordinates and values
        for k, dt, res in memo:
            if dt == Q.dtype and k == key:
                return res
        res = _evaluate(Q)
        memo[:] = [m for m in memo if m[1] != Q.dtype][:1] + [(key, Q.dtype, res)]
        return res

    def _evaluate(Q):
        s = Q[s_index] if s_index is not None else s_fixed
        e = model._element_at(ibeam, Q.real, float(np.real(s)))
        idx = off + beam.index_map[e]
        el = beam.elements[e]
        if point_compiled.AVAILABLE:                      # the same kinematics, compiled
            r, rp, J_r, J_psi, angles, psi_prime, frame, tmat = point_compiled.point_kinematics(
                el, Q[idx], s)
        else:
            kin = el.evaluate(Q[idx], s=np.array([s]), strains=False)
            r, rp, J_r, J_psi = kin.r[0], kin.rp[0], kin.J_r[0], kin.J_psi[0]
            sec = kin.sec
            angles, psi_prime, frame, tmat = (sec.angles[0], sec.psi_prime[0], sec.frame[0],
                                              sec.tmat[0])
        J = np.zeros((3, N), dtype=J_r.dtype)
        Jp = np.zeros((3, N), dtype=J_r.dtype)
        J[:, idx] = J_r
        Jp[:, idx] = J_psi
        if s_index is not None:
            J[:, s_index] += rp
            Jp[:, s_index] += psi_prime
        if o_sec is not None:                             # frame: rows e_t, e_b, e_s (global)
            o = o_sec[1] * frame[0] + o_sec[2] * frame[1] + o_sec[0] * frame[2]
            # small global rotation per dQ; tmat gives section components ordered (s, t, b)
            rot = frame[[2, 0, 1]].T @ (tmat @ Jp)
            J = J + np.stack([rot[1] * o[2] - rot[2] * o[1],      # delta_phi x o
                              rot[2] * o[0] - rot[0] * o[2],
                              rot[0] * o[1] - rot[1] * o[0]])
            r = r + o
        return r, J, angles, Jp

    def coords(Q):
        """The coordinates r and Psi depend on at Q: the element's, and s_index if moving."""
        s = np.real(Q[s_index]) if s_index is not None else s_fixed
        idx = off + beam.index_map[model._element_at(ibeam, np.real(Q), float(s))]
        return idx if s_index is None else np.append(idx, s_index)

    f.coords = coords
    cache[key] = f
    return f


def fixed_point(r) -> Callable:
    """A point fixed in space (m): the point-function signature with zero Jacobians."""
    r = np.asarray(r, float)

    def f(Q):
        Z = np.zeros((3, len(Q)))
        return r, Z, np.zeros(3), Z
    f.coords = lambda Q: np.zeros(0, dtype=int)
    return f



def _fixed(value):
    v = np.asarray(value, float)
    z = np.zeros_like(v)
    return lambda t: (v, z, z)


def _coincidence(name: str, fa, fb, fixed, part: int) -> NonlinearConstraint:
    """q_a - q_b = 0 (or q_a = fixed) for part 0 (centroid r) or 1 (Cardan angles Psi) of the
    point functions' (r, dr/dQ, Psi, dPsi/dQ)."""
    def evaluate(Q):
        a = fa(Q)
        if fb is None:
            return a[2 * part], a[2 * part + 1]
        b = fb(Q)
        return a[2 * part] - b[2 * part], a[2 * part + 1] - b[2 * part + 1]
    return NonlinearConstraint(name, 3, evaluate, None if fixed is None else _fixed(fixed),
                               points=(fa,) if fb is None else (fa, fb))


def point_coincidence(name: str, fa, fb=None, fixed=None) -> NonlinearConstraint:
    """Centroids coincide: r_a(Q) - r_b(Q) = 0, or r_a(Q) = fixed (Section 6, Eq. 47)."""
    return _coincidence(name, fa, fb, fixed, 0)


def angle_coincidence(name: str, fa, fb=None, fixed=None) -> NonlinearConstraint:
    """Orientations agree: Psi_a - Psi_b = 0 (Cardan angles in a common basis, Eq. 48)."""
    return _coincidence(name, fa, fb, fixed, 1)


def distance_driver(name: str, fa, fb, length) -> NonlinearConstraint:
    """|r_a - r_b| = L(t): a massless actuator imposing a distance (cylinder, drive).

    ``length(t)`` returns (L, L_dot, L_ddot); the multiplier is the actuator force (N),
    positive in tension."""
    def evaluate(Q):
        ra, Ja, _, _ = fa(Q)
        rb, Jb, _, _ = fb(Q)
        d = ra - rb
        n = np.sqrt(d @ d)
        return np.atleast_1d(n), ((d / n) @ (Ja - Jb))[None, :]
    return NonlinearConstraint(name, 1, evaluate, length, points=(fa, fb))


def rope_length(name: str, points, length: float) -> NonlinearConstraint:
    """Inextensible rope over frictionless point pulleys: sum |r_{i+1} - r_i| = L0 (m).

    The bilateral limit of :class:`sim_core.point_effects.RopeDrive` (effects.rope_elasticity =
    false): the rope length fixes the pulley kinematics (boom 3 moves twice the piston stroke,
    Zhao-Qi-Wang 2024 Eqs. 74-76).  The rope tension is T = -lambda (N); T < 0 means the opposite
    (retraction) rope carries |T|, which is why one bilateral constraint stands for both ropes."""
    def evaluate(Q):
        pts = [p(Q) for p in points]
        ell = 0.0
        J = 0.0
        for (ra, Ja, _, _), (rb, Jb, _, _) in zip(pts[:-1], pts[1:]):
            d = rb - ra
            n = np.sqrt(d @ d)
            ell = ell + n
            J = J + (d / n) @ (Jb - Ja)
        return np.atleast_1d(ell), np.atleast_2d(J)
    return NonlinearConstraint(name, 1, evaluate, _fixed([length]), points=tuple(points))
