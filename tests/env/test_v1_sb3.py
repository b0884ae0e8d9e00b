"""SB3 and Gymnasium checks of the v1 envs, and SB3 training on the native vector env through
boom_env.sb3_adapter.SB3VecEnv (SB3's autoreset convention)."""

import gymnasium as gym
import numpy as np
import pytest

import boom_env  # noqa: F401
from boom_env.sb3_adapter import SB3VecEnv

IDS = ("boom_env/TelescopicExtraction-v1", "boom_env/TelescopicRetraction-v1")
RANDOM = dict(payload_range=(20e3, 30e3), angle_range=(45.0, 75.0), rope_range=(1.0, 10.0))


@pytest.mark.parametrize("env_id", IDS)
@pytest.mark.parametrize("friction", [True, False])
def test_gymnasium_and_sb3_env_checkers_pass(env_id, friction):
    from gymnasium.utils.env_checker import check_env as gym_check
    from stable_baselines3.common.env_checker import check_env as sb3_check
    gym_check(gym.make(env_id, friction=friction, **RANDOM).unwrapped, skip_render_check=True)
    with __import__("warnings").catch_warnings(record=True) as w:
        __import__("warnings").simplefilter("always")
        sb3_check(gym.make(env_id, friction=friction), warn=True)
    # SB3 warns about the asymmetric, unnormalised observation box (SI units, documented);
    # nothing else
    msgs = [str(x.message) for x in w if "observation" not in str(x.message).lower()
            and "out of date" not in str(x.message)]
    assert not msgs, msgs


def test_adapter_equals_dummy_vec_env_of_the_scalar_env():
    """SB3 semantics: a finished sub-env is reset in the same step, its last observation in
    infos["terminal_observation"], truncation flagged; the same numbers as SB3's own
    DummyVecEnv over the scalar env (same seeds: sub-env i gets seed + i)."""
    from stable_baselines3.common.vec_env import DummyVecEnv
    n, kw = 4, dict(RANDOM, t_max=0.6)
    ours = SB3VecEnv(gym.make_vec(IDS[0], num_envs=n, **kw))
    ref = DummyVecEnv([lambda: gym.make(IDS[0], **kw) for _ in range(n)])
    ours.seed(3)
    ref.seed(3)
    assert np.array_equal(ours.reset(), ref.reset())
    rng = np.random.default_rng(0)
    dones = 0
    for _ in range(40):
        a = rng.uniform(-1, 1, (n, 1)).astype(np.float32)
        o1, r1, d1, i1 = ours.step(a)
        o2, r2, d2, i2 = ref.step(a)
        assert np.array_equal(o1, o2) and np.array_equal(r1, r2) and np.array_equal(d1, d2)
        for x, y in zip(i1, i2):
            assert ("terminal_observation" in x) == ("terminal_observation" in y)
            if "terminal_observation" in y:
                assert np.array_equal(x["terminal_observation"], y["terminal_observation"])
                assert x["TimeLimit.truncated"] == y["TimeLimit.truncated"]
            assert x["payload"] == y["payload"] and x["sway"][0] == y["sway"][0]
        dones += int(d1.sum())
    assert dones >= 2 * n


def test_ppo_learns_on_the_native_vector_env():
    """PPO runs 2000 steps on 8 native sub-envs through the adapter (SB3's rollout buffer,
    its episode bookkeeping from the infos: Gymnasium's vector RecordEpisodeStatistics fills
    info["episode"], SB3 reads it; VecNormalize on top)."""
    from gymnasium.wrappers.vector import RecordEpisodeStatistics
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize
    venv = VecNormalize(SB3VecEnv(RecordEpisodeStatistics(
        gym.make_vec(IDS[0], num_envs=8, t_max=2.0, **RANDOM))))
    model = PPO("MlpPolicy", venv, n_steps=64, batch_size=128, n_epochs=2, seed=0, device="cpu")
    model.learn(2000)
    assert model.num_timesteps >= 2000
    assert len(model.ep_info_buffer) > 0
    assert all(ep["l"] == 40 for ep in model.ep_info_buffer)   # t_max = 2 s of 0.05 s steps
    obs = venv.reset()
    act, _ = model.predict(obs, deterministic=True)
    assert act.shape == (8, 1) and np.all(np.abs(act) <= 1.0)


def test_desynchronised_starts_spread_the_episode_clocks():
    """desync_steps = H: after reset, sub-env i has run H - 1 - w_i steps of its episode, w_i
    the uniform draw of [0, H) from default_rng(desync_seed) (observation 4 is the time left,
    t_max - k dt); the draws are the documented ones, and the same seed gives the same
    batch."""
    n, H, dt, t_max = 16, 40, 0.05, 30.0
    venv = SB3VecEnv(gym.make_vec(IDS[0], num_envs=n, **RANDOM), desync_steps=H,
                     desync_seed=7)
    venv.seed(1)
    obs = venv.reset()
    when = np.random.default_rng(7).integers(0, H, n)
    np.testing.assert_allclose(obs[:, 4], t_max - (H - 1 - when) * dt, atol=1e-4)
    assert len(set(np.round(obs[:, 4], 3))) > n // 2
    again = SB3VecEnv(gym.make_vec(IDS[0], num_envs=n, **RANDOM), desync_steps=H,
                      desync_seed=7)
    again.seed(1)
    assert np.array_equal(again.reset(), obs)
    with pytest.raises(ValueError, match="desync_steps"):
        SB3VecEnv(gym.make_vec(IDS[0], num_envs=2), desync_steps=-1)


def test_a_bounds_truncation_is_a_time_limit_truncation_for_sb3():
    """Leaving the observation bounds truncates (info["diverged"]): the adapter passes it to
    SB3 as a truncation (``TimeLimit.truncated``, the value bootstrapped from the last good
    observation), as SB3's own DummyVecEnv over the scalar env does."""
    from stable_baselines3.common.vec_env import DummyVecEnv
    kw = dict(sway_limit=0.002)           # full acceleration swings the payload past 2 mrad
    ours = SB3VecEnv(gym.make_vec(IDS[0], num_envs=2, **kw))
    ref = DummyVecEnv([lambda: gym.make(IDS[0], **kw) for _ in range(2)])
    ours.seed(0)
    ref.seed(0)
    ours.reset()
    ref.reset()
    a = np.ones((2, 1), np.float32)
    for _ in range(200):
        _, _, d1, i1 = ours.step(a)
        _, _, d2, i2 = ref.step(a)
        assert np.array_equal(d1, d2)
        if d1.any():
            break
    assert d1.all()
    for x, y in zip(i1, i2):
        assert x["diverged"] and x["TimeLimit.truncated"]
        assert y["TimeLimit.truncated"]
        assert np.array_equal(x["terminal_observation"], y["terminal_observation"])
