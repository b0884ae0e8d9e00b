"""A sweep and the vector envs under load: both finish, with the results of a run without the
load, and nothing deadlocks.

One command (repository root), a few minutes on the 2-core machine:

    PYTHONPATH=. python benchmarks/fault_load.py

Workloads, each run in a child process under a wall-clock timeout (a deadlock is a timeout,
reported as such, never a hang of this script):

* ``sweep``: ``boom-sim sweep`` of 8 cases of ``beam_through_sleeve`` (0.05 s simulated,
  without the stress filter, 5 nodes: ~1-2 s of solving each; tip force 250/500/1000/2000 N
  x E 1.5e11/2.1e11 Pa) on a local Ray with 2 workers, checkpoints every second
  (``--checkpoint-every 1``, so that checkpoint writes happen under load too).  Correct: every
  case ``ok`` and every output array of every case equal (bit for bit) to the sweep's without
  the hog.
* ``env``: ``gymnasium.make_vec("boom_env/TelescopicExtraction-v0", num_envs=8,
  vectorization_mode="async")`` (8 worker processes on the 2 cores), reset with seed 0 and
  stepped 300 times with the same seeded random actions; each ``step_wait`` has a 120 s
  timeout.  Correct: the observations, rewards and episode ends of all 300 steps equal (bit
  for bit) to the ``"sync"`` vector env's (one process) on the same actions.

Each workload runs twice: without, and with a CPU hog (``python -c "while True: pass"``,
pinned to core 0 with ``taskset -c 0``) occupying a core.  Slow-down = wall(with the hog) /
wall(without), each wall time of the child process (Ray's start and the imports included).
Each core's busy share during each run and the load average at its start are recorded
(:func:`_machine.cpu_times`): the machine may be shared with other work, which the table
states.

Writes benchmarks/results/fault_load.md (atomically).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

_HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(_HERE, ".."))
sys.path.insert(0, ROOT)
sys.path.insert(0, _HERE)

from _machine import cpu_times, machine_lines, write_markdown  # noqa: E402

OUT = os.path.join(_HERE, "results", "fault_load.md")
ENV_ID = "boom_env/TelescopicExtraction-v0"
N_ENVS, N_STEPS = 8, 300
SWEEP = ["beam_through_sleeve",
         "--grid", "point_loads.0.force=[0, 0, -250],[0, 0, -500],[0, 0, -1000],[0, 0, -2000]",
         "--grid", "beams.0.section.E=1.5e11,2.1e11",
         "--set", "solver.t_end=0.05", "--set", "effects.filtering=false",
         "--set", "beams.0.n_nodes=5", "--set", "solver.n_output=11"]
TIMEOUT_S = {"sweep": 900.0, "env": 900.0}


# -- the children --------------------------------------------------------------------------------

def child_env(mode: str, out: str) -> None:
    """Step the vector env (``mode``) and save observations, rewards and episode ends."""
    import gymnasium as gym
    import numpy as np

    import boom_env  # noqa: F401
    venv = gym.make_vec(ENV_ID, num_envs=N_ENVS, vectorization_mode=mode)
    rng = np.random.default_rng(0)
    obs, _ = venv.reset(seed=0)
    O, R, E = [obs], [], []
    for _ in range(N_STEPS):
        a = rng.uniform(-1, 1, (N_ENVS, 1)).astype(np.float32)
        if mode == "async":
            venv.step_async(a)
            obs, rew, term, trunc, _ = venv.step_wait(timeout=120)
        else:
            obs, rew, term, trunc, _ = venv.step(a)
        O.append(obs)
        R.append(rew)
        E.append(np.logical_or(term, trunc))
    venv.close()
    np.savez(out, obs=np.array(O), rew=np.array(R), ends=np.array(E))


def run_child(args: list[str], timeout: float) -> tuple[float, str, dict, dict]:
    """(wall s, status 'ok' / 'timeout (deadlock?)' / 'exit N', cpu_times before, after);
    the 1-min load average at the start is appended to the busy shares' record."""
    c0 = cpu_times()
    c0["load"] = os.getloadavg()[0]
    t0 = time.perf_counter()
    env = dict(os.environ, PYTHONPATH=ROOT, MPLBACKEND="Agg")
    try:
        r = subprocess.run(args, cwd=ROOT, env=env, capture_output=True, text=True,
                           timeout=timeout)
        status = "ok" if r.returncode == 0 else f"exit {r.returncode}: {r.stderr[-500:]}"
    except subprocess.TimeoutExpired:
        status = f"timeout after {timeout:g} s (deadlock?)"
    return time.perf_counter() - t0, status, c0, cpu_times()


def busy(c0: dict, c1: dict) -> str:
    return ", ".join(f"core {c} {100 * (c1[c][0] - c0[c][0]) / max(c1[c][1] - c0[c][1], 1):.0f} %"
                     for c in sorted(c1) if c in c0) + f"; load {c0['load']:.1f}"


# -- comparisons -------------------------------------------------------------------------------

def same_sweep(a: str, b: str) -> tuple[bool, str]:
    """Every case ok in both and every output array equal."""
    import numpy as np

    from sim_core.result import Result
    cases = sorted(d for d in os.listdir(a) if not d.startswith(".")
                   and os.path.isdir(os.path.join(a, d)))
    if len(cases) != 8:
        return False, f"{len(cases)} case folders in {a}"
    for d in cases:
        for top in (a, b):
            s = json.load(open(os.path.join(top, d, "summary.json")))
            if s["status"] != "ok":
                return False, f"{d}: {s['status']} {s.get('error')}"
        ra, rb = (Result.load(os.path.join(top, d, "result.npz")) for top in (a, b))
        if not np.array_equal(ra.t, rb.t):
            return False, f"{d}: output times differ"
        for k in ra.keys():
            if not np.array_equal(np.asarray(ra[k]), np.asarray(rb[k]), equal_nan=True):
                return False, f"{d}: {k} differs"
    return True, "8 ok, every output equal"


