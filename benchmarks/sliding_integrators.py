"""Which integrator the paper scene's sliding phase wants: work against accuracy of explicit
and implicit methods over a window of steady extraction, and the spectrum behind it.

One command (from the repository root, pinned to one core):

    OPENBLAS_NUM_THREADS=1 taskset -c 0 python benchmarks/sliding_integrators.py

The paper scene (``telescopic_extraction``: 25 t, friction, stress filter h_f = 0.01 s, 8
sub-elements, n_dof 313) is run by ``simulate`` to t = ``--t0`` (default 4 s: the end of the
drive's ramp, the booms slide at 0.5 m/s from there to 12 s); from that state each integrator of
scipy runs the window [t0, t0 + ``--window``] on ``Model.rhs``:

* RK45 (the scene's method in the sliding; the paper's ode45) and DOP853 at several rtol
  (atol = rtol / 10, the scene's ratio);
* BDF and Radau with the structured state Jacobian (``sim_core.model.state_jacobian``, the one
  ``solver.method = "BDF"`` / ``"auto"`` use), dense LU;
* RK45 on the same scene with the filter window h_f = 0.03 s, where the filter's eigenvalue
  pair is 3 x closer to the origin: where RK45 then takes the same steps, they are set by
  accuracy, not stability.

Columns: steps, right-hand sides, structured Jacobians (each ~100 right-hand sides of work),
median step, wall time of the window (this process; state it with the machine lines), and the
error of the window's end against a reference (RK45 at rtol 1e-10 on the same model): the tip
position (m, the payload's point) and the largest velocity component (m/s or rad/s).

The spectrum: eigenvalues of the structured state Jacobian at t0 + window / 2, counted within 2 %
of the filter's pair lambda = (3/h_f)(-1/2 +- i sqrt(5/12)) (docs/model.md, Time integration),
and the largest outside it.  ``--out FILE``: the markdown table (default
``benchmarks/results/sliding_integrators.md``) with the machine state
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
sys.path.insert(0, _ROOT)
sys.path.insert(0, _HERE)

from scipy.integrate import BDF, DOP853, RK45, Radau  # noqa: E402

from _machine import cpu_times, machine_lines  # noqa: E402
from sim_core import load_scene, simulate  # noqa: E402
from sim_core.model.state_jacobian import state_jacobian  # noqa: E402
from sim_core.result import atomic_write_bytes  # noqa: E402
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium  # noqa: E402
from sim_core.systems.telescopic.schema import params_from_scene  # noqa: E402

SCENE = "telescopic_extraction"


def system(filter_h: float | None = None):
    """The paper scene's TelescopicSystem (rope pretension set by its initial equilibrium, as in
    a run), optionally with another filter window."""
    over = {} if filter_h is None else {"filtering.h": filter_h}
    ts = build_telescopic(params_from_scene(load_scene(SCENE, over)))
    initial_equilibrium(ts)
    return ts


def start_state(t0: float, filter_h: float | None = None) -> np.ndarray:
    """The scene's state at t0 (its own run from the static equilibrium)."""
    over = {"solver.t_end": t0, "solver.n_output": 2}
    if filter_h is not None:
        over["filtering.h"] = filter_h
    return np.asarray(simulate(load_scene(SCENE, over))["state"][-1], dtype=float)


def tip(ts, t: float, y: np.ndarray) -> np.ndarray:
    n = ts.model.n_dof
    Q, _ = ts.model.full_state(t, y[:n], y[n:])
    return np.asarray(ts.tip(Q)[0], dtype=float)


def run(ts, cls, t0, t1, y0, rtol, atol, implicit=False):
    """One window with scipy's ``cls``: (end state, steps, rhs, jacobians, median step, wall)."""
    m = ts.model
    count = {"rhs": 0, "jac": 0}

    def fun(t, y):
        count["rhs"] += 1
        return m.rhs(t, y)

    def jac(t, y):
        count["jac"] += 1
        return state_jacobian(m, t, y)

    kw = {"jac": jac} if implicit else {}
    s = cls(fun, t0, y0.copy(), t1, rtol=rtol, atol=atol, **kw)
    steps = []
    w0 = time.perf_counter()
    while s.status == "running":
        s.step()
        steps.append(s.t - s.t_old)
    wall = time.perf_counter() - w0
    if s.status != "finished":
        raise RuntimeError(f"{cls.__name__} rtol {rtol:g} failed at t = {s.t}")
    return s.y, len(steps), count["rhs"], count["jac"], float(np.median(steps)), wall


