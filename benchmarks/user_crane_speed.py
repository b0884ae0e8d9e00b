"""Wall time of the four-section hexagonal crane (`crane_hexagonal_4`) as a user runs it, and
what its default discretisation (n_nodes = 5) costs in accuracy against n_nodes = 9.

One command (repository root, an otherwise idle machine), a few minutes with the defaults:

    python benchmarks/user_crane_speed.py

The script pins itself to core 0 (the machine state's busy shares and affinity then describe
the timed runs) and starts every run as

    OPENBLAS_NUM_THREADS=1 taskset -c 0 boom-sim run crane_hexagonal_4 --out <tmpdir> --quiet

(``python -m sim_core.cli run ...``, so the checkout's package is the one timed): one core, so
the model never starts its element worker thread, and one BLAS thread.  It writes
benchmarks/results/user_crane_speed.md (atomically, :func:`_machine.write_markdown`) with the
command lines, the machine state (:func:`_machine.machine_lines`) and two tables.

``speed``: each case ``--runs`` times (default 3, the cases taking turns), median [min, max] of

* ``wall``: the child process's wall time (``time.perf_counter`` around ``subprocess.run``),
  start-up (imports, compiled-code cache), building the model, the integration and the writing
  of the results included, s;
* ``RTF`` = simulated time (the scene's ``solver.t_end``, 20 s) / median ``wall``;
* ``cpu``: the child's user + system time (``resource.getrusage(RUSAGE_CHILDREN)`` before and
  after), s: about the wall on one core;
* ``sim wall``, ``sim RTF``, ``steps``, ``RHS``: the integration's own wall time and real-time
  factor, its step and right-hand-side counts (summary.json ``wall_time_s``,
  ``real_time_factor``, ``n_steps``, ``n_rhs``).

Cases:

* ``default``: the command above, figures included (what ``boom-sim run`` does unasked);
* ``no_plots``: the same with ``--no-plots`` (the results without the figures).

``accuracy``: the ``default`` command with ``--set booms.n_nodes=9`` (8 sub-elements per boom,
the paper's discretisation) once, against the first ``default`` run (the scene's n_nodes = 5):
both runs' wall time, integration wall time, steps and right-hand sides, and over the whole
run (every output time, ``sim_core.result.Result.load(...)["tip_position"]``)

* ``max |tip_5 - tip_9|``: the largest distance between the two tip positions, m, and that
  distance relative to the tip's travel (the largest distance of the n_nodes = 9 tip from its
  initial position);
* ``max |F|``: the largest telescopic-cylinder force (``telescopic_cylinder_force``) of each
  run, and the relative difference of the two.

Options: ``--runs N``; ``--skip-accuracy`` (the speed table only); ``--out FILE``;
``--quick`` (``--set solver.t_end=2`` on every run, one run per case, written to
/tmp/user_crane_speed_quick.md unless ``--out`` is given: a check of the script, not a
benchmark).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, ROOT)

from benchmarks._machine import cpu_times, machine_lines, write_markdown
from sim_core import load_scene
from sim_core.result import Result

RESULTS = os.path.join(ROOT, "benchmarks", "results")
OUT = os.path.join(RESULTS, "user_crane_speed.md")
QUICK_OUT = os.path.join(tempfile.gettempdir(), "user_crane_speed_quick.md")
SCENE = "crane_hexagonal_4"
CORE = 0
CASES = {"default": [], "no_plots": ["--no-plots"]}
FINE_NODES = 9


def _command(out: str, flags: list[str], sets: list[str]) -> list[str]:
    cmd = ["taskset", "-c", str(CORE), sys.executable, "-m", "sim_core.cli", "run", SCENE,
           "--out", out, "--quiet", *flags]
    for s in sets:
        cmd += ["--set", s]
    return cmd


def _shown(flags: list[str], sets: list[str]) -> str:
    """The timed command as a user types it."""
    return (f"`OPENBLAS_NUM_THREADS=1 taskset -c {CORE} boom-sim run {SCENE} --out <tmpdir> "
            "--quiet" + "".join(f" {f}" for f in flags)
            + "".join(f" --set {s}" for s in sets) + "`")


def run_once(label: str, flags: list[str], sets: list[str], workdir: str) -> dict:
    """One pinned child process: wall and CPU time, exit status, summary.json, output folder."""
    out = tempfile.mkdtemp(prefix=f"{label}_", dir=workdir)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    env.pop("SIM_CORE_ELEMENT_WORKER", None)
    log_path = os.path.join(out, "stdout.txt")
    with open(log_path, "wb") as log:
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(_command(out, flags, sets), env=env, cwd=ROOT, stdout=log,
                              stderr=subprocess.STDOUT, check=False)
        wall = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    row = {"wall": wall, "exit": proc.returncode, "out": out,
           "cpu": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)}
    try:
        with open(os.path.join(out, "summary.json")) as f:
            row["summary"] = json.load(f)
    except (OSError, ValueError):
        row["summary"] = {}
    if row["exit"] != 0 or not row["summary"]:
        with open(log_path, "rb") as f:
            row["message"] = f.read().decode(errors="replace").strip()[-300:]
    return row


def _stats(values: list[float], fmt: str = ".2f") -> str:
    """median [min, max] of the values ("-" if none; one value where all are equal)."""
    values = [v for v in values if v is not None]
    if not values:
        return "-"
    if min(values) == max(values):
        return format(values[0], fmt)
    mid = statistics.median_low(values) if fmt == "d" else statistics.median(values)
    return (f"{format(mid, fmt)} "
            f"[{format(min(values), fmt)}, {format(max(values), fmt)}]")


def _common(a: Result, b: Result, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Output ``name`` of a and b at b's output times inside both runs (a interpolated where
    the output times differ, e.g. a run that stopped early)."""
    xa, xb = np.asarray(a[name], float), np.asarray(b[name], float)
    if a.t.shape == b.t.shape and np.allclose(a.t, b.t, rtol=0.0, atol=1e-12):
        return xa, xb
    keep = (b.t >= a.t[0]) & (b.t <= a.t[-1])
    xa2 = xa.reshape(len(a.t), -1)
    xi = np.column_stack([np.interp(b.t[keep], a.t, xa2[:, k]) for k in range(xa2.shape[1])])
    return xi.reshape((int(keep.sum()),) + xa.shape[1:]), xb[keep]


