"""The fast assembly and solve paths of the telescopic right-hand side against their references.

* reduced assembly (element and point-effect blocks scattered straight into P^T M P,
  ``sim_core.model._assembly_numba``) against forming the full M and projecting it;
* the compiled scatter against its numpy version;
* the saddle-point solve by block elimination over the beams (``saddle_point.kkt_factor_blocks_reference``
  and its compiled version ``sim_core.model._saddle_point_numba``) against the LU of the whole
  matrix, with and without the refinement step;
* the material point's real evaluation served from the real part of a complex-step one against
  a fresh real evaluation;
* the payload's local block (``PointMass.local``) against M += m J^T J, F += m J^T (g - a);
* the particular part A^+ b(t) of the state lift formed once where every linear constraint is
  constant, and the stacked targets of the nonlinear constraints, against their definitions.
"""

import numpy as np
import pytest

from sim_core.model import _assembly_numba as assembly_compiled
from sim_core.model import _saddle_point_numba as saddle_point_compiled
from sim_core.model.saddle_point import kkt_factor, kkt_factor_blocks_reference
from sim_core.physics.constraints import constraint_terms, material_point
from sim_core.physics.point_effects import PointMass
from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium


@pytest.fixture(scope="module")
def state():
    ts = build_telescopic(TelescopicParams(n_nodes=3, friction=True, payload=1000.0))
    z, _ = initial_equilibrium(ts)
    m = ts.model
    rng = np.random.default_rng(7)
    z = z + 1e-4 * rng.standard_normal(m.n_dof)
    zd = 0.05 * rng.standard_normal(m.n_dof)
    return ts, z, zd


def _dense_reference(m, t, z, zd):
    Q, Qd = m.full_state(t, z, zd)
    M, F = m.mass_force(t, Q, Qd)
    Qdd_p = m.A_pinv @ m.linear_targets(t, 2)
    return m.P.T @ M @ m.P, m.P.T @ (F - M @ Qdd_p)


def test_reduced_assembly_equals_the_projection(state):
    """M_r, F_r scattered block by block equal P^T M P, P^T (F - M Qdd_p) of the full arrays to
    round-off (the sums are the same, in another order)."""
    ts, z, zd = state
    m = ts.model
    assert m._sel is not None
    Mr, Fr = m.reduced_mass_force(0.3, z, zd)
    Mr0, Fr0 = _dense_reference(m, 0.3, z, zd)
    np.testing.assert_allclose(Mr, Mr0, rtol=0, atol=1e-13 * np.max(np.abs(Mr0)))
    np.testing.assert_allclose(Fr, Fr0, rtol=0, atol=1e-13 * np.max(np.abs(Fr0)))


def test_compiled_scatter_equals_numpy(state, monkeypatch):
    ts, z, zd = state
    m = ts.model
    if not assembly_compiled.AVAILABLE:
        pytest.skip("numba not installed: only the numpy scatter exists")
    Mr, Fr = m.reduced_mass_force(0.3, z, zd)
    monkeypatch.setattr(assembly_compiled, "AVAILABLE", False)
    Mr1, Fr1 = m.reduced_mass_force(0.3, z, zd)
    np.testing.assert_allclose(Mr, Mr1, rtol=0, atol=1e-14 * np.max(np.abs(Mr)))
    np.testing.assert_allclose(Fr, Fr1, rtol=0, atol=1e-14 * np.max(np.abs(Fr)))


def _saddle(m, z, zd, t=0.3):
    Q, Qd = m.full_state(t, z, zd)
    Mr, Fr, blocks = m._reduced_mass_force_at(t, Q, Qd, m.A_pinv @ m.linear_targets(t, 2), blocks=True)
    _, J, _, c = constraint_terms(m.nonlinear, t, Q, Qd)
    C = J @ m.P
    K = np.block([[Mr, C.T], [C, np.zeros((C.shape[0], C.shape[0]))]])
    return Mr, Fr, C, c, blocks, K


def _residual(K, Fr, c, sol):
    zdd, lam = sol
    r = np.concatenate([Fr, c]) - K @ np.concatenate([zdd, -lam])
    return np.max(np.abs(r)) / np.max(np.abs(Fr))


