"""Command line: ``boom-sim run|sweep|list|describe|plot|animate|export|report|dynamic-factor|fmu``.

``dynamic-factor`` runs a lift-off scene over a grid and writes the hoisting factor φ2
(:mod:`sim_core.dynamic_factor`); ``fmu`` packs a scene as an FMI 2.0 co-simulation FMU
(:mod:`sim_core.fmu`).

``run`` writes result.npz, summary.json, the figures and report.html (:mod:`sim_core.report`:
one self-contained page with the summary, the self-checks and an interactive plot of every
output; ``--no-report`` skips it); ``report`` writes that page again from a result file.
While it runs, ``run`` keeps the integrator's whole state in OUT/checkpoint.pkl
(``--checkpoint-every``, every 30 wall seconds by default; :mod:`sim_core.checkpoint`) and
``run --resume`` continues a killed run from it (and starts from t = 0 where there is none);
a damaged checkpoint or one of another scene exits with status 2.
Errors in the scene (or an unreadable result file for ``plot``, ``report``, ...) exit with
status 2 and a one-line message; a failed solve exits with status 3 and a one-line message
(time and reason), after writing summary.json with the error and, if the solver attached one
to the SimulationError (``.result``), the partial result.npz.  ``sweep`` (:mod:`sim_core.sweep`)
exits with status 2 for an invalid case or grid before running anything, 3 if any case failed (the
others still run) and 130 when interrupted (finished cases and the summary are kept).

``run``'s wall budget ``solver.max_wall_s`` covers the whole run (statics, integration,
outputs, figures, report: :mod:`sim_core.run_control`); Ctrl-C only sets the run's interrupt
flag, which every phase checks with the budget, so a run out of budget or interrupted exits
with status 3 and its partial result (a second Ctrl-C quits at once, status 130).  ``run``
and ``sweep`` lock their output folder while they write into it: a second writer is refused
with status 2, as is an ``--out`` naming a file (or, for ``report`` and ``animate``, a folder),
before anything runs.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import signal
import sys
import time
from pathlib import Path

from sim_core import run_control
from sim_core.api import load_scene, simulate
from sim_core.errors import SceneError, SimulationError
from sim_core.registry import system_kind
from sim_core.result import Result, atomic_write_bytes
from sim_core.scene.io import shipped_scenes


def _plain(text: str) -> str:
    """A docstring line for the terminal: reST literals (``x``) and roles (:mod:`x`) as plain
    text."""
    text = re.sub(r":[a-z]+:`~?([^`]+)`", r"\1", text)
    return text.replace("``", "")


def _overrides(items: list[str] | None) -> dict:
    out = {}
    for it in items or []:
        if "=" not in it:
            raise SceneError(f"--set {it!r}: expected KEY=VALUE, e.g. solver.t_end=4")
        k, v = it.split("=", 1)
        out[k.strip()] = v.strip()
    return out


class _Progress:
    """One-line progress: simulated time, wall time and real-time factor (tqdm if present)."""

    def __init__(self, t_end: float, enabled: bool):
        self.t_end = t_end
        self.bar = None
        self.last = 0.0
        if enabled:
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=t_end, unit="s(sim)", bar_format=(
                    "{l_bar}{bar}| {n:.3f}/{total:.3f} s sim [{elapsed} wall{postfix}]"),
                    file=sys.stderr)
            except ImportError:  # pragma: no cover
                self.bar = None

    def __call__(self, t: float, wall: float) -> None:
        if self.bar is None or wall - self.last < 0.2:
            return
        self.last = wall
        self.bar.n = min(t, self.t_end)
        self.bar.set_postfix_str(f"RTF {t / max(wall, 1e-9):.3g}")
        self.bar.refresh()

    def close(self, finished: bool = True):
        if self.bar is not None:
            if finished:
                self.bar.n = self.t_end
            self.bar.close()
            self.bar = None


def _one_line(msg: object) -> str:
    return " ".join(str(msg).split())


def _checkpoint_policy(args, out: Path):
    """``run``'s checkpoint policy: OUT/checkpoint.pkl every --checkpoint-every wall seconds
    (required: a run path without checkpoints is refused), by default every 30 s where the
    run path has them (a run shorter than that writes none); --checkpoint-every 0: none."""
    from sim_core.checkpoint import DEFAULT_EVERY_S, CheckpointPolicy
    every = args.checkpoint_every
    if every is not None and not every >= 0:
        raise _InputError(f"--checkpoint-every {every:g}: wall seconds between checkpoints, "
                          "allowed [0, inf) (0: no checkpoints)")
    if every == 0:
        if args.resume:
            raise _InputError("--resume with --checkpoint-every 0: a resume reads the "
                              "checkpoint (leave --checkpoint-every out or give it > 0)")
        return None
    return CheckpointPolicy(out / CHECKPOINT_FILE, DEFAULT_EVERY_S if every is None else every,
                            required=every is not None)


CHECKPOINT_FILE = "checkpoint.pkl"
#: the animation ``run --animate`` writes into its output folder (``report`` embeds it)
ANIMATION_FILE = "anim.gif"


def _out_folder(path: str, option: str = "--out", create: bool = True) -> Path:
    """An output folder named on the command line, checked before anything runs: not a file
    (nor below one), and created where ``create`` (a folder that cannot be created or written
    is an input error naming ``option``)."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise _InputError(f"{option} {path!r}: is a file, not a folder")
    for parent in out.parents:
        if parent.exists() and not parent.is_dir():
            raise _InputError(f"{option} {path!r}: {str(parent)!r} is a file, not a folder")
    if create:
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise _InputError(f"{option} {path!r}: cannot create the folder: "
                              f"{exc.strerror or exc}") from None
        if not os.access(out, os.W_OK | os.X_OK):
            raise _InputError(f"{option} {path!r}: the folder is not writable")
    return out


