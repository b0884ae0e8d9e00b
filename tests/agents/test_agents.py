"""agents: scripted schedules reach their targets, the ZV shaper cancels the residual vibration
of the mode it is tuned to, evaluation is deterministic, and PPO trains and evaluates (smoke)."""

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from agents import evaluate as ev
from agents import schedules as S
from sim_core.validation.closed_form import static_luffing_forces

DT, A_MAX, N = 0.05, 0.25, 600


@pytest.mark.parametrize("make", [S.cubic, S.trapezoid, S.zv_trapezoid])
def test_scripted_schedule_reaches_target_through_env(make):
    """Every schedule extracts 2 -> 8 m through the env and stops there.  The env integrates the
    per-step mean acceleration exactly, so the stroke is the trapezoidal integral of v(t): error
    O(dt^2 * |jump of dv/dt|) at the trapezoid's kinks, (0.05^2 / 12) * 0.25 ~ 5e-5 m per kink;
    1e-3 m allowed.  The rate must be back to zero up to the float32 rounding of the actions."""
    s = make()
    env = ev.make_eval_env()
    tr = ev.run_episode(env, ev.scripted_policy(s, DT, A_MAX, N), seed=0)
    m = ev.metrics(tr)
    assert abs(tr.stroke[-1] - 8.0) < 1e-3
    # actions pass the env as float32: |dv| <= N dt a_max 2^-24 = 4.5e-7 m/s
    assert abs(tr.rate[-1]) < N * DT * A_MAX * 2.0 ** -24
    assert m["time_to_target_s"] is not None and m["time_to_target_s"] <= s.t_end + 1e-9
    assert m["stop_time_s"] <= s.t_end + 1e-9
    assert np.all(np.abs(tr.rate) <= 0.5 + 1e-9)      # never exceeds the flow limit


def test_schedule_actions_match_rate_profile():
    """Mean-acceleration actions reproduce v(t) at every step boundary (cumulative sum)."""
    for s in S.all_schedules():
        a = s.actions(DT, A_MAX, N) * A_MAX
        v = np.concatenate([[0.0], np.cumsum(a) * DT])
        ref = np.array([s.rate(k * DT) for k in range(N + 1)])
        np.testing.assert_allclose(v, ref, atol=1e-12)


def test_schedule_with_too_large_acceleration_is_rejected():
    with pytest.raises(ValueError, match="a_max"):
        S.cubic(t_ramp=0.5, t_hold_end=12.0).actions(DT, A_MAX, N)


def test_zv_shaper_cancels_residual_vibration_of_its_mode():
    """Singer-Seering: a linear damped oscillator x'' + 2 zeta w x' + w^2 x = -a(t) driven by the
    ZV-shaped trapezoid has zero residual vibration after the motion (exactly, for the tuned
    omega and zeta); the unshaped trapezoid of the same duration leaves a residual of order
    a / w^2.  Tolerance: residual amplitude < 1e-3 of the unshaped one (integrator rtol 1e-10)."""
    w, z = S.first_mode()
    shaped = S.zv_trapezoid()
    plain = S.trapezoid()

    def residual(s):
        h = 1e-6

        def acc(t):
            return (s.rate(t + h) - s.rate(t - h)) / (2 * h)
        sol = solve_ivp(lambda t, y: [y[1], -acc(t) - 2 * z * w * y[1] - w * w * y[0]],
                        (0.0, s.t_end), [0.0, 0.0], rtol=1e-10, atol=1e-13, max_step=0.01)
        x, xd = sol.y[:, -1]
        return math.hypot(x, xd / w)
    assert residual(shaped) < 1e-3 * residual(plain)


def test_zv_impulses_sum_to_one_and_delay_half_period():
    w, z = 2.0, 0.05
    t, A = S.zv_impulses(w, z)
    assert A.sum() == pytest.approx(1.0, abs=1e-15)
    assert t[1] == pytest.approx(math.pi / (w * math.sqrt(1 - z * z)), rel=1e-15)


def test_force_at_rest_is_the_static_closed_form():
    """At rest (q = 0, a = 0) the evaluation's telescopic force is the rigid static force of
    docs/model.md#check-static-luffing (closed_form.static_luffing_forces, independent code
    path, z_c = 0)."""
    env = ev.make_eval_env()
    env.reset(seed=0)
    u = env.unwrapped
    ref = static_luffing_forces(math.radians(u.angle), u.rom.L, u.payload, z_c=(0.0, 0.0, 0.0))
    assert ev.telescopic_force(env, 0.0) == pytest.approx(ref.telescopic_force, rel=1e-6)


