"""Assembled model: beams + effects + boundary conditions -> M(q) q_ddot = F(t, q, q_dot).

Boundary conditions of the single-beam problems (clamped end, pinned end, roller, fixed material
end, end drawn through a rigid sleeve) are *linear* in the coordinates Q with prescribed right-
hand sides, A Q = b(t).  They are eliminated exactly: Q = Q_p(t) + P z with P an orthonormal
basis of null(A) and Q_p = A^+ b(t), so the integrated state is (z, z_dot) and there is no
constraint drift.  Constraint reactions are recovered as A^T lambda = M Q_ddot - F.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.linalg as sla

from sim_core.model import _saddle_point_numba as saddle_point_compiled
from sim_core.model import workers
from sim_core.model._assembly_numba import scatter_add, scatter_add_blocks
from sim_core.model.boundary import LinearConstraint, dense_rows
from sim_core.model.saddle_point import kkt_accelerations, kkt_factor
from sim_core.physics import _effects_numba as element_compiled
from sim_core.physics.beam.moving_node_beam import Beam
from sim_core.physics.complex_step import COMPLEX_STEP
from sim_core.physics.constraints import constraint_terms
from sim_core.physics.effects import (
    Effect,
    ElementContext,
    Gravity,
    PointLoad,
    StressFilter,
    effect_parameters,
)

Scalar = Callable[[float], float]


@dataclass
class ElementLoopPlan:
    """What :meth:`Model.element_loop_plan` hands a compiled loop: ``n`` reduced coordinates,
    the particular solution ``Qp`` (N,), the selection ``rows``/``sgn`` (Q = Qp + P z), the
    element coordinate map ``eidx`` (E, nq), the reduced index ``red`` (-1 where fixed) and sign
    ``sg`` of every full coordinate, and the element kernel's arguments ``kernel_args``."""

    n: int
    Qp: np.ndarray
    rows: np.ndarray
    sgn: np.ndarray
    eidx: np.ndarray
    red: np.ndarray
    sg: np.ndarray
    kernel_args: tuple


