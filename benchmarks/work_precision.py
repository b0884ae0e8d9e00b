"""Work-precision study (issue 5, "show what accuracy costs in time").

One command (repository root):

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/work_precision.py --quick   # < 5 min
    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/work_precision.py           # full

Quick mode: one telescopic mesh (2 sub-elements) and none of the rows that cannot finish in
its budget (those are full-mode rows): 3 min 44 s on the shared 2-core machine (2026-11-23;
~11 min before that trim); 57 s with the compiled kernels (2026-11-24).  Full mode
(2026-11-24): beam part 9 min; telescopic part 14 min as
``--part telescopic --tag full_T1 --skip-unfiltered --implicit-budget 300``.  Each run has a process-time budget (row status "budget").

Writes benchmarks/results/work_precision_beam.csv, work_precision_telescopic.csv and the
log-log PNGs work_precision_beam.png, work_precision_telescopic.png (error vs wall seconds per
simulated second).  ``--part beam`` / ``--part telescopic`` runs one part only.

(a) Beam, docs/model.md#check-moving-load: force P crossing a simply supported 10 m steel beam
    at speed c = alpha w1 L / pi (alpha = c/c_crit = 0.5).  Error = max over 41 output times of the
    midspan deflection error (m) against Fryba's series (sim_core.validation.closed_form,
    Fryba 1972 Ch. 1, 31 terms) AND against a converged reference (quick: 8 sub-elements,
    RK45 rtol 1e-7, filter h = 0.3 ms; full: 16 sub-elements, rtol 1e-9, h = 0.1 ms; the
    unfiltered model is too stiff for a reference in reasonable time, see docs/performance.md).  Sweeps: sub-elements (2, 4, 8, 16), rtol, filter h (SIMULTECH 2020
    Eq. 53), integrator (RK45 on model.rhs; generalized-alpha rho_inf = 0.8 adaptive and scipy
    Radau, both on Model.mass_and_force with finite-difference tangents).
(b) Telescopic extraction (Zhao-Qi-Wang 2024 Sec. 9), window [0, T] from the static
    equilibrium; case 9.1 (nearly rigid, E = 2.1e12 Pa, 1 t payload) and the flexible 25 t case.
    Error = |tip position(T) - reference tip position(T)| (m, Euclidean, boom-3 top centre).
    Reference: the finest mesh of the sweep, smallest filter h of the sweep, RK45 rtol 1e-9.
    Implicit integrators use :class:`sim_core.integrate.index1.Index1System` (M = I,
    f = Baumgarte-stabilized KKT accelerations).

Every row records wall time (s), wall seconds per simulated second, steps, model evaluations
(RHS / mass_and_force calls, including those of finite-difference Jacobians), Jacobian
evaluations and rejected steps (None where scipy does not report them).  Wall time is the
process time of one run on a machine shared with other jobs: compare rows of one run only.
"""

from __future__ import annotations

import argparse
import csv
import datetime
import math
import os
import sys
import time

if os.environ.get("OPENBLAS_NUM_THREADS") != "1":
    print("warning: run with OPENBLAS_NUM_THREADS=1 for comparable numbers", file=sys.stderr)

import numpy as np

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..")))

from sim_core.errors import SimulationError  # noqa: E402
from sim_core.integrate import integrate_generalized_alpha, integrate_scipy  # noqa: E402
from sim_core.integrate.driver import integrate  # noqa: E402
from sim_core.integrate.index1 import Index1System  # noqa: E402
from sim_core.model.boundary import (
    boundary_condition,
    reference_basis,  # noqa: E402
)
from sim_core.model.model import Model  # noqa: E402
from sim_core.physics.beam.moving_node_beam import Beam, BeamSection  # noqa: E402
from sim_core.physics.effects import Elasticity, Inertia, PointLoad, StressFilter  # noqa: E402
from sim_core.validation.closed_form import fryba_deflection  # noqa: E402

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
FIELDS = ["case", "integrator", "n_sub", "rtol", "filter_h", "t_sim", "status", "wall_s",
          "wall_per_sim_s", "n_steps", "n_evals", "n_jac", "n_rejected", "err_closed_m",
          "err_ref_m", "peak_m"]

