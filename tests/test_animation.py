"""sim_core.animation: replay animations of a telescopic run (GIF, MP4) from its geometry.

The results are short extractions of the paper's crane (3 nodes per boom, 2 s, the drive's ramp
shortened so that the booms extend by about 0.9 m per stage), one with the payload swinging on
the hoist rope; each simulation takes a few seconds and each animation about a second.
"""

import itertools
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from sim_core import Result, load_scene, simulate
from sim_core.animation import (
    ALLOWED_SUFFIXES,
    PAYLOAD_COLOUR,
    _Geometry,
    animate,
    frame_times,
)

_OVERRIDES = {"booms.n_nodes": 3, "solver.t_end": 2.0, "solver.n_output": 21,
              "drive.t_ramp": 0.5}


@pytest.fixture(scope="module")
def extraction():
    """2 s of the extraction (payload at the tip): the tip rises by about 1.5 m."""
    result = simulate(load_scene("telescopic_extraction", overrides=_OVERRIDES))
    assert result.error is None
    return result


@pytest.fixture(scope="module")
def swing():
    """The same with the payload swinging on the 10 m hoist rope (payload_position)."""
    result = simulate(load_scene("telescopic_extraction",
                                 overrides={**_OVERRIDES, "effects.payload_swing": True}))
    assert result.error is None and "payload_position" in result
    return result


def _frames(path):
    """The GIF's frames as RGB arrays (n, h, w, 3)."""
    with Image.open(path) as im:
        frames = []
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(np.asarray(im.convert("RGB"), dtype=np.int16))
    return np.array(frames)


def _is_payload(rgb):
    target = np.array([int(PAYLOAD_COLOUR[i:i + 2], 16) for i in (1, 3, 5)])
    return np.all(np.abs(rgb - target) <= 40, axis=-1)


def _boom_pixels(rgb):
    """The booms' pixels: coloured (saturated) ones, the payload's yellow left out (the rest
    of the picture, axes, text, cylinder, rope and sliders, is grey or black)."""
    saturated = rgb.max(axis=-1) - rgb.min(axis=-1) > 40
    return saturated & ~_is_payload(rgb)


def _bbox(mask):
    """(row min, row max, column min, column max) of the True pixels."""
    rows, cols = np.nonzero(mask)
    return rows.min(), rows.max(), cols.min(), cols.max()


def _tube_extent(result, k):
    """Horizontal (X) and vertical (Z) extent in m of the booms' tubes at output k: the outer
    contours swept along the centre lines, point = r + y e_t + z e_b."""
    lines = result["geometry_centre_lines"][k]
    frames = result["geometry_section_frames"][k]
    pts = []
    for b, outline in enumerate(result["geometry_section_outlines"]):
        yz = outline[np.all(np.isfinite(outline), axis=1)]
        pts.append(lines[b][:, None, :] + yz[None, :, 0, None] * frames[b][:, None, 0]
                   + yz[None, :, 1, None] * frames[b][:, None, 1])
    pts = np.concatenate([p.reshape(-1, 3) for p in pts])
    return np.ptp(pts[:, 0]), np.ptp(pts[:, 2])


def test_gif_has_the_expected_frames_and_is_not_blank(extraction, tmp_path):
    """2 s at 10 frames/s in real time: 21 frames (0, 0.1, ..., 2.0 s), 800 x 600 px; every
    frame shows coloured booms over a large area, and each differs from the one before; the file is
    the only one left in the folder (written through a temporary file + rename)."""
    out = animate(extraction, tmp_path / "extraction.gif", fps=10)
    assert out == tmp_path / "extraction.gif"
    assert len(frame_times(extraction.t, fps=10)) == 21
    with Image.open(out) as im:
        assert im.n_frames == 21
        assert im.size == (800, 600)
    frames = _frames(out)
    for rgb in frames:
        assert _boom_pixels(rgb).sum() > 2000
        packed = (rgb[..., 0].astype(np.int32) << 16) | (rgb[..., 1] << 8) | rgb[..., 2]
        assert len(np.unique(packed)) > 20
    assert all(np.any(a != b) for a, b in itertools.pairwise(frames))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["extraction.gif"]