def census(ts, t, y, filter_h):
    """(eigenvalues within 2 % of the filter pair, their count of all, largest |lambda| outside,
    the filter pair) of the structured Jacobian at (t, y)."""
    ev = np.linalg.eigvals(state_jacobian(ts.model, t, y))
    pair = (3.0 / filter_h) * (-0.5 + 1j * np.sqrt(5.0 / 12.0))
    near = np.minimum(np.abs(ev - pair), np.abs(ev - np.conj(pair))) <= 0.02 * abs(pair)
    return int(near.sum()), len(ev), float(np.max(np.abs(ev[~near]))), pair


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--t0", type=float, default=4.0)
    ap.add_argument("--window", type=float, default=2.0)
    ap.add_argument("--out", default=os.path.join(_HERE, "results", "sliding_integrators.md"))
    a = ap.parse_args(argv)
    cpu0, load0 = cpu_times(), os.getloadavg()
    t0, t1 = a.t0, a.t0 + a.window
    ts = system()
    y0 = start_state(t0)
    ref = run(ts, RK45, t0, t1, y0, 1e-10, 1e-11)
    cases = [("RK45", RK45, r, False, None) for r in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)]
    cases += [("DOP853", DOP853, r, False, None) for r in (1e-6, 1e-8)]
    cases += [("BDF", BDF, r, True, None) for r in (1e-4, 1e-5, 1e-6)]
    cases += [("Radau", Radau, r, True, None) for r in (1e-4, 1e-5, 1e-6)]
    cases += [("RK45, h_f = 0.03 s", RK45, r, False, 0.03) for r in (1e-4, 1e-6)]
    rows = []
    other = {}
    for name, cls, rtol, implicit, fh in cases:
        if fh is None:
            tsx, yx, refx = ts, y0, ref
        else:
            if fh not in other:
                tsf, yf = system(fh), start_state(t0, fh)
                other[fh] = (tsf, yf, run(tsf, RK45, t0, t1, yf, 1e-10, 1e-11))
            tsx, yx, refx = other[fh]
        y, steps, nrhs, njac, hmed, wall = run(tsx, cls, t0, t1, yx, rtol, rtol / 10, implicit)
        n = tsx.model.n_dof
        e_tip = float(np.max(np.abs(tip(tsx, t1, y) - tip(tsx, t1, refx[0]))))
        e_vel = float(np.max(np.abs(y[n:] - refx[0][n:])))
        rows.append((name, rtol, steps, nrhs, njac, hmed, wall, e_tip, e_vel))
        print(f"{name:20s} rtol {rtol:7.0e} steps {steps:5d} rhs {nrhs:6d} jac {njac:3d} "
              f"h {hmed * 1e3:6.2f} ms wall {wall:6.2f} s tip {e_tip:.2e} m vel {e_vel:.2e}",
              flush=True)
    tm = 0.5 * (t0 + t1)
    y_mid = start_state(tm)
    near, total, rest, pair = census(ts, tm, y_mid, 0.01)
    cpu1, load1 = cpu_times(), os.getloadavg()
    lines = [
        "# The paper scene's sliding phase: integrators, work and accuracy",
        "",
        f"`{SCENE}` from its own run's state at t = {t0:g} s, the window [{t0:g}, {t1:g}] s "
        "of steady extraction (0.5 m/s, friction sliding) with scipy's integrators on "
        "`Model.rhs`; atol = rtol / 10.  Errors at the window's end against RK45 at rtol "
        "1e-10 on the same model: the payload point's position (m) and the largest velocity "
        "component.  Wall: this window in this process.  Written by "
        "`benchmarks/sliding_integrators.py` (its docstring describes the cases).",
        "",
        "Machine:",
        "",
        *machine_lines(cpu0, cpu1, load0, load1),
        "",
        "| method | rtol | steps | right-hand sides | structured Jacobians | median step (ms) "
        "| wall (s) | tip error (m) | velocity error |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, rtol, steps, nrhs, njac, hmed, wall, e_tip, e_vel in rows:
        lines.append(f"| {name} | {rtol:.0e} | {steps} | {nrhs} | {njac} | {hmed * 1e3:.2f} | "
                     f"{wall:.2f} | {e_tip:.1e} | {e_vel:.1e} |")
    lines += [
        "",
        f"Spectrum of the structured state Jacobian at t = {tm:g} s: {near} of {total} "
        f"eigenvalues lie within 2 % of the filter's pair {pair.real:.0f} ± {abs(pair.imag):.0f}i "
        f"1/s; the largest |λ| outside is {rest:.0f} 1/s.  Dormand–Prince's stability boundary "
        f"along the pair's ray is |hλ| ≈ 3.36, h ≈ {3.36 / abs(pair) * 1e3:.1f} ms.",
    ]
    atomic_write_bytes(a.out, ("\n".join(lines) + "\n").encode())
    print("wrote", a.out)


if __name__ == "__main__":
    main()
