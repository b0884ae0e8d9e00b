"""Compiled (numba) rows of the point constraints of a model, and their structured-Jacobian
columns.

The constraint rows of the telescopic scene (Zhao-Qi-Wang 2024 Section 6, Eqs. 47-48:
centroids and Cardan angles coincide; the luffing and telescopic cylinders as distance drivers;
the inextensible rope as a sum of distances) are built in :mod:`sim_core.physics.constraints` from
material points (Eq. 6 with the moving contact coordinates of Section 5).  Evaluated in Python
they are 12 closures over two point functions each on every right-hand side and, column by
column in the structured Jacobian (:mod:`sim_core.model.state_jacobian`), about a thousand such
evaluations per Jacobian.  Here the same rows are one compiled program:

* every point once, at the complex-step state Q + i h Q_dot (h = 1e-20): r, its Jacobian,
  the Cardan angles and theirs on the point's own columns (its element's coordinates and
  its moving coordinate: :func:`sim_core.physics.beam._moving_node_beam_numba._point_local`, the same kernel
  as the Python path), and J Q_dot;
* per constraint its rows: a difference of components of two points (point or angle
  coincidence, a point fixed in space), a distance |r_a - r_b| (cylinders) or a sum of
  distances (rope); the value g and the Jacobian G = g_Q are the real parts, the quadratic
  velocity term g_QQ[Q_dot, Q_dot] = Im(G(Q + i h Q_dot) Q_dot) / h (as
  :func:`sim_core.physics.constraints.constraint_terms`), and Im(G(Q + i h Q_dot)) / h = g_QQ Q_dot
  (the structured Jacobian's rate columns);
* the Jacobian columns d/dQ_j of G^T lambda and of G Q_ddot - (b_ddot - g_QQ[Q_dot, Q_dot] -
  2 xi1 Phi_dot - xi2^2 Phi) by forward differences, re-evaluating only the points that depend
  on Q_j and the constraints that use them (the same steps and formulas as the Python pieces
  of :func:`sim_core.model.state_jacobian.state_jacobian`).

A constraint takes part when its factory (:func:`sim_core.physics.constraints.point_coincidence`,
``angle_coincidence``, ``distance_driver``, ``rope_length``, and a row selection of them) set
its ``program`` and all its points are material or fixed points; :func:`program_for` returns
None otherwise and the Python path runs (it stays the reference:
``tests/beam/test_constraint_compiled.py`` checks both agree).
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba
from sim_core.physics.beam import _cardan_numba as cardan_compiled
from sim_core.physics.beam import _moving_node_beam_numba as point_compiled
from sim_core.physics.complex_step import COMPLEX_STEP

DIFF_R, DIFF_PSI, DISTANCE, ROPE = 0, 1, 2, 3


def _eval_point(p, Qc, Qd, N, p_fixed, p_r, p_beam, p_sidx, p_sfix, p_off, p_hasoff,
                beam_first, beam_count, el_idx, el_right, n, D_all, pow_p, pow_t, bases, i_s1,
                R, J, PSI, JP, VR, VP, PC, PN):
    """Point p at the complex state Qc (= Q + i h Q_dot) into R, PSI, VR = J Qd, VP = JP Qd
    (complex) and its Jacobians on its own columns: J[p, :, k], JP[p, :, k] = d/dQ[PC[p, k]]
    for k < PN[p] (its element's coordinates, then its moving coordinate's column, which may
    repeat one of them: the rows add); returns the finite-check sum."""
    if p_fixed[p]:
        for i in range(3):
            R[p, i] = p_r[p, i]
            PSI[p, i] = 0.0
            VR[p, i] = 0.0
            VP[p, i] = 0.0
        PN[p] = 0
        return 0.0
    b = p_beam[p]
    sidx = p_sidx[p]
    s = Qc[sidx] if sidx >= 0 else p_sfix[p] + 0.0j
    e0 = beam_first[b]
    e = e0 + beam_count[b] - 1                     # Model.element_at
    for k in range(beam_count[b] - 1):
        if s.real < Qc[el_right[e0 + k]].real:
            e = e0 + k
            break
    o_sec = p_off[p] if p_hasoff[p] else p_off[p, :0]
    idx = el_idx[e]
    nq = idx.shape[0]
    r, Jr, ang, Jpsi, rp, psi_p, total = _point_local(Qc, idx, s, o_sec, n, D_all, pow_p,
                                                      pow_t, bases[e], i_s1)
    for k in range(nq):
        PC[p, k] = idx[k]
    PN[p] = nq
    if sidx >= 0:
        PC[p, nq] = sidx
        PN[p] = nq + 1
    for i in range(3):
        R[p, i] = r[i]
        PSI[p, i] = ang[i]
        vr = 0.0j
        vp = 0.0j
        for k in range(nq):
            J[p, i, k] = Jr[i, k]
            JP[p, i, k] = Jpsi[i, k]
            vr += Jr[i, k] * Qd[idx[k]]
            vp += Jpsi[i, k] * Qd[idx[k]]
        if sidx >= 0:
            J[p, i, nq] = rp[i]
            JP[p, i, nq] = psi_p[i]
            vr += rp[i] * Qd[sidx]
            vp += psi_p[i] * Qd[sidx]
        VR[p, i] = vr
        VP[p, i] = vp
    return total


def _eval_constraint(c, N, c_kind, c_row0, c_nrow, c_comp, c_pts, c_npts, R, J, PSI, JP, VR,
                     VP, PC, PN, g, Gc, quad_c):
    """Rows of constraint c from the point arrays: g (real), Gc (complex Jacobian rows, the
    points' own columns added in), quad_c = Gc Q_dot (complex; its imaginary part / h is
    g_QQ[Q_dot, Q_dot])."""
    kind = c_kind[c]
    r0 = c_row0[c]
    for i in range(c_nrow[c]):
        for k in range(N):
            Gc[r0 + i, k] = 0.0
    if kind == DIFF_R or kind == DIFF_PSI:
        a = c_pts[c, 0]
        bb = c_pts[c, 1] if c_npts[c] > 1 else -1
        X = R if kind == DIFF_R else PSI
        JX = J if kind == DIFF_R else JP
        VX = VR if kind == DIFF_R else VP
        for i in range(c_nrow[c]):
            comp = c_comp[c, i]
            row = r0 + i
            val = X[a, comp]
            v = VX[a, comp]
            for k in range(PN[a]):
                Gc[row, PC[a, k]] += JX[a, comp, k]
            if bb >= 0:
                val = val - X[bb, comp]
                v = v - VX[bb, comp]
                for k in range(PN[bb]):
                    Gc[row, PC[bb, k]] -= JX[bb, comp, k]
            g[row] = val.real
            quad_c[row] = v
        return
    # DISTANCE (two points) and ROPE (a chain): sum of |r_{i+1} - r_i| (a distance driver's
    # |r_a - r_b| is the chain b -> a)
    total = 0.0j
    v = 0.0j
    d = np.empty(3, dtype=np.complex128)
    for q in range(c_npts[c] - 1):
        if kind == DISTANCE:
            pa, pb = c_pts[c, 1], c_pts[c, 0]      # d = r_a - r_b
        else:
            pa, pb = c_pts[c, q], c_pts[c, q + 1]  # d = r_{q+1} - r_q
        for i in range(3):
            d[i] = R[pb, i] - R[pa, i]
        nn = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        total += nn
        for i in range(3):
            u = d[i] / nn
            v += u * (VR[pb, i] - VR[pa, i])
            for k in range(PN[pb]):
                Gc[r0, PC[pb, k]] += u * J[pb, i, k]
            for k in range(PN[pa]):
                Gc[r0, PC[pa, k]] -= u * J[pa, i, k]
    g[r0] = total.real
    quad_c[r0] = v


def _program_terms(Q, Qd, P, N, p_fixed, p_r, p_beam, p_sidx, p_sfix, p_off, p_hasoff,
                   beam_first, beam_count, el_idx, el_right, n, D_all, pow_p, pow_t, bases,
                   i_s1, c_kind, c_row0, c_nrow, c_comp, c_pts, c_npts, m, cstep):
    """All points and rows at (Q, Q_dot): (g (m,), Gc (m, N) complex, quad_c (m,) complex,
    point arrays, finite-check sum)."""
    Qc = np.empty(N, dtype=np.complex128)
    for k in range(N):
        Qc[k] = Q[k] + 1j * (cstep * Qd[k])
    R = np.empty((P, 3), dtype=np.complex128)
    PSI = np.empty((P, 3), dtype=np.complex128)
    VR = np.empty((P, 3), dtype=np.complex128)
    VP = np.empty((P, 3), dtype=np.complex128)
    L = el_idx.shape[1] + 1                  # a point's columns: its element's and its s
    J = np.zeros((P, 3, L), dtype=np.complex128)
    JP = np.zeros((P, 3, L), dtype=np.complex128)
    PC = np.zeros((P, L), dtype=np.int64)
    PN = np.zeros(P, dtype=np.int64)
    total = 0.0
    for p in range(P):
        total += _eval_point(p, Qc, Qd, N, p_fixed, p_r, p_beam, p_sidx, p_sfix, p_off,
                             p_hasoff, beam_first, beam_count, el_idx, el_right, n, D_all,
                             pow_p, pow_t, bases, i_s1, R, J, PSI, JP, VR, VP, PC, PN)
    g = np.zeros(m)
    Gc = np.zeros((m, N), dtype=np.complex128)
    quad_c = np.zeros(m, dtype=np.complex128)
    for c in range(c_kind.shape[0]):
        _eval_constraint(c, N, c_kind, c_row0, c_nrow, c_comp, c_pts, c_npts, R, J, PSI, JP,
                         VR, VP, PC, PN, g, Gc, quad_c)
    return g, Gc, quad_c, Qc, R, J, PSI, JP, VR, VP, PC, PN, total


def _terms(Q, Qd, P, N, p_fixed, p_r, p_beam, p_sidx, p_sfix, p_off, p_hasoff, beam_first,
           beam_count, el_idx, el_right, n, D_all, pow_p, pow_t, bases, i_s1, c_kind, c_row0,
           c_nrow, c_comp, c_pts, c_npts, m, cstep, rate_part):
    """(g, G (m, N), quad (m,), G_rate (m, N) or (0, N), finite-check sum): G = Re Gc,
    quad = Im(quad_c) / h, G_rate = Im(Gc) / h (with ``rate_part``)."""
    g, Gc, quad_c, _, _, _, _, _, _, _, _, _, total = _program_terms(
        Q, Qd, P, N, p_fixed, p_r, p_beam, p_sidx, p_sfix, p_off, p_hasoff, beam_first,
        beam_count, el_idx, el_right, n, D_all, pow_p, pow_t, bases, i_s1, c_kind, c_row0,
        c_nrow, c_comp, c_pts, c_npts, m, cstep)
    G = np.empty((m, N))
    Gr = np.empty((m if rate_part else 0, N))
    quad = np.empty(m)
    for i in range(m):
        quad[i] = quad_c[i].imag / cstep
        for k in range(N):
            G[i, k] = Gc[i, k].real
            if rate_part:
                Gr[i, k] = Gc[i, k].imag / cstep
    return g, G, quad, Gr, total


def _columns(Q, Qd, Qdd, lam, b0, bd, bdd, xi1, xi2, cols, steps, P, N, p_fixed, p_r, p_beam,
             p_sidx, p_sfix, p_off, p_hasoff, beam_first, beam_count, el_idx, el_right, n,
             D_all, pow_p, pow_t, bases, i_s1, c_kind, c_row0, c_nrow, c_comp, c_pts, c_npts,
             m, cstep, p_deps):
    """Forward-difference columns j in ``cols`` (steps ``steps``) of r1 = G^T lambda (N,) and
    r2 = G Q_ddot - (b_ddot - g_QQ[Q_dot, Q_dot] - 2 xi1 (G Q_dot - b_dot) - xi2^2 (g - b))
    (m,): (dR1 (N, ncols), dR2 (m, ncols), finite-check sum).  ``p_deps`` (P, N) bool: the
    coordinates each point depends on at Q."""
    g0, Gc0, qc0, Qc, R, J, PSI, JP, VR, VP, PC, PN, total = _program_terms(
        Q, Qd, P, N, p_fixed, p_r, p_beam, p_sidx, p_sfix, p_off, p_hasoff, beam_first,
        beam_count, el_idx, el_right, n, D_all, pow_p, pow_t, bases, i_s1, c_kind, c_row0,
        c_nrow, c_comp, c_pts, c_npts, m, cstep)
    K = c_kind.shape[0]
    r2_0 = np.empty(m)
    for i in range(m):
        gq = 0.0
        gd = 0.0
        for k in range(N):
            gq += Gc0[i, k].real * Qdd[k]
            gd += Gc0[i, k].real * Qd[k]
        r2_0[i] = gq - (bdd[i] - qc0[i].imag / cstep - 2.0 * xi1 * (gd - bd[i])
                        - xi2 * xi2 * (g0[i] - b0[i]))
    ncol = cols.shape[0]
    dR1 = np.zeros((N, ncol))
    dR2 = np.zeros((m, ncol))
    # scratch copies of the point arrays and rows, restored after each column
    R1, J1, PSI1, JP1, VR1, VP1 = R.copy(), J.copy(), PSI.copy(), JP.copy(), VR.copy(), VP.copy()
    PC1, PN1 = PC.copy(), PN.copy()
    g1 = g0.copy()
    Gc1 = Gc0.copy()
    qc1 = qc0.copy()
    Qx = Q.copy()
    uses = np.zeros(K, dtype=np.bool_)
    hit = np.zeros(P, dtype=np.bool_)
    for jj in range(ncol):
        j = cols[jj]
        h = steps[jj]
        nhit = 0
        for p in range(P):
            hit[p] = p_deps[p, j]
            if hit[p]:
                nhit += 1
        if nhit == 0:
            continue
        x = Q[j]
        Qx[j] = x + h
        Qc[j] = Qx[j] + 1j * (cstep * Qd[j])
        for p in range(P):
            if hit[p]:
                total += _eval_point(p, Qc, Qd, N, p_fixed, p_r, p_beam, p_sidx, p_sfix,
                                     p_off, p_hasoff, beam_first, beam_count, el_idx,
                                     el_right, n, D_all, pow_p, pow_t, bases, i_s1, R1, J1,
                                     PSI1, JP1, VR1, VP1, PC1, PN1)
        for c in range(K):
            uses[c] = False
            for q in range(c_npts[c]):
                if hit[c_pts[c, q]]:
                    uses[c] = True
            if not uses[c]:
                continue
            _eval_constraint(c, N, c_kind, c_row0, c_nrow, c_comp, c_pts, c_npts, R1, J1,
                             PSI1, JP1, VR1, VP1, PC1, PN1, g1, Gc1, qc1)
            for i in range(c_row0[c], c_row0[c] + c_nrow[c]):
                li = lam[i] / h
                gq = 0.0
                gd = 0.0
                for k in range(N):
                    gnew = Gc1[i, k].real
                    dR1[k, jj] += li * (gnew - Gc0[i, k].real)
                    gq += gnew * Qdd[k]
                    gd += gnew * Qd[k]
                r2 = gq - (bdd[i] - qc1[i].imag / cstep - 2.0 * xi1 * (gd - bd[i])
                           - xi2 * xi2 * (g1[i] - b0[i]))
                dR2[i, jj] = (r2 - r2_0[i]) / h
        # restore
        Qx[j] = x
        Qc[j] = x + 1j * (cstep * Qd[j])
        for p in range(P):
            if hit[p]:
                for i in range(3):
                    R1[p, i] = R[p, i]
                    PSI1[p, i] = PSI[p, i]
                    VR1[p, i] = VR[p, i]
                    VP1[p, i] = VP[p, i]
                    for k in range(PN[p]):
                        J1[p, i, k] = J[p, i, k]
                        JP1[p, i, k] = JP[p, i, k]
                PN1[p] = PN[p]
                for k in range(PN[p]):
                    PC1[p, k] = PC[p, k]
    return dR1, dR2, total


if AVAILABLE:
    _point_local = point_compiled.compiled_point_local
    _jit = numba.njit(cache=True, nogil=True)
    _eval_point = _jit(_eval_point)
    _eval_constraint = _jit(_eval_constraint)
    _program_terms = _jit(_program_terms)
    _terms_compiled = _jit(_terms)
    _columns_compiled = _jit(_columns)


class ConstraintProgram:
    """The point and row tables of a constraint list (see the module docstring); build with
    :func:`program_for`."""

    def __init__(self, model, points, cons):
        beams, offsets = model.beams, model.offsets
        els = [el for b in beams for el in b.elements]
        el0 = els[0]
        self.N = int(model.n_coords)
        self.n, self.i_s1 = int(el0.n), int(el0.i_s1)
        self.D_all = np.ascontiguousarray(el0.D_all, dtype=float)
        self.pow_p = np.ascontiguousarray(el0.pow_p)
        self.pow_t = np.ascontiguousarray(el0.pow_t)
        self.bases = np.ascontiguousarray(np.stack([el.G for el in els]), dtype=float)
        self.el_idx = np.stack([np.asarray(off + imap, dtype=np.int64)
                                for b, off in zip(beams, offsets) for imap in b.index_map])
        right, first, count = [], [], []
        for b, off in zip(beams, offsets):
            first.append(len(right))
            count.append(len(b.elements))
            right += [int(off + b.s_coord(e + 1)) for e in range(len(b.elements) - 1)] + [-1]
        self.el_right = np.array(right, dtype=np.int64)
        self.beam_first = np.array(first, dtype=np.int64)
        self.beam_count = np.array(count, dtype=np.int64)
        P = len(points)
        self.P = P
        self.points = points
        self.p_fixed = np.zeros(P, dtype=np.bool_)
        self.p_r = np.zeros((P, 3))
        self.p_beam = np.zeros(P, dtype=np.int64)
        self.p_sidx = np.full(P, -1, dtype=np.int64)
        self.p_sfix = np.zeros(P)
        self.p_off = np.zeros((P, 3))
        self.p_hasoff = np.zeros(P, dtype=np.bool_)
        for i, f in enumerate(points):
            spec = f.spec
            if spec[0] == "fixed":
                self.p_fixed[i] = True
                self.p_r[i] = spec[1]
                continue
            _, _, ibeam, s_fixed, s_index, o_sec = spec
            self.p_beam[i] = ibeam
            if s_index is not None:
                self.p_sidx[i] = int(s_index)
            else:
                self.p_sfix[i] = float(s_fixed)
            if o_sec is not None:
                self.p_off[i] = o_sec
                self.p_hasoff[i] = True
        where = {id(f): i for i, f in enumerate(points)}
        K = len(cons)
        self.m = int(sum(c.m for c in cons))
        npts = max(len(c.program[2]) for c in cons)
        self.c_kind = np.zeros(K, dtype=np.int64)
        self.c_row0 = np.zeros(K, dtype=np.int64)
        self.c_nrow = np.zeros(K, dtype=np.int64)
        self.c_comp = np.zeros((K, 3), dtype=np.int64)
        self.c_pts = np.zeros((K, max(npts, 2)), dtype=np.int64)
        self.c_npts = np.zeros(K, dtype=np.int64)
        row = 0
        for k, c in enumerate(cons):
            kind, comps, pts = c.program
            self.c_kind[k] = kind
            self.c_row0[k] = row
            self.c_nrow[k] = c.m
            self.c_comp[k, :len(comps)] = comps
            self.c_pts[k, :len(pts)] = [where[id(f)] for f in pts]
            self.c_npts[k] = len(pts)
            row += c.m

    def _args(self):
        return (self.P, self.N, self.p_fixed, self.p_r, self.p_beam, self.p_sidx, self.p_sfix,
                self.p_off, self.p_hasoff, self.beam_first, self.beam_count, self.el_idx,
                self.el_right, self.n, self.D_all, self.pow_p, self.pow_t, self.bases,
                self.i_s1, self.c_kind, self.c_row0, self.c_nrow, self.c_comp, self.c_pts,
                self.c_npts, self.m, COMPLEX_STEP)

    def terms(self, Q, Qd, rate_part: bool = False):
        """(g (m,) without the targets b, G = g_Q (m, N), g_QQ[Q_dot, Q_dot] (m,), and with
        ``rate_part`` d/dQ_dot of g_QQ[Q_dot, Q_dot] / 2 = g_QQ Q_dot (m, N), else None) at
        the real state (Q, Q_dot)."""
        Q = np.ascontiguousarray(Q, dtype=float)
        Qd = np.ascontiguousarray(Qd, dtype=float)
        g, G, quad, Gr, total = _terms_compiled(Q, Qd, *self._args(), bool(rate_part))
        cardan_compiled.check_finite(total, "constraint points")
        return g, G, quad, (Gr if rate_part else None)

    def dependencies(self, Q) -> np.ndarray:
        """(P, N) bool: the coordinates each point depends on at Q (its ``coords``: a
        material point's element and moving coordinate, none for a fixed point)."""
        deps = np.zeros((self.P, self.N), dtype=np.bool_)
        for p, f in enumerate(self.points):
            deps[p, f.coords(Q)] = True
        return deps

    def columns(self, Q, Qd, Qdd, lam, b0, bd, bdd, xi1, xi2, cols, steps, deps=None):
        """Forward-difference columns ``cols`` (steps ``steps``) of G^T lambda (N, ncols) and
        of the acceleration-level rows (m, ncols), see _columns; ``deps``: the points'
        :meth:`dependencies` at Q where the caller has them."""
        f = np.ascontiguousarray
        deps = self.dependencies(Q) if deps is None else deps
        dR1, dR2, total = _columns_compiled(
            f(Q, dtype=float), f(Qd, dtype=float), f(Qdd, dtype=float), f(lam, dtype=float),
            f(b0, dtype=float), f(bd, dtype=float), f(bdd, dtype=float), float(xi1),
            float(xi2), f(cols, dtype=np.int64), f(steps, dtype=float), *self._args(), deps)
        cardan_compiled.check_finite(total, "constraint points")
        return dR1, dR2


def program_for(cons) -> ConstraintProgram | None:
    """The compiled program of a constraint list (cached on its first constraint, rebuilt when
    the list changes), or None where it does not cover the list: numba missing, a constraint
    without ``program``, a point that is neither a material nor a fixed point, points of more
    than one model, or elements with unequal tables."""
    return cached_program(cons, "_compiled_program", _build)


def cached_program(cons, slot: str, build):
    """``build(cons)`` cached on the list's first constraint under ``slot`` and rebuilt when
    the list changes; None without numba or constraints."""
    if not AVAILABLE or not cons:
        return None
    key = tuple(id(c) for c in cons)
    hit = cons[0].__dict__.get(slot)
    if hit is not None and hit[0] == key:
        return hit[1]
    prog = build(cons)
    cons[0].__dict__[slot] = (key, prog)
    return prog


def program_points(cons, attr: str, kinds: tuple, model_kind: str):
    """(the point functions of the constraints' ``attr`` programs in first-use order, their
    model) or None where a constraint has no such program, a point's ``spec`` kind is not in
    ``kinds``, or the points of kind ``model_kind`` belong to more than one model (or none)."""
    points, seen, model = [], set(), None
    for c in cons:
        spec = getattr(c, attr, None)
        if spec is None:
            return None
        for f in spec[2]:
            s = getattr(f, "spec", None)
            if s is None or s[0] not in kinds:
                return None
            if s[0] == model_kind:
                if model is None:
                    model = s[1]
                elif s[1] is not model:
                    return None
            if id(f) not in seen:
                seen.add(id(f))
                points.append(f)
    return None if model is None else (points, model)


def equal_element_tables(model) -> bool:
    """Whether every element of the model has the first one's tables (one compiled kernel
    call serves all)."""
    els = [el for b in model.beams for el in b.elements]
    el0 = els[0]
    return all(el.n == el0.n and el.i_s1 == el0.i_s1 and len(el.G) == 3
               and np.array_equal(el.D_all, el0.D_all)
               and np.array_equal(el.pow_p, el0.pow_p)
               and np.array_equal(el.pow_t, el0.pow_t) for el in els)


def _build(cons):
    found = program_points(cons, "program", ("material", "fixed"), "material")
    if found is None or not equal_element_tables(found[1]):
        return None
    points, model = found
    return ConstraintProgram(model, points, cons)