@pytest.mark.skipif(not saddle_point_compiled.AVAILABLE, reason="needs numba")
def test_compiled_elimination_needs_no_refinement_at_the_paper_discretisation():
    """The paper scene (8 sub-elements, the filter's mass (h^2/6) K in M_r: element blocks with
    cond(A) up to ~1e7) at its static equilibrium: the numpy elimination (Y = A^-1 B by two
    triangular solves, S = D - B^T Y) leaves a residual well above the whole matrix LU's
    without its refinement step, the compiled one (W = L^-1 B, S = D - W^T W: rounding with
    cond(L) = cond(A)^(1/2)) does not -- why Model.kkt_refine is off.  Its solutions, five
    columns as the friction Newton's (F_r and unit loads on the contact coordinates), agree
    with the LU's to 1e-9 of their size.  Measured: residuals 4.9e-16 (LU), 6.5e-16
    (compiled), 2.8e-14 (numpy)."""
    from sim_core import load_scene
    from sim_core.systems.telescopic.schema import params_from_scene
    ts = build_telescopic(params_from_scene(load_scene("telescopic_extraction")))
    m = ts.model
    assert not m.kkt_refine
    z, _ = initial_equilibrium(ts)
    Mr, Fr, C, c, blocks, K = _saddle(m, z, np.zeros_like(z), t=0.0)
    r_lu = _residual(K, Fr, c, kkt_factor(Mr, C)(Fr, c))
    assert _residual(K, Fr, c, kkt_factor_blocks_reference(Mr, C, blocks, refine=False)(Fr, c)) > 10.0 * r_lu
    raw = saddle_point_compiled.kkt_factor_blocks(Mr, C, blocks, refine=False)
    assert _residual(K, Fr, c, raw(Fr, c)) <= 10.0 * r_lu
    Q, _ = m.full_state(0.0, z, np.zeros_like(z))
    idx = np.concatenate([a.coords for a in [ts.contact.at_state(0.0, Q, 0.0 * Q)]])
    Fs = np.column_stack([Fr, m.P[idx].T * np.max(np.abs(Fr))])
    cs = np.column_stack([c, np.zeros((len(c), len(idx)))])
    for a, b in zip(raw(Fs, cs), kkt_factor(Mr, C)(Fs, cs)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-9 * np.max(np.abs(b)))


def test_block_elimination_matches_the_whole_lu(state):
    """The elements' own coordinates (those of no other element: Model._block_of) are
    uncoupled blocks of M_r, one per element (the payload's mass sits on one element's
    coordinates and the shared ones): exactly zero between two blocks.  Block elimination with
    one refinement step solves the saddle-point system to the residual of the whole matrix's
    LU; for several right-hand sides at once too."""
    ts, z, zd = state
    m = ts.model
    Mr, Fr, C, c, blocks, K = _saddle(m, z, zd)
    n_el = sum(len(b.elements) for b in m.beams)
    assert blocks is not None and len(blocks) == n_el
    for i, bi in enumerate(blocks):
        assert np.abs(Mr[np.ix_(bi, bi)]).max() > 0
        for bj in blocks[i + 1:]:
            assert not np.any(Mr[np.ix_(bi, bj)])
    lu = kkt_factor(Mr, C)
    blk = kkt_factor(Mr, C, blocks)
    r_lu = _residual(K, Fr, c, lu(Fr, c))
    r_blk = _residual(K, Fr, c, blk(Fr, c))
    assert r_blk <= 10.0 * r_lu + 1e-14, (r_blk, r_lu)
    z0, lam0 = lu(Fr, c)
    z1, lam1 = blk(Fr, c)
    np.testing.assert_allclose(z1, z0, rtol=0, atol=1e-9 * np.max(np.abs(z0)))
    np.testing.assert_allclose(lam1, lam0, rtol=0, atol=1e-9 * np.max(np.abs(lam0)))
    rng = np.random.default_rng(3)
    Fs = np.column_stack([Fr, rng.standard_normal((len(Fr), 3)) * np.max(np.abs(Fr))])
    cs = np.column_stack([c, np.zeros((len(c), 3))])
    Z0, L0 = lu(Fs, cs)
    Z1, L1 = blk(Fs, cs)
    np.testing.assert_allclose(Z1, Z0, rtol=0, atol=1e-9 * np.max(np.abs(Z0)))
    np.testing.assert_allclose(L1, L0, rtol=0, atol=1e-9 * np.max(np.abs(L0)))
    # without the refinement step the residual is not at the LU's level (the blocks' condition,
    # ~1e8 and more with the filter mass, enters the Schur complement): the step is needed
    unrefined = kkt_factor_blocks_reference(Mr, C, blocks, refine=False)
    assert _residual(K, Fr, c, unrefined(Fr, c)) >= r_blk
    # the numpy elimination (the reference of the compiled one kkt_factor takes) and the
    # compiled one agree, refined and not
    ref = kkt_factor_blocks_reference(Mr, C, blocks)
    assert _residual(K, Fr, c, ref(Fr, c)) <= 10.0 * r_lu + 1e-14
    if saddle_point_compiled.AVAILABLE:
        comp = saddle_point_compiled.kkt_factor_blocks(Mr, C, blocks)
        for a, b in zip(comp(Fs, cs), ref(Fs, cs)):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-11 * np.max(np.abs(b)))
        # unit loads on border coordinates (as the friction Newton's columns): zero on every
        # block, whose solves the compiled elimination skips
        border = np.setdiff1d(np.arange(len(Fr)), np.concatenate(blocks))
        E = np.zeros((len(Fr), 3))
        E[border[:3], np.arange(3)] = np.max(np.abs(Fr))
        ce = np.zeros((len(c), 3))
        for a, b in zip(comp(E, ce), lu(E, ce)):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-9 * np.max(np.abs(b)))
        raw = saddle_point_compiled.kkt_factor_blocks(Mr, C, blocks, refine=False)
        for a, b in zip(raw(Fr, c), unrefined(Fr, c)):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-6 * np.max(np.abs(b)))


