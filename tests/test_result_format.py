"""The result file format (``result.npz``): it carries a format version, ``Result.load`` reads
the current one and the unversioned files written before (format 0), and everything it cannot
read (a newer or unknown format, a truncated or corrupted file, a file that is not ours) gives
a one-line :class:`ResultFormatError` naming the file and the problem, as does ``boom-sim plot``
(exit status 2)."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import sim_core
from sim_core import Result, ResultFormatError, load_scene, simulate
from sim_core.result import OLDEST_RESULT_FORMAT, RESULT_FORMAT

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def result() -> Result:
    """A small real result: the modal telescopic scene, 0.5 s (a fraction of a second)."""
    return simulate(load_scene("telescopic_extraction_rl", overrides={"solver.t_end": 0.5}))


@pytest.fixture
def saved(result, tmp_path) -> Path:
    return result.save(tmp_path / "run" / "result.npz")


def members(path: Path) -> dict[str, bytes]:
    """The raw .npy members of an .npz, name (with .npy) -> bytes."""
    with zipfile.ZipFile(path) as zf:
        return {n: zf.read(n) for n in zf.namelist()}


def npy(value) -> bytes:
    buf = io.BytesIO()
    np.save(buf, value, allow_pickle=False)
    return buf.getvalue()


def write_zip(path: Path, entries: dict[str, bytes]) -> Path:
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name, data in entries.items():
            zf.writestr(name, data)
    return path


def with_version(saved: Path, version) -> Path:
    """A copy of a saved file with its format version member replaced."""
    entries = members(saved)
    entries["__format__.npy"] = npy(np.array(version, dtype=np.int64))
    return write_zip(saved.with_name("versioned.npz"), entries)


def load_error(path: Path) -> str:
    """Load ``path``, expect a ResultFormatError, check it is one line naming the file."""
    with pytest.raises(ResultFormatError) as info:
        Result.load(path)
    msg = str(info.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}: "), msg
    assert info.value.path == str(path)
    return msg


def assert_same(back: Result, res: Result) -> None:
    np.testing.assert_array_equal(back.t, res.t)
    assert set(back.keys()) == set(res.keys())
    for k in res.keys():
        np.testing.assert_array_equal(back[k], res[k])
        assert back[k].dtype == res[k].dtype and back[k].shape == res[k].shape
    assert back.error == res.error
    assert back.scene == json.loads(json.dumps(res.scene, default=sim_core.result.json_default))
    assert back.stats == json.loads(json.dumps(res.stats, default=sim_core.result.json_default))


# -- what is read -----------------------------------------------------------------------------

def test_round_trip_keeps_everything_and_writes_the_current_format(result, saved):
    """save/load keeps t, every output (values, dtype, shape), the stats, the scene and the
    error, and the file carries the current format version as an integer member."""
    assert len(result.t) > 2 and len(result.outputs) > 1
    assert_same(Result.load(saved), result)
    with np.load(saved, allow_pickle=False) as z:
        assert z["__format__"].shape == () and int(z["__format__"]) == RESULT_FORMAT == 1
    assert sorted(p.name for p in saved.parent.iterdir()) == ["result.npz"]   # atomic: no temp


def test_unversioned_file_from_before_the_format_version_is_read_as_format_0(result, saved):
    """A file as ``Result.save`` wrote it before versioning (no ``__format__`` member, the
    same arrays and metadata otherwise) still loads, unchanged: format 0 is readable."""
    assert OLDEST_RESULT_FORMAT == 0
    entries = members(saved)
    del entries["__format__.npy"]
    old = write_zip(saved.with_name("old.npz"), entries)
    assert_same(Result.load(old), result)


# -- what is refused --------------------------------------------------------------------------

def test_newer_format_is_refused_with_upgrade_hint(saved):
    """A file written by a newer result format names that format, the one this version reads
    and says to upgrade the package."""
    path = with_version(saved, RESULT_FORMAT + 2)
    msg = load_error(path)
    assert (f"written by result format {RESULT_FORMAT + 2}, this version of telescopic-boom-sim "
            f"reads format {RESULT_FORMAT} (upgrade the package)") in msg


def test_unknown_older_format_number_is_refused(saved):
    """No real format is older than 0 (every older file reads as format 0): a version below
    that (-1) is reported as an unknown format, with the range this version reads."""
    msg = load_error(with_version(saved, -1))
    assert "unknown result format -1" in msg and f"reads formats 0 to {RESULT_FORMAT}" in msg


def test_version_that_is_not_an_integer_is_refused(saved):
    """A format member that is not an integer scalar is a corrupted file."""
    entries = members(saved)
    entries["__format__.npy"] = npy(np.array("one"))
    msg = load_error(write_zip(saved.with_name("x.npz"), entries))
    assert "format version is not an integer" in msg


def test_truncated_file_is_refused(saved):
    """A real result cut in half (an interrupted copy) is reported as truncated or corrupted."""
    data = saved.read_bytes()
    cut = saved.with_name("cut.npz")
    cut.write_bytes(data[: len(data) // 2])
    assert "truncated or corrupted" in load_error(cut)


def test_random_bytes_and_empty_file_are_not_result_files(tmp_path):
    """Random bytes and an empty file are reported as not a result file."""
    noise = tmp_path / "noise.npz"
    noise.write_bytes(np.random.default_rng(1).bytes(4096))
    assert "not a result file" in load_error(noise)
    empty = tmp_path / "empty.npz"
    empty.write_bytes(b"")
    assert "empty file" in load_error(empty)


def test_zip_that_is_not_one_of_ours_is_refused(tmp_path):
    """A valid .npz with neither a format version nor our metadata is not a result file."""
    path = tmp_path / "other.npz"
    np.savez(path, x=np.arange(3), y=np.ones(2))
    msg = load_error(path)
    assert "not a telescopic-boom-sim result file" in msg and "x, y" in msg


def test_missing_time_array_is_refused(saved):
    """A versioned file without its time array ``t`` names the missing array."""
    entries = members(saved)
    del entries["t.npy"]
    msg = load_error(write_zip(saved.with_name("no_t.npz"), entries))
    assert "missing array 't'" in msg


def test_corrupted_metadata_member_is_refused(saved):
    """Damaged bytes inside the compressed ``__meta__`` member (bad CRC / bad deflate data)
    name that member."""
    data = bytearray(saved.read_bytes())
    with zipfile.ZipFile(saved) as zf:
        info = zf.getinfo("__meta__.npy")
    start = info.header_offset + 30 + len(info.filename.encode()) + len(info.extra)
    for i in range(start + 10, start + min(info.compress_size, 60)):
        data[i] ^= 0xFF
    bad = saved.with_name("bad_meta.npz")
    bad.write_bytes(bytes(data))
    msg = load_error(bad)
    assert "truncated or corrupted" in msg and "'__meta__'" in msg


def test_unreadable_json_metadata_is_refused(saved):
    """An intact ``__meta__`` member whose text is not JSON is reported as unreadable JSON
    metadata; JSON that is not an object, or with a stats entry of the wrong kind, as
    corrupted metadata."""
    entries = members(saved)
    entries["__meta__.npy"] = npy(np.array('{"stats": {"n_steps": 3'))
    assert "unreadable JSON metadata" in load_error(write_zip(saved.with_name("a.npz"), entries))
    entries["__meta__.npy"] = npy(np.array("[1, 2]"))
    assert "corrupted metadata" in load_error(write_zip(saved.with_name("b.npz"), entries))
    entries["__meta__.npy"] = npy(np.array('{"stats": [1]}'))
    assert "'stats'" in load_error(write_zip(saved.with_name("c.npz"), entries))


def test_random_damage_never_leaks_a_low_level_error(saved):
    """Flipping random bytes or cutting a real file anywhere gives a ResultFormatError (or, where
    the damage hit bytes nothing checks, a loaded result): never a numpy/zipfile/json error."""
    data = saved.read_bytes()
    rng = np.random.default_rng(7)
    path = saved.with_name("fuzz.npz")
    for i in range(300):
        b = bytearray(data)
        if i % 3 == 0:
            b = b[: rng.integers(0, len(b))]
        else:
            for _ in range(rng.integers(1, 4)):
                b[rng.integers(0, len(b))] = rng.integers(0, 256)
        path.write_bytes(bytes(b))
        try:
            Result.load(path)
        except ResultFormatError as exc:
            assert "\n" not in str(exc)


def test_missing_file_stays_an_os_error(tmp_path):
    """A file that is not there is an OSError (FileNotFoundError) naming it, as before."""
    with pytest.raises(FileNotFoundError, match="nope.npz"):
        Result.load(tmp_path / "nope.npz")


def test_result_format_error_is_a_value_error_exported_by_the_package():
    """ResultFormatError is a ValueError (so ``boom-sim plot`` and callers catching ValueError
    catch it) and is exported from ``sim_core``."""
    assert issubclass(ResultFormatError, ValueError)
    assert "ResultFormatError" in sim_core.__all__


# -- the command line -------------------------------------------------------------------------

def test_plot_of_a_corrupted_file_exits_2_with_one_line(saved):
    """``boom-sim plot`` on a truncated result exits 2 with one line naming the file and the
    problem, no traceback."""
    data = saved.read_bytes()
    cut = saved.with_name("cut.npz")
    cut.write_bytes(data[: len(data) // 2])
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    env["MPLBACKEND"] = "Agg"
    proc = subprocess.run([sys.executable, "-m", "sim_core.cli", "plot", str(cut)],
                          capture_output=True, text=True, env=env, cwd=ROOT, timeout=120)
    assert proc.returncode == 2, (proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert str(cut) in lines[0] and "truncated or corrupted" in lines[0]
    assert not list(cut.parent.glob("*.png"))
