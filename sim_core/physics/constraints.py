"""Nonlinear (holonomic) constraints with Lagrange multipliers and Baumgarte stabilization.

A constraint is  g(Q) - b(t) = 0  with m rows acting on a subset of the coordinates.  The
model solves the index-1 form at acceleration level,

    [ M_r   C^T ] [ z_ddot ]   [ F_r                                              ]
    [ C     0   ] [ -lambda] = [ b_ddot - g_QQ[Q_dot, Q_dot] - g_Q Q_ddot_p
                                 - 2 xi1 (g_Q Q_dot - b_dot) - xi2^2 (g - b)    ]

with C = g_Q P (SIMULTECH 2020, Eq. 8: Phi_ddot + 2 xi1 Phi_dot + xi2^2 Phi = 0).  The quadratic
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

from sim_core.physics import _constraints_numba as constraint_compiled
from sim_core.physics import _rigid_body_numba as joint_compiled
from sim_core.physics._constraints_numba import DIFF_PSI, DIFF_R, DISTANCE, ROPE
from sim_core.physics.beam import _moving_node_beam_numba as point_compiled
from sim_core.physics.complex_step import COMPLEX_STEP

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
    # structured Jacobian (sim_core.model.state_jacobian) differentiates only those. None: unknown
    # (every coordinate is differenced)
    points: tuple | None = None
    # (kind, components, point functions) of sim_core.physics._constraints_numba, set by the factories
    # below: the rows as one compiled program (None: this constraint is evaluated in Python)
    program: tuple | None = None
    # (kind, vectors, frame functions) of the compiled joint rows of
    # sim_core.physics._rigid_body_numba (rigid frames: hinges, pins, prismatic joints), set by
    # the factories; None: not a joint row of that program
    joint_program: tuple | None = None

    def coords(self, Q: Vec) -> np.ndarray | None:
        """Coordinates g depends on at Q (None: possibly all)."""
        return None if self.points is None else dependencies(self.points, Q)

    def b(self, t: float):
        """(b, b_dot, b_ddot) at t (zeros without a target)."""
        if self.target is None:
            z = self.__dict__.get("_zeros")
            if z is None:
                z = self._zeros = np.zeros(self.m)
                z.flags.writeable = False
            return z, z, z
        return tuple(np.atleast_1d(np.asarray(x, float)) for x in self.target(t))



# material points: kinematics, rigid offset and the full-length Jacobians in one compiled call
# (point_compiled.point_full); False: the compiled kinematics and the rest in numpy (the
# reference of the tests)
POINTS_IN_ONE_CALL = True

# the rows of constraints built by the factories below as one compiled program
# (sim_core.physics._constraints_numba); False: each constraint's closure in Python (the reference)
COMPILED_ROWS = True


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
    real = not (np.iscomplexobj(Q) or np.iscomplexobj(Qd))
    if real and COMPILED_ROWS:
        prog = constraint_compiled.program_for(cons) or joint_compiled.joint_program_for(cons)
        if prog is not None:
            g, G, quad, _ = prog.terms(Q, Qd)
            b, bd, bdd = targets(cons, t)
            return g - b, G, G @ Qd - bd, bdd - quad
        part = _partition(cons)
        if part is not None:
            return _partitioned_terms(part, t, Q, Qd)
    return _python_terms(cons, t, Q, Qd, real)


def _partition(cons):
    """Where no compiled program covers the whole list (a turntable's joint rows beside the
    booms' contact rows): (the compiled program of the rows it covers, their row indices, the
    other constraints, their row indices), cached on the first constraint; None where the
    compiled part would be empty or everything."""
    key = tuple(id(c) for c in cons)
    hit = cons[0].__dict__.get("_partition")
    if hit is not None and hit[0] == key:
        return hit[1]
    kinds = ("material", "fixed")
    comp = [c for c in cons if c.program is not None
            and all(getattr(f, "spec", (None,))[0] in kinds for f in c.program[2])]
    rest = [c for c in cons if all(c is not x for x in comp)]
    part = None
    if comp and rest:
        prog = constraint_compiled.cached_program(comp, "_partial_program",
                                                  constraint_compiled._build)
        if prog is not None:
            starts = np.cumsum([0] + [c.m for c in cons])
            rows = {id(c): np.arange(starts[k], starts[k + 1]) for k, c in enumerate(cons)}
            part = (prog, comp, np.concatenate([rows[id(c)] for c in comp]), rest,
                    np.concatenate([rows[id(c)] for c in rest]), int(starts[-1]))
    cons[0].__dict__["_partition"] = (key, part)
    return part


def _partitioned_terms(part, t, Q, Qd):
    """constraint_terms from the compiled rows of a partition and the others in Python, in
    the list's row order."""
    prog, comp, r_comp, rest, r_rest, m = part
    g, G, quad, _ = prog.terms(Q, Qd)
    b, bd, bdd = targets(comp, t)
    phi, jac, dphi, rhs = (np.empty(m), np.empty((m, len(Q))), np.empty(m), np.empty(m))
    phi[r_comp], jac[r_comp], dphi[r_comp], rhs[r_comp] = g - b, G, G @ Qd - bd, bdd - quad
    phi[r_rest], jac[r_rest], dphi[r_rest], rhs[r_rest] = _python_terms(rest, t, Q, Qd, True)
    return phi, jac, dphi, rhs


