"""solver.method = "generalized_alpha": accuracy of the cantilever released under gravity, the
method's second order, the compiled loop against the numpy reference, and the scene rules.

The reference is the exact modal solution (sim_core.validation.closed_form.cantilever_release_tip,
50 modes).  At 2 sub-elements the spline beam's own spatial error on this case is 1.5e-5 m (a
run converged in time).  Generalized-alpha is second order (Chung & Hulbert 1993): halving h
quarters the time error, checked against a much finer run of the same model with a band (3, 5)
around 4 for the higher-order terms."""

import numpy as np
import pytest

import sim_core
from sim_core.errors import SceneError
from sim_core.integrate.driver import StructuredTangent
from sim_core.integrate.generalized_alpha import integrate_generalized_alpha
from sim_core.systems.beam.build import build_model
from sim_core.validation.closed_form import cantilever_release_tip

EI, RHOA, L = 7.22e8, 318.86, 10.0


def _tip_error(over: dict) -> tuple[float, sim_core.Result]:
    res = sim_core.simulate(sim_core.load_scene("cantilever_release", over))
    w = -res["tip_position"][:, 2]
    return float(np.max(np.abs(w - cantilever_release_tip(res.t, EI, RHOA, L)))), res


def test_shipped_scene_is_within_a_tenth_of_a_millimetre():
    """The shipped settings (h = 0.35 ms, rho_inf = 1) keep the tip within 1e-4 m of the modal
    solution over 2 s (peak deflection 11 mm), on the compiled path, with one tangent."""
    err, res = _tip_error({})
    assert err < 1e-4
    assert res.stats["compiled"] and res.stats["n_jac"] == 1
    assert not res.suspect and res.stats["checks"]["energy_balance"]["value"] < 1e-6


def test_second_order_in_the_step():
    """Against a run of the same discrete model at h = 25 us (its own time error ~1e-7 m, so the
    spatial error cancels), halving h from 1 ms to 0.5 ms divides the tip error by ~4 (0.5 s)."""
    def tip(h):
        res = sim_core.simulate(sim_core.load_scene("cantilever_release", {
            "solver.h": h, "solver.t_end": 0.5, "solver.n_output": 101,
            "solver.newton_atol": 1e-11}))
        return res["tip_position"][:, 2]
    ref = tip(2.5e-5)
    e1, e2 = (float(np.max(np.abs(tip(h) - ref))) for h in (1e-3, 5e-4))
    assert 3.0 < e1 / e2 < 5.0


def test_compiled_loop_equals_the_numpy_method():
    """The compiled loop (Newton to 1e-12 m) and integrate_generalized_alpha (numpy, the same
    scheme and step, its default Newton test) give the same states to 1e-9 m over 0.1 s."""
    sc = sim_core.load_scene("cantilever_release", {"solver.t_end": 0.1, "solver.n_output": 11,
                                                    "solver.h": 1e-3, "solver.newton_atol": 1e-12})
    res = sim_core.simulate(sc)
    model, Q0, Qd0 = build_model(sc)
    z0, zd0 = model.reduced_state(0.0, Q0, Qd0)
    ref = integrate_generalized_alpha(StructuredTangent(model), (0.0, 0.1), z0, zd0, h=1e-3,
                                      rho_inf=1.0, t_eval=res.t)
    n = model.n_dof
    np.testing.assert_allclose(res["state"][:, :n], ref.q, rtol=0, atol=1e-9)


def test_scene_rules():
    """Beam scenes default to generalized-alpha, error-controlled (no h) with h_max = t_end and
    newton_atol = atol / 10; h fixes the step and excludes h_max; the alpha keys belong to
    generalized_alpha; telescopic scenes keep the error-controlled ODE methods."""
    sol = sim_core.load_scene("beam_through_sleeve")["solver"]
    assert sol["method"] == "generalized_alpha" and "h" not in sol
    assert sol["h_max"] == sol["t_end"] and sol["newton_atol"] == pytest.approx(0.1 * sol["atol"])
    with pytest.raises(SceneError, match=r"solver\.h_max .*only the error-controlled"):
        sim_core.load_scene("cantilever_release", {"solver.h_max": 1e-3})
    with pytest.raises(SceneError, match=r"solver\.h_max = -1.0: out of range"):
        sim_core.load_scene("beam_through_sleeve", {"solver.h_max": -1.0})
    with pytest.raises(SceneError, match=r"solver\.rho_inf .*only method = 'generalized_alpha'"):
        sim_core.load_scene("beam_through_sleeve", {"solver.method": "RK45", "solver.rho_inf": 0.5})
    with pytest.raises(SceneError, match=r"solver\.method = 'generalized_alpha'"):
        sim_core.load_scene("telescopic_extraction", {"solver.method": "generalized_alpha"})


def test_sleeve_scene_runs_the_numpy_path():
    """A model outside the compiled loop (a sleeve: time-dependent boundary) runs the numpy
    method at the same fixed step and agrees with RK45 at a tight tolerance to 1e-7 m (the
    alpha run's time error at h = 0.2 ms is ~3e-9 m here)."""
    over = {"solver.t_end": 0.1, "solver.n_output": 11}
    alpha = sim_core.simulate(sim_core.load_scene("beam_through_sleeve", {
        **over, "solver.method": "generalized_alpha", "solver.h": 2e-4, "solver.rho_inf": 1.0}))
    rk = sim_core.simulate(sim_core.load_scene("beam_through_sleeve", {
        **over, "solver.rtol": 1e-9, "solver.atol": 1e-12}))
    assert not alpha.stats["compiled"]
    np.testing.assert_allclose(alpha["tip_position"], rk["tip_position"], rtol=0, atol=1e-7)
