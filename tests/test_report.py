"""The run's report (sim_core.report, ``boom-sim report``) without a browser: one file that
needs nothing beside it, one plot per output, the summary, the self-checks and the paper's
comparison rows in it, written atomically; bad inputs get a clear error (CLI: exit 2, one
line).  tests/test_report_browser.py opens the page in Chromium."""

from __future__ import annotations

import base64
import json
import math
import re
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from sim_core import cli
from sim_core import report as rp
from sim_core.result import Result
from sim_core.validation.closed_form import static_luffing_forces
from sim_core.validation.paper_rows import THETA, rigid_rows

pytest.importorskip("plotly")

N_T = 41


class _Page(HTMLParser):
    """The page's plot containers, script sources, media sources and text."""

    def __init__(self):
        super().__init__()
        self.plots, self.script_src, self.media_src, self.text = [], [], [], []
        self.links = []                     # every src and href of the page's elements

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.links += [v for k, v in attrs if k in ("src", "href") and v]
        if tag == "div" and rp.PLOT_CLASS in (a.get("class") or "").split():
            self.plots.append(a)
        if tag == "script" and "src" in a:
            self.script_src.append(a["src"])
        if tag in ("img", "video") and "src" in a:
            self.media_src.append(a["src"])

    def handle_data(self, data):
        self.text.append(data)


def parse(path: Path) -> _Page:
    page = _Page()
    page.feed(Path(path).read_text(encoding="utf-8"))
    page.text = " ".join(" ".join(page.text).split())
    return page


def result_of_every_shape(n: int = N_T) -> Result:
    """A result with the output shapes of the system kinds: a scalar, vectors, per-pair
    contact forces, slider springs per region, the integrator state, replay geometry and a
    time-independent section outline (NaN-padded)."""
    t = np.linspace(0.0, 2.0, n)
    w = np.sin(2 * np.pi * t)
    outline = np.full((3, 8, 2), np.nan)
    for k in range(3):
        a = np.linspace(0.0, 2 * np.pi, 6 + k, endpoint=False)
        outline[k, :6 + k] = np.c_[np.cos(a), np.sin(a)] * (0.4 - 0.03 * k)
    outputs = {
        "piston_stroke": 0.5 * t ** 2,
        "tip_position": np.c_[t, 0 * t, 1 + w],
        "contact_point_forces": np.einsum("t,pcj->tpcj", w, np.arange(24.0).reshape(2, 2, 6)),
        "friction_coefficient": np.tile([0.1, 0.15, 0.1, 0.15], (n, 1)),
        "slider_contact_forces": np.einsum("t,rs->trs", 1 + w, np.ones((4, 160))),
        "state": np.outer(w, np.arange(626.0)),
        "geometry_centre_lines": np.zeros((n, 3, 11, 3)) + t[:, None, None, None],
        "geometry_section_outlines": outline,
    }
    stats = {"wall_time_s": 1.5, "n_steps": 120, "n_rhs": 800, "min_step_s": 1e-4,
             "max_step_s": 0.02, "method": "auto", "real_time_factor": 1.33, "n_dof": 313,
             "checks": {"constraint_violation": {"value": 2e-8, "limit": 1e-3, "fail_limit": 1.5,
                                                 "ok": True, "gross": False,
                                                 "what": "largest constraint violation, m"},
                        "energy_balance": {"value": 0.05, "limit": 0.02, "fail_limit": 0.2,
                                           "ok": False, "gross": False,
                                           "what": "energy growth / exchanged energy"}},
             "suspect": True, "failed_checks": ["energy_balance"]}
    scene = {"kind": "telescopic", "name": "my_crane", "description": "a test crane",
             "source": "/somewhere/my_crane.toml", "solver": {"t_end": 2.0}}
    return Result(t, outputs, stats, scene)


