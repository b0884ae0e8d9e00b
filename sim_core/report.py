"""A run's report: one HTML file with the scene, the summary, the run's self-checks, an
interactive plot of every output, the animation and, for the paper scenes, the rows of the
comparison with Section 9 of Zhao-Qi-Wang 2024.

    from sim_core.report import write_report
    write_report(result, "out/report.html", animation="out/anim.gif")

The plots are plotly figures (plotly.js).  By default plotly.js is written into the file, which
then opens offline in any browser with nothing beside it; ``include_plotlyjs="directory"``
writes ``plotly.min.js`` beside the report instead (one copy for a folder of reports).  The
animation is embedded in the file as well (GIF as an image, MP4 as a video, base64).

Each time series of a physical quantity gets one plot (a ``<div class="report-plot"
id="plot-NAME">``), its components named by :data:`COMPONENT_LABELS` (the one table of what
every component of every output is: "X", "overlap 1-2 outer pad f_t", "stage 1-2 cylinder",
"extraction rope, boom 3"):

* a time series with a few components (a scalar, a vector, one value per boom pair or region):
  one line per component on one axis;
* one with a few groups of a few components (``contact_point_forces``: a pair's inner or
  outer contact point, six force and moment components): one axis per group, one line per
  component, the time axis shared;
* a larger one (the slider springs): a heat map of time against component, one per group
  where the groups are few.

The integrator state ``state``, the replay geometry ``geometry_*`` (the animation and the
ParaView export draw it) and the static station and stress-point tables are not plotted; the
per-station arrays ``section_forces``, ``section_stress`` and ``section_utilisation`` are shown
as their envelopes along each boom (section "Section forces").  A table at the end of the
outputs lists each of these with the reason.

A line keeps at most :data:`MAX_POINTS` points, and all lines of the page together at most
:data:`PAGE_POINTS` (each line at least :data:`MIN_POINTS`): beyond its share a line shows the
smallest and the largest value of each of share / 2 equal runs of output times (the envelope
keeps every peak); a heat map keeps at most :data:`MAX_CELLS` cells (every k-th output time).
The page is then a little over 1 MB at most without plotly.js and the animation; the result
file keeps every value.
"""

from __future__ import annotations

import base64
import html
import itertools
import json
import math
import re
import warnings
from pathlib import Path

import numpy as np

from sim_core._version import __version__
from sim_core.result import Result, atomic_write_bytes, json_default

#: The class of every plot's container (one per output); its id is ``plot-`` + the output name.
PLOT_CLASS = "report-plot"
#: Class of the section-force figures' containers (envelopes and history, not one per output).
STRENGTH_CLASS = "report-strength"
#: Points of one line in the page (an envelope of min and max beyond that) ...
MAX_POINTS = 4000
#: ... and of all lines of the page together (each line at least MIN_POINTS): the page's size
#: stays bounded whatever the number of output times (about 21 bytes a point: x and y as
#: base64 float64).
PAGE_POINTS = 60_000
MIN_POINTS = 200
#: Cells of one output's heat maps in the page (every k-th output time beyond that; 5.3 bytes
#: a cell: base64 float32).
MAX_CELLS = 50_000
#: Components on one axis (more: a heat map) and groups stacked as separate axes.
MAX_LINES = 12
MAX_GROUPS = 8
PLOTLYJS_FILE = "plotly.min.js"
# outputs without a time axis (whatever their first dimension)
_STATIC = {"geometry_section_outlines", "section_stations", "section_stress_points"}
# per-station arrays shown through the section envelopes (_strength_section)
_ENVELOPED = {"section_forces", "section_stress", "section_utilisation"}
# closed contours (NaN-padded to a common length): drawn without the padding, closed
_CLOSED = {"geometry_section_outlines", "section_stress_points"}

