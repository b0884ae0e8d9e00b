"""Throughput of the v1 envs: the native vector env against a SyncVectorEnv of the scalar env.

    python benchmarks/vector_env_speed.py            # writes benchmarks/results/vector_env_speed.md
    python benchmarks/vector_env_speed.py --only native-1024     # one case, prints its row

The full run takes one to two minutes of one core; it pins itself (and its child, which runs
the cases) to core 0, as ``taskset -c 0`` would: run it as it is, on an idle machine for
figures to publish.  Every case reports env steps per second of wall time and per second of the
child's CPU time (``time.process_time``): on a busy machine the wall figure shrinks with the
share of core 0 the child gets, the CPU figure shows the cost of the code itself (it still
grows somewhat where other processes share the caches and memory bandwidth).

Cases: ``native-N`` is ``gym.make_vec("boom_env/TelescopicExtraction-v1", num_envs=N,
vectorization_mode="vector_entry_point")`` (boom_env.vector_env: one array call per step for all
N cranes), ``sync-N`` the same id with ``vectorization_mode="sync"`` (N scalar envs stepped in
turn by gymnasium.vector.SyncVectorEnv), for N = 1, 64, 1024, 4096.  Per-env payload, angle and
rope length are drawn at every reset (``payload_range``, ``angle_range``, ``rope_range``: each
reset forms that crane's coupled tables), the env's defaults otherwise (stroke friction on);
actions uniform in [-1, 1] (pre-drawn, seeded);
episodes of 600 steps end and autoreset inside the timed loop (every case runs at least one
full episode per env where its step count allows, the sync cases with N >= 1024 a part of one:
their per-step cost does not depend on it).  Timed: the step loop; the first reset (which forms
the tables of all N cranes) is timed separately.  In these cases all episodes start together
and so end together: the autoresets of a step come in one call for all N.
``staggered-N`` is ``native-N`` with the episodes spread evenly over the 600 steps before the
timed loop (``reset`` with ``options["reset_mask"]``), as in training once episodes end at
different times: about N / 600 cranes reset at every step, one call per step.
``nofriction-N`` is ``native-N`` with ``friction=False``: what the stick-slip stroke costs.

The cases run in one child process, one after the other, after a warm-up of each case; the
parent records the machine state (:mod:`_machine`) over the child's run and writes the table
atomically.
"""

from __future__ import annotations

import argparse
import ast
import os
import subprocess
import sys
import time

import numpy as np

_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.abspath(os.path.join(_HERE, "..")))
sys.path.insert(0, _HERE)

from _machine import cpu_times, machine_lines, write_markdown  # noqa: E402

OUT = os.path.join(_HERE, "results", "vector_env_speed.md")
ENV_ID = "boom_env/TelescopicExtraction-v1"
RANDOM = dict(payload_range=(20e3, 30e3), angle_range=(45.0, 75.0), rope_range=(1.0, 10.0))
SIZES = (1, 64, 1024, 4096)
# batch steps per case (timed): native enough for >= 1 s and >= 2 episodes where it is cheap;
# sync until ~10 s
STEPS = {("native", 1): 3000, ("native", 64): 1500, ("native", 1024): 1200,
         ("native", 4096): 1200, ("sync", 1): 3000, ("sync", 64): 100, ("sync", 1024): 8,
         ("sync", 4096): 3}
EPISODE = 600                         # steps of an episode (the registration's TimeLimit)
CASES = tuple(f"{kind}-{n}" for n in SIZES
              for kind in ("native", "sync", "staggered", "nofriction"))