def _python_terms(cons, t, Q, Qd, real):
    """constraint_terms of each constraint's closure: the Jacobian's real part and the
    quadratic velocity term g_QQ[Q_dot, Q_dot] from one complex-step evaluation."""
    phis, jacs, dphis, rhs = [], [], [], []
    Qc = Q + 1j * COMPLEX_STEP * Qd                  # one complex state: the point caches serve all rows
    for c in cons:
        gc, Jc = c.evaluate(Qc)
        if real:    # the real parts of a complex-step evaluation are the real evaluation
            g, J = gc.real, Jc.real        # (to O(h^2) = 1e-40 relative)
        else:
            g, J = c.evaluate(Q)
        quad = (Jc @ Qd).imag / COMPLEX_STEP
        b, bd, bdd = c.b(t)
        phis.append(np.real(g) - b)
        jacs.append(np.real(J))
        dphis.append(np.real(J) @ Qd - bd)
        rhs.append(bdd - quad)
    return (np.concatenate(phis), np.vstack(jacs), np.concatenate(dphis), np.concatenate(rhs))


def targets(cons: list[NonlinearConstraint], t: float):
    """Stacked (b, b_dot, b_ddot) of the constraints at t: the rows of constraints without a
    target stay zero, only those with one are evaluated (the row layout is cached on the
    list's first constraint, as :func:`constraint_compiled.program_for` caches the program)."""
    key = tuple(id(c) for c in cons)
    hit = cons[0].__dict__.get("_target_layout") if cons else None
    if hit is None or hit[0] != key:
        rows, at = 0, []
        for c in cons:
            if c.target is not None:
                at.append((rows, rows + c.m, c))
            rows += c.m
        hit = (key, rows, at)
        if cons:
            cons[0].__dict__["_target_layout"] = hit
    _, rows, at = hit
    out = np.zeros((3, rows))
    for a, b, c in at:
        for i, x in enumerate(c.target(t)):
            out[i, a:b] = x
    return out[0], out[1], out[2]


