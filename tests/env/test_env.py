"""boom_env: API conformance (Gymnasium and SB3 checkers, warnings as errors), registration,
determinism, kinematics against the scene's prescribed schedule and the ROM scene, errors."""

import warnings

import gymnasium as gym
import numpy as np
import pytest

import boom_env  # noqa: F401
from boom_env import TelescopicBoomEnv

IDS = ["boom_env/TelescopicExtraction-v0", "boom_env/TelescopicRetraction-v0"]


@pytest.mark.parametrize("booms", [3, 5])
@pytest.mark.parametrize("env_id", IDS)
def test_gymnasium_check_env_no_warnings(env_id, booms):
    from gymnasium.utils.env_checker import check_env
    env = gym.make(env_id, booms=booms)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    env.close()


@pytest.mark.parametrize("booms", [3, 5])
@pytest.mark.parametrize("env_id", IDS)
def test_sb3_check_env_no_warnings(env_id, booms):
    from stable_baselines3.common.env_checker import check_env
    env = gym.make(env_id, booms=booms)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, warn=True)
    env.close()


@pytest.mark.parametrize("env_id", IDS)
def test_make_registration_and_time_limit(env_id):
    env = gym.make(env_id)
    assert env.spec.max_episode_steps == boom_env.MAX_EPISODE_STEPS == 600
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    n, done = 0, False
    while not done:
        obs, r, term, trunc, info = env.step(np.zeros(1, np.float32))   # never moves: no success
        n += 1
        done = term or trunc
        assert np.all(np.isfinite(obs)) and np.isfinite(r)
    assert trunc and not term and n == 600
    env.close()


def test_make_vec_two_envs():
    venv = gym.make_vec(IDS[0], num_envs=2, vectorization_mode="sync")
    obs, _ = venv.reset(seed=[1, 2])
    assert obs.shape == (2, 9) and obs.dtype == np.float32
    for _ in range(5):
        obs, r, term, trunc, _ = venv.step(np.ones((2, 1), np.float32))
    assert np.all(np.isfinite(obs)) and obs[0, 1] > 0
    venv.close()


def _rollout(seed, actions, **kw):
    env = TelescopicBoomEnv(payload_range=(20000.0, 30000.0), **kw)
    obs, info = env.reset(seed=seed)
    out = [obs]
    for a in actions:
        out.append(env.step(np.array([a], np.float32))[0])
    return np.array(out), info["payload"]


def test_same_seed_same_actions_identical_trajectory():
    acts = np.random.default_rng(3).uniform(-1, 1, 80)
    a, pa = _rollout(7, acts)
    b, pb = _rollout(7, acts)
    c, pc = _rollout(8, acts)
    assert pa == pb and np.array_equal(a, b)
    assert pc != pa and not np.array_equal(a, c)            # the payload is drawn from the seed


def test_domain_randomisation_range_checked():
    with pytest.raises(ValueError, match="payload"):
        TelescopicBoomEnv(payload_range=(10000.0, 30000.0))
    with pytest.raises(ValueError, match="luffing_angle_deg"):
        TelescopicBoomEnv().reset(options={"luffing_angle_deg": 30.0})


