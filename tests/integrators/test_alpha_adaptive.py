"""Error-controlled generalized-alpha (solver.method = "generalized_alpha" without h, the beam
scenes' default): accuracy against the released cantilever's modal solution, convergence as
rtol/atol tighten, the sleeve scene against RK45, and the typed errors of a stall, the wall
budget and Ctrl-C.

The tolerance argument.  A step is accepted when the RMS over the n coordinates of
e_i / (atol + rtol max|q_i|) is <= 1, so no coordinate's estimated local error exceeds
sqrt(n) (atol + rtol max|q_i|).  The tip of a beam whose right end is a free material point is
a node, so each tip coordinate is one of the q_i.  For the (nearly linear, undamped or
dissipative) beam the propagation of a local error does not amplify it, so after N accepted
steps the time error of a tip coordinate is at most N sqrt(n) (atol + rtol max|q_tip|): the
bound ``_time_error_bound`` below, loose (the local errors do not all add with one sign) but
following from the tolerances alone.  The estimate is asymptotic (e_q = c_q h^2 delta q_ddot,
Zienkiewicz & Xie 1991), which the factor sqrt(n) and the worst-case sum more than cover.
"""

import numpy as np
import pytest

import sim_core
from sim_core.errors import SimulationError, StalledIntegration
from sim_core.model.model import Model
from sim_core.scene.io import apply_overrides, read_scene
from sim_core.systems.beam.schema import validate
from sim_core.validation.closed_form import cantilever_release_tip

EI, RHOA, L = 7.22e8, 318.86, 10.0
SPATIAL = 1.5e-5     # m, the 2-sub-element beam's own error on this case (test_alpha_method.py)


def _cantilever(over: dict | None = None) -> dict:
    """The shipped cantilever_release without its fixed step (and without the newton_atol
    chosen for it): the beam default, error-controlled steps from rtol/atol."""
    raw, source = read_scene("cantilever_release")
    del raw["solver"]["h"], raw["solver"]["newton_atol"]
    return validate(apply_overrides(raw, over or {}), source)


def _time_error_bound(res: sim_core.Result, values: np.ndarray) -> float:
    """N sqrt(n) (atol + rtol max|value|): the module doc's bound on a node coordinate."""
    st = res.stats
    return st["n_steps"] * np.sqrt(st["n_dof"]) * (st["atol"] + st["rtol"] * np.max(np.abs(values)))


def test_default_method_reaches_the_modal_solution():
    """Defaults rtol 1e-6, atol 1e-8 (rho_inf 1 of the scene): the tip deflection is within the
    spatial error plus the tolerance bound of the 50-mode solution over 2 s, on the compiled
    path with a handful of tangents; it is also within the scene's 0.1 mm."""
    sc = _cantilever()
    assert sc["solver"]["method"] == "generalized_alpha" and "h" not in sc["solver"]
    res = sim_core.simulate(sc)
    w = -res["tip_position"][:, 2]
    err = float(np.max(np.abs(w - cantilever_release_tip(res.t, EI, RHOA, L))))
    st = res.stats
    assert st["compiled"] and st["step_control"] == "error" and st["n_jac"] <= 5
    assert err < SPATIAL + _time_error_bound(res, w)
    assert err < 1e-4
    assert 0 < st["min_step_s"] <= st["max_step_s"] <= sc["solver"]["h_max"]
    assert st["n_steps"] > 0 and st["n_rejected"] >= 0 and st["n_lu"] >= st["n_jac"]
    assert not res.suspect


def test_error_falls_as_the_tolerance_tightens():
    """Against a fixed-step run of the same discrete model at h = 25 us (its time error ~1e-7 m,
    so the spatial error cancels), 0.5 s: each tenfold tightening of rtol and atol cuts the
    tip error by more than 2 (tolerance proportionality of an error-per-step control of a
    second-order method: h ~ tol^(1/3), error ~ h^2 ~ tol^(2/3), a factor 4.6 a decade), and
    each error is within its tolerance bound."""
    ref = sim_core.simulate(sim_core.load_scene("cantilever_release", {
        "solver.h": 2.5e-5, "solver.t_end": 0.5, "solver.n_output": 101,
        "solver.newton_atol": 1e-11}))
    errs = []
    for rtol in (1e-4, 1e-5, 1e-6):
        res = sim_core.simulate(_cantilever({"solver.t_end": 0.5, "solver.n_output": 101,
                                             "solver.rtol": rtol, "solver.atol": rtol / 100}))
        z = res["tip_position"][:, 2]
        errs.append(float(np.max(np.abs(z - ref["tip_position"][:, 2]))))
        assert errs[-1] < _time_error_bound(res, z)
    assert errs[0] > 2.0 * errs[1] > 4.0 * errs[2]