def run_case(case: str, scale: float = 1.0, seed: int = 0):
    """(case, N, batch steps, env steps per wall second, first reset s, env steps per CPU
    second of this process) of one case, in this process."""
    import gymnasium as gym

    import boom_env  # noqa: F401
    kind, n = case.split("-")
    n = int(n)
    steps = max(2, int(STEPS[("sync" if kind == "sync" else "native", n)] * scale))
    mode = "sync" if kind == "sync" else "vector_entry_point"
    env = gym.make_vec(ENV_ID, num_envs=n, vectorization_mode=mode, **RANDOM,
                       friction=kind != "nofriction")
    rng = np.random.default_rng(seed)
    acts = rng.uniform(-1, 1, (steps, n, 1)).astype(np.float32)
    env.reset(seed=seed + 1)                          # warm-up (compiles, caches)
    for k in range(min(steps, 20)):
        env.step(acts[k])
    t0 = time.perf_counter()
    env.reset(seed=seed)
    t_reset = time.perf_counter() - t0
    if kind == "staggered":                        # crane i starts its episode at step i % 600
        start = np.arange(n) % EPISODE
        for k in range(EPISODE):
            env.step(acts[k % steps])
            mask = start == k
            if mask.any() and k > 0:
                env.reset(options={"reset_mask": mask})
    t0, c0 = time.perf_counter(), time.process_time()
    for k in range(steps):
        env.step(acts[k])
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    env.close()
    return (case, n, steps, steps * n / wall, t_reset, steps * n / cpu)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", choices=CASES, help="run this case here; print, write nothing")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--scale", type=float, default=1.0,
                    help="multiply every case's step count (default 1)")
    ap.add_argument("--out", default=OUT)
    a = ap.parse_args()
    if not a.scale > 0:
        ap.error(f"--scale = {a.scale}: allowed > 0")
    if a.only:
        print(run_case(a.only, a.scale))
        return
    if a.child:
        for case in CASES:
            print(run_case(case, a.scale), flush=True)
        return
    os.sched_setaffinity(0, {0})             # this process and the child: core 0 only
    cpu0, load0 = cpu_times(), os.getloadavg()
    out = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", "--scale",
                          str(a.scale)], capture_output=True, text=True, check=True)
    cpu1, load1 = cpu_times(), os.getloadavg()
    rows = [ast.literal_eval(line) for line in out.stdout.strip().splitlines()
            if line.startswith("(")]
    by = {(r[0].split("-")[0], r[1]): r for r in rows}
    import gymnasium as gym
    lines = ["# v1 vector env throughput", "",
             "Written by `benchmarks/vector_env_speed.py` (its docstring describes the cases).  "
             f"`{ENV_ID}`, control step 0.05 s, per-env randomised payload, luffing angle and "
             "rope length, random actions, autoresets inside the timed loop; all cases in one "
             f"process pinned to one core; gymnasium {gym.__version__}.", "",
             "Machine (the child process that ran the cases was pinned to core 0):", "",
             *machine_lines(cpu0, cpu1, load0, load1), "",
             "Env steps per second: of wall time, and of the child's CPU time (what the same "
             "run gets on a core of its own; the two agree on an idle machine).  native: "
             "all episodes end together (one autoreset call for all N cranes every 600 steps); "
             "staggered: the episodes spread over the 600 steps (about N / 600 autoresets at "
             "every step, as in training).", "",
             "| N envs | native, wall | native, CPU | staggered, CPU | native friction=False, "
             "CPU | SyncVectorEnv, wall | SyncVectorEnv, CPU | native / sync (CPU) | "
             "native first reset (s) | batch steps timed (native, sync) |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for n in SIZES:
        nat, syn = by[("native", n)], by[("sync", n)]
        stg, nof = by[("staggered", n)], by[("nofriction", n)]
        lines.append(f"| {n} | {nat[3]:.3g} | {nat[5]:.3g} | {stg[5]:.3g} | {nof[5]:.3g} | "
                     f"{syn[3]:.3g} | {syn[5]:.3g} | {nat[5] / syn[5]:.0f} | {nat[4]:.3g} | "
                     f"{nat[2]}, {syn[2]} |")
    lines += ["", "The first reset forms the coupled modal tables of every crane (the native "
              "env: one compiled call for all N).", ""]
    write_markdown(a.out, lines)


if __name__ == "__main__":
    main()