def test_metrics_settle_times():
    t = np.arange(0, 10.01, 1.0)
    stroke = np.array([2, 4, 6, 7.995, 8.02, 8.0, 8.0, 8.0, 8.0, 8.0, 8.0])
    rate = np.array([0, 1, 1, 1, 0.1, 0, 0, 0, 0, 0, 0.0])
    tr = ev.Trace(t, stroke, rate, 0 * t, 0 * t + 1e-3, 0 * t, 8.0, 0.0)
    m = ev.metrics(tr)
    assert m["time_to_target_s"] == 5.0          # 7.995 is inside 1 cm, 8.02 is not
    assert m["stop_time_s"] == 5.0
    assert m["residual_tip_rms_m"] == pytest.approx(1e-3)


def test_evaluation_is_deterministic():
    r1, _ = ev.evaluate(None, episodes=1, seed=3)
    r2, _ = ev.evaluate(None, episodes=1, seed=3)
    assert json.dumps(r1) == json.dumps(r2)


def test_ppo_smoke_train_and_evaluate(tmp_path):
    """A few hundred PPO steps train, save model + normalisation, and evaluate to finite
    metrics through the CLI (JSON on stdout, figure written)."""
    from agents.train_ppo import train
    path = train(512, seed=1, out=tmp_path / "run", n_envs=1, vec="dummy",
                 checkpoint_every=0, progress=False, curve_every=100)
    assert path.exists() and (tmp_path / "run" / "model_vecnormalize.json").exists()
    curve = (tmp_path / "run" / "learning_curve.csv").read_text().splitlines()
    assert curve[0].startswith("env_steps") and len(curve) >= 2
    fig = tmp_path / "ev.png"
    out = tmp_path / "ev.json"
    assert ev.main(["--model", str(path), "--json", "--figure", str(fig), "--out", str(out)]) == 0
    res = json.loads(out.read_text())
    assert set(res) == {"cubic", "trapezoid", "zv_trapezoid", "ppo"}
    for k in ("final_stroke_error_m", "residual_tip_rms_m", "peak_tip_deflection_m",
              "peak_telescopic_force_N"):
        assert math.isfinite(res["ppo"][k])
    assert fig.stat().st_size > 1000
    # deterministic policy: same seed, same numbers
    pol = ev.PPOPolicy(path)
    env = ev.make_eval_env()
    a = ev.run_episode(env, pol, 0)
    b = ev.run_episode(env, pol, 0)
    np.testing.assert_array_equal(a.stroke, b.stroke)


def test_action_repeat_is_a_zero_order_hold_of_the_env():
    """ActionRepeat(k) is exactly k env steps with the same action and the summed reward; the
    evaluation policy holds its action for k steps (meta action_repeat)."""
    import gymnasium as gym

    import boom_env  # noqa: F401
    from agents.wrappers import ActionRepeat
    a = np.array([0.7], dtype=np.float32)
    env = gym.make("boom_env/TelescopicExtraction-v0")
    rep = ActionRepeat(gym.make("boom_env/TelescopicExtraction-v0"), 4)
    env.reset(seed=5)
    rep.reset(seed=5)
    for _ in range(3):
        total = 0.0
        for _ in range(4):
            obs, r, *_ = env.step(a)
            total += r
        obs_r, r_r, *_ = rep.step(a)
        np.testing.assert_array_equal(obs, obs_r)
        assert r_r == pytest.approx(total, rel=1e-12, abs=1e-12)
    with pytest.raises(ValueError, match="repeat"):
        ActionRepeat(env, 0)


def test_ppo_policy_holds_its_action(tmp_path):
    from agents.train_ppo import train
    path = train(256, seed=2, out=tmp_path / "run", n_envs=1, vec="dummy", checkpoint_every=0,
                 progress=False, action_repeat=4)
    meta = json.loads((tmp_path / "run" / "model_meta.json").read_text())
    assert meta["action_repeat"] == 4
    pol = ev.PPOPolicy(path)
    env = ev.make_eval_env()
    obs, _ = env.reset(seed=0)
    acts = []
    for k in range(8):
        acts.append(pol(obs, k))
        obs, *_ = env.step(np.array([acts[-1]], dtype=np.float32))
    assert acts[0] == acts[1] == acts[2] == acts[3] and acts[4] == acts[5] == acts[6] == acts[7]