def _out_file(path: str, option: str = "--out") -> Path:
    """An output file named on the command line, checked before anything is computed: not a
    folder, and its folder not a file."""
    out = Path(path)
    if out.is_dir():
        raise _InputError(f"{option} {path!r}: is a folder, not a file")
    for parent in out.parents:
        if parent.exists() and not parent.is_dir():
            raise _InputError(f"{option} {path!r}: {str(parent)!r} is a file, not a folder")
    return out


@contextlib.contextmanager
def _folder_locked(out: Path, option: str = "--out"):
    """The output folder's lock (sim_core.run_control.folder_lock) for the block; a folder in
    use by another boom-sim is an input error (exit status 2)."""
    with contextlib.ExitStack() as stack:
        try:
            stack.enter_context(run_control.folder_lock(out, option))
        except run_control.FolderBusy as exc:
            raise _InputError(str(exc)) from None
        yield


@contextlib.contextmanager
def _interrupt_flag(budget: run_control.RunBudget):
    """Within the block Ctrl-C (SIGINT) only sets the run's interrupt flag, which every phase
    checks with its wall budget (sim_core.run_control), so that no KeyboardInterrupt is raised
    inside compiled code; a second Ctrl-C raises KeyboardInterrupt at once (force-quit)."""
    def handler(signum, frame):
        if budget.interrupted:
            raise KeyboardInterrupt
        budget.interrupt()
    try:
        old = signal.signal(signal.SIGINT, handler)
    except ValueError:            # not the main thread: signals stay as they are
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def cmd_run(args) -> int:
    # the run's wall budget (solver.max_wall_s) counts from here: statics, integration,
    # outputs, files, figures and report
    budget = run_control.RunBudget(None)
    with _interrupt_flag(budget):
        _out_folder(args.out, create=False)             # a file named --out: before the run
        scene = load_scene(args.scene, _overrides(args.set))
        budget.max_wall_s = scene["solver"].get("max_wall_s")
        out = _out_folder(args.out)
        policy = _checkpoint_policy(args, out)
        try:
            with _folder_locked(out), run_control.run_budget(budget):
                return _run(args, scene, out, policy)
        except KeyboardInterrupt:         # a second Ctrl-C: quit without the partial result
            print(f"boom-sim: interrupted twice: stopped without writing the partial result "
                  f"(files in {out} may be incomplete)", file=sys.stderr)
            return 130