def test_the_default_report_is_one_self_contained_file(tmp_path):
    res = result_of_every_shape()
    path = rp.write_report(res, tmp_path / "report.html")
    assert path == tmp_path / "report.html" and sorted(p.name for p in tmp_path.iterdir()) == [
        "report.html"]                          # nothing beside it, no temporary file left
    page = parse(path)
    text = path.read_text(encoding="utf-8")
    assert page.script_src == []                # plotly.js inline: no script to fetch
    # nothing the page loads or links to is outside the file (plotly.js's own source names
    # sites, for its map tiles and logo, which these plots do not use)
    assert page.links and all(v.startswith(("#", "data:")) for v in page.links), page.links
    from plotly.offline import get_plotlyjs
    assert get_plotlyjs()[:2000] in text
    # the scene's file path is not in the page (it names the author's machine)
    assert "/somewhere" not in text and '"solver": {' in page.text


def plotted(res: Result) -> list[str]:
    """The outputs with a plot of their own: all but the integrator state and the replay
    geometry (and the per-station section arrays, which result_of_every_shape lacks)."""
    return [n for n in res.outputs if n != "state" and not n.startswith("geometry_")]


def test_one_plot_per_time_series_with_a_stable_id(tmp_path):
    res = result_of_every_shape()
    page = parse(rp.write_report(res, tmp_path / "report.html"))
    assert [p["id"] for p in page.plots] == [f"plot-{name}" for name in plotted(res)]
    assert [p["data-output"] for p in page.plots] == plotted(res)
    assert "Plots (5)" in page.text


def test_state_and_replay_geometry_are_listed_not_plotted(tmp_path):
    res = result_of_every_shape()
    path = rp.write_report(res, tmp_path / "report.html")
    page, text = parse(path), path.read_text(encoding="utf-8")
    for name in ("state", "geometry_centre_lines", "geometry_section_outlines"):
        assert f'id="plot-{name}"' not in text and f'data-output="{name}"' not in text
        # in the index, linked to its row of the table of outputs without a plot
        assert f'<a href="#out-{name}">' in text and f'<tr id="out-{name}">' in text
    assert "replay geometry: drawn by the animation" in page.text
    assert "the integrator state" in page.text


def test_summary_and_self_checks_are_in_the_page(tmp_path):
    res = result_of_every_shape()
    page = parse(rp.write_report(res, tmp_path / "report.html"))
    assert "my_crane" in page.text and "a test crane" in page.text
    for fragment in ("steps 120", "RHS evaluations 800", "real-time factor 1.33",
                     "degrees of freedom 313", "smallest step 0.0001 s"):
        assert fragment in page.text, fragment
    # both checks with their values and limits; the failed one marked, the note naming it
    assert "constraint_violation 2e-08 0.001 1.5 ok" in page.text
    assert "energy_balance 0.05 0.02 0.2 suspect" in page.text
    assert res.suspect_note() in page.text
    assert "stopped early" not in page.text


def test_a_stopped_run_says_so(tmp_path):
    res = result_of_every_shape()
    res.error = "simulation failed at t = 1.5 s: step size too small"
    page = parse(rp.write_report(res, tmp_path / "report.html"))
    assert "stopped early" in page.text and res.error in page.text


def test_a_result_without_checks_says_so(tmp_path):
    res = result_of_every_shape()
    res.stats = {"n_steps": 3}
    page = parse(rp.write_report(res, tmp_path / "report.html"))
    assert "The result records no self-checks." in page.text


def test_long_series_keep_every_peak_within_the_point_budget(rng):
    """The page's envelope of a long series: at most MAX_POINTS points per line, in time
    order, holding every sample's extreme (a one-sample spike anywhere survives)."""
    n = 5 * rp.MAX_POINTS + 7
    t = np.linspace(0.0, 50.0, n)
    y = np.c_[np.sin(t), rng.normal(size=n)]
    spike = int(rng.integers(n))
    y[spike, 0] = 40.0
    x, yy, note = rp._envelope(t, y)
    assert len(x) <= rp.MAX_POINTS and note
    assert np.all(np.diff(x, axis=0) >= 0)
    assert yy[:, 0].max() == 40.0 and x[np.argmax(yy[:, 0]), 0] == t[spike]
    assert yy[:, 1].min() == y[:, 1].min() and yy[:, 1].max() == y[:, 1].max()
    # every kept point is a sample of the series
    for j in range(2):
        np.testing.assert_array_equal(np.interp(x[:, j], t, y[:, j]), yy[:, j])
    short = np.c_[np.arange(10.0)]
    x, yy, note = rp._envelope(np.arange(10.0), short)
    assert note == "" and np.array_equal(yy, short)


