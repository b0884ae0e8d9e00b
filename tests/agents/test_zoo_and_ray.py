"""The shipped RL Zoo hyper-parameter files: agents.train_ppo reads its PPO settings from the
same file RL Zoo reads, RL Zoo trains with them, SB3's SAC trains on the env with the shipped
SAC settings, and multi-seed training (in-process or one Ray task per seed) writes the run
folders and the report."""

import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
import yaml

import boom_env  # noqa: F401
from agents import train_ppo

ENV_ID = "boom_env/TelescopicExtraction-v0"
HP = Path(train_ppo.__file__).with_name("hyperparams")


def _entry(algo):
    with open(HP / f"{algo}.yml") as f:
        return yaml.safe_load(f)[ENV_ID]


def test_train_ppo_reads_the_shipped_rl_zoo_file():
    """train_ppo's PPO settings are the ENV_ID entry of agents/hyperparams/ppo.yml, the file
    RL Zoo reads with --conf-file: every PPO argument and the policy kwargs come from it."""
    entry = _entry("ppo")
    assert train_ppo.HYPERPARAMS_FILE == HP / "ppo.yml"
    hyper, policy_kwargs, vecnorm, n_envs = train_ppo.ppo_settings(train_ppo.load_hyperparams())
    for key, value in hyper.items():
        assert entry[key] == value
    assert set(hyper) == set(entry) - set(train_ppo.ZOO_KEYS)
    assert policy_kwargs == entry["policy_kwargs"] and n_envs == entry["n_envs"]
    assert bool(vecnorm) == bool(entry["normalize"])


def test_train_uses_the_given_file(tmp_path):
    """A changed yml changes the trained model's settings: n_steps per env is the file's
    n_steps x n_envs / the run's n_envs (same rollout size), batch size and policy net as
    written; unsupported keys and a missing env id are errors naming them."""
    from stable_baselines3 import PPO
    entry = dict(_entry("ppo"), n_steps=96, n_envs=2, batch_size=48, n_epochs=1,
                 policy_kwargs={"net_arch": [16]}, normalize=False)
    path = tmp_path / "ppo.yml"
    path.write_text(yaml.safe_dump({ENV_ID: entry}))
    model_path = train_ppo.train(192, seed=0, out=tmp_path / "run", n_envs=1, vec="dummy",
                                 checkpoint_every=0, progress=False, residual=None,
                                 hyperparams=path)
    model = PPO.load(model_path, device="cpu")
    assert model.n_steps == 192 and model.batch_size == 48 and model.n_epochs == 1
    assert model.policy.net_arch == [16]
    assert not (tmp_path / "run" / "model_vecnormalize.json").exists()     # normalize: false
    path.write_text(yaml.safe_dump({ENV_ID: dict(entry, frame_stack=4)}))
    with pytest.raises(ValueError, match="frame_stack"):
        train_ppo.train(64, seed=0, out=tmp_path / "bad", n_envs=1, vec="dummy", hyperparams=path)
    path.write_text(yaml.safe_dump({"CartPole-v1": entry}))
    with pytest.raises(ValueError, match=ENV_ID):
        train_ppo.load_hyperparams(path)


def test_lin_schedule_decays_linearly():
    """'lin_<x>' is RL Zoo's linear schedule x * progress_remaining."""
    hyper, *_ = train_ppo.ppo_settings({"learning_rate": "lin_0.001", "clip_range": 0.2})
    assert hyper["learning_rate"](1.0) == 0.001 and hyper["learning_rate"](0.25) == 0.00025
    with pytest.raises(ValueError, match="learning_rate"):
        train_ppo.ppo_settings({"learning_rate": "exp_0.001"})


def test_sac_trains_with_the_shipped_settings():
    """SB3 SAC with the shipped sac.yml entry (observation normalisation as written) runs
    3000 steps on the env, the last 2000 with gradient updates (gradient_steps per train_freq
    steps, as written): the replay buffer holds every transition, the updates happened, the
    losses are finite, and the policy's actions stay in the action space."""
    import torch
    from stable_baselines3 import SAC
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import VecNormalize
    torch.set_num_threads(1)
    hyper, policy_kwargs, vecnorm, n_envs = train_ppo.zoo_settings(_entry("sac"), SAC)
    hyper.update(learning_starts=1000)
    venv = make_vec_env(ENV_ID, n_envs=n_envs, seed=0)
    if vecnorm:
        venv = VecNormalize(venv, gamma=hyper.get("gamma", 0.99), **vecnorm)
    model = SAC("MlpPolicy", venv, seed=0, device="cpu", policy_kwargs=policy_kwargs, **hyper)
    model.learn(3000)
    expected = 2000 // hyper["train_freq"] * hyper["gradient_steps"]
    assert model.replay_buffer.size() * n_envs == 3000
    assert expected - hyper["gradient_steps"] <= model._n_updates <= expected
    losses = {k: v for k, v in model.logger.name_to_value.items() if "loss" in k}
    assert losses and all(np.isfinite(v) for v in losses.values())
    obs = venv.reset()
    act, _ = model.predict(obs, deterministic=False)
    assert act.shape == (n_envs, 1) and np.all(np.abs(act) <= 1.0)
    venv.close()