def _run(args, scene: dict, out: Path, policy) -> int:
    """``run`` in its locked output folder under the run's budget (cmd_run)."""
    from sim_core.checkpoint import CheckpointError, checkpointing
    resume = bool(args.resume)
    if resume and policy is not None and not Path(policy.path).exists():
        # nothing to continue (no run was cut short here, or it finished): a fresh run, so
        # that one command line serves the first start and every restart of a batch job
        print(f"boom-sim: no checkpoint in {policy.path}: starting from t = 0", file=sys.stderr)
        resume = False
    prog = _Progress(scene["solver"]["t_end"], not args.quiet)
    try:
        with checkpointing(policy, resume=resume):
            result = simulate(scene, progress=prog)
    except CheckpointError as exc:
        prog.close(finished=False)
        raise _InputError(str(exc)) from None
    except SimulationError as exc:
        prog.close(finished=False)
        return _failed(scene, out, exc, policy)
    prog.close()
    try:
        result.save(out / "result.npz")
        summary = {"scene": scene["name"], **result.stats}
        atomic_write_bytes(out / "summary.json",
                           json.dumps(summary, indent=2, default=str).encode())
        if policy is not None:          # the result is written: the checkpoint is obsolete
            policy.clear()
        t_last = float(result.t[-1]) if len(result.t) else 0.0
        run_control.check("figures", t_last)
        figs = [] if args.no_plots else _plots(result, out)
        if args.animate:
            run_control.check("figures", t_last)
            figs.append(_animate(result, out / ANIMATION_FILE))
        report = None
        if not args.no_report:
            run_control.check("report", t_last)
            report = _report(result, out / "report.html",
                             out / ANIMATION_FILE if args.animate else None)
    except SimulationError as exc:     # the budget or Ctrl-C after the result: it is whole
        exc.result = result
        return _failed(scene, out, exc, policy)
    st = result.stats
    wall = float(st.get("wall_time_s", 0.0))
    rtf = st.get("real_time_factor", scene["solver"]["t_end"] / max(wall, 1e-12))
    work = "; ".join(f"{st[k]} {label}" for k, label in
                     (("n_steps", "steps"), ("n_rhs", "RHS")) if k in st)
    load = st.get("load_start")
    machine = (f"; whole run {st['wall_s']:.1f} s wall, {st['cpu_s']:.1f} s CPU"
               + (f", load {load[0]:g} on {st.get('usable_cpus', '?')} CPUs" if load else "")
               if "wall_s" in st and "cpu_s" in st else "")
    print(f"{scene['name']}: {scene['solver']['t_end']:g} s simulated in {wall:.1f} s wall "
          f"(RTF {rtf:.3g})" + (f"; {work}" if work else "") + machine + f"; wrote {out}/result.npz, "
          f"summary.json" + (f", {len(figs)} figures" if figs else "")
          + (", report.html" if report else ""))
    if result.suspect:                 # a cheap self-check failed (summary.json: failed_checks)
        print(f"boom-sim: warning: {result.suspect_note()}", file=sys.stderr)
    return 0


def _failed(scene: dict, out: Path, exc: SimulationError, policy) -> int:
    """A failed run's files (:func:`_save_failure`), its one-line message; exit status 3."""
    note = _save_failure(scene, out, exc)
    if policy is not None and Path(policy.path).is_file():
        note += f"; the last checkpoint is kept ({policy.path}: --resume continues from it)"
    print(f"boom-sim: {_one_line(exc)}{note}", file=sys.stderr)
    return 3


def _save_failure(scene: dict, out: Path, exc: SimulationError) -> str:
    """Keep what a failed run produced: the partial result (if the solver attached one, with
    ``error`` set) and a summary.json naming the failure.  Returns a note for the one-line
    message.  Never raises (the SimulationError is what the user must see); a file that cannot
    be written is reported on stderr."""
    partial = getattr(exc, "result", None)         # the outputs up to the failure, if any
    summary = {"scene": scene["name"], "error": _one_line(exc), "t_fail_s": exc.t,
               "step_s": exc.step, "result_file": None}
    try:
        if partial is not None:
            if partial.error is None:
                partial.error = _one_line(exc)
            if not partial.scene:
                partial.scene = scene
            partial.save(out / "result.npz")
            summary["result_file"] = "result.npz"
            summary.update({k: v for k, v in partial.stats.items() if k not in summary})
        atomic_write_bytes(out / "summary.json", json.dumps(summary, indent=2, default=str).encode())
    except Exception as w:  # noqa: BLE001 - report and go on to the exit status 3
        print(f"boom-sim: warning: could not write the failed run's files to {out}: {_one_line(w)}",
              file=sys.stderr)
        return ""
    if partial is None:
        return f"; no partial result (summary.json written to {out})"
    if not len(partial.t):
        return f"; no output times reached (result.npz written to {out})"
    t_last = float(partial.t[-1])
    return f"; partial result up to t = {t_last:.6g} s written to {out / 'result.npz'}"


