"""What the folding long-boom scene (`folding_boom`, SIMULTECH 2020) costs: one right-hand side,
a short window of the scene and, with ``--full``, the whole 45 s.

One command (from the repository root, pinned to one core):

    OPENBLAS_NUM_THREADS=1 taskset -c 0 python benchmarks/folding_speed.py [--full]

* ``rhs``: one ``Model.rhs`` of the scene's model (8 sub-elements per boom, n_dof 130) at its
  static equilibrium with a small random velocity; every call at a state of its own (a relative
  perturbation of 1e-9: the frames keep their last evaluation, and a benchmark that repeats one
  state measures cache hits); thread CPU time, minimum and median of 30 runs of 5 calls;
* ``jacobian``: one structured state Jacobian (``sim_core.model.state_jacobian``), the one the
  BDF and "auto" methods use, minimum of 5;
* ``window``: the first ``--window`` s (default 3 s: the luffing stage's start) of the scene
  through ``simulate`` with each of ``--methods`` (default the scene's method and RK45): wall
  time of the whole run and of the integration alone, steps, right-hand sides, real-time
  factor (RTF = simulated s / wall s);
* ``--full``: the whole 45 s with the scene's method, and the checks of the slow test
  ``tests/folding/test_scene_run.py::test_full_scenario`` (slew reached, constraint violation,
  final tip height).

``--root DIR`` times the sim_core of another checkout with this same script (e.g. the tree
before a change); ``--out FILE`` writes the markdown table there (default
``benchmarks/results/folding_speed.md``), with the machine state
(:func:`_machine.machine_lines`).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

_HERE = os.path.dirname(os.path.abspath(__file__))
_ROOT = os.path.abspath(os.path.join(_HERE, ".."))
if "--root" in sys.argv:
    _ROOT = os.path.abspath(sys.argv[sys.argv.index("--root") + 1])
sys.path.insert(0, _ROOT)
sys.path.insert(1, _HERE)

from _machine import cpu_times, machine_lines  # benchmarks/

from sim_core import load_scene, simulate
from sim_core.model.state_jacobian import state_jacobian
from sim_core.systems.folding.build import build_folding, initial_equilibrium
from sim_core.systems.folding.schema import params_from_scene

OUT = os.path.join(_HERE, "results", "folding_speed.md")


def rhs_cost(runs: int = 30, calls: int = 5):
    """(min, median) ms of one Model.rhs and the min s of one structured Jacobian."""
    sc = load_scene("folding_boom")
    fs = build_folding(params_from_scene(sc))
    m = fs.model
    z0 = initial_equilibrium(fs)
    rng = np.random.default_rng(0)
    y = np.concatenate([z0, 1e-3 * rng.standard_normal(len(z0))])
    t = 16.0                                  # inside the slew stage: every drive moves
    m.rhs(t, y)
    times = []
    for r in range(runs):
        ys = [y * (1.0 + 1e-9 * rng.standard_normal(len(y))) for _ in range(calls)]
        c0 = time.thread_time()
        for yk in ys:
            m.rhs(t, yk)
        times.append((time.thread_time() - c0) / calls * 1e3)
    jac = []
    for _ in range(5):
        yk = y * (1.0 + 1e-9 * rng.standard_normal(len(y)))
        c0 = time.thread_time()
        state_jacobian(m, t, yk)
        jac.append(time.thread_time() - c0)
    return float(np.min(times)), float(np.median(times)), float(np.min(jac)), m.n_dof


def run_window(t_end: float, method: str | None):
    ov = {"solver.t_end": t_end, "solver.n_output": max(2, round(10 * t_end) + 1)}
    if method is not None:
        ov["solver.method"] = method
    sc = load_scene("folding_boom", ov)
    w0, c0 = time.perf_counter(), time.process_time()
    res = simulate(sc)
    wall = time.perf_counter() - w0
    st = dict(res.stats)
    st["cpu_s"] = time.process_time() - c0    # this process's CPU (one thread: no worker)
    return sc["solver"]["method"], wall, st, res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", default=None, help="time the sim_core of another checkout")
    ap.add_argument("--window", type=float, default=3.0, help="simulated s of the window")
    ap.add_argument("--methods", default=None,
                    help="comma-separated solver methods of the window (default: the scene's "
                         "and RK45)")
    ap.add_argument("--full", action="store_true", help="also the whole 45 s (scene's method)")
    ap.add_argument("--out", default=OUT)
    a = ap.parse_args()
    scene_method = load_scene("folding_boom")["solver"]["method"]
    methods = a.methods.split(",") if a.methods else list(dict.fromkeys([scene_method, "RK45"]))
    cpu0, load0 = cpu_times(), os.getloadavg()
    rmin, rmed, jmin, n_dof = rhs_cost()
    print(f"rhs {rmin:.2f} ms (min), {rmed:.2f} ms (median); jacobian {jmin:.3f} s", flush=True)
    rows = []
    for meth in methods:
        meth, wall, st, _ = run_window(a.window, meth)
        rows.append((f"first {a.window:g} s", meth, wall, st))
        print(f"{meth} {a.window:g} s: wall {wall:.1f} s, CPU {st['cpu_s']:.1f} s, "
              f"{st.get('n_steps')} steps, {st.get('n_rhs')} rhs", flush=True)
    checks = None
    if a.full:
        meth, wall, st, res = run_window(45.0, None)
        rows.append(("whole 45 s", meth, wall, st))
        checks = (res.error is None,
                  float(res["slew_angle"][-1] + np.pi / 2),
                  float(np.max(res["constraint_violation"])),
                  float(res["tip_position"][-1, 0]))
        print(f"{meth} 45 s: wall {wall:.1f} s, CPU {st['cpu_s']:.1f} s; checks {checks}",
              flush=True)
    cpu1, load1 = cpu_times(), os.getloadavg()
    command = ("`OPENBLAS_NUM_THREADS=1 taskset -c 0 python benchmarks/folding_speed.py"
               + (" --full" if a.full else "") + "`"
               + (f" (sim_core of `{a.root}`)" if a.root else ""))
    lines = ["# The folding long-boom scene: what it costs", "",
             (f"{command}; scene `folding_boom` (8 sub-elements per boom, n_dof {n_dof}, "
              "h = 0.005 s, rtol 1e-6, atol 1e-8)."), "",
             "Machine state:", ""] + machine_lines(cpu0, cpu1, load0, load1) + [
             "", "| quantity | value |", "|---|---|",
             ("| one right-hand side, thread CPU (min / median of 30 x 5 calls) | "
              f"{rmin:.2f} / {rmed:.2f} ms |"),
             f"| one structured state Jacobian (min of 5) | {jmin:.3f} s |", "",
             ("| stretch | method | wall s (whole run) | RTF | CPU s (whole run) | RTF on CPU "
              "| wall s (integration) | steps | right-hand sides | Jacobians |"),
             "|---|---|---|---|---|---|---|---|---|---|"]
    for label, meth, wall, st in rows:
        t_sim = 45.0 if label.startswith("whole") else a.window
        w_int = float(st.get("wall_time_s", float("nan")))
        cpu = st["cpu_s"]
        lines.append(f"| {label} | {meth} | {wall:.1f} | {t_sim / wall:.2f} | {cpu:.1f} | "
                     f"{t_sim / cpu:.2f} | {w_int:.1f} | {st.get('n_steps', '-')} | "
                     f"{st.get('n_rhs', '-')} | {st.get('n_jacobians', '-')} |")
    if checks is not None:
        ok, slew, viol, tip = checks
        lines += ["", ("Checks of the slow test on the whole run: finished "
                       f"{'yes' if ok else 'NO'}; final slew + 90 deg = {slew:.1e} rad "
                       f"(|.| <= 1e-9); max constraint violation {viol:.2e} (< 1e-4); final tip "
                       f"height {tip:.2f} m (24.39 +- 1.5 m).")]
    lines += ["", ("RTF = simulated s / wall s of the whole run (building the model and its "
                   "static equilibrium, ~2-3 s, included); RTF on CPU = simulated s / CPU s of "
                   "the process (one thread), what the run costs where it has the core to "
                   "itself; the integration alone is the solver's wall time (statistics "
                   "`wall_time_s`).  The machine may be shared: the busy share of each core "
                   "above says how much.")]
    text = "\n".join(lines) + "\n"
    with open(a.out, "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