def test_large_outputs_are_heat_maps_within_the_cell_budget():
    t = np.linspace(0.0, 1.0, 2001)
    fig, note = rp._figure("state", np.outer(np.sin(t), np.arange(626.0)), t, "")
    cells = sum(np.asarray(tr.z).size for tr in fig.data)
    assert all(tr.type == "heatmap" for tr in fig.data) and cells <= rp.MAX_CELLS
    assert "every" in note
    fig, _ = rp._figure("slider_contact_forces", np.ones((11, 4, 160)), t[:11], "N")
    assert len(fig.data) == 4 and [a.text for a in fig.layout.annotations] == [
        "I_12", "II_12", "I_23", "II_23"]


def test_section_outlines_are_drawn_closed_without_their_padding():
    res = result_of_every_shape()
    fig, note = rp._figure("geometry_section_outlines", res["geometry_section_outlines"],
                           res.t, "m")
    assert "time-independent" in note and len(fig.data) == 3
    for k, tr in enumerate(fig.data):
        x, y = np.asarray(tr.x), np.asarray(tr.y)
        assert len(x) == 6 + k + 1 and np.all(np.isfinite(x))
        assert (x[0], y[0]) == (x[-1], y[-1])


def test_the_animation_is_embedded(tmp_path):
    from PIL import Image
    gif = tmp_path / "anim.gif"
    frames = [Image.new("RGB", (16, 12), c) for c in ((200, 0, 0), (0, 0, 200))]
    frames[0].save(gif, save_all=True, append_images=frames[1:], duration=100)
    page = parse(rp.write_report(result_of_every_shape(), tmp_path / "r.html", animation=gif))
    (src,) = page.media_src
    assert src.startswith("data:image/gif;base64,")
    assert base64.b64decode(src.split(",", 1)[1]) == gif.read_bytes()
    mp4 = tmp_path / "anim.mp4"
    mp4.write_bytes(b"\x00\x00\x00\x18ftypisom\x00\x00\x02\x00isomiso2" + bytes(64))
    page = parse(rp.write_report(result_of_every_shape(), tmp_path / "r.html", animation=mp4))
    (src,) = page.media_src
    assert src.startswith("data:video/mp4;base64,")
    assert base64.b64decode(src.split(",", 1)[1]) == mp4.read_bytes()


def test_plotlyjs_beside_the_report_for_a_folder_of_reports(tmp_path):
    res = result_of_every_shape()
    a = rp.write_report(res, tmp_path / "a.html", include_plotlyjs="directory")
    js = tmp_path / rp.PLOTLYJS_FILE
    mtime = js.stat().st_mtime_ns
    b = rp.write_report(res, tmp_path / "b.html", include_plotlyjs="directory")
    assert js.stat().st_mtime_ns == mtime                  # one copy, written once
    from plotly.offline import get_plotlyjs
    assert js.read_text(encoding="utf-8") == get_plotlyjs()
    for p in (a, b):
        assert parse(p).script_src == [rp.PLOTLYJS_FILE]
        assert p.stat().st_size < js.stat().st_size / 2