def _load_result(path) -> Result:
    try:
        return Result.load(path)
    except (OSError, ValueError, KeyError) as exc:
        raise _InputError(f"cannot read result file {str(path)!r}: {_one_line(exc)}") from None


def _animate(result: Result, out: Path, **kw) -> Path:
    """The run's animation (sim_core.animation); a result without replay geometry is an input
    error naming why."""
    from sim_core.animation import animate
    try:
        return animate(result, out, **kw)
    except (ValueError, ImportError) as exc:
        raise _InputError(f"cannot animate: {_one_line(exc)}") from None


def cmd_animate(args) -> int:
    _out_file(args.out)
    res = _load_result(args.result)
    kw = {"scale": args.scale, "speed": args.speed, "fps": args.fps, "t_start": args.t_start,
          "t_end": args.t_end, "view": args.view}
    if args.overlay:
        kw["overlays"] = tuple(args.overlay)
    path = _animate(res, Path(args.out), **kw)
    print(f"wrote {path}")
    return 0


def cmd_export(args) -> int:
    from sim_core.vtk_export import export_vtk
    _out_folder(args.vtk, "--vtk", create=False)
    res = _load_result(args.result)
    try:
        pvd = export_vtk(res, Path(args.vtk))
    except (ValueError, OSError) as exc:
        raise _InputError(f"cannot export: {_one_line(exc)}") from None
    print(f"wrote {pvd} ({len(res.t)} time steps; open it in ParaView)")
    return 0


def _report(result: Result, path: Path, animation: Path | None = None,
            plotlyjs: bool | str = True) -> Path | None:
    """The run's report (sim_core.report); a missing plotly only skips it (the result files
    are already written), a bad animation file or a failed write is an input error."""
    try:
        import plotly  # noqa: F401

        from sim_core.report import write_report
    except ImportError:
        print("boom-sim: warning: plotly is not installed, report.html skipped", file=sys.stderr)
        return None
    try:
        return write_report(result, path, animation=animation, include_plotlyjs=plotlyjs)
    except (ValueError, OSError) as exc:
        raise _InputError(f"cannot write the report: {_one_line(exc)}") from None


def cmd_report(args) -> int:
    out = _out_file(args.out) if args.out else Path(args.result).parent / "report.html"
    res = _load_result(args.result)
    try:
        import plotly  # noqa: F401
    except ImportError:
        raise _InputError("plotly is not installed (pip install plotly)") from None
    # the run's animation (run --animate) where one sits beside the result
    beside = Path(args.result).parent / ANIMATION_FILE
    animation = (Path(args.animation) if args.animation else
                 beside if not args.no_animation and beside.is_file() else None)
    path = _report(res, out, animation, "directory" if args.plotly_beside else True)
    print(f"wrote {path}" + (f" (animation: {animation})" if animation is not None else ""))
    return 0


def _plots(result: Result, out: Path) -> list:
    """Figures; a missing matplotlib only skips them (the result files are already written)."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        print("boom-sim: warning: matplotlib is not installed, figures skipped", file=sys.stderr)
        return []
    return _figures(result, out)


def _figures(result: Result, out: Path) -> list:
    """Every figure of the result's system kind (``run`` and ``plot``)."""
    return system_kind(result.scene).figures(result, out)


def cmd_list(args) -> int:
    for name, path in sorted(shipped_scenes().items()):
        sc = load_scene(path)
        print(f"{name:32s} {sc['description']}")
    return 0


def cmd_describe(args) -> int:
    scene = load_scene(args.scene, _overrides(args.set))
    kind = system_kind(scene)
    if args.json:
        # one JSON object: the resolved scene and, where the kind computes them, its derived
        # properties (telescopic: every boom's section constants and the luffing lever)
        out = {"scene": {k: v for k, v in scene.items() if k != "source"}}
        if hasattr(kind, "properties"):
            out.update(kind.properties(scene))
        print(json.dumps(out, indent=2))
        return 0
    print(f"scene {scene['name']}: {scene['description']}")
    print("effects: " + ", ".join(f"{k}={'on' if v else 'off'}" for k, v in scene["effects"].items()))
    for line in kind.describe(scene):
        print(line)
    print(json.dumps({k: v for k, v in scene.items() if k != "source"}, indent=2))
    return 0