def test_block_elimination_falls_back_where_a_block_is_not_definite(state):
    """A block that is not positive definite (here: negated) is not eliminated: the whole LU
    solves."""
    ts, z, zd = state
    m = ts.model
    Mr, Fr, C, c, blocks, K = _saddle(m, z, zd)
    Mr0 = Mr.copy()
    b = blocks[0]
    Mr0[np.ix_(b, b)] *= -1.0
    assert kkt_factor_blocks_reference(Mr0, C, blocks) is None
    if saddle_point_compiled.AVAILABLE:
        assert saddle_point_compiled.kkt_factor_blocks(Mr0, C, blocks) is None
    sol = kkt_factor(Mr0, C, blocks)(Fr, c)
    ref = kkt_factor(Mr0, C)(Fr, c)
    assert np.all(np.isfinite(sol[0])) and np.all(np.isfinite(sol[1]))
    np.testing.assert_array_equal(sol[0], ref[0])
    np.testing.assert_array_equal(sol[1], ref[1])


def test_real_point_evaluation_from_the_complex_one(state):
    """A real state equal to the real part of the last complex-step state is served from that
    evaluation; its values equal a fresh real evaluation to round-off."""
    ts, z, zd = state
    m = ts.model
    Q, Qd = m.full_state(0.3, z, zd)
    p = material_point(m, 1, s_index=ts.s3_index[1])
    fresh = [np.array(x) for x in p(Q.copy())]              # a real evaluation
    p(Q + 1j * 1e-20 * Qd)                                 # a complex one at the same Q
    served = p(Q)
    for a, b in zip(served, fresh):
        assert not np.iscomplexobj(a)
        np.testing.assert_allclose(a, b, rtol=1e-15, atol=1e-15 * max(np.max(np.abs(b)), 1.0))
    other = Q.copy()
    other[p.coords(Q)[0]] += 1e-3                          # a coordinate of the point moved
    np.testing.assert_raises(AssertionError, np.testing.assert_allclose, p(other)[0], served[0])


def test_payload_local_block_is_the_dense_formula(state):
    ts, z, zd = state
    m = ts.model
    pm = next(pe for pe in m.point_effects if isinstance(pe, PointMass))
    Q, Qd = m.full_state(0.3, z, zd)
    _, J, _, _ = pm.point(Q)
    h = 1e-7                                    # the point's acceleration J_dot Qd by differences
    a = ((pm.point(Q + h * Qd)[1] - pm.point(Q - h * Qd)[1]) / (2 * h)) @ Qd
    N = len(Q)
    M, F = np.zeros((N, N)), np.zeros(N)
    pm.add(0.3, Q, Qd, M, F)
    np.testing.assert_allclose(M, pm.mass * J.T @ J, rtol=0, atol=1e-12 * pm.mass)
    f_ref = J.T @ (pm.mass * (pm.gravity - a))
    np.testing.assert_allclose(F, f_ref, rtol=0, atol=1e-6 * np.max(np.abs(f_ref)))


