"""boom_env with standard learners: pickling, vector envs (sync and async) without warnings,
the env checkers with and without the observed parameters, the reward scale, and the
``module:id`` form of gym.make."""

import pickle
import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest

import boom_env  # noqa: F401
from boom_env import TelescopicBoomEnv

ENV_ID = "boom_env/TelescopicExtraction-v0"
RANGES = dict(payload_range=(20000.0, 30000.0), angle_range=(45.0, 75.0))


def _actions(n, seed=0):
    return np.random.default_rng(seed).uniform(-1, 1, (n, 1)).astype(np.float32)


def test_pickle_round_trip_continues_the_same_episode():
    """A pickled env (gym.make: wrappers included) unpickles to the same state: stepping the
    copy and the original with the same actions gives bitwise equal observations and rewards,
    and the copy's episode ends at the same step (the time limit's counter travels too)."""
    env = gym.make(ENV_ID, **RANGES)
    env.reset(seed=3)
    acts = _actions(700)
    for a in acts[:50]:
        env.step(a)
    copy = pickle.loads(pickle.dumps(env))
    assert copy.unwrapped.payload == env.unwrapped.payload
    for k, a in enumerate(acts[50:]):
        o1, r1, te1, tr1, _ = env.step(a)
        o2, r2, te2, tr2, _ = copy.step(a)
        np.testing.assert_array_equal(o1, o2)
        assert r1 == r2 and (te1, tr1) == (te2, tr2)
        if te1 or tr1:
            break
    assert tr1 and k == 600 - 50 - 1                      # truncated by the 600-step limit
    copy.reset(seed=4)                                    # the copy's generator is its own
    assert np.all(np.isfinite(copy.step(acts[0])[0]))


def _errors_but_v0_is_out_of_date():
    """Every warning an error, except Gymnasium's notice that a ``-v0`` id has a newer version
    (v1 is registered beside it; v0 stays for reproducibility and keeps its behaviour)."""
    warnings.simplefilter("error")
    warnings.filterwarnings("ignore", message=r".*is out of date.*", category=DeprecationWarning)


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_make_vec_steps_without_warnings(mode):
    """gymnasium.make_vec with 4 envs, both vectorisation modes, warnings as errors: in this
    process and in the async workers, which are forked (``context="fork"``, the Linux default
    before Python 3.14) and so inherit the "error" filter; a warning there makes the worker
    fail and the vector env raise here."""
    kw = {"vector_kwargs": {"context": "fork"}} if mode == "async" else {}
    with warnings.catch_warnings():
        _errors_but_v0_is_out_of_date()
        venv = gym.make_vec(ENV_ID, num_envs=4, vectorization_mode=mode, **kw)
        obs, _ = venv.reset(seed=0)
        acts = np.ones((4, 1), np.float32)
        for _ in range(10):
            obs, r, term, trunc, _ = venv.step(acts)
        venv.close()
    assert obs.shape == (4, 9) and obs.dtype == np.float32 and np.all(np.isfinite(obs))
    assert np.all(obs[:, 1] > 0)                          # all four extend at a = a_max
    assert r.shape == (4,) and np.all(np.isfinite(r))


def test_async_workers_turn_warnings_into_errors():
    """The check above can fail: a warning inside a forked worker (render() without a render
    mode warns) reaches this process as an error."""
    with warnings.catch_warnings():
        _errors_but_v0_is_out_of_date()
        venv = gym.make_vec(ENV_ID, num_envs=2, vectorization_mode="async",
                            vector_kwargs={"context": "fork"})
        venv.reset(seed=0)
        with pytest.raises(UserWarning, match="error from Worker"):
            venv.call("render")
        warnings.simplefilter("ignore")                   # the failed worker's shutdown
        venv.close(terminate=True)


@pytest.mark.parametrize("observe", [False, True])
def test_checkers_pass_with_and_without_observed_parameters(observe):
    """Gymnasium's and SB3's env checkers, warnings as errors, on the randomised env."""
    from gymnasium.utils.env_checker import check_env as gym_check
    from stable_baselines3.common.env_checker import check_env as sb3_check
    env = gym.make(ENV_ID, observe_parameters=observe, **RANGES).unwrapped   # with its spec
    assert env.observation_space.shape == ((11,) if observe else (9,))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gym_check(env)
        sb3_check(env, warn=True)