def cmd_plot(args) -> int:
    if args.out:
        _out_folder(args.out, create=False)
    res = _load_result(args.result)
    out = _out_folder(args.out) if args.out else Path(args.result).parent
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise _InputError("matplotlib is not installed (pip install matplotlib)") from None
    figs = _figures(res, out)
    print(f"wrote {len(figs)} figures to {out}")
    return 0


def _grid_and_fixed(args) -> tuple[dict, dict]:
    """The --grid values and the --set overrides of a sweep; a key in both is refused."""
    from sim_core.sweep import parse_grid
    grid = parse_grid(args.grid)
    fixed = _overrides(args.set)
    both = sorted(set(grid) & set(fixed))
    if both:
        raise SceneError(f"--grid {both[0]} and --set {both[0]}: a key is either swept or fixed")
    return grid, fixed


def cmd_sweep(args) -> int:
    from sim_core.sweep import SweepError, run_sweep
    grid, fixed = _grid_and_fixed(args)
    t0 = time.perf_counter()
    try:
        every = args.checkpoint_every
        if not every >= 0:
            raise _InputError(f"--checkpoint-every {every:g}: wall seconds between a case's "
                              "checkpoints, allowed [0, inf) (0: none)")
        fresh = not Path(args.out).exists()
        out = _out_folder(args.out)
        try:
            with _folder_locked(out):         # one sweep at a time writes into --out
                rows = run_sweep(args.scene, grid, args.out, fixed=fixed,
                                 address=args.address, workers=args.workers, quiet=args.quiet,
                                 plots=args.plots, retries=args.retries,
                                 checkpoint_every=every or float("inf"))
        except (SweepError, SceneError):
            if fresh:                         # refused before any case ran: leave no folder
                with contextlib.suppress(OSError):
                    out.rmdir()
            raise
    except SweepError as exc:
        raise _InputError(str(exc)) from None
    except KeyboardInterrupt:
        print(f"boom-sim: sweep interrupted; finished cases and {args.out}/summary.csv kept "
              f"(run the same command again to resume)", file=sys.stderr)
        return 130
    st = [r["status"] for r in rows]
    out = Path(args.out)
    files = ["summary.csv"] + [f for f in ("summary.parquet", "summary.png") if (out / f).exists()]
    print(f"{args.scene}: {len(rows)} cases in {time.perf_counter() - t0:.1f} s wall: "
          f"{st.count('ok')} ok, {st.count('failed')} failed, {st.count('skipped')} skipped; "
          f"wrote {out}/{{{','.join(files)}}}")
    failed = [r for r in rows if r["status"] == "failed"]
    for r in failed:
        print(f"boom-sim: case {r['case']} failed: {r['error_type']}: {r['error']}", file=sys.stderr)
    return 3 if failed else 0


class _InputError(Exception):
    """A bad command-line input other than a scene (exit status 2)."""


def cmd_dynamic_factor(args) -> int:
    """The hoisting load case over a grid (:mod:`sim_core.dynamic_factor`): exit 2 for a bad
    scene or grid, 3 if a cell failed (the others still run)."""
    from sim_core.dynamic_factor import dynamic_factor
    from sim_core.sweep import SweepError
    grid, fixed = _grid_and_fixed(args)
    t0 = time.perf_counter()
    try:
        out = _out_folder(args.out)
        with _folder_locked(out):
            rows = dynamic_factor(args.scene, grid, out, fixed=fixed, slack=args.slack,
                                  after=args.after,
                                  serial=True if args.serial else None, workers=args.workers,
                                  quiet=args.quiet)
    except SweepError as exc:
        raise _InputError(str(exc)) from None
    failed = [r for r in rows if r["status"] == "failed"]
    print(f"{args.scene}: {len(rows)} lift-offs in {time.perf_counter() - t0:.1f} s wall, "
          f"{len(failed)} failed; wrote {out}/dynamic_factor.{{csv,md,png}}")
    for r in failed:
        print(f"boom-sim: case {r['case']} failed: {r.get('error')}", file=sys.stderr)
    return 3 if failed else 0