_XYZ = ("X", "Y", "Z")
# unit of each output (docs/user_guide.md#outputs)
_UNITS = {
    "tip_position": "m", "tip_velocity": "m/s", "tip_acceleration": "m/s²",
    "tip_deflection": "m", "payload_position": "m", "piston_stroke": "m", "stage_stroke": "m",
    "luffing_cylinder_force": "N", "telescopic_cylinder_force": "N", "drive_forces": "N",
    "hoist_rope_force": "N",
    "payload_ground_force": "N",
    "rope_tension": "N", "rope_tensions": "N", "cylinder_forces": "N", "cylinder_lengths": "m",
    "contact_point_forces": "N, N m", "inner_contact_s": "m", "outer_contact_s": "m",
    "constraint_violation": "m, rad", "slider_contact_forces": "N", "friction_coefficient": "–",
    "pad_forces": "N", "pad_couples": "N m", "pad_face_forces": "N",
    "luffing_angle": "rad", "slew_angle": "rad", "boom_angles": "rad", "sway_angle": "rad",
    "energy_kinetic": "J", "energy_strain": "J", "energy_gravity": "J",
    "angular_momentum": "kg m²/s", "element_ends": "m", "reactions": "N, N m",
    "modal_coordinates": "–", "geometry_centre_lines": "m", "geometry_section_frames": "–",
    "geometry_luffing_cylinder": "m", "geometry_contacts": "m", "geometry_section_outlines": "m",
    "section_stations": "m", "section_forces": "N, N m", "section_stress": "Pa",
    "section_stress_points": "m", "section_utilisation": "–",
}
_PADS = ("outer pad", "inner pad")        # sim_core.systems.telescopic.sliders.PAD_NAMES
#: What each component of an output is, the one table of the report's labels: one entry per
#: axis after the time axis, either the names of that axis' entries or the name of a rule of
#: :data:`_AXIS_RULES` that names them from the axis' length and the scene.  The order is the
#: order in which the system kinds write the output (sim_core/systems/*/build.py).
COMPONENT_LABELS = {
    "tip_position": (_XYZ,), "tip_velocity": (_XYZ,), "tip_acceleration": (_XYZ,),
    "tip_deflection": (_XYZ,), "payload_position": (_XYZ,), "angular_momentum": (_XYZ,),
    "contact_point_forces": ("overlap", ("inner contact", "outer contact"),
                             ("f_s", "f_t", "f_b", "m_s", "m_t", "m_b")),
    "inner_contact_s": ("overlap",), "outer_contact_s": ("overlap",),
    "stage_stroke": ("stage",), "drive_forces": ("drive",), "rope_tensions": ("rope",),
    "rope_tension": (("extraction rope", "retraction rope"),),
    "slider_contact_forces": ("region", "spring"), "friction_coefficient": ("region",),
    "pad_forces": ("overlap", _PADS, ("f_t", "f_b")),
    "pad_couples": ("overlap", _PADS, ("m_t", "m_b")),
    "pad_face_forces": ("overlap", _PADS, "patch"),
    "sway_angle": (("in the luffing plane", "across it"),),
    "boom_angles": (("boom-1 elevation", "boom-2 relative"),),
    "cylinder_forces": (("cylinder 1", "cylinder 2"),),
    "cylinder_lengths": (("cylinder 1", "cylinder 2"),),
    "modal_coordinates": ("mode",), "element_ends": ("breakpoint",),
    "reactions": ("constraint row",),
    "geometry_section_outlines": ("boom", "point", ("e_t", "e_b")),
    "section_stress_points": ("boom", "point", ("e_t", "e_b")),
    "section_forces": ("boom", "station", ("N", "Q_t", "Q_b", "T", "M_t", "M_b")),
    "section_stress": ("boom", "station", "point", ("sigma", "tau")),
    "section_utilisation": ("boom", "station"),
}
_WHAT = {
    "tip_position": "tip position, global axes",
    "tip_velocity": "tip velocity, global axes",
    "tip_acceleration": "tip acceleration, global axes",
    "piston_stroke": "stroke of the active stage, L_s - L_s(0)",
    "luffing_cylinder_force": "luffing-cylinder force, positive pushing",
    "telescopic_cylinder_force": "telescopic-cylinder force, positive pushing",
    "contact_point_forces": "force and moment at every contact point, section frame "
                            "(e_s, e_t, e_b)",
    "inner_contact_s": "material coordinate of each pair's inner contact point",
    "outer_contact_s": "material coordinate of each pair's outer contact point",
    "constraint_violation": "largest residual of the constraints",
    "slider_contact_forces": "normal force of every slider spring, per contact region",
    "pad_forces": "force of each overlap's outer and inner pad on the inner boom, contact-section "
                  "frame (e_t, e_b)",
    "pad_couples": "couple each pad carries across its length, about (e_t, e_b)",
    "pad_face_forces": "normal force of each pad's springs summed per bearing patch (face)",
    "friction_coefficient": "friction coefficient per contact region",
    "state": "integrator state (mixed units)",
    "geometry_centre_lines": "replay geometry: each boom's centre line (X, Y, Z of its points)",
    "geometry_section_frames": "replay geometry: section frames along each boom",
    "geometry_luffing_cylinder": "replay geometry: luffing cylinder base D2 and head D3",
    "geometry_contacts": "replay geometry: each overlap's inner and outer contact points",
    "geometry_section_outlines": "each boom's outer contour in section coordinates",
    "section_stations": "material coordinates of the section-force stations of each boom",
    "section_forces": "(N, Q_t, Q_b, T, M_t, M_b) at every station, section frame",
    "section_stress": "normal stress and shear-stress magnitude at the outline points of "
                      "every station",
    "section_stress_points": "each boom's stress points on its outline, section coordinates",
    "section_utilisation": "largest von Mises stress of every station over material.f_y",
}
_STAT_KEYS = (("wall_time_s", "wall time", "s"), ("real_time_factor", "real-time factor", ""),
              ("method", "method", ""), ("n_dof", "degrees of freedom", ""),
              ("n_steps", "steps", ""), ("n_rejected", "rejected steps", ""),
              ("n_rhs", "RHS evaluations", ""), ("n_failed_rhs", "failed RHS evaluations", ""),
              ("min_step_s", "smallest step", "s"), ("max_step_s", "largest step", "s"),
              ("n_method_switches", "method switches", ""), ("rtol", "rtol", ""),
              ("atol", "atol", ""))
_PLOTLYJS_OPTIONS = "True, False, 'cdn', 'directory' or a path/URL ending in '.js'"


def write_report(result, path, *, animation=None, scene_name=None, include_plotlyjs=True) -> Path:
    """Write the report of ``result`` (a :class:`sim_core.result.Result`) to ``path`` (HTML,
    atomically) and return the path.

    ``animation``: a GIF or MP4 file (:func:`sim_core.animation.animate`) embedded in the page.
    ``scene_name``: the title (default: the scene's name).  ``include_plotlyjs`` as plotly's
    ``write_html``: True embeds plotly.js (the file works offline by itself), "directory"
    writes ``plotly.min.js`` beside the report and loads it from there, "cdn" loads it from
    plotly's CDN, a string ending in ".js" loads that, False leaves it to the page's host.

    Raises TypeError for a result that is not a Result, ValueError for an animation that is
    not a GIF or MP4 or an unknown ``include_plotlyjs``, OSError for an unreadable animation.
    """
    if not isinstance(result, Result):
        raise TypeError(f"result: expected a sim_core.result.Result, got {type(result).__name__}")
    if not (isinstance(include_plotlyjs, bool) or include_plotlyjs in ("cdn", "directory")
            or (isinstance(include_plotlyjs, str) and include_plotlyjs.endswith(".js"))):
        raise ValueError(f"include_plotlyjs: {include_plotlyjs!r} is not one of "
                         f"{_PLOTLYJS_OPTIONS}")
    path = Path(path)
    media = _animation_html(Path(animation)) if animation is not None else ""
    title = str(scene_name if scene_name is not None else result.scene.get("name") or "result")
    page = _page(result, title, media, _plotlyjs_head(include_plotlyjs))
    if include_plotlyjs == "directory":
        _write_plotlyjs_beside(path)
    atomic_write_bytes(path, page.encode("utf-8"))
    return path


# ----------------------------------------------------------------------------- page