def compare(coarse_npz: str, fine_npz: str) -> dict:
    """Tip-position and telescopic-cylinder-force differences of two runs over the whole run."""
    a, b = Result.load(coarse_npz), Result.load(fine_npz)
    ta, tb = _common(a, b, "tip_position")
    dist = np.linalg.norm(ta - tb, axis=1)
    k = int(np.argmax(dist))
    tip_b = np.asarray(b["tip_position"], float)
    travel = float(np.max(np.linalg.norm(tip_b - tip_b[0], axis=1)))
    fa = float(np.max(np.abs(a["telescopic_cylinder_force"])))
    fb = float(np.max(np.abs(b["telescopic_cylinder_force"])))
    keep_t = b.t[(b.t >= a.t[0]) & (b.t <= a.t[-1])]
    return {"tip_max": float(dist[k]), "tip_at": float(keep_t[k]), "travel": travel,
            "tip_rel": float(dist[k]) / travel if travel > 0 else float("nan"),
            "tip_final": float(dist[-1]), "f_coarse": fa, "f_fine": fb,
            "f_rel": abs(fa - fb) / fb if fb > 0 else float("nan"),
            "n_compared": len(dist), "errors": (a.error, b.error)}


def _failed_lines(rows: list[tuple[str, dict]]) -> list[str]:
    bad = [(label, r) for label, r in rows if r["exit"] != 0 or not r["summary"]]
    if not bad:
        return []
    return ["", "Failed runs:", ""] + [
        f"- {label}: exit {r['exit']}: {r.get('message', '')}" for label, r in bad]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=None,
                    help="runs per speed case (default 3; 1 with --quick)")
    ap.add_argument("--quick", action="store_true",
                    help="t_end = 2 s, one run per case: checks the script only (writes to "
                         f"{QUICK_OUT} unless --out is given)")
    ap.add_argument("--skip-accuracy", action="store_true",
                    help=f"no n_nodes = {FINE_NODES} run and no accuracy table")
    ap.add_argument("--out", default=None, help=f"markdown file (default {OUT})")
    args = ap.parse_args(argv)
    runs = args.runs if args.runs is not None else (1 if args.quick else 3)
    if runs < 1:
        ap.error("--runs must be at least 1")
    out_path = args.out or (QUICK_OUT if args.quick else OUT)
    if shutil.which("taskset") is None:
        ap.error("taskset (util-linux) is needed: every run is pinned to one core")
    if CORE not in os.sched_getaffinity(0):
        ap.error(f"core {CORE} is not in this process's affinity set "
                 f"{sorted(os.sched_getaffinity(0))}")
    os.sched_setaffinity(0, {CORE})           # the script too: machine_lines reports core 0
    sets = ["solver.t_end=2"] if args.quick else []
    overrides = dict(s.split("=", 1) for s in sets)
    scene = load_scene(SCENE, overrides)
    t_end = float(scene["solver"]["t_end"])
    n_nodes = int(scene["booms"]["n_nodes"])

    cpu0, load0 = cpu_times(), os.getloadavg()
    workdir = tempfile.mkdtemp(prefix="user_crane_speed_")
    results: dict[str, list[dict]] = {c: [] for c in CASES}
    fine, acc = None, None
    try:
        for k in range(runs):
            for case, flags in CASES.items():
                r = run_once(case, flags, sets, workdir)
                results[case].append(r)
                s = r["summary"]
                print(f"{case:9s} run {k + 1}: wall {r['wall']:.2f} s, cpu {r['cpu']:.2f} s, "
                      f"sim wall {s.get('wall_time_s', float('nan')):.2f} s, "
                      f"{s.get('n_steps')} steps, exit {r['exit']}", flush=True)
        if not args.skip_accuracy:
            fine = run_once(f"n_nodes_{FINE_NODES}", [],
                            sets + [f"booms.n_nodes={FINE_NODES}"], workdir)
            s = fine["summary"]
            print(f"n_nodes={FINE_NODES}: wall {fine['wall']:.2f} s, sim wall "
                  f"{s.get('wall_time_s', float('nan')):.2f} s, {s.get('n_steps')} steps, "
                  f"exit {fine['exit']}", flush=True)
            coarse = results["default"][0]
            npz = [os.path.join(r["out"], "result.npz") for r in (coarse, fine)]
            if all(os.path.exists(p) for p in npz):
                acc = compare(*npz)
                print(f"max |tip_{n_nodes} - tip_{FINE_NODES}| {acc['tip_max']:.3e} m "
                      f"({acc['tip_rel']:.2e} of travel {acc['travel']:.3f} m); max |F| "
                      f"relative difference {acc['f_rel']:.2e}", flush=True)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    cpu1, load1 = cpu_times(), os.getloadavg()

    bench_cmd = ("`python benchmarks/user_crane_speed.py"
                 + (f" --runs {args.runs}" if args.runs is not None else "")
                 + (" --quick" if args.quick else "")
                 + (" --skip-accuracy" if args.skip_accuracy else "")
                 + (f" --out {args.out}" if args.out else "") + "`")
    lines = [f"# The four-section hexagonal crane (`{SCENE}`): speed and discretisation",
             "", (f"{bench_cmd}; {t_end:g} s simulated, {runs} run(s) per speed case, "
                  "median [min, max].  Written by benchmarks/user_crane_speed.py (its docstring "
                  "describes the cases and columns)."
                  + ("  QUICK CHECK of the script (t_end = 2 s), not a benchmark."
                     if args.quick else "")),
             "", "Timed commands (each `python -m sim_core.cli run`, the checkout's package):",
             "", *(f"- {case}: {_shown(flags, sets)}" for case, flags in CASES.items())]
    if not args.skip_accuracy:
        lines.append(f"- accuracy: {_shown([], sets + [f'booms.n_nodes={FINE_NODES}'])}, "
                     f"against the first `default` run (n_nodes = {n_nodes})")
    lines += ["", "Machine state:", "", *machine_lines(cpu0, cpu1, load0, load1), "",
              "## Speed", "",
              ("| case | runs | wall s | RTF | cpu s | sim wall s | sim RTF | steps | RHS "
               "| exit |"),
              "|---|---|---|---|---|---|---|---|---|---|"]
    for case, rows in results.items():
        walls = [r["wall"] for r in rows]
        sums = [r["summary"] for r in rows]
        lines.append(
            f"| {case} | {len(rows)} | {_stats(walls)} | "
            f"{t_end / statistics.median(walls):#.3g} | {_stats([r['cpu'] for r in rows])} | "
            f"{_stats([s.get('wall_time_s') for s in sums])} | "
            f"{_stats([s.get('real_time_factor') for s in sums], '#.3g')} | "
            f"{_stats([s.get('n_steps') for s in sums], 'd')} | "
            f"{_stats([s.get('n_rhs') for s in sums], 'd')} | "
            f"{', '.join(str(e) for e in sorted({r['exit'] for r in rows}))} |")
    lines += ["", ("RTF = simulated time / median wall time of the whole command (start-up, "
                   "the section constants (from the on-disk cache of "
                   "`sim_core.physics.cross_sections`, filled by a run before the benchmark), "
                   "building the model, the integration, writing the results and, in "
                   "`default`, the figures); sim RTF = the integration's own (summary.json "
                   "`real_time_factor`).")]
    labelled = [(case, r) for case, rows in results.items() for r in rows]
    if fine is not None:
        coarse = results["default"][0]
        lines += ["", "## Accuracy of the default discretisation", "",
                  ("| n_nodes | sub-elements per boom | n_dof | wall s | sim wall s | steps "
                   "| RHS | exit |"), "|---|---|---|---|---|---|---|---|"]
        for nn, r in ((n_nodes, coarse), (FINE_NODES, fine)):
            s = r["summary"]
            lines.append(f"| {nn} | {nn - 1} | {s.get('n_dof', '-')} | {r['wall']:.2f} | "
                         f"{_stats([s.get('wall_time_s')])} | {s.get('n_steps', '-')} | "
                         f"{s.get('n_rhs', '-')} | {r['exit']} |")
        if acc is not None:
            lines += ["", "| quantity | value |", "|---|---|",
                      (f"| max over {acc['n_compared']} output times of \\|tip_{n_nodes} - "
                       f"tip_{FINE_NODES}\\| | {acc['tip_max']:.3e} m (at t = "
                       f"{acc['tip_at']:.2f} s) |"),
                      f"| tip travel (n_nodes = {FINE_NODES}) | {acc['travel']:.3f} m |",
                      (f"| max \\|tip_{n_nodes} - tip_{FINE_NODES}\\| / travel | "
                       f"{acc['tip_rel']:.2e} |"),
                      (f"| \\|tip_{n_nodes} - tip_{FINE_NODES}\\| at the end | "
                       f"{acc['tip_final']:.3e} m |"),
                      (f"| largest telescopic-cylinder force, n_nodes = {n_nodes} / "
                       f"{FINE_NODES} | {acc['f_coarse']:.6g} / {acc['f_fine']:.6g} N |"),
                      f"| its relative difference | {acc['f_rel']:.2e} |"]
            if any(acc["errors"]):
                lines += ["", f"A run stopped early: {acc['errors']}"]
        else:
            lines += ["", "No comparison: a run wrote no result.npz."]
        lines += ["", ("The tip travel is the largest distance of the n_nodes = "
                       f"{FINE_NODES} tip from its initial position; the `default` row's "
                       "wall time is the first run of the speed table's `default` case.")]
        labelled.append((f"n_nodes={FINE_NODES}", fine))
    failed = _failed_lines(labelled)
    lines += failed
    write_markdown(out_path, lines)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
