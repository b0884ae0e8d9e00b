"""What a looser tolerance buys on the paper scene, per method: wall time against the error of
the tip and of the telescopic cylinder force.

One command (from the repository root, pinned to one core):

    OPENBLAS_NUM_THREADS=1 taskset -c 0 python benchmarks/tolerance_accuracy.py

``telescopic_extraction`` (20 s) runs whole through ``simulate`` at each (rtol, atol) with
``solver.method`` = "auto", "RK45" and "BDF"; the reference is RK45 at rtol 1e-8, atol 1e-9.
Columns: the run's wall time (``simulate``, this process), accepted steps, the largest step,
the largest tip position error (m) and the largest cylinder force error over the 201 outputs,
the latter as a fraction of the reference force's range over the run, and the time of that
largest force error; for "auto" the first switch to BDF and the last switch.  ``--out FILE``: the
markdown table (default ``benchmarks/results/tolerance_accuracy.md``) with the machine state
(:func:`_machine.machine_lines`).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.abspath(os.path.join(_HERE, "..")))
sys.path.insert(0, _HERE)

from _machine import cpu_times, machine_lines, write_markdown  # noqa: E402
from sim_core import load_scene, simulate  # noqa: E402

SCENE = "telescopic_extraction"
TOLERANCES = ((1e-6, 1e-7), (1e-5, 1e-6), (1e-4, 1e-5), (1e-2, 1e-7), (1e-2, 1e-3))
METHODS = ("auto", "RK45", "BDF")


def run(over: dict):
    """(wall s, result, tip (n, 3), cylinder force (n,)) of the scene with ``over``."""
    w0 = time.perf_counter()
    r = simulate(load_scene(SCENE, overrides=over))
    wall = time.perf_counter() - w0
    n = len(r.t)
    return (wall, r, np.reshape(r["tip_position"], (n, -1))[:, :3],
            np.reshape(r["telescopic_cylinder_force"], (n, -1))[:, 0])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(_HERE, "results", "tolerance_accuracy.md"))
    a = ap.parse_args(argv)
    cpu0, load0 = cpu_times(), os.getloadavg()
    _, _, tip0, f0 = run({"solver.rtol": 1e-8, "solver.atol": 1e-9, "solver.method": "RK45"})
    span = float(np.ptp(f0))
    rows = []
    for rtol, atol in TOLERANCES:
        for method in METHODS:
            wall, r, tip, f = run({"solver.rtol": rtol, "solver.atol": atol,
                                   "solver.method": method})
            st = r.stats
            k = int(np.argmax(np.abs(f - f0)))
            switches = (f"{st['first_switch_to_bdf_s']:.2f}, {st['last_switch_s']:.2f}"
                        if st.get("n_method_switches") else "–")
            row = (rtol, atol, method, wall, st["n_steps"], st["max_step_s"],
                   float(np.max(np.abs(tip - tip0))), float(np.abs(f - f0)[k]) / span,
                   float(r.t[k]), switches)
            rows.append(row)
            print(" ".join(str(x) for x in row), flush=True)
    cpu1, load1 = cpu_times(), os.getloadavg()
    lines = [
        "# The paper scene at looser tolerances: time and accuracy per method",
        "",
        f"`{SCENE}` (20 s) at each (rtol, atol) and method against RK45 at rtol 1e-8, "
        f"atol 1e-9.  Force error: the largest telescopic cylinder force error over the "
        f"outputs as a fraction of the reference force's range ({span / 1e3:.0f} kN).  Wall: "
        "`simulate` in this process.  Written by `benchmarks/tolerance_accuracy.py`.",
        "",
        "Which figure is which: the wall times here are of `simulate` alone (model "
        "build, integration, outputs), without the command's start-up and files, so "
        "they compare methods and tolerances with each other; the whole command's time "
        "is `scene_speed.md`, at its own commit and date.",
        "",
        "Machine:",
        "",
        *machine_lines(cpu0, cpu1, load0, load1),
        "",
        "| rtol | atol | method | wall (s) | steps | largest step (ms) | tip error (m) "
        "| force error / range | at t (s) | first switch to BDF, last switch (s) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for rtol, atol, method, wall, steps, h_max, e_tip, e_f, t_f, switches in rows:
        lines.append(f"| {rtol:.0e} | {atol:.0e} | {method} | {wall:.1f} | {steps} | "
                     f"{h_max * 1e3:.0f} | {e_tip:.1e} | {e_f:.1e} | {t_f:.1f} | {switches} |")
    write_markdown(a.out, lines)


if __name__ == "__main__":
    main()
