"""Wall time of a crane scene as a user runs it, and what its compare cases cost and change.

``boom-sim run SCENE`` is timed whole; each compare case (a finer mesh, friction on, ...) runs
the same command with other settings and shows what they cost in time and change in the result.

One command per committed table (repository root, an otherwise idle machine), minutes with the
defaults:

    python benchmarks/user_crane_speed.py                               # crane_hexagonal_4
    python benchmarks/user_crane_speed.py --scene crane_lift_and_slew

The script pins itself to core 0 (the machine state's busy shares and affinity then describe
the timed runs) and starts every run as

    OPENBLAS_NUM_THREADS=1 taskset -c 0 boom-sim run SCENE --out <tmpdir> --quiet

(``python -m sim_core.cli run ...``, so the checkout's package is the one timed): one core, so
the model never starts its element worker thread, and one BLAS thread.  It writes (atomically,
:func:`_machine.write_markdown`) the command lines, the scene's description, the machine state
(:func:`_machine.machine_lines`) and two tables to ``--out``, by default
benchmarks/results/user_crane_speed.md for ``crane_hexagonal_4``,
benchmarks/results/lift_and_slew_speed.md for ``crane_lift_and_slew`` and
benchmarks/results/<scene>_speed.md for any other scene.

``Speed``: each case ``--runs`` times (default 3, the cases taking turns), median [min, max] of

* ``wall``: the child process's wall time (``time.perf_counter`` around ``subprocess.run``),
  start-up (imports, compiled-code cache), building the model, the integration and the writing
  of the results included, s;
* ``RTF`` = simulated time (the scene's ``solver.t_end``) / median ``wall``;
* ``cpu``: the child's user + system time (``resource.getrusage(RUSAGE_CHILDREN)`` before and
  after), s: about the wall on one core;
* ``sim wall``, ``sim RTF``, ``steps``, ``RHS``: the integration's own wall time and real-time
  factor, its step and right-hand-side counts (summary.json ``wall_time_s``,
  ``real_time_factor``, ``n_steps``, ``n_rhs``).

Speed cases:

* ``default``: the command above, figures included (what ``boom-sim run`` does unasked);
* ``no_plots``: the same with ``--no-plots`` (the results without the figures).

``Compare cases`` (``--compare LABEL:KEY=VALUE[,KEY=VALUE...]``, repeatable): each runs the
``default`` command once with ``--set KEY=VALUE`` for each pair, and is compared against the
REFERENCE, the first ``default`` run (the scene as shipped).  Default cases:

* ``crane_hexagonal_4`` (n_nodes = 5): ``n_nodes=9:booms.n_nodes=9`` (8 sub-elements per boom,
  the paper's discretisation: what the default mesh costs in accuracy);
* ``crane_lift_and_slew`` (n_nodes = 3, rtol 3e-6, friction off): ``n_nodes=5:booms.n_nodes=5``
  (what the coarse mesh costs in accuracy), ``rtol=1e-6:solver.rtol=1e-6,solver.atol=1e-7``
  (what the tolerance costs) and ``friction:effects.friction=true`` (what friction costs in
  time);
* any other scene: twice the sub-elements (``booms.n_nodes`` = 2 (n_nodes - 1) + 1) where the
  scene has ``booms.n_nodes``, and friction on where the scene has it off.

Its first table gives, for the reference and each case, the ``--set`` overrides, n_nodes,
sub-elements per boom, n_dof, ``wall s``, ``sim wall s``, ``steps``, ``RHS`` and ``exit`` (the
reference's wall time is that of the first ``default`` run of the speed table).  Its second,
one column per case, over the output times common to the case and the reference (the case's
outputs interpolated to the reference's times where they differ,
``sim_core.result.Result.load(...)``):

* ``max |tip - tip_ref|``: the largest distance between the case's and the reference's tip
  positions (``tip_position``), m, the time of it, and that distance relative to the
  reference's tip travel (the largest distance of the reference's tip from its initial
  position); the distance at the last common time;
* the largest telescopic-cylinder force (``max |telescopic_cylinder_force|``) of case and
  reference, and its relative difference ``|F - F_ref| / F_ref``;
* where both results have them: ``max |sway - sway_ref|`` (``sway_angle``, (n, 2) rad: the
  largest difference of either component, deg, beside the reference's largest sway), and the
  relative differences of the largest hoist-rope force (``hoist_rope_force``, N) and of the
  largest luffing-cylinder force (``luffing_cylinder_force``, N).

Options: ``--scene NAME``; ``--compare ...`` (replaces the default cases); ``--runs N``;
``--skip-compare`` (the speed table only; ``--skip-accuracy`` is the same); ``--out FILE``;
``--quick`` (``--set solver.t_end=2`` on every run, one run per case, written to
/tmp/<the default file's name without .md>_quick.md unless ``--out`` is given: a check of the
script, not a benchmark).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, ROOT)

from benchmarks._machine import cpu_times, machine_lines, write_markdown
from sim_core import SceneError, load_scene
from sim_core.result import Result

RESULTS = os.path.join(ROOT, "benchmarks", "results")
DEFAULT_SCENE = "crane_hexagonal_4"
OUT_NAMES = {"crane_hexagonal_4": "user_crane_speed.md",
             "crane_lift_and_slew": "lift_and_slew_speed.md"}
TITLES = {"crane_hexagonal_4": "The four-section hexagonal crane",
          "crane_lift_and_slew": "The paper's crane lifting and slewing a swinging payload"}
DEFAULT_COMPARE = {"crane_hexagonal_4": ["n_nodes=9:booms.n_nodes=9"],
                   "crane_lift_and_slew": ["n_nodes=5:booms.n_nodes=5",
                                           "rtol=1e-6:solver.rtol=1e-6,solver.atol=1e-7",
                                           "friction:effects.friction=true"]}
CORE = 0
CASES = {"default": [], "no_plots": ["--no-plots"]}
REF = "default"


def out_name(scene: str) -> str:
    """The scene's table file name under benchmarks/results."""
    return OUT_NAMES.get(scene, f"{os.path.splitext(os.path.basename(scene))[0]}_speed.md")