_DYNAMIC_FACTOR_HELP = """\
The hoisting load case (EN 13001-2 / ISO 8686-1): lift a grounded payload off for every cell
of the --grid (boom lengths or strokes, luffing angles, hoisting speeds hoist_drive.v_max) and
write into --out the case folders, dynamic_factor.csv and .md (per cell: working radius,
hoisting speed v_h, phi2 = peak rope force / static rope force, the rigid-crane value
1 + (v_h/g) sqrt(k/m), the tip's peak deflection, EN 13001-2's phi2 = phi2_min + beta2 v_h for
HC1-HC4) and dynamic_factor.png (phi2 and the deflection against the working radius).  The
scene needs effects.ground and a [hoist_drive] winding in; each cell starts with the rope
--slack m slack and runs --after s past the time the hoist has wound that in.  Cells run as
Ray tasks where Ray is installed (--serial: one after the other here).

example:
  boom-sim dynamic-factor crane_lift_off --grid booms.luffing_angle_deg=30,45,60 \\
      --grid hoist_drive.v_max=0.25,0.5 --out phi2
"""


_SWEEP_HELP = """\
Run the Cartesian product of the --grid values as Ray tasks, one simulation per task (1 CPU
each), and write into --out: one folder per case (named from its overrides; result.npz and
summary.json, written under a temporary name and renamed into place), summary.csv (Parquet
too if pyarrow is installed: overrides, status ok/failed/skipped, error type and message,
wall time, steps, scalar outcomes) and summary.png (each outcome against the first grid key).
Every case is validated before anything runs.  Running the same command again skips the
cases already done; a failed case is recorded and the others go on; Ctrl-C keeps the
finished cases.  A case whose worker process dies (killed, out of memory) is retried
--retries times, resuming from its checkpoint (OUT/.checkpoints, every --checkpoint-every
wall seconds), then recorded as failed; running the command again runs only the failed and
missing cases.  Needs Ray (pip install 'telescopic-boom-sim[cluster]').

example:
  boom-sim sweep telescopic_extraction_rl --grid payload.mass=20000,25000,30000 \\
      --grid booms.luffing_angle_deg=45,60,75 --out sweep_rl --workers 2
"""

_EPILOG = """\
sweeps:
  boom-sim sweep SCENE --grid KEY=V1,V2,... [--grid ...] [--set KEY=VALUE] --out DIR
                 [--address ADDR] [--workers N]
  runs every combination of the grid values as a Ray task (local Ray by default, --address
  joins a cluster), writes one result folder per case, DIR/summary.csv and DIR/summary.png;
  re-running skips finished cases.  Details: boom-sim sweep --help.
"""


def cmd_fmu(args) -> int:
    """Pack a scene as an FMI 2.0 co-simulation FMU (:mod:`sim_core.fmu`): exit 2 for a bad
    scene or option."""
    from sim_core.fmu import build_fmu
    out = _out_file(args.out)
    if out.suffix != ".fmu":
        raise _InputError(f"--out {args.out!r}: an FMU file name ends in .fmu")
    lists = {k: None if v is None else [x.strip() for x in ",".join(v).split(",") if x.strip()]
             for k, v in (("outputs", args.outputs), ("inputs", args.inputs))}
    path, cfg = build_fmu(args.scene, out, step_size=args.step, overrides=_overrides(args.set),
                          parameters=args.param or (), outputs=lists["outputs"],
                          inputs=lists["inputs"], limits=args.limits, stop_time=args.stop_time,
                          model_name=args.name)
    print(f"wrote {path}: {cfg['model_name']}, {len(cfg['inputs'])} inputs, "
          f"{len(cfg['outputs'])} outputs, {len(cfg['parameters'])} parameters, "
          f"step {cfg['step_size']:g} s")
    return 0


_FMU_HELP = """\
Pack a scene as an FMI 2.0 co-simulation FMU (pythonfmu): inputs command_<actuator> (the
actuator's acceleration, m/s^2 or rad/s^2, held over each communication step), outputs one
scalar per component of the chosen outputs (tip_position_x, ..., actuator_<name>_position),
parameters the scene keys named with --param (applied when the FMU is initialized).  The FMU
carries the scene; running it needs Python with telescopic-boom-sim (this version) installed
on the target machine.  Needs pip install 'telescopic-boom-sim[fmu]'.

example:
  boom-sim fmu crane_lift_and_slew --out crane.fmu --step 0.01 --param payload.mass \\
      --outputs tip_position,sway_angle,hoist_rope_force,actuators
"""