@pytest.mark.parametrize("view", ["two", "3d"])
def test_booms_visibly_extend(extraction, tmp_path, view):
    """The first and last frames differ in thousands of pixels, the booms cover pixels in the
    last that they did not in the first, and the drawn booms grow as the geometry says.  Side view (left panel of view="two", X-Z at a fixed equal-aspect
    scale): the height and width in pixels of the booms' drawing grow by the ratio of the
    tubes' extents in Z and X at t = 0 and t = 2 s (within 3 %), by more than 20 px.  3D view
    (perspective, no fixed scale): the drawing's height grows by at least half that ratio's
    excess over 1."""
    out = animate(extraction, tmp_path / f"extend_{view}.gif", fps=10, view=view)
    frames = _frames(out)
    first, last = frames[0], frames[-1]
    if view == "two":
        first, last = first[:, :400], last[:, :400]          # the side view
    assert np.any(first != last, axis=-1).sum() > 2000
    m0, m1 = _boom_pixels(first), _boom_pixels(last)
    assert (m1 & ~m0).sum() > 500                             # boom drawn where none was

    r0, r1, c0, c1 = _bbox(m0)
    s0, s1, d0, d1 = _bbox(m1)
    h0, h1 = r1 - r0, s1 - s0
    w0, w1 = c1 - c0, d1 - d0
    x_first, z_first = _tube_extent(extraction, 0)
    x_last, z_last = _tube_extent(extraction, -1)
    assert z_last / z_first > 1.08                            # the geometry: the booms extend
    if view == "two":
        assert h1 - h0 > 20 and w1 - w0 > 10
        assert h1 / h0 == pytest.approx(z_last / z_first, rel=0.03)
        assert w1 / w0 == pytest.approx(x_last / x_first, rel=0.03)
        assert abs(r1 - s1) <= 3                              # the root stays where it is
    else:
        assert h1 / h0 > 1 + 0.5 * (z_last / z_first - 1)


def test_swinging_payload_moves(swing, tmp_path):
    """With payload_position the payload (yellow marker) moves in the side view as the
    geometry says: its pixel centroid moves between the first and the last frame by the
    payload's displacement in X-Z times the drawing's scale (px/m, from the booms' drawn height
    and the tubes' Z extent), within 25 % and 4 px, and by more than 15 px."""
    out = animate(swing, tmp_path / "swing.gif", fps=10, view="two")
    frames = _frames(out)
    first, last = frames[0][:, :400], frames[-1][:, :400]
    centres = []
    for rgb in (first, last):
        rows, cols = np.nonzero(_is_payload(rgb))
        assert rows.size > 20
        centres.append(np.array([cols.mean(), rows.mean()]))
    moved = centres[1] - centres[0]

    r0, r1, _, _ = _bbox(_boom_pixels(first))
    px_per_m = (r1 - r0) / _tube_extent(swing, 0)[1]
    dp = swing["payload_position"][-1] - swing["payload_position"][0]
    expected = px_per_m * np.array([dp[0], -dp[2]])          # image rows grow downwards
    assert np.hypot(*expected) > 15
    assert np.hypot(*(moved - expected)) < max(4.0, 0.25 * np.hypot(*expected))


def test_window_speed_and_overlays(swing, tmp_path):
    """t_start/t_end and speed: 0.5-1.5 s at twice real time and 10 frames/s gives 6 frames
    (0.5, 0.7, ..., 1.5 s); overlays missing from the result are skipped without error."""
    times = frame_times(swing.t, speed=2.0, fps=10, t_start=0.5, t_end=1.5)
    np.testing.assert_allclose(times, [0.5, 0.7, 0.9, 1.1, 1.3, 1.5])
    out = animate(swing, tmp_path / "window.gif", speed=2.0, fps=10, t_start=0.5, t_end=1.5,
                  overlays=("hoist_rope_force", "sway_angle", "slew_angle", "no_such_output"))
    with Image.open(out) as im:
        assert im.n_frames == 6
    with pytest.raises(ValueError, match="not inside the run"):
        frame_times(swing.t, t_start=1.0, t_end=5.0)