def _residual_env():
    import gymnasium as gym

    import boom_env  # noqa: F401
    from agents.wrappers import ResidualOnSchedule
    return ResidualOnSchedule(gym.make("boom_env/TelescopicExtraction-v0", tol_deflection=0.0),
                              S.cubic(), scale=0.25, omega=1.0)


def test_zero_residual_is_the_scripted_schedule():
    """With u = 0 the residual wrapper commands the cubic schedule itself: its stroke reference
    is the env's exact kinematics of the schedule's actions, so the tracking error stays at the
    float32 rounding of the actions (N dt^2 a_max 2^-24 ~ 1e-8 m per step, summed) and the
    feedback adds nothing; stroke and tip deflection equal the scripted run's."""
    env = _residual_env()
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs) and obs.shape == (11,)
    ref = ev.run_episode(ev.make_eval_env(), ev.scripted_policy(S.cubic(), DT, A_MAX, N), seed=0)
    strokes, defl = [obs[0]], [0.0]
    for _ in range(N):
        obs, r, term, trunc, info = env.step(np.zeros(1, np.float32))
        assert abs(obs[9]) < 1e-6 and abs(obs[10]) < 1e-6         # e (m), e' (m/s)
        strokes.append(info["stroke"])
        defl.append(float(np.hypot(*info["tip_deflection"])))
        if term or trunc:
            break
    np.testing.assert_allclose(strokes, ref.stroke, atol=1e-6)
    np.testing.assert_allclose(defl, ref.deflection, atol=1e-8)


def test_tracking_feedback_returns_a_disturbed_stroke_to_the_schedule_end():
    """A constant residual of +1 (scale 0.25: d = 0.0625 m/s^2) for the first 2 s pushes the
    stroke ahead of the schedule: closed loop e = d / omega^2 (1 - (1 + omega t) exp(-omega t)),
    3.7 cm at 2 s; then the critically damped feedback (omega 1 rad/s) brings it back as
    (1 + omega t) exp(-omega t), < 1e-9 m left 28 s later, so the episode ends at 8 m within
    1 mm and at rest.  The appended observation is the deviation L_s - L_ref."""
    env = _residual_env()
    obs, _ = env.reset(seed=0)
    peak = 0.0
    for k in range(N):
        u = 1.0 if k < 40 else 0.0
        obs, r, term, trunc, info = env.step(np.array([u], np.float32))
        peak = max(peak, abs(obs[9]))
        if term or trunc:
            break
    assert 0.03 < peak < 0.045                # the disturbance moved the stroke as predicted
    assert abs(info["stroke"] - 8.0) < 1e-3 and abs(info["stroke_rate"]) < 1e-3


def test_residual_policy_evaluation_replays_the_training_wrapper(tmp_path):
    """A residual PPO model (a few hundred steps) acting through agents.evaluate.PPOPolicy gives
    the same strokes as the same model acting through the training wrapper: the evaluation
    rebuilds the schedule, feedback and observation of ResidualOnSchedule from the model's
    meta file."""
    from agents.train_ppo import train
    path = train(256, seed=3, out=tmp_path / "run", n_envs=1, vec="dummy", checkpoint_every=0,
                 progress=False, residual="cubic")
    meta = json.loads((tmp_path / "run" / "model_meta.json").read_text())
    assert meta["action_mode"] == "residual" and meta["residual"]["schedule"] == "cubic"
    pol = ev.PPOPolicy(path)
    env = ev.make_eval_env()
    pol.bind(env)
    tr = ev.run_episode(env, pol, 0)
    wrapped = _residual_env()
    obs, _ = wrapped.reset(seed=0)
    strokes = [obs[0]]
    for _ in range(N):
        obs, r, term, trunc, info = wrapped.step(np.array([pol._act(obs)], np.float32))
        strokes.append(info["stroke"])
        if term or trunc:
            break
    np.testing.assert_allclose(strokes, tr.stroke, atol=1e-9)
    with pytest.raises(ValueError, match="random_start"):
        train(64, seed=0, out=tmp_path / "bad", n_envs=1, vec="dummy", checkpoint_every=0,
              progress=False, residual="cubic", random_start=0.5)
    with pytest.raises(ValueError, match="schedule"):
        S.by_name("sinusoid")


