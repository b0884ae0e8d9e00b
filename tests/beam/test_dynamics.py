"""Dynamic validation: Fryba's moving force (docs/model.md#check-moving-load)."""

import numpy as np
import pytest

from sim_core.integrate import integrate_generalized_alpha
from sim_core.model.boundary import boundary_condition, reference_basis
from sim_core.model.model import Model
from sim_core.physics.beam.moving_node_beam import Beam
from sim_core.physics.effects import Elasticity, Inertia, PointLoad
from sim_core.validation.closed_form import fryba_deflection
from tests.beam.conftest import I_T, RHO, A, E, L, section


def _simply_supported(load):
    b = Beam("b", L, section(), (0.0, L), n_nodes=9, reference_basis=reference_basis([1, 0, 0]))
    cons = [boundary_condition([0], [b], 0, "left", "pinned", [0, 0, 0]),
            boundary_condition([0], [b], 0, "right", "roller", [L, 0, 0], [1, 0, 0])]
    return Model([b], [Inertia(), Elasticity()], [load], cons), b


@pytest.mark.parametrize("alpha", [0.25, 0.5])
def test_fryba_moving_force_midspan(alpha):
    """Force P crossing a simply supported beam at speed c (Fryba).  Midspan deflection within
    2 % of its peak over the whole crossing.  Time integration: generalized-alpha without
    numerical damping (rho_inf = 1), h = T_1/100 (phase error (omega_1 h)^2/12 ~ 3e-4)."""
    m_ = RHO * A
    EI = E * I_T
    w1 = (np.pi / L) ** 2 * np.sqrt(EI / m_)
    c = alpha * w1 * L / np.pi
    P = 500.0                                  # static midspan deflection / L ~ 5e-4
    load = PointLoad(0, lambda t: min(c * t, L), lambda t: np.array([0.0, 0.0, -P]))
    model, b = _simply_supported(load)
    Q0 = b.straight_coordinates([0, 0, 0], [1, 0, 0])
    z0, zd0 = model.reduced_state(0.0, Q0, np.zeros_like(Q0))
    t_end = L / c
    h = (2 * np.pi / w1) / 100
    t_eval = np.linspace(0.0, t_end, 41)
    res = integrate_generalized_alpha(model, (0.0, t_end), z0, zd0, rho_inf=1.0, h=h,
                                      t_eval=t_eval)
    w_num = np.array([-model.point(0, L / 2, model.full_state(t, q, 0 * q)[0])[0][2]
                      for t, q in zip(res.t, res.q)])
    w_ref = fryba_deflection(L / 2, res.t, P, c, L, EI, m_, n_terms=31)
    peak = np.max(np.abs(w_ref))
    assert np.max(np.abs(w_num - w_ref)) < 0.02 * peak


@pytest.mark.slow
def test_free_vibration_energy_conserved_to_solver_tolerance():
    """Undamped, unfiltered free vibration from a statically deflected (bent and twisted) shape
    of a stocky cantilever: T + U constant (docs/model.md#check-energy).  The drift over one
    period is below 1e-4 of U_0 and shrinks as rtol is tightened (measured 1.3e-7 at rtol 1e-5,
    1.5e-9 at 1e-7).
    Explicit RK45 is stiffness-limited here (highest mode ~350 x the first), hence `slow`."""
    from scipy.integrate import solve_ivp

    from sim_core.model.statics import static_equilibrium
    from sim_core.physics.beam.moving_node_beam import BeamSection
    sec = BeamSection(EA=E * 1e-2, GJ=8e10 * 2e-4, EI_t=E * 1e-4, EI_b=E * 1e-4, rhoA=RHO * 1e-2,
                      J_s=RHO * 2e-4)
    b = Beam("b", 4.0, sec, (0.0, 4.0), n_nodes=3, reference_basis=reference_basis([1, 0, 0]))
    cons = [boundary_condition([0], [b], 0, "left", "clamped", [0, 0, 0], [1, 0, 0]),
            boundary_condition([0], [b], 0, "right", "free")]
    tip = PointLoad(0, lambda t: 4.0, lambda t: np.array([0.0, 2e4, -5e4]))
    m_load = Model([b], [Inertia(), Elasticity()], [tip], cons)
    Q0 = b.straight_coordinates([0, 0, 0], [1, 0, 0])
    z0, _ = m_load.reduced_state(0.0, Q0, np.zeros_like(Q0))
    z_def = static_equilibrium(m_load, z0)
    model = Model([b], [Inertia(), Elasticity()], [], cons)
    Q, _ = model.full_state(0.0, z_def, np.zeros_like(z_def))
    U0 = model.energies(0.0, Q, np.zeros_like(Q))["U"]
    w1 = 1.8751 ** 2 * np.sqrt(E * 1e-4 / (RHO * 1e-2 * 4.0 ** 4))
    t_end = 2 * np.pi / w1
    n = model.n_dof
    drifts = []
    for rtol in (1e-5, 1e-6):
        sol = solve_ivp(model.rhs, (0.0, t_end), np.concatenate([z_def, 0 * z_def]), rtol=rtol,
                        atol=1e-3 * rtol * np.max(np.abs(z_def)), t_eval=np.linspace(0, t_end, 9))
        assert sol.success
        e_tot = []
        for t, y in zip(sol.t, sol.y.T):
            Qt, Qdt = model.full_state(t, y[:n], y[n:])
            en = model.energies(t, Qt, Qdt)
            e_tot.append(en["T"] + en["U"])
        drifts.append(np.max(np.abs(np.array(e_tot) - U0)) / U0)
    assert drifts[0] < 1e-4
    assert drifts[1] < drifts[0]
