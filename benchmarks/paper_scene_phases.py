"""Where the paper scene's dynamics spend their time, phase by phase, and what sets RK45's step
in each.

One command (from the repository root, pinned to one core):

    OPENBLAS_NUM_THREADS=1 taskset -c 0 python benchmarks/paper_scene_phases.py

1. ``telescopic_extraction`` runs whole through ``simulate`` with a progress callback, which
   reports after every accepted step (t, wall).  Per phase of the drive (breakaway, ramp up,
   constant speed, ramp down, stick-in and hold) and per ``--bin`` s (default 0.5 s): the
   integration's wall time, the accepted steps and their mean length.
2. From the scene's own state at each ``--probe`` time (default 3 s, in the ramp up, and 8 s, at
   constant speed), scipy's RK45 (the scene's method while sliding, rtol 1e-6, atol 1e-7) runs
   0.5 s on ``Model.rhs``.  After every accepted step the component that dominates the scaled
   error estimate |e_i| / (atol + rtol |y_i|) is recorded and named (coordinate or velocity, boom,
   spline element, entry of the element's coordinate layout, module doc of
   ``sim_core.physics.beam.moving_node_beam``).  The step is stability-limited where the error
   norm stays well below 1 at steps near the filter pair's bound (~13.6 ms, docs/model.md: Time
   integration) and accuracy-limited where the norm sits at the controller's ~0.6 with steps
   below it.

``--out FILE``: the markdown table (default ``benchmarks/results/paper_scene_phases.md``) with
the machine state (:func:`_machine.machine_lines`).
"""

from __future__ import annotations

import argparse
import collections
import os
import sys
import time

import numpy as np

_HERE = os.path.dirname(os.path.abspath(__file__))
_ROOT = os.path.abspath(os.path.join(_HERE, ".."))
sys.path.insert(0, _ROOT)
sys.path.insert(0, _HERE)

from scipy.integrate import RK45  # noqa: E402

from _machine import cpu_times, machine_lines, write_markdown  # noqa: E402
from sim_core import load_scene, simulate  # noqa: E402
from sliding_integrators import start_state, system  # noqa: E402

SCENE = "telescopic_extraction"


def phases(scene: dict) -> list[tuple[str, float, float]]:
    """(name, t_start, t_end) of the drive's phases (scene [drive]: ramps of t_ramp s, constant
    speed to t_hold_end); the first second is the breakaway from stick."""
    d, t_end = scene["drive"], scene["solver"]["t_end"]
    t_r, t_h = d["t_ramp"], d["t_hold_end"]
    return [("breakaway", 0.0, 1.0), ("ramp up", 1.0, t_r), ("constant speed", t_r, t_h),
            ("ramp down", t_h, t_h + t_r), ("stick-in and hold", t_h + t_r, t_end)]


def coordinate_label(model, i: int) -> str:
    """Name of component i of the state y = (z, z_dot) of the telescopic model."""
    n = model.n_dof
    kind, j = ("velocity of ", i - n) if i >= n else ("", i)
    P = model.P.toarray() if hasattr(model.P, "toarray") else np.asarray(model.P)
    rows = np.nonzero(P[:, j])[0]
    names = []
    for b, (beam, off) in enumerate(zip(model.beams, model.offsets)):
        for e, (el, imap) in enumerate(zip(beam.elements, beam.index_map)):
            for r in rows:
                for loc in np.nonzero(off + imap == r)[0]:
                    names.append(f"boom {b + 1} element {e + 1} {_layout(el.n, int(loc))}")
    return kind + (" = ".join(names) if names else f"coordinate {j} (not of a beam)")