@dataclass
class Model:
    """A set of beams with the effects and boundary conditions of a scene."""

    beams: list[Beam]
    effects: list[Effect]
    point_loads: list[PointLoad] = field(default_factory=list)
    constraints: list[LinearConstraint] = field(default_factory=list)
    nonlinear: list = field(default_factory=list)          # constraints.NonlinearConstraint
    point_effects: list = field(default_factory=list)      # point_effects.PointMass, RopeDrive
    n_extra: int = 0            # extra coordinates after the beams (e.g. inner contact points s_2,k)
    # forces that depend on the constraint multipliers (contact friction, Section 8.3): objects
    # with forces(t, Q, Qd, lam) -> (N,).  With at_state(t, Q, Qd) -> an object with .coords (k,)
    # and .values(lam, gradient) -> (g (k,), dg/dlam (k, m)) (forces E g(lam) on k coordinates)
    # they are solved by Newton in g; otherwise by fixed-point iteration on lambda
    multiplier_forces: list = field(default_factory=list)
    multiplier_tol: float = 1e-8
    multiplier_newton: bool = True     # False: the fixed point even where at_state is offered
    multiplier_max_iter: int = 8
    # the multiplier Newton's loop in one compiled call where the force offers it (friction:
    # FrictionAtState.newton); False: the Python loop (the reference)
    multiplier_newton_compiled: bool = True
    # the multiplier Newton starts from the last solution (Model._multiplier_newton); False:
    # from g = 0 at every evaluation
    multiplier_warm_start: bool = True
    baumgarte: tuple[float, float] = (10.0, 10.0)          # xi1, xi2 in 1/s (SIMULTECH 2020 Eq. 8)
    # the saddle-point system by block elimination over the elements' own coordinates
    # (saddle_point.kkt_factor; _block_of: the coordinates shared by two elements, the extra
    # coordinates and the multipliers form the border) where M_r is block-diagonal in them;
    # False: the LU of the whole matrix (the reference).  Per element rather than per beam:
    # more, smaller Cholesky factors and a wider border factor faster at 8 sub-elements
    # (benchmarks/telescopic_rhs_speed.py)
    kkt_blocks: bool = True
    # one step of iterative refinement after each compiled block-elimination solve
    # (saddle_point_compiled).  Off: with W = L^-1 B and S = D - W^T W the elimination's
    # rounding grows with cond(L) = cond(A)^(1/2), not cond(A) (up to ~1e7 for the paper
    # scene's element blocks with the filter's mass), and its residual is at the whole matrix
    # LU's level without the step (tests/telescopic/test_assembly_paths.py), while the step
    # doubles the solve.  The numpy elimination (no numba; A^-1 B by two solves) always refines
    kkt_refine: bool = False
    # payloads and ropes from one compiled evaluation of their points
    # (point_effects.CompiledPointEffects); False: each effect's local() in Python (the reference)
    point_effects_compiled: bool = True
    # the element batch on a worker thread while the constraint rows are evaluated
    # (_element_blocks_started), where the model's governor allows a helper thread (at least
    # two cores in the affinity set, SIM_CORE_ELEMENT_POOL, and the worker getting a core of
    # its own: Model.governor, workers.Governor); False: on the calling thread
    element_thread: bool = True
    # after handing the batch to the thread pool, release the GIL once (time.sleep(0)) so that
    # the pool's thread takes it at once: otherwise it waits while this thread runs the Python
    # of the constraint rows (the batch started 0.27 ms after submission, 0.08 ms with the
    # hand-over; the element batch itself takes ~0.9 ms at 8 sub-elements)
    element_yield: bool = True
    # with element_thread: hand the batch to a persistent compiled worker through a mailbox and
    # an atomic state word (beam/workers.py: no queue, no wake-up, no GIL hand-over;
    # 1.46 -> 1.39 ms per right-hand side, interleaved A/B; its result arrays are the worker's
    # mailbox, valid until the next batch is started); False: the thread pool
    element_spin: bool = True
    # with element_spin and kkt_blocks: add each element into M_r and factor its block as soon
    # as the worker publishes it, while the worker computes the next elements
    # (saddle_point_compiled.kkt_factor_pipelined); False: wait for the whole batch, then
    # assemble and factor (the reference)
    kkt_pipeline: bool = True

    def __post_init__(self):
        self.offsets = np.cumsum([0] + [b.n_coords for b in self.beams])[:-1]
        self.n_coords = int(sum(b.n_coords for b in self.beams)) + int(self.n_extra)
        self.needs = frozenset().union(*(e.needs for e in self.effects)) if self.effects else frozenset()
        self._reduce()

    # -- constraint elimination ----------------------------------------------------------
    def _reduce(self) -> None:
        N = self.n_coords
        for c in self.constraints:
            if isinstance(c.rows, list):      # sparse {index: coefficient} rows
                c.rows = dense_rows(N, c.rows)
        if self.constraints:
            A = np.vstack([c.rows for c in self.constraints])
        else:
            A = np.zeros((0, N))
        self.A = A
        if A.shape[0]:
            u, sv, vt = np.linalg.svd(A)
            rank = int(np.sum(sv > 1e-12 * sv[0]))
            if rank < A.shape[0]:
                raise ValueError("boundary conditions are redundant (rank-deficient constraint rows)")
            self.P = vt[rank:].T
            self.A_pinv = np.linalg.pinv(A)
        else:
            self.P = np.eye(N)
            self.A_pinv = np.zeros((N, 0))
        self.n_dof = self.P.shape[1]
        self._sel = _selection(self.P)

    def linear_targets(self, t: float, which: int) -> np.ndarray:
        if not self.constraints:
            return np.zeros(0)
        return np.concatenate([(c.value, c.rate, c.accel)[which](t) for c in self.constraints])

    def full_state(self, t: float, z: np.ndarray, zd: np.ndarray):
        """Q, Q_dot from the reduced state."""
        return self.lift(t, z, 0), self.lift(t, zd, 1)

    def _particular(self, t: float, which: int) -> np.ndarray:
        """A^+ b^(which)(t) (which = 0, 1, 2: position, rate, acceleration level), read-only;
        formed once where every constraint is constant (b' = b'' = 0)."""
        cache = self.__dict__.get("_particular_cache")
        if cache is None:
            const = bool(self.constraints) and all(c.constant for c in self.constraints)
            cache = self._particular_cache = [None] * 3 if const else False
        if cache is False:
            return self.A_pinv @ self.linear_targets(t, which)
        if cache[which] is None:
            X = self.A_pinv @ self.linear_targets(0.0, which) if which == 0 else np.zeros(self.n_coords)
            X.flags.writeable = False
            cache[which] = X
        return cache[which]

    def lift(self, t: float, x: np.ndarray, which: int) -> np.ndarray:
        """A^+ b^(which)(t) + P x (which = 0, 1, 2: position, rate, acceleration level); P x as
        a signed scatter where P only selects coordinates."""
        X = self._particular(t, which)
        if self._sel is None:
            return X + self.P @ x
        rows, sgn, _ = self._sel
        X = X.astype(np.result_type(X, x))          # a copy: _particular's may be shared
        X[rows] += sgn * x
        return X

    def _times_P(self, J: np.ndarray) -> np.ndarray:
        """J P (rows of coordinate derivatives -> reduced coordinates); a signed column
        selection where P only selects coordinates."""
        if self._sel is None:
            return J @ self.P
        rows, sgn, _ = self._sel
        return J[:, rows] * sgn

    def reduced_state(self, t: float, Q: np.ndarray, Qd: np.ndarray):
        """Project a full state onto the constraint manifold's coordinates (z, z_dot)."""
        z = self.P.T @ (Q - self._particular(t, 0))
        zd = self.P.T @ (Qd - self._particular(t, 1))
        return z, zd

    def describe(self) -> list[str]:
        """Lines naming the assembled contributions (effects, point effects, multiplier forces,
        point loads) and the coordinate count, constraint rows and degrees of freedom."""
        n_nl = sum(c.m for c in self.nonlinear)
        return ["assembled contributions: " + ", ".join(e.name for e in self.effects)
                + "".join(f", {pe.name}" for pe in self.point_effects)
                + "".join(f", {mf.name}" for mf in self.multiplier_forces)
                + (f", {len(self.point_loads)} point load(s)" if self.point_loads else ""),
                f"coordinates: {self.n_coords}, linear constraints: {self.A.shape[0]}, "
                f"nonlinear constraint rows: {n_nl}, DOF: {self.n_dof - n_nl}"]

    # -- assembly --------------------------------------------------------------------------
    def element_indices(self):
        """Yield (element, its global coordinate indices) for every element of every beam."""
        for b, off in zip(self.beams, self.offsets):
            for el, imap in zip(b.elements, b.index_map):
                yield el, off + imap

    def element_contexts(self, t: float, Q: np.ndarray, Qd: np.ndarray):
        """Yield (global indices, ElementContext) for every element; kinematics computed once."""
        for el, idx in self.element_indices():
            yield idx, self.element_context(t, el, Q[idx], Qd[idx])

    def element_kinematics(self, el, qe: np.ndarray):
        """Position-level kinematics of one element with the strains the effects declare in
        ``needs``."""
        return el.evaluate(qe, strains="strains" in self.needs,
                           material_strain="material_strain" in self.needs)

    def element_context(self, t: float, el, qe: np.ndarray, qde: np.ndarray,
                        kin=None) -> ElementContext:
        """Kinematics of one element with the quantities the effects declare in ``needs``
        (``kin``: the position-level kinematics at qe, if already at hand)."""
        mat = "material_strain" in self.needs
        if kin is None:
            kin = self.element_kinematics(el, qe)
        ctx = ElementContext(t, el, qe, qde, kin, el.q_w * kin.ell)
        if "convective" in self.needs:
            kc = el.evaluate(qe + 1j * COMPLEX_STEP * qde, s=kin.s, sub=kin.sub,
                             strains=mat, material_strain=mat)
            c = {"a": np.einsum("gin,n->gi", kc.J_r, qde).imag / COMPLEX_STEP,
                 "w_dot": np.einsum("gin,n->gi", kc.J_w, qde).imag / COMPLEX_STEP}
            if mat:
                c["eps_ddot"] = np.einsum("gin,n->gi", kc.B_s, qde).imag / COMPLEX_STEP
            ctx.conv = c
        return ctx

    def element_mass_force(self, ctx: ElementContext, mass: bool = True):
        """Element mass matrix (or None) and force vector from the model's effects."""
        ne = len(ctx.qe)
        Me = np.zeros((ne, ne)) if mass else None
        Fe = np.zeros(ne)
        for eff in self.effects:
            eff.element_terms(ctx, Me, Fe)
        return Me, Fe

    def element_terms(self, t: float, el, qe: np.ndarray, qde: np.ndarray, mass: bool = True,
                      kin=None):
        """Element mass matrix (or None) and force vector at (qe, qde): the compiled kernel of
        :mod:`sim_core.physics._effects_numba` where it covers the model's effects (Inertia,
        Elasticity, StressFilter, Gravity; no mass-centre offset; real states), otherwise
        ``element_mass_force(element_context(...))`` (the reference; ``kin``: the
        position-level kinematics at qe, if already at hand)."""
        kw = self._compiled_effects(el.section) if element_compiled.AVAILABLE else None
        if kw is not None and not (np.iscomplexobj(qe) or np.iscomplexobj(qde)):
            return element_compiled.element_mass_force(el, qe, qde, needs_mass=mass, **kw)
        return self.element_mass_force(self.element_context(t, el, qe, qde, kin), mass)

    def element_residual(self, t: float, el, qe: np.ndarray, qde: np.ndarray,
                         qdde: np.ndarray) -> np.ndarray:
        """F_e - M_e qdde of one element; on the compiled path the product is formed through
        the kernel's weighted rows without the mass matrix (the structured Jacobian differences
        this column by column)."""
        kw = self._compiled_effects(el.section) if element_compiled.AVAILABLE else None
        if kw is not None and not (np.iscomplexobj(qe) or np.iscomplexobj(qde)):
            return element_compiled.element_mass_force(el, qe, qde, qdde=qdde, **kw)[1]
        Me, Fe = self.element_mass_force(self.element_context(t, el, qe, qde))
        return Fe - Me @ qdde

    def element_terms_compiled(self, el) -> bool:
        """True where :meth:`element_terms` of this element takes the compiled kernel (for real
        states)."""
        return element_compiled.AVAILABLE and self._compiled_effects(el.section) is not None

    def effects_changed(self) -> None:
        """After effects were added to an assembled model (an effect plug-in): recompute what
        the effects need and drop the compiled kernel's verdicts."""
        self.needs = frozenset().union(*(e.needs for e in self.effects)) if self.effects \
            else frozenset()
        self.__dict__.pop("_compiled_kw", None)

    @property
    def uncompiled_effects(self) -> list[str]:
        """Names of the effects the compiled element kernel does not cover (they send the
        elements to the numpy path)."""
        from sim_core.physics.effects import Elasticity, Inertia
        covered = (Inertia, Elasticity, StressFilter, Gravity)
        return [e.name for e in self.effects if type(e) not in covered]

    def _compiled_effects(self, section):
        """element_compiled's effect arguments for this section, or None where the kernel does
        not cover the effects.  The verdict and the constant arguments are kept per section and
        effect list; the gravity vector and the filter's h are read at every call (statics scale
        the gravity of an effect in place)."""
        key = (id(section), tuple(id(e) for e in self.effects))
        cache = self.__dict__.setdefault("_compiled_kw", {})
        if key not in cache:
            try:
                kw = effect_parameters(self.effects, section)
                grav = [e for e in self.effects if isinstance(e, Gravity)]
                filt = [e for e in self.effects if isinstance(e, StressFilter)]
                cache[key] = (kw, grav[0] if grav else None, filt[0] if filt else None)
            except ValueError:
                cache[key] = None
                names = self.uncompiled_effects
                if names and element_compiled.AVAILABLE and not self.__dict__.get("_warned"):
                    # said once per model, never silently: the run is slower on this path
                    import warnings
                    self._warned = True
                    warnings.warn(f"effect {', '.join(names)} has no compiled element kernel: "
                                  "the elements run on the numpy path (slower)", RuntimeWarning,
                                  stacklevel=2)
        entry = cache[key]
        if entry is None:
            return None
        kw, grav, filt = entry
        if grav is not None:
            kw["g"] = np.asarray(grav.g, dtype=float)
        if filt is not None:
            kw["h"] = filt.h
        return kw

    def mass_force(self, t: float, Q: np.ndarray, Qd: np.ndarray, mass: bool = True):
        """Full-coordinate mass matrix (or None) and force vector: M Q_ddot = F."""
        N = self.n_coords
        dt = np.result_type(Q, Qd, float)
        M = np.zeros((N, N), dtype=dt) if mass else None
        F = np.zeros(N, dtype=dt)
        full = self.__dict__.get("_full_map")
        if full is None:
            full = self._full_map = (np.arange(N), np.ones(N))
        rest, _ = self._scatter_local_terms(t, Q, Qd, M, F, *full)
        for pe in rest:
            pe.add(t, Q, Qd, M, F)
        return M, F

    def _scatter_local_terms(self, t, Q, Qd, M, F, red, sg, Qdd_p=None, elements=None,
                             defer: bool = False) -> list:
        """Add every element's, point load's and local point effect's (Me, Fe) into (M, F)
        through the coordinate map (red, sg) (:func:`assembly_compiled.scatter_add`); with
        ``Qdd_p`` the force is F - M Qdd_p.  Returns the point effects without a local form
        (``local(t, Q, Qd, mass) -> (idx, Me, Fe)``), for the caller to add on full arrays,
        and whether a point effect's mass couples two beams (elements never do).  ``elements``:
        the element batch if already started (:meth:`_element_blocks_started`); ``defer``: leave
        it out (the caller adds it, :meth:`_reduced_mass_force_at`)."""
        mass = M is not None
        coupled = False

        def put(idx, Me, Fe):
            if Qdd_p is not None and Me is not None:
                Fe = Fe - Me @ Qdd_p[idx]
            scatter_add(M, F, red, sg, idx, Me, Fe)

        blocks = elements
        if blocks is None and mass:
            blocks = self._element_blocks_started(t, Q, Qd)
        for pl in self.point_loads:
            put(*self._point_load_terms(pl, t, Q))
        rest = []
        batch = self._compiled_point_effects() if not np.iscomplexobj(Q) \
            and not np.iscomplexobj(Qd) else None
        local = iter(batch.local(Q, Qd, mass, t=t)) if batch is not None else None
        for pe in self.point_effects:
            if hasattr(pe, "local"):
                idx, Me, Fe = next(local) if local is not None else pe.local(t, Q, Qd, mass)
                if Me is not None and not coupled:
                    o = self._block_of()[idx]
                    o = o[o >= 0]
                    coupled = o.size > 0 and o.min() != o.max()
                put(idx, Me, Fe)
            else:
                rest.append(pe)
        if defer:
            return rest, coupled
        if blocks is not None:                 # the batch (started above, maybe on the worker)
            Ms, Fs = blocks()
            if Qdd_p is not None or not scatter_add_blocks(M, F, red, sg, self._element_idx,
                                                           Ms, Fs):
                for (_, idx), Me, Fe in zip(self.element_indices(), Ms, Fs):
                    put(idx, Me, Fe)
        else:
            for el, idx in self.element_indices():
                put(idx, *self.element_terms(t, el, Q[idx], Qd[idx], mass))
        return rest, coupled

    def _compiled_point_effects(self):
        """The point effects' local blocks from one compiled evaluation
        (point_effects.CompiledPointEffects: payloads and ropes; rigid_body.CompiledRigidBodies:
        rigid bodies) where ``point_effects_compiled`` and one covers them, else None."""
        if not self.point_effects_compiled:
            return None
        key = tuple(id(pe) for pe in self.point_effects)
        hit = self.__dict__.get("_pe_batch")
        if hit is None or hit[0] != key:
            from sim_core.physics.point_effects import CompiledPointEffects
            from sim_core.physics.rigid_body import CompiledRigidBodies
            hit = self._pe_batch = (key, CompiledPointEffects.build(self.point_effects)
                                    or CompiledRigidBodies.build(self.point_effects))
        return hit[1]

    def _element_blocks_started(self, t, Q, Qd):
        """Start the mass matrices and forces of all elements as one compiled batch
        (:class:`element_compiled.ElementBatch`) and return a function that waits for them:
        (Me (E, nq, nq), Fe (E, nq)) in the order of :meth:`element_indices`.  The batch runs
        without the GIL; with ``element_thread`` on a worker thread, so that the point effects
        and the constraint rows (Python) are evaluated meanwhile on the calling thread.  None
        where the batch does not cover the model (other effects, unequal elements, complex
        states): the elements are then evaluated one by one."""
        plan = self._element_batch_plan(Q, Qd)
        if plan is None:
            return None
        batch, kw = plan
        QE, QDE = Q[self._element_idx], Qd[self._element_idx]
        if self.element_thread and self.element_spin and workers.AVAILABLE \
                and self.governor().allowed:
            worker = self.__dict__.get("_spin_worker")
            if worker is None or worker.batch is not batch:
                if worker is not None:
                    worker.stop()
                worker = self._spin_worker = workers.ElementWorker(batch, *QE.shape)
            if self.governor().use_worker(worker):
                worker.submit(QE, QDE, kw["h"], kw["g"], t)
                return workers.WorkerBatch(worker)
            return workers.run_inline(lambda: batch(QE, QDE, kw["h"], kw["g"]), t)
        return self._run(lambda: batch(QE, QDE, kw["h"], kw["g"]), t)

    def governor(self) -> workers.Governor:
        """Whether the element batches use a helper thread (:class:`workers.Governor`:
        the cores in the affinity set, ``SIM_CORE_ELEMENT_POOL`` and whether the worker gets
        a core of its own), one per model."""
        gov = self.__dict__.get("_governor")
        if gov is None:
            gov = self._governor = workers.Governor()
        return gov

    def _element_differences_started(self, Q, Qd, Qdd, steps, rates=True):
        """Start the structured Jacobian's element columns, element by element
        (:meth:`element_compiled.ElementBatch.differences`; with ``element_thread`` on the
        worker thread, and the calling thread takes the rest when it waits) and return a
        function that waits for them: per element (d(F - M Qdd)/dq, dF/dq_dot), in the order
        of :meth:`element_indices`.  ``steps(x)``:
        the forward-difference steps of a coordinate vector; ``rates`` False: dF/dq_dot left
        zero.  None where the batch does not cover the model."""
        plan = self._element_batch_plan(Q, Qd)
        if plan is None:
            return None
        batch, kw = plan
        ix = self._element_idx
        QE, QDE, QDDE = Q[ix], Qd[ix], np.ascontiguousarray(Qdd[ix], dtype=float)
        HQ = np.stack([steps(q) for q in QE])
        HQD = np.stack([steps(q) for q in QDE])
        E, nq = QE.shape
        DP, DR = np.empty((E, nq, nq)), np.empty((E, nq, nq))

        def element(e):
            r = slice(e, e + 1)
            DP[r], DR[r] = batch.differences(QE[r], QDE[r], QDDE[r], HQ[r], HQD[r], kw["h"],
                                             kw["g"], element=e, rates=rates)
        shared = workers.SharedElements(E, element)

        def job():
            shared.run()
            return DP, DR
        wait = self._run(job)                # at once without element_thread

        def finish():
            # the calling thread, its own pieces done, takes the elements the worker has not
            # started (~10 ms each at 8 sub-elements: the two threads end together)
            try:
                shared.run()
            except BaseException:
                shared.stop()
                try:
                    wait()
                except Exception:  # noqa: BLE001 - the calling thread's error is the one raised
                    pass
                raise
            return wait()                   # the worker's error, if any; finite-checked
        return finish

    def _run(self, job, t: float = float("nan")):
        """job() on the element worker thread with ``element_thread`` where the governor allows
        a helper thread (a function that waits for it and checks its result for non-finite
        values on the calling thread), else at once; a division by zero or an overflow in the
        batch is an :class:`ElementEvaluationError` at time t."""
        if not (self.element_thread and self.governor().threads()):
            return workers.run_inline(job, t)
        future = workers.thread_pool().submit(job)
        if self.element_yield:
            time.sleep(0)       # hand the GIL over now (see element_yield)

        def wait():
            try:
                out = future.result()
            except (ZeroDivisionError, OverflowError) as exc:
                raise workers.evaluation_error(exc, t) from exc
            return workers.checked_batch(out)
        return wait

    def element_loop_plan(self) -> "ElementLoopPlan | None":
        """The arrays a compiled time-step loop needs to evaluate this model without Python
        (:mod:`sim_core.integrate._generalized_alpha_numba`): the element batch's tables and
        effect arguments, the element -> coordinate map and the reduction Q = Q_p + P z with P a
        signed selection.  None where the model has anything outside the compiled element batch:
        point loads or point effects, nonlinear constraints, multiplier forces, extra
        coordinates, time-dependent or non-selecting linear constraints, effects the kernel does
        not cover."""
        if (not element_compiled.AVAILABLE or self.point_loads or self.point_effects
                or self.nonlinear or self.multiplier_forces or self._sel is None or self.n_extra
                or not all(c.constant for c in self.constraints)):
            return None
        Q0 = np.array(self._particular(0.0, 0), dtype=float)
        plan = self._element_batch_plan(Q0, np.zeros_like(Q0))
        if plan is None:
            return None
        batch, kw = plan
        eidx = np.ascontiguousarray(self._element_idx, dtype=np.int64)
        if np.setdiff1d(np.arange(self.n_coords), eidx.ravel()).size:
            return None                           # a coordinate outside every element
        rows, sgn, _ = self._sel
        red = np.full(self.n_coords, -1, dtype=np.int64)
        red[rows] = np.arange(len(rows))
        sg = np.zeros(self.n_coords)
        sg[rows] = sgn
        grav = np.ascontiguousarray(kw["g"], dtype=float)
        args = batch.element_arguments() + (float(kw["h"]), grav, batch.inertia,
                                            batch.elasticity, bool(np.any(grav != 0.0)),
                                            float(COMPLEX_STEP))
        return ElementLoopPlan(int(self.n_dof), Q0, np.ascontiguousarray(rows, dtype=np.int64),
                               np.ascontiguousarray(sgn, dtype=float), eidx, red, sg, args)

    def _element_batch_plan(self, Q, Qd):
        """(ElementBatch, effect arguments of this call) or None where the batch does not cover
        the model (other effects, unequal elements, complex states)."""
        if not element_compiled.AVAILABLE or np.iscomplexobj(Q) or np.iscomplexobj(Qd):
            return None
        pairs = self.__dict__.get("_element_pairs")
        if pairs is None:
            pairs = self._element_pairs = list(self.element_indices())
            self._element_idx = (np.stack([idx for _, idx in pairs])
                                 if len({len(idx) for _, idx in pairs}) == 1 else None)
        if self._element_idx is None:
            return None
        els = [el for el, _ in pairs]
        key = tuple(id(e) for e in self.effects)
        plan = self.__dict__.get("_element_batch")
        if plan is None or plan[0] != key or (plan[1] is not None and not plan[1].valid(els)):
            kws = [self._compiled_effects(el.section) for el in els]
            plan = self._element_batch = (key, element_compiled.ElementBatch.plan(els, kws))
        batch = plan[1]
        if batch is None:
            return None
        return batch, self._compiled_effects(els[0].section)    # h and g of this call

    def _block_of(self) -> np.ndarray:
        """The saddle-point block of each coordinate: the index of the element (in
        :meth:`element_indices` order) whose coordinates alone hold it, -1 where it is shared by
        two elements (a breakpoint's coefficients) or belongs to none (an extra coordinate).
        No element's mass couples two blocks, so M_r is block-diagonal in them apart from the
        border of the -1 coordinates."""
        owner = self.__dict__.get("_owner")
        if owner is None:
            count = np.zeros(self.n_coords, dtype=int)
            owner = np.full(self.n_coords, -1)
            for e, (_, idx) in enumerate(self.element_indices()):
                count[idx] += 1
                owner[idx] = e
            owner[count != 1] = -1
            self._owner = owner
        return owner

    def _add_point_load(self, pl: PointLoad, t: float, Q: np.ndarray, F: np.ndarray) -> None:
        idx, _, Fe = self._point_load_terms(pl, t, Q)
        F[idx] += Fe

    def _point_load_terms(self, pl: PointLoad, t: float, Q: np.ndarray):
        """(idx, None, Fe): J_r^T f (+ J_w^T moment) of a point load at its element."""
        beam = self.beams[pl.beam]
        off = self.offsets[pl.beam]
        s = float(pl.s_of_t(t))
        e = self.element_at(pl.beam, Q, s)
        idx = off + beam.index_map[e]
        kin = beam.elements[e].evaluate(Q[idx], s=np.array([s]), strains=False)
        Fe = kin.J_r[0].T @ np.asarray(pl.force(t), float)
        if pl.moment is not None:
            Fe = Fe + kin.J_w[0].T @ np.asarray(pl.moment(t), float)
        return idx, None, Fe

    def element_at(self, ibeam: int, Q: np.ndarray, s: float) -> int:
        """The element of beam ``ibeam`` that holds material coordinate s at Q (by the real
        parts of its interior breakpoints' coordinates)."""
        table = self.__dict__.get("_interior_s")
        if table is None:
            table = self._interior_s = [
                [int(off + b.s_coord(e + 1)) for e in range(len(b.elements) - 1)]
                for b, off in zip(self.beams, self.offsets)]
        for e, j in enumerate(table[ibeam]):
            if s < Q[j].real:
                return e
        return len(table[ibeam])

    # -- reduced dynamics ------------------------------------------------------------------
    def reduced_mass_force(self, t: float, z: np.ndarray, zd: np.ndarray):
        """(M_r, F_r) = (P^T M P, P^T (F - M Qdd_p)): the reduced system M_r z_ddot = F_r."""
        Q, Qd = self.full_state(t, z, zd)
        return self._reduced_mass_force_at(t, Q, Qd, self._particular(t, 2))

    def _reduced_mass_force_at(self, t, Q, Qd, Qdd_p, blocks: bool = False, elements=None,
                               pipeline: bool = False):
        """(M_r, F_r) at the full state; ``blocks``: and the reduced coordinates of each
        element's own coordinates (:meth:`_block_of`) where M_r is block-diagonal in them (no
        point effect's mass couples two of them), else None (for ``saddle_point.kkt_factor``).
        ``elements``: the element batch if already started (:meth:`_element_blocks_started`).
        ``pipeline`` (with ``blocks``): a fourth value, the element batch of the worker where it
        is left for the caller to add (:func:`saddle_point_compiled.kkt_factor_pipelined`),
        else None (then it is in M_r, F_r)."""
        if self._sel is None:
            if pipeline:
                return self._reduced_mass_force_at(t, Q, Qd, Qdd_p, blocks, elements) + (None,)
            if elements is not None:
                elements()                      # not used on this path: wait for it
            M, F = self.mass_force(t, Q, Qd)
            out = self.P.T @ M @ self.P, self.P.T @ (F - M @ Qdd_p)
            return out + (None,) if blocks else out
        # P selects (and signs) coordinates, the usual case of boundary conditions that fix
        # single coordinates: the blocks go straight into P^T M P (assembly_compiled)
        rows, sgn, sgn2 = self._sel
        red = self.__dict__.get("_red_map")
        if red is None:
            # (reduced index, sign) of each coordinate, the blocks (each element's own reduced
            # coordinates, where it has any) and each element's block or -1
            owner = self._block_of()[rows]
            own = [np.flatnonzero(owner == e) for e in range(sum(len(b.elements)
                                                                 for b in self.beams))]
            has = np.array([len(b) > 0 for b in own], dtype=bool)
            red = self._red_map = (np.full(self.n_coords, -1), np.zeros(self.n_coords),
                                   [b for b in own if len(b)],
                                   np.where(has, np.cumsum(has) - 1, -1).astype(np.int64))
            red[0][rows] = np.arange(len(rows))
            red[1][rows] = sgn
        n = len(rows)
        dt = np.result_type(Q, Qd, float)
        Mr = np.zeros((n, n), dtype=dt)
        Fr = np.zeros(n, dtype=dt)
        Qdd_p = Qdd_p if np.any(Qdd_p) else None
        defer = (pipeline and blocks and isinstance(elements, workers.WorkerBatch) and Qdd_p is None
                 and dt == np.float64)
        rest, coupled = self._scatter_local_terms(t, Q, Qd, Mr, Fr, *red[:2], Qdd_p=Qdd_p,
                                                  elements=elements, defer=defer)
        if rest:
            N = self.n_coords
            M, F = np.zeros((N, N), dtype=dt), np.zeros(N, dtype=dt)
            for pe in rest:
                pe.add(t, Q, Qd, M, F)
            Mr += M[np.ix_(rows, rows)] * sgn2
            Fr += sgn * (F if Qdd_p is None else F - M @ Qdd_p)[rows]
            coupled = True                      # unknown where the mass went
        if defer and coupled:                   # no blocks to factor early: add the batch now
            Ms, Fs = elements()
            scatter_add_blocks(Mr, Fr, red[0], red[1], self._element_idx, Ms, Fs)
            defer = False
        if not blocks:
            return Mr, Fr
        out = Mr, Fr, (None if coupled else red[2])
        return out + ((elements if defer else None),) if pipeline else out

    @property
    def n(self) -> int:
        """Number of independent coordinates (integrators.SecondOrderSystem protocol)."""
        return self.n_dof

    def mass_and_force(self, t: float, q: np.ndarray, v: np.ndarray):
        """(M, f) of the reduced system M z_ddot = f (integrators.SecondOrderSystem)."""
        return self.reduced_mass_force(t, q, v)

    def accelerations(self, t: float, z: np.ndarray, zd: np.ndarray) -> np.ndarray:
        return self.accelerations_and_multipliers(t, z, zd)[0]

    def accelerations_and_multipliers(self, t: float, z: np.ndarray, zd: np.ndarray):
        """z_ddot and the multipliers of the nonlinear constraints (empty if there are none)."""
        Q, Qd = self.full_state(t, z, zd)
        Qdd_p = self._particular(t, 2)
        if not self.nonlinear:
            Mr, Fr = self._reduced_mass_force_at(t, Q, Qd, Qdd_p)
            return sla.solve(Mr, Fr, assume_a="pos"), np.zeros(0)
        # the element batch runs (on the worker thread) while the constraint rows and the
        # multiplier forces' state-only parts (friction: section maps, mu(s_dot)) are formed
        elements = self._element_blocks_started(t, Q, Qd) if self._sel is not None else None
        newton = bool(self.multiplier_forces) and self.multiplier_newton and all(
            hasattr(mf, "at_state") for mf in self.multiplier_forces)
        try:
            phi, J, dphi, c_rhs = constraint_terms(self.nonlinear, t, Q, Qd)
            ats = [mf.at_state(t, Q, Qd) for mf in self.multiplier_forces] if newton else None
        except BaseException:
            if elements is not None:            # do not leave the batch running
                try:
                    elements()
                except Exception:  # noqa: BLE001 - the constraint rows' error is the one raised
                    pass
            raise
        pipeline = self.kkt_pipeline and self.kkt_blocks and saddle_point_compiled.PIPELINE
        Mr, Fr, blocks, *deferred = self._reduced_mass_force_at(
            t, Q, Qd, Qdd_p, blocks=True, elements=elements, pipeline=pipeline)
        xi1, xi2 = self.baumgarte
        c_rhs = c_rhs - J @ Qdd_p - 2.0 * xi1 * dphi - xi2 ** 2 * phi
        if not (self.multiplier_forces or self.kkt_blocks):
            return kkt_accelerations(Mr, Fr, self._times_P(J), c_rhs)
        # the saddle-point system by block elimination (pipelined with the worker where it
        # runs), with friction or without: the dense LU of the whole matrix grows as n^1.15
        # with the sub-elements and is the slower path at the paper's discretisation
        if deferred and deferred[0] is not None:
            solve = self._pipelined_factor(Mr, Fr, self._times_P(J), blocks, deferred[0])
        else:
            solve = kkt_factor(Mr, self._times_P(J), blocks if self.kkt_blocks else None,
                               refine=self.kkt_refine)
        if newton:
            return self._multiplier_newton(ats, solve, Fr, c_rhs)
        zdd, lam = solve(Fr, c_rhs)
        if not self.multiplier_forces:
            return zdd, lam
        for _ in range(self.multiplier_max_iter):
            dF = sum(mf.forces(t, Q, Qd, lam) for mf in self.multiplier_forces)
            zdd, lam_new = solve(Fr + self.P.T @ dF, c_rhs)
            change = np.max(np.abs(lam_new - lam)) / max(np.max(np.abs(lam_new)), 1.0)
            lam = lam_new
            if change < self.multiplier_tol:
                break
        return zdd, lam

    def _pipelined_factor(self, Mr, Fr, C, blocks, batch: "workers.WorkerBatch"):
        """The saddle-point solve while the worker's element batch is added into (Mr, Fr)
        block by block (:func:`saddle_point_compiled.kkt_factor_pipelined`); the whole
        matrix's LU where a block is not positive definite (as :func:`kkt_factor`)."""
        red = self._red_map                     # blocks is red[2], each element's block red[3]
        solve, out = saddle_point_compiled.kkt_factor_pipelined(
            Mr, Fr, C, blocks, batch.worker, red[0], red[1], self._element_idx, red[3],
            refine=self.kkt_refine)
        workers.checked_batch(out)
        return solve if solve is not None else kkt_factor(Mr, C, None)

    def _multiplier_newton(self, ats, solve, Fr, c_rhs):
        """Multiplier-dependent forces E g(lambda) on k coordinates (friction: the contact
        coordinates, Section 8.3): the saddle-point solution is affine in g,
        (z_ddot, lambda) = (z0, lam0) + (Z, L) g  (one factorisation, k + 1 right-hand sides),
        so the coupled problem is the k-dimensional  r(g) = g - g(lam0 + L g) = 0,  solved by
        Newton with the Jacobian  I - (dg/dlambda) L  (dg/dlambda analytic: the micro-motion
        sensitivity, ContactSolution.normal_load_gradient).  A Newton step that does not reduce |r|
        is replaced by the fixed-point step g <- g(lambda).  Stops when a Newton step changes
        lambda by less than multiplier_tol (relative to max |lambda|, at least 1); the step is
        taken, its error is of the order of its square.  ``ats``: the multiplier forces at the
        state (their ``at_state``)."""
        idx = np.concatenate([a.coords for a in ats])
        k = len(idx)
        if k == 0:
            return solve(Fr, c_rhs)
        sol = solve(np.column_stack([Fr, self.P[idx].T]),
                    np.column_stack([c_rhs, np.zeros((len(c_rhs), k))]))
        zdd0, Z = sol[0][:, 0], sol[0][:, 1:]
        lam0, L = sol[1][:, 0], sol[1][:, 1:]
        # warm start: the last solution of the same coordinates (consecutive evaluations are
        # at nearby states: 2 force evaluations instead of 3 from g = 0; the converged g does
        # not depend on the start beyond the Newton's stopping error, the square of its step)
        warm = self.__dict__.get("_g_warm")
        g0 = warm[1] if (self.multiplier_warm_start and warm is not None
                         and np.array_equal(warm[0], idx)) else np.zeros(k)
        if self.multiplier_newton_compiled and len(ats) == 1 and hasattr(ats[0], "newton"):
            g = ats[0].newton(lam0, L, self.multiplier_tol, self.multiplier_max_iter, g0)
            if g is not None:                   # the loop below in one compiled call
                self._g_warm = (idx, g)
                return zdd0 + Z @ g, lam0 + L @ g

        def values(g):
            lam = lam0 + L @ g
            parts = [a.values(lam, gradient=True) for a in ats]
            return lam, np.concatenate([p[0] for p in parts]), np.vstack([p[1] for p in parts])

        g = g0.copy()
        lam, gv, dg = values(g)
        r = g - gv
        for _ in range(self.multiplier_max_iter):
            step = np.linalg.solve(np.eye(k) - dg @ L, -r)
            g_new = g + step
            dlam = L @ step
            if np.max(np.abs(dlam)) < self.multiplier_tol * max(np.max(np.abs(lam + dlam)), 1.0):
                g = g_new                 # converged: the last step is below the tolerance
                break
            lam_new, gv_new, dg_new = values(g_new)
            r_new = g_new - gv_new
            if np.max(np.abs(r_new)) > np.max(np.abs(r)):     # safeguard: fixed-point step
                g_new = gv
                lam_new, gv_new, dg_new = values(g_new)
                r_new = g_new - gv_new
            g, lam, gv, dg, r = g_new, lam_new, gv_new, dg_new, r_new
        self._g_warm = (idx, g)
        return zdd0 + Z @ g, lam0 + L @ g

    def friction_in_slope_band(self, t: float, z: np.ndarray, zd: np.ndarray) -> bool | None:
        """Whether a multiplier force's friction law is in its slope band at (t, z, z_dot),
        where it makes the dynamics stiff (ContactFriction.in_slope_band: a contact sticking,
        breaking away or coming to stick); None where no multiplier force says (no friction).
        The ``"auto"`` method (:class:`sim_core.integrate.switching.MethodSwitch`) runs BDF only
        while it is True."""
        forces = [mf for mf in self.multiplier_forces if hasattr(mf, "in_slope_band")]
        if not forces:
            return None
        _, Qd = self.full_state(t, z, zd)
        return any(mf.in_slope_band(Qd) for mf in forces)

    def nonsmooth_rate_columns(self) -> np.ndarray:
        """Columns of the state Jacobian d(y')/dy, y = (z, z_dot), that carry a non-smooth
        rate law: the reduced rates the multiplier forces' velocity coordinates depend on
        (friction: the contact coordinates' s_dot of Eq. 65, whose mu(v)
        (docs/model.md#input-friction) is only C0 at |v| = v_eps).  Their velocity coordinates
        are fixed coordinate indices (``velocity_coords`` does not read Q).  Used by
        :class:`sim_core.integrate.driver.RefreshedJacobian`; empty without such forces."""
        full = sorted({int(i) for mf in self.multiplier_forces
                       if hasattr(mf, "velocity_coords") for i in mf.velocity_coords(None)})
        if not full:
            return np.zeros(0, dtype=int)
        return self.n_dof + np.flatnonzero(np.any(self.P[full] != 0.0, axis=0))

    def constraint_violation(self, t: float, z: np.ndarray, zd: np.ndarray) -> np.ndarray:
        """Position-level violation of every nonlinear constraint row (m or rad)."""
        if not self.nonlinear:
            return np.zeros(0)
        Q, Qd = self.full_state(t, z, zd)
        return constraint_terms(self.nonlinear, t, Q, Qd)[0]

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """First-order right-hand side for y = (z, z_dot)."""
        n = self.n_dof
        z, zd = y[:n], y[n:]
        return np.concatenate([zd, self.accelerations(t, z, zd)])

    def reactions(self, t: float, z: np.ndarray, zd: np.ndarray, solved=None) -> np.ndarray:
        """Constraint multipliers lambda (one per constraint row): A^T lambda = M Q_ddot - F.
        ``solved``: (z_ddot, lambda) of :meth:`accelerations_and_multipliers` at the same
        state, where the caller has them (saves that solve)."""
        Q, Qd = self.full_state(t, z, zd)
        M, F = self.mass_force(t, Q, Qd)
        zdd, lam = solved if solved is not None else self.accelerations_and_multipliers(t, z, zd)
        R = M @ self.lift(t, zdd, 2) - F
        if self.nonlinear:
            R = R - constraint_terms(self.nonlinear, t, Q, Qd)[1].T @ lam
        return self.A_pinv.T @ R

    # -- energies ----------------------------------------------------------------------------
    def energies(self, t: float, Q: np.ndarray, Qd: np.ndarray, gravity=None) -> dict:
        """Kinetic T (material velocities), strain U and gravity potential V, J."""
        T = U = V = 0.0
        g = np.zeros(3) if gravity is None else np.asarray(gravity, float)
        for el, idx in self.element_indices():
            qe, qde = Q[idx], Qd[idx]
            kin = el.evaluate(qe, strains=True)
            wl = el.q_w * kin.ell
            v = np.einsum("gin,n->gi", kin.J_r, qde)
            w = np.einsum("gin,n->gi", kin.J_w, qde)
            sec = el.section
            r = kin.r
            # mass centre r + d (docs/model.md#input-sections), see effects
            if sec.has_offset:
                d_glob = kin.sec.frame[:, 0] * sec.y_c + kin.sec.frame[:, 1] * sec.z_c
                ws = w[:, [1, 2, 0]]    # (s, t, b) -> (t, b, s) body components
                wxd = np.stack([-sec.z_c * ws[:, 2], sec.y_c * ws[:, 2],
                                sec.z_c * ws[:, 0] - sec.y_c * ws[:, 1]], axis=1)
                v = v + np.einsum("gji,gj->gi", kin.sec.frame, wxd)
                r = r + d_glob
            T += 0.5 * np.dot(wl, sec.rhoA * np.sum(v * v, axis=1) + w * w @ sec.J)
            U += np.dot(wl, el.strain_energy_density(kin))
            V -= np.dot(wl * sec.rhoA, r @ g)
        return {"T": float(T), "U": float(U), "V": float(V)}

    # -- points ------------------------------------------------------------------------------
    def point_motion(self, ibeam: int, s: float, t: float, z: np.ndarray, zd: np.ndarray,
                     zdd: np.ndarray | None = None):
        """Position, material velocity and (if zdd given) material acceleration of material
        point s of beam ``ibeam`` (global frame; m, m/s, m/s^2)."""
        Q, Qd = self.full_state(t, z, zd)
        r, kin, idx = self.point(ibeam, s, Q)
        v = kin.J_r[0] @ Qd[idx]
        if zdd is None:
            return r, v, None
        Qdd = self.lift(t, zdd, 2)
        el = self.beams[ibeam].elements[0]
        e = self.element_at(ibeam, Q, s)
        el = self.beams[ibeam].elements[e]
        kc = el.evaluate(Q[idx] + 1j * COMPLEX_STEP * Qd[idx], s=kin.s, sub=kin.sub, strains=False)
        a = kin.J_r[0] @ Qdd[idx] + (kc.J_r[0] @ Qd[idx]).imag / COMPLEX_STEP
        return r, v, a

    def point(self, ibeam: int, s: float, Q: np.ndarray):
        """Position (3,) of material point s of beam ``ibeam`` and its element kinematics."""
        beam = self.beams[ibeam]
        off = self.offsets[ibeam]
        e = self.element_at(ibeam, Q, s)
        idx = off + beam.index_map[e]
        kin = beam.elements[e].evaluate(Q[idx], s=np.array([s]), strains=True)
        return kin.r[0], kin, idx


def _selection(P: np.ndarray):
    """(rows, values, outer(values, values)) if every column of P has exactly one non-zero
    entry, in distinct rows (then P^T X P = X[rows][:, rows] * outer(values, values)); else
    None.  The outer product is kept so the right-hand side does not rebuild it."""
    nz = P != 0.0
    if P.size == 0 or not np.all(nz.sum(axis=0) == 1):
        return None
    rows = np.argmax(nz, axis=0)
    if len(np.unique(rows)) != len(rows):
        return None
    vals = P[rows, np.arange(P.shape[1])].copy()
    return rows, vals, np.outer(vals, vals)