_CSS = """
:root { --fg: #1f2933; --muted: #616e7c; --line: #e4e7eb; --accent: #3f51b5;
        --ok: #1b7f3b; --warn: #b26a00; --bad: #b42318; --bg: #f7f8fa; }
* { box-sizing: border-box; }
body { margin: 0; font: 15px/1.5 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif;
       color: var(--fg); background: var(--bg); }
header { background: var(--accent); color: #fff; padding: 1.2rem 2rem 1rem; }
header h1 { margin: 0; font-size: 1.6rem; font-weight: 600; }
header p { margin: .25rem 0 0; opacity: .92; }
nav { position: sticky; top: 0; z-index: 10; background: #fff; border-bottom: 1px solid var(--line);
      padding: .5rem 2rem; display: flex; gap: 1.2rem; flex-wrap: wrap; }
nav a { color: var(--accent); text-decoration: none; font-weight: 500; }
nav a:hover { text-decoration: underline; }
main { max-width: 1200px; margin: 0 auto; padding: 1rem 2rem 3rem; }
section { background: #fff; border: 1px solid var(--line); border-radius: 6px;
          padding: .8rem 1.4rem 1.2rem; margin: 1.2rem 0; }
h2 { font-size: 1.25rem; margin: .4rem 0 .8rem; }
h3 { font-size: 1.02rem; margin: 1.4rem 0 .2rem; font-family: ui-monospace, monospace; }
p.caption { margin: 0 0 .3rem; color: var(--muted); font-size: .9rem; }
table { border-collapse: collapse; width: 100%; font-size: .92rem; }
th, td { text-align: left; padding: .3rem .6rem; border-bottom: 1px solid var(--line);
         vertical-align: top; }
th { background: #f1f3f6; font-weight: 600; }
td.num { font-variant-numeric: tabular-nums; white-space: nowrap; }
table.kv { width: auto; min-width: 50%; }
.badge { display: inline-block; white-space: nowrap; padding: .05rem .55rem;
         border-radius: 999px; font-size: .85rem; font-weight: 600; color: #fff; }
.ok { background: var(--ok); } .warn { background: var(--warn); } .bad { background: var(--bad); }
.neutral { background: var(--muted); }
.note { border-left: 4px solid var(--warn); background: #fff8e6; padding: .5rem .8rem; }
.error { border-left: 4px solid var(--bad); background: #fdecea; padding: .5rem .8rem; }
pre { background: #f4f5f7; padding: .8rem; overflow: auto; max-height: 40rem; font-size: .85rem; }
details summary { cursor: pointer; font-weight: 500; margin: .3rem 0; }
ul.index { columns: 3 14rem; padding-left: 1.2rem; font-family: ui-monospace, monospace;
           font-size: .9rem; }
figure { margin: 0; } figure img, figure video { max-width: 100%; border: 1px solid var(--line); }
.report-plot { width: 100%; }
td code { white-space: nowrap; }
footer { color: var(--muted); font-size: .85rem; text-align: center; padding: 1rem; }
"""


def _page(res: Result, title: str, media: str, plotlyjs_head: str) -> str:
    esc = html.escape
    n = len(res.t)
    span = f"t = {float(res.t[0]):g} to {float(res.t[-1]):g} s, {n} output times" if n else \
        "no output times"
    kind = res.scene.get("kind", "")
    status = _status_badge(res)
    sections = [_summary_section(res), _checks_section(res)]
    paper = _paper_section(res)
    if paper:
        sections.append(paper)
    if media:
        sections.append(f'<section id="animation"><h2>Animation</h2>{media}</section>')
    max_points = _points_per_line(res)
    strength = _strength_section(res, max_points)
    if strength:
        sections.append(strength)
    plots, n_plots = _plots_section(res, enveloped=bool(strength), max_points=max_points)
    sections.append(plots)
    sections.append(_scene_section(res))
    links = [("summary", "Summary"), ("checks", "Checks")]
    if paper:
        links.append(("paper", "Paper comparison"))
    if media:
        links.append(("animation", "Animation"))
    if strength:
        links.append(("strength", "Section forces"))
    links += [("plots", f"Plots ({n_plots})"), ("scene", "Scene")]
    nav = "".join(f'<a href="#{a}">{esc(label)}</a>' for a, label in links)
    description = res.scene.get("description", "")
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
        "<link rel=\"icon\" href=\"data:,\">\n"
        f"<meta name=\"generator\" content=\"sim_core {esc(__version__)}\">\n"
        f"<title>{esc(title)} - boom-sim report</title>\n<style>{_CSS}</style>\n"
        f"{plotlyjs_head}</head>\n<body>\n"
        f"<header><h1>{esc(title)}</h1>"
        + (f"<p>{esc(str(description))}</p>" if description else "")
        + f"<p>{esc(str(kind))}{' · ' if kind else ''}{esc(span)} · {status} · "
        f"sim_core {esc(__version__)}</p></header>\n<nav>{nav}</nav>\n<main>\n"
        + "\n".join(sections)
        + f"\n</main>\n<footer>Written by sim_core {esc(__version__)} (telescopic-boom-sim); "
        "plots: plotly.js.</footer>\n</body>\n</html>\n")


def _status_badge(res: Result) -> str:
    if res.error:
        return '<span class="badge bad">stopped early</span>'
    if res.suspect:
        return '<span class="badge warn">suspect</span>'
    return '<span class="badge ok">complete</span>'


def _fmt(v) -> str:
    """A statistic as text: numbers to 4 significant digits, containers as compact JSON."""
    if isinstance(v, bool) or v is None:
        return str(v)
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        return f"{v:.4g}" if math.isfinite(v) else str(v)
    if isinstance(v, (dict, list, tuple)):
        return json.dumps(v, default=json_default)
    return str(v)


def _summary_section(res: Result) -> str:
    esc = html.escape
    st = res.stats
    out = ['<section id="summary"><h2>Summary</h2>']
    if res.error:
        t_last = f"{float(res.t[-1]):g} s" if len(res.t) else "no output"
        out.append(f'<p class="error"><b>The run stopped early</b> (outputs up to {t_last}): '
                   f"{esc(res.error)}</p>")
    rows = [("status", _status_badge(res))]
    if len(res.t):
        rows.append(("simulated", esc(f"{float(res.t[0]):g} to {float(res.t[-1]):g} s, "
                                      f"{len(res.t)} output times")))
    rows.append(("outputs", str(len(res.outputs))))
    for key, label, unit in _STAT_KEYS:
        if key in st:
            rows.append((label, esc(_fmt(st[key]) + (f" {unit}" if unit else ""))))
    if "wall_s" in st and "cpu_s" in st:
        # the whole simulate call and the load it ran under (sim_core.api._timed): a wall time
        # reads only beside its CPU time and the machine's load
        rows.append(("whole run: wall, CPU", esc(f"{st['wall_s']:.3g} s, {st['cpu_s']:.3g} s")))
        loads = [st.get("load_start"), st.get("load_end")]
        if all(isinstance(x, (list, tuple)) and x for x in loads):
            rows.append(("load average (1 min): start, end", esc(
                f"{loads[0][0]:g}, {loads[1][0]:g} on {st.get('usable_cpus', '?')} usable CPUs")))
    out.append('<table class="kv">' + "".join(f"<tr><th>{esc(k)}</th><td class=\"num\">{v}</td>"
                                              "</tr>" for k, v in rows) + "</table>")
    rest = {k: v for k, v in st.items() if k not in ("checks", "suspect", "failed_checks")}
    if rest:
        out.append("<details><summary>All solver statistics (summary.json)</summary>"
                   '<table class="kv">' + "".join(
                       f"<tr><th>{esc(str(k))}</th><td class=\"num\">{esc(_fmt(v))}</td></tr>"
                       for k, v in rest.items()) + "</table></details>")
    out.append("</section>")
    return "\n".join(out)