@pytest.mark.parametrize("kwargs, error, fragment", [
    ({"include_plotlyjs": "somewhere"}, ValueError, "include_plotlyjs"),
    ({"animation": "anim.png"}, ValueError, "not a .gif or .mp4"),
    ({"animation": "missing.gif"}, FileNotFoundError, "missing.gif"),
    ({"animation": "fake.gif"}, ValueError, "not a GIF image"),
    ({"animation": "fake.mp4"}, ValueError, "not an MP4 video"),
])
def test_bad_inputs_raise_and_keep_the_existing_report(tmp_path, kwargs, error, fragment):
    (tmp_path / "fake.gif").write_bytes(b"not a gif at all")
    (tmp_path / "fake.mp4").write_bytes(b"not an mp4 at all")
    (tmp_path / "anim.png").write_bytes(b"\x89PNG\r\n\x1a\n")
    if "animation" in kwargs:
        kwargs = {"animation": tmp_path / kwargs["animation"]}
    out = tmp_path / "report.html"
    out.write_text("the previous report")
    with pytest.raises(error, match=re.escape(fragment)):
        rp.write_report(result_of_every_shape(), out, **kwargs)
    assert out.read_text() == "the previous report"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".report.html")]


def test_a_result_that_is_not_a_result_is_refused(tmp_path):
    with pytest.raises(TypeError, match="sim_core.result.Result"):
        rp.write_report({"t": [0.0]}, tmp_path / "r.html")
    assert not (tmp_path / "r.html").exists()


def test_a_failed_write_leaves_the_previous_report(tmp_path, monkeypatch):
    out = tmp_path / "report.html"
    out.write_text("the previous report")

    def broken(*args, **kwargs):
        raise OSError("disk full")
    monkeypatch.setattr("sim_core.result.os.fsync", broken)
    with pytest.raises(OSError, match="disk full"):
        rp.write_report(result_of_every_shape(), out)
    assert out.read_text() == "the previous report"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.html"]


# -- the paper's comparison rows -------------------------------------------------------------

def rigid_scene_result(t_end: float = 20.0) -> Result:
    """The nearly rigid paper scene (Section 9.1) moving exactly as the rigid kinematics of
    Eqs. 75-76 with its static cylinder forces plus the drive's inertia: every statement of
    Section 9.1 holds for it."""
    t = np.linspace(0.0, t_end, int(round(10 * t_end)) + 1)
    tau = np.clip(t / 16.0, 0.0, 1.0)
    s0 = 6.0 * (3 * tau ** 2 - 2 * tau ** 3)                  # 2 -> 8 m, at rest at both ends
    v = 6.0 * (6 * tau - 6 * tau ** 2) / 16.0
    a = 6.0 * (6 - 12 * tau) / 16.0 ** 2 * (t < 16.0)
    e = np.array([math.cos(THETA), 0.0, math.sin(THETA)])
    r0 = np.array([7.404, 0.0, 13.024])
    stat = static_luffing_forces(THETA, 2.0, 1000.0)
    ls = 2.0 + s0
    outputs = {"tip_position": r0 + 2.0 * s0[:, None] * e, "tip_velocity": 2.0 * v[:, None] * e,
               "piston_stroke": s0, "telescopic_cylinder_force": stat.telescopic_force + 4e3 * a,
               "luffing_cylinder_force": np.array([static_luffing_forces(THETA, x, 1000.0)
                                                   .luffing_force for x in ls])}
    return Result(t, outputs, {"n_steps": 10}, {"kind": "telescopic",
                                                "name": "telescopic_extraction_rigid"})


def test_a_paper_scene_shows_its_rows(tmp_path):
    res = rigid_scene_result()
    rows = rigid_rows(res)
    assert len(rows) == 4 and all(r.holds for r in rows), [(r.statement, r.value) for r in rows]
    page = parse(rp.write_report(res, tmp_path / "report.html"))
    assert "Comparison with the paper" in page.text and "Paper comparison" in page.text
    assert "4 of 4 statements hold" in page.text
    for r in rows:
        assert f"{r.figure} {r.statement} {r.value} holds" in page.text