# -- beam (docs/model.md#check-moving-load) --------------------------------------------------
E, G_MOD, RHO, L = 2.1e11, 8.0e10, 7850.0, 10.0
A, I_T, I_B = 1e-2, 1e-5, 1.3e-5
P_LOAD = 500.0          # N; static midspan deflection P L^3/(48 EI) = 5.0 mm
ALPHA = 0.5             # c / c_crit (Fryba's speed parameter)


def beam_section() -> BeamSection:
    J = I_T + I_B
    return BeamSection(EA=E * A, GJ=G_MOD * J, EI_t=E * I_T, EI_b=E * I_B, rhoA=RHO * A,
                       J_s=RHO * J, J_t=0.0, J_b=0.0)


def beam_case():
    """(c m/s, t_end s, w1 rad/s): w1 = (pi/L)^2 sqrt(EI/m), c = alpha w1 L / pi (Fryba 1972)."""
    w1 = (math.pi / L) ** 2 * math.sqrt(E * I_T / (RHO * A))
    c = ALPHA * w1 * L / math.pi
    return c, L / c, w1


def beam_model(n_sub: int, filter_h: float):
    c, t_end, _ = beam_case()
    load = PointLoad(0, lambda t: min(c * t, L), lambda t: np.array([0.0, 0.0, -P_LOAD]))
    b = Beam("b", L, beam_section(), (0.0, L), n_nodes=n_sub + 1,
             reference_basis=reference_basis([1, 0, 0]))
    cons = [boundary_condition([0], [b], 0, "left", "pinned", [0, 0, 0]),
            boundary_condition([0], [b], 0, "right", "roller", [L, 0, 0], [1, 0, 0])]
    eff = [Inertia(), Elasticity()] + ([StressFilter(filter_h)] if filter_h > 0 else [])
    model = Model([b], eff, [load], cons)
    Q0 = b.straight_coordinates([0, 0, 0], [1, 0, 0])
    z0, zd0 = model.reduced_state(0.0, Q0, np.zeros_like(Q0))
    return model, z0, zd0


BUDGET = [20.0]          # s of process time per run; exceeded -> row status "budget"


class _Budget:
    """SecondOrderSystem proxy that aborts a run after BUDGET[0] s of process time."""

    def __init__(self, system):
        self.system, self.n, self.t0 = system, system.n, time.process_time()

    def check(self, t):
        if time.process_time() - self.t0 > BUDGET[0]:
            raise SimulationError(t, f"budget {BUDGET[0]:g} s exceeded")

    def mass_and_force(self, t, q, v):
        self.check(t)
        return self.system.mass_and_force(t, q, v)


def run_integrator(integrator, system_for_implicit, rk_model, z0, zd0, t_end, rtol, t_eval):
    """-> (q at t_eval (k, n), stats dict).  atol = rtol * 1e-3 (m, rad; m/s, rad/s)."""
    atol = 1e-3 * rtol
    n = z0.size
    if integrator in ("RK45", "auto"):           # sim_core.integrate.driver.integrate on model.rhs
        b = _Budget(system_for_implicit)
        t, ys, st = integrate(rk_model, np.concatenate([z0, zd0]), t_end,
                              {"rtol": rtol, "atol": atol, "n_output": len(t_eval),
                               "method": integrator}, progress=lambda t, w: b.check(t))
        return ys[:, :n], {"n_steps": st["n_steps"], "n_evals": st["n_rhs"],
                           "n_jac": st.get("n_jacobians", 0), "n_rejected": None}
    if integrator == "GA":
        r = integrate_generalized_alpha(_Budget(system_for_implicit), (0.0, t_end), z0, zd0, rho_inf=0.8,
                                        rtol=rtol, atol=atol, t_eval=t_eval)
    else:
        r = integrate_scipy(_Budget(system_for_implicit), (0.0, t_end), z0, zd0, method=integrator,
                            rtol=rtol, atol=atol, t_eval=t_eval)
    s = r.stats
    return r.q, {"n_steps": s.n_steps, "n_evals": s.n_force_evaluations,
                 "n_jac": s.n_jacobian_evaluations, "n_rejected": s.n_rejected}


