"""Learning curves of several PPO training runs (3 seeds) and the comparison table.

    python -m agents.report --runs agents/runs/seed0 agents/runs/seed1 agents/runs/seed2 \
        --eval agents/results/evaluation.json --out agents/results

writes ``learning_curve.png`` (mean episode return of the stochastic training policy vs
environment steps, one line per seed, and the cubic schedule's return in the same env as a
reference line) and ``comparison.md`` (the evaluation JSON as a table, plus the final training
returns per seed and their spread).
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

from sim_core.figures import save_figure

from .evaluate import atomic_write_text

COLUMNS = (("time_to_target_s", "time to target (s)", "{:.2f}"),
           ("final_stroke_error_m", "final stroke error (mm)", "{:.2f}", 1e3),
           ("residual_tip_rms_m", "residual tip RMS, 4 s after stop (mm)", "{:.3f}", 1e3),
           ("tip_rms_16_20_m", "tip RMS 16-20 s (mm)", "{:.3f}", 1e3),
           ("peak_tip_deflection_m", "peak tip deflection (mm)", "{:.2f}", 1e3),
           ("peak_telescopic_force_N", "peak telescopic force (kN)", "{:.1f}", 1e-3),
           ("episode_return", "env return (30 s)", "{:.1f}"))


def read_curve(run: Path) -> np.ndarray:
    with open(run / "learning_curve.csv") as f:
        rows = list(csv.reader(f))[1:]
    if not rows:
        raise ValueError(f"{run / 'learning_curve.csv'}: no finished episode (train for more "
                         "than one episode, 600 env steps per env)")
    return np.array([[float(x) for x in r] for r in rows])


def cubic_training_return(env_kwargs: dict | None = None) -> float:
    """Return of the paper's cubic schedule from 2 m in the *training* env (the registered env
    with the run's env arguments, default agents.settings.TRAIN_ENV_KWARGS; reward scale 1
    unless they set it, as agents.train_ppo.train trains).  Runs with random
    start strokes (agents.wrappers.RandomStart) are not strictly comparable with it; for a
    residual run it is the return of the residual policy's u = 0."""
    import gymnasium as gym

    import boom_env  # noqa: F401

    from .evaluate import ENV_ID, run_episode, scripted_policy
    from .schedules import cubic
    from .settings import TRAIN_ENV_KWARGS
    env = gym.make(ENV_ID, **{"reward_scale": 1.0,
                              **(TRAIN_ENV_KWARGS if env_kwargs is None else env_kwargs)})
    u = env.unwrapped
    pol = scripted_policy(cubic(), u.dt, u.a_max, int(round(u.t_max / u.dt)))
    return run_episode(env, pol, 0).total_return


def table(res: dict) -> str:
    head = "| controller | " + " | ".join(c[1] for c in COLUMNS) + " |"
    lines = [head, "|" + " --- |" * (len(COLUMNS) + 1)]
    for name, m in res.items():
        cells = []
        for c in COLUMNS:
            v = m.get(c[0])
            cells.append("never" if v is None else c[2].format(v * (c[3] if len(c) > 3 else 1)))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m agents.report")
    ap.add_argument("--runs", nargs="+", required=True, help="training run directories")
    ap.add_argument("--eval", help="evaluation JSON of agents.evaluate --out")
    ap.add_argument("--out", default="agents/results")
    ap.add_argument("--title", default="PPO on boom_env/TelescopicExtraction-v0")
    ap.add_argument("--figure", default="learning_curve.png", help="file name in --out")
    ap.add_argument("--table", default="comparison.md", help="file name in --out")
    args = ap.parse_args(argv)
    out = Path(args.out)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    finals = []
    for run in map(Path, args.runs):
        c = read_curve(run)
        ax.plot(c[:, 0], c[:, 2], lw=1.2, label=run.name)
        finals.append((run.name, c[-1, 0], c[-1, 2], c[-1, 3]))
    meta_path = Path(args.runs[0]) / "model_meta.json"
    meta = json.loads(meta_path.read_text()) if meta_path.exists() else {}
    ref = cubic_training_return(meta.get("env_kwargs"))
    random_start = float(meta.get("random_start") or 0.0)
    ax.axhline(ref, color="k", ls="--", lw=1, label=f"cubic schedule from 2 m, training env ({ref:.0f})")
    lo = min(ref, min(f[2] for f in finals))
    ax.set_ylim(lo - 0.5 * abs(lo), max(ref, max(f[2] for f in finals)) + 0.2 * abs(lo))
    ax.set_xlabel("environment steps")
    ax.set_ylabel("mean episode return (last 20)")
    ax.set_title(args.title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, out / args.figure)
    plt.close(fig)
    md = ["# PPO baseline vs scripted schedules", ""]
    if args.eval:
        md += [table(json.loads(Path(args.eval).read_text())), ""]
    r = np.array([f[2] for f in finals])
    md += ["Training runs (stochastic policy, mean return of the last 20 episodes):", "",
           "| run | env steps | mean return | success rate |", "| --- | --- | --- | --- |"]
    md += [f"| {n} | {int(s)} | {ret:.1f} | {sr:.2f} |" for n, s, ret, sr in finals]
    md += ["", f"Spread over the runs: mean {r.mean():.1f}, std {r.std(ddof=1) if len(r) > 1 else 0:.1f}; "
           f"cubic schedule from 2 m in the training env: {ref:.1f}"
           + (f" (a fraction {random_start:g} of the training episodes starts at a random "
              "stroke, so the curves are not strictly comparable with it)." if random_start
              else "."), ""]
    atomic_write_text(out / args.table, "\n".join(md))
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
