"""What each effect of the paper's extraction scene costs (issue "Scenes and effects").

One command (from the repository root):

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/effects_speed.py [--quick]

runs the shipped ``telescopic_extraction`` scene (paper 9.2: flexible booms, 25 t, friction with
the slider-spring distribution, filtering, elastic ropes) over a short window from its static
equilibrium, then the same scene with each effect switched off in turn (through the scene
overrides, exactly as a user would: ``--set effects.friction=false`` ...), and the rigid limit
(``effects.flexible=false``, which needs friction off).  For each row: wall time of the static
equilibrium and of the dynamics, RK45 steps and RHS evaluations, wall seconds per simulated
second, and the speed-up against the full scene.  The window is short because the full scene is
slow (see docs/performance.md for the cost per simulated second in general); all rows
use the same window, so the ratios are what the table is for.

Writes benchmarks/results/effects_speed.csv and .md (atomically).  ``--quick``: 2 sub-elements
per spline element instead of the paper's 8 (``booms.n_nodes = 3``) and a 0.1 s window.
"""

from __future__ import annotations

import argparse
import csv
import io
import os
import platform
import sys
import time
from datetime import datetime, timezone

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..")))

from sim_core import load_scene  # noqa: E402
from sim_core.errors import SimulationError  # noqa: E402
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium, simulate_telescopic# noqa: E402
from sim_core.systems.telescopic.schema import params_from_scene  # noqa: E402

ROWS = [
    ("full scene (paper 9.2)", {}),
    ("friction off", {"effects.friction": False}),
    ("contact_distribution off", {"effects.contact_distribution": False}),
    ("friction + contact_distribution off", {"effects.friction": False,
                                             "effects.contact_distribution": False}),
    ("filtering off", {"effects.filtering": False}),
    ("torsion off", {"effects.torsion": False}),
    ("rope_elasticity off", {"effects.rope_elasticity": False}),
    ("gravity off", {"effects.gravity": False}),
    ("rigid limit (flexible off, friction off)", {"effects.flexible": False,
                                                  "effects.friction": False}),
]


def _atomic_write(path: str, text: str) -> None:
    from sim_core.result import atomic_write_bytes
    atomic_write_bytes(path, text.encode())


class _TimeLimit(Exception):
    def __init__(self, t):
        self.t = t


def run_row(overrides: dict, t_window: float, n_nodes: int | None, limit: float) -> dict:
    ov = dict(overrides)
    if n_nodes is not None:
        ov["booms.n_nodes"] = n_nodes
    scene = load_scene("telescopic_extraction", overrides=ov)
    p = params_from_scene(scene)
    sol = scene["solver"]
    row = {"static_s": 0.0}
    if p.flexible:
        w = time.perf_counter()
        ts = build_telescopic(p)
        initial_equilibrium(ts)
        row["static_s"] = time.perf_counter() - w
        row["dof"] = ts.model.n_dof - sum(c.m for c in ts.model.nonlinear)
    w = time.perf_counter()
    reached = {"t": t_window}

    def progress(t, wall):
        if wall > limit:                 # a row that would take hours: stop, report the rate
            raise _TimeLimit(t)
    sim_window = t_window
    try:
        res = simulate_telescopic(p, t_window, 3, sol["rtol"], sol["atol"], progress)
        row["error"] = ""
        stats = res.stats
    except SimulationError as exc:
        row["error"] = str(exc)
        stats = getattr(getattr(exc, "result", None), "stats", {}) or {}
    except _TimeLimit as stop:
        sim_window = max(stop.t, 1e-12)
        row["error"] = f"stopped by the {limit:g} s limit at t = {stop.t:.3g} s (rate extrapolated)"
        stats = {"wall_time_s": limit}
    total = time.perf_counter() - w
    # the integrator's own wall clock (simulate_telescopic also repeats the static solve)
    row["dynamics_s"] = float(stats.get("wall_time_s", total))
    row["steps"] = stats.get("n_steps", 0)
    row["rhs"] = stats.get("n_rhs", stats.get("nfev", 0))
    row.setdefault("dof", stats.get("n_dof", 0))
    row["wall_per_sim_s"] = row["dynamics_s"] / sim_window
    del reached
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="n_nodes = 3 and a 0.1 s window")
    ap.add_argument("--window", type=float, default=None, help="simulated window, s")
    ap.add_argument("--limit", type=float, default=300.0,
                    help="wall seconds per row before it is stopped and its rate extrapolated")
    ap.add_argument("--only", default=None,
                    help="comma-separated row numbers (0 = full scene) to run a subset")
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "results"))
    args = ap.parse_args(argv)
    n_nodes = 3 if args.quick else None
    window = args.window or (0.1 if args.quick else 0.2)
    os.makedirs(args.out, exist_ok=True)
    rows = []
    rows_sel = ROWS if args.only is None else [ROWS[int(i)] for i in args.only.split(",")]
    for name, ov in rows_sel:
        r = run_row(ov, window, n_nodes, args.limit)
        r["configuration"] = name
        rows.append(r)
        print(f"{name:45s} static {r['static_s']:7.1f} s  dynamics {r['dynamics_s']:8.1f} s  "
              f"steps {r['steps']:6d}  rhs {r['rhs']:7d}  {r['error'][:60]}", flush=True)
    base = rows[0]["wall_per_sim_s"]
    for r in rows:
        r["speedup"] = base / r["wall_per_sim_s"] if r["wall_per_sim_s"] > 0 else float("inf")
    tag = "quick" if args.quick else "paper"
    keys = ["configuration", "dof", "static_s", "dynamics_s", "wall_per_sim_s", "steps", "rhs",
            "speedup", "error"]
    buf = io.StringIO()
    w = csv.DictWriter(buf, keys, extrasaction="ignore")
    w.writeheader()
    w.writerows(rows)
    _atomic_write(os.path.join(args.out, f"effects_speed_{tag}.csv"), buf.getvalue())
    head = (f"Effects of `telescopic_extraction` ({'n_nodes = 3' if args.quick else 'paper discretisation, n_nodes = 9'}), "
            f"window 0 - {window:g} s from the static equilibrium, RK45 rtol 1e-6 / atol 1e-7.  "
            f"{datetime.now(timezone.utc):%Y-%m-%d}, {platform.processor() or platform.machine()}, "
            "one thread (OPENBLAS_NUM_THREADS=1); machine shared with other jobs, so absolute "
            "times are noisy; ratios come from one run.\n\n")
    md = [head, "| configuration | DOF | static solve s | dynamics s | wall s per simulated s | "
                "RK45 steps | RHS evals | speed-up vs full |",
          "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        err = f" (failed: {r['error'][:80]})" if r["error"] else ""
        md.append(f"| {r['configuration']}{err} | {r['dof']} | {r['static_s']:.1f} | "
                  f"{r['dynamics_s']:.2f} | {r['wall_per_sim_s']:.1f} | {r['steps']} | {r['rhs']} | "
                  f"{r['speedup']:.1f}x |")
    _atomic_write(os.path.join(args.out, f"effects_speed_{tag}.md"), "\n".join(md) + "\n")
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