def test_observed_parameters_are_the_episode_parameters_normalised():
    """obs[9], obs[10] = (2 x - lo - hi) / (hi - lo) of the episode's payload and angle over the
    tables' range (float32 rounding: 6e-8), constant during the episode; the paper's 25 t and
    60 deg are the centre 0 and the range ends map to -1 and +1; the first 9 entries are the
    observation without the option."""
    from sim_core.systems.telescopic.modal import allowed_ranges
    (p_lo, p_hi), (a_lo, a_hi), _ = allowed_ranges()
    env = TelescopicBoomEnv(observe_parameters=True, **RANGES)
    plain = TelescopicBoomEnv(**RANGES)
    seen = []
    for seed in range(5):
        obs, info = env.reset(seed=seed)
        ref, _ = plain.reset(seed=seed)
        expect = [(2 * info["payload"] - p_lo - p_hi) / (p_hi - p_lo),
                  (2 * info["luffing_angle_deg"] - a_lo - a_hi) / (a_hi - a_lo)]
        np.testing.assert_allclose(obs[9:], expect, atol=6e-8)
        np.testing.assert_array_equal(obs[:9], ref)
        for a in _actions(20, seed):
            obs, *_ = env.step(a)
            np.testing.assert_allclose(obs[9:], expect, atol=6e-8)
        seen.append(expect)
    assert np.ptp(np.array(seen), axis=0).min() > 0.2       # the draws differ and are seen
    fixed = TelescopicBoomEnv(observe_parameters=True)
    np.testing.assert_array_equal(fixed.reset(seed=0)[0][9:], [0.0, 0.0])
    ends = fixed.reset(options={"payload": p_hi, "luffing_angle_deg": a_lo})[0][9:]
    np.testing.assert_array_equal(ends, [1.0, -1.0])


def test_reward_scale_multiplies_every_term():
    """Same actions, scale 1 and the default: every step's reward is 0.01 times the unscaled
    one (relative 1e-12), including the end-stop penalty and the success bonus, and
    info["reward_unscaled"] is the unscaled reward in both envs."""
    unscaled = TelescopicBoomEnv(reward_scale=1.0)
    scaled = TelescopicBoomEnv()
    assert scaled.reward_scale == 0.01
    for e in (unscaled, scaled):
        e.reset(seed=0, options={"stroke_start": 7.5})
    stop = False
    for k in range(100):                 # full acceleration into the end stop at 8.25 m
        a = np.array([1.0 if k < 60 else -0.3], np.float32)
        (o1, r1, *_, i1), (o2, r2, *_, i2) = unscaled.step(a), scaled.step(a)
        np.testing.assert_array_equal(o1, o2)
        assert r2 == pytest.approx(0.01 * r1, rel=1e-12)
        assert i1["reward_unscaled"] == r1 and i2["reward_unscaled"] == pytest.approx(r1, rel=1e-12)
        stop |= i1["end_stop"]
    assert stop                                           # the end-stop penalty was scaled too
    # standing still: -(w_time + w_progress) per s, unscaled -11 per s over the 30 s
    env = gym.make(ENV_ID)
    env.reset(seed=0)
    total = sum(env.step(np.zeros(1, np.float32))[1] for _ in range(600))
    assert total == pytest.approx(-0.01 * 11.0 * 30.0, rel=1e-9)


def test_success_bonus_is_scaled():
    """Starting at rest at the target, the first step is a success: reward = scale * (bonus -
    w_time dt), the only terms left (the deflection is zero at rest in equilibrium)."""
    for scale in (1.0, 0.01, 2.5):
        env = TelescopicBoomEnv(reward_scale=scale)
        env.reset(seed=0, options={"stroke_start": 8.0, "stroke_target": 8.0})
        _, r, term, trunc, info = env.step(np.zeros(1, np.float32))
        assert term and info["success"]
        assert r == pytest.approx(scale * (50.0 - 1.0 * env.dt), rel=1e-9)


@pytest.mark.parametrize("bad", [0.0, -0.01, float("nan"), float("inf")])
def test_bad_reward_scale_raises(bad):
    with pytest.raises(ValueError, match="reward_scale"):
        TelescopicBoomEnv(reward_scale=bad)


def test_bad_observe_parameters_raises():
    with pytest.raises(ValueError, match="observe_parameters"):
        TelescopicBoomEnv(observe_parameters="yes")


def test_make_with_module_prefix_imports_the_package():
    """gym.make("boom_env:boom_env/TelescopicExtraction-v0") in a fresh interpreter that has
    not imported boom_env: Gymnasium imports the package (which registers the ids) first."""
    code = ("import sys, gymnasium as gym\n"
            "assert 'boom_env' not in sys.modules\n"
            "env = gym.make('boom_env:boom_env/TelescopicExtraction-v0')\n"
            "obs, _ = env.reset(seed=0)\n"
            "print(env.spec.id, env.spec.max_episode_steps, obs.shape)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["boom_env/TelescopicExtraction-v0", "600", "(9,)"]