def default_compare(scene_name: str, scene: dict) -> list[str]:
    """The default ``--compare`` specs of a scene (module docstring)."""
    if scene_name in DEFAULT_COMPARE:
        return list(DEFAULT_COMPARE[scene_name])
    specs = []
    nn = (scene.get("booms") or {}).get("n_nodes")
    if isinstance(nn, int):
        specs.append(f"n_nodes={2 * (nn - 1) + 1}:booms.n_nodes={2 * (nn - 1) + 1}")
    if (scene.get("effects") or {}).get("friction") is False:
        specs.append("friction:effects.friction=true")
    return specs


def parse_compare(spec: str) -> tuple[str, list[str]]:
    """``LABEL:KEY=VALUE[,KEY=VALUE...]`` -> (label, ["KEY=VALUE", ...]).  A comma-separated
    piece without ``=`` continues the previous value (``k=[1,2]``)."""
    label, sep, rest = spec.partition(":")
    label = label.strip()
    if not sep or not label or not rest.strip():
        raise ValueError(f"--compare {spec!r}: expected LABEL:KEY=VALUE[,KEY=VALUE...]")
    sets: list[str] = []
    for piece in rest.split(","):
        if "=" in piece and piece.split("=", 1)[0].strip():
            sets.append(piece.strip())
        elif sets:
            sets[-1] += "," + piece
        else:
            raise ValueError(f"--compare {spec!r}: {piece!r} is no KEY=VALUE")
    return label, sets


def _command(scene: str, out: str, flags: list[str], sets: list[str]) -> list[str]:
    cmd = ["taskset", "-c", str(CORE), sys.executable, "-m", "sim_core.cli", "run", scene,
           "--out", out, "--quiet", *flags]
    for s in sets:
        cmd += ["--set", s]
    return cmd


def _shown(scene: str, flags: list[str], sets: list[str]) -> str:
    """The timed command as a user types it."""
    return (f"`OPENBLAS_NUM_THREADS=1 taskset -c {CORE} boom-sim run {scene} --out <tmpdir> "
            "--quiet" + "".join(f" {f}" for f in flags)
            + "".join(f" --set {s}" for s in sets) + "`")


