"""Index-1 (M = I) wrapper of a nonlinearly constrained model (sim_core.integrate.index1).

Generalized-alpha on the Baumgarte-stabilized ODE z_ddot = a(t, z, z_dot) of the nearly rigid
telescopic case 9.1 (Zhao-Qi-Wang 2024 Sec. 9.1) against explicit RK45 on model.rhs.
"""

import numpy as np
import pytest

from sim_core.integrate import integrate_generalized_alpha
from sim_core.integrate.driver import integrate
from sim_core.integrate.index1 import Index1System
from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium


def test_wrapper_is_identity_mass_and_model_accelerations():
    ts = build_telescopic(TelescopicParams(n_nodes=3, E=2.1e12, payload=1000.0))
    m = ts.model
    sys_ = Index1System(m)
    z, zd = m.reduced_state(0.0, ts.Q0, np.zeros_like(ts.Q0))
    M, f = sys_.mass_and_force(0.0, z, zd)
    assert sys_.n == m.n_dof
    np.testing.assert_array_equal(M, np.eye(m.n_dof))
    np.testing.assert_allclose(f, m.accelerations(0.0, z, zd), rtol=0, atol=0)


@pytest.mark.slow
def test_generalized_alpha_on_index1_wrapper_matches_rk45_rigid_case():
    """Window 0.05 s from the static equilibrium (~10-30 s static solve + ~40 s stepping on a
    shared 2-core machine, hence `slow`).

    Tolerance from the integrators' tolerances: both control the local error per step to
    atol + rtol |y| (scipy norm); for the tip position (|r| ~ 15 m) the per-step bound is
    rtol |r|.  The global error of a stable run over a window of a few dozen steps stays
    within ~ rtol |r| (errors are not all of one sign); we allow the sum of both runs' bounds:
    tol = (rtol_GA + rtol_RK) |r_tip| + atol."""
    p = TelescopicParams(n_nodes=3, E=2.1e12, payload=1000.0)    # case 9.1, filter h = 0.01 s
    ts = build_telescopic(p)
    m = ts.model
    z0, _ = initial_equilibrium(ts)
    t_end = 0.05
    rtol_ga, atol_ga = 1e-5, 1e-6
    rtol_rk, atol_rk = 1e-7, 1e-8
    _, ys, _ = integrate(m, np.concatenate([z0, 0 * z0]), t_end,
                              {"rtol": rtol_rk, "atol": atol_rk, "n_output": 2})
    res = integrate_generalized_alpha(Index1System(m), (0.0, t_end), z0, 0 * z0, rtol=rtol_ga,
                                      atol=atol_ga, t_eval=[t_end])
    n = m.n_dof

    def tip(y):
        Q, _ = m.full_state(t_end, y[:n], y[n:])
        return ts.tip(Q)[0]

    r_rk = tip(ys[-1])
    r_ga = tip(np.concatenate([res.q[-1], res.v[-1]]))
    tol = (rtol_ga + rtol_rk) * np.linalg.norm(r_rk) + atol_ga
    assert np.linalg.norm(r_ga - r_rk) < tol
    # the Baumgarte feedback keeps the position-level constraints closed along the GA run
    assert np.max(np.abs(m.constraint_violation(t_end, res.q[-1], res.v[-1]))) < 1e-6