def test_deflection_scale(extraction):
    """scale = 1 draws the true centre lines; scale = 10 keeps the root point and every
    point's position along boom 1's root chord, and multiplies the offset from the chord by 10."""
    k = 10
    t = extraction.t[k]
    lines = extraction["geometry_centre_lines"][k]
    true = _Geometry(extraction, 1.0).at(t)["centre"]
    np.testing.assert_allclose(true, lines, atol=1e-12)
    big = _Geometry(extraction, 10.0).at(t)["centre"]
    r0 = lines[0, 0]
    a = extraction["geometry_section_frames"][k, 0, 0, 2]
    along = (lines - r0) @ a
    offset = (lines - r0) - along[..., None] * a
    np.testing.assert_allclose(big - r0, along[..., None] * a + 10.0 * offset, atol=1e-9)
    assert np.abs(offset).max() > 1e-3                        # there is a deflection to scale


def test_mp4(extraction, tmp_path):
    """An MP4 through imageio-ffmpeg's ffmpeg: written, non-empty, with the expected 21
    frames (2 s at 10 frames/s)."""
    imageio_ffmpeg = pytest.importorskip(
        "imageio_ffmpeg", reason="MP4 needs imageio-ffmpeg (the [media] extra)")
    out = animate(extraction, tmp_path / "extraction.mp4", fps=10, scale=20.0)
    assert out.stat().st_size > 1000
    n_frames, _ = imageio_ffmpeg.count_frames_and_secs(str(out))
    assert n_frames == 21
    assert sorted(p.name for p in tmp_path.iterdir()) == ["extraction.mp4"]


def test_result_without_geometry_raises(tmp_path):
    """A result without geometry_centre_lines (the modal ROM, beam or folding scenes): a
    one-line ValueError saying the result has no replay geometry; nothing is written."""
    t = np.linspace(0.0, 1.0, 5)
    result = Result(t=t, outputs={"tip_position": np.zeros((5, 3))},
                    scene={"name": "beam_through_sleeve"})
    with pytest.raises(ValueError, match="no replay geometry") as info:
        animate(result, tmp_path / "beam.gif")
    assert "\n" not in str(info.value)
    assert "telescopic" in str(info.value)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["crane.avi", "crane.png", "crane"])
def test_bad_suffix_raises(extraction, tmp_path, name):
    """Any suffix but .gif and .mp4: ValueError naming the allowed ones; nothing written."""
    with pytest.raises(ValueError, match=r"\.gif, \.mp4"):
        animate(extraction, tmp_path / name)
    assert ALLOWED_SUFFIXES == (".gif", ".mp4")
    assert list(tmp_path.iterdir()) == []


def test_failed_render_keeps_the_old_file(extraction, tmp_path, monkeypatch):
    """Atomic writing: a render that fails half-way leaves an existing file as it was and no
    temporary file behind."""
    from sim_core import animation

    out = tmp_path / "old.gif"
    out.write_bytes(b"old")
    calls = []
    update = animation._Renderer.update

    def failing(self, tq):
        calls.append(tq)
        if len(calls) > 3:
            raise RuntimeError("boom")
        update(self, tq)

    monkeypatch.setattr(animation._Renderer, "update", failing)
    with pytest.raises(RuntimeError, match="boom"):
        animate(extraction, out, fps=10)
    assert out.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["old.gif"]


def test_import_is_light():
    """Importing sim_core.animation imports neither matplotlib nor Pillow."""
    code = ("import sys, sim_core.animation; "
            "assert 'matplotlib' not in sys.modules and 'PIL' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)
