"""Time to accuracy of generalized-alpha on the released cantilever (scene cantilever_release).

The scene: a 10 m cantilever (EI 7.22e8 N m^2, rhoA 318.86 kg/m) released straight and at rest
under gravity, 2 s simulated.  The error is the largest |w - w_ref| of the downward tip
deflection w = -tip_position_z (m) against the 50-mode Euler-Bernoulli solution
(:func:`sim_core.validation.closed_form.cantilever_release_tip`), taken at the outputs (every
~5 ms) and at every step (a separate, untimed run with one output per step).

Each tolerance has its cheapest setting found by a search over meshes (sub-elements =
beams.0.n_nodes - 1, beams.0.n_gauss Gauss points), rho_inf and the step h on the grid
4e-3 * 2^(-k/4) s, where the two next smaller steps had to pass as well; newton_atol = tol / 10.
The driver cuts each output interval into equal steps of at most solver.h, so n_output is chosen
(outputs every 4.6-5 ms) to keep the effective step within 0.5 % below h.

Every timing is meant to run on one core (the model then never starts its element worker
thread).  From the repository root:

    taskset -c 0 python benchmarks/cantilever_accuracy.py --case 1e-4      # one JSON line
    taskset -c 0 python benchmarks/cantilever_accuracy.py --case rk45      # ~20 s
    taskset -c 0 python benchmarks/cantilever_accuracy.py --profile        # per-step costs
    taskset -c 0 python benchmarks/cantilever_accuracy.py --table          # ~3-4 min
    taskset -c 0 python benchmarks/cantilever_accuracy.py --adaptive       # error-controlled

``--case TOL`` (1e-3, 1e-4, 1e-5, 1e-6) loads the scene with the setting's overrides, runs
:func:`sim_core.simulate` once (the compiled functions load from numba's cache), then
``--repeat`` (5) times and reports min / median of

* the integration wall time, ``result.stats["wall_time_s"]``;
* scene -> Result: :func:`sim_core.load_scene` + :func:`sim_core.simulate` (model build,
  integration, the outputs at every output time and the energy-balance check).

``--case rk45`` is the project's default method (RK45, rtol 1e-4, the scene's mesh: 2
sub-elements x 5 Gauss points) for comparison, one run after a 0.01 s warm-up.

``--profile`` breaks down the scene's own setting (2 x 5, 16 DOF, h 3.5e-4 s, rho_inf 1): the
compiled loop per step, one residual and one tangent (M, K, C and the inverse iteration matrix)
called from Python, and the sections of scene -> Result.

``--adaptive`` measures the error-controlled generalized-alpha (the beam scenes' default: no
solver.h) for the 1e-4 and 1e-5 settings' meshes and rho_inf: the loosest rtol on the grid
10^(-k/4) (atol = rtol x 0.01 m, the deflection's scale) whose tip error at the outputs and
that of the two next tighter rtol meet the tolerance, then min / median of ``--repeat`` timed
runs after a warm-up, as ``--case``; it rewrites only the section "Error-controlled steps"
at the end of the report, with its own machine state (the fixed-step table above it is one
earlier run).

``--table`` runs every case and the profile in child processes (which inherit this process's
CPU affinity), times the whole process of ``--case 1e-4 --repeat 1`` and ``--case 1e-5
--repeat 1`` (``--whole-runs`` runs after one warm-up; or takes those figures from
``--whole-process FILE``, a JSON object {"1e-4": {"runs": n, "wall_s": [min, median, max]}})
and writes benchmarks/results/cantilever_accuracy.md (atomically) with the machine's state:
cores, affinity, load average, and each core's busy share during the run (/proc/stat).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, ROOT)

import numpy as np  # noqa: E402

from benchmarks._machine import cpu_times, machine_lines  # noqa: E402
from sim_core import load_scene, simulate  # noqa: E402
from sim_core.result import atomic_write_bytes  # noqa: E402
from sim_core.validation.closed_form import cantilever_release_tip  # noqa: E402

SCENE = "cantilever_release"
OUT = os.path.join(ROOT, "benchmarks", "results", "cantilever_accuracy.md")
T_END = 2.0
# cheapest setting per tolerance (m): sub-elements, Gauss points, rho_inf, h = 4e-3 2^(-k/4) s
SETTINGS = {
    "1e-3": {"tol": 1e-3, "n_sub": 2, "n_gauss": 4, "rho_inf": 0.9, "h": 4e-3 * 2 ** (-3 / 4)},
    "1e-4": {"tol": 1e-4, "n_sub": 2, "n_gauss": 3, "rho_inf": 0.9, "h": 4e-3 * 2 ** (-13 / 4)},
    "1e-5": {"tol": 1e-5, "n_sub": 4, "n_gauss": 3, "rho_inf": 0.9, "h": 4e-3 * 2 ** (-22 / 4)},
    "1e-6": {"tol": 1e-6, "n_sub": 8, "n_gauss": 4, "rho_inf": 1.0, "h": 4e-3 * 2 ** (-31 / 4)},
}
CASES = tuple(SETTINGS) + ("rk45",)
RK45_RTOL = 1e-4
TARGETS = (("1e-4", 0.1), ("1e-5", 0.5))       # (tolerance, wall-time target s)
WHOLE_TOLS = ("1e-4", "1e-5")
FEW_OUTPUTS = 101                               # outputs every 20 ms: the cost of the outputs
WHOLE_COMMANDS = ("--case 1e-4 --once", "--case 1e-5 --once",
                  "--case 1e-4 --repeat 1", "--case 1e-5 --repeat 1")


def output_grid(h: float, t_end: float = T_END, slack: float = 0.005) -> tuple[int, int]:
    """(output intervals, steps per interval): the fewest outputs with a spacing of 1-5 ms whose
    equal steps are at most h and at least h (1 - slack)."""
    n_min = math.ceil(t_end / h * (1.0 - 1e-12))
    cands = [(d, N) for N in range(n_min, math.ceil(n_min * (1.0 + slack)) + 1)
             for d in range(math.ceil(t_end / 5e-3), math.floor(t_end / 1e-3) + 1) if N % d == 0]
    if not cands:
        raise ValueError(f"no output grid for h = {h:g} s")
    d, N = min(cands)
    return d, N // d


def reference(t) -> np.ndarray:
    """The modal tip deflection (m, downwards) with the scene's section and length."""
    sc = load_scene(SCENE)
    b = sc["beams"][0]
    sec = b["section"]
    return cantilever_release_tip(t, sec["E"] * sec["I_b"], sec["rho"] * sec["A"], b["length"],
                                  g=-sc["gravity"]["g"][2])


