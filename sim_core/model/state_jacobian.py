"""Jacobian of the state equations by implicit differentiation and local finite differences.

The integrated system is y = (z, z_dot), y' = (z_dot, z_ddot(t, z, z_dot)), where z_ddot and the
constraint multipliers lambda solve the index-1 saddle-point system of :class:`sim_core.model.model.
Model` (constraint rows g(Q) = b(t), Baumgarte terms xi1, xi2; SIMULTECH 2020 Eq. 8), with the
multiplier-dependent friction forces of Zhao-Qi-Wang 2024 Section 8.3 in the force vector:

    R1 = P^T [ F(Q, Q_dot) + F_mu(Q, Q_dot, lambda) - M(Q) Q_ddot + G(Q)^T lambda ] = 0
    R2 = G(Q) Q_ddot - (b_ddot - g_QQ[Q_dot, Q_dot] - 2 xi1 Phi_dot - xi2^2 Phi)     = 0

with Q = Q_p(t) + P z, Q_ddot = Q_ddot_p(t) + P z_ddot, G = g_Q.  By the implicit function
theorem, with u = (z_ddot, lambda),

    du/dy = -[dR/du]^-1 dR/dy,   dR/du = [[-M_r, C^T + P^T dF_mu/dlambda], [C, 0]],  C = G P.

dR/dy is a sum of *local* pieces at frozen (Q_ddot, lambda): each element's F_e - M_e Q_ddot,e
depends only on the element's coordinates, each constraint row only on the elements of its
points (``NonlinearConstraint.coords``), the payload, ropes and friction only on their points'.
Each piece is forward-differenced in its own coordinates, so a Jacobian costs about
2 x (coordinates per element) element evaluations per element instead of 2 n_dof evaluations
of the whole right-hand side (scipy BDF's ``num_jac``): at the paper's 8 sub-elements the
telescopic Jacobian costs ~100 right-hand sides instead of ~880 (measured in
``benchmarks/jacobian_speed.py``).  Pieces that do not say which coordinates they depend on are
differenced in all of them (correct, only slower).  Checked against central differences of the
whole right-hand side in ``tests/integrators/test_state_jacobian.py``.  The friction's multiplier
derivative dF_mu/dlambda is analytic (the micro-motion sensitivity of the friction Newton,
:class:`sim_core.physics.contact.friction.FrictionAtState`).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from sim_core.physics._constraints_numba import program_for
from sim_core.physics._rigid_body_numba import joint_program_for
from sim_core.physics.complex_step import COMPLEX_STEP
from sim_core.physics.constraints import _partition, constraint_terms, targets

REL_STEP = 1.5e-8                # ~sqrt(machine epsilon): forward-difference step per unit of |x|
# the constraint pieces' columns in one compiled sweep (sim_core.physics._constraints_numba) where the
# constraints are covered; False: column by column in Python (the reference)
COMPILED_CONSTRAINT_COLUMNS = True


def _steps(x: np.ndarray, rel_step: float) -> np.ndarray:
    h = rel_step * np.maximum(np.abs(x), 1.0)
    return (x + h) - x                    # exactly representable steps


def _difference(fun, x: np.ndarray, cols, rel_step: float, central: bool = False):
    """Forward (or central) differences of fun() (an array that reads ``x``) with respect to
    x[cols]: shape (fun's shape, len(cols)).  x is perturbed in place and restored."""
    base = None if central else fun()
    d = None
    for k, (j, h) in enumerate(zip(cols, _steps(x[cols], rel_step))):
        xj = x[j]
        x[j] = xj + h
        up = fun()
        if central:
            x[j] = xj - h
            lo = fun()
        x[j] = xj
        if d is None:
            d = np.empty(np.shape(up) + (len(cols),))
        d[..., k] = (up - lo) / (2.0 * h) if central else (up - base) / h
    return d if d is not None else np.zeros(np.shape(fun()) + (0,))


def state_jacobian(model, t: float, y: np.ndarray, rel_step: float = REL_STEP,
                   central: bool = False, return_cost: bool = False):
    """d y' / d y (2 n_dof x 2 n_dof) of ``model.rhs`` at (t, y); see the module docstring.
    ``central``: central instead of forward differences (twice the work; truncation error
    O(h^2) instead of O(h), for checks).  With ``return_cost`` also the cost in whole
    right-hand-side evaluations."""
    n = model.n_dof
    y = np.asarray(y, dtype=float)
    z, zd = y[:n], y[n:]
    zdd, lam = model.accelerations_and_multipliers(t, z, zd)
    Q, Qd = model.full_state(t, z, zd)
    Qdd = model.lift(t, zdd, 2)
    dR1, dR2, G, cost = residual_derivatives(model, t, Q, Qd, Qdd, lam, rel_step, central)
    N, m = model.n_coords, len(lam)

    dF_dlam = np.zeros((N, m))
    for mf in model.multiplier_forces:
        if hasattr(mf, "at_state"):         # analytic: F_mu = E g(lambda), the friction Newton's
            at = mf.at_state(t, Q, Qd)
            np.add.at(dF_dlam, at.coords, at.values(lam, gradient=True)[1])
            continue
        lx = lam.copy()
        dF_dlam += _difference(lambda mf=mf: mf.forces(t, Q, Qd, lx), lx, np.arange(m),
                               rel_step, central)

    # reduced coordinates and the saddle-point solve (X P and P^T X by Model._times_P: a signed
    # selection where P only selects coordinates)
    XP = model._times_P

    def PtXP(X):
        return XP(XP(X).T).T

    Mr, _ = model.reduced_mass_force(t, z, zd)
    if m:
        if G is None:
            G = constraint_terms(model.nonlinear, t, Q, Qd)[1]
        C = XP(G)
    else:
        C = np.zeros((0, n))
    A = np.zeros((n + m, n + m))
    A[:n, :n] = -Mr
    A[:n, n:] = C.T + XP(dF_dlam.T).T
    A[n:, :n] = C
    B = np.empty((n + m, 2 * n))
    B[:n, :n] = PtXP(dR1[:, :N])
    B[:n, n:] = PtXP(dR1[:, N:])
    B[n:, :n] = XP(dR2[:, :N])
    B[n:, n:] = XP(dR2[:, N:])
    dU = -sla.solve(A, B)
    jac = np.zeros((2 * n, 2 * n))
    jac[:n, n:] = np.eye(n)
    jac[n:] = dU[:n]
    if return_cost:
        return jac, cost
    return jac


def residual_derivatives(model, t: float, Q: np.ndarray, Qd: np.ndarray, Qdd: np.ndarray,
                         lam: np.ndarray, rel_step: float = REL_STEP, central: bool = False,
                         friction: bool = True, rates: bool = True):
    """(dR1 (N, 2N), dR2 (m, 2N), G or None, cost): the derivatives of the residuals R1 (before
    the reduction by P) and R2 of the module docstring with respect to (Q, Q_dot) at frozen
    (Q_ddot, lambda), summed from the local pieces; G = g_Q where the compiled constraint sweep
    forms it; cost in whole right-hand-side evaluations.  ``friction=False`` leaves out the
    multiplier-dependent friction forces (the statics' residual has none); ``rates=False`` skips
    the Q_dot columns (left zero) where only the position tangent is wanted.  At Q_dot = Q_ddot = 0
    the Q columns of dR1 are the tangent of the static residual F(Q) + G^T lambda
    (:func:`sim_core.model.statics.structured_force_tangent`)."""
    N = model.n_coords
    Q, Qd = np.array(Q, dtype=float), np.array(Qd, dtype=float)
    m = len(lam)
    dR1 = np.zeros((N, 2 * N))            # d/d(Q, Q_dot) of F + F_mu - M Q_ddot + G^T lambda
    dR2 = np.zeros((m, 2 * N))            # d/d(Q, Q_dot) of G Q_ddot - rhs
    n_el = 0
    el_evals = 0

    # elements: F_e(q_e, qd_e) - M_e(q_e) qdd_e in the element's own coordinates; the rate
    # columns skip the mass matrix (M_e does not depend on rates), and on the numpy path reuse
    # the position-level kinematics
    # the compiled batch of all elements' columns (on the worker thread, while the point pieces
    # below are differenced on this one), else element by element here.  The compiled sweeps
    # take forward steps; a central difference is the mean of the sweeps with steps +h and -h:
    # (f(x + h) - f(x)) / h and (f(x - h) - f(x)) / (-h) average to (f(x + h) - f(x - h)) / 2h
    signs = (1.0, -1.0) if central else (1.0,)
    weight = 1.0 / len(signs)

    def signed_steps(sign):
        return lambda x: sign * _steps(x, rel_step)

    batch = model._element_differences_started(Q, Qd, Qdd, signed_steps(1.0), rates)
    for el, idx in ([] if batch is not None else model.element_indices()):
        qdde = Qdd[idx]
        qe, qde = Q[idx].copy(), Qd[idx].copy()
        kin0 = None if model.element_terms_compiled(el) else model.element_kinematics(el, qe)

        def by_position(el=el, qe=qe, qde=qde, qdde=qdde):
            return model.element_residual(t, el, qe, qde, qdde)

        def by_rate(el=el, qe=qe, qde=qde, kin=kin0):
            return model.element_terms(t, el, qe, qde, mass=False, kin=kin)[1]

        cols = np.arange(len(idx))
        dR1[np.ix_(idx, idx)] += _difference(by_position, qe, cols, rel_step, central)
        if rates:
            dR1[np.ix_(idx, N + idx)] += _difference(by_rate, qde, cols, rel_step, central)
        n_el += 1
        el_evals += (2 if central else 1) * (2 if rates else 1) * len(idx) + 1

    # pieces acting through points (point loads, payload, ropes, constraints, friction): each
    # says which coordinates it depends on; they are differenced column by column together, so
    # a point shared by several pieces is evaluated once per column (its cache is keyed on its
    # own coordinates, sim_core.physics.constraints.material_point)
    pieces = []                            # (Q columns, Q_dot columns, fun -> (r1 (N,), r2), rows)

    def cols_of(obj, attr="coords"):
        c = getattr(obj, attr)(Q) if hasattr(obj, attr) else None
        return np.arange(N) if c is None else np.asarray(c, dtype=int)

    for pl in model.point_loads:           # J_r(s)^T f at the element that holds the load point
        beam, off = model.beams[pl.beam], model.offsets[pl.beam]
        e = model.element_at(pl.beam, Q, float(pl.s_of_t(t)))

        def point_load(Qx, Qdx, pl=pl):
            F = np.zeros(N)
            model._add_point_load(pl, t, Qx, F)
            return F, None
        pieces.append((off + beam.index_map[e], np.zeros(0, int), point_load, None))

    # payload and ropes in one compiled program (point_effects.CompiledPointEffects.jacobian)
    # where it covers them, else as pieces below
    pe_batch = model._compiled_point_effects()
    for sign in (signs if pe_batch is not None else ()):
        dQ, dQd = pe_batch.jacobian(Q, Qd, Qdd, signed_steps(sign))
        dR1[:, :N] += weight * dQ
        dR1[:, N:] += weight * dQd
    # F_pe - M_pe Q_ddot of the effects outside the compiled program (slider seats)
    for pe in (pe_batch.uncompiled if pe_batch is not None else model.point_effects):
        def point_effect(Qx, Qdx, pe=pe):
            F = np.zeros(N)
            if hasattr(pe, "local"):           # a block on a few coordinates
                idx, Me, Fe = pe.local(t, Qx, Qdx)
                F[idx] = Fe if Me is None else Fe - Me @ Qdd[idx]
                return F, None
            M = np.zeros((N, N))
            pe.add(t, Qx, Qdx, M, F)
            return F - M @ Qdd, None
        pieces.append((cols_of(pe), cols_of(pe, "velocity_coords"), point_effect, None))

    # constraints: G^T lambda and G Q_ddot - (b_ddot - g_QQ[Qd, Qd] - 2 xi1 Phi_dot - xi2^2 Phi);
    # their Q_dot derivatives are exact: d/dQ_dot of g_QQ[Qd, Qd] = 2 (dG/dQ . Qd), the imaginary
    # part of the complex-step Jacobian G(Q + i h Q_dot) / h
    xi1, xi2 = model.baumgarte
    row = 0
    prog = ((program_for(model.nonlinear) or joint_program_for(model.nonlinear))
            if COMPILED_CONSTRAINT_COLUMNS else None)
    G = None                               # g_Q at (Q, Q_dot), where the sweep forms it
    if prog is not None:        # all constraint pieces in one compiled sweep (same differences)
        b0, bd, bdd = targets(model.nonlinear, t)
        deps = prog.dependencies(Q)
        cols = np.flatnonzero(deps.any(axis=0))
        for sign in signs:
            d1, d2 = prog.columns(Q, Qd, Qdd, lam, b0, bd, bdd, xi1, xi2, cols,
                                  signed_steps(sign)(Q[cols]), deps)
            dR1[:, cols] += weight * d1
            dR2[:, cols] += weight * d2
        _, G, _, G_rate = prog.terms(Q, Qd, rate_part=True)     # d/dQ_dot as below
        dR2[:, N:] += 2.0 * G_rate + 2.0 * xi1 * G
    # where no program covers every row (a turntable's joints beside the booms' contact rows):
    # the rows a compiled program covers in its sweep, the others as pieces below
    part = (_partition(model.nonlinear) if prog is None and COMPILED_CONSTRAINT_COLUMNS
            and model.nonlinear else None)
    python_rows = model.nonlinear if prog is None else []
    if part is not None:
        pc, comp, r_comp, python_rows, _, _ = part
        b0, bd, bdd = targets(comp, t)
        deps = pc.dependencies(Q)
        cols = np.flatnonzero(deps.any(axis=0))
        for sign in signs:
            d1, d2 = pc.columns(Q, Qd, Qdd, lam[r_comp], b0, bd, bdd, xi1, xi2, cols,
                                signed_steps(sign)(Q[cols]), deps)
            dR1[:, cols] += weight * d1
            dR2[np.ix_(r_comp, cols)] += weight * d2
        _, Gc, _, Gc_rate = pc.terms(Q, Qd, rate_part=True)
        dR2[r_comp, N:] += 2.0 * Gc_rate + 2.0 * xi1 * Gc
    starts = np.cumsum([0] + [c.m for c in model.nonlinear])
    first = {id(c): int(starts[k]) for k, c in enumerate(model.nonlinear)}
    for c in python_rows:
        row = first[id(c)]
        sl = slice(row, row + c.m)
        b0, bd, bdd = c.b(t)

        def constraint(Qx, Qdx, c=c, lam_c=lam[sl], b0=b0, bd=bd, bdd=bdd):
            # one complex-step evaluation: its real parts are the real evaluation (to O(h^2) =
            # 1e-40 relative, as in constraints.constraint_terms), so no point is evaluated twice
            gc, Jc = c.evaluate(Qx + 1j * COMPLEX_STEP * Qdx)
            g, J = gc.real, Jc.real
            quad = (Jc @ Qdx).imag / COMPLEX_STEP
            rhs = bdd - quad - 2.0 * xi1 * (J @ Qdx - bd) - xi2 ** 2 * (g - b0)
            return J.T @ lam_c, J @ Qdd - rhs
        pieces.append((cols_of(c), np.zeros(0, int), constraint, sl))
        _, Jc = c.evaluate(Q + 1j * COMPLEX_STEP * Qd)
        dR2[sl, N:] += 2.0 * np.imag(Jc) / COMPLEX_STEP + 2.0 * xi1 * np.real(Jc)

    # friction forces (Section 8.3), split into the parts the force offers (friction: one per
    # contact region, so a column re-solves only the regions whose contact point depends on it);
    # their multiplier derivative is formed below (analytic where the force offers at_state)
    for mf in (model.multiplier_forces if friction else []):
        for part in (mf.pieces() if hasattr(mf, "pieces") else [mf]):
            pieces.append((cols_of(part), cols_of(part, "velocity_coords"),
                           lambda Qx, Qdx, part=part: (part.forces(t, Qx, Qdx, lam), None), None))

    base = [None if central else fun(Q, Qd) for _, _, fun, _ in pieces]
    for which, x in enumerate((Q, Qd) if rates else (Q,)):
        users: dict[int, list[int]] = {}
        for k, piece in enumerate(pieces):
            for j in piece[which]:
                users.setdefault(int(j), []).append(k)
        cols = np.array(sorted(users), dtype=int)
        for j, h in zip(cols, _steps(x[cols], rel_step)):
            xj = x[j]
            x[j] = xj + h
            up = [pieces[k][2](Q, Qd) for k in users[j]]
            if central:
                x[j] = xj - h
                lo = [pieces[k][2](Q, Qd) for k in users[j]]
            else:
                lo = [base[k] for k in users[j]]
            x[j] = xj
            col = j + which * N
            scale = 1.0 / (2.0 * h if central else h)
            for k, u, l in zip(users[j], up, lo):
                dR1[:, col] += (u[0] - l[0]) * scale
                if pieces[k][3] is not None:
                    dR2[pieces[k][3], col] += (u[1] - l[1]) * scale

    if batch is not None:
        for sign in signs:
            if sign < 0.0:                 # the -h sweep after the +h one (one worker)
                batch = model._element_differences_started(Q, Qd, Qdd, signed_steps(sign),
                                                             rates)
            DP, DR = batch()
            for (_, idx), dp, dr in zip(model.element_indices(), DP, DR):
                dR1[np.ix_(idx, idx)] += weight * dp
                dR1[np.ix_(idx, N + idx)] += weight * dr
                if sign > 0.0:
                    n_el += 1
                el_evals += (2 if rates else 1) * len(idx) + 1
    return dR1, dR2, G, el_evals / max(n_el, 1)