def midspan(model, ts, qs):
    """Midspan deflection w (m, positive along the load, -Z)."""
    return np.array([-model.point(0, L / 2, model.full_state(t, q, 0 * q)[0])[0][2]
                     for t, q in zip(ts, qs)])


def beam_run(n_sub, integrator, rtol, filter_h, t_eval):
    c, t_end, _ = beam_case()
    model, z0, zd0 = beam_model(n_sub, filter_h)
    w0 = time.process_time()
    row = {"case": "beam_fryba", "integrator": integrator, "n_sub": n_sub, "rtol": rtol,
           "filter_h": filter_h, "t_sim": t_end}
    try:
        q, st = run_integrator(integrator, model, model, z0, zd0, t_end, rtol, t_eval)
        row["status"] = "ok"
    except SimulationError as exc:
        row.update(status=("budget" if "budget" in str(exc) else "failed") + f": t={exc.t:.3g} s", wall_s=time.process_time() - w0)
        return row, None
    wall = time.process_time() - w0
    row.update(st, wall_s=wall, wall_per_sim_s=wall / t_end)
    return row, midspan(model, t_eval, q)


def part_beam(quick: bool, out_rows: list):
    c, t_end, w1 = beam_case()
    t_eval = np.linspace(0.0, t_end, 41)
    w_fryba = fryba_deflection(L / 2, t_eval, P_LOAD, c, L, E * I_T, RHO * A, n_terms=31)
    peak = float(np.max(np.abs(w_fryba)))
    print(f"[beam] Fryba alpha={ALPHA}: c = {c:.3f} m/s, crossing {t_end:.4f} s, "
          f"peak midspan {peak * 1e3:.3f} mm", flush=True)
    # Without the stress filter the axial / high bending modes of the quintic splines make
    # RK45 stability-limited (h ~ 1e-5 s) and the implicit error test resolve them: the filter
    # (h^2/6) K mass caps the highest frequency near sqrt(6)/h (SIMULTECH 2020, Eq. 53), so the
    # reference is a small-h filtered run; its filter error shows in the h sweep.
    BUDGET[0] = 120.0 if quick else 1200.0
    ref_n, ref_h, ref_r = (8, 3e-4, 1e-7) if quick else (16, 1e-4, 1e-9)
    ref_row, w_ref = beam_run(ref_n, "RK45", ref_r, ref_h, t_eval)
    if w_ref is None:
        raise SystemExit(f"beam reference failed: {ref_row}")
    print(f"  reference ({ref_n} sub, RK45 rtol {ref_r:g}, h {ref_h:g} s): "
          f"{ref_row['wall_s']:.1f} s, err vs Fryba {np.max(np.abs(w_ref - w_fryba)):.3e} m",
          flush=True)
    ref_row.update(peak_m=peak, err_closed_m=float(np.max(np.abs(w_ref - w_fryba))),
                   err_ref_m=0.0, case="beam_fryba_REFERENCE")
    out_rows.append(ref_row)
    BUDGET[0] = 15.0 if quick else 300.0
    configs = []
    h0 = 1e-3
    for r in ((1e-3, 1e-5, 1e-7) if quick else (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)):
        configs.append((4, "RK45", r, h0))
    # quick mode leaves out the rows that hit its 15 s budget in the last full measurement
    # (unfiltered implicit runs, Radau at rtol 1e-4, RK45 at h = 0.3 ms): full mode only
    for ig in ("GA", "Radau"):
        for r in ((1e-3,) if quick and ig == "Radau" else (1e-3, 1e-4) if quick
                  else (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)):
            configs.append((4, ig, r, h0))
        if not quick:
            configs.append((4, ig, 1e-3, 0.0))               # unfiltered: implicit only
    for n in ((2, 8) if quick else (2, 8, 16)):
        configs.append((n, "RK45", 1e-5, h0))
        configs.append((n, "GA", 1e-4, h0))
    for h in ((3e-3, 1e-2) if quick else (1e-4, 3e-4, 3e-3, 1e-2)):
        configs.append((4, "RK45", 1e-5, h))
    if not quick:
        configs.append((4, "BDF", 1e-4, h0))
        configs.append((4, "RK45", 1e-5, 0.0))               # unfiltered explicit
    for n, ig, r, h in configs:
        row, w = beam_run(n, ig, r, h, t_eval)
        row["peak_m"] = peak
        if w is not None:
            row["err_closed_m"] = float(np.max(np.abs(w - w_fryba)))
            row["err_ref_m"] = float(np.max(np.abs(w - w_ref)))
        out_rows.append(row)
        print("  " + fmt(row), flush=True)


