"""Which integrator the paper scene's sliding phase wants: work against accuracy of explicit
and implicit methods over a window of steady extraction, and the spectrum behind it.

One command (from the repository root, pinned to one core):

    OPENBLAS_NUM_THREADS=1 taskset -c 0 python benchmarks/sliding_integrators.py

The paper scene (``telescopic_extraction``: 25 t, friction, stress filter h_f = 0.01 s, 8
sub-elements, n_dof 313) is run by ``simulate`` to t = ``--t0`` (default 4 s: the end of the
drive's ramp, the booms slide at 0.5 m/s from there to 12 s); from that state each integrator
runs the window [t0, t0 + ``--window``] on ``Model.rhs``:

* RK45 (the scene's method in the sliding; the paper's ode45) and DOP853 at several rtol
  (atol = rtol / 10, the scene's ratio);
* BDF and Radau with the structured state Jacobian (``sim_core.model.state_jacobian``, the one
  ``solver.method = "BDF"`` / ``"auto"`` use), dense LU;
* generalized-alpha (``sim_core.integrate.generalized_alpha``, rho_inf 0.9) at fixed steps on
  the first-order model as ``M = I``, ``f = z_ddot(t, z, z_dot)``, its Newton tangent from the
  structured state Jacobian: the implicit method of ``solver.method = "generalized_alpha"``
  (second order) through the sliding;
* the Rosenbrock-W method ROS34PW2 (J. Rang, L. Angermann, "New Rosenbrock W-methods of order
  3 for partial differential algebraic equations of index 1", BIT 45 (2005) 761-787: 4
  stages, order 3 with any Jacobian approximation, L-stable, embedded order 2) with the
  structured Jacobian frozen over ``refresh`` s of simulated time: a linearly implicit method
  whose Newton matrix need not be exact (:func:`run_rosenbrock_w`);
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

import scipy.linalg as sla  # noqa: E402
from scipy.integrate import BDF, DOP853, RK45, Radau  # noqa: E402

from _machine import cpu_times, machine_lines, write_markdown  # noqa: E402
from sim_core import load_scene, simulate  # noqa: E402
from sim_core.integrate.generalized_alpha import integrate_generalized_alpha  # noqa: E402
from sim_core.model.state_jacobian import state_jacobian  # noqa: E402
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


class _FirstOrderAsSecond:
    """``Model.rhs`` (y = (z, z_dot)) as the SecondOrderSystem ``I z_ddot = f(t, z, z_dot)`` of
    :func:`integrate_generalized_alpha`; the tangent (K, C) = (-dz_ddot/dz, -dz_ddot/dz_dot)
    from the structured state Jacobian."""

    def __init__(self, model, count):
        self.model, self.count, self.n = model, count, model.n_dof
        self.eye = np.eye(self.n)

    def mass_and_force(self, t, q, v):
        self.count["rhs"] += 1
        return self.eye, self.model.rhs(t, np.concatenate([q, v]))[self.n:]

    def tangent(self, t, q, v):
        self.count["jac"] += 1
        J = state_jacobian(self.model, t, np.concatenate([q, v]))
        return -J[self.n:, :self.n], -J[self.n:, self.n:]


def run_alpha(ts, t0, t1, y0, h, rho_inf=0.9):
    """The window with generalized-alpha at the fixed step h (s); run()'s tuple."""
    count = {"rhs": 0, "jac": 0}
    n = ts.model.n_dof
    w0 = time.perf_counter()
    r = integrate_generalized_alpha(_FirstOrderAsSecond(ts.model, count), (t0, t1), y0[:n],
                                    y0[n:], h=h, rho_inf=rho_inf, rtol=1e-6, atol=1e-7,
                                    t_eval=[t1])
    wall = time.perf_counter() - w0
    return r.y[-1], r.stats.n_steps, count["rhs"], count["jac"], (t1 - t0) / r.stats.n_steps, wall


