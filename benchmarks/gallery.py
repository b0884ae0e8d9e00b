"""The documentation's gallery: every shipped scene run as shipped, its animation and its report.

    python benchmarks/gallery.py                         # the default set: the fast scenes
    python benchmarks/gallery.py --scenes crane_lift_and_slew folding_boom
    python benchmarks/gallery.py --all                   # every shipped scene

For each scene it runs ``simulate(load_scene(name))`` with the scene as shipped (no override:
the whole manoeuvre) and writes

* ``docs/gallery/<scene>.gif``: the run replayed by :func:`sim_core.animation.animate` (the
  scene's whole time in about ``PLAYBACK_S`` seconds at ``FPS`` frames per second, deflection
  exaggerated ``SCALE`` times, the 3-D view), scaled to ``WIDTH_PX`` pixels wide: small enough
  to commit.  Only results that record the replay geometry (the telescopic full model) have
  one; for the others the page says why;
* ``docs/gallery/<scene>/report.html``: :func:`sim_core.report.write_report` with the
  animation embedded and plotly.js loaded from ``docs/gallery/plotly.min.js``, one copy for
  all reports; every output but the replay geometry and the integrator state (``LEFT_OUT``);
* ``docs/gallery/<scene>/meta.json``: the run's record (simulated time, wall time, method,
  animation or the reason for none, and the commit it was built from, which the page leaves
  out);

and then rewrites ``docs/gallery.md`` from the shipped scenes and every ``meta.json`` present,
so a run of some scenes keeps the others' entries and a scene never built says which command
builds it.  Files are written atomically.  The default set (``DEFAULT_SCENES``) takes a few
minutes on one core; ``--all`` adds the long runs (~10 min).
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import html
import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks._machine import commit  # noqa: E402
from sim_core import load_scene, simulate  # noqa: E402
from sim_core.result import atomic_write_bytes  # noqa: E402
from sim_core.scene.io import shipped_scenes  # noqa: E402

GALLERY = ROOT / "docs" / "gallery"
PAGE = ROOT / "docs" / "gallery.md"
PLOTLYJS = "plotly.min.js"
#: fast scenes: the default run of this script stays at a few minutes
DEFAULT_SCENES = ("telescopic_extraction", "telescopic_extraction_rl", "beam_through_sleeve",
                  "cantilever_release")
PLAYBACK_S = 10.0          # s of playback for the whole run
FPS = 5                    # frames per second of the GIF
SCALE = 20.0               # deflection exaggeration
WIDTH_PX = 480             # width of the committed GIF
#: outputs the gallery's reports leave out: the replay geometry (the animation shows it) and
#: the integrator state (megabytes of heat maps in every report otherwise)
LEFT_OUT = ("geometry_", "state")


def _write_json(path: Path, obj) -> None:
    atomic_write_bytes(path, (json.dumps(obj, indent=2) + "\n").encode("utf-8"))


def _shrink_gif(src: Path, dst: Path, width: int) -> None:
    """``src`` scaled to ``width`` pixels wide (height in proportion), every frame and its
    duration kept, written atomically to ``dst``."""
    from PIL import Image, ImageSequence

    with Image.open(src) as im:
        w, h = im.size
        size = (width, max(1, round(h * width / w)))
        frames, durations = [], []
        for frame in ImageSequence.Iterator(im):
            durations.append(frame.info.get("duration", im.info.get("duration", 100)))
            frames.append(frame.convert("RGB").resize(size, Image.LANCZOS)
                          .quantize(colors=128, method=Image.Quantize.MEDIANCUT))
    with tempfile.NamedTemporaryFile(suffix=".gif", dir=dst.parent, delete=False) as tmp:
        name = tmp.name
    try:
        frames[0].save(name, save_all=True, append_images=frames[1:], duration=durations,
                       loop=0, optimize=True, disposal=1)
        os.chmod(name, 0o644)
        os.replace(name, dst)
    finally:
        if os.path.exists(name):
            os.unlink(name)


def _plotlyjs(folder: Path) -> None:
    """plotly.js once for all reports (replaced atomically where it differs)."""
    from plotly.offline import get_plotlyjs
    js = get_plotlyjs().encode("utf-8")
    target = folder / PLOTLYJS
    if not target.is_file() or target.read_bytes() != js:
        atomic_write_bytes(target, js)


def build(name: str) -> dict:
    """Run one scene as shipped; write its GIF, report and meta.json; return the meta."""
    from sim_core.animation import animate
    from sim_core.report import write_report

    scene = load_scene(name)
    t_end = float(scene["solver"]["t_end"])
    folder = GALLERY / name
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    result = simulate(scene)
    wall = time.perf_counter() - t0
    gif = GALLERY / f"{name}.gif"
    meta = {"scene": name, "description": scene.get("description", ""), "t_end_s": t_end,
            "wall_s": round(wall, 1), "method": str(result.stats.get("method", "")),
            "n_dof": result.stats.get("n_dof"), "error": result.error,
            "built": f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d}",
            "commit": commit()}
    with tempfile.TemporaryDirectory(prefix="gallery_") as tmp:
        full = Path(tmp) / "full.gif"
        try:
            animate(result, full, scale=SCALE, speed=max(t_end / PLAYBACK_S, 0.05), fps=FPS)
        except ValueError as exc:                  # no replay geometry in this result
            meta["animation"] = None
            meta["no_animation"] = " ".join(str(exc).split())
            if gif.exists():
                gif.unlink()
        else:
            _shrink_gif(full, gif, WIDTH_PX)
            meta["animation"] = gif.name
            meta["animation_note"] = (f"the whole {t_end:g} s in {PLAYBACK_S:g} s, {FPS} frames "
                                      f"per second, deflection x{SCALE:g}")
    _plotlyjs(GALLERY)
    shown = {k: v for k, v in result.outputs.items() if not k.startswith(LEFT_OUT)}
    write_report(dataclasses.replace(result, outputs=shown), folder / "report.html",
                 animation=gif if meta["animation"] else None,
                 include_plotlyjs=f"../{PLOTLYJS}")
    meta["report"] = f"{name}/report.html"
    _write_json(folder / "meta.json", meta)
    return meta


def page() -> str:
    """docs/gallery.md from the shipped scenes and the meta.json files present."""
    lines = ["# Gallery", "",
             "Every shipped scene run as shipped (the whole manoeuvre, no shortened time): its "
             "animation and its report, an HTML page with the scene, the run's statistics and "
             "self-checks and an interactive plot of every output (here without the replay "
             "geometry, which the animation shows, and the integrator state).  The reports "
             "open from this site and need no network.", "",
             "The files are rebuilt by `python benchmarks/gallery.py` (the fast scenes; "
             "`--all` for every scene, `--scenes NAME ...` for some) and committed under "
             "`docs/gallery/`.  The animations exaggerate the booms' deflection; run "
             "`boom-sim run SCENE --animate` or `boom-sim animate` for your own "
             "([user guide](user_guide.md#seeing-the-crane-move)); how long each scene takes "
             "is on the [performance](performance.md) page (a report's wall time is its own "
             "run's, with the figures and the animation, on a machine that was doing other "
             "work: not a speed measurement).", ""]
    for name in sorted(shipped_scenes()):
        meta_path = GALLERY / name / "meta.json"
        lines += [f"## `{name}`", ""]
        if not meta_path.is_file():
            desc = load_scene(name).get("description", "")
            lines += [desc, "", f"Not built yet: `python benchmarks/gallery.py --scenes {name}`.",
                      ""]
            continue
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
        lines += [meta["description"], ""]
        run = f"{meta['t_end_s']:g} s simulated ({meta['method']}, {meta['n_dof']} coordinates)"
        if meta.get("error"):
            run += f"; the run stopped early: {meta['error']}"
        lines += [f"[Report](gallery/{meta['report']}) · {run}.", ""]
        if meta.get("animation"):
            lines += [f"![{name}](gallery/{meta['animation']})", "",
                      f"*{html.escape(meta['animation_note'])}.*", ""]
        else:
            lines += [f"No animation: {meta['no_animation']}", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=None,
                    help=f"shipped scenes to build (default: {' '.join(DEFAULT_SCENES)})")
    ap.add_argument("--all", action="store_true", help="every shipped scene")
    ap.add_argument("--page-only", action="store_true",
                    help="only rewrite docs/gallery.md from the files present")
    args = ap.parse_args(argv)
    names = sorted(shipped_scenes())
    scenes = [] if args.page_only else (names if args.all else args.scenes or DEFAULT_SCENES)
    unknown = [s for s in scenes if s not in names]
    if unknown:
        ap.error(f"unknown scene(s) {', '.join(unknown)}; shipped: {', '.join(names)}")
    GALLERY.mkdir(parents=True, exist_ok=True)
    for name in scenes:
        t0 = time.perf_counter()
        meta = build(name)
        print(f"{name}: run {meta['wall_s']:g} s, "
              f"{'animation' if meta['animation'] else 'no animation'}, report; "
              f"{time.perf_counter() - t0:.0f} s in all", flush=True)
    atomic_write_bytes(PAGE, page().encode("utf-8"))
    print(f"wrote {PAGE.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
