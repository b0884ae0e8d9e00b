"""Speed-up of ``boom-sim sweep`` (sim_core.sweep.run_sweep) with 1 and with 2 local Ray workers.

One command (repository root), ~2-3 min on the 2-core machine:

    PYTHONPATH=. python benchmarks/sweep_speed.py --note "idle machine"

Two sweeps, each run with ``workers=1`` and ``workers=2`` into fresh output folders (nothing
is skipped):

* ``rl12``: the 12-case sweep of the CI smoke and tests/scenes/test_sweep.py: the modal
  reduced-order scene ``telescopic_extraction_rl`` (20 s simulated, ~0.1 s of solving per
  case), payload.mass 20/25/30 t x booms.luffing_angle_deg 45/50/55/60.  Ray's start
  (~4 s), the worker processes' imports and the summary figure dominate: this is the
  overhead of a sweep.
* ``beam6``: 6 cases of ``beam_through_sleeve`` over 1 s simulated (a few seconds of
  solving each): tip force 250/500/1000 N x E 1.5e11/2.1e11 Pa.
* ``paper4``: 4 cases of the paper extraction at 2 sub-elements per spline element over 6 s
  (statics and several seconds of solving each): payload 20/25 t x contact.moment_model
  rigid/couple: compute-bound cases.

Per run: wall time of the whole run_sweep call (Ray start and stop, every case, the summary
files), and the sum of the cases' own wall times (``wall_s`` of the rows: one simulate() call
each, model build included).  Speed-up = wall(1 worker) / wall(2 workers); the ideal is 2 on
2 cores.  The load average before and after each run is recorded: on a machine shared with
other work the speed-up is lower than on an idle one.  ``--note`` states the machine state in
the report.

Writes benchmarks/results/sweep_speed.md (atomically).
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import shutil
import sys
import tempfile
import time

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..")))

from sim_core.result import atomic_write_bytes  # noqa: E402
from sim_core.sweep import run_sweep  # noqa: E402

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")

SWEEPS = {
    "rl12": ("telescopic_extraction_rl",
             {"payload.mass": ["20000", "25000", "30000"],
              "booms.luffing_angle_deg": ["45", "50", "55", "60"]}, {}),
    "beam6": ("beam_through_sleeve",
              {"point_loads.0.force": ["[0, 0, -250]", "[0, 0, -500]", "[0, 0, -1000]"],
               "beams.0.section.E": ["1.5e11", "2.1e11"]},
              {"solver.t_end": "1.0", "solver.n_output": "21"}),
    "paper4": ("telescopic_extraction",
               {"payload.mass": ["20000", "25000"], "contact.moment_model": ["rigid", "couple"]},
               {"booms.n_nodes": "3", "solver.t_end": "6.0"}),
}


def measure(key: str, workers: int, root: str) -> dict:
    scene, grid, fixed = SWEEPS[key]
    out = os.path.join(root, f"{key}_w{workers}")
    shutil.rmtree(out, ignore_errors=True)                 # fresh: no case is skipped
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    rows = run_sweep(scene, grid, out, fixed=fixed, workers=workers, quiet=True)
    wall = time.perf_counter() - t0
    st = [r["status"] for r in rows]
    row = {"sweep": key, "scene": scene, "cases": len(rows), "workers": workers, "wall_s": wall,
           "case_wall_sum_s": sum(r["wall_s"] or 0.0 for r in rows),
           "ok": st.count("ok"), "failed": st.count("failed"),
           "load_before": load0, "load_after": os.getloadavg()[0]}
    print(row, flush=True)
    return row


def report(rows: list[dict], note: str) -> str:
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    lines = [f"# Sweep speed-up, 1 vs 2 local Ray workers ({stamp}, {platform.node()}, "
             f"{os.cpu_count()} cores)", "",
             f"Machine state: {note}.", "",
             "| sweep | scene | cases | workers | wall (s) | sum of case wall (s) | ok | failed "
             "| load avg before / after | speed-up |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        base = next(b for b in rows if b["sweep"] == r["sweep"] and b["workers"] == 1)
        lines.append(f"| {r['sweep']} | {r['scene']} | {r['cases']} | {r['workers']} | "
                     f"{r['wall_s']:.1f} | {r['case_wall_sum_s']:.1f} | {r['ok']} | {r['failed']} "
                     f"| {r['load_before']:.1f} / {r['load_after']:.1f} | "
                     f"{base['wall_s'] / r['wall_s']:.2f} |")
    lines += ["",
              "wall: the whole run_sweep call (Ray start and stop, all cases, summary.csv and "
              "summary.png); sum of case wall: the cases' own simulate() times (model build "
              "included).  Speed-up: wall with 1 worker / wall with this many workers (ideal 2 "
              "on 2 cores).  rl12 cases take ~0.1 s each, so its wall time is mostly Ray's "
              "start, the workers' imports and the figure.  beam6 cases are compute-bound, "
              "and a beam case may start the element worker thread of "
              "sim_core/model/workers.py beside its own (its governor stops it when it "
              "lags behind), so with 2 workers the cases' own wall times (sum of case wall) "
              "grow a little.  With other work on the machine (load "
              "average above the core count) both workers share the cores with it and the "
              "speed-up is below the idle one.",
              "", "Reproduce: `PYTHONPATH=. python benchmarks/sweep_speed.py --note \"...\"`."]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--note", required=True,
                    help="machine state written into the report, e.g. 'idle' or 'shared with "
                         "other jobs'")
    ap.add_argument("--sweeps", default="rl12,beam6,paper4",
                    help=f"comma-separated subset of {','.join(SWEEPS)}")
    ap.add_argument("--out", default=os.path.join(RESULTS, "sweep_speed.md"))
    args = ap.parse_args()
    keys = [k.strip() for k in args.sweeps.split(",")]
    unknown = [k for k in keys if k not in SWEEPS]
    if unknown:
        ap.error(f"--sweeps {unknown[0]!r}: allowed {', '.join(SWEEPS)}")
    rows = []
    with tempfile.TemporaryDirectory(prefix="sweep_speed_") as root:
        for key in keys:
            for workers in (1, 2):
                rows.append(measure(key, workers, root))
    text = report(rows, args.note)
    atomic_write_bytes(args.out, text.encode())
    print(text)


if __name__ == "__main__":
    main()
