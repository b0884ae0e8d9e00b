"""A drive table's ``table_file`` is confined to the scene file's folder (or a folder of
BOOM_SIM_DATA_DIR), capped in size and rows, read as UTF-8 text, and its rows are range-checked
as inline ``table`` rows; every refusal is a SceneError naming the field (and the line) that
never shows the file's contents.  An inline table whose rate overflows to NaN fails
``max_rate``."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from sim_core import load_scene
from sim_core.errors import SceneError
from sim_core.systems.telescopic import actuators

SCENE = (Path(__file__).resolve().parents[2] / "sim_core" / "scenes"
         / "telescopic_extraction.toml").read_text()
CSV = "time_s,stroke_m\n0,2.5\n1,2.6\n2,2.9\n3,3.0\n"
FAST = {"booms.n_nodes": 3, "solver.t_end": 3.0}


def scene_with(folder: Path, table_file: str, extra: str = "") -> Path:
    """A copy of the paper's crane in ``folder`` whose drive replays ``table_file``."""
    text = SCENE.replace('direction = "extraction"',
                         f'direction = "extraction"\nprofile = "table"\n'
                         f'table_file = {table_file!r}{extra}')
    text = text.replace("stroke0 = 2.0\n", "")
    path = folder / "scene.toml"
    folder.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def refused(path: Path, *parts: str, monkeypatch=None) -> str:
    with pytest.raises(SceneError) as err:
        load_scene(str(path), FAST)
    msg = str(err.value)
    assert "drive.table_file" in msg and "\n" not in msg, msg
    for p in parts:
        assert p in msg, msg
    return msg


@pytest.fixture(autouse=True)
def _no_data_dir(monkeypatch):
    monkeypatch.delenv(actuators.DATA_DIR_ENV, raising=False)


def test_a_table_file_beside_the_scene_loads(tmp_path):
    (tmp_path / "s" / "data").mkdir(parents=True)
    (tmp_path / "s" / "data" / "stroke.csv").write_text(CSV)
    sc = load_scene(str(scene_with(tmp_path / "s", "data/stroke.csv")), FAST)
    assert sc["booms"]["stroke0"] == 2.5


def test_an_absolute_path_outside_is_refused(tmp_path):
    (tmp_path / "outside.csv").write_text(CSV)
    refused(scene_with(tmp_path / "s", str(tmp_path / "outside.csv")), "no such file inside")


def test_dot_dot_out_of_the_folder_is_refused(tmp_path):
    (tmp_path / "outside.csv").write_text(CSV)
    refused(scene_with(tmp_path / "s", "../outside.csv"), "no such file inside")


def test_a_symbolic_link_out_of_the_folder_is_refused(tmp_path):
    (tmp_path / "outside.csv").write_text(CSV)
    (tmp_path / "s").mkdir()
    os.symlink(tmp_path / "outside.csv", tmp_path / "s" / "link.csv")
    refused(scene_with(tmp_path / "s", "link.csv"), "symbolic links followed")


def test_a_named_data_folder_is_allowed(tmp_path, monkeypatch):
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "stroke.csv").write_text(CSV)
    scene = scene_with(tmp_path / "s", "stroke.csv")
    refused(scene, "BOOM_SIM_DATA_DIR")
    monkeypatch.setenv(actuators.DATA_DIR_ENV, str(tmp_path / "data"))
    assert load_scene(str(scene), FAST)["booms"]["stroke0"] == 2.5
    # an absolute path inside the named folder too
    scene = scene_with(tmp_path / "s2", str(tmp_path / "data" / "stroke.csv"))
    assert load_scene(str(scene), FAST)["booms"]["stroke0"] == 2.5


def test_a_binary_file_is_a_scene_error(tmp_path):
    (tmp_path / "s").mkdir()
    (tmp_path / "s" / "bin.csv").write_bytes(Path("/bin/ls").read_bytes()[:4096])
    refused(scene_with(tmp_path / "s", "bin.csv"), "line 1", "UTF-8")


def test_a_nul_byte_is_a_scene_error(tmp_path):
    (tmp_path / "s").mkdir()
    (tmp_path / "s" / "nul.csv").write_bytes(b"t,s\n0,2.5\n1,\x002.6\n")
    refused(scene_with(tmp_path / "s", "nul.csv"), "line 3", "NUL")