def test_tracking_term_of_the_residual_training_reward():
    """w_track adds -(e / 1 cm)^2 dt to the env's reward, nothing else changes."""
    import gymnasium as gym

    import boom_env  # noqa: F401
    from agents.wrappers import ResidualOnSchedule
    envs = [ResidualOnSchedule(gym.make("boom_env/TelescopicExtraction-v0", tol_deflection=0.0),
                               S.cubic(), w_track=w) for w in (0.0, 1.0)]
    for e in envs:
        e.reset(seed=0)
    seen = 0.0
    for k in range(60):
        u = np.array([0.8 if k < 30 else -0.3], np.float32)
        (o0, r0, *_), (o1, r1, *_) = (e.step(u) for e in envs)
        np.testing.assert_array_equal(o0, o1)
        assert r1 == pytest.approx(r0 - (float(o1[9]) / 0.01) ** 2 * DT, rel=1e-12, abs=1e-12)
        seen = max(seen, abs(float(o1[9])))
    assert seen > 1e-3                        # the term was exercised
    with pytest.raises(ValueError, match="w_track"):
        ResidualOnSchedule(envs[0].env, S.cubic(), w_track=-1.0)


def test_traces_round_trip_and_oscillation_metric(tmp_path):
    """Saved traces load back unchanged; the oscillation metric is the RMS of the deflection
    vector about its window mean, so a constant offset of the deflection reference does not
    change it (while it does change the |d| RMS)."""
    env = ev.make_eval_env()
    tr = ev.run_episode(env, ev.scripted_policy(S.cubic(), DT, A_MAX, N), seed=0)
    ev.save_traces({"cubic": tr}, tmp_path / "t.npz")
    back = ev.load_traces(tmp_path / "t.npz")["cubic"]
    np.testing.assert_array_equal(back.deflection_xz, tr.deflection_xz)
    assert back.target == tr.target and back.total_return == tr.total_return
    m = ev.metrics(tr)
    shifted = ev.Trace(**{**tr.__dict__, "deflection_xz": tr.deflection_xz + [3e-3, -2e-3]})
    shifted.deflection = np.hypot(*shifted.deflection_xz.T)
    m2 = ev.metrics(shifted)
    assert m2["residual_tip_oscillation_m"] == pytest.approx(m["residual_tip_oscillation_m"], rel=1e-9)
    assert m2["residual_tip_rms_m"] > 2 * m["residual_tip_rms_m"]
    # the vibration after the cubic's stop is a free oscillation about ~0: both metrics agree
    assert m["residual_tip_oscillation_m"] == pytest.approx(m["residual_tip_rms_m"], rel=0.05)


def test_deflection_offset_shifts_only_the_observed_deflection():
    """DeflectionOffset adds one constant (per episode, within +-max_offset, seeded) to the
    observed dX, dZ; the other observations and the reward are the env's."""
    import gymnasium as gym

    import boom_env  # noqa: F401
    from agents.wrappers import DeflectionOffset
    plain = gym.make("boom_env/TelescopicExtraction-v0")
    wrapped = DeflectionOffset(gym.make("boom_env/TelescopicExtraction-v0"), 5e-3)
    o0, _ = plain.reset(seed=4)
    o1, _ = wrapped.reset(seed=4)
    off = o1[5:7] - o0[5:7]
    assert np.all(np.abs(off) <= 5e-3) and np.any(np.abs(off) > 0)
    for _ in range(20):
        a = np.array([0.6], np.float32)
        (o0, r0, *_), (o1, r1, *_) = plain.step(a), wrapped.step(a)
        np.testing.assert_allclose(o1[5:7] - o0[5:7], off, atol=1e-9)
        np.testing.assert_array_equal(np.delete(o1, [5, 6]), np.delete(o0, [5, 6]))
        assert r1 == r0
    o2, _ = wrapped.reset(seed=4)
    np.testing.assert_allclose(o2[5:7] - plain.reset(seed=4)[0][5:7], off, atol=1e-9)
    with pytest.raises(ValueError, match="max_offset"):
        DeflectionOffset(plain, -1.0)
