"""boom_env speed: env steps per second and real-time factor (simulated s per wall s).

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 python benchmarks/env_speed.py [--paper-steps 20]

    PYTHONPATH=. OPENBLAS_NUM_THREADS=1 python benchmarks/env_speed.py --only vec-async-4 --vec-steps 2000

Writes benchmarks/env_speed.md.  Cases: fidelity "rl" (modal ROM, one process), vector envs of
2 and 4 copies (gym.make_vec, "sync": one process steps them in turn, "async": one worker
process each), and a short "paper" estimate (full sim_core model, n_nodes 3, a few control
steps; the static-equilibrium reset is timed separately).  Random actions (uniform in [-1, 1],
seeded); episodes are reset when they end (the vector envs reset their sub-envs themselves).
``--only CASE`` runs one case, prints its row and writes nothing: for timing whole processes
from outside.  ``--machine-state`` is the table's note on the machine's load ("side by side
with other work" unless measured on an idle machine); the 1-minute load average before and
after the run is recorded with it.  The numbers are wall-clock.  A "## Notes" section at the
end of env_speed.md (e.g. whole-process timings of ``--only`` runs) is kept when the table is
rewritten.
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


CASES = ("rl", "vec-sync-2", "vec-async-2", "vec-sync-4", "vec-async-4", "paper")


def run_case(case: str, a) -> tuple:
    """(case label, workers, env steps, env steps/s, real-time factor, reset) of one case."""
    if case == "rl":
        sps, rtf, tr = bench_single("rl", a.rl_steps)
        return ("rl (modal ROM, 3 modes)", "1 process", a.rl_steps, sps, rtf, f"{tr * 1e3:.1f} ms")
    if case == "paper":
        sps, rtf, tr = bench_single("paper", a.paper_steps)
        return ("paper (full model, n_nodes 3)", "1 process", a.paper_steps, sps, rtf, f"{tr:.0f} s")
    _, mode, n = case.split("-")
    n = int(n)
    sps, rtf = bench_vector(n, a.vec_steps, mode)
    workers = "1 process" if mode == "sync" else f"{n} worker processes"
    return (f"rl, gym.make_vec {mode}, {n} envs", workers, a.vec_steps * n, sps, rtf, "-")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rl-steps", type=int, default=6000)
    ap.add_argument("--vec-steps", type=int, default=2000, help="batch steps per vector case")
    ap.add_argument("--paper-steps", type=int, default=20)
    ap.add_argument("--only", choices=CASES, help="run this case only; print, write nothing")
    ap.add_argument("--machine-state", default="side by side with other work",
                    help="the table's note on the machine's load")
    a = ap.parse_args()
    for name in ("rl_steps", "vec_steps", "paper_steps"):
        if getattr(a, name) < 1:
            ap.error(f"--{name.replace('_', '-')} = {getattr(a, name)}: allowed >= 1")
    if a.only:
        print(run_case(a.only, a))
        return
    load0 = os.getloadavg()[0]
    rows = []
    for case in CASES:
        rows.append(run_case(case, a))
        print(rows[-1])
    load1 = os.getloadavg()[0]
    lines = ["# boom_env speed (benchmarks/env_speed.py)", "",
             f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
             f"{a.machine_state} (1-minute load average {load0:.1f} before, {load1:.1f} after); "
             f"Python {platform.python_version()}, gymnasium {gym.__version__}.  Control step "
             "dt = 0.05 s, random actions.  Real-time factor = simulated time / wall time.", "",
             "| case | workers | env steps | env steps/s | real-time factor | reset |",
             "| --- | --- | --- | --- | --- | --- |"]
    for name, w, n, sps, rtf, tr in rows:
        lines.append(f"| {name} | {w} | {n} | {sps:.1f} | {rtf:.3g} | {tr} |")
    by = {r[0]: r[3] for r in rows}
    ratios = []
    for n in (2, 4):
        sync, asyn = (by[f"rl, gym.make_vec {m}, {n} envs"] for m in ("sync", "async"))
        ratios.append(f"{n} envs {sync / asyn:.2f}")
    lines += ["", "The `paper` row is an estimate from a few control steps after the reset "
              "(the reset solves the static equilibrium of the full model).  "
              f"Vector envs, sync / async steps per second: {', '.join(ratios)}.", ""]
    out = Path(__file__).with_name("env_speed.md")
    notes = ""
    if out.exists():                      # hand-written notes below "## Notes" are kept
        old = out.read_text()
        if "\n## Notes" in old:
            notes = old[old.index("\n## Notes") + 1:]
    out.write_text("\n".join(lines) + "\n" + notes)
    print(out.read_text())


if __name__ == "__main__":
    main()