# -- telescopic ------------------------------------------------------------------------------
_EQ_CACHE: dict = {}


def telescopic_system(case: str, n_sub: int, filter_h: float):
    """Build the scene and its static equilibrium (cached per case and mesh: the filter does
    not change the statics).  initial_equilibrium also sets the retraction-rope length, so it
    is re-applied to every freshly built system."""
    from sim_core.systems.telescopic.params import TelescopicParams
    from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
    kw = dict(E=2.1e12, payload=1000.0) if case == "rigid_9.1" else dict(payload=25000.0)
    p = TelescopicParams(n_nodes=n_sub + 1, filter_h=filter_h, friction=False, **kw)
    ts = build_telescopic(p)
    key = (case, n_sub)
    if key not in _EQ_CACHE:
        w0 = time.process_time()
        z, _ = initial_equilibrium(ts)
        Q, _ = ts.model.full_state(0.0, z, np.zeros_like(z))
        L0 = {pe.name: pe.L0 for pe in ts.model.point_effects if hasattr(pe, "L0")}
        _EQ_CACHE[key] = (z, L0)
        print(f"  static equilibrium {case} n_sub={n_sub}: {time.process_time() - w0:.1f} s",
              flush=True)
    z, L0 = _EQ_CACHE[key]
    for pe in ts.model.point_effects:
        if pe.name in L0:
            pe.L0 = L0[pe.name]
    return ts, z.copy()


# --skip-unfiltered / --implicit-budget (full mode of 2026-11-24): the unfiltered telescopic
# rows crawl at ~5 us RK45 steps into their whole budget, and GA/Radau need less than 900 s
OPTIONS = {"skip_unfiltered": False, "implicit_budget": None}


def tele_run(case, n_sub, integrator, rtol, filter_h, T):
    row = {"case": f"telescopic_{case}", "integrator": integrator, "n_sub": n_sub, "rtol": rtol,
           "filter_h": filter_h, "t_sim": T}
    if filter_h == 0.0 and OPTIONS["skip_unfiltered"]:
        row.update(status="skipped (unfiltered)")
        return row, None
    saved = BUDGET[0]
    if integrator in ("GA", "Radau") and OPTIONS["implicit_budget"]:
        BUDGET[0] = OPTIONS["implicit_budget"]
    try:
        return _tele_run(row, case, n_sub, integrator, rtol, filter_h, T)
    finally:
        BUDGET[0] = saved


def _tele_run(row, case, n_sub, integrator, rtol, filter_h, T):
    try:
        ts, z0 = telescopic_system(case, n_sub, filter_h)
    except SimulationError as exc:                     # e.g. static Newton not converged
        row.update(status="static equilibrium failed: " + str(exc)[-60:])
        return row, None
    m = ts.model
    w0 = time.process_time()
    try:
        q, st = run_integrator(integrator, Index1System(m), m, z0, 0 * z0, T, rtol,
                               np.array([0.0, T]))
        row["status"] = "ok"
    except SimulationError as exc:
        row.update(status=("budget" if "budget" in str(exc) else "failed") + f": t={exc.t:.3g} s", wall_s=time.process_time() - w0)
        return row, None
    wall = time.process_time() - w0
    row.update(st, wall_s=wall, wall_per_sim_s=wall / T)
    Q, _ = m.full_state(T, q[-1], 0 * q[-1])
    return row, ts.tip(Q)[0]


