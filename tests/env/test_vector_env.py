"""The native vector env of the v1 ids (boom_env.vector_env): one implementation with the scalar
env (equal trajectories), Gymnasium's NEXT_STEP autoreset semantics, seeding, and the checks
Gymnasium offers (its single-env checker on the scalar ids; the vector wrappers)."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode, SyncVectorEnv, VectorEnv

import boom_env  # noqa: F401
from boom_env.telescopic_sway_env import TelescopicSwayEnv
from boom_env.vector_env import TelescopicSwayVectorEnv

IDS = ("boom_env/TelescopicExtraction-v1", "boom_env/TelescopicRetraction-v1")
RANDOM = dict(payload_range=(20e3, 30e3), angle_range=(45.0, 75.0), rope_range=(1.0, 10.0))


def _compare(native, sync, n_steps, rng, n):
    """Step both with the same actions; everything equal (the same code and the same draws)."""
    ends = 0
    for _ in range(n_steps):
        a = rng.uniform(-1.2, 1.2, (n, 1)).astype(np.float32)
        r1, r2 = native.step(a), sync.step(a)
        assert np.array_equal(r1[0], r2[0])
        assert np.array_equal(r1[1], r2[1])
        assert np.array_equal(r1[2], r2[2]) and np.array_equal(r1[3], r2[3])
        assert set(r1[4]) == set(r2[4])
        for k, y in r2[4].items():
            x = r1[4][k]
            if x.dtype == object:
                assert list(x) == list(y), k
            else:
                assert np.array_equal(x, y), k
        ends += int(np.sum(r1[2] | r1[3]))
    return ends


@pytest.mark.parametrize("env_id", IDS)
def test_make_vec_gives_the_native_vector_env(env_id):
    v = gym.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point")
    assert isinstance(v.unwrapped, TelescopicSwayVectorEnv) and isinstance(v, VectorEnv)
    assert v.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert v.single_observation_space == gym.make(env_id).observation_space
    assert v.single_action_space == gym.make(env_id).action_space
    obs, _ = v.reset(seed=0)
    assert obs.shape == (3, 13) and v.observation_space.contains(obs)
    v.close()


@pytest.mark.parametrize("env_id, law", [(i, "coulomb") for i in IDS]
                         + [(IDS[0], "regularised")])
def test_native_equals_sync_vector_env_of_the_scalar_env_across_autoresets(env_id, law):
    """Per-env payload, angle and rope length (drawn per sub-env), random actions, episodes of
    20 steps (t_max = 1 s) so that every sub-env resets several times: observations, rewards,
    flags and infos are the same numbers as a SyncVectorEnv of the scalar env (with either
    friction law)."""
    n, kw = 5, dict(RANDOM, t_max=1.0, friction_law=law)
    native = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kw)
    sync = gym.make_vec(env_id, num_envs=n, vectorization_mode="sync", **kw)
    assert isinstance(sync, SyncVectorEnv)
    o1, i1 = native.reset(seed=7)
    o2, i2 = sync.reset(seed=7)
    assert np.array_equal(o1, o2)
    assert np.array_equal(i1["payload"], i2["payload"])
    assert len(set(i1["payload"])) == n                      # each sub-env its own draw
    ends = _compare(native, sync, 90, np.random.default_rng(0), n)
    assert ends >= 4 * n
    # a partial reset with new options, then on
    mask = np.array([True, False, True, False, False])
    o1, _ = native.reset(options={"reset_mask": mask.copy(), "rope_length": 2.5})
    o2, _ = sync.reset(options={"reset_mask": mask.copy(), "rope_length": 2.5})
    assert np.array_equal(o1, o2)
    _compare(native, sync, 30, np.random.default_rng(1), n)


def test_scalar_env_is_the_batch_of_one():
    """The scalar env and a vector env of one crane give the same trajectory."""
    env = gym.make(IDS[0], **RANDOM).unwrapped
    vec = TelescopicSwayVectorEnv(1, **RANDOM, task="extraction", dt=0.05, t_max=30.0)
    o, _ = env.reset(seed=11)
    ov, _ = vec.reset(seed=11)
    assert np.array_equal(o, ov[0])
    rng = np.random.default_rng(3)
    for _ in range(200):
        a = rng.uniform(-1, 1, 1).astype(np.float32)
        o, r, te, tr, info = env.step(a)
        ov, rv, tev, trv, infov = vec.step(a[None])
        assert np.array_equal(o, ov[0]) and r == rv[0] and te == tev[0] and tr == trv[0]
        assert info["sway"][0] == infov["sway"][0, 0]


def test_next_step_autoreset_semantics():
    """Gymnasium's NEXT_STEP: the step after an episode ends returns the sub-env's reset
    observation, reward 0 and no termination, and ignores its action; the other sub-envs
    step on."""
    v = gym.make_vec(IDS[0], num_envs=2, vectorization_mode="vector_entry_point", t_max=0.5)
    obs0, _ = v.reset(seed=0)
    a = np.array([[1.0], [-1.0]], np.float32)
    for k in range(10):
        obs, rew, term, trunc, info = v.step(a)
        assert not np.any(term)
        assert np.all(trunc == (k == 9))
    snapshot = v.unwrapped.core.rom.save_state()
    obs_a, rew_a, term_a, trunc_a, info_a = v.step(np.array([[0.3], [1.0]], np.float32))
    v.unwrapped.core.rom.restore_state(snapshot)
    v.unwrapped._autoreset[:] = True
    obs_b, *_ = v.step(np.array([[-0.9], [0.0]], np.float32))
    assert np.array_equal(obs_a, obs0) and np.array_equal(obs_b, obs0)   # actions ignored
    assert np.all(rew_a == 0.0) and not np.any(term_a | trunc_a)
    assert np.all(info_a["time"] == 0.0) and np.all(info_a["_time"])
    obs, rew, term, trunc, info = v.step(a)                  # a normal step again
    assert np.all(rew != 0.0) and np.all(info["time"] == pytest.approx(0.05))


def test_seeding_is_reproducible_and_per_env():
    v = TelescopicSwayVectorEnv(4, **RANDOM)
    _, i1 = v.reset(seed=5)
    _, i2 = v.reset(seed=5)
    _, i3 = v.reset(seed=[5, 6, 7, 8])
    for k in ("payload", "luffing_angle_deg", "rope_length"):
        assert np.array_equal(i1[k], i2[k]) and np.array_equal(i1[k], i3[k])
    s = TelescopicSwayEnv(**RANDOM)
    _, info = s.reset(seed=6)
    assert info["payload"] == i1["payload"][1] and info["rope_length"] == i1["rope_length"][1]
    with pytest.raises(ValueError, match="seed"):
        v.reset(seed=[1, 2])


def test_vector_wrappers_run_on_the_native_env():
    """Gymnasium's vector wrappers (episode statistics, observation normalisation) accept it."""
    from gymnasium.wrappers.vector import NormalizeObservation, RecordEpisodeStatistics
    v = gym.make_vec(IDS[0], num_envs=3, t_max=0.5)
    v = NormalizeObservation(RecordEpisodeStatistics(v))
    v.reset(seed=0)
    done = 0
    for _ in range(25):
        obs, rew, term, trunc, info = v.step(np.zeros((3, 1), np.float32))
        assert np.all(np.isfinite(obs))
        if "episode" in info:
            done += int(info["_episode"].sum())
    assert done == 6                                          # 3 sub-envs, 2 episodes each


def test_non_finite_actions_raise_and_no_nan_is_ever_emitted():
    v = TelescopicSwayVectorEnv(2)
    v.reset(seed=0)
    with pytest.raises(ValueError, match="not finite"):
        v.step(np.array([[np.nan], [0.0]]))
    # a state driven out of range (start sway at the limit, pumped at the pendulum frequency)
    # truncates with a reason and the last good observation
    v.reset(seed=0, options={"sway": (0.3, 0.0), "rope_length": 1.0})
    seen = False
    for k in range(600):
        a = np.full((2, 1), np.sign(np.sin(np.sqrt(9.81) * 0.05 * k)))
        obs, rew, term, trunc, info = v.step(a)
        assert np.all(np.isfinite(obs)) and np.all(np.isfinite(rew))
        if info["diverged"].any():
            seen = True
            assert "sway" in info["reason"][info["diverged"]][0]
            break
    assert seen
