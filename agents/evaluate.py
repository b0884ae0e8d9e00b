"""Evaluate the scripted schedules and a trained PPO policy on the same env and seeds.

    python -m agents.evaluate --model agents/models/ppo_extraction.zip --episodes 3 --json

prints one JSON object {name: {metric: value}} (metrics averaged over the episodes; seeds
``seed, seed + 1, ...``) and writes a figure of stroke, stroke rate and tip deflection vs time
(first episode) for every controller.

Evaluation protocol (identical for every controller)
----------------------------------------------------
* Env: ``boom_env/TelescopicExtraction-v0`` (modal ROM of the full model, paper scene: 25 t,
  60 deg, L_s 2 -> 8 m, dt = 0.05 s, t_max = 30 s) with ``tol_deflection = 0``: the success
  termination is switched off so that every controller runs the whole 30 s and the vibration
  after the stop is observed; ``reward_scale = 1``: ``episode_return`` is in the env's
  unscaled reward units (the env's default scale 0.01 divides it by 100).  The PPO policy
  acts (deterministically) for the whole episode; a scripted schedule commands a = 0 after
  its end.
* ``time_to_target_s``: first time after which |L_s - L*| <= 1 cm for the rest of the episode.
* ``stop_time_s``: first time after which additionally |dL_s/dt| <= 5 mm/s (the env's speed
  tolerance) for the rest of the episode.
* ``final_stroke_error_m``: |L_s - L*| at the end of the episode (30 s).
* ``residual_tip_rms_m``: RMS of the tip deflection |d| (from the static tip at the current L_s)
  over the 4 s after ``stop_time_s`` (control-step samples).
* ``tip_rms_16_20_m``: RMS of |d| over the same fixed window for every controller, 16-20 s
  (the 4 s after the end of the paper's cubic schedule): controllers that keep moving after
  reaching the target (a policy damping the vibration actively) are then compared at the same
  time, not each after its own stop.  ``tip_oscillation_16_20_m``: the same window, deflection
  vector about its mean (see ``residual_tip_oscillation_m``).
* ``residual_tip_oscillation_m``: RMS of d - mean(d) (the deflection vector about its own mean)
  over the same window: the vibration alone.  It equals the residual RMS when the deflection
  reference is the model's own static tip (the modal ROM); with ``fidelity="paper"`` the
  env's reference (the tables' static tip change added to the full model's tip at reset)
  can be off by a constant (~0.1 mm at full extension with the current tables), and this
  metric is not affected by such an offset.
* ``peak_tip_deflection_m``: max |d| over the episode.
* ``peak_telescopic_force_N``: max |F| of the telescopic cylinder force, F = F_rigid + Gamma . q''
  (see :func:`telescopic_force`).
A controller that never stops gets ``null`` times and residuals over the last 4 s.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from .settings import ENV_ID

STROKE_TOL = 0.01        # m, "reaches the target" (issue: within 1 cm)
SPEED_TOL = 5e-3         # m/s, the env's tol_speed
RESIDUAL_WINDOW = 4.0    # s
FIXED_WINDOW = (16.0, 20.0)   # s, after the end of the paper's cubic schedule


@dataclass
class Trace:
    """Control-step samples of one episode (all arrays (n,), SI units)."""

    t: np.ndarray            # s, end of each step (t[0] = 0 is the reset state)
    stroke: np.ndarray       # m
    rate: np.ndarray         # m/s
    accel: np.ndarray        # m/s^2, applied during the step ending at t
    deflection: np.ndarray   # m, |d| of the tip from its static position at L_s
    force: np.ndarray        # N, telescopic cylinder force
    target: float            # m
    total_return: float
    deflection_xz: np.ndarray | None = None   # (n, 2) m, the deflection vector (dX, dZ)


def make_eval_env(**kwargs):
    """The evaluation env: the registered extraction env with success termination off and the
    unscaled reward (``reward_scale = 1``); ``kwargs`` override or add constructor arguments."""
    import gymnasium as gym

    import boom_env  # noqa: F401
    return gym.make(ENV_ID, **{"tol_deflection": 0.0, "reward_scale": 1.0, **kwargs})


def telescopic_force(env, a: float) -> float:
    """Telescopic-cylinder force (N) of the env's modal model after a step with acceleration a.

    F = m2 (a + g sin th) + 2 T_e with T_e = (m3 + m_p)(2 a + g sin th): the rigid-boom force of
    the inextensible rope drive (boom 3 moves twice the stroke, Zhao-Qi-Wang 2024 Eqs. 74-76;
    the boom masses of sim_core.rom.boom_masses), plus the elastic part Gamma . q'' of the modal
    coordinates:
    the kinetic energy of Q = Q_s(L_s) + Phi q has the cross term L_s' Gamma . q' (Gamma = Phi^T M
    dQ_s/dL_s, mass-normalised modes), whose Lagrange term along L_s is Gamma . q''.  The ROM is
    frictionless and drops the slow d Gamma/dt terms."""
    from sim_core.rom import boom_masses
    u = env.unwrapped
    if not hasattr(u, "_masses"):
        u._masses = list(boom_masses(3))
    m2, m3 = u._masses[1], u._masses[2]
    gs = 9.81 * math.sin(math.radians(u.angle))
    F_rigid = m2 * (a + gs) + 2.0 * (m3 + u.payload) * (2.0 * a + gs)
    rom = u.rom
    c = rom.tb.coefficients(rom.L)
    w, z, g, g2, b1, b2 = c[0], c[1], c[2], c[3], c[4], c[5]
    v = rom.v
    qdd = -g * a - (g2 - b2) * v * v + b1 * v - 2.0 * z * w * rom.qd - w * w * rom.q
    return float(F_rigid + g @ qdd)


def run_episode(env, policy: Callable[[np.ndarray, int], float], seed: int) -> Trace:
    """Run one full episode; ``policy(obs, k)`` returns the normalised action of step k."""
    obs, info = env.reset(seed=seed)
    u = env.unwrapped
    rom_force = u.fidelity == "rl"        # the force formula needs the ROM's modal state
    rows = [(0.0, info["stroke"], info["stroke_rate"], 0.0, 0.0,
             telescopic_force(env, 0.0) if rom_force else math.nan, 0.0, 0.0)]
    total, k = 0.0, 0
    while True:
        act = float(np.clip(policy(obs, k), -1.0, 1.0))
        obs, r, term, trunc, info = env.step(np.array([act], dtype=np.float32))
        total += r
        k += 1
        a = float(obs[2])
        rows.append((info["time"], info["stroke"], info["stroke_rate"], a,
                     float(np.hypot(*info["tip_deflection"])),
                     telescopic_force(env, a) if rom_force else math.nan,
                     *map(float, info["tip_deflection"])))
        if term or trunc:
            break
    arr = np.array(rows)
    return Trace(arr[:, 0], arr[:, 1], arr[:, 2], arr[:, 3], arr[:, 4], arr[:, 5],
                 float(u.L_target), float(total), arr[:, 6:8])


def _settle_time(t: np.ndarray, ok: np.ndarray) -> float | None:
    """First time after which ``ok`` holds for the rest of the samples (None if never)."""
    if not ok[-1]:
        return None
    bad = np.flatnonzero(~ok)
    return float(t[0] if len(bad) == 0 else t[min(bad[-1] + 1, len(t) - 1)])


def metrics(tr: Trace) -> dict:
    """The evaluation metrics of one episode (see the module docstring)."""
    err = np.abs(tr.stroke - tr.target)
    t_target = _settle_time(tr.t, err <= STROKE_TOL)
    t_stop = _settle_time(tr.t, (err <= STROKE_TOL) & (np.abs(tr.rate) <= SPEED_TOL))
    t0 = t_stop if t_stop is not None else tr.t[-1] - RESIDUAL_WINDOW
    win = (tr.t >= t0 - 1e-9) & (tr.t <= t0 + RESIDUAL_WINDOW + 1e-9)
    fixed = (tr.t >= FIXED_WINDOW[0] - 1e-9) & (tr.t <= FIXED_WINDOW[1] + 1e-9)
    return {"time_to_target_s": t_target,
            "stop_time_s": t_stop,
            "final_stroke_error_m": float(err[-1]),
            "residual_tip_rms_m": float(np.sqrt(np.mean(tr.deflection[win] ** 2))),
            "residual_tip_oscillation_m": _oscillation(tr, win),
            "residual_window_s": float(tr.t[win][-1] - tr.t[win][0]),
            "tip_rms_16_20_m": (float(np.sqrt(np.mean(tr.deflection[fixed] ** 2)))
                                if fixed.any() else None),
            "tip_oscillation_16_20_m": _oscillation(tr, fixed) if fixed.any() else None,
            "peak_tip_deflection_m": float(tr.deflection.max()),
            "peak_telescopic_force_N": (None if np.all(np.isnan(tr.force))
                                        else float(np.nanmax(np.abs(tr.force)))),
            "episode_return": tr.total_return}


def _oscillation(tr: Trace, win: np.ndarray) -> float | None:
    if tr.deflection_xz is None:
        return None
    d = tr.deflection_xz[win]
    return float(np.sqrt(np.mean(np.sum((d - d.mean(axis=0)) ** 2, axis=1))))


def mean_metrics(ms: list[dict]) -> dict:
    """Mean over episodes; a time is null if any episode never reached it."""
    out = {}
    for key in ms[0]:
        vals = [m[key] for m in ms]
        out[key] = None if any(v is None for v in vals) else float(np.mean(vals))
    out["episodes"] = len(ms)
    return out


def scripted_policy(schedule, dt: float, a_max: float, n_steps: int):
    acts = schedule.actions(dt, a_max, n_steps)
    return lambda obs, k: float(acts[k]) if k < len(acts) else 0.0


class PPOPolicy:
    """A saved SB3 PPO model with its VecNormalize observation statistics, acting
    deterministically on raw env observations."""

    def __init__(self, model_path: str | os.PathLike, vecnorm_path: str | os.PathLike | None = None,
                 a_max: float = 0.25):
        from stable_baselines3 import PPO

        from .model_io import load_sb3, load_vecnorm
        self.model = load_sb3(PPO, model_path, device="cpu")
        self.a_max = float(a_max)         # m/s^2, the env's (to undo the increment action)
        vecnorm_path = Path(vecnorm_path) if vecnorm_path else _vecnorm_for(Path(model_path))
        self.obs_rms, self.clip_obs, self.eps = None, 10.0, 1e-8
        meta = Path(model_path).with_name(Path(model_path).stem + "_meta.json")
        if not meta.exists():
            meta = Path(model_path).with_name("model_meta.json")
        self.du_max, self.repeat, self._held, self.residual = None, 1, 0.0, None
        if meta.exists():
            info = json.loads(meta.read_text())
            self.du_max = info.get("du_max")
            self.repeat = int(info.get("action_repeat") or 1)
            self.residual = info.get("residual")
        self.tracker = None
        if vecnorm_path.exists():
            vn = load_vecnorm(vecnorm_path)
            self.obs_rms, self.clip_obs, self.eps = vn.obs_rms, vn.clip_obs, vn.epsilon

    def bind(self, env) -> None:
        """Build the residual policy's base controller for ``env`` (its dt, a_max, t_max)."""
        if self.residual:
            from .schedules import by_name
            from .wrappers import ScheduleTracker
            self.tracker = ScheduleTracker.for_env(by_name(self.residual["schedule"]), env,
                                                   self.residual["scale"], self.residual["omega"])

    def __call__(self, obs: np.ndarray, k: int) -> float:
        if self.tracker is not None:       # agents.wrappers.ResidualOnSchedule
            if k == 0:
                self.tracker.reset(obs[0])
            return self.tracker.command(obs, k, self._act(self.tracker.augment(obs, k)))
        if k % self.repeat:                # agents.wrappers.ActionRepeat: zero-order hold
            return self._held
        self._held = self._act(obs)
        return self._held

    def _act(self, obs: np.ndarray) -> float:
        if self.residual and self.tracker is None:
            raise RuntimeError("residual policy: call bind(env) before acting")
        x = np.asarray(obs, dtype=np.float64)
        if self.obs_rms is not None:
            x = np.clip((x - self.obs_rms.mean) / np.sqrt(self.obs_rms.var + self.eps),
                        -self.clip_obs, self.clip_obs)
        act, _ = self.model.predict(x.astype(np.float32), deterministic=True)
        u = float(np.clip(np.asarray(act).reshape(-1)[0], -1.0, 1.0))
        if self.du_max:
            # agents.wrappers.AccelerationIncrement: the previous applied acceleration is obs[2]
            a_prev = float(obs[2]) / self.a_max
            return float(np.clip(a_prev + self.du_max * u, -1.0, 1.0))
        return u


