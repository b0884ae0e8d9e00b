"""Command line: ``boom-sim run|sweep|list|describe|plot|animate|export|report``.

``run`` writes result.npz, summary.json, the figures and report.html (:mod:`sim_core.report`:
one self-contained page with the summary, the self-checks and an interactive plot of every
output; ``--no-report`` skips it); ``report`` writes that page again from a result file.
While it runs, ``run`` keeps the integrator's whole state in OUT/checkpoint.pkl
(``--checkpoint-every``, every 30 wall seconds by default; :mod:`sim_core.checkpoint`) and
``run --resume`` continues a killed run from it; a bad checkpoint exits with status 2.
Errors in the scene (or an unreadable result file for ``plot``, ``report``, ...) exit with
status 2 and a one-line message; a failed solve exits with status 3 and a one-line message
(time and reason), after writing summary.json with the error and, if the solver attached one
to the SimulationError (``.result``), the partial result.npz.  ``sweep`` (:mod:`sim_core.sweep`)
exits with status 2 for an invalid case or grid before running anything, 3 if any case failed (the
others still run) and 130 when interrupted (finished cases and the summary are kept).
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import time
from pathlib import Path

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


def cmd_run(args) -> int:
    from sim_core.checkpoint import CheckpointError, checkpointing
    scene = load_scene(args.scene, _overrides(args.set))
    out = Path(args.out)
    policy = _checkpoint_policy(args, out)
    prog = _Progress(scene["solver"]["t_end"], not args.quiet)
    try:
        with checkpointing(policy, resume=bool(args.resume)):
            result = simulate(scene, progress=prog)
    except CheckpointError as exc:
        prog.close(finished=False)
        raise _InputError(str(exc)) from None
    except SimulationError as exc:
        prog.close(finished=False)
        note = _save_failure(scene, out, exc)
        if policy is not None and Path(policy.path).is_file():
            note += f"; the last checkpoint is kept ({policy.path}: --resume continues from it)"
        print(f"boom-sim: {_one_line(exc)}{note}", file=sys.stderr)
        return 3
    prog.close()
    result.save(out / "result.npz")
    summary = {"scene": scene["name"], **result.stats}
    atomic_write_bytes(out / "summary.json", json.dumps(summary, indent=2, default=str).encode())
    if policy is not None:          # the result is written: the checkpoint is obsolete
        policy.clear()
    figs = [] if args.no_plots else _plots(result, out)
    if args.animate:
        figs.append(_animate(result, out / "anim.gif"))
    report = None if args.no_report else _report(result, out / "report.html",
                                                 out / "anim.gif" if args.animate else None)
    st = result.stats
    wall = float(st.get("wall_time_s", 0.0))
    rtf = st.get("real_time_factor", scene["solver"]["t_end"] / max(wall, 1e-12))
    work = "; ".join(f"{st[k]} {label}" for k, label in
                     (("n_steps", "steps"), ("n_rhs", "RHS")) if k in st)
    print(f"{scene['name']}: {scene['solver']['t_end']:g} s simulated in {wall:.1f} s wall "
          f"(RTF {rtf:.3g})" + (f"; {work}" if work else "") + f"; wrote {out}/result.npz, "
          f"summary.json" + (f", {len(figs)} figures" if figs else "")
          + (", report.html" if report else ""))
    if result.suspect:                 # a cheap self-check failed (summary.json: failed_checks)
        print(f"boom-sim: warning: {result.suspect_note()}", file=sys.stderr)
    return 0


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
    t_last = float(partial.t[-1]) if len(partial.t) else 0.0
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
    res = _load_result(args.result)
    try:
        pvd = export_vtk(res, Path(args.vtk))
    except (ValueError, OSError) as exc:
        raise _InputError(f"cannot export: {_one_line(exc)}") from None
    print(f"wrote {pvd} ({len(res.t)} time steps; open it in ParaView)")
    return 0


def _report(result: Result, path: Path, animation: Path | None = None) -> Path | None:
    """The run's report (sim_core.report); a missing plotly only skips it (the result files
    are already written), a bad animation file or a failed write is an input error."""
    try:
        import plotly  # noqa: F401

        from sim_core.report import write_report
    except ImportError:
        print("boom-sim: warning: plotly is not installed, report.html skipped", file=sys.stderr)
        return None
    try:
        return write_report(result, path, animation=animation)
    except (ValueError, OSError) as exc:
        raise _InputError(f"cannot write the report: {_one_line(exc)}") from None


def cmd_report(args) -> int:
    res = _load_result(args.result)
    out = Path(args.out) if args.out else Path(args.result).parent / "report.html"
    try:
        import plotly  # noqa: F401
    except ImportError:
        raise _InputError("plotly is not installed (pip install plotly)") from None
    path = _report(res, out, Path(args.animation) if args.animation else None)
    print(f"wrote {path}")
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
    res = _load_result(args.result)
    out = Path(args.out) if args.out else Path(args.result).parent
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise _InputError("matplotlib is not installed (pip install matplotlib)") from None
    figs = _figures(res, out)
    print(f"wrote {len(figs)} figures to {out}")
    return 0


def cmd_sweep(args) -> int:
    from sim_core.sweep import SweepError, parse_grid, run_sweep
    grid = parse_grid(args.grid)
    fixed = _overrides(args.set)
    both = sorted(set(grid) & set(fixed))
    if both:
        raise SceneError(f"--grid {both[0]} and --set {both[0]}: a key is either swept or fixed")
    t0 = time.perf_counter()
    try:
        every = args.checkpoint_every
        if not every >= 0:
            raise _InputError(f"--checkpoint-every {every:g}: wall seconds between a case's "
                              "checkpoints, allowed [0, inf) (0: none)")
        rows = run_sweep(args.scene, grid, args.out, fixed=fixed, address=args.address,
                         workers=args.workers, quiet=args.quiet, plots=args.plots,
                         retries=args.retries, checkpoint_every=every or float("inf"))
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
                   help="continue from OUT/checkpoint.pkl (exit 2 if there is none, or if it "
                        "was written for another scene); the result equals the uninterrupted "
                        "run's")
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
                    help="a GIF or MP4 (boom-sim animate) to embed in the page")
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
