"""Cost growth of the telescopic model: wall time per simulated second vs the number of
sub-elements per spline element and vs the number of booms (2..6, the synchronized drive of
docs/model.md "N-boom drives"), with log-log fitted exponents.

One command (repository root), ~3-5 min, pinned to one core:

    OPENBLAS_NUM_THREADS=1 taskset -c 0 python benchmarks/cost_growth.py

Writes benchmarks/results/cost_growth.md (table and machine state), cost_growth.csv and
cost_growth.png.

Per configuration (case 9.1 stiffness, E = 2.1e12 Pa, 1 t payload, no friction, filter
h = 0.01 s; ``TelescopicParams(n_booms=N, n_nodes=n_sub + 1)``), from the static equilibrium:

* ``rhs_ms``: one ``model.rhs`` (KKT solve), best of 5 repeats of 3 calls (wall time), each
  call at a slightly different state (the point functions keep their last evaluation, so one
  repeated state would time cache hits);
* an RK45 run (rtol 1e-5, atol 1e-6) over T = 0.1 s, the best of 3 runs: steps, RHS
  evaluations, and ``wall_per_sim_s`` = wall time / T.

Wall time (``time.perf_counter``), not process time: the element worker thread, where a second
core is free, waits actively between requests, and process time would count that.  With the
filter on, RK45 is stability-limited (step ~ 1.3 h: the filter mass (h^2/6) K caps the highest
frequency near sqrt(6)/h; SIMULTECH 2020 Eq. 53), so steps per simulated second hardly depend on
the mesh or the number of booms and the growth is that of one RHS.

Fitted exponent p of cost ~ x^p: least squares of log(cost) on log(x).
"""

from __future__ import annotations

import csv
import datetime
import io
import os
import sys
import time

if os.environ.get("OPENBLAS_NUM_THREADS") != "1":
    print("warning: run with OPENBLAS_NUM_THREADS=1 for comparable numbers", file=sys.stderr)

import numpy as np

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..")))

from benchmarks._machine import cpu_times, machine_lines  # noqa: E402
from sim_core.integrate.driver import integrate  # noqa: E402
from sim_core.result import atomic_write_bytes  # noqa: E402
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium  # noqa: E402
from sim_core.systems.telescopic.params import TelescopicParams  # noqa: E402

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
FIELDS = ["sweep", "n_booms", "n_sub", "n_dof", "rhs_ms", "t_sim", "n_steps", "n_rhs", "wall_s",
          "wall_per_sim_s", "status"]
T = 0.1


def measure(n_booms: int, n_sub: int, sweep: str) -> dict:
    p = TelescopicParams(n_booms=n_booms, n_nodes=n_sub + 1, E=2.1e12, payload=1000.0,
                         friction=False, filter_h=0.01)
    ts = build_telescopic(p)
    m = ts.model
    z0, _ = initial_equilibrium(ts)
    y0 = np.concatenate([z0, np.zeros_like(z0)])
    # every call at a state of its own (relative perturbation 1e-9)
    rng = np.random.default_rng(0)
    ys = [y0 + 1e-9 * (np.abs(y0) + 1e-3) * rng.standard_normal(len(y0)) for _ in range(16)]
    m.rhs(0.0, ys[-1])
    best = np.inf
    for r in range(5):
        t0 = time.perf_counter()
        for k in range(3):
            m.rhs(0.0, ys[3 * r + k])
        best = min(best, (time.perf_counter() - t0) / 3)
    row = {"sweep": sweep, "n_booms": n_booms, "n_sub": n_sub, "n_dof": m.n_dof,
           "rhs_ms": 1e3 * best, "t_sim": T}
    try:
        wall = np.inf
        for _ in range(3):                   # the same steps each time (deterministic)
            t0 = time.perf_counter()
            _, _, st = integrate(m, y0, T, {"rtol": 1e-5, "atol": 1e-6, "n_output": 2})
            wall = min(wall, time.perf_counter() - t0)
        row.update(n_steps=st["n_steps"], n_rhs=st["n_rhs"], wall_s=wall, wall_per_sim_s=wall / T,
                   status="ok")
    except Exception as exc:                               # recorded, not hidden
        row.update(status=f"failed: {str(exc)[:60]}")
    print(row, flush=True)
    return row