def _zoo(tmp_path, algo, n, seed=0, extra=()):
    cmd = [sys.executable, "-m", "rl_zoo3.train", "--algo", algo, "--env", ENV_ID,
           "--gym-packages", "boom_env", "--conf-file", str(HP / f"{algo}.yml"), "-n", str(n),
           "--seed", str(seed), "-f", str(tmp_path / "logs"), "--num-threads", "1", *extra]
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=1500, cwd=tmp_path)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    run = tmp_path / "logs" / algo / f"{ENV_ID.replace('/', '-')}_1"
    return run, out.stdout


def test_rl_zoo_trains_with_the_shipped_ppo_file(tmp_path):
    """``python -m rl_zoo3.train --algo ppo --env boom_env/TelescopicExtraction-v0
    --gym-packages boom_env --conf-file agents/hyperparams/ppo.yml -n 20000``: runs, saves
    model and normalisation statistics, used the file's settings (RL Zoo's config.yml), and
    every monitored episode finished with a finite return below 0.01 * bonus = 0.5 (the
    success bonus, scaled, is the only positive term)."""
    run, stdout = _zoo(tmp_path, "ppo", 20000)
    name = ENV_ID.replace("/", "-")
    assert (run / f"{name}.zip").exists() and (run / name / "vecnormalize.pkl").exists()
    with open(run / name / "config.yml") as f:
        used = dict(yaml.unsafe_load(f))
    entry = _entry("ppo")
    for key in ("n_steps", "batch_size", "gamma", "gae_lambda", "n_envs"):
        assert used[key] == entry[key]
    rows = []
    for mon in run.glob("*.monitor.csv"):
        with open(mon) as f:
            next(f)
            rows += [float(r["r"]) for r in csv.DictReader(f)]
    assert len(rows) >= 20000 // 600 - entry["n_envs"]          # finished episodes
    assert all(np.isfinite(rows)) and max(rows) < 0.5


def test_train_seeds_writes_run_folders_and_report(tmp_path):
    """--seeds without Ray: OUT/seed<N> per seed (model, normalisation, meta, curve) and the
    report (learning_curve.png, comparison.md with one row per seed) in OUT."""
    out = tmp_path / "runs"
    assert train_ppo.main(["--seeds", "3", "4", "--timesteps", "768", "--n-envs", "1",
                           "--vec", "dummy", "--checkpoint-every", "0", "--no-progress",
                           "--set", "n_steps=64", "--set", "batch_size=64",
                           "--out", str(out)]) == 0
    for s in (3, 4):
        d = out / f"seed{s}"
        for f in ("model.zip", "model_vecnormalize.json", "model_meta.json", "learning_curve.csv"):
            assert (d / f).exists(), d / f
        assert json.loads((d / "model_meta.json").read_text())["seed"] == s
    md = (out / "comparison.md").read_text()
    assert "| seed3 |" in md and "| seed4 |" in md and (out / "learning_curve.png").exists()