def _checks_section(res: Result) -> str:
    esc = html.escape
    checks = res.stats.get("checks") or {}
    out = ['<section id="checks"><h2>Self-checks</h2>',
           '<p class="caption">Cheap checks of the finished run against its own result '
           "(sim_core.integrate.checks): a value above its suspect limit marks the result "
           "suspect, one above its fail limit stops the run.</p>"]
    if not isinstance(checks, dict) or not checks:
        out.append("<p>The result records no self-checks.</p></section>")
        return "\n".join(out)
    if res.suspect:
        out.append(f'<p class="note">{esc(res.suspect_note())}</p>')
    out.append("<table><tr><th>check</th><th>value</th><th>suspect above</th>"
               "<th>fails above</th><th>verdict</th><th>what</th></tr>")
    for name, c in checks.items():
        if not isinstance(c, dict):
            out.append(f"<tr><td>{esc(str(name))}</td><td colspan=\"5\">{esc(_fmt(c))}</td></tr>")
            continue
        if c.get("gross"):
            badge = '<span class="badge bad">fails</span>'
        elif not c.get("ok", True):
            badge = '<span class="badge warn">suspect</span>'
        else:
            badge = '<span class="badge ok">ok</span>'
        out.append(f"<tr><td>{esc(str(name))}</td>"
                   + "".join(f'<td class="num">{esc(_fmt(c.get(k)))}</td>'
                             for k in ("value", "limit", "fail_limit"))
                   + f"<td>{badge}</td><td>{esc(str(c.get('what', '')))}</td></tr>")
    out.append("</table></section>")
    return "\n".join(out)


def _paper_section(res: Result) -> str:
    """The rows of the comparison with Section 9 for a paper scene ("" for any other scene)."""
    from sim_core.validation import paper_rows as pr
    esc = html.escape
    name = res.scene.get("name")
    if name not in pr.ROWS:
        return ""
    out = ['<section id="paper"><h2>Comparison with the paper</h2>',
           f"<p class=\"caption\">{esc(pr.TITLES[name])}: the statements of Section 9 of "
           "Zhao-Qi-Wang 2024 (Mathematics 12, 2496) on its figures, computed from this run as "
           "benchmarks/paper_comparison.py computes them for docs/validation.md "
           "(sim_core.validation.paper_rows).</p>"]
    contact = res.scene.get("contact") or {}
    models = [f"{k} = {contact[k]}" for k in ("moment_model", "friction_load") if k in contact]
    if models:
        out.append(f"<p>Contact models of this run: {esc(', '.join(models))}.</p>")
    why = pr.not_applicable(res)
    rows = None
    if not why:
        try:
            with warnings.catch_warnings(), np.errstate(all="ignore"):
                warnings.simplefilter("ignore", RuntimeWarning)
                rows = pr.ROWS[name](res)
        except Exception as exc:  # noqa: BLE001 - the report still shows everything else
            why = f"the rows could not be computed ({type(exc).__name__}: {exc})"
    if why:
        out.append(f'<p class="note">No comparison rows: {esc(why)}.</p></section>')
        return "\n".join(out)
    held = sum(1 for r in rows if r.holds)
    judged = sum(1 for r in rows if r.holds is not None)
    out.append(f"<p><b>{held} of {judged}</b> statements hold.</p>")
    out.append('<table class="paper-rows"><tr><th>Fig.</th><th>statement</th><th>this run</th>'
               "<th></th></tr>")
    for r in rows:
        badge = ('<span class="badge neutral">reported</span>' if r.holds is None else
                 '<span class="badge ok">holds</span>' if r.holds else
                 '<span class="badge bad">does not hold</span>')
        out.append(f"<tr><td>{esc(r.figure)}</td><td>{_md_links(r.statement)}</td>"
                   f"<td>{esc(r.value)}</td><td>{badge}</td></tr>")
    out.append("</table></section>")
    return "\n".join(out)


def _md_links(text: str) -> str:
    """A row's statement as HTML: its markdown links to the docs pages shown as their text."""
    return html.escape(re.sub(r"\[([^\]]+)\]\([^)]+\)", r"\1", text))


def _scene_section(res: Result) -> str:
    scene = {k: v for k, v in res.scene.items() if k != "source"}
    text = json.dumps(scene, indent=2, default=json_default)
    return ('<section id="scene"><h2>Scene</h2><p class="caption">The resolved scene the run '
            "used (defaults filled in, overrides applied), as stored in the result.</p>"
            f"<details><summary>Resolved scene (JSON)</summary><pre>{html.escape(text)}</pre>"
            "</details></section>")


def _animation_html(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"animation: {str(path)!r} is not a .gif or .mp4 file")
    data = path.read_bytes()                            # OSError: missing, unreadable
    if suffix == ".gif" and not data.startswith((b"GIF87a", b"GIF89a")):
        raise ValueError(f"animation: {str(path)!r} is not a GIF image")
    if suffix == ".mp4" and data[4:8] != b"ftyp":
        raise ValueError(f"animation: {str(path)!r} is not an MP4 video")
    b64 = base64.b64encode(data).decode("ascii")
    if suffix == ".gif":
        body = f'<img src="data:image/gif;base64,{b64}" alt="animation of the run">'
    else:
        body = (f'<video controls loop muted playsinline src="data:video/mp4;base64,{b64}">'
                "</video>")
    return (f'<figure>{body}<figcaption class="caption">{html.escape(path.name)}'
            "</figcaption></figure>")


