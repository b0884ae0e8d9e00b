"""boom_env speed: env steps per second and real-time factor (simulated s per wall s).

    OPENBLAS_NUM_THREADS=1 python benchmarks/env_speed.py [--paper-steps 100]

    OPENBLAS_NUM_THREADS=1 python benchmarks/env_speed.py --only vec-async-4 --vec-steps 2000

Writes benchmarks/results/env_speed.md with the machine state (:func:`_machine.machine_lines`:
each core's busy share during the run, load average, commit).  Run it unpinned on an idle
machine: the async vector envs put one worker process on each core.  Cases: fidelity "rl"
(modal ROM, one process), vector envs of 2 and 4 copies (gym.make_vec, "sync": one process
steps them in turn, "async": one worker process each), and "paper" (the full sim_core model,
``paper_n_nodes`` 3, frictionless: the env's defaults), its first reset (the static
equilibrium of the full model) timed separately from its steps, once in this process (both
cores: the element worker thread may take the second) and once in a child process pinned to
core 0 (one core per env, as in a vector env with one process per core).  Random actions (uniform in
[-1, 1], seeded); episodes are reset when they end (the vector envs reset their sub-envs
themselves).  ``--only CASE`` runs one case, prints its row and writes nothing: for timing
whole processes from outside.  The numbers are wall-clock.
"""

from __future__ import annotations

import argparse
import ast
import os
import subprocess
import sys
import time

import gymnasium as gym
import numpy as np

_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.abspath(os.path.join(_HERE, "..")))
sys.path.insert(0, _HERE)

import boom_env  # noqa: E402, F401
from _machine import cpu_times, machine_lines, write_markdown  # noqa: E402

OUT = os.path.join(_HERE, "results", "env_speed.md")

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


def bench_vector(n_envs: int, n_steps: int, mode: str = "async", seed: int = 0):
    """Steps/s and real-time factor of gym.make_vec(n_envs, mode) over n_steps batch steps
    (n_steps * n_envs env steps); the vector env's construction and reset are not timed."""
    venv = gym.make_vec(ENV_ID, num_envs=n_envs, vectorization_mode=mode)
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


CASES = ("rl", "vec-sync-2", "vec-async-2", "vec-sync-4", "vec-async-4", "paper",
         "paper-core0")


def run_case(case: str, a) -> tuple:
    """(case label, workers, env steps, env steps/s, real-time factor, reset) of one case."""
    if case == "rl":
        sps, rtf, tr = bench_single("rl", a.rl_steps)
        return ("rl (modal ROM, 3 modes)", "1 process", a.rl_steps, sps, rtf, f"{tr * 1e3:.1f} ms")
    if case == "paper-core0":           # the same in a child process pinned to core 0
        out = subprocess.run(
            [sys.executable, os.path.abspath(__file__), "--only", "paper", "--paper-steps",
             str(a.paper_steps)], capture_output=True, text=True, check=True,
            preexec_fn=lambda: os.sched_setaffinity(0, {0}))
        row = ast.literal_eval(out.stdout.strip().splitlines()[-1])
        return (row[0] + ", pinned to core 0", *row[1:])
    if case == "paper":
        sps, rtf, tr = bench_single("paper", a.paper_steps)
        return ("paper (full model, n_nodes 3, frictionless)", "1 process", a.paper_steps, sps,
                rtf, f"{tr:.2f} s")
    _, mode, n = case.split("-")
    n = int(n)
    sps, rtf = bench_vector(n, a.vec_steps, mode)
    workers = "1 process" if mode == "sync" else f"{n} worker processes"
    return (f"rl, gym.make_vec {mode}, {n} envs", workers, a.vec_steps * n, sps, rtf, "-")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rl-steps", type=int, default=6000)
    ap.add_argument("--vec-steps", type=int, default=2000, help="batch steps per vector case")
    ap.add_argument("--paper-steps", type=int, default=100)
    ap.add_argument("--only", choices=CASES, help="run this case only; print, write nothing")
    ap.add_argument("--out", default=OUT)
    a = ap.parse_args()
    for name in ("rl_steps", "vec_steps", "paper_steps"):
        if getattr(a, name) < 1:
            ap.error(f"--{name.replace('_', '-')} = {getattr(a, name)}: allowed >= 1")
    if a.only:
        print(run_case(a.only, a))
        return
    cpu0, load0 = cpu_times(), os.getloadavg()
    rows = []
    for case in CASES:
        rows.append(run_case(case, a))
        print(rows[-1])
    cpu1, load1 = cpu_times(), os.getloadavg()
    lines = ["# boom_env speed", "",
             "Written by `benchmarks/env_speed.py` (its docstring describes the cases).  Control "
             "step dt = 0.05 s, random actions; real-time factor = simulated time / wall time; "
             f"gymnasium {gym.__version__}.", "", "Machine:", "",
             *machine_lines(cpu0, cpu1, load0, load1), "",
             "| case | workers | env steps | env steps/s | real-time factor | first reset |",
             "| --- | --- | --- | --- | --- | --- |"]
    for name, w, n, sps, rtf, tr in rows:
        lines.append(f"| {name} | {w} | {n} | {sps:.1f} | {rtf:.3g} | {tr} |")
    by = {r[0]: r[3] for r in rows}
    ratios = []
    for n in (2, 4):
        sync, asyn = (by[f"rl, gym.make_vec {m}, {n} envs"] for m in ("sync", "async"))
        ratios.append(f"{n} envs {sync / asyn:.2f}")
    lines += ["", "The `paper` row's reset solves the static equilibrium of the full model; its "
              "steps are timed after it.  Vector envs, sync / async steps per second: "
              f"{', '.join(ratios)}.", ""]
    write_markdown(a.out, lines)


if __name__ == "__main__":
    main()