def test_a_file_above_the_size_cap_is_refused_before_it_is_parsed(tmp_path):
    (tmp_path / "s").mkdir()
    big = "t,s\n" + "".join(f"{k * 1e-3:.6f},2.5\n" for k in range(120000))
    assert len(big) > actuators.TABLE_FILE_MAX_BYTES
    (tmp_path / "s" / "big.csv").write_text(big)
    refused(scene_with(tmp_path / "s", "big.csv"), "1048576 bytes", "20000 rows")


def test_more_rows_than_the_cap_are_refused(tmp_path):
    (tmp_path / "s").mkdir()
    rows = "".join(f"{k * 1e-3:g},2.5\n" for k in range(actuators.TABLE_FILE_MAX_ROWS + 1))
    assert len(rows) < actuators.TABLE_FILE_MAX_BYTES
    (tmp_path / "s" / "many.csv").write_text("t,s\n" + rows)
    refused(scene_with(tmp_path / "s", "many.csv"), "more than 20000 rows")


def test_a_bad_line_is_named_but_not_echoed(tmp_path):
    (tmp_path / "s").mkdir()
    secret = "root:x:0:0:SECRET-TOKEN"
    (tmp_path / "s" / "bad.csv").write_text(f"t,s\n0,2.5\n1,2.6\n{secret}\n")
    msg = refused(scene_with(tmp_path / "s", "bad.csv"), "line 4")
    assert "SECRET" not in msg and "root" not in msg
    # a file whose first line is not numeric either: the header is skipped, never shown
    (tmp_path / "s" / "hdr.csv").write_text(f"{secret}\n{secret}\n")
    msg = refused(scene_with(tmp_path / "s", "hdr.csv"), "line 2")
    assert "SECRET" not in msg


@pytest.mark.parametrize("row, column", [("1e308,2.6", "time"), ("1,1e308", "position"),
                                         ("1,-1e308", "position"), ("1,nan", "position"),
                                         ("inf,2.6", "time")])
def test_rows_are_range_checked_like_inline_rows(tmp_path, row, column):
    (tmp_path / "s").mkdir()
    (tmp_path / "s" / "big.csv").write_text(f"t,s\n0,2.5\n{row}\n3,3.0\n")
    msg = refused(scene_with(tmp_path / "s", "big.csv"), f"line 3 {column}")
    assert "allowed" in msg
    # the same value inline is refused by the same declaration
    t, s = row.split(",")
    text = scene_with(tmp_path / "i", "x").read_text().replace(
        "table_file = 'x'", f"table = [[0, 2.5], [{t}, {s}], [3, 3.0]]")
    (tmp_path / "i" / "scene.toml").write_text(text)
    with pytest.raises(SceneError, match=r"drive\.table\[1\]"):
        load_scene(str(tmp_path / "i" / "scene.toml"), FAST)


def _luffing_table(tmp_path, rows: str) -> Path:
    text = SCENE + f"\n[luffing_drive]\nprofile = \"table\"\ntable = {rows}\nmax_rate = 10.0\n"
    path = tmp_path / "luffing.toml"
    path.write_text(text)
    return path


def test_a_nan_rate_fails_max_rate(tmp_path):
    """Two rows inside their ranges 1e-300 s apart: the rate overflows and the interpolant's
    largest rate is NaN, which the max_rate check refuses (NaN > limit is False)."""
    with pytest.raises(SceneError, match=r"luffing_drive: .* rate of nan .*max_rate"):
        load_scene(str(_luffing_table(tmp_path, "[[0, 40.0], [1e-300, 41.0]]")), FAST)


def test_an_overflowing_slope_is_a_scene_error(tmp_path):
    """More rows with a step of 5e-324 s: the interpolant's slopes overflow (scipy refuses
    them with a ValueError), reported as the table's SceneError."""
    with pytest.raises(SceneError, match=r"luffing_drive\.table: .*not finite"):
        load_scene(str(_luffing_table(tmp_path, "[[0, 40.0], [5e-324, 41.0], [1, 42], [2, 43]]")),
                   FAST)
