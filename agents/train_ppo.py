"""Train the PPO baseline on ``boom_env/TelescopicExtraction-v0``.

    python -m agents.train_ppo --timesteps 300000 --seed 0 --out agents/runs/seed0
    python -m agents.train_ppo --seeds 0 1 2 --ray [--address ADDR] --out agents/runs

The policy is by default a *residual* on the paper's cubic schedule (``--residual cubic``,
``agents.wrappers.ResidualOnSchedule``): the env action is the schedule's feed-forward
acceleration plus a critically damped tracking feedback on the schedule's stroke history plus
0.25 a_max times the policy output, so the untrained policy (output ~0) is the cubic schedule
and PPO learns the correction that lowers the tip vibration (residual policy learning, Silver
et al. 2018; Johannink et al. 2019).  ``--residual none`` trains the acceleration from scratch
(it did not reach the target in 400k steps with the shipped hyper-parameters).

Stable-Baselines3 PPO with an MLP policy, observation and reward normalisation (VecNormalize),
a SubprocVecEnv with one env process per available core (``--vec dummy`` runs them in-process,
which is faster for the cheap modal env on a loaded machine: see benchmarks/results/env_speed.md),
a progress bar, optional TensorBoard logging (``--tensorboard DIR``, needs ``tensorboard``),
periodic checkpoints, and on exit:

* ``DIR/model.zip`` and ``DIR/model_vecnormalize.json`` (the observation statistics the policy
  needs at evaluation as JSON, see ``agents.evaluate.PPOPolicy`` and ``agents.model_io``);
* ``DIR/learning_curve.csv``: environment steps, episodes, mean return of the last 20 finished
  training episodes (the stochastic policy's undiscounted, unnormalised env return) and their
  success rate.

PPO hyper-parameters: the entry of ``boom_env/TelescopicExtraction-v0`` in
``agents/hyperparams/ppo.yml``, the RL Zoo file (``--hyperparams`` another one; ``--set``
overrides single values).

``--seeds S1 S2 ...`` trains one run per seed into ``OUT/seed<S>`` and writes the report of
``agents.report`` (learning_curve.png, comparison.md) into OUT.  With ``--ray`` each seed is a
Ray task (``ray.init()`` on this machine, or the cluster at ``--address``; ray is imported only
then): SB3 trains inside the task, Ray only schedules, and the task hands the run's files back
to be written here, so the folders are the same as without Ray.

Training is reproducible for a given seed up to the floating-point non-determinism of torch:
the env, the policy initialisation and the action noise are seeded (``set_random_seed``),
torch runs single-threaded.
"""

from __future__ import annotations

import argparse
import csv
import io
import os
import sys
import time
from pathlib import Path

import numpy as np

from .settings import ENV_ID, RESIDUAL_ENV_KWARGS, TRAIN_ENV_KWARGS
# PPO hyper-parameters: the RL Zoo file shipped with the package (single source: RL Zoo reads
# the same file with ``--conf-file``), its entry for ENV_ID.  The reasons for the values are
# in the file.
HYPERPARAMS_FILE = Path(__file__).with_name("hyperparams") / "ppo.yml"
# keys of an RL Zoo entry that are not PPO constructor arguments and that train() handles
ZOO_KEYS = ("n_envs", "n_timesteps", "policy", "normalize", "policy_kwargs")


def load_hyperparams(path: str | os.PathLike = HYPERPARAMS_FILE, env_id: str = ENV_ID) -> dict:
    """The RL Zoo hyper-parameter entry of ``env_id`` in the yml file ``path`` (a dict of
    RL Zoo keys: n_envs, n_timesteps, policy, normalize, policy_kwargs and PPO arguments)."""
    import yaml
    with open(path) as f:
        table = yaml.safe_load(f)
    if not isinstance(table, dict) or env_id not in table:
        raise ValueError(f"{path}: no entry for env id {env_id!r} (entries: "
                         f"{sorted(table) if isinstance(table, dict) else 'none'})")
    return dict(table[env_id])