def fit(x, y) -> float:
    """Slope of the least-squares line log y = p log x + c."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def markdown(rows, fits, machine) -> str:
    """The committed table: one row per configuration, the fitted exponents, the machine."""
    out = ["# Cost growth of the telescopic model", "",
           "Written by `benchmarks/cost_growth.py` (its docstring says how each figure is taken); "
           "reproduce with `OPENBLAS_NUM_THREADS=1 taskset -c 0 python benchmarks/cost_growth.py`."
           "  Case 9.1 stiffness (E = 2.1e12 Pa), 1 t payload, no friction, filter h = 10 ms, "
           "synchronized drive, RK45 rtol 1e-5 over 0.1 s from the static equilibrium; wall "
           "time, best of 3 runs.", "", "Machine:", "", *machine, "",
           "| sweep | booms | sub-el. | DOF | ms / RHS | steps in 0.1 s | RHS evals | "
           "wall s / sim s | status |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ok = r.get("status") == "ok"
        run = (f"{r['n_steps']} | {r['n_rhs']} | {r['wall_per_sim_s']:.2f}" if ok
               else "- | - | -")
        out.append(f"| {r['sweep']} | {r['n_booms']} | {r['n_sub']} | {r['n_dof']} | "
                   f"{r['rhs_ms']:.2f} | {run} | {r['status']} |")
    out += ["", "Fitted exponents (least squares in log-log; a handful of points each, so "
            "+-0.3):", ""]
    for sweep, f in fits.items():
        out.append(f"- {sweep}: " + ", ".join(f"{k} ~ x^{v:.2f}" for k, v in f.items()))
    return "\n".join(out) + "\n"


def main():
    os.makedirs(RESULTS, exist_ok=True)
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    aff = sorted(os.sched_getaffinity(0))
    header = (f"{stamp}; wall time (best of repeats); affinity {aff}; "
              f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    cpu0, load0 = cpu_times(), os.getloadavg()
    rows = [measure(3, n, "sub_elements") for n in (2, 4, 8)]
    rows += [measure(N, 2, "booms") for N in (2, 3, 4, 5, 6)]
    machine = machine_lines(cpu0, cpu_times(), load0, os.getloadavg())
    fits = {}
    for sweep, key in (("sub_elements", "n_sub"), ("booms", "n_booms")):
        rs = [r for r in rows if r["sweep"] == sweep and r.get("status") == "ok"]
        x = [r[key] for r in rs]
        fits[sweep] = {"wall_per_sim_s": fit(x, [r["wall_per_sim_s"] for r in rs]),
                       "rhs_ms": fit(x, [r["rhs_ms"] for r in rs]),
                       "n_dof": fit(x, [r["n_dof"] for r in rs])}
    fh = io.StringIO(newline="")
    fh.write("# " + header + "\n")
    for sweep, f in fits.items():
        fh.write(f"# fitted exponent ({sweep}): " +
                 ", ".join(f"{k} ~ x^{v:.2f}" for k, v in f.items()) + "\n")
    w = csv.DictWriter(fh, FIELDS)
    w.writeheader()
    for r in rows:
        w.writerow({k: r.get(k, "") for k in FIELDS})
    atomic_write_bytes(os.path.join(RESULTS, "cost_growth.csv"), fh.getvalue().encode())
    atomic_write_bytes(os.path.join(RESULTS, "cost_growth.md"),
                       markdown(rows, fits, machine).encode())
    print(fits)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, (sweep, key, label) in zip(axes, (("sub_elements", "n_sub", "sub-elements per spline element (3 booms)"),
                                              ("booms", "n_booms", "number of booms (2 sub-elements)"))):
        rs = [r for r in rows if r["sweep"] == sweep and r.get("status") == "ok"]
        x = np.array([r[key] for r in rs], float)
        for yk, mk, unit in (("wall_per_sim_s", "o-", "wall s / simulated s"), ("rhs_ms", "s--", "ms per RHS")):
            y = np.array([r[yk] for r in rs])
            ax.loglog(x, y, mk, label=f"{unit} (slope {fits[sweep][yk]:.2f})")
        ax.set_xlabel(label)
        ax.set_xticks(x)
        ax.set_xticklabels([f"{v:g}" for v in x])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Telescopic model cost growth (RK45, filter h = 0.01 s); " + header, fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    atomic_write_bytes(os.path.join(RESULTS, "cost_growth.png"), buf.getvalue())


if __name__ == "__main__":
    main()
