"""Dynamic validation: Fryba's moving force (SCENARIOS C3)."""

import numpy as np
import pytest

from sim_core.assemble import reference_basis
from sim_core.beam.moving_node_beam import Beam
from sim_core.effects import Elasticity, Inertia, PointLoad
from sim_core.integrators import integrate_generalized_alpha
from sim_core.model import Model, boundary_condition
from sim_core.validation.closed_form import fryba_deflection
from tests.beam.conftest import A, E, I_T, L, RHO, section


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