# ----------------------------------------------------------------------------- plotly.js

def _plotlyjs_head(include) -> str:
    if include is False:
        return ""
    if include is True:
        from plotly.offline import get_plotlyjs
        js = get_plotlyjs().replace("</script", "<\\/script")
        return f"<script>{js}</script>\n"
    if include == "cdn":
        from plotly.offline import get_plotlyjs_version
        src = f"https://cdn.plot.ly/plotly-{get_plotlyjs_version()}.min.js"
    elif include == "directory":
        src = PLOTLYJS_FILE
    else:
        src = include
    return f'<script charset="utf-8" src="{html.escape(src)}"></script>\n'


def _write_plotlyjs_beside(path: Path) -> None:
    """plotly.min.js beside the report (replaced atomically where it differs)."""
    from plotly.offline import get_plotlyjs
    js = get_plotlyjs().encode("utf-8")
    target = path.parent / PLOTLYJS_FILE
    try:
        if target.read_bytes() == js:
            return
    except OSError:
        pass
    atomic_write_bytes(target, js)


# ----------------------------------------------------------------------------- plots

def _strength_section(res: Result, max_points: int = MAX_POINTS) -> str:
    """Envelopes of the section forces and the utilisation along each boom (largest and
    smallest over the run) and their history at the most utilised station ("" for a result
    without section forces)."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots
    if not {"section_forces", "section_stations"} <= set(res.outputs):
        return ""
    F = np.asarray(res["section_forces"], dtype=float)
    st = np.asarray(res["section_stations"], dtype=float)
    if F.ndim != 4 or F.shape[0] == 0 or F.shape[1:3] != st.shape or F.shape[3] != 6:
        return ""
    n, N, S, _ = F.shape
    U = np.asarray(res["section_utilisation"], dtype=float) if "section_utilisation" in \
        res.outputs else np.full((n, N, S), np.nan)
    names = COMPONENT_LABELS["section_forces"][-1]
    units = ("N",) * 3 + ("N m",) * 3
    rows = [(names[c], units[c], F[..., c]) for c in range(6)] + [("utilisation", "–", U)]
    fig = make_subplots(rows=len(rows), cols=1, vertical_spacing=0.025,
                        subplot_titles=[f"{a} ({u})" for a, u, _ in rows])
    colours = _template().layout.colorway
    for r, (label, _, Y) in enumerate(rows):
        finite = np.isfinite(Y).any(axis=0)
        hi = np.where(finite, np.nanmax(np.where(np.isfinite(Y), Y, -np.inf), axis=0), np.nan)
        lo = np.where(finite, np.nanmin(np.where(np.isfinite(Y), Y, np.inf), axis=0), np.nan)
        for k in range(N):
            c = colours[k % len(colours)]
            fig.add_trace(go.Scatter(x=st[k], y=hi[k], mode="lines", name=f"boom {k + 1}",
                                     legendgroup=f"boom {k + 1}", showlegend=r == 0,
                                     line=dict(color=c)), row=r + 1, col=1)
            fig.add_trace(go.Scatter(x=st[k], y=lo[k], mode="lines", name=f"boom {k + 1} min",
                                     legendgroup=f"boom {k + 1}", showlegend=False,
                                     line=dict(color=c, dash="dot")), row=r + 1, col=1)
    fig.update_layout(template=_template(), height=120 + 230 * len(rows), hovermode="closest")
    fig.update_xaxes(title_text="s (m)", row=len(rows), col=1)
    if np.isfinite(U).any():
        k, j = np.unravel_index(np.nanargmax(np.where(np.isfinite(U), U, -np.inf).max(axis=0)),
                                (N, S))
        why = f"largest utilisation, {float(np.nanmax(U[:, k, j])):.3g}"
    else:
        k, j = np.unravel_index(np.argmax(np.abs(F[..., 3:]).max(axis=(0, 3))), (N, S))
        why = "largest moment (no stresses: a section without geometry)"
    t = np.asarray(res.t, dtype=float)
    hist = make_subplots(rows=3, cols=1, shared_xaxes=True, vertical_spacing=0.06,
                         subplot_titles=["forces (N)", "moments (N m)", "utilisation (–)"])
    for c in range(6):
        x, yy, _ = _envelope(t, F[:, k, j, c:c + 1], max_points)
        hist.add_trace(go.Scatter(x=x[:, 0], y=yy[:, 0], mode="lines", name=names[c]),
                       row=1 + c // 3, col=1)
    x, yy, _ = _envelope(t, U[:, k, j][:, None], max_points)
    hist.add_trace(go.Scatter(x=x[:, 0], y=yy[:, 0], mode="lines", name="utilisation"),
                   row=3, col=1)
    hist.update_layout(template=_template(), height=640)
    hist.update_xaxes(title_text="t (s)", row=3, col=1)
    esc = html.escape
    return ('<section id="strength"><h2>Section forces</h2><p class="caption">'
            + esc("Envelopes along each boom: the largest (solid) and smallest (dotted) value "
                  "over the run of every section force (section frame: N axial, Q_t and Q_b "
                  "shear, T torque, M_t and M_b bending) and of the utilisation (largest von "
                  "Mises stress of the section over material.f_y), against the material "
                  "coordinate s.") + "</p>"
            + _plot_div(fig, "strength-envelopes", "section_forces", STRENGTH_CLASS)
            + '<p class="caption">'
            + esc(f"History at the most utilised station: boom {k + 1}, s = {st[k, j]:g} m "
                  f"({why}).") + "</p>"
            + _plot_div(hist, "strength-history", "section_forces", STRENGTH_CLASS)
            + "</section>")


def _not_plotted(name: str, shape: tuple, n_t: int, enveloped: bool) -> str:
    """Why an output has no plot of its own ("" where it has one): the integrator state and the
    replay geometry are no time series of one physical quantity, the station and stress-point
    tables are static coordinates, and the per-station arrays are shown through the section
    envelopes (:func:`_strength_section`)."""
    if name == "state":
        return ("the integrator state (coordinates and rates of mixed units): what the energy "
                "check and a resume read, not one physical quantity")
    if name.startswith("geometry_"):
        return "replay geometry: drawn by the animation (boom-sim animate) and the ParaView export"
    if name in _STATIC:
        return "a time-independent table of coordinates: the axes of the section envelopes"
    if name in _ENVELOPED:
        return ("shown as its envelopes along each boom under Section forces" if enveloped else
                "one value per station and output time: too many for a plot of its own")
    return ""


def _plots_section(res: Result, enveloped: bool = False,
                   max_points: int = MAX_POINTS) -> tuple[str, int]:
    esc = html.escape
    used: set = set()
    ids = {name: _dom_id(name, used) for name in res.outputs}
    t = np.asarray(res.t, dtype=float)
    arrays = {name: np.asarray(res.outputs[name]) for name in res.outputs}
    skipped = {name: why for name, a in arrays.items()
               if (why := _not_plotted(name, a.shape, len(t), enveloped))}
    parts, n_plots = [], 0
    for name, pid in ids.items():
        if name in skipped:
            continue
        arr = arrays[name]
        unit = _UNITS.get(name, "")
        what = _WHAT.get(name, "")
        shape = "×".join(str(s) for s in arr.shape) or "scalar"
        head = (f'<h3 id="out-{pid}">{esc(name)}</h3><p class="caption">'
                + esc(", ".join(x for x in (what, f"shape {shape}", f"unit {unit}" if unit else "")
                                if x)))
        try:
            values = np.asarray(arr, dtype=float)
        except (TypeError, ValueError):
            parts.append(head + " (not numeric: shown as text)</p><pre>"
                         + esc(np.array2string(arr, threshold=200)) + "</pre>")
            continue
        fig, note = _figure(name, values, t, unit, scene=res.scene, max_points=max_points)
        parts.append(head + (esc("; " + note) if note else "") + "</p>"
                     + _plot_div(fig, pid, name))
        n_plots += 1
    index = "".join(f'<li><a href="#out-{pid}">{esc(n)}</a></li>' for n, pid in ids.items())
    if skipped:
        parts.append('<h3 id="out-not-plotted">Not plotted</h3><p class="caption">Outputs of '
                     "the result file without a plot of their own, and where they are shown."
                     '</p><table class="not-plotted"><tr><th>output</th><th>shape</th>'
                     "<th>what</th><th>why not plotted</th></tr>"
                     + "".join(f'<tr id="out-{ids[n]}"><td><code>{esc(n)}</code></td>'
                               f'<td class="num">'
                               f'{esc("×".join(str(s) for s in arrays[n].shape) or "scalar")}'
                               f"</td><td>{esc(_WHAT.get(n, ''))}</td><td>{esc(why)}</td></tr>"
                               for n, why in skipped.items())
                     + "</table>")
    body = ('<section id="plots"><h2>Outputs</h2><p class="caption">Every time series of the '
            "result against time (drag to zoom, double-click to reset, click a legend entry to "
            "hide a line); the outputs without a plot of their own are listed at the end.</p>"
            f'<ul class="index">{index}</ul>' + "\n".join(parts) + "</section>")
    return body, n_plots


def _points_per_line(res: Result) -> int:
    """Points of one line in the page: at most MAX_POINTS, and at most PAGE_POINTS over all
    the page's lines (at least MIN_POINTS each), so that the page's size is bounded whatever
    the number of output times."""
    n_t = len(res.t)
    n_lines = 7 if "section_forces" in res.outputs else 0    # the section-force history
    for name in res.outputs:
        shape = np.shape(res.outputs[name])
        if name in _STATIC or not shape or shape[0] != n_t \
                or _not_plotted(name, shape, n_t, True):
            continue
        comps = int(np.prod(shape[1:])) if len(shape) > 1 else 1
        if _layout(shape[1:]) != "heatmap":
            n_lines += comps
    if n_lines == 0:
        return MAX_POINTS
    return int(max(MIN_POINTS, min(MAX_POINTS, PAGE_POINTS // n_lines)))


def _dom_id(name: str, used: set) -> str:
    base = re.sub(r"[^A-Za-z0-9_-]", "-", name) or "output"
    pid, i = base, 1
    while pid in used:
        i += 1
        pid = f"{base}-{i}"
    used.add(pid)
    return pid


_TEMPLATE = None


def _template():
    """A small plotly template (the default one would be repeated in every figure)."""
    global _TEMPLATE
    if _TEMPLATE is None:
        import plotly.graph_objects as go
        axis = dict(gridcolor="#e4e7eb", linecolor="#9aa5b1", zerolinecolor="#cbd2d9",
                    ticks="outside", tickcolor="#9aa5b1", automargin=True)
        _TEMPLATE = go.layout.Template(layout=dict(
            font=dict(family="system-ui, sans-serif", size=12, color="#1f2933"),
            paper_bgcolor="#ffffff", plot_bgcolor="#ffffff", xaxis=axis, yaxis=axis,
            colorway=["#3f51b5", "#e8710a", "#1b7f3b", "#b42318", "#7b3fb5", "#8d6e63",
                      "#d81b60", "#607d8b", "#9e9d24", "#00838f", "#5c6bc0", "#f4511e"],
            hovermode="x unified", margin=dict(l=60, r=20, t=30, b=45),
            legend=dict(orientation="h", yanchor="bottom", y=1.0, x=0)))
    return _TEMPLATE


def _plot_div(fig, pid: str, name: str, cls: str = PLOT_CLASS) -> str:
    import plotly.io as pio
    height = fig.layout.height or 320
    # plotly escapes "<", ">" and "/" in the figure's JSON but writes ``config`` with plain
    # json.dumps into the <script> block: only the DOM id (letters, digits, "_", "-"; the
    # output's name wherever the name is made of those) goes there, never the name itself.
    div = pio.to_html(fig, include_plotlyjs=False, full_html=False, div_id=f"plotly-{pid}",
                      default_width="100%", default_height=f"{height}px", validate=False,
                      config={"responsive": True, "displaylogo": False,
                              "toImageButtonOptions": {"filename": pid}})
    return (f'<div class="{cls}" id="plot-{pid}" data-output="{html.escape(name)}">'
            f"{div}</div>")


def _figure(name: str, y: np.ndarray, t: np.ndarray, unit: str, *, scene=None,
            max_points: int = MAX_POINTS):
    """The plotly figure of one output and a note on what the page shows of it."""
    if name not in _STATIC and y.ndim >= 1 and y.shape[0] == len(t):
        return _time_figure(name, y, t, unit, scene or {}, max_points)
    return _static_figure(name, y, unit, scene or {})


def _layout(rest: tuple) -> str:
    """How a time series of component shape ``rest`` is drawn: "lines" (one axis), "groups"
    (one axis per group of the last axis' components) or "heatmap"."""
    comps = int(np.prod(rest)) if rest else 1
    if comps <= MAX_LINES and len(rest) <= 1:
        return "lines"
    groups = int(np.prod(rest[:-1])) if len(rest) >= 2 else 1
    if len(rest) >= 2 and groups <= MAX_GROUPS and rest[-1] <= MAX_LINES:
        return "groups"
    return "heatmap"


def _stage(k: int) -> str:
    return f"{k + 1}-{k + 2}"


def _telescopic_layout(scene: dict):
    """(stages with a prescribed length, booms moved by a rope unit, mechanism) of a
    telescopic scene (sim_core.systems.telescopic.build.drive_layout), None for another."""
    booms, drive = scene.get("booms"), scene.get("drive")
    if scene.get("kind") != "telescopic" or not isinstance(booms, dict) \
            or not isinstance(drive, dict) or "count" not in booms:
        return None
    from sim_core.systems.telescopic.build import drive_layout
    mechanism = drive.get("mechanism", "synchronized")
    return (*drive_layout(int(booms["count"]), mechanism), mechanism)


def _drive_names(n: int, scene: dict):
    """drive_forces: one column per prescribed stage length (build.drive_name)."""
    layout = _telescopic_layout(scene)
    if layout is None or len(layout[0]) != n:
        return [f"drive {k + 1}" for k in range(n)]
    what = "cylinder" if layout[2] == "synchronized" else "drive"
    return [f"stage {_stage(k)} {what}" for k in layout[0]]


def _rope_names(n: int, scene: dict):
    """rope_tensions: the extraction and the retraction rope of every rope unit, in the
    order of the units (build.rope_names)."""
    layout = _telescopic_layout(scene)
    if layout is None or 2 * len(layout[1]) != n:
        return [f"rope {k + 1}" for k in range(n)]
    return [f"{kind} rope, boom {j + 1}" for j in layout[1]
            for kind in ("extraction", "retraction")]


# names of an axis' entries from its length (and the scene): the rules of COMPONENT_LABELS
_AXIS_RULES = {
    "overlap": lambda n, sc: [f"overlap {_stage(k)}" for k in range(n)],
    "stage": lambda n, sc: [f"stage {_stage(k)}" for k in range(n)],
    # contact regions I_12, II_12, I_23, II_23, ... (sim_core.physics.contact)
    "region": lambda n, sc: ([f"{'I' if r % 2 == 0 else 'II'}_{r // 2 + 1}{r // 2 + 2}"
                              for r in range(n)] if n % 2 == 0 else None),
    "drive": _drive_names, "rope": _rope_names,
    "boom": lambda n, sc: [f"boom {k + 1}" for k in range(n)],
}


def component_axes(name: str, shape: tuple, scene: dict | None = None) -> list[list[str]] | None:
    """The names of the entries of every axis of one output time's ``shape`` of output
    ``name`` (:data:`COMPONENT_LABELS`), None where the table does not name them."""
    spec = COMPONENT_LABELS.get(name)
    if spec is None or len(spec) != len(shape):
        if len(shape) == 1 and shape[0] == 3 and _UNITS.get(name) in ("m", "m/s", "m/s²"):
            return [list(_XYZ)]
        return None
    axes = []
    for ax, n in zip(spec, shape):
        if isinstance(ax, tuple):
            names = list(ax)
        elif ax in _AXIS_RULES:
            names = _AXIS_RULES[ax](n, scene or {})
        else:                                       # numbered entries: "spring 1", "mode 1"
            names = [f"{ax} {k + 1}" for k in range(n)]
        if names is None or len(names) != n:
            return None
        axes.append(names)
    return axes


def component_labels(name: str, shape: tuple, scene: dict | None = None) -> list[str]:
    """One label per component of ``name`` at one output time (C order over ``shape``): the
    names of its axes joined ("overlap 1-2 outer pad f_t"); index lists where
    :data:`COMPONENT_LABELS` does not name them, the output's name for a scalar."""
    if not shape:
        return [name]
    axes = component_axes(name, shape, scene)
    if axes is None:
        if len(shape) == 1:
            return [f"[{k}]" for k in range(shape[0])]
        return [str(list(ix)) for ix in np.ndindex(*shape)]
    return [" ".join(c) for c in itertools.product(*axes)]


def _envelope(t: np.ndarray, y: np.ndarray, max_points: int = MAX_POINTS):
    """At most ``max_points`` points per column of ``y`` (n, m): where n is larger, the smallest
    and the largest value of each of max_points / 2 runs of rows, in time order.  Returns
    (x, y) arrays of shape (k, m) and a note ("" where every point is kept)."""
    n, m = y.shape
    if n <= max_points:
        return np.repeat(t[:, None], m, axis=1), y, ""
    nb = max(1, max_points // 2)
    size = math.ceil(n / nb)
    nb = math.ceil(n / size)
    pad = nb * size - n
    yp = np.concatenate([y, np.repeat(y[-1:], pad, axis=0)]) if pad else y
    blocks = yp.reshape(nb, size, m)
    lo = np.argmin(np.where(np.isnan(blocks), np.inf, blocks), axis=1)
    hi = np.argmax(np.where(np.isnan(blocks), -np.inf, blocks), axis=1)
    base = (np.arange(nb) * size)[:, None]
    first = np.minimum(lo, hi) + base
    second = np.maximum(lo, hi) + base
    idx = np.minimum(np.stack([first, second], axis=1).reshape(2 * nb, m), n - 1)
    note = (f"{n} output times: each line shows the smallest and the largest value of each "
            f"run of {size}")
    return t[idx], np.take_along_axis(y, idx, axis=0), note


def _time_figure(name: str, y: np.ndarray, t: np.ndarray, unit: str, scene: dict,
                 max_points: int = MAX_POINTS):
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots
    n = len(t)
    rest = y.shape[1:]
    comps = int(np.prod(rest)) if rest else 1
    Y = y.reshape(n, comps)
    ytitle = f"{name} ({unit})" if unit else name
    layout = _layout(rest)
    if layout == "lines":
        labels = component_labels(name, rest, scene)
        x, yy, note = _envelope(t, Y, max_points)
        fig = go.Figure([go.Scatter(x=x[:, j], y=yy[:, j], mode="lines", name=labels[j])
                         for j in range(comps)])
        fig.update_layout(template=_template(), height=320, showlegend=comps > 1,
                          xaxis_title="t (s)", yaxis_title=ytitle)
        return fig, note
    if layout == "groups":
        groups, last = int(np.prod(rest[:-1])), rest[-1]
        axes = component_axes(name, rest, scene)
        if axes is None:
            glabels = component_labels(name, rest[:-1])
            labels = [f"[{k}]" for k in range(last)]
        else:
            glabels = [" ".join(c) for c in itertools.product(*axes[:-1])]
            labels = axes[-1]
        fig = make_subplots(rows=groups, cols=1, shared_xaxes=True, vertical_spacing=0.04,
                            subplot_titles=glabels)
        x, yy, note = _envelope(t, Y, max_points)
        colours = _template().layout.colorway
        for g in range(groups):
            for j in range(last):
                c = g * last + j
                fig.add_trace(go.Scatter(x=x[:, c], y=yy[:, c], mode="lines", name=labels[j],
                                         legendgroup=labels[j], showlegend=g == 0,
                                         line=dict(color=colours[j % len(colours)]),
                                         meta=glabels[g]), row=g + 1, col=1)
        height = 100 + 190 * groups
        # the legend above the first axis' title
        fig.update_layout(template=_template(), height=height, margin=dict(t=55),
                          legend=dict(y=1.0 + 28.0 / (height - 100), yanchor="bottom"))
        fig.update_xaxes(title_text="t (s)", row=groups, col=1)
        fig.update_yaxes(title_text=unit or None)
        return fig, note
    return _heatmaps(name, Y, rest, t, unit, scene)


def _heatmaps(name: str, Y: np.ndarray, rest: tuple, t: np.ndarray, unit: str, scene: dict):
    """Time against component (one heat map per group where the first axis is short)."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots
    n, comps = Y.shape
    axes = component_axes(name, rest, scene)
    if len(rest) >= 2 and rest[0] <= MAX_GROUPS:
        groups, per = rest[0], comps // rest[0]
        titles = axes[0] if axes else component_labels(name, rest[:1])
        inner = rest[1:]
    else:
        groups, per, titles, inner = 1, comps, None, rest
    keep = max(2, MAX_CELLS // max(comps, 1))
    note = ""
    if n > keep:
        step = math.ceil(n / keep)
        idx = np.arange(0, n, step)
        if idx[-1] != n - 1:
            idx = np.append(idx, n - 1)
        note = f"{n} output times: every {step}th shown"
    else:
        idx = np.arange(n)
    if axes is not None and len(inner) == 1:    # the axis named by its entries' kind
        ylabel = str(COMPONENT_LABELS[name][-1]) if isinstance(COMPONENT_LABELS[name][-1], str) \
            else "component"
        ylabel += " (index from 0)"
    else:
        ylabel = ("component " + "×".join(str(s) for s in inner) + " (flattened)"
                  if len(inner) > 1 else "component")
    fig = make_subplots(rows=groups, cols=1, shared_xaxes=True, vertical_spacing=0.05,
                        subplot_titles=titles)
    finite = Y[np.isfinite(Y)]
    zmin, zmax = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    for g in range(groups):
        z = Y[idx][:, g * per:(g + 1) * per].T.astype(np.float32)
        fig.add_trace(go.Heatmap(x=t[idx], y=np.arange(per), z=z, zmin=zmin, zmax=zmax,
                                 coloraxis="coloraxis", name=titles[g] if titles else name),
                      row=g + 1, col=1)
        fig.update_yaxes(title_text=ylabel, row=g + 1, col=1)
    fig.update_layout(template=_template(), height=110 + 230 * groups, hovermode="closest",
                      coloraxis=dict(colorscale="Viridis", colorbar=dict(title=unit or "")))
    fig.update_xaxes(title_text="t (s)", row=groups, col=1)
    return fig, note


def _static_figure(name: str, y: np.ndarray, unit: str, scene: dict | None = None):
    """A time-independent array: (x, y) pairs as shapes to scale, rows as curves, else a heat
    map."""
    import plotly.graph_objects as go
    if y.ndim == 0:
        y = y.reshape(1)
    if y.ndim >= 2 and y.shape[-1] == 2:
        pts = [p[~np.isnan(p).any(axis=1)] for p in y.reshape(-1, y.shape[-2], 2)]
        if name in _CLOSED:                  # a contour: its last point joined to its first
            pts = [np.vstack([p, p[:1]]) if len(p) > 2 else p for p in pts]
        axes = component_axes(name, y.shape, scene)
        labels = ([" ".join(c) for c in itertools.product(*axes[:-2])] if axes and y.ndim > 2
                  else component_labels(name, y.shape[:-2]) if y.ndim > 2 else [name])
        comp = axes[-1] if axes else ["x", "y"]
        fig = go.Figure([go.Scatter(x=p[:, 0], y=p[:, 1], mode="lines", name=labels[k])
                         for k, p in enumerate(pts)])
        fig.update_layout(template=_template(), height=420, hovermode="closest",
                          xaxis_title=f"{comp[0]} ({unit})" if unit else comp[0],
                          yaxis_title=f"{comp[1]} ({unit})" if unit else comp[1])
        fig.update_yaxes(scaleanchor="x", scaleratio=1)
        return fig, "time-independent: drawn to scale"
    rows = y.reshape(-1, y.shape[-1]) if y.ndim >= 2 else y.reshape(1, -1)
    if len(rows) <= MAX_LINES:
        fig = go.Figure([go.Scatter(x=np.arange(rows.shape[1]), y=r, mode="lines+markers",
                                    name=f"[{k}]" if len(rows) > 1 else name)
                         for k, r in enumerate(rows)])
        fig.update_layout(template=_template(), height=320, xaxis_title="index",
                          yaxis_title=f"{name} ({unit})" if unit else name)
    else:
        fig = go.Figure(go.Heatmap(z=rows.astype(np.float32), colorscale="Viridis"))
        fig.update_layout(template=_template(), height=420, hovermode="closest",
                          xaxis_title="last index", yaxis_title="row")
    return fig, "time-independent"