def ppo_settings(entry: dict) -> tuple[dict, dict, dict, int]:
    """:func:`zoo_settings` of an RL Zoo PPO entry."""
    from stable_baselines3 import PPO
    return zoo_settings(entry, PPO)


def zoo_settings(entry: dict, algo) -> tuple[dict, dict, dict, int]:
    """Split an RL Zoo entry for the SB3 class ``algo`` into (constructor arguments,
    policy_kwargs, VecNormalize arguments (empty: no normalisation), n_envs the entry is meant
    for).  Values follow RL Zoo's conventions: ``normalize`` true / false / a mapping of
    VecNormalize arguments (its gamma is the algorithm's), ``policy_kwargs`` a mapping (RL
    Zoo's string form is not read here), ``learning_rate`` and ``clip_range`` a number or
    ``"lin_<x>"`` (linear decay from x to 0), ``train_freq`` a number or a list."""
    import inspect
    allowed = set(inspect.signature(algo.__init__).parameters) - {"self", "policy", "env",
                                                                   "policy_kwargs"}
    entry = dict(entry)
    unknown = set(entry) - allowed - set(ZOO_KEYS)
    if unknown:
        raise ValueError(f"hyper-parameters {sorted(unknown)}: not supported here (allowed "
                         f"for {algo.__name__}: {sorted(set(ZOO_KEYS) | allowed)})")
    policy = entry.pop("policy", "MlpPolicy")
    if policy != "MlpPolicy":
        raise ValueError(f"policy = {policy!r}: allowed 'MlpPolicy'")
    n_envs = entry.pop("n_envs", 1)
    if not (isinstance(n_envs, int) and n_envs >= 1):
        raise ValueError(f"n_envs = {n_envs!r}: allowed integers >= 1")
    entry.pop("n_timesteps", None)
    norm = entry.pop("normalize", False)
    if not isinstance(norm, (bool, dict)):
        raise ValueError(f"normalize = {norm!r}: allowed true, false or a yml mapping of "
                         "VecNormalize arguments")
    vecnorm = {} if norm is False else {"norm_obs": True, "norm_reward": True,
                                        **(norm if isinstance(norm, dict) else {})}
    policy_kwargs = entry.pop("policy_kwargs", None) or {}
    if not isinstance(policy_kwargs, dict):
        raise ValueError(f"policy_kwargs = {policy_kwargs!r}: write it as a yml mapping")
    for key in ("learning_rate", "clip_range"):
        v = entry.get(key)
        if isinstance(v, str):
            kind, _, x = v.partition("_")
            if kind != "lin":
                raise ValueError(f"{key} = {v!r}: allowed a number or 'lin_<x>'")
            entry[key] = _linear(float(x))
    if isinstance(entry.get("train_freq"), list):
        entry["train_freq"] = tuple(entry["train_freq"])
    return entry, dict(policy_kwargs), vecnorm, n_envs


def _linear(x0: float):
    """Linear decay x0 * progress_remaining (RL Zoo's 'lin_<x>'), picklable for model.save."""
    import functools
    return functools.partial(_scaled_progress, x0)


def _scaled_progress(x0: float, progress_remaining: float) -> float:
    return x0 * progress_remaining




def _make_env(rank: int, seed: int, du_max: float | None, env_kwargs: dict,
              random_start: float = 0.0, action_repeat: int = 1, residual: dict | None = None,
              obs_offset: float = 0.0):
    def thunk():
        import gymnasium as gym
        from stable_baselines3.common.monitor import Monitor

        import boom_env  # noqa: F401
        env = gym.make(ENV_ID, **env_kwargs)
        if obs_offset > 0:
            from .wrappers import DeflectionOffset
            env = DeflectionOffset(env, obs_offset)
        if random_start > 0:
            from .wrappers import RandomStart
            env = RandomStart(env, random_start)
        if du_max:
            from .wrappers import AccelerationIncrement
            env = AccelerationIncrement(env, du_max)
        if residual:
            from .schedules import by_name
            from .wrappers import ResidualOnSchedule
            env = ResidualOnSchedule(env, by_name(residual["schedule"]), residual["scale"],
                                     residual["omega"], residual["w_track"])
        if action_repeat > 1:
            from .wrappers import ActionRepeat
            env = ActionRepeat(env, action_repeat)
        env = Monitor(env, info_keywords=("success",))
        env.reset(seed=seed + rank)
        env.action_space.seed(seed + rank)
        return env
    return thunk


