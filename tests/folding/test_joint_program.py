"""The folding manipulator's joint rows as one compiled program (``JointProgram`` of
``sim_core.physics._rigid_body_numba``) against the Python closures of
``sim_core.physics.rigid_body`` and ``sim_core.physics.constraints`` (the reference).

The program evaluates the same frames and rows (hinges: point coincidence and axis rows, planar
pins, prismatic joints, and with rigid cylinders the distance drivers) in the same algebra in
another order, so the rows agree to round-off of each quantity's scale; the structured
Jacobian's constraint columns are the same forward differences with the same steps of values
equal to round-off, so they agree to round-off / step (eps / 1.5e-8 ~ 1e-8 of a row's scale;
1e-6 allowed).  Coarse systems (4 sub-elements per boom), a deformed and moving state.
"""

import numpy as np
import pytest

from sim_core.model import state_jacobian
from sim_core.physics import _rigid_body_numba as joint_compiled
from sim_core.physics import constraints
from sim_core.physics.constraints import NonlinearConstraint
from sim_core.systems.folding.build import FoldingParams, build_folding

pytestmark = pytest.mark.skipif(not joint_compiled.AVAILABLE, reason="numba not installed")


@pytest.fixture(scope="module", params=["spring_cylinders", "rigid_cylinders"])
def state(request):
    fs = build_folding(FoldingParams(n_nodes=5,
                                     rigid_cylinders=request.param == "rigid_cylinders"))
    m = fs.model
    rng = np.random.default_rng(3)
    Q = fs.Q0 + 1e-3 * rng.standard_normal(fs.Q0.shape)
    for b, off in zip(m.beams, m.offsets):          # fixed material ends stay exact
        Q[off + b.s_coord(0)] = 0.0
        Q[off + b.s_coord(len(b.elements))] = b.length
    Q[fs.i_phi] = -0.4
    Qd = rng.standard_normal(Q.shape)
    return request.param, fs, Q, Qd


def test_program_covers_every_joint(state):
    name, fs, _, _ = state
    prog = joint_compiled.joint_program_for(fs.model.nonlinear)
    assert prog is not None
    assert prog.m == sum(c.m for c in fs.model.nonlinear)
    kinds = set(prog.c_kind.tolist())
    assert {joint_compiled.COINCIDENCE, joint_compiled.HINGE_AXIS, joint_compiled.PLANAR_PIN,
            joint_compiled.PRISMATIC} <= kinds
    assert (joint_compiled.DISTANCE in kinds) == (name == "rigid_cylinders")
    assert set(prog.f_kind.tolist()) == {joint_compiled.PLANAR, joint_compiled.BEAM}


def test_rows_equal_the_python_closures(state, monkeypatch):
    """Phi, G = g_Q, Phi_dot and b_ddot - g_QQ[Q_dot, Q_dot] (sums of terms of size |G| |Q_dot|
    and |G_Q| |Q_dot|^2: their tolerance is round-off of those sizes)."""
    _, fs, Q, Qd = state
    cons = fs.model.nonlinear
    monkeypatch.setattr(constraints, "COMPILED_ROWS", False)
    ref = constraints.constraint_terms(cons, 0.7, Q, Qd)
    monkeypatch.setattr(constraints, "COMPILED_ROWS", True)
    got = constraints.constraint_terms(cons, 0.7, Q, Qd)
    phi, G, dphi, rhs = ref
    gq = np.abs(G).max() * np.abs(Qd).max()
    for name, a, b, scale in (("phi", got[0], phi, max(np.abs(phi).max(), 1e-3)),
                              ("G", got[1], G, np.abs(G).max()),
                              ("dphi", got[2], dphi, gq),
                              ("rhs", got[3], rhs, max(np.abs(rhs).max(), gq * np.abs(Qd).max()))):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * scale, err_msg=name)