def test_numpy_path_meets_the_same_bound(monkeypatch):
    """The numpy path (a model outside the compiled loop; here the plan withheld) takes the
    same error-controlled method (its position estimate, floor and controller constants) and
    meets the same tolerance bound against the fine fixed-step run, 0.2 s at rtol 1e-5."""
    over = {"solver.t_end": 0.2, "solver.n_output": 41}
    ref = sim_core.simulate(sim_core.load_scene("cantilever_release", {
        **over, "solver.h": 2.5e-5, "solver.newton_atol": 1e-11}))
    monkeypatch.setattr(Model, "element_loop_plan", lambda self: None)
    res = sim_core.simulate(_cantilever({**over, "solver.rtol": 1e-5, "solver.atol": 1e-7}))
    assert not res.stats["compiled"] and res.stats["step_control"] == "error"
    z = res["tip_position"][:, 2]
    assert np.max(np.abs(z - ref["tip_position"][:, 2])) < _time_error_bound(res, z)


def test_sleeve_scene_default_agrees_with_rk45():
    """beam_through_sleeve on its default (error-controlled generalized-alpha, numpy path: the
    sleeve is a time-dependent boundary; rtol 1e-6, atol 1e-8) against RK45 at rtol 1e-9,
    atol 1e-12 (its own error far below): every tip coordinate within its tolerance bound,
    0.1 s."""
    over = {"solver.t_end": 0.1, "solver.n_output": 11}
    alpha = sim_core.simulate(sim_core.load_scene("beam_through_sleeve", over))
    rk = sim_core.simulate(sim_core.load_scene("beam_through_sleeve", {
        **over, "solver.method": "RK45", "solver.rtol": 1e-9, "solver.atol": 1e-12}))
    assert alpha.stats["method"] == "generalized_alpha" and not alpha.stats["compiled"]
    for j in range(3):
        r = alpha["tip_position"][:, j]
        assert np.max(np.abs(r - rk["tip_position"][:, j])) < _time_error_bound(alpha, r)


def test_absurd_tolerance_stalls_with_the_typed_error():
    """rtol 1e-12, atol 1e-14 m (the tightest the scene validator allows) ask for steps of
    ~1e-6 s: the mean over 1000 accepted steps falls below t_end / 1e6 and StalledIntegration
    names the time reached, with the partial result (a few outputs at most) attached."""
    sc = _cantilever({"solver.rtol": 1e-12, "solver.atol": 1e-14})
    with pytest.raises(StalledIntegration) as info:
        sim_core.simulate(sc)
    exc = info.value
    assert 0.0 <= exc.t < sc["solver"]["t_end"] and f"{exc.t:.6g}" in str(exc)
    assert "stalled" in exc.reason and exc.mean_step < sc["solver"]["t_end"] / 1e6
    assert exc.result is not None and len(exc.result.t) >= 1


def test_wall_budget_and_ctrl_c_end_with_a_partial_result():
    """solver.max_wall_s is honoured between compiled calls (at most 1000 steps each): a budget
    of 1 us stops the run with the typed error naming it; Ctrl-C (here raised by the progress
    callback) ends it likewise, with the outputs reached so far."""
    sc = _cantilever({"solver.max_wall_s": 1e-6})
    with pytest.raises(SimulationError, match="max_wall_s") as info:
        sim_core.simulate(sc)
    assert 0.0 < info.value.t < 2.0 and len(info.value.result.t) < 401

    def interrupt(t, wall):
        if t > 0.1:
            raise KeyboardInterrupt
    with pytest.raises(SimulationError, match="KeyboardInterrupt") as info:
        sim_core.simulate(_cantilever(), progress=interrupt)
    res = info.value.result
    assert 0.1 < info.value.t < 2.0 and res.t[-1] <= info.value.t + 1e-12
    assert np.all(np.isfinite(res["tip_position"]))