def _curve_callback(path: Path, every: int):
    from stable_baselines3.common.callbacks import BaseCallback

    class LearningCurve(BaseCallback):
        """Writes (steps, episodes, mean return, success rate) of the last 20 episodes."""

        def __init__(self):
            super().__init__()
            self.returns: list[float] = []
            self.success: list[float] = []
            self.next = 0
            self.rows: list[tuple] = []

        def _on_step(self) -> bool:
            for info in self.locals.get("infos", []):
                ep = info.get("episode")
                if ep is not None:
                    self.returns.append(float(ep["r"]))
                    self.success.append(float(bool(info.get("success", False))))
            if self.num_timesteps >= self.next and self.returns:
                self.rows.append((self.num_timesteps, len(self.returns),
                                  float(np.mean(self.returns[-20:])),
                                  float(np.mean(self.success[-20:]))))
                self.next = self.num_timesteps + every
                self._write()
            return True

        def _on_training_end(self) -> None:
            if self.returns:
                self.rows.append((self.num_timesteps, len(self.returns),
                                  float(np.mean(self.returns[-20:])),
                                  float(np.mean(self.success[-20:]))))
            self._write()

        def _write(self) -> None:
            from .evaluate import atomic_write_text
            buf = io.StringIO(newline="")
            w = csv.writer(buf)
            w.writerow(["env_steps", "episodes", "mean_return_last20", "success_rate_last20"])
            w.writerows(self.rows)
            atomic_write_text(path, buf.getvalue())

    return LearningCurve()