def overrides(case: str, n_output: int | None = None) -> dict:
    s = SETTINGS[case]
    n_int, _ = output_grid(s["h"])
    return {"beams.0.n_nodes": s["n_sub"] + 1, "beams.0.n_gauss": s["n_gauss"],
            "solver.h": s["h"], "solver.rho_inf": s["rho_inf"],
            "solver.newton_atol": s["tol"] / 10, "solver.n_output": n_output or n_int + 1}


def rk45_scene(extra: dict | None = None) -> dict:
    """The scene with the project's default method (RK45 at rtol RK45_RTOL), validated as
    load_scene does (the generalized-alpha keys removed: RK45 rejects them)."""
    from sim_core.registry import system_kind
    from sim_core.scene.io import apply_overrides, read_scene
    raw, source = read_scene(SCENE)
    for key in ("h", "rho_inf", "newton_atol"):
        raw["solver"].pop(key, None)
    raw = apply_overrides(raw, {"solver.method": "RK45", "solver.rtol": RK45_RTOL,
                                **(extra or {})})
    return system_kind(raw).validate(raw, source)


def tip_error(res) -> float:
    return float(np.max(np.abs(-np.asarray(res["tip_position"])[:, 2] - reference(res.t))))


def error_every_step(case: str, n_output: int | None = None) -> float:
    """Max tip error with an output at every step (the effective step of ``n_output`` outputs;
    the driver and the tip position only, without the other outputs)."""
    from sim_core.integrate.driver import integrate
    from sim_core.systems.beam.build import build_model
    h = SETTINGS[case]["h"]
    if n_output is None:
        n_int, k = output_grid(h)
    else:
        n_int = n_output - 1
        k = math.ceil(T_END / n_int / h * (1.0 - 1e-12))
    scene = load_scene(SCENE, overrides(case, n_output=n_int * k + 1))
    model, Q0, Qd0 = build_model(scene)
    z0, zd0 = model.reduced_state(0.0, Q0, Qd0)
    ts, ys, _ = integrate(model, np.concatenate([z0, zd0]), T_END, scene["solver"])
    n, last = model.n_dof, len(model.beams) - 1
    L = model.beams[last].length
    w = np.array([-np.real(model.point(last, L, model.full_state(t, y[:n], y[n:])[0])[0][2])
                  for t, y in zip(ts, ys)])
    return float(np.max(np.abs(w - reference(ts))))