def part_telescopic(quick: bool, out_rows: list, window: float | None = None,
                    subs_override: tuple | None = None,
                    cases: tuple = ("rigid_9.1", "flexible_25t"), on_row=None):
    T = window if window else (0.2 if quick else 1.0)
    BUDGET[0] = (60.0 if quick else 900.0) * max(1.0, T / (0.2 if quick else 1.0))
    for case in cases:
        # quick: one mesh (2 sub-elements; the 4-sub static equilibrium alone costs ~35 s)
        subs = (2,) if quick else (2, 4, 8)
        hs = (0.01, 0.03) if quick else (0.003, 0.01, 0.03)
        if subs_override:
            subs = subs_override
        ref_sub, ref_h = subs[-1], hs[0]
        print(f"[telescopic {case}] window {T} s; reference n_sub={ref_sub} h={ref_h} "
              f"RK45 rtol 1e-9", flush=True)
        ref_row, r_ref = tele_run(case, ref_sub, "RK45", 1e-9, ref_h, T)
        ref_row["err_ref_m"] = 0.0
        ref_row["case"] += "_REFERENCE"
        out_rows.append(ref_row)
        if on_row:
            on_row()
        print("  " + fmt(ref_row), flush=True)
        if r_ref is None:
            continue
        configs = []
        rtols = (1e-3, 1e-5, 1e-7) if quick else (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
        for r in rtols:
            configs.append((subs[0], "RK45", r, 0.01))
        for n in subs[1:]:
            configs.append((n, "RK45", 1e-6, 0.01))
        for h in hs:
            if h != 0.01:
                configs.append((subs[0], "RK45", 1e-6, h))
        if not quick:
            configs.append((subs[0], "RK45", 1e-6, 0.0))      # no filter: expected to fail
            configs.append((subs[0], "auto", 1e-6, 0.0))      # no filter, RK45 <-> BDF
            for ig in ("GA", "Radau"):
                for r in (1e-3, 1e-4):
                    configs.append((subs[0], ig, r, 0.01))
        for n, ig, r, h in configs:
            if (n, ig, r, h) == (ref_sub, "RK45", 1e-9, ref_h):
                continue
            row, r_tip = tele_run(case, n, ig, r, h, T)
            if r_tip is not None:
                row["err_ref_m"] = float(np.linalg.norm(r_tip - r_ref))
            out_rows.append(row)
            if on_row:
                on_row()
            print("  " + fmt(row), flush=True)


# -- output ----------------------------------------------------------------------------------
def fmt(row):
    def g(k, f="{:.3g}"):
        v = row.get(k)
        return "-" if v is None else (f.format(v) if isinstance(v, float) else str(v))
    return (f"{row['case']:<22} {row['integrator']:<6} sub={row['n_sub']:<3} rtol={row['rtol']:<7g}"
            f" h={row['filter_h']:<6g} {row['status'][:40]:<8} wall/sim={g('wall_per_sim_s')}"
            f" steps={g('n_steps')} evals={g('n_evals')} jac={g('n_jac')} rej={g('n_rejected')}"
            f" err_closed={g('err_closed_m')} err_ref={g('err_ref_m')}")


def write_csv(rows, path, header):
    with open(path, "w", newline="") as fh:
        fh.write("# " + header + "\n")
        w = csv.DictWriter(fh, FIELDS)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in FIELDS})