def train(timesteps: int, seed: int, out: str | os.PathLike, n_envs: int | None = None,
          vec: str = "subproc", tensorboard: str | None = None, checkpoint_every: int = 100_000,
          progress: bool = True, curve_every: int = 5_000, verbose: int = 0,
          hyper_overrides: dict | None = None, policy_overrides: dict | None = None,
          du_max: float | None = None, env_kwargs: dict | None = None,
          random_start: float = 0.0, action_repeat: int = 1,
          residual: str | None = None, residual_scale: float = 0.25,
          residual_omega: float = 1.0, residual_w_track: float = 1.0,
          obs_offset: float = 0.0,
          hyperparams: str | os.PathLike | dict = HYPERPARAMS_FILE) -> Path:
    """Train and save; returns the path of the saved model.  ``residual`` = a schedule name of
    ``agents.schedules`` makes the policy a residual on that schedule with tracking feedback
    (``agents.wrappers.ResidualOnSchedule``: scale, feedback frequency rad/s and the weight of
    the tracking term of the training reward, see RESIDUAL_ENV_KWARGS).  PPO settings: the
    ENV_ID entry of the RL Zoo file ``hyperparams`` (:func:`load_hyperparams`; or that entry
    itself, a dict), then
    ``hyper_overrides`` / ``policy_overrides``; its ``n_steps`` is per env for the entry's
    ``n_envs``, rescaled so that a rollout has the same size with ``n_envs`` envs.  The env's
    reward scale is 1 unless ``env_kwargs`` sets it: VecNormalize divides the rewards by the
    running std of the return, so the scale does not change the learning, and the learning
    curve stays in the unscaled units of agents/README.md."""
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import CallbackList, CheckpointCallback
    from stable_baselines3.common.utils import set_random_seed
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecNormalize

    if timesteps < 1:
        raise ValueError(f"timesteps = {timesteps}: allowed >= 1")
    if vec not in ("subproc", "dummy"):
        raise ValueError(f"vec = {vec!r}: allowed 'subproc', 'dummy'")
    n_envs = n_envs or max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                           else (os.cpu_count() or 1))
    if n_envs < 1:
        raise ValueError(f"n_envs = {n_envs}: allowed >= 1")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)
    set_random_seed(seed)
    default_env = RESIDUAL_ENV_KWARGS if residual else TRAIN_ENV_KWARGS
    env_kwargs = {"reward_scale": 1.0, **(default_env if env_kwargs is None else env_kwargs)}
    entry = hyperparams if isinstance(hyperparams, dict) else load_hyperparams(hyperparams)
    hyper, policy_kwargs, vecnorm, zoo_n_envs = ppo_settings(entry)
    hyper.update(hyper_overrides or {})
    policy_kwargs.update(policy_overrides or {})
    if sum(bool(x) for x in (du_max, action_repeat > 1, residual)) > 1:
        raise ValueError("du_max, action_repeat > 1 and residual: choose one action parameterisation")
    res = None
    if residual:
        from .schedules import by_name
        by_name(residual)                                  # validates the name
        if random_start > 0:
            raise ValueError("residual with random_start > 0: the schedule's reference starts "
                             "at the task's start stroke; use random_start = 0")
        res = dict(schedule=residual, scale=float(residual_scale), omega=float(residual_omega),
                   w_track=float(residual_w_track))
    fns = [_make_env(i, seed, du_max, env_kwargs, random_start, action_repeat, res, obs_offset)
           for i in range(n_envs)]
    venv = SubprocVecEnv(fns, start_method="spawn") if vec == "subproc" and n_envs > 1 else DummyVecEnv(fns)
    venv.seed(seed)
    if vecnorm:
        venv = VecNormalize(venv, gamma=hyper.get("gamma", 0.99), **vecnorm)
    # same rollout size per update as the entry's n_steps x n_envs
    hyper["n_steps"] = max(64, hyper.get("n_steps", 2048) * zoo_n_envs // n_envs)
    if tensorboard:
        try:
            import tensorboard  # noqa: F401
        except ImportError:
            raise SystemExit("--tensorboard needs the tensorboard package (pip install tensorboard)")
    model = PPO("MlpPolicy", venv, seed=seed, device="cpu", policy_kwargs=policy_kwargs,
                tensorboard_log=tensorboard, verbose=verbose, **hyper)
    if not tensorboard and verbose == 0:
        # SB3's default logger would create an empty SB3-<time> folder in the temp directory
        # on every learn(); nothing is logged here, so a logger without outputs is set
        from stable_baselines3.common.logger import Logger
        model.set_logger(Logger(folder=None, output_formats=[]))
    cbs = [_curve_callback(out / "learning_curve.csv", curve_every)]
    if checkpoint_every > 0:
        cbs.append(CheckpointCallback(save_freq=max(checkpoint_every // n_envs, 1),
                                      save_path=str(out / "checkpoints"), name_prefix="ppo",
                                      save_vecnormalize=True))
    t0 = time.perf_counter()
    try:
        model.learn(total_timesteps=timesteps, callback=CallbackList(cbs), progress_bar=progress)
    finally:
        wall = time.perf_counter() - t0
        path = out / "model.zip"
        model.save(str(out / "model.tmp.zip"))
        os.replace(out / "model.tmp.zip", path)
        if vecnorm:
            from .model_io import save_vecnorm
            save_vecnorm(venv, out / "model_vecnormalize.json")
        import json

        from .evaluate import atomic_write_text
        atomic_write_text(out / "model_meta.json", json.dumps(
            {"env_id": ENV_ID, "action_mode": ("increment" if du_max else
                                               "residual" if res else "acceleration"),
             "du_max": du_max, "action_repeat": action_repeat, "residual": res,
             "env_kwargs": env_kwargs,
             "random_start": random_start, "obs_offset": obs_offset,
             "seed": seed, "timesteps": int(model.num_timesteps)}) + "\n")
        atomic_write_text(out / "train_info.txt",
                          f"timesteps {model.num_timesteps}\nseed {seed}\nn_envs {n_envs}\n"
                          f"vec {vec}\nwall_s {wall:.1f}\nhyper {hyper}\n"
                          f"policy_kwargs {policy_kwargs}\n")
        venv.close()
    return path


def train_seeds(seeds: list[int], out: str | os.PathLike, use_ray: bool = False,
                address: str | None = None, ray_cpus: float = 1.0, **kwargs) -> list[Path]:
    """Train one run per seed into ``out/seed<seed>`` (:func:`train` with ``kwargs``); returns
    the model paths.  ``use_ray``: each seed is one Ray task (``ray.init()`` on this machine,
    or joining the cluster at ``address``) reserving ``ray_cpus`` CPUs; the task trains in a
    temporary directory of its node and returns the run's files, which are written here, so
    the nodes need no shared file system.  The folders are the same as without Ray."""
    out = Path(out)
    dirs = [out / f"seed{s}" for s in seeds]
    if not use_ray:
        return [train(seed=s, out=d, **kwargs) for s, d in zip(seeds, dirs)]
    import ray

    from sim_core.result import atomic_write_bytes
    started = not ray.is_initialized()
    if started:
        if address:
            ray.init(address=address)
        else:
            ray.init(include_dashboard=False)
    try:
        task = ray.remote(num_cpus=ray_cpus)(_train_packed)
        kwargs = dict(kwargs, progress=False)     # a progress bar per task garbles the log
        refs = [task.remote(s, kwargs) for s in seeds]
        paths = []
        for d, files in zip(dirs, ray.get(refs)):
            for rel, data in files.items():
                (d / rel).parent.mkdir(parents=True, exist_ok=True)
                atomic_write_bytes(d / rel, data)
            paths.append(d / "model.zip")
        return paths
    finally:
        if started:
            ray.shutdown()


def _train_packed(seed: int, kwargs: dict) -> dict[str, bytes]:
    """Ray task body: :func:`train` in a temporary directory; returns {relative path: bytes}."""
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        run = Path(tmp) / "run"
        train(seed=seed, out=run, **kwargs)
        return {str(p.relative_to(run)): p.read_bytes() for p in run.rglob("*") if p.is_file()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m agents.train_ppo",
                                 description="Train the PPO extraction baseline (see module doc).")
    ap.add_argument("--timesteps", type=int, default=300_000,
                    help="environment steps (default 300000: 9 min per run with three runs "
                         "sharing 2 cores)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--seeds", type=int, nargs="+", default=None, metavar="SEED",
                    help="train one run per seed into OUT/seed<SEED> and write the report "
                         "(agents.report: learning_curve.png, comparison.md) into OUT")
    ap.add_argument("--out", default=None,
                    help="output directory (default agents/runs/seed<SEED>; with --seeds the "
                         "parent directory, default agents/runs)")
    ap.add_argument("--ray", action="store_true",
                    help="with --seeds: one Ray task per seed (local ray.init() unless "
                         "--address); SB3 still trains, Ray only schedules")
    ap.add_argument("--address", default=None,
                    help="with --ray: address of a running Ray cluster to join (e.g. auto or "
                         "HOST:6379); its nodes need this package installed")
    ap.add_argument("--ray-cpus", type=float, default=1.0,
                    help="with --ray: CPUs Ray reserves per seed's task (default 1)")
    ap.add_argument("--hyperparams", default=str(HYPERPARAMS_FILE),
                    help="RL Zoo yml file with the PPO hyper-parameters (entry "
                         f"{ENV_ID}; default the shipped agents/hyperparams/ppo.yml)")
    ap.add_argument("--n-envs", type=int, default=None, help="parallel envs (default: cores)")
    ap.add_argument("--vec", choices=("subproc", "dummy"), default="subproc")
    ap.add_argument("--tensorboard", default=None, help="TensorBoard log directory (optional)")
    ap.add_argument("--checkpoint-every", type=int, default=100_000, help="env steps; 0 = off")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    ap.add_argument("--du-max", type=float, default=0.0,
                    help="policy commands the acceleration increment per step (x du_max a_max; "
                         "agents.wrappers.AccelerationIncrement, e.g. 0.1; default 0 = the "
                         "policy commands the acceleration itself)")
    ap.add_argument("--random-start", type=float, default=None,
                    help="fraction of training episodes started at a random piston length "
                         "(agents.wrappers.RandomStart; default 0.5, with --residual 0)")
    ap.add_argument("--residual", default="cubic", metavar="SCHEDULE",
                    help="the policy is a residual on this scripted schedule with tracking "
                         "feedback (agents.wrappers.ResidualOnSchedule; default cubic, the "
                         "paper's); 'none': the policy commands the acceleration from scratch")
    ap.add_argument("--residual-scale", type=float, default=0.25,
                    help="residual authority as a fraction of a_max (default 0.25)")
    ap.add_argument("--residual-omega", type=float, default=1.0,
                    help="tracking-feedback frequency, rad/s (default 1)")
    ap.add_argument("--residual-track-weight", type=float, default=1.0,
                    help="training-reward weight of (deviation from the schedule / 1 cm)^2 per "
                         "s (default 1)")
    ap.add_argument("--action-repeat", type=int, default=1,
                    help="hold each policy action for K env steps (agents.wrappers.ActionRepeat; "
                         "control period K x 0.05 s; default 1)")
    ap.add_argument("--obs-offset", type=float, default=0.0,
                    help="random constant offset (m) of the observed tip deflection per "
                         "episode, drawn from [-X, X] (agents.wrappers.DeflectionOffset; "
                         "default 0: no offsets; e.g. 0.005)")
    ap.add_argument("--env-set", action="append", default=[], metavar="KEY=VALUE",
                    help="training-env constructor argument (replaces the defaults "
                         f"{TRAIN_ENV_KWARGS}); repeatable")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a PPO hyper-parameter (e.g. --set use_sde=True); repeatable")
    args = ap.parse_args(argv)

    def literal_pairs(items, flag):
        import ast
        out = {}
        for kv in items:
            k, _, v = kv.partition("=")
            try:
                out[k] = ast.literal_eval(v)
            except (ValueError, SyntaxError):
                ap.error(f"{flag} {kv}: value must be a Python literal")
        return out
    over = literal_pairs(args.set, "--set")
    if args.timesteps < 1:
        ap.error(f"--timesteps = {args.timesteps}: allowed >= 1")
    if args.n_envs is not None and args.n_envs < 1:
        ap.error(f"--n-envs = {args.n_envs}: allowed >= 1")
    pol = {k: over.pop(k) for k in list(over) if k in ("log_std_init", "net_arch")}
    env_kwargs = literal_pairs(args.env_set, "--env-set") if args.env_set else None
    if args.residual == "none":
        args.residual = None
    if args.address and not args.ray:
        ap.error("--address needs --ray")
    if args.ray and args.seeds is None:
        ap.error("--ray needs --seeds")
    if args.ray_cpus <= 0:
        ap.error(f"--ray-cpus = {args.ray_cpus}: allowed > 0")
    if not Path(args.hyperparams).is_file():
        ap.error(f"--hyperparams {args.hyperparams}: file not found")
    kwargs = dict(timesteps=args.timesteps, n_envs=args.n_envs, vec=args.vec,
                  tensorboard=args.tensorboard, checkpoint_every=args.checkpoint_every,
                  progress=not args.no_progress, hyper_overrides=over, policy_overrides=pol,
                  du_max=args.du_max, env_kwargs=env_kwargs,
                  random_start=(args.random_start if args.random_start is not None
                                else 0.0 if args.residual else 0.5),
                  action_repeat=args.action_repeat, residual=args.residual,
                  residual_scale=args.residual_scale, residual_omega=args.residual_omega,
                  residual_w_track=args.residual_track_weight,
                  obs_offset=args.obs_offset,
                  hyperparams=load_hyperparams(args.hyperparams))
    if args.seeds is not None:
        if len(set(args.seeds)) != len(args.seeds):
            ap.error(f"--seeds {args.seeds}: each seed once")
        out = Path(args.out or "agents/runs")
        for path in train_seeds(args.seeds, out, use_ray=args.ray, address=args.address,
                                ray_cpus=args.ray_cpus, **kwargs):
            print(f"saved {path}")
        from . import report
        report.main(["--runs", *(str(out / f"seed{s}") for s in args.seeds), "--out", str(out)])
        return 0
    path = train(seed=args.seed, out=args.out or f"agents/runs/seed{args.seed}", **kwargs)
    print(f"saved {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