def test_jacobian_columns_equal_the_python_pieces(state, monkeypatch):
    _, fs, Q, Qd = state
    m = fs.model
    z, zd = m.reduced_state(0.7, Q, Qd)
    y = np.concatenate([z, zd])
    monkeypatch.setattr(state_jacobian, "COMPILED_CONSTRAINT_COLUMNS", False)
    ref = state_jacobian.state_jacobian(m, 0.7, y)
    monkeypatch.setattr(state_jacobian, "COMPILED_CONSTRAINT_COLUMNS", True)
    got = state_jacobian.state_jacobian(m, 0.7, y)
    scale = np.maximum(np.abs(ref).max(axis=1, keepdims=True), 1e-300)
    err = np.max(np.abs(got - ref) / scale)
    print(f"largest difference / row scale: {err:.2e}")
    assert err < 1e-6


def test_a_joint_without_program_takes_the_python_path(state):
    """A hand-written row (no ``joint_program``) is not compiled: joint_program_for says None
    and constraint_terms evaluates the closures (the rows then include the extra one)."""
    _, fs, Q, Qd = state
    cons = fs.model.nonlinear
    tip = fs.frames["boom2_tip"]

    def evaluate(Qx):
        r, J, _, _ = tip(Qx)
        return r[2:3], J[2:3]
    extra = NonlinearConstraint("tip_height", 1, evaluate, points=(tip,))
    rows = list(cons) + [extra]
    assert joint_compiled.joint_program_for(rows) is None
    phi = constraints.constraint_terms(rows, 0.0, Q, Qd)[0]
    np.testing.assert_allclose(phi[-1], np.real(tip(Q)[0][2]), rtol=1e-14)


def _dense(N, idx, Me, Fe):
    M, F = np.zeros((N, N)), np.zeros(N)
    F[idx] += Fe
    if Me is not None:
        M[np.ix_(idx, idx)] += Me
    return M, F


def test_rigid_body_blocks_equal_the_python_terms(state):
    """CompiledRigidBodies (one compiled call for every body) against RigidBody.local, and the
    other effects passed through with the time: the same Newton-Euler terms in another order
    (1e-13 of each block's scale); compared on the full coordinates, since a rod that shares
    its barrel's angle lists its columns in frame order, not sorted."""
    _, fs, Q, Qd = state
    m = fs.model
    batch = m._compiled_point_effects()
    assert type(batch).__name__ == "CompiledRigidBodies"
    N = len(Q)
    for pe, got in zip(m.point_effects, batch.local(Q, Qd, True, t=1.3)):
        M1, F1 = _dense(N, *got)
        M0, F0 = _dense(N, *pe.local(1.3, Q, Qd, True))
        np.testing.assert_allclose(F1, F0, rtol=0, atol=1e-13 * np.abs(F0).max(),
                                   err_msg=pe.name)
        np.testing.assert_allclose(M1, M0, rtol=0, atol=1e-13 * max(np.abs(M0).max(), 1e-300),
                                   err_msg=pe.name)


def test_jacobian_with_compiled_bodies_equals_the_python_pieces(state, monkeypatch):
    """The bodies' structured-Jacobian columns from the compiled blocks against the Python
    pieces (the same forward differences of values equal to round-off: 1e-6 of a row's
    scale allowed, as above)."""
    _, fs, Q, Qd = state
    m = fs.model
    z, zd = m.reduced_state(0.7, Q, Qd)
    y = np.concatenate([z, zd])
    monkeypatch.setattr(m, "point_effects_compiled", False)
    ref = state_jacobian.state_jacobian(m, 0.7, y)
    monkeypatch.setattr(m, "point_effects_compiled", True)
    got = state_jacobian.state_jacobian(m, 0.7, y)
    scale = np.maximum(np.abs(ref).max(axis=1, keepdims=True), 1e-300)
    err = np.max(np.abs(got - ref) / scale)
    print(f"largest difference / row scale: {err:.2e}")
    assert err < 1e-6
