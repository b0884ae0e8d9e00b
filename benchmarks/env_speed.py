"""boom_env speed: env steps per second and real-time factor (simulated s per wall s).

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 python benchmarks/env_speed.py [--paper-steps 4]

Writes benchmarks/env_speed.md.  Cases: fidelity "rl" (modal ROM, one process), a vector env of
2 processes (gym.make_vec, async), and a short "paper" estimate (full sim_core model, n_nodes 3,
a few control steps; the static-equilibrium reset is timed separately).  Random actions
(uniform in [-1, 1], seeded); episodes are reset when they end.  The machine is shared: the
numbers are wall-clock and include whatever load other users put on it.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import boom_env  # noqa: F401

ENV_ID = "boom_env/TelescopicExtraction-v0"


def bench_single(fidelity: str, n_steps: int, seed: int = 0):
    env = gym.make(ENV_ID, fidelity=fidelity)
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    env.reset(seed=seed)
    t_reset = time.perf_counter() - t0
    dt = env.unwrapped.dt
    t0 = time.perf_counter()
    for _ in range(n_steps):
        _, _, term, trunc, _ = env.step(rng.uniform(-1, 1, 1).astype(np.float32))
        if term or trunc:
            env.reset()
    wall = time.perf_counter() - t0
    env.close()
    return n_steps / wall, n_steps * dt / wall, t_reset


def bench_vector(n_envs: int, n_steps: int, seed: int = 0):
    venv = gym.make_vec(ENV_ID, num_envs=n_envs, vectorization_mode="async")
    rng = np.random.default_rng(seed)
    venv.reset(seed=seed)
    dt = 0.05
    t0 = time.perf_counter()
    for _ in range(n_steps):
        venv.step(rng.uniform(-1, 1, (n_envs, 1)).astype(np.float32))
    wall = time.perf_counter() - t0
    venv.close()
    total = n_steps * n_envs
    return total / wall, total * dt / wall


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rl-steps", type=int, default=6000)
    ap.add_argument("--vec-steps", type=int, default=3000)
    ap.add_argument("--paper-steps", type=int, default=4)
    a = ap.parse_args()
    rows = []
    sps, rtf, tr = bench_single("rl", a.rl_steps)
    rows.append(("rl (modal ROM, 3 modes)", "1", a.rl_steps, sps, rtf, f"{tr * 1e3:.1f} ms"))
    print(rows[-1])
    sps, rtf = bench_vector(2, a.vec_steps)
    rows.append(("rl, gym.make_vec async", "2 processes", a.vec_steps * 2, sps, rtf, "-"))
    print(rows[-1])
    sps, rtf, tr = bench_single("paper", a.paper_steps)
    rows.append(("paper (full model, n_nodes 3)", "1", a.paper_steps, sps, rtf, f"{tr:.0f} s"))
    print(rows[-1])
    lines = ["# boom_env speed (benchmarks/env_speed.py)", "",
             f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores shared "
             f"with other users; Python {platform.python_version()}; "
             f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.  Control step dt = 0.05 s, "
             "random actions.  Real-time factor = simulated time / wall time.", "",
             "| case | workers | env steps | env steps/s | real-time factor | reset |",
             "| --- | --- | --- | --- | --- | --- |"]
    for name, w, n, sps, rtf, tr in rows:
        lines.append(f"| {name} | {w} | {n} | {sps:.1f} | {rtf:.3g} | {tr} |")
    lines += ["", "The `paper` row is an estimate from a few control steps after the reset "
              "(the reset solves the static equilibrium of the full model)."]
    out = Path(__file__).with_name("env_speed.md")
    out.write_text("\n".join(lines) + "\n")
    print(out.read_text())


if __name__ == "__main__":
    main()