def test_angle_randomisation_draws_inside_the_tables_and_is_seeded():
    """angle_range draws the luffing angle per reset from the env's seeded generator, within
    the tabulated range; the ROM responds to it (the first bending mode of the tables differs
    between the ends of the range) and the same seed gives the same angle and trajectory."""
    from sim_core.systems.telescopic.modal import allowed_ranges
    _, (a_lo, a_hi), _ = allowed_ranges()
    assert a_hi - a_lo >= 30.0                           # 45-75 deg tables
    env = TelescopicBoomEnv(angle_range=(a_lo, a_hi), payload_range=(20000.0, 30000.0))
    angles = []
    for seed in range(6):
        obs, info = env.reset(seed=seed)
        angles.append(info["luffing_angle_deg"])
        assert a_lo <= info["luffing_angle_deg"] <= a_hi
    assert np.ptp(angles) > 5.0
    runs = []
    for _ in range(2):
        obs, info = env.reset(seed=3)
        traj = [obs]
        for _ in range(40):
            obs, *_ = env.step(np.array([0.5], np.float32))
            traj.append(obs)
        runs.append(np.array(traj))
    np.testing.assert_array_equal(runs[0], runs[1])
    assert np.all(np.isfinite(runs[0])) and np.max(np.abs(runs[0][:, 5:7])) > 1e-5
    from sim_core.systems.telescopic.modal import tables_for
    w = [tables_for(25000.0, a, 1).coefficients(5.0)[0, 0] for a in (a_lo, a_hi)]
    assert abs(w[0] - w[1]) > 1e-3 * w[0]


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_action_raises(bad):
    env = TelescopicBoomEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="not finite"):
        env.step(np.array([bad], np.float32))


def test_cubic_schedule_as_actions_reproduces_scene():
    """The paper's schedule (docs/model.md#input-drive) fed as actions: the action of step k is
    the mean acceleration (v(t_k+1) - v(t_k)) / dt, so the stroke rate is exact at the step ends
    and the stroke error is at most N_moving * dt^3 * max|jerk| / 12 (bound of the chord rule).
    The tip response equals sim_core.simulate on the rl scene, which uses the same kinematics
    and the same ROM (agreement to round-off)."""
    import sim_core
    from sim_core.physics.drive_profiles import CubicSmoothstepSchedule
    sc = sim_core.load_scene("telescopic_extraction_rl")
    res = sim_core.simulate(sc)
    d = sc["drive"]
    sched = CubicSmoothstepSchedule(v_max=d["v_max"], t_ramp=d["t_ramp"], t_hold_end=d["t_hold_end"],
                                    s0=sc["booms"]["stroke0"])
    env = TelescopicBoomEnv(n_modes=sc["model"]["n_modes"])
    env.reset(seed=0)
    dt = env.dt
    assert np.allclose(np.diff(res.t), dt)
    n = len(res.t) - 1
    L, defl, sat = [env.rom.L], [np.zeros(2)], False
    for k in range(n):
        a = (sched.rate((k + 1) * dt) - sched.rate(k * dt)) / dt
        obs, r, term, trunc, info = env.step(np.array([a / env.a_max], np.float32))
        L.append(info["stroke"])
        defl.append(info["tip_deflection"])
        sat |= info["velocity_saturated"]
        if term or trunc:
            break
    L = np.array(L)
    t = res.t[:len(L)]
    jerk_max = 6 * d["v_max"] / d["t_ramp"] ** 2
    n_moving = int(np.ceil(sched.t_end / dt))
    bound = n_moving * dt ** 3 * jerk_max / 12 + 1e-6     # + float32 rounding of the action
    assert np.max(np.abs(L - sched.stroke(t))) <= bound
    # the ROM scene: same stroke and same tip deflection (float32 actions: relative 6e-8)
    assert np.max(np.abs(L - (sc["booms"]["stroke0"] + res["piston_stroke"][:len(L)]))) <= 1e-6
    ref = res["tip_deflection"][:len(L)][:, [0, 2]]
    scale = np.max(np.abs(ref))
    assert scale > 1e-5                                    # a dynamic response is present
    assert np.max(np.abs(np.array(defl) - ref)) <= 1e-4 * scale