def run_once(scene: str, label: str, flags: list[str], sets: list[str], workdir: str) -> dict:
    """One pinned child process: wall and CPU time, exit status, summary.json, output folder."""
    out = tempfile.mkdtemp(prefix=re.sub(r"[^A-Za-z0-9_.-]", "_", label) + "_", dir=workdir)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    env.pop("SIM_CORE_ELEMENT_WORKER", None)
    log_path = os.path.join(out, "stdout.txt")
    with open(log_path, "wb") as log:
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(_command(scene, out, flags, sets), env=env, cwd=ROOT, stdout=log,
                              stderr=subprocess.STDOUT, check=False)
        wall = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    row = {"wall": wall, "exit": proc.returncode, "out": out,
           "cpu": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)}
    try:
        with open(os.path.join(out, "summary.json")) as f:
            row["summary"] = json.load(f)
    except (OSError, ValueError):
        row["summary"] = {}
    if row["exit"] != 0 or not row["summary"]:
        with open(log_path, "rb") as f:
            row["message"] = f.read().decode(errors="replace").strip()[-300:]
    return row


def _stats(values: list[float], fmt: str = ".2f") -> str:
    """median [min, max] of the values ("-" if none; one value where all are equal)."""
    values = [v for v in values if v is not None]
    if not values:
        return "-"
    if min(values) == max(values):
        return format(values[0], fmt)
    mid = statistics.median_low(values) if fmt == "d" else statistics.median(values)
    return (f"{format(mid, fmt)} "
            f"[{format(min(values), fmt)}, {format(max(values), fmt)}]")