def _vecnorm_for(model_path: Path) -> Path:
    from .model_io import vecnorm_path_for
    return vecnorm_path_for(model_path)



def evaluate(model: str | list | None = None, episodes: int = 1, seed: int = 0,
             payload_range: tuple[float, float] | None = None, fidelity: str = "rl",
             only: list[str] | None = None) -> tuple[dict, dict]:
    """Run every scripted schedule (and the PPO policy of every ``model`` path: "ppo" for one,
    "ppo_<label>" for several, label = the parent directory name) on seeds seed..seed+K-1.
    ``fidelity="paper"`` runs the env on the full sim_core model (slow; the telescopic force is
    then not computed); ``only`` restricts the controllers to these names.
    Returns ({name: mean metrics}, {name: first-episode Trace})."""
    from . import schedules as S
    kw = {"fidelity": fidelity}
    if payload_range:
        kw["payload_range"] = payload_range
    env = make_eval_env(**kw)
    u = env.unwrapped
    n_steps = int(round(u.t_max / u.dt))
    controllers: dict[str, Callable] = {}
    for s in S.all_schedules():
        controllers[s.name] = scripted_policy(s, u.dt, u.a_max, n_steps)
    models = [model] if isinstance(model, (str, os.PathLike)) else list(model or [])
    for mp in models:
        name = "ppo" if len(models) == 1 else f"ppo_{Path(mp).parent.name}"
        controllers[name] = PPOPolicy(mp, a_max=u.a_max)
        controllers[name].bind(env)
    if only:
        unknown = set(only) - set(controllers)
        if unknown:
            raise ValueError(f"only = {sorted(unknown)}: allowed {sorted(controllers)}")
        controllers = {k: v for k, v in controllers.items() if k in only}
    results, traces = {}, {}
    for name, pol in controllers.items():
        ms = []
        for i in range(episodes):
            if payload_range and name == "zv_trapezoid":
                # model-based shaper: retuned to the episode's payload (known to the operator)
                env.reset(seed=seed + i)
                zv = S.zv_trapezoid(payload=u.payload, angle_deg=u.angle)
                pol = scripted_policy(zv, u.dt, u.a_max, n_steps)
            tr = run_episode(env, pol, seed + i)
            ms.append(metrics(tr))
            if i == 0:
                traces[name] = tr
        results[name] = mean_metrics(ms)
    env.close()
    return results, traces


