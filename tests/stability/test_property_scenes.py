"""Hard case 8: property-based scenes drawn inside the valid ranges of the scene schema
(sim_core.systems.telescopic.schema).  Every run either completes with finite outputs or raises the typed
sim_core.errors.SimulationError (with a partial result) - never another exception, never a NaN,
and with a bounded number of integrator steps (no hang).

Default run: the rigid limit (effects.flexible = false, elastic ropes: one stiff rope dof) and the
modal ROM route (model.reduction = "modal"), tens of scenes each.  Slow: a few full flexible
scenes (n_nodes = 3, friction drawn on or off) on short windows."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import sim_core
from sim_core.errors import SimulationError

from .thresholds import MAX_STEPS_PER_SECOND

L = 10.0


def _log_uniform(lo, hi):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda x: 10.0 ** x)


@st.composite
def drive(draw, lo=0.0 + 1e-3, hi=L - 1e-3):
    """stroke0, direction, v_max, t_ramp, t_hold_end with the whole stroke history inside
    (lo, hi) (the geometric rule 0 < L_s(t) < length of the schema)."""
    stroke0 = draw(st.floats(lo + 0.05, hi - 0.05))
    direction = draw(st.sampled_from(["extraction", "retraction"]))
    v_max = draw(st.floats(0.01, 1.0))
    t_ramp = draw(st.floats(0.05, 4.0))
    t_hold_end = draw(st.floats(t_ramp, t_ramp + 12.0))
    end = stroke0 + (1 if direction == "extraction" else -1) * v_max * t_hold_end
    assume(lo < end < hi)
    # schema rule: the sliders (2w) must fit the shortest overlap L - max L_s
    overlap = L - max(stroke0, end)
    return {"contact.slider_width": min(0.3, 0.5 * overlap),"booms.stroke0": stroke0, "drive.direction": direction, "drive.v_max": v_max,
            "drive.t_ramp": t_ramp, "drive.t_hold_end": t_hold_end}


def _run(scene):
    """simulate; returns the Result, or None after a typed SimulationError (checked)."""
    try:
        res = sim_core.simulate(scene)
    except SimulationError as exc:
        part = getattr(exc, "result", None)
        if part is not None:
            for v in part.outputs.values():
                assert np.all(np.isfinite(np.asarray(v, float)))
        return None
    assert res.error is None
    for name, v in res.outputs.items():
        assert np.all(np.isfinite(np.asarray(v, float))), name
    return res


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(d=drive(), angle=st.floats(0.0, 85.0), payload=st.floats(0.0, 50000.0),
       E=_log_uniform(2.1e10, 2.1e12), EA=_log_uniform(1e7, 1e9), t_end=st.floats(0.1, 2.0),
       elastic=st.booleans())
def test_rigid_limit_scenes(d, angle, payload, E, EA, t_end, elastic):
    scene = sim_core.load_scene("telescopic_extraction", {
        **d, "booms.luffing_angle_deg": angle, "payload.mass": payload, "booms.E": E,
        "ropes.EA": EA, "solver.t_end": t_end, "solver.n_output": 21,
        "effects.flexible": False, "effects.friction": False,
        "effects.contact_distribution": False, "effects.rope_elasticity": elastic})
    res = _run(scene)
    if res is not None:
        assert res.stats["n_steps"] <= MAX_STEPS_PER_SECOND * t_end + 100, res.stats
        # the prescribed stroke is followed (kinematic drive) and the rope dof stays bounded:
        # boom 3 never leaves boom 2 by more than the rope stretch (T/EA * 20 m << 1 m)
        s = scene["booms"]["stroke0"] + res["piston_stroke"]
        assert np.all((s > 0.0) & (s < L))


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(d=drive(lo=1.75, hi=8.25), payload=st.floats(20000.0, 30000.0),
       t_end=st.floats(0.1, 30.0))
def test_modal_rom_scenes(d, payload, t_end):
    scene = sim_core.load_scene("telescopic_extraction_rl", {
        **d, "payload.mass": payload, "solver.t_end": t_end, "solver.n_output": 31,
        "effects.contact_distribution": False})
    res = _run(scene)
    if res is not None:
        assert np.max(np.abs(res["tip_deflection"])) < 1.0       # metres: bounded response


@pytest.mark.slow
@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(d=drive(), angle=st.floats(0.0, 85.0), payload=st.floats(0.0, 30000.0),
       E=_log_uniform(2.1e10, 2.1e12), friction=st.booleans())
def test_full_model_scenes(d, angle, payload, E, friction):
    scene = sim_core.load_scene("telescopic_extraction", {
        **d, "booms.luffing_angle_deg": angle, "payload.mass": payload, "booms.E": E,
        "booms.n_nodes": 3, "solver.t_end": 0.05, "solver.n_output": 3,
        "effects.friction": friction, "effects.contact_distribution": False})
    res = _run(scene)
    if res is not None:
        assert res.stats["n_steps"] <= 0.05 / 1e-5 + 100          # MIN_STEP_FRICTION floor
