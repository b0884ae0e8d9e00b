"""Nonlinear constraints with multipliers (index-1 + Baumgarte) against exact elimination.

A clamp written as nonlinear constraints (centroid coincidence + Cardan-angle coincidence,
Zhao-Qi-Wang 2024 Section 6) must give the same accelerations and reactions as the linear
clamp eliminated exactly, at any state consistent with the constraints.
"""

import numpy as np

from sim_core.model.boundary import boundary_condition
from sim_core.model.model import Model
from sim_core.physics.constraints import angle_coincidence, material_point, point_coincidence
from sim_core.physics.effects import PointLoad
from tests.beam.conftest import cantilever


def test_kkt_clamp_equals_eliminated_clamp(rng):
    tip = PointLoad(0, lambda t: 10.0, lambda t: np.array([0.0, 3e3, -5e3]))
    lin, Q0 = cantilever(loads=[tip], gravity=[0, 0, -9.81])
    b = lin.beams[0]
    # same beam: only the material end conditions are linear, the clamp is nonlinear
    cons = [boundary_condition([0], [b], 0, "left", "free"),
            boundary_condition([0], [b], 0, "right", "free")]
    nl = Model([b], lin.effects, lin.point_loads, cons)
    root = material_point(nl, 0, s_fixed=0.0)
    nl.nonlinear = [point_coincidence("root", root, fixed=[0.0, 0.0, 0.0]),
                    angle_coincidence("root_angles", root, fixed=[0.0, 0.0, 0.0])]
    # a deformed, moving state that satisfies the clamp
    z = 1e-3 * rng.normal(size=lin.n_dof)
    zd = 1e-2 * rng.normal(size=lin.n_dof)
    Q, Qd = lin.full_state(0.0, z, zd)
    zdd_lin = lin.accelerations(0.0, z, zd)
    Qdd_lin = lin.P @ zdd_lin
    zn, zdn = nl.reduced_state(0.0, Q, Qd)
    np.testing.assert_allclose(nl.constraint_violation(0.0, zn, zdn), 0.0, atol=1e-12)
    zdd_nl, lam = nl.accelerations_and_multipliers(0.0, zn, zdn)
    Qdd_nl = nl.P @ zdd_nl
    scale = np.max(np.abs(Qdd_lin))
    np.testing.assert_allclose(Qdd_nl, Qdd_lin, atol=1e-7 * scale)
    # reaction force at the root: linear rows 0..2 are r_1 = 0
    R_lin = lin.reactions(0.0, z, zd)[:3]
    np.testing.assert_allclose(lam[:3], R_lin, rtol=1e-6, atol=1e-6 * np.max(np.abs(R_lin)))


def test_selection_fast_path_equals_the_dense_projection():
    """Model.reduced_mass_force takes P^T M P as a sub-matrix when P only selects (and signs)
    coordinates; the dense products give the same numbers (bitwise: one non-zero term per sum,
    times +-1).  A P whose columns mix coordinates keeps the dense route."""
    from sim_core.model.model import _selection
    from sim_core.systems.telescopic.params import TelescopicParams
    from sim_core.systems.telescopic.build import build_telescopic
    m = build_telescopic(TelescopicParams(n_nodes=3)).model
    assert m._sel is not None
    rng = np.random.default_rng(1)
    z = 1e-3 * rng.standard_normal(m.n_dof)
    zd = 1e-2 * rng.standard_normal(m.n_dof)
    Mr, Fr = m.reduced_mass_force(0.2, z, zd)
    sel, m._sel = m._sel, None
    try:
        Mr0, Fr0 = m.reduced_mass_force(0.2, z, zd)
    finally:
        m._sel = sel
    np.testing.assert_array_equal(Mr, Mr0)
    np.testing.assert_array_equal(Fr, Fr0)
    P = np.zeros((3, 2))
    P[0, 0], P[2, 1] = 1.0, -1.0
    rows, vals, _ = _selection(P)
    assert list(rows) == [0, 2] and list(vals) == [1.0, -1.0]
    P[1, 1] = 0.5                                  # column 1 mixes two coordinates
    assert _selection(P) is None
    assert _selection(np.eye(3)[:, [0, 0]]) is None    # same row twice