def test_element_batch_equals_the_elements_one_by_one(state):
    """The compiled batch (element_compiled.ElementBatch, one call for all elements) gives each
    element's kernel result (bitwise); on the worker thread or the calling thread the
    right-hand side is the same."""
    from sim_core.physics import _effects_numba as element_compiled
    if not element_compiled.AVAILABLE:
        pytest.skip("numba not installed")
    ts, z, zd = state
    m = ts.model
    Q, Qd = m.full_state(0.3, z, zd)
    started = m._element_blocks_started(0.3, Q, Qd)
    assert started is not None
    Ms, Fs = started()
    for (el, idx), Me, Fe in zip(m.element_indices(), Ms, Fs):
        M1, F1 = m.element_terms(0.3, el, Q[idx], Qd[idx])
        np.testing.assert_array_equal(Me, M1)
        np.testing.assert_array_equal(Fe, F1)
    y = np.concatenate([z, zd])
    m.element_thread = True
    a = m.rhs(0.3, y)
    m.element_thread = False
    try:
        b = m.rhs(0.3, y)
    finally:
        m.element_thread = True
    # equal to round-off (the micro-motion solves are warm-started from the previous call)
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * np.max(np.abs(a)))
    m.element_yield = False            # no GIL hand-over after submitting: the same numbers
    try:
        c = m.rhs(0.3, y)
    finally:
        m.element_yield = True
    np.testing.assert_allclose(a, c, rtol=1e-12, atol=1e-12 * np.max(np.abs(a)))


def test_element_batch_non_finite_raises_in_the_callers_error_state(state):
    """numpy's error state is per thread: the batch's finite check runs on the calling thread,
    so a non-finite element raises FloatingPointError where the caller asked numpy to raise
    (the integrator's right-hand side), as the one-by-one path does."""
    from sim_core.physics import _effects_numba as element_compiled
    if not element_compiled.AVAILABLE:
        pytest.skip("numba not installed")
    ts, z, zd = state
    m = ts.model
    Q, Qd = m.full_state(0.3, z, zd)
    bad = Q.copy()
    bad[next(iter(m.element_indices()))[1][5]] = np.inf
    with np.errstate(invalid="raise", over="raise"):
        with pytest.raises(FloatingPointError):
            m._element_blocks_started(0.3, bad, Qd)()


def _rhs_in_child(conn, model, y):
    conn.send(model.rhs(0.3, y))
    conn.close()


def test_element_worker_in_a_forked_process(state):
    """A process forked after the parent used the worker thread gets a worker of its own (the
    parent's thread does not exist in the child): its right-hand side completes and equals the
    parent's."""
    import multiprocessing as mp
    ts, z, zd = state
    m = ts.model
    y = np.concatenate([z, zd])
    parent = m.rhs(0.3, y)                   # the parent's worker exists now
    ctx = mp.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_rhs_in_child, args=(send, m, y))
    proc.start()
    assert recv.poll(120), "the forked child's right-hand side did not complete"
    child = recv.recv()
    proc.join(30)
    np.testing.assert_allclose(child, parent, rtol=1e-12, atol=1e-12 * np.max(np.abs(parent)))


def test_jacobian_element_batch_equals_the_one_by_one_columns(state):
    """The structured Jacobian's element columns by the compiled batch (on the worker thread)
    equal the element-by-element differences: the same kernel at the same steps, up to the
    round-off of forward differences (eps / rel_step ~ 1e-8 of the column scale; the compiled
    call sequence and the micro-motion warm starts differ in the last bits)."""
    from sim_core.model.state_jacobian import state_jacobian
    from sim_core.physics import _effects_numba as element_compiled
    if not element_compiled.AVAILABLE:
        pytest.skip("numba not installed")
    ts, z, zd = state
    m = ts.model
    y = np.concatenate([z, zd])
    J_batch = state_jacobian(m, 0.3, y)
    m._element_differences_started = lambda *a: None       # the one-by-one path
    try:
        J_one = state_jacobian(m, 0.3, y)
    finally:
        del m._element_differences_started
    scale = np.max(np.abs(J_one), axis=0)
    np.testing.assert_allclose(J_batch, J_one, rtol=0, atol=1e-7 * np.max(scale))


@pytest.mark.parametrize("moving", [False, True])
def test_offset_point_jacobian_is_the_derivative(state, moving):
    """A material point with a rigid offset (rope anchors, pivots; optionally at a moving
    contact coordinate): dr/dQ v equals the complex-step derivative of r along random v, and
    dPsi/dQ v that of Psi."""
    ts, z, zd = state
    m = ts.model
    Q, _ = m.full_state(0.3, z, zd)
    kw = dict(s_index=ts.s3_index[1]) if moving else dict(s_fixed=3.0)
    p = material_point(m, 1, offset=(0.3, -0.1, 0.2), **kw)
    r, J, psi, Jp = [np.array(x) for x in p(Q)]
    rng = np.random.default_rng(4)
    h = 1e-20
    for _ in range(3):
        v = rng.standard_normal(len(Q))
        rc, _, psic, _ = p(Q + 1j * h * v)
        np.testing.assert_allclose(J @ v, np.imag(rc) / h, rtol=1e-10,
                                   atol=1e-12 * np.abs(J @ v).max())
        np.testing.assert_allclose(Jp @ v, np.imag(psic) / h, rtol=1e-10,
                                   atol=1e-12 * np.abs(Jp @ v).max())


