"""Wall time of the paper's extraction scene alone and on a shared machine.

One command (repository root, an otherwise idle machine with at least two cores), ~3-5 min
with the defaults:

    python benchmarks/loaded_speed.py

Writes benchmarks/results/loaded_speed.md (atomically).  Each case runs the whole command

    boom-sim run telescopic_extraction --out <temporary folder> --quiet --no-plots

as a child process (``python -m sim_core.cli``, so the checkout's package is the one timed),
``--repeat`` times, and reports the median, min and max of

* ``wall``: the child's wall time, start-up (imports, compiled-code cache) included, s;
* ``RTF`` = simulated time / wall (the scene's 20 s unless ``--set solver.t_end=...``);
* ``cpu``: the child's user + system time (``os.wait4``), s: more than the wall where it runs
  two threads (the element worker), about the wall where it runs one;
* ``sim wall``: the integration's own wall time (summary.json ``wall_time_s``), and the
  summary's step count and the element worker's state at the end (``worker_in_use``,
  ``worker_stops``: sim_core.model.workers.Governor).

Cases:

* ``alone``: one copy, all the cores of this process's affinity set;
* ``pinned``: one copy on one core (``taskset -c <first core>``): the model sees one core and
  never starts the worker thread;
* ``pair``: two copies started together on the same cores (the wall of each copy);
* ``hog``: one copy next to a CPU-bound process (a Python busy loop) that runs for the whole
  copy (the situation the worker's governor is for);
* ``alone_off``: as ``alone`` with ``SIM_CORE_ELEMENT_WORKER=off`` (the calling-thread path:
  what the worker gains on an idle machine).

``--cases`` picks some (comma-separated); ``--set KEY=VALUE`` is passed to ``boom-sim run``
(e.g. ``--set solver.t_end=2`` for a quick check of the script).  The machine's state (cores,
affinity, load average before and after, CPU model, commit) heads the report: a load average
near or above the core count before the run means the figures are not those of an idle
machine.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, ROOT)

from benchmarks._machine import commit, cpu_model  # noqa: E402
from sim_core import load_scene  # noqa: E402
from sim_core.result import atomic_write_bytes  # noqa: E402

RESULTS = os.path.join(ROOT, "benchmarks", "results")
SCENE = "telescopic_extraction"
CASES = ("alone", "pinned", "pair", "hog", "alone_off")
HOG = "import time\nt = time.monotonic()\nwhile True:\n    pass\n"


def _command(out: str, sets: list[str]) -> list[str]:
    cmd = [sys.executable, "-m", "sim_core.cli", "run", SCENE, "--out", out, "--quiet",
           "--no-plots"]
    for s in sets:
        cmd += ["--set", s]
    return cmd


def _start(cmd: list[str], env: dict, cpus: str | None, log):
    if cpus is not None:
        cmd = ["taskset", "-c", cpus] + cmd
    return subprocess.Popen(cmd, env=env, cwd=ROOT, stdout=log, stderr=subprocess.STDOUT)


def _reap(proc, t0: float) -> dict:
    """Wait for proc; wall (s, from t0) and user + system time (s) of the child."""
    _, status, ru = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    return {"wall": wall, "cpu": ru.ru_utime + ru.ru_stime, "exit": proc.returncode}


def _summary(out: str) -> dict:
    try:
        with open(os.path.join(out, "summary.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def run_case(case: str, sets: list[str], cpus: list[int], logdir: str) -> list[dict]:
    """One repetition of a case: a row per copy of the simulation."""
    env = dict(os.environ)
    env.pop("SIM_CORE_ELEMENT_WORKER", None)
    if case == "alone_off":
        env["SIM_CORE_ELEMENT_WORKER"] = "off"
    pin = str(cpus[0]) if case == "pinned" else None
    copies = 2 if case == "pair" else 1
    outs = [tempfile.mkdtemp(prefix=f"loaded_speed_{case}_", dir=logdir) for _ in range(copies)]
    logs = [open(os.path.join(o, "stdout.txt"), "wb") for o in outs]
    hog = None
    try:
        if case == "hog":
            hog = subprocess.Popen([sys.executable, "-c", HOG], stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
            time.sleep(0.5)                 # the hog is running before the copy starts
        t0 = time.perf_counter()
        procs = [_start(_command(o, sets), env, pin, log) for o, log in zip(outs, logs)]
        rows = [_reap(p, t0) for p in procs]
    finally:
        if hog is not None:
            hog.kill()
            hog.wait()
        for log in logs:
            log.close()
    for row, o in zip(rows, outs):
        row["summary"] = _summary(o)
        if row["exit"] != 0:
            with open(os.path.join(o, "stdout.txt"), "rb") as f:
                row["message"] = f.read().decode(errors="replace").strip()[-300:]
    return rows


def _stats(values: list[float]) -> tuple[float, float, float]:
    return statistics.median(values), min(values), max(values)


def _machine() -> list[str]:
    aff = sorted(os.sched_getaffinity(0))
    return [f"- CPU: {cpu_model()}; {os.cpu_count()} logical processors, affinity {aff}",
            f"- Python {platform.python_version()}, {platform.platform()}",
            f"- commit {commit()}",
            f"- {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="runs per case (default 3)")
    ap.add_argument("--cases", default=",".join(CASES),
                    help=f"comma-separated subset of {', '.join(CASES)}")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="scene override passed to boom-sim run (e.g. solver.t_end=2)")
    ap.add_argument("--out", default=os.path.join(RESULTS, "loaded_speed.md"))
    args = ap.parse_args(argv)
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    bad = [c for c in cases if c not in CASES]
    if bad:
        ap.error(f"unknown case(s) {bad}: allowed {CASES}")
    if ("pinned" in cases) and shutil.which("taskset") is None:
        ap.error("taskset (util-linux) is needed for the pinned case")
    overrides = dict(s.split("=", 1) for s in args.set)
    t_end = float(load_scene(SCENE, overrides)["solver"]["t_end"])
    cpus = sorted(os.sched_getaffinity(0))
    load_before = os.getloadavg()
    logdir = tempfile.mkdtemp(prefix="loaded_speed_")
    results: dict[str, list[dict]] = {c: [] for c in cases}
    try:
        for k in range(args.repeat):
            for case in cases:
                rows = run_case(case, args.set, cpus, logdir)
                results[case].extend(rows)
                for r in rows:
                    print(f"{case:10s} run {k + 1}: wall {r['wall']:.2f} s, cpu {r['cpu']:.2f} s,"
                          f" exit {r['exit']}", flush=True)
    finally:
        shutil.rmtree(logdir, ignore_errors=True)
    load_after = os.getloadavg()

    lines = ["# Paper extraction scene alone and on a shared machine", "",
             f"`boom-sim run {SCENE} --quiet --no-plots`"
             + "".join(f" `--set {s}`" for s in args.set)
             + f" ({t_end:g} s simulated), {args.repeat} run(s) per case; "
             "median [min, max].  Written by benchmarks/loaded_speed.py (its docstring "
             "describes the cases and columns).", "",
             "Which figure is which: this table compares machine states (two cores, one "
             "core, beside other work) for one command at one commit; the time of every "
             "shipped scene on one core is `scene_speed.md`, each table gives its own commit "
             "and date, so compare rows within one table.", "",
             "Machine:", "", *_machine(),
             f"- load average (1, 5, 15 min) before: {load_before[0]:.2f}, {load_before[1]:.2f}, "
             f"{load_before[2]:.2f}; after: {load_after[0]:.2f}, {load_after[1]:.2f}, "
             f"{load_after[2]:.2f}", "",
             "| case | copies | wall s | RTF | cpu s | sim wall s | steps | worker in use / stops "
             "| exit |",
             "|---|---|---|---|---|---|---|---|---|"]
    for case in cases:
        rows = results[case]
        if not rows:
            continue
        w = _stats([r["wall"] for r in rows])
        c = _stats([r["cpu"] for r in rows])
        sims = [r["summary"].get("wall_time_s") for r in rows if r["summary"].get("wall_time_s")]
        steps = sorted({r["summary"].get("n_steps") for r in rows if r["summary"]})
        workers = sorted({f"{r['summary'].get('worker_in_use')} / "
                          f"{r['summary'].get('worker_stops')}" for r in rows if r["summary"]})
        sim = (f"{statistics.median(sims):.2f} [{min(sims):.2f}, {max(sims):.2f}]" if sims
               else "-")
        exits = sorted({r["exit"] for r in rows})
        lines.append(
            f"| {case} | {2 if case == 'pair' else 1} | {w[0]:.2f} [{w[1]:.2f}, {w[2]:.2f}] "
            f"| {t_end / w[0]:.3g} | {c[0]:.2f} [{c[1]:.2f}, {c[2]:.2f}] | {sim} "
            f"| {', '.join(str(s) for s in steps) or '-'} | {'; '.join(workers) or '-'} "
            f"| {', '.join(str(e) for e in exits)} |")
    failed = [(case, r) for case in cases for r in results[case] if r["exit"] != 0]
    if failed:
        lines += ["", "Failed runs:", ""]
        lines += [f"- {case}: exit {r['exit']}: {r.get('message', '')}" for case, r in failed]
    lines += ["", "RTF = simulated time / median wall time of the whole command (start-up "
              "included); `pair` lists each copy's wall time."]
    atomic_write_bytes(args.out, ("\n".join(lines) + "\n").encode())
    print(f"wrote {args.out}")
    return 0 if not failed else 1


if __name__ == "__main__":
    sys.exit(main())