def run_case(case: str, repeat: int, once: bool = False, n_output: int | None = None) -> dict:
    """The case's JSON row; ``once``: a single cold run (no warm-up, no every-step error);
    ``n_output``: instead of the output grid of :func:`output_grid`."""
    if case == "rk45":
        if not once:
            simulate(rk45_scene({"solver.t_end": 0.01}))       # load the compiled functions
        make, repeat = (lambda: rk45_scene({"solver.n_output": 401})), 1
    else:
        ov = overrides(case, n_output)
        make = lambda: load_scene(SCENE, ov)                  # noqa: E731
        if not once:
            simulate(make())                                    # load the compiled functions
        else:
            repeat = 1
    integ, s2r = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = simulate(make())
        s2r.append(time.perf_counter() - t0)
        integ.append(res.stats["wall_time_s"])
    st = res.stats
    sol = res.scene["solver"] if hasattr(res, "scene") else make()["solver"]
    row = {"case": case, "n_sub": res.scene["beams"][0]["n_nodes"] - 1,
           "n_gauss": res.scene["beams"][0]["n_gauss"], "n_dof": st.get("n_dof"),
           "method": sol["method"], "n_output": sol["n_output"],
           "steps": st.get("n_steps"), "n_rhs": st.get("n_rhs"), "n_jac": st.get("n_jac"),
           "compiled": st.get("compiled"),
           "err_outputs_m": tip_error(res),
           "energy_balance": st.get("checks", {}).get("energy_balance", {}).get("value"),
           "suspect": bool(res.suspect), "repeat": repeat, "cold": once,
           "integration_s": [min(integ), statistics.median(integ)],
           "scene_to_result_s": [min(s2r), statistics.median(s2r)],
           "affinity": sorted(os.sched_getaffinity(0))}
    if case == "rk45":
        row.update(rtol=sol["rtol"], atol=sol["atol"], err_steps_m=None)
    else:
        s = SETTINGS[case]
        row.update(tol_m=s["tol"], rho_inf=s["rho_inf"], h=s["h"], newton_atol=s["tol"] / 10,
                   h_eff=st["max_step_s"], h_eff_min=st["min_step_s"],
                   err_steps_m=None if once else error_every_step(case, n_output))
    return row


ADAPTIVE_TOLS = ("1e-4", "1e-5")
ADAPTIVE_SECTION = "## Error-controlled steps (the beam scenes' default)"


def adaptive_scene(case: str, rtol: float, n_output: int = 401) -> dict:
    """The scene on the setting's mesh and rho_inf without solver.h: error-controlled steps at
    rtol, atol = rtol x 0.01 m, newton_atol = atol / 10 (the default)."""
    from sim_core.registry import system_kind
    from sim_core.scene.io import apply_overrides, read_scene
    s = SETTINGS[case]
    raw, source = read_scene(SCENE)
    for key in ("h", "newton_atol"):
        raw["solver"].pop(key, None)
    raw = apply_overrides(raw, {"beams.0.n_nodes": s["n_sub"] + 1, "beams.0.n_gauss": s["n_gauss"],
                                "solver.rho_inf": s["rho_inf"], "solver.rtol": rtol,
                                "solver.atol": rtol * 0.01, "solver.n_output": n_output})
    return system_kind(raw).validate(raw, source)


def run_adaptive(case: str, repeat: int) -> dict:
    """The loosest rtol = 10^(-k/4) meeting the case's tolerance (with the two next tighter
    ones), then its timings (module doc)."""
    tol = SETTINGS[case]["tol"]
    simulate(adaptive_scene(case, 1e-4, n_output=11))          # load the compiled functions
    errs, k = {}, 8
    while k <= 40:
        for j in (k, k + 1, k + 2):
            if j not in errs:
                errs[j] = tip_error(simulate(adaptive_scene(case, 10 ** (-j / 4))))
        if all(errs[j] <= tol for j in (k, k + 1, k + 2)):
            break
        k += 1
    rtol = 10 ** (-k / 4)
    integ, s2r = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = simulate(adaptive_scene(case, rtol))
        s2r.append(time.perf_counter() - t0)
        integ.append(res.stats["wall_time_s"])
    st = res.stats
    return {"case": case, "tol_m": tol, "rtol": rtol, "atol": rtol * 0.01,
            "n_sub": SETTINGS[case]["n_sub"], "n_gauss": SETTINGS[case]["n_gauss"],
            "n_dof": st["n_dof"], "rho_inf": st["rho_inf"], "n_output": len(res.t),
            "steps": st["n_steps"], "rejected": st["n_rejected"], "n_rhs": st["n_rhs"],
            "n_jac": st["n_jac"], "n_lu": st["n_lu"], "min_step_s": st["min_step_s"],
            "max_step_s": st["max_step_s"], "compiled": st["compiled"],
            "err_outputs_m": tip_error(res), "searched": {f"{10 ** (-j / 4):.3g}": e
                                                          for j, e in sorted(errs.items())},
            "integration_s": [min(integ), statistics.median(integ)],
            "scene_to_result_s": [min(s2r), statistics.median(s2r)],
            "affinity": sorted(os.sched_getaffinity(0))}