def save_traces(traces: dict, path) -> None:
    """Write {name: Trace} to an npz file (atomically)."""
    import io
    from dataclasses import asdict

    from sim_core.result import atomic_write_bytes
    arrays = {f"{name}/{k}": np.asarray(v) for name, tr in traces.items()
              for k, v in asdict(tr).items() if v is not None}
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    atomic_write_bytes(path, buf.getvalue())


def load_traces(path) -> dict:
    """{name: Trace} from a file of :func:`save_traces`."""
    out: dict = {}
    with np.load(path) as f:
        for key in f.files:
            name, field = key.rsplit("/", 1)
            out.setdefault(name, {})[field] = f[key]
    return {n: Trace(**{k: (float(v) if v.ndim == 0 else v) for k, v in d.items()})
            for n, d in out.items()}


def plot(traces: dict, path: str | os.PathLike, title: str | None = None) -> None:
    """Stroke, stroke rate and tip deflection vs time for every controller (one PNG)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sim_core.figures import save_figure
    fig, ax = plt.subplots(3, 1, figsize=(7.5, 7.5), sharex=True)
    for name, tr in traces.items():
        ax[0].plot(tr.t, tr.stroke, label=name)
        ax[1].plot(tr.t, tr.rate, label=name)
        ax[2].plot(tr.t, 1e3 * tr.deflection, label=name, lw=1)
    ax[0].set_ylabel("piston length L_s (m)")
    ax[1].set_ylabel("stroke rate (m/s)")
    ax[2].set_ylabel("tip deflection |d| (mm)")
    ax[2].set_xlabel("time (s)")
    ax[0].legend(loc="lower right", fontsize=8)
    for a in ax:
        a.grid(alpha=0.3)
    ax[0].set_title(title or "Extraction 2 -> 8 m, 25 t, 60 deg (boom_env modal ROM)", fontsize=9)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def atomic_write_text(path, text: str) -> None:
    from sim_core.result import atomic_write_bytes
    atomic_write_bytes(path, text.encode())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m agents.evaluate", description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", nargs="+", help="PPO model .zip (its *_vecnormalize.json beside "
                                               "it); several: one column each; omit to "
                                               "evaluate the scripted schedules only")
    ap.add_argument("--episodes", type=int, default=1, help="episodes per controller (seeds "
                                                            "seed .. seed+K-1), default 1")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--payload-range", type=float, nargs=2, metavar=("LO", "HI"),
                    help="randomise the payload (kg) per episode within the modal tables' range")
    ap.add_argument("--fidelity", choices=("rl", "paper"), default="rl",
                    help="env fidelity: rl (modal ROM, default) or paper (full model, slow)")
    ap.add_argument("--only", nargs="+", metavar="NAME",
                    help="evaluate only these controllers (e.g. cubic ppo)")
    ap.add_argument("--traces", help="also save the first episode's traces (npz) here; "
                                     "--plot-traces merges such files into one figure")
    ap.add_argument("--plot-traces", nargs="+", metavar="NPZ",
                    help="only plot saved traces (files of --traces) into --figure and exit")
    ap.add_argument("--title", default=None, help="figure title")
    ap.add_argument("--json", action="store_true", help="print the metrics as one JSON object")
    ap.add_argument("--out", help="also write the JSON here")
    ap.add_argument("--figure", default="agents/results/evaluation.png",
                    help="figure path (default agents/results/evaluation.png); '' for none")
    args = ap.parse_args(argv)
    if args.plot_traces:
        traces = {}
        for f in args.plot_traces:
            traces.update(load_traces(f))
        plot(traces, args.figure, args.title)
        return 0
    if args.episodes < 1:
        ap.error(f"--episodes = {args.episodes}: allowed >= 1")
    for mp in args.model or []:
        if not Path(mp).exists():
            ap.error(f"--model {mp}: file not found")
    res, traces = evaluate(args.model[0] if args.model and len(args.model) == 1 else args.model,
                           args.episodes, args.seed,
                           tuple(args.payload_range) if args.payload_range else None,
                           args.fidelity, args.only)
    text = json.dumps(res, indent=2)
    if args.out:
        atomic_write_text(args.out, text + "\n")
    if args.traces:
        save_traces(traces, args.traces)
    if args.figure:
        plot(traces, args.figure, args.title)
    if args.json:
        print(text)
    else:
        for name, m in res.items():
            print(f"{name:>14s}: " + ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
                                              for k, v in m.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