def plot(rows, path, title, err_keys):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(err_keys), figsize=(6.5 * len(err_keys), 5), squeeze=False)
    markers = {"RK45": "o", "GA": "s", "Radau": "^", "BDF": "v"}
    for ax, (key, label) in zip(axes[0], err_keys):
        groups: dict = {}
        for r in rows:
            if r.get("status") != "ok" or not r.get(key) or r[key] <= 0:
                continue
            cs = r["case"].replace("telescopic_", "")
            gk = (cs, r["integrator"], r["n_sub"], r["filter_h"])
            groups.setdefault(gk, []).append(r)
        for (cs, ig, n, h), rs in sorted(groups.items(), key=lambda kv: str(kv[0])):
            rs = sorted(rs, key=lambda r: r["rtol"])
            ax.loglog([r["wall_per_sim_s"] for r in rs], [r[key] for r in rs],
                      marker=markers.get(ig, "x"), ls="-" if len(rs) > 1 else "none",
                      label=f"{cs} {ig} sub={n} h={h:g}")
        for lvl, txt in ((1e-2, "1 cm"), (1e-3, "1 mm"), (1e-4, "0.1 mm")):
            ax.axhline(lvl, color="0.7", lw=0.8, ls=":")
            ax.text(ax.get_xlim()[0] if ax.lines else 1, lvl, txt, fontsize=7, color="0.4")
        ax.set_xlabel("wall seconds per simulated second (process time, shared machine)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="reduced sweep (< 5 min)")
    ap.add_argument("--part", choices=("beam", "telescopic", "all"), default="all")
    ap.add_argument("--window", type=float, default=None,
                    help="telescopic window T (s); default 0.2 (quick) / 1.0 (full)")
    ap.add_argument("--subs", type=str, default=None,
                    help="telescopic sub-element sweep, e.g. 2,4 (last = reference mesh)")
    ap.add_argument("--cases", type=str, default="rigid_9.1,flexible_25t",
                    help="telescopic cases (comma-separated)")
    ap.add_argument("--tag", type=str, default="", help="suffix of the telescopic output files")
    ap.add_argument("--skip-unfiltered", action="store_true",
                    help="leave out the telescopic rows without the stress filter")
    ap.add_argument("--implicit-budget", type=float, default=None,
                    help="process-time budget (s) of the telescopic GA/Radau rows")
    args = ap.parse_args()
    OPTIONS.update(skip_unfiltered=args.skip_unfiltered, implicit_budget=args.implicit_budget)
    os.makedirs(RESULTS, exist_ok=True)
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    mode = "quick" if args.quick else "full"
    header = (f"{stamp}; mode {mode}; wall = process CPU time of one run, machine shared with "
              f"other jobs (2 cores); OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    t0 = time.perf_counter()
    if args.part in ("beam", "all"):
        rows: list = []
        part_beam(args.quick, rows)
        write_csv(rows, os.path.join(RESULTS, "work_precision_beam.csv"), header)
        plot(rows, os.path.join(RESULTS, "work_precision_beam.png"),
             "Fryba moving load (alpha 0.5), midspan deflection; " + header,
             [("err_closed_m", "max error vs Fryba closed form (m)"),
              ("err_ref_m", "max error vs converged reference (m)")])
    if args.part in ("telescopic", "all"):
        rows = []
        subs = tuple(int(x) for x in args.subs.split(",")) if args.subs else None
        tag = f"_{args.tag}" if args.tag else ""
        csv_path = os.path.join(RESULTS, f"work_precision_telescopic{tag}.csv")
        hdr = header + (f"; window {args.window} s, sub-elements {args.subs}" if tag else "")
        part_telescopic(args.quick, rows, args.window, subs, tuple(args.cases.split(",")),
                        on_row=lambda: write_csv(rows, csv_path, hdr))   # incremental
        write_csv(rows, csv_path, hdr)
        plot(rows, os.path.join(RESULTS, f"work_precision_telescopic{tag}.png"),
             "Telescopic extraction, tip position error at T; " + header,
             [("err_ref_m", "tip position error vs reference (m)")])
    print(f"total {time.perf_counter() - t0:.0f} s (wall clock)")


if __name__ == "__main__":
    main()
