"""The folding manipulator's joint rows as one compiled program (``JointProgram`` of
``sim_core.physics._rigid_body_numba``) and its rigid bodies' blocks in one compiled call
(``CompiledRigidBodies``) against the Python closures of ``sim_core.physics.rigid_body`` and
``sim_core.physics.constraints`` (the reference; tolerances in ``tests/compiled_rows.py``).
The joints: hinges (point coincidence and axis rows), planar pins, prismatic joints, and with
rigid cylinders the distance drivers.  Coarse systems (4 sub-elements per boom), a deformed
and moving state.
"""

import numpy as np
import pytest

from sim_core.model import state_jacobian
from sim_core.physics import _rigid_body_numba as joint_compiled
from sim_core.physics import constraints
from sim_core.systems.folding.build import FoldingParams, build_folding
from tests.compiled_rows import assert_rows_equal_python, height_row, jacobian_difference
from tests.folding.conftest import moving_state

pytestmark = pytest.mark.skipif(not joint_compiled.AVAILABLE, reason="numba not installed")


@pytest.fixture(scope="module", params=["spring_cylinders", "rigid_cylinders"])
def state(request):
    fs = build_folding(FoldingParams(n_nodes=5,
                                     rigid_cylinders=request.param == "rigid_cylinders"))
    return (request.param, fs, *moving_state(fs, 3))


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
    _, fs, Q, Qd = state
    assert_rows_equal_python(fs.model.nonlinear, 0.7, Q, Qd, monkeypatch)


@pytest.mark.parametrize("path", ["joint columns", "rigid bodies"])
def test_jacobian_equals_the_python_pieces(state, monkeypatch, path):
    """The structured Jacobian with the joint program's constraint columns, or with the rigid
    bodies' columns from their compiled blocks, against the Python pieces."""
    _, fs, Q, Qd = state
    m = fs.model
    z, zd = m.reduced_state(0.7, Q, Qd)
    owner, switch = ((state_jacobian, "COMPILED_CONSTRAINT_COLUMNS") if path == "joint columns"
                     else (m, "point_effects_compiled"))
    assert jacobian_difference(m, 0.7, np.concatenate([z, zd]), monkeypatch, owner,
                               switch) < 1e-6


def test_a_joint_without_program_takes_the_python_path(state):
    """A hand-written row (no ``joint_program``) is not compiled: joint_program_for says None
    and constraint_terms evaluates the closures (the rows then include the extra one)."""
    _, fs, Q, Qd = state
    cons = fs.model.nonlinear
    tip = fs.frames["boom2_tip"]
    rows = list(cons) + [height_row(tip)]
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