def adaptive_section(repeat: int, out_path: str) -> int:
    """Runs :func:`run_adaptive` for ADAPTIVE_TOLS in child processes and rewrites the report's
    section ADAPTIVE_SECTION (module doc)."""
    cpu0, load0 = cpu_times(), os.getloadavg()
    rows = {c: _child(["--adaptive-case", c, "--repeat", str(repeat)]) for c in ADAPTIVE_TOLS}
    for r in rows.values():
        print(json.dumps(r), flush=True)
    cpu1, load1 = cpu_times(), os.getloadavg()
    fixed = {}
    for c in ADAPTIVE_TOLS:
        try:
            fixed[c] = _child(["--case", c, "--repeat", str(repeat)])
        except RuntimeError:
            fixed[c] = None
    tol_name = {"1e-4": "0.1 mm", "1e-5": "0.01 mm"}
    L = [ADAPTIVE_SECTION, "",
         "Written by `taskset -c 0 python benchmarks/cantilever_accuracy.py --adaptive` (a run "
         "of its own, after the table above).  The beam scenes' default: generalized-alpha "
         "without solver.h, the step chosen by the local error estimate e_q = c_q h² Δq̈ "
         "(Zienkiewicz & Xie 1991 for generalized-alpha) against rtol and atol = rtol × 0.01 m "
         "(`sim_core.integrate.driver._alpha_adaptive`), on the meshes and ρ∞ of the fixed-step "
         "rows; rtol the loosest of 10^(−k/4) meeting the tolerance with the two next tighter "
         f"ones.  Min / median of {repeat} timed runs after a warm-up, 401 outputs.  For "
         "comparison the fixed-step row of the same tolerance, re-measured in this run "
         "(`--case`).", "", "Machine:", "", *machine_lines(cpu0, cpu1, load0, load1), "",
         "| tol | sub-el. × Gauss (DOF) | ρ∞ | rtol (atol) | steps (rejected) | step min – max (s) "
         "| tangents / inverses | max tip error at outputs (m) | integration (s) "
         "| scene → Result (s) | fixed h, same run: integration / scene → Result (s) |",
         "|---|---|---|---|---|---|---|---|---|---|---|"]
    for c in ADAPTIVE_TOLS:
        r, f = rows[c], fixed[c]
        fx = (f"{f['integration_s'][1]:.3g} / {f['scene_to_result_s'][1]:.3g}"
              if f else "–")
        L.append(f"| {tol_name[c]} | {r['n_sub']} × {r['n_gauss']} ({r['n_dof']}) "
                 f"| {r['rho_inf']:g} | {r['rtol']:.3g} ({r['atol']:.3g}) "
                 f"| {r['steps']} ({r['rejected']}) "
                 f"| {r['min_step_s']:.3g} – {r['max_step_s']:.3g} | {r['n_jac']} / {r['n_lu']} "
                 f"| {r['err_outputs_m']:.3g} | **{_mm(r['integration_s'])}** "
                 f"| {_mm(r['scene_to_result_s'])} | {fx} |")
    L += ["", "Searched rtol → tip error (m): " + "; ".join(
        f"{tol_name[c]}: " + ", ".join(f"{k} → {v:.2g}" for k, v in rows[c]["searched"].items())
        for c in ADAPTIVE_TOLS) + "."]
    text = open(out_path).read() if os.path.exists(out_path) else ""
    if ADAPTIVE_SECTION in text:
        text = text[:text.index(ADAPTIVE_SECTION)].rstrip("\n") + "\n"
    atomic_write_bytes(out_path, (text + "\n" + "\n".join(L) + "\n").encode())
    print(f"wrote {out_path}")
    return 0