def test_constraint_rows_from_the_complex_evaluation(state):
    """constraint_terms takes g and G of each row as the real parts of its complex-step
    evaluation: equal to the rows' real evaluation to round-off."""
    ts, z, zd = state
    m = ts.model
    Q, Qd = m.full_state(0.3, z, zd)
    phi, J, _, _ = constraint_terms(m.nonlinear, 0.3, Q, Qd)
    row = 0
    for c in m.nonlinear:
        Qx = Q * (1.0 + 1e-6)               # other states first (real and complex): no
        c.evaluate(Qx)                      # cache entry of the points can serve Q
        c.evaluate(Qx + 1j * 1e-20 * Qd)
        g, G = c.evaluate(Q.copy())
        b = c.b(0.3)[0]
        np.testing.assert_allclose(phi[row:row + c.m], np.real(g) - b, rtol=1e-14,
                                   atol=1e-14 * max(np.max(np.abs(g)), 1.0))
        np.testing.assert_allclose(J[row:row + c.m], np.real(G), rtol=1e-14,
                                   atol=1e-14 * max(np.max(np.abs(G)), 1.0))
        row += c.m


@pytest.mark.parametrize("kind", ["moving", "fixed_offset", "moving_offset"])
def test_point_in_one_compiled_call_equals_the_reference(state, kind, monkeypatch):
    """A material point's kinematics, rigid offset and full-length Jacobians in one compiled
    call (point_compiled.point_full) against the compiled kinematics with the rest in numpy,
    for a real and a complex-step state (two point functions, each with its own cache)."""
    from sim_core.physics import constraints
    from sim_core.physics.beam import _moving_node_beam_numba as point_compiled
    if not point_compiled.AVAILABLE:
        pytest.skip("numba not installed")
    ts, z, zd = state
    m = ts.model
    ibeam, kw = {"moving": (1, dict(s_index=ts.s3_index[1])),
                 "fixed_offset": (1, dict(s_fixed=1.3, offset=(0.3, -0.1, 0.2))),
                 "moving_offset": (0, dict(s_index=ts.s2_index[0],
                                           offset=(-0.2, 0.05, 0.1)))}[kind]
    cache = m.__dict__.setdefault("_material_points", {})
    saved = dict(cache)
    try:
        cache.clear()
        fast = material_point(m, ibeam, **kw)
        cache.clear()
        ref = material_point(m, ibeam, **kw)
    finally:
        cache.clear()
        cache.update(saved)
    assert fast is not ref
    Q, Qd = m.full_state(0.3, z, zd)
    for X in (Q, Q + 1e-20j * Qd):
        monkeypatch.setattr(constraints, "POINTS_IN_ONE_CALL", True)
        a = fast(X)
        monkeypatch.setattr(constraints, "POINTS_IN_ONE_CALL", False)
        b = ref(X)
        assert np.iscomplexobj(a[1]) == np.iscomplexobj(X)
        for u, v in zip(a, b):
            np.testing.assert_allclose(u, v, rtol=1e-13, atol=1e-13 * max(np.max(np.abs(v)), 1))


def test_a_point_mass_across_two_elements_takes_the_whole_matrix(state):
    """A point effect whose mass couples the own coordinates of two elements breaks the block
    structure: _reduced_mass_force_at then reports no blocks (the whole LU solves); on one
    element's coordinates (and shared ones) the blocks stay."""
    ts, z, zd = state
    m = ts.model
    owner = m._block_of()
    a = int(np.flatnonzero(owner == 0)[0])
    b = int(np.flatnonzero(owner == 1)[0])
    shared = int(np.flatnonzero(owner == -1)[0])

    class Lumped:
        def __init__(self, idx):
            self.idx = np.array(idx)

        def local(self, t, Q, Qd, mass=True):
            k = len(self.idx)
            return self.idx, (np.eye(k) if mass else None), np.zeros(k)

    t = 0.3
    Q, Qd = m.full_state(t, z, zd)
    Qdd_p = m.A_pinv @ m.linear_targets(t, 2)
    for idx, whole in (([a, b], True), ([a, shared], False)):
        m.point_effects.append(Lumped(idx))
        try:
            _, _, blocks = m._reduced_mass_force_at(t, Q, Qd, Qdd_p, blocks=True)
        finally:
            m.point_effects.pop()
        assert (blocks is None) == whole, idx


