"""The constraint rows as one compiled program (``sim_core.physics._constraints_numba``) against the
Python closures of ``sim_core.physics.constraints`` (the reference), for the rows and for the structured
Jacobian's constraint columns.

Scenes: the telescopic system with friction and payload (point and angle coincidences with
moving contact points, a point fixed in space, two distance drivers), without torsion (angle
rows selected by ``telescopic._rows``) and with the inextensible rope (a chain of distances over
the pulleys)."""

import numpy as np
import pytest

from sim_core.model import state_jacobian
from sim_core.physics import _constraints_numba as constraint_compiled
from sim_core.physics import constraints
from sim_core.physics.constraints import constraint_terms, material_point
from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from tests.compiled_rows import assert_rows_equal_python, height_row, jacobian_difference

pytestmark = pytest.mark.skipif(not constraint_compiled.AVAILABLE, reason="numba not installed")

VARIANTS = {
    "friction_payload": dict(n_nodes=3, friction=True, payload=1000.0),
    "no_torsion": dict(n_nodes=3, torsion=False, payload=1000.0),
    "inextensible_rope": dict(n_nodes=3, rope_elasticity=False, payload=1000.0),
}


@pytest.fixture(scope="module", params=sorted(VARIANTS))
def state(request):
    ts = build_telescopic(TelescopicParams(**VARIANTS[request.param]))
    z, _ = initial_equilibrium(ts)
    m = ts.model
    rng = np.random.default_rng(11)
    z = z + 1e-4 * rng.standard_normal(m.n_dof)
    zd = 0.05 * rng.standard_normal(m.n_dof)
    return request.param, ts, z, zd


def test_program_covers_the_scene_constraints(state):
    name, ts, _, _ = state
    prog = constraint_compiled.program_for(ts.model.nonlinear)
    assert prog is not None
    assert prog.m == sum(c.m for c in ts.model.nonlinear)
    kinds = set(prog.c_kind.tolist())
    assert {constraint_compiled.DIFF_R, constraint_compiled.DIFF_PSI,
            constraint_compiled.DISTANCE} <= kinds
    assert (constraint_compiled.ROPE in kinds) == (name == "inextensible_rope")


def test_rows_equal_the_python_closures(state, monkeypatch):
    _, ts, z, zd = state
    m = ts.model
    Q, Qd = m.full_state(0.7, z, zd)
    assert_rows_equal_python(m.nonlinear, 0.7, Q, Qd, monkeypatch)


def test_jacobian_columns_equal_the_python_pieces(state, monkeypatch):
    _, ts, z, zd = state
    y = np.concatenate([z, zd])
    assert jacobian_difference(ts.model, 0.7, y, monkeypatch, state_jacobian,
                               "COMPILED_CONSTRAINT_COLUMNS") < 1e-6


def test_a_constraint_without_program_takes_the_python_path(state):
    """A hand-written constraint (no ``program``) is not compiled: program_for says None and
    constraint_terms evaluates the closures (the rows then include the extra one)."""
    _, ts, z, zd = state
    m = ts.model
    tip = material_point(m, len(m.beams) - 1, s_fixed=m.beams[-1].length)
    extra = height_row(tip)
    cons = list(m.nonlinear) + [extra]
    assert constraint_compiled.program_for(cons) is None
    Q, Qd = m.full_state(0.0, z, zd)
    phi, G, _, _ = constraint_terms(cons, 0.0, Q, Qd)
    assert phi.shape == (sum(c.m for c in cons),)
    np.testing.assert_allclose(phi[-1], np.real(tip(Q)[0][2]), rtol=1e-14)


def test_sweep_columns_are_the_differences_of_the_closures(state, monkeypatch):
    """prog.columns against forward differences of the Python rows with the same steps:
    r1 = G^T lambda and r2 = G Q_ddot - (b_ddot - g_QQ[Q_dot, Q_dot] - 2 xi1 Phi_dot - xi2^2
    Phi), for random lambda and Q_ddot.  Equal values differenced with the same step agree to
    round-off / step (~1e-8 of the columns' scale; 1e-6 allowed)."""
    _, ts, z, zd = state
    m = ts.model
    t = 0.7
    Q, Qd = m.full_state(t, z, zd)
    Q, Qd = Q.copy(), Qd.copy()
    rng = np.random.default_rng(3)
    lam = 1e4 * rng.standard_normal(sum(c.m for c in m.nonlinear))
    Qdd = rng.standard_normal(len(Q))
    xi1, xi2 = 20.0, 20.0
    prog = constraint_compiled.program_for(m.nonlinear)
    cols = np.flatnonzero(prog.dependencies(Q).any(axis=0))
    steps = state_jacobian._steps(Q[cols], state_jacobian.REL_STEP)
    b0, bd, bdd = constraints.targets(m.nonlinear, t)
    d1, d2 = prog.columns(Q, Qd, Qdd, lam, b0, bd, bdd, xi1, xi2, cols, steps)
    monkeypatch.setattr(constraints, "COMPILED_ROWS", False)

    def r(Qx):
        phi, G, dphi, rhs = constraint_terms(m.nonlinear, t, Qx, Qd)
        return G.T @ lam, G @ Qdd - (rhs - 2.0 * xi1 * dphi - xi2 ** 2 * phi)
    r1_0, r2_0 = r(Q)
    e1 = np.empty_like(d1)
    e2 = np.empty_like(d2)
    for k, (j, h) in enumerate(zip(cols, steps)):
        Qx = Q.copy()
        Qx[j] += h
        r1, r2 = r(Qx)
        e1[:, k] = (r1 - r1_0) / h
        e2[:, k] = (r2 - r2_0) / h
    assert np.abs(e1).max() > 0 and np.abs(e2).max() > 0
    np.testing.assert_allclose(d1, e1, rtol=0, atol=1e-6 * np.abs(e1).max())
    np.testing.assert_allclose(d2, e2, rtol=0, atol=1e-6 * np.abs(e2).max())