def _best(f, n: int) -> float:
    best = math.inf
    for _ in range(n):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


def profile() -> dict:
    """Per-step costs and the sections of scene -> Result for the scene's own setting."""
    from sim_core.integrate import _generalized_alpha_numba as ga
    from sim_core.integrate.driver import integrate
    from sim_core.integrate.generalized_alpha import GeneralizedAlphaParameters
    from sim_core.model.state_jacobian import REL_STEP
    from sim_core.physics import _effects_numba as ec
    from sim_core.systems.beam.build import build_model
    from sim_core.systems.beam.run import _beam_result, beam_energy_check

    simulate(load_scene(SCENE))                                 # load the compiled functions
    reps = 5
    sec = {k: [] for k in ("load_scene", "build", "integration", "outputs", "energy_check",
                           "simulate")}
    for _ in range(reps):
        t0 = time.perf_counter()
        scene = load_scene(SCENE)
        t1 = time.perf_counter()
        model, Q0, Qd0 = build_model(scene)
        z0, zd0 = model.reduced_state(0.0, Q0, Qd0)
        y0 = np.concatenate([z0, zd0])
        t2 = time.perf_counter()
        ts, ys, stats = integrate(model, y0, T_END, scene["solver"])
        t3 = time.perf_counter()
        res = _beam_result(model, scene, ts, ys, stats, None)
        t4 = time.perf_counter()
        beam_energy_check(model, scene, res)
        t5 = time.perf_counter()
        simulate(load_scene(SCENE))
        t6 = time.perf_counter()
        for k, v in zip(sec, (t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4, t6 - t5)):
            sec[k].append(v)
    sol = scene["solver"]
    n_output = sol["n_output"]
    # the compiled loop: 400 calls of one output interval each, and one call for all steps
    one_call = dict(sol, n_output=2)
    loop = {}
    for name, s in (("per_output_interval", sol), ("one_call", one_call)):
        walls, steps = [], None
        for _ in range(reps):
            _, _, st = integrate(model, y0, T_END, s)
            walls.append(st["wall_time_s"])
            steps, nrhs, njac, h_eff = st["n_steps"], st["n_rhs"], st["n_jac"], st["max_step_s"]
        loop[name] = {"steps": steps, "h_eff": h_eff, "n_rhs": nrhs, "n_jac": njac,
                      "wall_min_s": min(walls), "us_per_step": min(walls) / steps * 1e6}
    # one residual and one tangent from Python, at the state of t = 1 s
    plan = model.element_loop_plan()
    n, N = plan.n, len(plan.Qp)
    y = ys[len(ys) // 2]
    z, zd = y[:n], y[n:]
    zdd = model.accelerations(float(ts[len(ts) // 2]), z, zd)
    Q, Qd, Qdd = np.empty(N), np.empty(N), np.empty(N)
    ga.lift(z, plan.Qp, plan.rows, plan.sgn, Q)
    ga.lift(zd, np.zeros(N), plan.rows, plan.sgn, Qd)
    ga.lift(zdd, np.zeros(N), plan.rows, plan.sgn, Qdd)
    r = np.empty(n)
    p = GeneralizedAlphaParameters.from_rho_inf(sol["rho_inf"])
    h = loop["one_call"]["h_eff"]
    bq = p.beta * (1 - p.alpha_f) / (1 - p.alpha_m) * h * h
    bv = p.gamma * (1 - p.alpha_f) / (1 - p.alpha_m) * h

    def residual():
        ga.residual(Q, Qd, Qdd, plan.eidx, plan.red, plan.sg, n, *plan.kernel_args, r)

    def tangent():
        M, K, C, _ = ga.mass_tangent(Q, Qd, Qdd, REL_STEP, plan.eidx, plan.red, plan.sg, n,
                                     *plan.kernel_args, ec.NO_ACC)
        np.linalg.inv(M + bq * K + bv * C)

    residual(), tangent()
    n_calls = 2000
    t_res = _best(lambda: [residual() for _ in range(n_calls)], 5) / n_calls
    t_tan = _best(tangent, 50)
    t_acc = _best(lambda: model.accelerations(1.0, z, zd), 200)
    return {"n_dof": int(model.n_dof), "n_sub": scene["beams"][0]["n_nodes"] - 1,
            "n_gauss": scene["beams"][0]["n_gauss"], "h": sol["h"], "rho_inf": sol["rho_inf"],
            "n_output": n_output, "loop": loop, "residual_us": t_res * 1e6,
            "tangent_us": t_tan * 1e6, "model_accelerations_us": t_acc * 1e6,
            "sections_min_s": {k: min(v) for k, v in sec.items()},
            "sections_median_s": {k: statistics.median(v) for k, v in sec.items()},
            "affinity": sorted(os.sched_getaffinity(0))}


# -- the report ------------------------------------------------------------------------------

def _child(args: list[str]) -> dict:
    out = subprocess.run([sys.executable, os.path.abspath(__file__)] + args, cwd=ROOT,
                         capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"{args}: exit {out.returncode}\n{out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def _whole_process(command: str, runs: int) -> dict:
    """Wall time (s) of the whole child process, one warm-up run then ``runs`` runs."""
    walls = []
    for k in range(runs + 1):
        t0 = time.perf_counter()
        proc = subprocess.Popen([sys.executable, os.path.abspath(__file__)] + command.split(),
                                cwd=ROOT, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        proc.wait()
        if k:
            walls.append(time.perf_counter() - t0)
    return {"runs": runs, "wall_s": [min(walls), statistics.median(walls), max(walls)]}


def _mm(v, digits=3) -> str:
    return f"{v[0]:.{digits}g} / {v[1]:.{digits}g}"


def table(repeat: int, whole_runs: int, whole_file: str | None, out_path: str) -> int:
    cpu0, load0 = cpu_times(), os.getloadavg()
    rows = {}
    for case in CASES:
        rows[case] = _child(["--case", case, "--repeat", str(repeat)])
        print(json.dumps(rows[case]), flush=True)
    prof = _child(["--profile"])
    print(json.dumps(prof), flush=True)
    cold = {c: [_child(["--case", c, "--once"]) for _ in range(3)] for c in WHOLE_TOLS}
    print(json.dumps(cold), flush=True)
    few = {c: _child(["--case", c, "--repeat", str(repeat), "--n-output", str(FEW_OUTPUTS)])
           for c in WHOLE_TOLS}
    print(json.dumps(few), flush=True)
    if whole_file:
        with open(whole_file) as f:
            whole = json.load(f)
    else:
        whole = {c: _whole_process(c, whole_runs) for c in WHOLE_COMMANDS}
    cpu1, load1 = cpu_times(), os.getloadavg()

    tol_name = {"1e-3": "1 mm", "1e-4": "0.1 mm", "1e-5": "0.01 mm", "1e-6": "1 µm"}
    L = ["# Released cantilever: time to accuracy of generalized-alpha", "",
         f"Scene `{SCENE}` (10 m, EI 7.22e8 N m², ρA 318.86 kg/m, released under gravity, "
         f"{T_END:g} s simulated).  Error: max |w − w_ref| of the downward tip deflection "
         "against the 50-mode solution (`cantilever_release_tip`), at the outputs (every "
         "4.6–5 ms) and at every step (a separate untimed run).  Written by "
         "`benchmarks/cantilever_accuracy.py` (its docstring says how each figure is taken); "
         "reproduce with `taskset -c 0 python benchmarks/cantilever_accuracy.py --table`, "
         "one row with `... --case 1e-4`.", "",
         "Machine:", "", *machine_lines(cpu0, cpu1, load0, load1), "",
         "## Time to accuracy (one core)", "",
         f"Times are min / median of {repeat} in-process repetitions after one warm-up run "
         "(the compiled functions already loaded).  *Integration*: `result.stats"
         "[\"wall_time_s\"]`.  *Scene → Result*: `load_scene` + `simulate` (model build, "
         "integration, every output's accelerations, tip kinematics, energies and reactions, "
         "and the energy check).  h_eff: the step the driver takes (each output interval cut "
         "into equal steps of at most h).  newton_atol = tol / 10.", "",
         "| tol | sub-el. × Gauss (DOF) | ρ∞ | h (s) | h_eff (s) | outputs | steps | "
         "residuals / step | max tip error at outputs / at every step (m) | integration (s) | "
         "scene → Result (s) |",
         "|---|---|---|---|---|---|---|---|---|---|---|"]
    fails = []
    for case in SETTINGS:
        r = rows[case]
        ok = r["err_outputs_m"] <= r["tol_m"] and r["err_steps_m"] <= r["tol_m"]
        if not ok:
            fails.append(case)
        L.append(f"| {tol_name[case]} | {r['n_sub']} × {r['n_gauss']} ({r['n_dof']}) "
                 f"| {r['rho_inf']:g} | {r['h']:.4g} | {r['h_eff']:.4g} | {r['n_output']} "
                 f"| {r['steps']} | {r['n_rhs'] / r['steps']:.2f} "
                 f"| {r['err_outputs_m']:.3g} / {r['err_steps_m']:.3g}{'' if ok else ' ✗'} "
                 f"| **{_mm(r['integration_s'])}** | {_mm(r['scene_to_result_s'])} |")
    k = rows["rk45"]
    L.append(f"| RK45, rtol {k['rtol']:.0e} (the project's default method) | {k['n_sub']} × "
             f"{k['n_gauss']} ({k['n_dof']}) | – | adaptive | – | {k['n_output']} "
             f"| {k['steps']} | {k['n_rhs'] / k['steps']:.2f} | {k['err_outputs_m']:.3g} / – "
             f"| {k['integration_s'][0]:.3g} (1 run) | {k['scene_to_result_s'][0]:.3g} |")
    L += ["", "Every generalized-alpha row ran compiled (`stats[\"compiled\"]`: "
          + ", ".join(str(rows[c]["compiled"]) for c in SETTINGS) + "); energy balance "
          "(drift / exchanged energy): "
          + ", ".join(f"{rows[c]['energy_balance']:.1e}" for c in CASES) + " (limit 0.02)."
          + (" ✗: over its tolerance." if fails else ""), "",
          "### Cold start and whole process", "",
          "*Cold scene → Result*: the first `load_scene` + `simulate` in a fresh process "
          f"(`--case TOL --once`, {len(cold[WHOLE_TOLS[0]])} processes, min / median): it adds "
          "numba loading the compiled functions from its on-disk cache.  *Whole process*: "
          "interpreter start, imports and everything the command does, measured from outside, "
          f"{whole[WHOLE_COMMANDS[0]]['runs']} runs after one warm-up, pinned to core 0 "
          "(`taskset -c 0`), min / median / max.  `--once` is one cold scene → Result; "
          "`--repeat 1` adds a warm-up run, one timed run and the every-step error run.", "",
          "| tol | cold scene → Result (s) | command | whole process wall (s) |",
          "|---|---|---|---|"]
    for c in WHOLE_COMMANDS:
        w = whole[c]["wall_s"]
        tol = c.split()[1]
        cs = [r["scene_to_result_s"][0] for r in cold[tol]]
        cs = f"{min(cs):.3f} / {statistics.median(cs):.3f}" if "--once" in c else "–"
        L.append(f"| {tol_name[tol]} | {cs} "
                 f"| `taskset -c 0 python benchmarks/cantilever_accuracy.py {c}` "
                 f"| {w[0]:.2f} / {w[1]:.2f} / {w[2]:.2f} |")

    L += ["", "### Targets (2 s simulated, one core)", ""]
    for case, limit in TARGETS:
        r = rows[case]
        integ, s2r = r["integration_s"][1], r["scene_to_result_s"][1]
        cs = statistics.median([x["scene_to_result_s"][0] for x in cold[case]])
        wp = whole[f"--case {case} --once"]["wall_s"][1]
        acc = r["err_steps_m"] <= r["tol_m"] and r["err_outputs_m"] <= r["tol_m"]

        def verdict(x, limit=limit):
            return f"{x:.3g} s, {'met' if x <= limit else 'not met'}"
        L.append(f"- **{tol_name[case]} in ≤ {limit:g} s**: accuracy "
                 f"{'met' if acc else 'NOT met'} ({max(r['err_steps_m'], r['err_outputs_m']):.3g}"
                 f" m).  Median wall: integration alone {verdict(integ)}; warm scene → Result "
                 f"({r['n_output']} outputs, energy check) {verdict(s2r)}; cold scene → Result "
                 f"{verdict(cs)}; whole process (`--once`) {verdict(wp)}.  With "
                 f"{FEW_OUTPUTS} outputs (every 20 ms; h_eff {few[case]['h_eff']:.4g} s, error "
                 f"{max(few[case]['err_steps_m'], few[case]['err_outputs_m']):.3g} m) warm "
                 f"scene → Result takes {verdict(few[case]['scene_to_result_s'][1])} "
                 f"(`--case {case} --n-output {FEW_OUTPUTS}`).")
    rk = rows["rk45"]["integration_s"][0]
    L += [f"- Against RK45 at rtol 1e-4 on the scene's mesh ({rk:.3g} s integration, error "
          f"{rows['rk45']['err_outputs_m']:.2g} m): the 0.1 mm row integrates "
          f"{rk / rows['1e-4']['integration_s'][1]:.0f}× faster, the 0.01 mm row "
          f"{rk / rows['1e-5']['integration_s'][1]:.0f}× faster and more accurate."]

    p = prof
    lp, lo = p["loop"]["per_output_interval"], p["loop"]["one_call"]
    s = p["sections_min_s"]
    parts = s["load_scene"] + s["build"] + s["integration"] + s["outputs"] + s["energy_check"]
    L += ["", f"## Per-step cost: the scene's own setting ({p['n_sub']} × {p['n_gauss']}, "
          f"{p['n_dof']} DOF, h {p['h']:g} s, ρ∞ {p['rho_inf']:g})", "",
          "Min of 5, one core.", "",
          "| piece | µs |", "|---|---|",
          f"| one step, compiled loop, all {lo['steps']} steps in one call "
          f"(h_eff {lo['h_eff']:.4g} s) | **{lo['us_per_step']:.2f}** |",
          f"| one step, as the scene runs ({p['n_output'] - 1} output intervals, "
          f"{lp['steps']} steps, h_eff {lp['h_eff']:.4g} s) | {lp['us_per_step']:.2f} |",
          f"| one residual (element kernel + reduction), one call from Python, call overhead "
          "included "
          f"({lo['n_rhs'] / lo['steps']:.2f} per step) | {p['residual_us']:.2f} |",
          f"| tangent: M, K, C by element differences + inverse of the iteration matrix, "
          f"from Python ({lo['n_jac']} per run) | {p['tangent_us']:.0f} |",
          f"| `Model.accelerations` (numpy path, once per output) "
          f"| {p['model_accelerations_us']:.1f} |", "",
          f"Scene → Result ({p['n_output']} outputs), min of 5 per section (s):", "",
          "| load_scene | build model | integration | outputs | energy check | sum | "
          "`simulate` + `load_scene` |", "|---|---|---|---|---|---|---|",
          f"| {s['load_scene']:.4f} | {s['build']:.4f} | {s['integration']:.4f} "
          f"| {s['outputs']:.4f} | {s['energy_check']:.4f} | {parts:.4f} "
          f"| {s['simulate']:.4f} |", "",
          f"The outputs cost {s['outputs'] / (p['n_output']) * 1e3:.2f} ms each (accelerations, "
          "tip kinematics, energies, reactions per output time, in numpy): at ~400 outputs "
          "they take more than the integration of the 0.1 mm setting."]
    atomic_write_bytes(out_path, ("\n".join(L) + "\n").encode())
    print(f"wrote {out_path}")
    return 1 if fails else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--case", choices=CASES, help="one setting (tolerance in m) or rk45")
    g.add_argument("--profile", action="store_true", help="per-step costs of the scene")
    g.add_argument("--table", action="store_true", help="every case; writes the report")
    g.add_argument("--adaptive", action="store_true",
                   help="the error-controlled default; rewrites its section of the report")
    g.add_argument("--adaptive-case", choices=ADAPTIVE_TOLS,
                   help="one error-controlled setting (JSON line)")
    ap.add_argument("--repeat", type=int, default=5, help="timed repetitions (default 5)")
    ap.add_argument("--n-output", type=int,
                    help="with --case: this many outputs (default: every 4.6-5 ms)")
    ap.add_argument("--once", action="store_true",
                    help="with --case: one cold scene -> Result, nothing else (for timing the "
                         "whole process)")
    ap.add_argument("--whole-runs", type=int, default=5,
                    help="whole-process runs per command in --table (default 5)")
    ap.add_argument("--whole-process", metavar="FILE",
                    help="whole-process figures measured outside (JSON), instead of --whole-runs")
    ap.add_argument("--out", default=OUT)
    args = ap.parse_args(argv)
    if args.case:
        print(json.dumps(run_case(args.case, args.repeat, args.once, args.n_output)), flush=True)
        return 0
    if args.profile:
        print(json.dumps(profile()), flush=True)
        return 0
    if args.adaptive_case:
        print(json.dumps(run_adaptive(args.adaptive_case, args.repeat)), flush=True)
        return 0
    if args.adaptive:
        return adaptive_section(args.repeat, args.out)
    return table(args.repeat, args.whole_runs, args.whole_process, args.out)


if __name__ == "__main__":
    sys.exit(main())