def _common(a: Result, b: Result, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Output ``name`` of a and b at b's output times inside both runs (a interpolated where
    the output times differ, e.g. a run that stopped early)."""
    xa, xb = np.asarray(a[name], float), np.asarray(b[name], float)
    if a.t.shape == b.t.shape and np.allclose(a.t, b.t, rtol=0.0, atol=1e-12):
        return xa, xb
    keep = (b.t >= a.t[0]) & (b.t <= a.t[-1])
    xa2 = xa.reshape(len(a.t), -1)
    xi = np.column_stack([np.interp(b.t[keep], a.t, xa2[:, k]) for k in range(xa2.shape[1])])
    return xi.reshape((int(keep.sum()),) + xa.shape[1:]), xb[keep]


def _largest(res: Result, name: str) -> float:
    return float(np.max(np.abs(np.asarray(res[name], float))))


def _rel(x: float, ref: float) -> float:
    return abs(x - ref) / abs(ref) if ref != 0 else float("nan")


def compare(case_npz: str, ref_npz: str) -> dict:
    """Differences of a case's run from the reference run over the output times of both:
    tip position, the largest telescopic-cylinder force and, where both have them, the sway
    angles and the largest hoist-rope and luffing-cylinder forces."""
    a, b = Result.load(case_npz), Result.load(ref_npz)
    ta, tb = _common(a, b, "tip_position")
    dist = np.linalg.norm(ta - tb, axis=1)
    k = int(np.argmax(dist))
    tip_b = np.asarray(b["tip_position"], float)
    travel = float(np.max(np.linalg.norm(tip_b - tip_b[0], axis=1)))
    keep_t = b.t[(b.t >= a.t[0]) & (b.t <= a.t[-1])]
    fa, fb = _largest(a, "telescopic_cylinder_force"), _largest(b, "telescopic_cylinder_force")
    acc = {"tip_max": float(dist[k]), "tip_at": float(keep_t[k]), "travel": travel,
           "tip_rel": float(dist[k]) / travel if travel > 0 else float("nan"),
           "tip_final": float(dist[-1]), "f_case": fa, "f_ref": fb, "f_rel": _rel(fa, fb),
           "n_compared": len(dist), "errors": (a.error, b.error)}
    if "sway_angle" in a and "sway_angle" in b:
        sa, sb = _common(a, b, "sway_angle")
        d = np.degrees(np.abs(sa - sb)).reshape(len(sa), -1)
        j = int(np.argmax(np.max(d, axis=1)))
        acc.update(sway_max=float(np.max(d)), sway_at=float(keep_t[j]),
                   sway_ref=float(np.degrees(_largest(b, "sway_angle"))))
    for name, key in (("hoist_rope_force", "hoist"), ("luffing_cylinder_force", "luff")):
        if name in a and name in b:
            ha, hb = _largest(a, name), _largest(b, name)
            acc.update({f"{key}_case": ha, f"{key}_ref": hb, f"{key}_rel": _rel(ha, hb)})
    return acc


def _failed_lines(rows: list[tuple[str, dict]]) -> list[str]:
    bad = [(label, r) for label, r in rows if r["exit"] != 0 or not r["summary"]]
    if not bad:
        return []
    return ["", "Failed runs:", ""] + [
        f"- {label}: exit {r['exit']}: {r.get('message', '')}" for label, r in bad]


def _quantity_lines(labels: list[str], accs: dict[str, dict | None]) -> list[str]:
    """The compare quantities, one column per case ("-" where a case has none)."""
    got = [accs[c] for c in labels if accs.get(c) is not None]
    if not got:
        return ["No comparison: no case and reference pair wrote result.npz."]

    def row(name: str, cell) -> str:
        cells = []
        for c in labels:
            a = accs.get(c)
            try:
                cells.append(cell(a) if a is not None else "- (no result.npz)")
            except KeyError:
                cells.append("-")
        return f"| {name} | " + " | ".join(cells) + " |"

    n = sorted({a["n_compared"] for a in got})
    lines = ["| quantity (case against the reference `default`) | " + " | ".join(labels) + " |",
             "|---|" + "---|" * len(labels),
             row(f"max over the common output times ({', '.join(map(str, n))}) of "
                 "\\|tip - tip_ref\\|",
                 lambda a: f"{a['tip_max']:.3e} m (at t = {a['tip_at']:.2f} s)"),
             row("tip travel of the reference",
                 lambda a: f"{a['travel']:.3f} m" if a["travel"] >= 1e-3
                 else f"{a['travel']:.3e} m"),
             row("max \\|tip - tip_ref\\| / travel", lambda a: f"{a['tip_rel']:.2e}"),
             row("\\|tip - tip_ref\\| at the last common time",
                 lambda a: f"{a['tip_final']:.3e} m"),
             row("largest telescopic-cylinder force, case / reference",
                 lambda a: f"{a['f_case']:.6g} / {a['f_ref']:.6g} N"),
             row("its relative difference", lambda a: f"{a['f_rel']:.2e}")]
    if any("sway_max" in a for a in got):
        lines += [row("max \\|sway - sway_ref\\| (either component)",
                      lambda a: f"{a['sway_max']:.3e} deg (at t = {a['sway_at']:.2f} s)"),
                  row("largest \\|sway\\| of the reference", lambda a: f"{a['sway_ref']:.3f} deg")]
    if any("hoist_rel" in a for a in got):
        lines += [row("largest hoist-rope force, case / reference",
                      lambda a: f"{a['hoist_case']:.6g} / {a['hoist_ref']:.6g} N"),
                  row("its relative difference", lambda a: f"{a['hoist_rel']:.2e}")]
    if any("luff_rel" in a for a in got):
        lines += [row("largest luffing-cylinder force, case / reference",
                      lambda a: f"{a['luff_case']:.6g} / {a['luff_ref']:.6g} N"),
                  row("its relative difference", lambda a: f"{a['luff_rel']:.2e}")]
    for c in labels:
        a = accs.get(c)
        if a is not None and any(a["errors"]):
            lines += ["", f"{c}: a run stopped early (case, reference): {a['errors']}"]
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default=DEFAULT_SCENE,
                    help=f"shipped scene name or TOML file (default {DEFAULT_SCENE})")
    ap.add_argument("--compare", action="append", default=None, metavar="LABEL:KEY=VALUE[,...]",
                    help="a compare case: the default command once with --set KEY=VALUE for "
                         "each pair, against the first default run (repeatable; default: "
                         + "; ".join(f"{s}: {', '.join(c)}" for s, c in DEFAULT_COMPARE.items())
                         + "; other scenes: twice the sub-elements, friction on where off)")
    ap.add_argument("--runs", type=int, default=None,
                    help="runs per speed case (default 3; 1 with --quick)")
    ap.add_argument("--quick", action="store_true",
                    help="t_end = 2 s, one run per case: checks the script only (writes to "
                         "/tmp/<name>_quick.md unless --out is given)")
    ap.add_argument("--skip-compare", "--skip-accuracy", dest="skip_compare",
                    action="store_true", help="no compare runs and no compare tables")
    ap.add_argument("--out", default=None,
                    help="markdown file (default benchmarks/results/" + out_name(DEFAULT_SCENE)
                         + " for " + DEFAULT_SCENE + ", "
                         + ", ".join(f"{n} for {s}" for s, n in OUT_NAMES.items()
                                     if s != DEFAULT_SCENE)
                         + ", else <scene>_speed.md)")
    args = ap.parse_args(argv)
    scene_name = args.scene
    runs = args.runs if args.runs is not None else (1 if args.quick else 3)
    if runs < 1:
        ap.error("--runs must be at least 1")
    name = out_name(scene_name)
    quick_out = os.path.join(tempfile.gettempdir(), f"{os.path.splitext(name)[0]}_quick.md")
    out_path = args.out or (quick_out if args.quick else os.path.join(RESULTS, name))
    if shutil.which("taskset") is None:
        ap.error("taskset (util-linux) is needed: every run is pinned to one core")
    if CORE not in os.sched_getaffinity(0):
        ap.error(f"core {CORE} is not in this process's affinity set "
                 f"{sorted(os.sched_getaffinity(0))}")
    sets = ["solver.t_end=2"] if args.quick else []
    overrides = dict(s.split("=", 1) for s in sets)
    try:
        scene = load_scene(scene_name, overrides)
    except (SceneError, OSError) as exc:      # a named error, not a trace
        ap.error(f"--scene {scene_name}: {exc}")
    t_end = float(scene["solver"]["t_end"])
    specs = args.compare if args.compare is not None else default_compare(scene_name, scene)
    compares: dict[str, list[str]] = {}
    case_scene: dict[str, dict] = {REF: scene}
    if not args.skip_compare:
        for spec in specs:
            try:
                label, extra = parse_compare(spec)
            except ValueError as exc:
                ap.error(str(exc))
            if label in compares or label in CASES:
                ap.error(f"--compare {spec!r}: label {label!r} used twice or taken by a speed "
                         "case")
            try:                                  # a bad key fails here, not after the runs
                case_scene[label] = load_scene(
                    scene_name, {**overrides, **dict(s.split("=", 1) for s in extra)})
            except (SceneError, OSError) as exc:
                ap.error(f"--compare {spec!r}: {exc}")
            compares[label] = extra
    os.sched_setaffinity(0, {CORE})           # the script too: machine_lines reports core 0

    cpu0, load0 = cpu_times(), os.getloadavg()
    workdir = tempfile.mkdtemp(prefix=f"{os.path.splitext(name)[0]}_")
    results: dict[str, list[dict]] = {c: [] for c in CASES}
    case_runs: dict[str, dict] = {}
    accs: dict[str, dict | None] = {}
    try:
        for k in range(runs):
            for case, flags in CASES.items():
                r = run_once(scene_name, case, flags, sets, workdir)
                results[case].append(r)
                s = r["summary"]
                print(f"{case:9s} run {k + 1}: wall {r['wall']:.2f} s, cpu {r['cpu']:.2f} s, "
                      f"sim wall {s.get('wall_time_s', float('nan')):.2f} s, "
                      f"{s.get('n_steps')} steps, exit {r['exit']}", flush=True)
        ref = results[REF][0]
        ref_npz = os.path.join(ref["out"], "result.npz")
        for label, extra in compares.items():
            r = run_once(scene_name, label, [], sets + extra, workdir)
            case_runs[label] = r
            s = r["summary"]
            print(f"{label}: wall {r['wall']:.2f} s, sim wall "
                  f"{s.get('wall_time_s', float('nan')):.2f} s, {s.get('n_steps')} steps, "
                  f"exit {r['exit']}", flush=True)
            npz = os.path.join(r["out"], "result.npz")
            accs[label] = None
            if os.path.exists(npz) and os.path.exists(ref_npz):
                acc = accs[label] = compare(npz, ref_npz)
                print(f"  against {REF}: max |tip - tip_ref| {acc['tip_max']:.3e} m "
                      f"({acc['tip_rel']:.2e} of travel {acc['travel']:.3f} m); max |F| "
                      f"relative difference {acc['f_rel']:.2e}"
                      + (f"; max |sway - sway_ref| {acc['sway_max']:.3e} deg"
                         if "sway_max" in acc else "")
                      + (f"; hoist force {acc['hoist_rel']:.2e}" if "hoist_rel" in acc else "")
                      + (f"; luffing force {acc['luff_rel']:.2e}" if "luff_rel" in acc
                         else ""), flush=True)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    cpu1, load1 = cpu_times(), os.getloadavg()

    bench_cmd = ("`python benchmarks/user_crane_speed.py"
                 + (f" --scene {scene_name}" if scene_name != DEFAULT_SCENE else "")
                 + "".join(f" --compare {c}" for c in (args.compare or []))
                 + (f" --runs {args.runs}" if args.runs is not None else "")
                 + (" --quick" if args.quick else "")
                 + (" --skip-compare" if args.skip_compare else "")
                 + (f" --out {args.out}" if args.out else "") + "`")
    title = TITLES.get(scene_name, "Scene")
    description = str(scene.get("description", "")).strip()
    lines = [f"# {title} (`{scene_name}`): speed"
             + (f" and compare cases ({', '.join(compares)})" if compares else ""),
             "", (f"{bench_cmd}; scene `{scene_name}`, {t_end:g} s simulated, {runs} run(s) per "
                  "speed case, median [min, max].  Written by benchmarks/user_crane_speed.py "
                  "(its docstring describes the cases and columns)."
                  + ("  QUICK CHECK of the script (t_end = 2 s), not a benchmark."
                     if args.quick else ""))]
    if description:
        lines += ["", f"Scene `{scene_name}`: {description}."
                  if not description.endswith(".") else f"Scene `{scene_name}`: {description}"]
    lines += ["", "Timed commands (each `python -m sim_core.cli run`, the checkout's package):",
              "", *(f"- {case}: {_shown(scene_name, flags, sets)}"
                    for case, flags in CASES.items())]
    for label, extra in compares.items():
        lines.append(f"- {label}: {_shown(scene_name, [], sets + extra)}, against the "
                     f"reference, the first `{REF}` run")
    lines += ["", "Machine state:", "", *machine_lines(cpu0, cpu1, load0, load1), "",
              "## Speed", "",
              ("| case | runs | wall s | RTF | cpu s | sim wall s | sim RTF | steps | RHS "
               "| exit |"),
              "|---|---|---|---|---|---|---|---|---|---|"]
    for case, rows in results.items():
        walls = [r["wall"] for r in rows]
        sums = [r["summary"] for r in rows]
        lines.append(
            f"| {case} | {len(rows)} | {_stats(walls)} | "
            f"{t_end / statistics.median(walls):#.3g} | {_stats([r['cpu'] for r in rows])} | "
            f"{_stats([s.get('wall_time_s') for s in sums])} | "
            f"{_stats([s.get('real_time_factor') for s in sums], '#.3g')} | "
            f"{_stats([s.get('n_steps') for s in sums], 'd')} | "
            f"{_stats([s.get('n_rhs') for s in sums], 'd')} | "
            f"{', '.join(str(e) for e in sorted({r['exit'] for r in rows}))} |")
    lines += ["", ("RTF = simulated time / median wall time of the whole command (start-up, "
                   "building the model (section constants of [[boom]] tables from the on-disk "
                   "cache of `sim_core.physics.cross_sections`, filled by an earlier run), the "
                   "integration, writing the results and, in `default`, the figures); sim RTF "
                   "= the integration's own (summary.json `real_time_factor`).")]
    labelled = [(case, r) for case, rows in results.items() for r in rows]
    if compares:
        ref = results[REF][0]
        lines += ["", "## Compare cases against the reference", "",
                  (f"Reference: the first `{REF}` run (the scene as shipped).  Each case is the "
                   f"`{REF}` command once with its `--set` overrides; differences are case "
                   "minus reference, relative differences divided by the reference's value."),
                  "", ("| run | --set | n_nodes | sub-elements per boom | n_dof | wall s "
                       "| sim wall s | steps | RHS | exit |"),
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for label, r, extra in ([(f"{REF} (reference)", ref, [])]
                                + [(c, case_runs[c], compares[c]) for c in compares]):
            s = r["summary"]
            nn = (case_scene[label if label in case_scene else REF].get("booms") or {}).get(
                "n_nodes", "-")
            sub = nn - 1 if isinstance(nn, int) else "-"
            lines.append(f"| {label} | {' '.join(f'`{e}`' for e in extra) or '-'} | {nn} | "
                         f"{sub} | "
                         f"{s.get('n_dof', '-')} | {r['wall']:.2f} | "
                         f"{_stats([s.get('wall_time_s')])} | {s.get('n_steps', '-')} | "
                         f"{s.get('n_rhs', '-')} | {r['exit']} |")
        lines += ["", *_quantity_lines(list(compares), accs)]
        lines += ["", ("The tip travel is the largest distance of the reference's tip from its "
                       "initial position; a case's outputs are interpolated to the reference's "
                       "output times where they differ; the reference's wall time is the first "
                       f"run of the speed table's `{REF}` case.")]
        labelled += [(c, case_runs[c]) for c in compares]
    failed = _failed_lines(labelled)
    lines += failed
    write_markdown(out_path, lines)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