def _fmu_parser(sub) -> None:
    fm = sub.add_parser("fmu", help="pack a scene as an FMI 2.0 co-simulation FMU",
                        description=_FMU_HELP,
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    fm.add_argument("scene", help="shipped scene name or path to a TOML scene")
    fm.add_argument("--out", required=True, help="the FMU file (NAME.fmu)")
    fm.add_argument("--step", type=float, default=0.01, metavar="S",
                    help="the default communication step, s (default: %(default)g; the "
                         "importer may use others)")
    fm.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="fix a scene value in the FMU")
    fm.add_argument("--param", action="append", metavar="KEY",
                    help="a scene key (a number) as an FMU parameter, e.g. payload.mass "
                         "(repeat for more)")
    fm.add_argument("--outputs", action="append", metavar="NAME,...",
                    help="the outputs (Simulation.outputs names; default: tip position and "
                         "deflection, sway angles, cylinder forces, slew torque, rope force, "
                         "pad forces and the actuators, those the scene has)")
    fm.add_argument("--inputs", action="append", metavar="ACTUATOR,...",
                    help="the commanded actuators (default: all); the others follow the "
                         "scene's profiles")
    fm.add_argument("--limits", choices=("raise", "clip"), default="raise",
                    help="a command beyond an actuator's limits fails the step (raise, "
                         "default) or is held at the limits (clip)")
    fm.add_argument("--stop-time", type=float, default=None, metavar="S",
                    help="the default experiment's stop time, s (default: solver.t_end)")
    fm.add_argument("--name", default=None,
                    help="the model identifier (default: the scene's name)")
    fm.set_defaults(func=cmd_fmu)