def _layout(nn: int, k: int) -> str:
    """Entry k of an element's coordinate layout with nn nodes (moving_node_beam module doc)."""
    xyz = "xyz"
    if k < 3 * nn:
        return f"r_{k // 3 + 1}.{xyz[k % 3]}"
    k -= 3 * nn
    if k < 12:
        return ["r'_1", "r'_n", "r''_1", "r''_n"][k // 3] + f".{xyz[k % 3]}"
    k -= 12
    if k < 2 * nn:
        return f"gamma_{k + 1}" if k < nn else f"gamma'_{k - nn + 1}"
    return ["s_1", "s_n"][k - 2 * nn]


def probe(ts, t0: float, span: float = 0.5):
    """RK45 (rtol 1e-6, atol 1e-7) over [t0, t0 + span] from the scene's state at t0: (steps,
    right-hand sides, median step s, median error norm, counts of the dominant component)."""
    y0 = start_state(t0)
    s = RK45(ts.model.rhs, t0, y0, t0 + span, rtol=1e-6, atol=1e-7)
    top, hs, norms = collections.Counter(), [], []
    while s.status == "running":
        s.step()
        if s.status == "failed":
            raise RuntimeError(f"RK45 failed at t = {s.t}")
        h = s.t - s.t_old
        ratio = np.abs(h * (s.K.T @ s.E)) / (1e-7 + 1e-6 * np.maximum(np.abs(s.y_old),
                                                                       np.abs(s.y)))
        if s.status == "running":             # the last step is cut to land on t0 + span
            hs.append(h)
            norms.append(float(np.sqrt(np.mean(ratio ** 2))))
            top[int(np.argmax(ratio))] += 1
    return len(hs), s.nfev, float(np.median(hs)), float(np.median(norms)), top


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", type=float, default=0.5)
    ap.add_argument("--probe", type=float, nargs="*", default=[3.0, 8.0])
    ap.add_argument("--out", default=os.path.join(_HERE, "results", "paper_scene_phases.md"))
    a = ap.parse_args(argv)
    cpu0, load0 = cpu_times(), os.getloadavg()
    scene = load_scene(SCENE)
    marks = []
    w0 = time.perf_counter()
    res = simulate(scene, progress=lambda t, wall: marks.append((float(t), float(wall))))
    command = time.perf_counter() - w0
    st = res.stats
    T = np.array([m[0] for m in marks])
    W = np.array([m[1] for m in marks])

    def window(t_a, t_b):
        sel = (T > t_a) & (T <= t_b + 1e-9)
        i = np.nonzero(sel)[0]
        if len(i) == 0:
            return 0.0, 0, float("nan")
        w_a = W[i[0] - 1] if i[0] > 0 else 0.0
        return float(W[i[-1]] - w_a), len(i), (t_b - t_a) / len(i)

    ts = system()
    probes = [(t0, *probe(ts, t0)) for t0 in a.probe]
    cpu1, load1 = cpu_times(), os.getloadavg()
    lines = [
        "# The paper scene's dynamics phase by phase",
        "",
        f"`{SCENE}` (20 s, `solver.method = \"auto\"`) run whole by `simulate`; the wall times "
        "are the integration's own clock between accepted steps (progress callback), the "
        "command's start-up and outputs not included.  Written by "
        "`benchmarks/paper_scene_phases.py` (its docstring describes the method).",
        "",
        "Machine:",
        "",
        *machine_lines(cpu0, cpu1, load0, load1),
        "",
        f"`simulate` took {command:.2f} s, the integration {st['wall_time_s']:.2f} s: "
        f"{st['n_steps']} steps, {st['n_rhs']} right-hand sides, {st['n_jacobians']} "
        f"structured Jacobians, {st['n_method_switches']} method switches.",
        "",
        "| phase | t (s) | wall (s) | steps | mean step (ms) |",
        "|---|---|---|---|---|",
    ]
    for name, t_a, t_b in phases(scene):
        wall, steps, mean = window(t_a, t_b)
        lines.append(f"| {name} | {t_a:g}–{t_b:g} | {wall:.2f} | {steps} | {mean * 1e3:.1f} |")
    lines += ["", f"Per {a.bin:g} s:", "", "| t (s) | wall (s) | steps | mean step (ms) |",
              "|---|---|---|---|"]
    for t_a in np.arange(0.0, scene["solver"]["t_end"] - 1e-9, a.bin):
        wall, steps, mean = window(float(t_a), float(t_a + a.bin))
        lines.append(f"| {t_a:g}–{t_a + a.bin:g} | {wall:.2f} | {steps} | {mean * 1e3:.1f} |")
    lines += ["", "RK45 (rtol 1e-6, atol 1e-7) for 0.5 s from the scene's state: what sets "
              "the step.", "",
              "| from t (s) | steps | right-hand sides | median step (ms) | median error norm "
              "| dominant component of the error estimate (share of steps) |",
              "|---|---|---|---|---|---|"]
    for t0, steps, nfev, h_med, norm, top in probes:
        share = ", ".join(f"{coordinate_label(ts.model, i)} ({100 * c / steps:.0f} %)"
                          for i, c in top.most_common(2))
        lines.append(f"| {t0:g} | {steps} | {nfev} | {h_med * 1e3:.2f} | {norm:.2f} | {share} |")
        print(lines[-1], flush=True)
    write_markdown(a.out, lines)


if __name__ == "__main__":
    main()