def same_env(a: str, b: str) -> tuple[bool, str]:
    import numpy as np
    x, y = np.load(a), np.load(b)
    for k in ("obs", "rew", "ends"):
        if x[k].shape != y[k].shape or not np.array_equal(x[k], y[k]):
            return False, f"{k} differs"
    return True, f"{N_STEPS} steps x {N_ENVS} envs: observations, rewards, ends equal"


# -- main ----------------------------------------------------------------------------------------

def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--child-env", choices=("sync", "async"), help=argparse.SUPPRESS)
    ap.add_argument("--child-out", help=argparse.SUPPRESS)
    ap.add_argument("--note", default="", help="a line on the machine state for the report")
    args = ap.parse_args(argv)
    if args.child_env:
        child_env(args.child_env, args.child_out)
        return 0

    tmp = tempfile.mkdtemp(prefix="fault_load_")
    py = sys.executable
    sweep = [py, "-m", "sim_core.cli", "sweep", *SWEEP, "--workers", "2", "--quiet",
             "--checkpoint-every", "1"]
    env = [py, os.path.abspath(__file__), "--child-env"]
    load0 = os.getloadavg()
    all0 = cpu_times()
    rows = []
    # the reference of the env: the sync vector env, without the hog
    ref_wall, ref_status, c0, c1 = run_child(env + ["sync", "--child-out",
                                                    f"{tmp}/env_sync.npz"], TIMEOUT_S["env"])
    rows.append(("env, gym.make_vec sync (reference)", "no", ref_wall, ref_status,
                 busy(c0, c1), "-"))
    walls = {}
    for loaded in (False, True):
        hog = None
        if loaded:
            hog = subprocess.Popen(["taskset", "-c", "0", py, "-c", "while True: pass"])
            time.sleep(1.0)
        try:
            tag = "loaded" if loaded else "unloaded"
            w, st, c0, c1 = run_child(sweep + ["--out", f"{tmp}/sweep_{tag}"], TIMEOUT_S["sweep"])
            ok = same_sweep(f"{tmp}/sweep_unloaded", f"{tmp}/sweep_{tag}") if st == "ok" \
                else (False, st)
            if ok[0] and not loaded:
                ok = (True, "8 ok (the reference)")
            walls[("sweep", loaded)] = w
            rows.append(("sweep, 8 cases, 2 Ray workers", "core 0" if loaded
                         else "no", w, st, busy(c0, c1),
                         ("equal to the run without the hog: " if loaded else "") + ok[1]
                         if ok[0] else "WRONG: " + ok[1]))
            w, st, c0, c1 = run_child(env + ["async", "--child-out", f"{tmp}/env_{tag}.npz"],
                                      TIMEOUT_S["env"])
            ok = same_env(f"{tmp}/env_sync.npz", f"{tmp}/env_{tag}.npz") \
                if st == "ok" and ref_status == "ok" else (False, st)
            walls[("env", loaded)] = w
            rows.append((f"env, gym.make_vec async, {N_ENVS} envs", "core 0" if loaded
                         else "no", w, st, busy(c0, c1),
                         ("equal to sync: " + ok[1]) if ok[0] else "WRONG: " + ok[1]))
        finally:
            if hog is not None:
                hog.kill()
                hog.wait()
    all1 = cpu_times()
    load1 = os.getloadavg()
    shutil.rmtree(tmp, ignore_errors=True)

    lines = ["# A sweep and the vector envs under load",
             "",
             "Written by `benchmarks/fault_load.py` (its docstring describes the workloads).  "
             "Each workload runs in a child process under a wall-clock timeout; hog: a CPU "
             "hog (`python -c \"while True: pass\"`, `taskset -c 0`) occupies core 0, or "
             "not.  Wall time of the child process (imports, Ray's start and stop included); "
             "the busy share of each core is measured over that child's run (this workload, "
             "the hog and anything else on the machine) and the 1-min load average at its "
             "start: where other work shares the machine, the runs without the hog are "
             "loaded too, and the slow-down understates the hog's own effect.",
             "",
             "Machine (over the whole benchmark):",
             ""]
    lines += machine_lines(all0, all1, load0, load1)
    if args.note:
        lines.append(f"- note: {args.note}")
    lines += ["",
              "| workload | hog | wall s | finished | busy share of each core; load average "
              "| result |",
              "| --- | --- | --- | --- | --- | --- |"]
    for name, load, w, st, b, res in rows:
        lines.append(f"| {name} | {load} | {w:.1f} | {st} | {b} | {res} |")
    lines.append("")
    for what in ("sweep", "env"):
        if (what, False) in walls and (what, True) in walls:
            lines.append(f"Slow-down with the CPU hog, {what} (wall with / without): "
                         f"{walls[(what, True)] / walls[(what, False)]:.2f} x "
                         f"({walls[(what, False)]:.1f} -> {walls[(what, True)]:.1f} s).")
    write_markdown(OUT, lines)
    print("\n".join(lines[-(len(rows) + 5):]))
    bad = [r for r in rows if r[3] != "ok" or r[5].startswith("WRONG")]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
