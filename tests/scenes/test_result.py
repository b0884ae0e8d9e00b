"""Result files: save/load round trip and atomic writing."""

from __future__ import annotations

import json
import os
import stat

import numpy as np
import pytest

import sim_core
from sim_core import result as result_mod
from sim_core.result import Result, atomic_write_bytes

SCENE = {"name": "demo", "description": "a test", "source": "/x/demo.toml",
         "solver": {"t_end": 0.5, "method": "RK45", "rtol": 1e-6, "n_output": 3},
         "effects": {"gravity": True, "torsion": False, "filtering": False},
         "beams": [{"name": "rod", "breakpoints": [8.0, 12.0], "n_nodes": 5,
                    "section": {"E": 2.1e11, "rotary_bending": True}}],
         "boundary": [{"beam": 0, "end": "left", "kind": "sleeve", "position": None,
                       "direction": [1.0, 0.0, 0.0], "speed": -0.5}],
         "point_loads": [], "initial": {"static_equilibrium": False}}


def make(rng, error=None) -> Result:
    t = np.linspace(0.0, 0.5, 3)
    outputs = {"tip_position": rng.standard_normal((3, 3)),
               "energy_kinetic": rng.random(3),
               "state": rng.standard_normal((3, 7)),
               "reactions": np.zeros((3, 0)),
               "flags": np.array([1, 0, 1], dtype=np.int32)}
    stats = {"wall_time_s": 1.25, "n_steps": 12, "n_rhs": 80, "min_step_s": 1e-5,
             "max_step_s": 0.01, "method": "RK45", "n_dof": np.int64(31),
             "real_time_factor": np.float64(0.4)}
    return Result(t, outputs, stats, SCENE, error)


def files(folder):
    return sorted(p.name for p in folder.iterdir())


@pytest.mark.parametrize("error", [None, "simulation failed at t = 0.3 s: boom"])
def test_round_trip_keeps_arrays_stats_scene_and_error(tmp_path, rng, error):
    res = make(rng, error)
    path = res.save(tmp_path / "deep" / "folder" / "result.npz")       # parents are created
    back = Result.load(path)
    np.testing.assert_array_equal(back.t, res.t)
    assert set(back.keys()) == set(res.keys())
    for k in res.keys():
        np.testing.assert_array_equal(back[k], res[k])
        assert back[k].dtype == res[k].dtype and back[k].shape == res[k].shape
    # numpy scalars in the stats come back as plain numbers, not text
    assert back.stats == {**res.stats, "n_dof": 31, "real_time_factor": 0.4}
    assert isinstance(back.stats["n_dof"], int)
    assert back.scene == SCENE
    assert back.error == error
    assert files(path.parent) == ["result.npz"]                         # no temp file left


def test_saved_file_records_versions(tmp_path, rng):
    path = make(rng).save(tmp_path / "r.npz")
    with np.load(path, allow_pickle=False) as z:
        meta = json.loads(str(z["__meta__"]))
    assert meta["versions"]["sim_core"] == sim_core.__version__
    assert meta["versions"]["numpy"] == np.__version__


def test_result_access(rng):
    res = make(rng)
    assert "tip_position" in res and "nope" not in res
    with pytest.raises(KeyError, match="available"):
        res["nope"]


def test_save_overwrites_an_existing_file(tmp_path, rng):
    path = tmp_path / "result.npz"
    make(rng).save(path)
    new = make(rng, error="second")
    new.save(path)
    assert Result.load(path).error == "second"
    assert files(tmp_path) == ["result.npz"]


# -- atomicity --------------------------------------------------------------------------------

@pytest.mark.parametrize("where", ["replace", "fsync", "write"])
def test_failing_write_leaves_the_existing_file_untouched(tmp_path, rng, monkeypatch, where):
    path = tmp_path / "result.npz"
    make(rng).save(path)
    before = path.read_bytes()

    def boom(*a, **k):
        raise OSError(28, "No space left on device")

    if where == "replace":
        monkeypatch.setattr(result_mod.os, "replace", boom)
    elif where == "fsync":
        monkeypatch.setattr(result_mod.os, "fsync", boom)
    else:  # the data write itself fails half-way
        real_fdopen = os.fdopen

        class HalfFile:
            def __init__(self, f):
                self.f = f

            def __enter__(self):
                return self

            def __exit__(self, *exc):
                self.f.close()

            def write(self, data):
                self.f.write(data[: len(data) // 2])
                raise OSError(28, "No space left on device")

            def flush(self):
                self.f.flush()

            def fileno(self):
                return self.f.fileno()

        monkeypatch.setattr(result_mod.os, "fdopen", lambda fd, mode: HalfFile(real_fdopen(fd, mode)))

    with pytest.raises(OSError, match="No space left"):
        make(rng, error="new").save(path)
    assert path.read_bytes() == before
    assert Result.load(path).error is None
    assert files(tmp_path) == ["result.npz"]                           # temp file removed


def test_interrupted_write_removes_the_temp_file(tmp_path, monkeypatch):
    path = tmp_path / "summary.json"
    atomic_write_bytes(path, b"old")

    def interrupt(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(result_mod.os, "replace", interrupt)
    with pytest.raises(KeyboardInterrupt):
        atomic_write_bytes(path, b"new")
    assert path.read_bytes() == b"old"
    assert files(tmp_path) == ["summary.json"]


def test_failing_write_without_an_existing_file_leaves_nothing(tmp_path, monkeypatch):
    monkeypatch.setattr(result_mod.os, "replace", lambda *a: (_ for _ in ()).throw(OSError("x")))
    with pytest.raises(OSError):
        atomic_write_bytes(tmp_path / "a.bin", b"data")
    assert files(tmp_path) == []


def test_temp_file_is_in_the_target_folder_and_renamed(tmp_path, monkeypatch):
    """The data goes to a temporary file next to the target (same file system), which is then
    renamed over it: readers never see a partial file."""
    seen = []
    real_replace = os.replace

    def spy(src, dst):
        seen.append((os.path.dirname(src), os.path.basename(src), os.fspath(dst)))
        assert open(src, "rb").read() == b"payload"
        real_replace(src, dst)

    monkeypatch.setattr(result_mod.os, "replace", spy)
    atomic_write_bytes(tmp_path / "x.json", b"payload")
    (folder, name, dst), = seen
    assert folder == str(tmp_path) and name.startswith(".x.json.") and name.endswith(".tmp")
    assert dst == str(tmp_path / "x.json")
    assert (tmp_path / "x.json").read_bytes() == b"payload"


@pytest.mark.skipif(os.name != "posix", reason="POSIX permissions")
def test_written_files_get_normal_permissions(tmp_path):
    """mkstemp creates 0600 files; results must be readable like any other file."""
    umask = os.umask(0o022)
    try:
        atomic_write_bytes(tmp_path / "new.bin", b"1")
        assert stat.S_IMODE((tmp_path / "new.bin").stat().st_mode) == 0o644
        old = tmp_path / "old.bin"
        old.write_bytes(b"0")
        os.chmod(old, 0o640)
        atomic_write_bytes(old, b"1")                 # a replaced file keeps its mode
        assert stat.S_IMODE(old.stat().st_mode) == 0o640
    finally:
        os.umask(umask)