def test_a_statement_that_fails_is_marked(tmp_path):
    res = rigid_scene_result()
    # the tip drifts off the rigid line in proportion to the travel: 50 mm at its end
    drift = 0.05 * res["piston_stroke"] / res["piston_stroke"][-1]
    res.outputs["tip_position"] = res["tip_position"] + drift[:, None] * np.array([0, 0, 1.0])
    page = parse(rp.write_report(res, tmp_path / "report.html"))
    assert "3 of 4 statements hold" in page.text
    assert "max |r - r_rigid| = 50.0 mm over a 12 m travel does not hold" in page.text


def test_a_short_paper_run_says_why_it_has_no_rows(tmp_path):
    page = parse(rp.write_report(rigid_scene_result(t_end=5.0), tmp_path / "report.html"))
    assert ("No comparison rows: the paper's statements cover 0 to 20 s; this run covers 0 to "
            "5 s.") in page.text


def test_other_scenes_have_no_paper_section(tmp_path):
    page = parse(rp.write_report(result_of_every_shape(), tmp_path / "report.html"))
    assert "Comparison with the paper" not in page.text and "Paper comparison" not in page.text


# -- command line ----------------------------------------------------------------------------

def test_boom_sim_report_writes_the_report_beside_the_result(tmp_path, capsys):
    res = result_of_every_shape()
    res.save(tmp_path / "result.npz")
    assert cli.main(["report", str(tmp_path / "result.npz")]) == 0
    assert f"wrote {tmp_path / 'report.html'}" in capsys.readouterr().out
    assert len(parse(tmp_path / "report.html").plots) == len(plotted(res))
    out = tmp_path / "elsewhere" / "r.html"
    assert cli.main(["report", str(tmp_path / "result.npz"), "--out", str(out)]) == 0
    assert len(parse(out).plots) == len(plotted(res))


@pytest.mark.parametrize("content, fragment", [
    (b"", "empty file"), (b"hello", "not a result file"), (None, "No such file")])