def test_compiled_point_effects_equal_their_local_blocks(state):
    """The payload and rope blocks from one compiled evaluation of their points
    (point_effects.CompiledPointEffects) against each effect's ``local`` (the reference):
    the same formulas on the same point kinematics, equal to round-off (the fixture's
    extraction rope is taut, the retraction rope slack); and the right-hand side with and
    without them."""
    from sim_core.physics.point_effects import CompiledPointEffects, PointMass, RopeDrive
    ts, z, zd = state
    m = ts.model
    if not m.point_effects or CompiledPointEffects.build(m.point_effects) is None:
        pytest.skip("numba not installed: no compiled point effects")
    kinds = {type(pe) for pe in m.point_effects}
    assert kinds == {PointMass, RopeDrive}
    t = 0.3
    Q, Qd = m.full_state(t, z, zd)
    batch = CompiledPointEffects.build(m.point_effects)
    tensions = []
    for pe, (idx, Me, Fe) in zip(m.point_effects, batch.local(Q, Qd)):
        idx0, Me0, Fe0 = pe.local(t, Q, Qd)
        np.testing.assert_array_equal(idx, idx0)
        scale = max(np.abs(Fe0).max(), 1.0)
        np.testing.assert_allclose(Fe, Fe0, rtol=0, atol=1e-12 * scale)
        if Me0 is None:
            assert Me is None
            tensions.append(float(np.abs(Fe0).max()))
        else:
            np.testing.assert_allclose(Me, Me0, rtol=0, atol=1e-12 * np.abs(Me0).max())
    assert max(tensions) > 0                     # a taut rope is among them
    y = np.concatenate([z, zd])
    m.point_effects_compiled = False
    try:
        ref = m.rhs(t, y)
    finally:
        m.point_effects_compiled = True
    np.testing.assert_allclose(m.rhs(t, y), ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def _pipeline_or_skip(m):
    from sim_core.model import workers as element_worker
    if not (saddle_point_compiled.PIPELINE and m.element_thread and m.element_spin
            and element_worker.AVAILABLE):
        pytest.skip("no compiled element worker: no pipelined factorisation")


def test_pipelined_factor_equals_assembly_then_factor(state, monkeypatch):
    """Each element added into M_r and its block factored as the worker publishes it
    (saddle_point_compiled.kkt_factor_pipelined) is the same arithmetic as assembling the
    whole batch first and then factoring (Model.kkt_pipeline = False, the reference), apart
    from the order in which the border's Schur complement is summed: the right-hand sides agree
    to round-off (1e-12 of the largest entry; a missing element or block would be O(1)), and
    the pipelined path is the one taken."""
    ts, z, zd = state
    m = ts.model
    _pipeline_or_skip(m)
    calls = []
    real = saddle_point_compiled.kkt_factor_pipelined

    def counted(*a, **k):
        calls.append(1)
        return real(*a, **k)
    monkeypatch.setattr(saddle_point_compiled, "kkt_factor_pipelined", counted)
    rng = np.random.default_rng(11)
    for k in range(3):
        y = np.concatenate([z + 1e-4 * rng.standard_normal(m.n_dof),
                            0.05 * rng.standard_normal(m.n_dof)])
        out = {}
        for flag in (False, True):
            m.kkt_pipeline = flag
            m.__dict__.pop("_g_warm", None)        # the same friction-Newton start
            try:
                out[flag] = m.rhs(0.3 + 0.1 * k, y)
            finally:
                m.kkt_pipeline = True
        assert np.all(np.isfinite(out[True]))
        np.testing.assert_allclose(out[True], out[False], rtol=0,
                                   atol=1e-12 * np.abs(out[False]).max())
    assert len(calls) == 3


def test_pipelined_factor_falls_back_where_a_block_is_not_definite(state):
    """A block that is not positive definite (here: a large negative mass put on one element's
    own coordinates before the batch is added) stops the elimination, but every element is
    still added: (M_r, F_r) equal the assembled ones, and Model._pipelined_factor solves with
    the whole matrix's LU."""
    ts, z, zd = state
    m = ts.model
    _pipeline_or_skip(m)
    t = 0.3
    Q, Qd = m.full_state(t, z, zd)
    Qdd_p = m.A_pinv @ m.linear_targets(t, 2)
    Mr_ref, Fr_ref, blocks = m._reduced_mass_force_at(t, Q, Qd, Qdd_p, blocks=True)
    elements = m._element_blocks_started(t, Q, Qd)
    Mr, Fr, blocks2, deferred = m._reduced_mass_force_at(t, Q, Qd, Qdd_p, blocks=True,
                                                         elements=elements, pipeline=True)
    assert deferred is elements and blocks2 is blocks
    b = blocks[0]
    push = -1e3 * np.abs(Mr_ref).max() * np.eye(len(b))
    Mr[np.ix_(b, b)] += push
    _, J, _, c = constraint_terms(m.nonlinear, t, Q, Qd)
    C = J @ m.P
    solve = m._pipelined_factor(Mr, Fr, C, blocks, deferred)
    Mr[np.ix_(b, b)] -= push
    scale = np.abs(Mr_ref).max()
    np.testing.assert_allclose(Mr, Mr_ref, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(Fr, Fr_ref, rtol=0, atol=1e-12 * np.abs(Fr_ref).max())
    Mr_bad = Mr_ref.copy()
    Mr_bad[np.ix_(b, b)] += push
    assert saddle_point_compiled.kkt_factor_blocks(Mr_bad, C, blocks) is None
    ref = kkt_factor(Mr_bad, C)(Fr_ref, c)
    got = solve(Fr_ref, c)
    for a, r in zip(got, ref):
        np.testing.assert_allclose(a, r, rtol=0, atol=1e-9 * np.abs(r).max())


def test_pipeline_adds_the_batch_at_once_where_a_point_mass_couples_two_elements(state):
    """With a point effect's mass across two elements' own coordinates there are no blocks to
    factor early: the batch is added before _reduced_mass_force_at returns (no deferred
    batch), equal to the assembly without the pipeline."""
    ts, z, zd = state
    m = ts.model
    _pipeline_or_skip(m)
    owner = m._block_of()
    a = int(np.flatnonzero(owner == 0)[0])
    b = int(np.flatnonzero(owner == 1)[0])

    class Lumped:
        def local(self, t, Q, Qd, mass=True):
            return np.array([a, b]), (np.eye(2) if mass else None), np.zeros(2)

    t = 0.3
    Q, Qd = m.full_state(t, z, zd)
    Qdd_p = m.A_pinv @ m.linear_targets(t, 2)
    m.point_effects.append(Lumped())
    try:
        Mr0, Fr0, _ = m._reduced_mass_force_at(t, Q, Qd, Qdd_p, blocks=True)
        elements = m._element_blocks_started(t, Q, Qd)
        Mr, Fr, blocks, deferred = m._reduced_mass_force_at(
            t, Q, Qd, Qdd_p, blocks=True, elements=elements, pipeline=True)
    finally:
        m.point_effects.pop()
    assert blocks is None and deferred is None
    np.testing.assert_allclose(Mr, Mr0, rtol=0, atol=1e-12 * np.abs(Mr0).max())
    np.testing.assert_allclose(Fr, Fr0, rtol=0, atol=1e-12 * np.abs(Fr0).max())


def test_compiled_point_effect_jacobian_equals_the_python_pieces(state):
    """The structured Jacobian with the payload and ropes from their compiled program
    (point_effects.CompiledPointEffects.jacobian: program columns, the ropes' T'(l) and the
    payload's rate part analytic) against the Python pieces (forward differences of each
    effect's ``local``): both are forward differences at the same steps, so they agree to the
    differences' truncation and round-off, ~1e-8 of the column scale (sqrt(eps) ~ 1.5e-8;
    measured 2.2e-8, asserted 1e-7).  That scale is the booms' stiffness, so the effects'
    own pieces are checked too, against central differences of their ``local`` terms to
    1e-6 of their scale (dropping the payload's inertia or rate term, or the rope's T'(l),
    fails it)."""
    from sim_core.model.state_jacobian import _steps, state_jacobian
    from sim_core.physics.point_effects import CompiledPointEffects
    ts, z, zd = state
    m = ts.model
    if CompiledPointEffects.build(m.point_effects) is None:
        pytest.skip("numba not installed: no compiled point effects")
    y = np.concatenate([z, zd])
    J_compiled = state_jacobian(m, 0.3, y)
    m.point_effects_compiled = False
    try:
        J_python = state_jacobian(m, 0.3, y)
    finally:
        m.point_effects_compiled = True
    scale = np.max(np.abs(J_python), axis=0)
    np.testing.assert_allclose(J_compiled, J_python, rtol=0, atol=1e-7 * np.max(scale))
    # the effects' own pieces against central differences of their summed local terms
    # F - M Qdd (at the model's accelerations, so the payload's inertia term is in): central
    # differences are O(h^2) accurate, the compiled forward ones O(h) ~ 1e-8 of the scale
    Q, Qd = m.full_state(0.3, z, zd)
    Qdd = m.lift(0.3, m.accelerations(0.3, z, zd), 2)
    dQ, dQd = m._compiled_point_effects().jacobian(Q, Qd, Qdd, lambda x: _steps(x, 1.5e-8))

    def pieces(Qx, Qdx):
        F = np.zeros(len(Q))
        for pe in m.point_effects:
            idx, Me, Fe = pe.local(0.3, Qx, Qdx)
            F[idx] += Fe if Me is None else Fe - Me @ Qdd[idx]
        return F
    cols = np.flatnonzero(np.abs(dQ).sum(axis=0) + np.abs(dQd).sum(axis=0))
    for X, D in ((Q, dQ), (Qd, dQd)):
        ref = np.empty((len(Q), len(cols)))
        for k, j in enumerate(cols):
            h = 1e-6 * max(abs(X[j]), 1.0)
            xj = X[j]
            X[j] = xj + h
            up = pieces(Q, Qd)
            X[j] = xj - h
            lo = pieces(Q, Qd)
            X[j] = xj
            ref[:, k] = (up - lo) / (2 * h)
        np.testing.assert_allclose(D[:, cols], ref, rtol=0, atol=1e-6 * np.abs(ref).max())


def test_shared_elements_are_each_taken_once():
    """The Jacobian's element columns are shared between the worker and the calling thread
    (model._SharedElements): each element is computed exactly once whoever takes it, and after
    ``stop`` no further one is handed out."""
    import threading

    from sim_core.model.workers import SharedElements as _SharedElements
    done, lock = [], threading.Lock()

    def work(e):
        with lock:
            done.append(e)
    shared = _SharedElements(50, work)
    th = threading.Thread(target=shared.run)
    th.start()
    shared.run()
    th.join()
    assert sorted(done) == list(range(50))
    done.clear()
    shared = _SharedElements(5, work)
    shared.stop()
    shared.run()
    assert done == []


def test_particular_lift_and_targets_equal_their_definitions(state):
    """Model._particular(t, which) = A^+ b^(which)(t): formed once for the telescopic model
    (every boundary condition constant: the rates are zero) and at every call for a sleeve
    (time-dependent material flow); constraints.targets stacks (b, b_dot, b_ddot) of the
    nonlinear constraints (the cylinder's prescribed stroke; zeros elsewhere) as each
    constraint's own b(t)."""
    from sim_core import load_scene
    from sim_core.physics.constraints import targets
    from sim_core.systems.beam.build import build_model
    ts, _, _ = state
    sleeve, _, _ = build_model(load_scene("beam_through_sleeve"))
    for m, constant in ((ts.model, True), (sleeve, False)):
        assert all(c.constant for c in m.constraints) is constant
        for t in (0.0, 0.7, 3.1):
            for which in range(3):
                X = m._particular(t, which)
                np.testing.assert_array_equal(X, m.A_pinv @ m.linear_targets(t, which))
                assert not X.flags.writeable or not constant
        if constant:
            assert m._particular(0.7, 0) is m._particular(3.1, 0)
    cons = ts.model.nonlinear
    assert any(c.target is not None for c in cons)
    for t in (0.0, 2.0, 13.0):
        got = targets(cons, t)
        for i in range(3):
            np.testing.assert_array_equal(got[i], np.concatenate([c.b(t)[i] for c in cons]))
    # the sleeve's lift moves with its prescribed flow: a rate that is not zero
    assert np.any(sleeve._particular(1.0, 1) != 0.0)


def test_frictionless_model_takes_the_block_elimination(monkeypatch):
    """Without friction (no multiplier forces: case 9.1 of the cost-growth benchmark) the
    saddle-point system is solved by the same block elimination, pipelined with the element
    worker, as with friction -- not by the dense LU of the whole matrix (kkt_accelerations,
    kept for Model.kkt_blocks False) -- and gives the dense LU's accelerations and multipliers
    (to 1e-9 of their size; measured 1e-13)."""
    from sim_core.model import model as model_module
    ts = build_telescopic(TelescopicParams(n_nodes=3, friction=False, payload=1000.0, E=2.1e12))
    m = ts.model
    assert not m.multiplier_forces
    z0, zd0 = m.reduced_state(0.0, ts.Q0, np.zeros_like(ts.Q0))
    rng = np.random.default_rng(11)
    z = z0 + 1e-4 * rng.standard_normal(m.n_dof)
    zd = 0.05 * rng.standard_normal(m.n_dof)
    m.kkt_blocks = False
    a_ref, lam_ref = m.accelerations_and_multipliers(0.3, z, zd)
    m.kkt_blocks = True

    def dense(*args):
        raise AssertionError("the dense LU was used")
    monkeypatch.setattr(model_module, "kkt_accelerations", dense)
    a, lam = m.accelerations_and_multipliers(0.3, z, zd)
    np.testing.assert_allclose(a, a_ref, rtol=0, atol=1e-9 * np.max(np.abs(a_ref)))
    np.testing.assert_allclose(lam, lam_ref, rtol=0, atol=1e-9 * np.max(np.abs(lam_ref)))
