"""Wall time of every shipped scene as a user runs it, pinned to one core.

One command writes the committed table (repository root, an otherwise idle machine; about
4 minutes per run of all scenes on one core):

    python benchmarks/scene_speed.py                    # every shipped scene, --runs 3
    python benchmarks/scene_speed.py --runs 1 --scenes telescopic_extraction_rl cantilever_release \
        --out /tmp/scene_speed.md                        # a subset, elsewhere

The script pins itself to core 0 (the machine state's busy shares then describe the timed
runs) and starts every run as

    OPENBLAS_NUM_THREADS=1 taskset -c 0 boom-sim run SCENE --out <tmpdir> --quiet --no-plots \
        [--no-report]

(``python -m sim_core.cli run ...``, the checkout's package): one core, so the model never
starts its element worker thread, and one BLAS thread.  The scenes take turns, ``--runs``
rounds.  Columns, median [min, max] over the runs:

* ``simulated s``: the scene's ``solver.t_end``; ``method``, ``DOF``: summary.json's ``method``
  and ``n_dof``;
* ``wall s``: the child process's wall time (``time.perf_counter`` around ``subprocess.run``):
  start-up (imports, the compiled-code cache), building the model and its static equilibrium,
  the integration and writing ``result.npz`` and ``summary.json``; neither the figures
  (``--no-plots``: they add 2-3 s to a crane run, ``benchmarks/results/user_crane_speed.md``)
  nor, where the command writes one, the report (``--no-report``);
* ``RTF``: simulated s / median wall s, the real-time factor of the whole command;
* ``cpu s``: the child's user + system time (``resource.getrusage(RUSAGE_CHILDREN)`` before
  and after); ``RTF on CPU``: simulated s / median cpu s, what the command runs at where it
  has the core to itself (on a machine shared with other jobs the wall time includes the
  time the core served them; the busy shares in the machine state say how much);
* ``steps``: summary.json's ``n_steps`` (the modal scenes report none).

The first run after installing compiles the numba kernels (~20-30 s, cached on disk), so
before the timed rounds each scene runs once untimed for ``--warmup`` simulated seconds
(default 0.5 s; 0 skips it), which loads or compiles its kernels.  It writes (atomically, ``_machine.write_markdown``) the commands, the machine state
(``_machine.machine_lines``) and the table to ``--out`` (default
benchmarks/results/scene_speed.md).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, ROOT)

from benchmarks._machine import cpu_times, machine_lines, write_markdown  # noqa: E402
from benchmarks.user_crane_speed import _stats, run_once  # noqa: E402
from sim_core import load_scene  # noqa: E402
from sim_core.scene.io import shipped_scenes  # noqa: E402

CORE = 0
OUT = os.path.join(ROOT, "benchmarks", "results", "scene_speed.md")


def _flags() -> list[str]:
    """--no-plots, and --no-report where this checkout's ``boom-sim run`` writes a report."""
    helptext = subprocess.run([sys.executable, "-m", "sim_core.cli", "run", "--help"], cwd=ROOT,
                              capture_output=True, text=True, check=False).stdout
    return ["--no-plots"] + (["--no-report"] if "--no-report" in helptext else [])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=None,
                    help="shipped scene names (default: every shipped scene)")
    ap.add_argument("--runs", type=int, default=3, help="runs per scene (default 3)")
    ap.add_argument("--warmup", type=float, default=0.5,
                    help="untimed run of each scene first, simulated s (default 0.5; 0: none)")
    ap.add_argument("--out", default=OUT, help=f"the table (default {OUT})")
    args = ap.parse_args(argv)
    names = sorted(shipped_scenes())
    scenes = args.scenes or names
    unknown = [s for s in scenes if s not in names]
    if unknown:
        ap.error(f"unknown scene(s) {', '.join(unknown)}; shipped: {', '.join(names)}")
    if args.runs < 1:
        ap.error(f"--runs {args.runs}: must be >= 1")
    t_end = {s: float(load_scene(s)["solver"]["t_end"]) for s in scenes}

    flags = _flags()
    os.sched_setaffinity(0, {CORE})           # the script too: machine_lines reports core 0
    rows: dict[str, list[dict]] = {s: [] for s in scenes}
    with tempfile.TemporaryDirectory(prefix="scene_speed_") as work:
        for s in scenes if args.warmup > 0 else ():
            run_once(s, s, flags, [f"solver.t_end={min(args.warmup, t_end[s]):g}"],
                     work)
        cpu0, load0 = cpu_times(), os.getloadavg()
        for k in range(args.runs):
            for s in scenes:
                row = run_once(s, s, flags, [], work)
                rows[s].append(row)
                print(f"run {k + 1}/{args.runs} {s}: {row['wall']:.2f} s, exit {row['exit']}",
                      flush=True)
        cpu1, load1 = cpu_times(), os.getloadavg()

    lines = ["# Every shipped scene: wall time of `boom-sim run`, one core", "",
             f"Written by `benchmarks/scene_speed.py` (its docstring describes the columns); "
             f"{args.runs} run(s) per scene, the scenes taking turns, median [min, max].  "
             "Timed command: `OPENBLAS_NUM_THREADS=1 taskset -c 0 boom-sim run SCENE --out "
             f"<tmpdir> --quiet {' '.join(flags)}` (the numba kernels compiled and cached "
             "beforehand).", "",
             "Which figure is which: this table is the reference for the time of a whole "
             "`boom-sim run` of each shipped scene.  `loaded_speed.md` times the paper "
             "scene's command on other machine states (two cores, beside other work) and "
             "`tolerance_accuracy.md` only `simulate` (no start-up, no files); each table "
             "gives its own commit and date, so compare rows within one table.",
             "", "Machine state:", "", *machine_lines(cpu0, cpu1, load0, load1), "",
             "| scene | simulated s | method | DOF | wall s | RTF | cpu s | RTF on CPU | "
             "steps |",
             "|---|---|---|---|---|---|---|---|---|"]
    failed = []
    for s in scenes:
        rs = rows[s]
        ok = [r for r in rs if r["exit"] == 0]
        summ = [r["summary"] for r in ok]
        walls = [r["wall"] for r in ok]
        med = statistics.median(walls) if walls else None
        rtf = f"{t_end[s] / med:.3g}" if med else "-"
        cpus = [r["cpu"] for r in ok]
        rtf_cpu = f"{t_end[s] / statistics.median(cpus):.3g}" if cpus else "-"
        method = summ[0].get("method", "-") if summ else "-"
        dof = summ[0].get("n_dof", "-") if summ else "-"
        steps = _stats([m["n_steps"] for m in summ if "n_steps" in m], "d")
        lines.append(
            f"| `{s}` | {t_end[s]:g} | {method} | {dof} | {_stats(walls)} | {rtf} | "
            f"{_stats(cpus)} | {rtf_cpu} | {steps} |")
        failed += [(s, r.get("message", "")) for r in rs if r["exit"] != 0]
    lines += ["", "RTF = simulated s / median wall s of the whole command (start-up and "
              "writing the result included); RTF on CPU = simulated s / median cpu s of the "
              "command, its pace where it has the core to itself.  A scene whose runs failed "
              "shows - and is listed below."]
    if failed:
        lines += ["", "Failed runs:", ""] + [f"- `{s}`: {' '.join(m.split())}"
                                            for s, m in failed]
    write_markdown(args.out, lines)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