def test_end_stop_and_velocity_saturation_reported():
    env = TelescopicBoomEnv(task="extraction")
    env.reset(seed=0, options={"stroke_start": 7.5, "stroke_target": 8.0})
    seen_sat = seen_stop = False
    for _ in range(200):
        obs, r, term, trunc, info = env.step(np.ones(1, np.float32))
        seen_sat |= info["velocity_saturated"]
        seen_stop |= info["end_stop"]
        assert env.L_min <= info["stroke"] <= env.L_max
        assert abs(info["stroke_rate"]) <= env.v_max + 1e-12
    assert seen_stop and info["stroke"] == env.L_max and info["stroke_rate"] == 0.0
    env.reset(seed=0)
    for _ in range(60):
        obs, r, term, trunc, info = env.step(np.ones(1, np.float32))
        seen_sat |= info["velocity_saturated"]
    assert seen_sat and abs(info["stroke_rate"] - env.v_max) < 1e-12


def test_rgb_array_render():
    env = TelescopicBoomEnv(render_mode="rgb_array")
    env.reset(seed=0)
    env.step(np.ones(1, np.float32))
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert frame.std() > 0
    assert env.metadata["render_fps"] > 0
    env.close()


def test_diverged_solver_truncates_without_nan(monkeypatch):
    env = TelescopicBoomEnv()
    obs0, _ = env.reset(seed=0)

    def boom(*a, **k):
        raise FloatingPointError("forced failure")
    monkeypatch.setattr(env.rom, "advance", boom)
    obs, r, term, trunc, info = env.step(np.ones(1, np.float32))
    assert trunc and not term and info["diverged"] and "forced failure" in info["reason"]
    assert np.all(np.isfinite(obs)) and np.isfinite(r)


@pytest.mark.slow
def test_paper_fidelity_steps_the_full_model():
    """fidelity='paper': the full model follows the env's stroke kinematics (cylinder target
    replaced per step) and starts at rest in equilibrium: the deflection from the static tip is
    the small dynamic response (mm), the same order as the ROM's for the same actions."""
    env = TelescopicBoomEnv(fidelity="paper")
    rom = TelescopicBoomEnv()
    o_p, _ = env.reset(seed=0)
    o_r, _ = rom.reset(seed=0)
    assert np.max(np.abs(o_p[5:])) < 1e-9                # starts in its own equilibrium
    for _ in range(4):
        o_p, r, term, trunc, info = env.step(np.ones(1, np.float32))
        o_r = rom.step(np.ones(1, np.float32))[0]
        assert not info["diverged"], info["reason"]
    assert np.allclose(o_p[:5], o_r[:5])
    assert np.all(np.isfinite(o_p)) and np.max(np.abs(o_p[5:7])) < 1e-2
    n = env._ts.model.n_dof                              # target time: end of the last step
    assert np.max(np.abs(env._ts.model.constraint_violation(env.dt, env._y[:n], env._y[n:]))) < 1e-6


@pytest.mark.parametrize("a", [-8.9e-16, 0.0, -1e-14, -1e-9, -1e-6, 1e-14])
def test_tiny_acceleration_at_speed_hits_no_end_stop(a):
    """Regression: a tiny braking command at full speed mid-stroke must not 'hit' the far end
    stop (the textbook quadratic root (-v + r) / a cancelled to a spurious small positive time,
    and the stroke jumped to L_min).  Exact kinematics: L + v dt + a dt^2 / 2."""
    from boom_env.telescopic_env import _first_hit
    env = TelescopicBoomEnv(task="extraction")
    L, v = 3.0, env.v_max
    segs, L1, v1, sat, stop = env._segments(L, v, a)
    assert not stop
    assert L1 == pytest.approx(L + v * env.dt + 0.5 * min(a, 0.0) * env.dt ** 2, abs=1e-15)
    # the far stop is reached only after reversing: t = roots of a t^2/2 + v t + (L - L_min)
    # (|a| < 1e-15 is treated as a = 0: never)
    t_hit = _first_hit(L, v, a, env.L_min)
    assert t_hit > 1e3
    if a < -1e-15:
        t_exact = (-v - np.sqrt(v * v - 2 * a * (L - env.L_min))) / a
        assert t_hit == pytest.approx(t_exact, rel=1e-9)