def test_boom_sim_report_of_a_bad_result_exits_2_with_one_line(tmp_path, capsys, content,
                                                               fragment):
    path = tmp_path / "result.npz"
    if content is not None:
        path.write_bytes(content)
    assert cli.main(["report", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("boom-sim: error: ") and fragment in err
    assert not (tmp_path / "report.html").exists()


def test_boom_sim_report_with_a_bad_animation_exits_2(tmp_path, capsys):
    result_of_every_shape().save(tmp_path / "result.npz")
    (tmp_path / "anim.gif").write_bytes(b"no gif")
    assert cli.main(["report", str(tmp_path / "result.npz"), "--animation",
                     str(tmp_path / "anim.gif")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "not a GIF image" in err


def _fake_run(monkeypatch):
    res = result_of_every_shape()
    monkeypatch.setattr(sys.modules["sim_core.cli"], "simulate",
                        lambda scene, progress=None, **kw: Result(res.t, res.outputs,
                                                                 dict(res.stats), scene))


def test_boom_sim_run_writes_the_report_unless_told_not_to(tmp_path, monkeypatch, capsys):
    _fake_run(monkeypatch)
    out = tmp_path / "out"
    args = ["run", "beam_through_sleeve", "--set", "solver.t_end=0.05", "--quiet", "--no-plots"]
    assert cli.main([*args, "--out", str(out)]) == 0
    assert "report.html" in capsys.readouterr().out
    page = parse(out / "report.html")
    assert len(page.plots) == len(plotted(result_of_every_shape()))
    assert json.loads((out / "summary.json").read_text())["n_steps"] == 120
    out2 = tmp_path / "out2"
    assert cli.main([*args, "--out", str(out2), "--no-report"]) == 0
    assert "report.html" not in capsys.readouterr().out
    assert not (out2 / "report.html").exists() and (out2 / "result.npz").exists()


# -- the shipped scenes' reports: what is plotted, every component named, the page's size ----

REAL_SCENES = ("telescopic_extraction", "crane_hexagonal_4")


@pytest.fixture(scope="module")
def shipped_runs():
    """The first 0.1 s of two shipped scenes with every output of the telescopic kind (replay
    geometry, section forces, pads, ropes), with their 201 output times as shipped."""
    from sim_core import load_scene, simulate
    return {name: simulate(load_scene(name, overrides={"solver.t_end": 0.1}))
            for name in REAL_SCENES}


def _figures(res: Result):
    """(output name, figure) of every output the page plots, as the page draws them."""
    page = rp._plots_section(res, enveloped=True)[0]
    names = re.findall(r'data-output="([^"]+)"', page)
    t = np.asarray(res.t, dtype=float)
    return [(n, rp._figure(n, np.asarray(res[n], dtype=float), t, rp._UNITS.get(n, ""),
                           scene=res.scene)[0]) for n in names]


@pytest.mark.parametrize("scene", REAL_SCENES)
def test_shipped_reports_plot_time_series_only(shipped_runs, scene, tmp_path):
    res = shipped_runs[scene]
    text = rp.write_report(res, tmp_path / "r.html", include_plotlyjs=False).read_text()
    shown = re.findall(r'class="report-plot" id="plot-[^"]+" data-output="([^"]+)"', text)
    never = {"state", "section_stations", "section_stress_points", "section_forces",
             "section_stress", "section_utilisation"}
    never |= {n for n in res.outputs if n.startswith("geometry_")}
    assert never <= set(res.outputs) and not never & set(shown)
    assert set(shown) | never == set(res.outputs)
    # the per-station arrays are in the section envelopes instead, the rest listed
    assert text.count(f'class="{rp.STRENGTH_CLASS}"') == 2
    for name in never:
        assert f'<tr id="out-{name}">' in text


@pytest.mark.parametrize("scene", REAL_SCENES)
def test_every_plotted_component_is_named(shipped_runs, scene):
    """Every line's name says what it is (no index fallback), no two lines of a plot share
    a name, and the telescopic kind's components carry the names of its build."""
    res = shipped_runs[scene]
    n_booms = res.scene["booms"]["count"]
    for name, fig in _figures(res):
        shape = np.asarray(res[name]).shape[1:]
        labels = rp.component_labels(name, shape, res.scene)
        assert len(labels) == max(1, int(np.prod(shape))) == len(set(labels)), name
        assert not any(re.search(r"\[\d", lab) for lab in labels), (name, labels)
        if all(tr.type == "scatter" for tr in fig.data):
            full = [f"{tr.meta} {tr.name}" if tr.meta else tr.name for tr in fig.data]
            assert full == labels, name
        else:                     # heat maps: one per group, titled by it
            titles = [a.text for a in fig.layout.annotations]
            assert titles == rp.component_axes(name, shape, res.scene)[0], name
    shape = lambda n: np.asarray(res[n]).shape[1:]      # noqa: E731
    assert rp.component_labels("tip_position", shape("tip_position")) == ["X", "Y", "Z"]
    assert rp.component_labels("pad_forces", shape("pad_forces"))[:3] == [
        "overlap 1-2 outer pad f_t", "overlap 1-2 outer pad f_b", "overlap 1-2 inner pad f_t"]
    # the synchronized drive: cylinders on stages 1-2, 3-4, ..., a rope unit for booms 3, 5, ...
    assert rp.component_labels("drive_forces", shape("drive_forces"), res.scene) == [
        f"stage {k + 1}-{k + 2} cylinder" for k in range(0, n_booms - 1, 2)]
    assert rp.component_labels("rope_tensions", shape("rope_tensions"), res.scene) == [
        f"{kind} rope, boom {j + 1}" for j in range(2, n_booms, 2)
        for kind in ("extraction", "retraction")]
    assert rp.component_labels("friction_coefficient", shape("friction_coefficient"))[:2] == [
        "I_12", "II_12"]


def _page_bytes(res: Result, path: Path) -> int:
    """The report's size without plotly.js (the same 4.6 MB in every page, or one file
    beside a folder of reports) and without an animation."""
    return rp.write_report(res, path, include_plotlyjs=False).stat().st_size


@pytest.mark.parametrize("scene", REAL_SCENES)
def test_page_size_is_bounded(shipped_runs, scene, tmp_path):
    """Under 2 MB with the shipped 201 output times, and still with 40 times as many: the
    lines then share the page's point budget (min/max envelopes, every peak kept)."""
    res = shipped_runs[scene]
    assert _page_bytes(res, tmp_path / "a.html") < 2e6
    n = 40 * (len(res.t) - 1) + 1
    t = np.linspace(res.t[0], res.t[-1], n)
    long = Result(t, {k: (np.repeat(v[:1], n, axis=0) if v.shape[:1] == res.t.shape
                          and k not in rp._STATIC else v) for k, v in res.outputs.items()},
                  res.stats, res.scene)
    assert _page_bytes(long, tmp_path / "b.html") < 2e6


def test_report_with_plotly_beside_is_a_small_page(shipped_runs, tmp_path):
    """``boom-sim report --plotly-beside`` writes plotly.js once beside the page and loads it
    from there: the page itself stays under 2 MB, and it names the file it loads."""
    res = shipped_runs["crane_hexagonal_4"]
    res.save(tmp_path / "result.npz")
    assert cli.main(["report", str(tmp_path / "result.npz"), "--plotly-beside",
                     "--no-animation"]) == 0
    page = tmp_path / "report.html"
    assert (tmp_path / rp.PLOTLYJS_FILE).stat().st_size > 1e6
    assert page.stat().st_size < 2e6
    assert f'src="{rp.PLOTLYJS_FILE}"' in page.read_text()


# -- boom-sim report picks up the run's animation ----------------------------------------------

def _gif(path: Path) -> Path:
    from PIL import Image
    frames = [Image.new("RGB", (16, 12), c) for c in ((200, 0, 0), (0, 0, 200))]
    frames[0].save(path, save_all=True, append_images=frames[1:], duration=100)
    return path


def test_boom_sim_report_embeds_the_animation_that_run_wrote(tmp_path, monkeypatch, capsys):
    """run --animate writes its animation into OUT; report OUT/result.npz embeds that file
    (unless --no-animation), as run's own report does."""
    _fake_run(monkeypatch)
    written = []
    monkeypatch.setattr(sys.modules["sim_core.cli"], "_animate",
                        lambda result, path, **kw: written.append(_gif(path)) or path)
    out = tmp_path / "out"
    assert cli.main(["run", "beam_through_sleeve", "--set", "solver.t_end=0.05", "--quiet",
                     "--no-plots", "--animate", "--out", str(out)]) == 0
    (gif,) = written
    assert gif.parent == out
    first = parse(out / "report.html").media_src
    (out / "report.html").unlink()
    capsys.readouterr()
    assert cli.main(["report", str(out / "result.npz")]) == 0
    assert f"(animation: {gif})" in capsys.readouterr().out
    src = parse(out / "report.html").media_src
    assert src == first and len(src) == 1
    assert base64.b64decode(src[0].split(",", 1)[1]) == gif.read_bytes()
    assert cli.main(["report", str(out / "result.npz"), "--no-animation"]) == 0
    assert parse(out / "report.html").media_src == []


def test_boom_sim_report_without_an_animation_beside_has_none(tmp_path, capsys):
    result_of_every_shape().save(tmp_path / "result.npz")
    assert cli.main(["report", str(tmp_path / "result.npz")]) == 0
    assert "animation" not in capsys.readouterr().out
    assert parse(tmp_path / "report.html").media_src == []
    # an explicit --animation wins over the one beside the result
    _gif(tmp_path / cli.ANIMATION_FILE)
    other = _gif(tmp_path / "other.gif")
    other.write_bytes(other.read_bytes() + b"\x00")
    assert cli.main(["report", str(tmp_path / "result.npz"), "--animation", str(other)]) == 0
    (src,) = parse(tmp_path / "report.html").media_src
    assert base64.b64decode(src.split(",", 1)[1]) == other.read_bytes()