def test_ray_flags_are_checked():
    """Ray flags without their companions are usage errors, and ray is imported only with
    --ray (the module and a plain run do not import it)."""
    code = ("import sys\nfrom agents import train_ppo\n"
            "train_ppo.train_seeds([0], sys.argv[1], timesteps=64, n_envs=1, vec='dummy', "
            "checkpoint_every=0, progress=False, "
            "hyper_overrides={'n_steps': 32, 'batch_size': 64})\n"
            "assert 'ray' not in sys.modules\n")
    with tempfile.TemporaryDirectory() as tmp:
        out = subprocess.run([sys.executable, "-c", code, tmp], capture_output=True, text=True,
                             timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    with pytest.raises(SystemExit):
        train_ppo.main(["--address", "auto", "--seeds", "0"])          # --address needs --ray
    with pytest.raises(SystemExit):
        train_ppo.main(["--ray"])                                      # --ray needs --seeds
    with pytest.raises(SystemExit):
        train_ppo.main(["--seeds", "1", "1"])                          # each seed once


@pytest.mark.slow
def test_ray_runs_one_task_per_seed_with_the_same_results(tmp_path):
    """--ray: one Ray task per seed on a local Ray instance; the folders have the same files
    as without Ray and the same learning curves and metadata (training is seeded and
    single-threaded, so Ray only changes where it runs)."""
    args = ["--timesteps", "768", "--n-envs", "1", "--vec", "dummy", "--checkpoint-every", "0",
            "--no-progress", "--seeds", "0", "1", "--set", "n_steps=64", "--set", "batch_size=64"]
    assert train_ppo.main([*args, "--out", str(tmp_path / "plain")]) == 0
    assert train_ppo.main([*args, "--ray", "--out", str(tmp_path / "ray")]) == 0
    for s in (0, 1):
        a, b = tmp_path / "plain" / f"seed{s}", tmp_path / "ray" / f"seed{s}"
        assert {p.name for p in a.iterdir()} == {p.name for p in b.iterdir()}
        assert (a / "learning_curve.csv").read_text() == (b / "learning_curve.csv").read_text()
        assert (a / "model_meta.json").read_text() == (b / "model_meta.json").read_text()
    assert (tmp_path / "ray" / "comparison.md").exists()


def _deterministic_return(policy, obs_filter=lambda o: o) -> float:
    """Return of one episode of the registered env (default reward scale) from its fixed
    start (25 t, 60 deg, 2 -> 8 m): env and policy are deterministic, so one episode is exact."""
    import gymnasium as gym
    env = gym.make(ENV_ID)
    obs, _ = env.reset(seed=0)
    total, k, done = 0.0, 0, False
    while not done:
        obs, r, term, trunc, _ = env.step(np.asarray(policy(obs_filter(obs), k), np.float32))
        total += r
        k += 1
        done = term or trunc
    return total


@pytest.mark.slow
def test_rl_zoo_sac_with_the_shipped_settings_beats_standing_still(tmp_path):
    """RL Zoo, SAC, the shipped sac.yml, 100k env steps, seed 0 (2-10 min on 2 cores), with
    RL Zoo's evaluation every 10k steps (deterministic policy; one episode: env and start are
    deterministic, so one episode is exact).  Asserts: the best evaluated policy, the one RL
    Zoo keeps as best_model.zip, scores clearly better than standing still, and the final
    policy (re-run here with the saved observation statistics, equal to RL Zoo's evaluation at
    100k) better than standing still.
    "Standing still" = the zero action, measured here (-11 per s unscaled over 30 s: -3.3).
    "Clearly": at least a quarter of the gap between standing still and the paper's cubic
    schedule (-1.588, measured here) is closed, i.e. a return above -2.87.  The returns are
    exact, so any margin is real; a quarter (0.43, 43 unscaled, ~4 s of standing still) asks
    for a policy that extends a good part of the way.  The check on the final policy is weaker
    because SAC's evaluated returns swing from one evaluation to the next (agents/README.md,
    "Standard learners on the registered env", gives the measured returns and the command)."""
    import pickle

    from stable_baselines3 import SAC

    from agents.evaluate import scripted_policy
    from agents.schedules import cubic
    run, _ = _zoo(tmp_path, "sac", 100_000, seed=0,
                  extra=["--eval-freq", "10000", "--eval-episodes", "1"])
    name = ENV_ID.replace("/", "-")
    evals = np.load(run / "evaluations.npz")
    assert list(evals["timesteps"]) == list(range(10_000, 100_001, 10_000))
    best = float(evals["results"].max())
    model = SAC.load(run / f"{name}.zip", device="cpu")
    with open(run / name / "vecnormalize.pkl", "rb") as f:
        vn = pickle.load(f)
    final = _deterministic_return(lambda o, k: model.predict(o, deterministic=True)[0],
                                  vn.normalize_obs)
    # RL Zoo's own evaluation at 100k normalised with the statistics of its last sync
    assert final == pytest.approx(float(evals["results"][-1, 0]), abs=0.1)
    still = _deterministic_return(lambda o, k: np.zeros(1))
    sched = scripted_policy(cubic(), 0.05, 0.25, 600)
    cubic_return = _deterministic_return(lambda o, k: np.array([sched(o, k)]))
    assert still == pytest.approx(-3.3, rel=1e-9) and cubic_return > still + 1.0
    print(f"SAC 100k: evaluations {np.round(evals['results'].ravel(), 3).tolist()}, best "
          f"{best:.3f}, final {final:.3f}; standing still {still:.3f}, cubic {cubic_return:.3f}")
    assert best > still + 0.25 * (cubic_return - still), (best, still, cubic_return)
    assert final > still, (final, still)