# ROS34PW2 (Rang & Angermann 2005, Table 4.1): alpha_ij, gamma_ij (i > j), gamma, b, b_hat
_RW_GAMMA = 4.3586652150845900e-01
_RW_A = np.array([[0.0, 0.0, 0.0, 0.0],
                  [8.7173304301691801e-01, 0.0, 0.0, 0.0],
                  [8.4457060015369423e-01, -1.1299064236484185e-01, 0.0, 0.0],
                  [0.0, 0.0, 1.0, 0.0]])
_RW_G = np.array([[0.0, 0.0, 0.0, 0.0],
                  [-8.7173304301691801e-01, 0.0, 0.0, 0.0],
                  [-9.0338057013044082e-01, 5.4180672388095326e-02, 0.0, 0.0],
                  [2.4212380706095346e-01, -1.2232505839045147e+00, 5.4526025533510214e-01, 0.0]])
_RW_B = np.array([2.4212380706095346e-01, -1.2232505839045147e+00, 1.5452602553351020e+00,
                  4.3586652150845900e-01])
_RW_BHAT = np.array([3.7810903145819369e-01, -9.6042292212423178e-02, 0.5,
                     2.1793326075422950e-01])


def run_rosenbrock_w(ts, t0, t1, y0, rtol, atol, refresh):
    """The window with ROS34PW2 (module doc); run()'s tuple.

    Stages (Hairer & Wanner, Solving ODEs II, Sect. IV.7, in the W-form for the autonomised
    system, whose approximate Jacobian has no time column):
    (I - gamma h J) k_i = h f(t + c_i h, y + sum_j alpha_ij k_j) + h J sum_j gamma_ij k_j,
    y1 = y + sum b_i k_i, error estimate sum (b_i - b_hat_i) k_i, scipy's RMS norm, step factor
    clip(0.9 err^(-1/3), 0.2, 5), h kept for a factor in [1, 1.2).  J is the structured state
    Jacobian [[0, I], [J_zz, J_zv]], formed anew once ``refresh`` s have passed since the last
    one; I - gamma h J is solved through its velocity block I - gamma h J_zv - (gamma h)^2 J_zz
    (one n x n LU per Jacobian and step size)."""
    m = ts.model
    n = m.n_dof
    count = {"rhs": 0, "jac": 0}
    c = _RW_A.sum(axis=1)
    t, y, h = t0, y0.copy(), 0.01
    steps = []
    lu = key = None
    t_jac = -np.inf
    w0 = time.perf_counter()
    while t < t1 - 1e-12 * (t1 - t0):
        h = min(h, t1 - t)
        if t - t_jac >= refresh:
            J = state_jacobian(m, t, y)
            count["jac"] += 1
            Jzz, Jzv, t_jac = J[n:, :n], J[n:, n:], t
        if key != (h, t_jac):
            gh = _RW_GAMMA * h
            lu = sla.lu_factor(np.eye(n) - gh * Jzv - gh * gh * Jzz, check_finite=False)
            key = (h, t_jac)
        k = np.zeros((4, 2 * n))
        for i in range(4):
            count["rhs"] += 1
            r = h * m.rhs(t + c[i] * h, y + _RW_A[i, :i] @ k[:i])
            if i:
                s = _RW_G[i, :i] @ k[:i]
                r[:n] += h * s[n:]
                r[n:] += h * (Jzz @ s[:n] + Jzv @ s[n:])
            kv = sla.lu_solve(lu, r[n:] + _RW_GAMMA * h * (Jzz @ r[:n]), check_finite=False)
            k[i, :n], k[i, n:] = r[:n] + _RW_GAMMA * h * kv, kv
        y1 = y + _RW_B @ k
        scale = atol + rtol * np.maximum(np.abs(y), np.abs(y1))
        err = float(np.sqrt(np.mean(((_RW_B - _RW_BHAT) @ k / scale) ** 2)))
        if not np.isfinite(err):
            raise RuntimeError(f"ROS34PW2 rtol {rtol:g}: non-finite state at t = {t}")
        if err <= 1.0:
            t, y = t + h, y1
            steps.append(h)
        fac = min(5.0, max(0.2, 0.9 * err ** (-1.0 / 3.0))) if err > 0.0 else 5.0
        h *= 1.0 if err <= 1.0 and 1.0 <= fac < 1.2 else fac
    wall = time.perf_counter() - w0
    return y, len(steps), count["rhs"], count["jac"], float(np.median(steps)), wall


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

    def scipy_case(cls, rtol, implicit):
        return f"{rtol:.0e}", lambda tsx, yx: run(tsx, cls, t0, t1, yx, rtol, rtol / 10, implicit)

    cases = [("RK45", *scipy_case(RK45, r, False), None) for r in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)]
    cases += [("DOP853", *scipy_case(DOP853, r, False), None) for r in (1e-6, 1e-8)]
    cases += [("BDF", *scipy_case(BDF, r, True), None) for r in (1e-4, 1e-5, 1e-6)]
    cases += [("Radau", *scipy_case(Radau, r, True), None) for r in (1e-4, 1e-5, 1e-6)]
    cases += [("generalized-alpha, rho_inf 0.9", f"h = {h * 1e3:g} ms",
               lambda tsx, yx, h=h: run_alpha(tsx, t0, t1, yx, h), None)
              for h in (0.02, 0.01, 0.005)]
    cases += [(f"ROS34PW2, Jacobian every {every:g} s", f"{r:.0e}",
               lambda tsx, yx, r=r, every=every: run_rosenbrock_w(tsx, t0, t1, yx, r, r / 10,
                                                                  every), None)
              for r, every in ((1e-5, 0.1), (1e-6, 0.1), (1e-6, 0.5))]
    cases += [("RK45, h_f = 0.03 s", *scipy_case(RK45, r, False), 0.03) for r in (1e-4, 1e-6)]
    rows = []
    other = {}
    for name, setting, runner, fh in cases:
        if fh is None:
            tsx, yx, refx = ts, y0, ref
        else:
            if fh not in other:
                tsf, yf = system(fh), start_state(t0, fh)
                other[fh] = (tsf, yf, run(tsf, RK45, t0, t1, yf, 1e-10, 1e-11))
            tsx, yx, refx = other[fh]
        y, steps, nrhs, njac, hmed, wall = runner(tsx, yx)
        n = tsx.model.n_dof
        e_tip = float(np.max(np.abs(tip(tsx, t1, y) - tip(tsx, t1, refx[0]))))
        e_vel = float(np.max(np.abs(y[n:] - refx[0][n:])))
        rows.append((name, setting, steps, nrhs, njac, hmed, wall, e_tip, e_vel))
        print(f"{name:34s} {setting:9s} steps {steps:5d} rhs {nrhs:6d} jac {njac:3d} "
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
        "of steady extraction (0.5 m/s, friction sliding) with scipy's integrators, "
        "generalized-alpha and the Rosenbrock-W method ROS34PW2 on `Model.rhs`; "
        "atol = rtol / 10.  Errors at the window's end against RK45 at rtol "
        "1e-10 on the same model: the payload point's position (m) and the largest velocity "
        "component.  Wall: this window in this process.  Written by "
        "`benchmarks/sliding_integrators.py` (its docstring describes the cases).",
        "",
        "Machine:",
        "",
        *machine_lines(cpu0, cpu1, load0, load1),
        "",
        "| method | rtol or step | steps | right-hand sides | structured Jacobians "
        "| median step (ms) | wall (s) | tip error (m) | velocity error |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, setting, steps, nrhs, njac, hmed, wall, e_tip, e_vel in rows:
        lines.append(f"| {name} | {setting} | {steps} | {nrhs} | {njac} | {hmed * 1e3:.2f} | "
                     f"{wall:.2f} | {e_tip:.1e} | {e_vel:.1e} |")
    lines += [
        "",
        f"Spectrum of the structured state Jacobian at t = {tm:g} s: {near} of {total} "
        f"eigenvalues lie within 2 % of the filter's pair {pair.real:.0f} ± {abs(pair.imag):.0f}i "
        f"1/s; the largest |λ| outside is {rest:.0f} 1/s.  Dormand–Prince's stability boundary "
        f"along the pair's ray is |hλ| ≈ 3.36, h ≈ {3.36 / abs(pair) * 1e3:.1f} ms.",
    ]
    write_markdown(a.out, lines)


if __name__ == "__main__":
    main()
