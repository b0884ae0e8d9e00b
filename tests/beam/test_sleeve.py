"""A beam drawn through a rigid frictionless point sleeve (docs/model.md#check-sleeve).

The sleeve exit is a fixed spatial point; the element's end node sits there and its material
coordinate s_1(t) is prescribed: material flows through the node (Section 3).
"""

import numpy as np
import pytest

from sim_core import load_scene
from sim_core.integrate import integrate_generalized_alpha
from sim_core.model.statics import static_equilibrium
from sim_core.systems.beam.build import build_model
from sim_core.validation.closed_form import bigoni_sleeve


def _scene(**over):
    base = {"effects.gravity": False, "effects.filtering": False, "initial.static_equilibrium": False}
    base.update(over)
    return load_scene("beam_through_sleeve", overrides=base)


def test_axial_drawing_without_load_is_a_rigid_flow():
    """No gravity, no load: the rod stays straight, the material velocity is v e_s everywhere,
    the kinetic energy is constant and the sleeve exerts no force (eta = 0)."""
    sc = _scene(**{"point_loads": [], "beams.0.n_nodes": 5})
    model, Q0, Qd0 = build_model(sc)
    z, zd = model.reduced_state(0.0, Q0, Qd0)
    # implicit generalized-alpha, fixed step: the exact solution (rigid flow, q_ddot = 0) is
    # reproduced by the scheme, so any deviation is a modelling error, not a time-step error
    res = integrate_generalized_alpha(model, (0.0, 1.0), z, zd, h=0.05, t_eval=[0.0, 0.5, 1.0])
    rhoA = model.beams[0].section.rhoA
    for t, zz, zzd in zip(res.t, res.q, res.v):
        Q, Qd = model.full_state(t, zz, zzd)
        el, imap = model.beams[0].elements[0], model.beams[0].index_map[0]
        kin = el.evaluate(Q[imap])
        v = np.einsum("gin,n->gi", kin.J_r, Qd[imap])
        np.testing.assert_allclose(v, np.tile([0.5, 0.0, 0.0], (len(v), 1)), atol=1e-9 * 0.5)
        np.testing.assert_allclose(kin.r[:, 1:], 0.0, atol=1e-12)
        # the modelled domain grows as material leaves the sleeve: T = rhoA l(t) v^2 / 2
        ell = 12.0 - Q[model.beams[0].s_coord(0)]
        T = model.energies(t, Q, Qd)["T"]
        assert T == pytest.approx(0.5 * rhoA * ell * 0.5 ** 2, rel=1e-9)
        lam = model.reactions(t, zz, zzd)
        sleeve_s_row = model.constraints[0].rows.shape[0] - 1
        assert abs(lam[sleeve_s_row]) < 1e-5   # axial sleeve reaction (eta) vanishes (N; EA = 1.6e9 N)
    # the free length grew by v t
    assert Q[model.beams[0].s_coord(0)] == pytest.approx(8.0 - 0.5 * 1.0, abs=1e-12)


@pytest.mark.parametrize("s1", [8.0, 6.0, 4.0])
def test_tip_load_deflection_and_configurational_force(s1):
    """Quasi-static tip load P at free length l = 12 - s_1: tip deflection P l^3/(3EI) and the
    axial force needed to hold the rod in the sleeve = M^2/(2EI), M = P l (Bigoni et al. 2015).
    Deflection/l ~ 1e-3 keeps geometric nonlinearity below 1e-3; tolerance 2 %
    (docs/model.md#check-sleeve)."""
    P = -50.0
    sc = _scene(**{"point_loads.0.force": [0.0, 0.0, P], "beams.0.breakpoints": [s1, 12.0],
                   "beams.0.origin": [-s1, 0.0, 0.0], "boundary.0.speed": 0.0})
    model, Q0, _ = build_model(sc)
    z0, _ = model.reduced_state(0.0, Q0, np.zeros_like(Q0))
    z = static_equilibrium(model, z0)
    Q, _ = model.full_state(0.0, z, np.zeros_like(z))
    ell = 12.0 - s1
    EI = sc["beams"][0]["section"]["E"] * sc["beams"][0]["section"]["I_t"]
    ref = bigoni_sleeve(abs(P), ell, EI)
    r, _, _ = model.point(0, 12.0, Q)
    assert r[2] == pytest.approx(-ref.tip_deflection, rel=2e-2)
    lam = model.reactions(0.0, z, np.zeros_like(z))
    # the last row of the sleeve condition prescribes s_1; its multiplier is the holding force
    sleeve_rows = model.constraints[0].rows.shape[0]
    assert lam[sleeve_rows - 1] == pytest.approx(ref.configurational_force, rel=2e-2)


def test_energy_balance_of_the_open_domain():
    """Tip-loaded rod pushed out at 0.5 m/s (docs/model.md#check-sleeve): the energy of the
    modelled domain,
    E = T + U - P . r_tip, changes by the work of the sleeve's axial reaction (eta s_dot) plus the
    kinetic energy carried in by the material leaving the sleeve (rho A v^2 / 2 per metre):
    dE = int eta s_dot dt + rho A v^3 t / 2 to 1e-3 of dE.  Generalized-alpha with rho_inf = 1
    (no numerical dissipation), h = 2 ms; the work integral by the trapezoidal rule."""
    P, v = -50.0, -0.5
    sc = _scene(**{"point_loads.0.force": [0.0, 0.0, P], "boundary.0.speed": v,
                   "beams.0.n_nodes": 5})
    model, Q0, Qd0 = build_model(sc)
    z0, zd0 = model.reduced_state(0.0, Q0, Qd0)
    z0 = static_equilibrium(model, z0)
    t_end = 2.0
    res = integrate_generalized_alpha(model, (0.0, t_end), z0, zd0, rho_inf=1.0, h=0.002,
                                      t_eval=np.linspace(0.0, t_end, 201))
    s_row = model.constraints[0].rows.shape[0] - 1
    rhoA = model.beams[0].section.rhoA
    E, power = [], []
    for t, q, qd in zip(res.t, res.q, res.v):
        Q, Qd = model.full_state(t, q, qd)
        en = model.energies(t, Q, Qd)
        r, _, _ = model.point(0, 12.0, Q)
        E.append(en["T"] + en["U"] - P * r[2])
        power.append(model.reactions(t, q, qd)[s_row] * v)
    E, power = np.array(E), np.array(power)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(res.t))])
    flux = 0.5 * rhoA * v ** 2 * abs(v) * res.t
    dE = E - E[0]
    assert np.max(np.abs(dE - (work + flux))) < 1e-3 * abs(dE[-1])
