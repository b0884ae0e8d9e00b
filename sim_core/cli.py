"""Command line: ``boom-sim run|list|describe|plot``.

Errors in the scene exit with status 2 and a one-line message; a failed solve exits with
status 3 and a one-line message (time and reason).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from .errors import SceneError, SimulationError
from .result import Result, atomic_write_bytes
from .scene import load_scene, shipped_scenes


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
                    "{l_bar}{bar}| {n:.3f}/{total:.3f} s sim [{elapsed} wall, {postfix}]"),
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

    def close(self):
        if self.bar is not None:
            self.bar.n = self.t_end
            self.bar.close()


def cmd_run(args) -> int:
    from .plots import plot_result
    from .simulate import simulate
    scene = load_scene(args.scene, _overrides(args.set))
    out = Path(args.out)
    prog = _Progress(scene["solver"]["t_end"], not args.quiet)
    try:
        result = simulate(scene, progress=prog)
    finally:
        prog.close()
    result.save(out / "result.npz")
    summary = {"scene": scene["name"], **result.stats}
    atomic_write_bytes(out / "summary.json", json.dumps(summary, indent=2).encode())
    figs = [] if args.no_plots else plot_result(result, out)
    print(f"{scene['name']}: {scene['solver']['t_end']:g} s simulated in "
          f"{result.stats['wall_time_s']:.1f} s wall (RTF {result.stats['real_time_factor']:.3g}); "
          f"{result.stats['n_steps']} steps, {result.stats['n_rhs']} RHS; wrote {out}/result.npz, "
          f"summary.json" + (f", {len(figs)} figures" if figs else ""))
    return 0


def cmd_list(args) -> int:
    for name, path in sorted(shipped_scenes().items()):
        sc = load_scene(path)
        print(f"{name:32s} {sc['description']}")
    return 0


def cmd_describe(args) -> int:
    from .assemble import build_model
    scene = load_scene(args.scene, _overrides(args.set))
    model, _, _ = build_model(scene)
    print(f"scene {scene['name']}: {scene['description']}")
    print("effects: " + ", ".join(f"{k}={'on' if v else 'off'}" for k, v in scene["effects"].items()))
    print("assembled contributions: " + ", ".join(e.name for e in model.effects)
          + (f", {len(model.point_loads)} point load(s)" if model.point_loads else ""))
    print(f"coordinates: {model.n_coords}, constraints: {model.A.shape[0]}, DOF: {model.n_dof}")
    print(json.dumps({k: v for k, v in scene.items() if k != "source"}, indent=2))
    return 0


def cmd_plot(args) -> int:
    from .plots import plot_result
    res = Result.load(args.result)
    out = Path(args.out) if args.out else Path(args.result).parent
    figs = plot_result(res, out)
    print(f"wrote {len(figs)} figures to {out}")
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="boom-sim", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="simulate a scene, write result.npz, summary.json, figures")
    r.add_argument("scene", help="shipped scene name or path to a TOML scene")
    r.add_argument("--out", default="results", help="output folder (default: results)")
    r.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene value")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.add_argument("--no-plots", action="store_true")
    r.set_defaults(func=cmd_run)
    sub.add_parser("list", help="shipped scenes").set_defaults(func=cmd_list)
    d = sub.add_parser("describe", help="resolved scene, effects and DOF count")
    d.add_argument("scene")
    d.add_argument("--set", action="append", metavar="KEY=VALUE")
    d.set_defaults(func=cmd_describe)
    pl = sub.add_parser("plot", help="figures from a result file")
    pl.add_argument("result")
    pl.add_argument("--out", default=None)
    pl.set_defaults(func=cmd_plot)
    args = p.parse_args(argv)
    try:
        return args.func(args)
    except SceneError as exc:
        print(f"boom-sim: scene error: {exc}", file=sys.stderr)
        return 2
    except SimulationError as exc:
        print(f"boom-sim: {exc}", file=sys.stderr)
        return 3


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
