"""Fuzzing the envs' constructors and steps (hypothesis).

Constructor: random keyword arguments of ``gym.make(id, **kwargs)`` (values in and out of their
ranges, of wrong types, NaN and inf) either build a working env or raise ValueError / TypeError
naming one of the arguments given.  Steps: random actions (in and out of [-1, 1], extreme,
NaN): a non-finite action raises ValueError, everything else steps, and no observation, reward
or info deflection is ever NaN (a state that leaves its bounds truncates with a reason).
"""

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import boom_env  # noqa: F401

V0 = "boom_env/TelescopicExtraction-v0"
V1 = "boom_env/TelescopicExtraction-v1"

bad_numbers = st.one_of(st.just(math.nan), st.just(math.inf), st.just(-math.inf),
                        st.floats(-1e12, 1e12, allow_nan=False), st.integers(-10, 10))
junk = st.one_of(st.text(max_size=3), st.booleans(), st.none(), st.lists(st.integers(), max_size=3))


def number(lo, hi):
    """Mostly values in [lo, hi], sometimes anything."""
    return st.one_of(st.floats(lo, hi, allow_nan=False), bad_numbers, junk)


def pair(lo, hi):
    return st.one_of(st.tuples(st.floats(lo, hi), st.floats(lo, hi)).map(lambda p: tuple(sorted(p))),
                     st.tuples(bad_numbers, bad_numbers), junk)


COMMON = {
    "dt": number(0.01, 0.1), "a_max": number(0.05, 1.0), "v_max": number(0.1, 1.0),
    "t_max": number(0.5, 3.0), "booms": st.one_of(st.sampled_from([3, 5]), bad_numbers, junk),
    "luffing_angle_deg": number(45, 75), "angle_range": pair(45, 75),
    "n_modes": st.one_of(st.integers(0, 5), junk), "w_time": number(0, 10),
    "w_progress": number(0, 10), "w_jerk": number(0, 1), "reward_scale": number(1e-3, 1),
    "observe_parameters": st.one_of(st.booleans(), junk), "tol_stroke": number(0, 0.01),
    "d_ref": number(1e-4, 1.0), "dv_ref": number(1e-3, 1.0),
    "stroke_limits": pair(1.75, 8.25),
}
V1_ONLY = {
    "payload": number(20e3, 30e3), "payload_range": pair(20e3, 30e3),
    "rope_length": number(1.0, 10.0), "rope_range": pair(1.0, 10.0),
    "sway_limit": number(0.01, 0.3), "friction": st.one_of(st.booleans(), junk),
    "mu_static": number(0.0, 0.3), "mu_dynamic": number(0.0, 0.1),
    "cylinder_area": number(1e-3, 0.1), "hydraulic_damping": number(0.05, 0.9),
    "sway_ref": number(1e-3, 0.1), "w_sway": number(0, 10),
    "friction_law": st.one_of(st.sampled_from(["coulomb", "regularised"]), junk),
}
V0_ONLY = {"payload": number(20e3, 30e3), "payload_range": pair(20e3, 30e3)}

actions = st.one_of(st.floats(-1, 1), st.floats(-1e300, 1e300), st.just(math.nan),
                    st.just(math.inf), st.just(-math.inf))


def _kwargs(space):
    return st.dictionaries(st.sampled_from(sorted(space)), st.none(), max_size=5).flatmap(
        lambda d: st.fixed_dictionaries({k: space[k] for k in d}))


def _check(env_id, kwargs, acts):
    try:
        env = gym.make(env_id, **kwargs)
        obs, info = env.reset(seed=0)
    except (ValueError, TypeError) as exc:
        msg = str(exc)
        assert any(k in msg for k in kwargs), f"{type(exc).__name__} names no argument: {msg}"
        return
    assert np.all(np.isfinite(obs))
    for a in acts:
        with np.errstate(over="ignore"):
            act = np.array([a], dtype=np.float32)
        if not np.isfinite(act[0]):
            with pytest.raises(ValueError):
                env.step(act)
            continue
        obs, r, term, trunc, info = env.step(act)
        assert np.all(np.isfinite(obs)) and math.isfinite(r)
        assert np.all(np.isfinite(info["tip_deflection"]))
        assert env.observation_space.contains(obs)
        if info["diverged"]:
            assert trunc and info["reason"]
        if term or trunc:
            obs, info = env.reset()
            assert np.all(np.isfinite(obs))


FUZZ = settings(max_examples=40, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@FUZZ
@given(kwargs=_kwargs({**COMMON, **V1_ONLY}), acts=st.lists(actions, min_size=1, max_size=25))
def test_v1_constructor_and_steps(kwargs, acts):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _check(V1, kwargs, acts)


@FUZZ
@given(kwargs=_kwargs({**COMMON, **V0_ONLY}), acts=st.lists(actions, min_size=1, max_size=25))
def test_v0_constructor_and_steps(kwargs, acts):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _check(V0, kwargs, acts)


@FUZZ
@given(acts=st.lists(st.tuples(actions, actions), min_size=1, max_size=30))
def test_v1_vector_env_steps(acts):
    v = gym.make_vec(V1, num_envs=2, t_max=0.5)
    v.reset(seed=1)
    for a in acts:
        with np.errstate(over="ignore"):
            act = np.array(a, dtype=np.float32)[:, None]
        if not np.all(np.isfinite(act)):
            with pytest.raises(ValueError):
                v.step(act)
            continue
        obs, r, term, trunc, info = v.step(act)
        assert np.all(np.isfinite(obs)) and np.all(np.isfinite(r))
