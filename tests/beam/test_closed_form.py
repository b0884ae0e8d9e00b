"""Closed-form validation of the beam (docs/model.md#check-cantilever-statics,
docs/model.md#check-cantilever-frequencies) and a refinement study."""

import numpy as np
import pytest

from sim_core.model.statics import linear_modes, static_equilibrium
from sim_core.physics.effects import PointLoad
from sim_core.validation.closed_form import (
    cantilever_bending_omegas,
    cantilever_tip_load,
    cantilever_uniform_load,
    fixed_free_axial_f1,
    fixed_free_torsion_f1,
)
from tests.beam.conftest import G_MOD, I_B, I_T, RHO, A, E, L, cantilever, section


def _solve_static(m, Q0):
    z0, _ = m.reduced_state(0.0, Q0, np.zeros_like(Q0))
    z = static_equilibrium(m, z0)
    Q, _ = m.full_state(0.0, z, np.zeros_like(z))
    return Q


def test_cantilever_tip_load():
    """w = PL^3/(3EI), slope PL^2/(2EI) (docs/model.md#check-cantilever-statics);
    deflection/L = 1e-4, so geometric nonlinearity is O(1e-8) and the 0.5 % tolerance of that
    check is far above it."""
    P = -1e3 * 0.1
    m, Q0 = cantilever(loads=[PointLoad(0, lambda t: L, lambda t: np.array([0.0, 0.0, P]))])
    Q = _solve_static(m, Q0)
    r, kin, _ = m.point(0, L, Q)
    ref = cantilever_tip_load(P, L, E * I_T)
    assert r[2] == pytest.approx(ref.deflection, rel=5e-3)
    assert kin.rp[0, 2] / kin.rp[0, 0] == pytest.approx(ref.slope, rel=5e-3)


def test_cantilever_self_weight():
    g = np.array([0.0, 0.0, -9.81 * 0.01])        # scaled gravity keeps deflection/L < 1e-3
    m, Q0 = cantilever(gravity=g)
    Q = _solve_static(m, Q0)
    r, kin, _ = m.point(0, L, Q)
    q = RHO * A * g[2]
    ref = cantilever_uniform_load(q, L, E * I_T)
    assert r[2] == pytest.approx(ref.deflection, rel=5e-3)
    assert kin.rp[0, 2] / kin.rp[0, 0] == pytest.approx(ref.slope, rel=5e-3)


@pytest.fixture(scope="module")
def cantilever_modes():
    m, Q0 = cantilever()
    z0, _ = m.reduced_state(0.0, Q0, np.zeros_like(Q0))
    w, vec = linear_modes(m, z0)
    return w


def test_cantilever_bending_frequencies(cantilever_modes):
    """First three bending frequencies in both planes (docs/model.md#check-cantilever-frequencies;
    Euler-Bernoulli, no rotary inertia)."""
    w = cantilever_modes
    m_ = RHO * A
    for EI in (E * I_T, E * I_B):
        for k, (ref, tol) in enumerate(zip(cantilever_bending_omegas(EI, m_, L, 3), (5e-3, 1e-2, 2e-2))):
            assert np.min(np.abs(w / ref - 1)) < tol, (k, ref)


def test_cantilever_axial_and_torsional_frequencies(cantilever_modes):
    w = cantilever_modes
    fa = fixed_free_axial_f1(E * A, RHO * A, L)
    ft = fixed_free_torsion_f1(G_MOD * (I_T + I_B), section().J_s, L)
    assert np.min(np.abs(w / (2 * np.pi * fa) - 1)) < 1e-2
    assert np.min(np.abs(w / (2 * np.pi * ft) - 1)) < 1e-2


def test_refinement_study_bending_frequency_converges_at_high_order():
    """Error of the 3rd bending eigenvalue for 2, 4, 8, 16 sub-elements.

    Observed asymptotic rate: the eigenvalue error falls by 2^8 or more per halving of l
    (order >= 8, as expected for the C4 quintic spline: 2 (p - 1) with p = 5), until it reaches
    the round-off floor of the finite-difference tangent (~1e-8)."""
    ref = cantilever_bending_omegas(E * I_T, RHO * A, L, 3)[2]
    errs = []
    for n_nodes in (3, 5, 9, 17):
        m, Q0 = cantilever(n_nodes=n_nodes)
        z0, _ = m.reduced_state(0.0, Q0, np.zeros_like(Q0))
        w, _ = linear_modes(m, z0)
        errs.append(np.min(np.abs(w / ref - 1)))
    errs = np.array(errs)
    assert errs[0] > errs[1] > errs[2]
    rate = np.log2(errs[1] / errs[2])
    assert rate > 8.0, errs
    assert errs[3] < 1e-6, errs