class StateMemo:
    """The last evaluation of a point function per number kind (real, complex), keyed by the
    values of the coordinates it depends on.  A real state equal to the real part of the last
    complex one is served from that evaluation's real parts (equal to the real evaluation to
    O(h^2) = 1e-40 relative for the complex step h = 1e-20), so constraint rows that need both
    evaluate a point once."""

    def __init__(self):
        self._memo: dict = {}

    def lookup(self, Q, cols):
        """(key, the stored result or None) for state Q with dependence on coordinates cols."""
        key = (cols.tobytes(), Q[cols].tobytes())
        kind = Q.dtype.kind
        hit = self._memo.get(kind)
        if hit is not None and hit[0] == key:
            return key, hit[1]
        if kind != "c":
            hit = self._memo.get("c")
            if hit is not None and hit[2] == key:
                res = tuple(np.ascontiguousarray(x.real) for x in hit[1])
                self._memo[kind] = (key, res, None)
                return key, res
        return key, None

    def store(self, Q, cols, key, res):
        """Keep res as the evaluation at Q (cols and key as given to and by :meth:`lookup`);
        returns res."""
        kind = Q.dtype.kind
        real_key = (key[0], Q[cols].real.tobytes()) if kind == "c" else None
        self._memo[kind] = (key, res, real_key)
        return res


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

    # the last real and the last complex evaluation, keyed on the coordinates the point depends
    # on and their values, so a state that differs elsewhere (another body's coordinate
    # perturbed for a Jacobian column) reuses the evaluation.  The real part of a complex-step
    # evaluation is the real evaluation (to O(h^2) = 1e-40 relative, far below round-off): a
    # real state equal to the real part of the last complex one is served from it, so the
    # constraint rows, which need both, evaluate the point once
    memo = StateMemo()

    def f(Q):
        e, idx, cols = locate(Q)
        key, res = memo.lookup(Q, cols)
        if res is None:
            res = memo.store(Q, cols, key, _evaluate(Q, e, idx))
        return res

    def _evaluate(Q, e, idx):
        s = Q[s_index] if s_index is not None else s_fixed
        el = beam.elements[e]
        if point_compiled.AVAILABLE and POINTS_IN_ONE_CALL:
            # kinematics, offset and the full-length Jacobians in one compiled call
            return point_compiled.point_full(el, Q, idx, s_index, s, o_sec, N)
        if point_compiled.AVAILABLE:                      # the same kinematics, compiled
            r, rp, J_r, J_psi, angles, psi_prime, frame, tmat = point_compiled.point_kinematics(
                el, Q[idx], s)
        else:
            kin = el.evaluate(Q[idx], s=np.array([s]), strains=False)
            r, rp, J_r, J_psi = kin.r[0], kin.rp[0], kin.J_r[0], kin.J_psi[0]
            sec = kin.sec
            angles, psi_prime, frame, tmat = (sec.angles[0], sec.psi_prime[0], sec.frame[0],
                                              sec.tmat[0])
        if o_sec is not None:                             # frame: rows e_t, e_b, e_s (global)
            o = o_sec[1] * frame[0] + o_sec[2] * frame[1] + o_sec[0] * frame[2]
            # small global rotation per dQ; tmat gives section components ordered (s, t, b);
            # on the element's columns (the s column below gets the same map through psi')
            R = frame[[2, 0, 1]].T @ tmat
            ox = np.array([[0.0, o[2], -o[1]], [-o[2], 0.0, o[0]], [o[1], -o[0], 0.0]],
                          dtype=R.dtype)                  # J += (R dpsi) x o = ox R dpsi
            oxR = ox @ R
            J_r = J_r + oxR @ J_psi
            rp = rp + oxR @ psi_prime
            r = r + o
        J = np.zeros((3, N), dtype=J_r.dtype)
        Jp = np.zeros((3, N), dtype=J_r.dtype)
        J[:, idx] = J_r
        Jp[:, idx] = J_psi
        if s_index is not None:
            J[:, s_index] += rp
            Jp[:, s_index] += psi_prime
        return r, J, angles, Jp

    # per element: its global indices, and the coordinates r and Psi depend on there (the
    # element's, and s_index if moving)
    where = [(off + imap, off + imap if s_index is None else np.append(off + imap, s_index))
             for imap in beam.index_map]
    for pair in where:                   # shared by every call: read-only
        for a in pair:
            a.flags.writeable = False

    def locate(Q):
        """(element, its global indices, the coordinates r and Psi depend on at Q)."""
        s = Q[s_index].real if s_index is not None else s_fixed
        e = model.element_at(ibeam, Q, float(s))
        return (e,) + where[e]

    def coords(Q):
        """The coordinates r and Psi depend on at Q: the element's, and s_index if moving."""
        return locate(Q)[2]

    f.coords = coords
    f.spec = ("material", model, ibeam, s_fixed, s_index, o_sec)   # constraint_compiled
    cache[key] = f
    return f


def fixed_point(r) -> Callable:
    """A point fixed in space (m): the point-function signature with zero Jacobians."""
    r = np.asarray(r, float)

    def f(Q):
        Z = np.zeros((3, len(Q)))
        return r, Z, np.zeros(3), Z
    f.coords = lambda Q: np.zeros(0, dtype=int)
    f.spec = ("fixed", r)                      # constraint_compiled
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
    pts = (fa,) if fb is None else (fa, fb)
    return NonlinearConstraint(name, 3, evaluate, None if fixed is None else _fixed(fixed),
                               points=pts,
                               program=(DIFF_PSI if part else DIFF_R, (0, 1, 2), pts),
                               joint_program=None if part or fb is None else
                               ("coincidence", (), pts))


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
    return NonlinearConstraint(name, 1, evaluate, length, points=(fa, fb),
                               program=(DISTANCE, (), (fa, fb)),
                               joint_program=("distance", (), (fa, fb)))


def rope_length(name: str, points, length: float) -> NonlinearConstraint:
    """Inextensible rope over frictionless point pulleys: sum |r_{i+1} - r_i| = L0 (m).

    The bilateral limit of :class:`sim_core.physics.point_effects.RopeDrive` (effects.rope_elasticity =
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
    return NonlinearConstraint(name, 1, evaluate, _fixed([length]), points=tuple(points),
                               program=(ROPE, (), tuple(points)))