def _dynamic_factor_parser(sub) -> None:
    df = sub.add_parser("dynamic-factor", help="the hoisting load case: phi2 of a lift-off over "
                                               "a grid, with EN 13001-2's values",
                        description=_DYNAMIC_FACTOR_HELP,
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    df.add_argument("scene", help="shipped scene name (e.g. crane_lift_off) or TOML path")
    df.add_argument("--grid", action="append", default=[], metavar="KEY=V1,V2,...",
                    help="a swept scene key and its values (repeat for more keys)")
    df.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="override a scene value in every cell")
    df.add_argument("--out", required=True, help="output folder (created)")
    df.add_argument("--slack", type=float, default=0.05, metavar="M",
                    help="slack of the hoist rope at the start, m (default: %(default)g)")
    df.add_argument("--after", type=float, default=1.0, metavar="S",
                    help="simulated time after the rope is taut, s (default: %(default)g)")
    df.add_argument("--serial", action="store_true",
                    help="run the cells one after the other in this process (no Ray)")
    df.add_argument("--workers", type=int, default=None, metavar="N",
                    help="at most N cells at a time (Ray)")
    df.add_argument("--quiet", action="store_true", help="no progress bar")
    df.set_defaults(func=cmd_dynamic_factor)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="boom-sim", description=_plain(__doc__.splitlines()[0]),
                                epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="simulate a scene, write result.npz, summary.json, figures")
    r.add_argument("scene", help="shipped scene name or path to a TOML scene")
    r.add_argument("--out", default="results", help="output folder (default: results)")
    r.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene value")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.add_argument("--no-plots", action="store_true")
    r.add_argument("--animate", action="store_true",
                   help="also write anim.gif, the crane in motion (telescopic full model)")
    r.add_argument("--no-report", action="store_true",
                   help="no report.html (the summary, checks and every output, plotly)")
    r.add_argument("--checkpoint-every", type=float, default=None, metavar="S",
                   help="write the integrator's whole state to OUT/checkpoint.pkl at most every "
                        "S wall seconds (default: 30 where the run path has checkpoints; a run "
                        "shorter than that writes none; 0: none); removed once the result is "
                        "written")
    r.add_argument("--resume", action="store_true",
                   help="continue from OUT/checkpoint.pkl, or start from t = 0 where there "
                        "is none (exit 2 if it is damaged or was written for another scene); "
                        "the result equals the uninterrupted run's")
    r.set_defaults(func=cmd_run)
    sw = sub.add_parser("sweep", help="run the Cartesian product of scene overrides as Ray tasks",
                        description=_SWEEP_HELP, formatter_class=argparse.RawDescriptionHelpFormatter)
    sw.add_argument("scene", help="shipped scene name or path to a TOML scene")
    sw.add_argument("--grid", action="append", required=True, metavar="KEY=V1,V2,...",
                    help="a swept scene key and its values (repeat for more keys; TOML arrays "
                         "and quoted strings may contain commas)")
    sw.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="override a scene value in every case")
    sw.add_argument("--out", required=True, help="output folder (created; reused to resume)")
    sw.add_argument("--address", default=None,
                    help="join this Ray cluster (Ray's address format, e.g. auto or "
                         "ray://head:10001); default: start a local Ray")
    sw.add_argument("--workers", type=int, default=None, metavar="N",
                    help="at most N cases at a time (local Ray: N CPUs; default: all cores)")
    sw.add_argument("--plots", action="store_true",
                    help="also write the figures of 'run' into every case folder")
    sw.add_argument("--quiet", action="store_true", help="no progress bar")
    sw.add_argument("--retries", type=int, default=2, metavar="N",
                    help="run a case whose worker process died up to N more times, then record "
                         "it as failed (default: %(default)s)")
    sw.add_argument("--checkpoint-every", type=float, default=30.0, metavar="S",
                    help="a case's checkpoint every S wall seconds, which its retry resumes "
                         "from (default: %(default)g; 0: none)")
    sw.set_defaults(func=cmd_sweep)
    _dynamic_factor_parser(sub)
    _fmu_parser(sub)
    sub.add_parser("list", help="shipped scenes").set_defaults(func=cmd_list)
    d = sub.add_parser("describe", help="resolved scene, effects and DOF count")
    d.add_argument("scene")
    d.add_argument("--set", action="append", metavar="KEY=VALUE")
    d.add_argument("--json", action="store_true",
                   help="print one JSON object: the resolved scene and its derived properties "
                        "(telescopic: every boom's section constants, the luffing lever)")
    d.set_defaults(func=cmd_describe)
    pl = sub.add_parser("plot", help="figures from a result file")
    pl.add_argument("result")
    pl.add_argument("--out", default=None)
    pl.set_defaults(func=cmd_plot)
    an = sub.add_parser("animate", help="an animation of a result (GIF or MP4)")
    an.add_argument("result")
    an.add_argument("--out", default="anim.gif", help="anim.gif or anim.mp4 (default anim.gif)")
    an.add_argument("--scale", type=float, default=1.0,
                    help="deflection exaggeration (1: the true shape)")
    an.add_argument("--speed", type=float, default=1.0, help="playback speed (1: real time)")
    an.add_argument("--fps", type=int, default=20, help="frames per second")
    an.add_argument("--t-start", type=float, default=None, help="window start, s")
    an.add_argument("--t-end", type=float, default=None, help="window end, s")
    an.add_argument("--view", choices=("3d", "two"), default="3d",
                    help="a 3-D view or a side and a top view")
    an.add_argument("--overlay", action="append", metavar="OUTPUT",
                    help="an output shown with its value (repeat; default: stroke and "
                         "telescopic cylinder force)")
    an.set_defaults(func=cmd_animate)
    ex = sub.add_parser("export", help="a result as a ParaView time series")
    ex.add_argument("result")
    ex.add_argument("--vtk", required=True, metavar="DIR",
                    help="folder for result.pvd and one .vtu per output time")
    ex.set_defaults(func=cmd_export)
    rp = sub.add_parser("report", help="one HTML page of a result: summary, checks, every "
                                       "output as an interactive plot")
    rp.add_argument("result")
    rp.add_argument("--out", default=None,
                    help="the HTML file (default: report.html beside the result)")
    rp.add_argument("--animation", default=None, metavar="FILE",
                    help=f"a GIF or MP4 (boom-sim animate) to embed in the page (default: "
                         f"{ANIMATION_FILE} beside the result, which run --animate writes, "
                         f"where there is one)")
    rp.add_argument("--no-animation", action="store_true",
                    help=f"no animation in the page, even with {ANIMATION_FILE} beside the "
                         "result")
    rp.add_argument("--plotly-beside", action="store_true",
                    help="load plotly.js from plotly.min.js beside the page (written there) "
                         "instead of carrying it inside: a small page, one library for a "
                         "folder of reports")
    rp.set_defaults(func=cmd_report)
    args = p.parse_args(argv)
    try:
        return args.func(args)
    except BrokenPipeError:
        # the reader of the output went away (``boom-sim describe ... | head``): not an error;
        # stdout goes to /dev/null so that the interpreter's final flush stays quiet
        import os
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except SceneError as exc:
        print(f"boom-sim: scene error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except _InputError as exc:
        print(f"boom-sim: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except SimulationError as exc:
        print(f"boom-sim: {_one_line(exc)}", file=sys.stderr)
        return 3


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
