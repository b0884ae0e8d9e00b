"""``boom-sim sweep`` / :mod:`sim_core.sweep`: Ray-parallel scene-override sweeps.

The 12-case sweep runs the modal reduced-order scene ``telescopic_extraction_rl`` (~0.1 s per
case) through the command line in a subprocess, as a user would (a local Ray with 2 workers
is started and stopped by the sweep).  The other Ray tests share one local Ray (2 CPUs)
started by a module fixture, which run_sweep uses as it finds it.
"""

from __future__ import annotations

import csv
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sim_core import cli
from sim_core.errors import SceneError
from sim_core.result import Result
from sim_core.sweep import (
    SweepError,
    case_name,
    completed_case,
    grid_cases,
    parse_grid,
    rigid_tip_deviation,
    run_sweep,
    scalar_outcomes,
    split_values,
)

ROOT = Path(__file__).resolve().parents[2]
RL = "telescopic_extraction_rl"
GRID_12 = ["--grid", "payload.mass=20000,25000,30000",
           "--grid", "booms.luffing_angle_deg=45,50,55,60"]
# a short beam run (see test_cli.py): ~0.1 s of solving once the model is compiled
BEAM = "beam_through_sleeve"
BEAM_SHORT = {"solver.t_end": "0.002", "effects.filtering": "false", "beams.0.n_nodes": "5",
              "solver.n_output": "5"}


def boom_sim(*args: str, timeout: float = 240.0):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    env["MPLBACKEND"] = "Agg"
    return subprocess.run([sys.executable, "-m", "sim_core.cli", *args], capture_output=True,
                          text=True, env=env, cwd=ROOT, timeout=timeout)


def read_rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def case_dirs(out: Path) -> list[Path]:
    return sorted(p for p in out.iterdir() if p.is_dir())


@pytest.fixture(scope="module")
def local_ray():
    """A local Ray with 2 CPUs for the in-process sweeps (an already running one is kept)."""
    ray = pytest.importorskip("ray")
    import logging
    started = not ray.is_initialized()
    if started:
        ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False,
                 logging_level=logging.ERROR)
    yield ray
    if started:
        ray.shutdown()


# -- the 12-case sweep through the command line ------------------------------------------------

def test_twelve_case_sweep_then_rerun_skips_every_case(tmp_path):
    pytest.importorskip("ray")
    out = tmp_path / "sweep"
    first = boom_sim("sweep", RL, *GRID_12, "--out", str(out), "--workers", "2", "--quiet")
    assert first.returncode == 0, first.stderr
    assert "Traceback" not in first.stderr
    assert "12 cases" in first.stdout and "12 ok, 0 failed, 0 skipped" in first.stdout

    rows = read_rows(out / "summary.csv")
    assert len(rows) == 12 and {r["status"] for r in rows} == {"ok"}
    assert (out / "summary.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    dirs = case_dirs(out)
    assert len(dirs) == 12 and not [p for p in out.iterdir() if p.name.startswith(".")]
    assert {d.name for d in dirs} == {r["case"] for r in rows}
    for d in dirs:
        assert (d / "result.npz").is_file() and json.loads((d / "summary.json").read_text())[
            "status"] == "ok"
    # each folder holds the run of its own overrides
    res = Result.load(out / "payload.mass=30000__booms.luffing_angle_deg=45" / "result.npz")
    assert res.scene["payload"]["mass"] == 30000 and res.scene["booms"]["luffing_angle_deg"] == 45
    assert res.t[-1] == pytest.approx(20.0)

    # outcomes follow the physics: a steeper boom ends higher; a heavier payload bends the
    # boom further from its rigid-boom kinematics
    val = {(float(r["payload.mass"]), float(r["booms.luffing_angle_deg"])): r for r in rows}
    for m in (20000, 25000, 30000):
        z = [float(val[(m, a)]["final_tip_z_m"]) for a in (45, 50, 55, 60)]
        assert np.all(np.diff(z) > 0.5), z
    for a in (45, 50, 55, 60):
        dev = [float(val[(m, a)]["max_tip_deviation_from_rigid_m"]) for m in (20000, 25000, 30000)]
        assert dev[0] > 0 and np.all(np.diff(dev) > 0), dev

    mtimes = {d.name: (d / "result.npz").stat().st_mtime_ns for d in dirs}
    again = boom_sim("sweep", RL, *GRID_12, "--out", str(out), "--workers", "2", "--quiet")
    assert again.returncode == 0, again.stderr
    assert "0 ok, 0 failed, 12 skipped" in again.stdout
    rows2 = read_rows(out / "summary.csv")
    assert [r["status"] for r in rows2] == ["skipped"] * 12
    assert {d.name: (d / "result.npz").stat().st_mtime_ns for d in case_dirs(out)} == mtimes
    # the skipped rows carry the outcomes of the run that made the folders
    for r1, r2 in zip(rows, rows2):
        assert r2["case"] == r1["case"] and r2["final_tip_z_m"] == r1["final_tip_z_m"]


# -- fail fast on invalid cases and grids (nothing runs, no Ray) -------------------------------

def test_invalid_value_fails_fast_naming_the_field(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "ray", None)       # any Ray import would fail
    out = tmp_path / "out"
    with pytest.raises(SceneError) as err:
        run_sweep(RL, {"payload.mass": [25000, 30000], "booms.luffing_angle_deg": [60, 95]}, out)
    msg = str(err.value)
    assert "booms.luffing_angle_deg = 95" in msg and "[0, 85]" in msg
    assert "case payload.mass=25000__booms.luffing_angle_deg=95" in msg
    assert "and 1 more invalid case" in msg
    assert not out.exists()
    # the command line: status 2, one line naming the field
    assert cli.main(["sweep", RL, "--grid", "payload.mass=25000,-5", "--out", str(out)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("boom-sim: scene error: case payload.mass=-5")
    assert "payload.mass = -5" in lines[0] and "[0, 2e+06]" in lines[0]
    assert not out.exists()


def test_misspelt_grid_key_gets_a_suggestion(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(SceneError, match=r"payload\.mas: unknown key .*did you mean 'mass'"):
        run_sweep(RL, {"payload.mas": [1000]}, tmp_path / "out")


@pytest.mark.parametrize("items, parts", [
    (["payload.mass"], ["--grid 'payload.mass'", "KEY=V1,V2"]),
    (["=1,2"], ["empty key"]),
    (["payload.mass="], ["--grid payload.mass=", "value 1 of 1 is empty"]),
    (["payload.mass=1,,2"], ["value 2 of 3 is empty"]),
    (["payload.mass=1", "payload.mass=2"], ["--grid payload.mass", "given twice"]),
    (["payload.mass=1,2,1"], ["--grid payload.mass", "value '1' given twice"]),
])
def test_grid_syntax_errors_name_the_key(items, parts):
    with pytest.raises(SceneError) as err:
        parse_grid(items)
    for p in parts:
        assert p in str(err.value), (p, str(err.value))


def test_grid_values_keep_toml_arrays_and_quoted_strings_whole():
    assert split_values('[0, 0, -1],[1, 0, 0], 2') == ["[0, 0, -1]", "[1, 0, 0]", "2"]
    assert split_values('"a,b",c') == ['"a,b"', "c"]
    grid = parse_grid(["gravity.g=[0, 0, -9.81],[0, 0, -1.62]", "solver.t_end=1,2,3"])
    cases = grid_cases(grid)
    assert len(cases) == 6
    assert cases[0] == {"gravity.g": "[0, 0, -9.81]", "solver.t_end": "1"}
    assert cases[1]["solver.t_end"] == "2" and cases[3]["gravity.g"] == "[0, 0, -1.62]"


def test_same_key_in_grid_and_set_is_an_error(tmp_path, capsys):
    assert cli.main(["sweep", RL, "--grid", "payload.mass=20000", "--set", "payload.mass=1",
                     "--out", str(tmp_path / "o")]) == 2
    assert "either swept or fixed" in capsys.readouterr().err


def test_bad_worker_count_and_output_file_are_rejected(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(SweepError, match=r"workers = 0: must be an integer >= 1"):
        run_sweep(RL, {"payload.mass": [25000]}, tmp_path / "o", workers=0)
    f = tmp_path / "file"
    f.write_text("x")
    with pytest.raises(SweepError, match="is a file, not a folder"):
        run_sweep(RL, {"payload.mass": [25000]}, f)


def test_case_names_are_file_system_safe_distinct_and_stable():
    a = case_name({"gravity.g": "[0, 0, -1]", "name": "a/b"})
    b = case_name({"gravity.g": "[0, 0, -1]", "name": "a_b"})
    assert a != b
    for n in (a, b):
        assert not set(n) - set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._=+-")
    assert a == case_name({"gravity.g": "[0, 0, -1]", "name": "a/b"})
    assert case_name({"payload.mass": 25000}) == "payload.mass=25000"
    long = case_name({f"k{i}": "x" * 30 for i in range(10)})
    assert len(long) <= 129


# -- outcomes --------------------------------------------------------------------------------

def test_telescopic_outcomes_peaks_final_tip_and_rigid_deviation():
    t = np.linspace(0.0, 1.0, 5)
    s = np.array([0.0, 0.1, 0.2, 0.3, 0.4])                     # piston stroke, m
    e = np.array([math.cos(math.radians(60.0)), 0.0, math.sin(math.radians(60.0))])
    dev = np.array([0.0, 0.01, -0.03, 0.02, 0.0])               # off the rigid path, m
    normal = np.array([-e[2], 0.0, e[0]])
    tip = np.array([1.0, 0.0, 2.0]) + 2 * s[:, None] * e + dev[:, None] * normal
    res = Result(t, {"tip_position": tip, "piston_stroke": s,
                     "telescopic_cylinder_force": np.array([1.0, -5e5, 3e5, 2.0, 0.0]),
                     "luffing_cylinder_force": np.array([2e6, 2.5e6, -3e6, 1e6, 1e6]),
                     "constraint_violation": np.array([0.0, 1e-9, 3e-9, 2e-9, 0.0])})
    scene = {"kind": "telescopic", "booms": {"count": 3, "luffing_angle_deg": 60.0}}
    out = scalar_outcomes(res, scene)
    assert out["peak_abs_telescopic_cylinder_force_N"] == 5e5
    assert out["peak_abs_luffing_cylinder_force_N"] == 3e6
    assert out["max_constraint_violation"] == 3e-9
    assert out["final_tip_x_m"] == pytest.approx(tip[-1, 0])
    assert out["final_tip_z_m"] == pytest.approx(tip[-1, 2])
    assert out["max_tip_deviation_from_rigid_m"] == pytest.approx(0.03)
    # two booms: boom 2 moves with the stroke (no ropes), so the same motion is off by s
    two = rigid_tip_deviation(res, {"booms": {"count": 2, "luffing_angle_deg": 60.0}})
    assert two == pytest.approx(np.max(np.hypot(s, dev)))


def test_generic_outcomes_are_peak_abs_of_each_output_without_the_state():
    res = Result(np.array([0.0, 1.0]), {"tip_position": np.array([[1.0, -4.0, 0.0], [2.0, 0.0, 3.0]]),
                                        "energy_kinetic": np.array([0.0, 7.5]),
                                        "state": np.array([[100.0], [200.0]])})
    assert scalar_outcomes(res, {"name": "x"}) == {"max_abs_tip_position": 4.0,
                                                   "max_abs_energy_kinetic": 7.5}


# -- failures at run time, interruption, resuming (in-process, shared local Ray) ------------------

def test_run_time_failure_is_recorded_and_the_others_finish(tmp_path, local_ray):
    out = tmp_path / "beam"
    grid = {"solver.max_wall_s": ["1e-9", "60"]}              # 1 ns: stops in the statics
    rows = run_sweep(BEAM, grid, out, fixed=BEAM_SHORT, workers=2, quiet=True)
    by = {r["solver.max_wall_s"]: r for r in rows}
    bad, good = by["1e-9"], by["60"]
    assert bad["status"] == "failed" and bad["error_type"] == "WallBudgetExhausted"
    assert "solver.max_wall_s" in bad["error"]
    assert good["status"] == "ok" and good["error_type"] is None and good["n_steps"] > 1
    # the rod's tip starts 4 m out of the sleeve at the origin and moves 1 mm in 2 ms
    assert good["max_abs_tip_position"] == pytest.approx(4.0, abs=5e-3)
    assert good["max_abs_element_ends"] == pytest.approx(12.0)
    table = {r["case"]: r for r in read_rows(out / "summary.csv")}
    assert table[bad["case"]]["status"] == "failed"
    assert table[bad["case"]]["error_type"] == "WallBudgetExhausted"
    assert table[good["case"]]["status"] == "ok"
    assert (out / "summary.png").is_file()
    # the failed case keeps its summary and partial result, marked failed
    summary = json.loads((out / bad["case"] / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["error_type"] == "WallBudgetExhausted"
    assert Result.load(out / bad["case"] / "result.npz").error is not None
    # resuming skips the finished case and runs the failed one again
    ran = []
    rows = run_sweep(BEAM, grid, out, fixed=BEAM_SHORT, workers=2, quiet=True,
                     on_case=lambda row, rec: ran.append((row["case"], rec is not None)))
    assert {r["case"]: r["status"] for r in rows} == {bad["case"]: "failed",
                                                      good["case"]: "skipped"}
    assert sorted(ran) == sorted([(bad["case"], True), (good["case"], False)])


def test_changed_fixed_override_reruns_the_case(tmp_path, local_ray):
    out = tmp_path / "rl"
    grid = {"payload.mass": ["25000"]}
    first = run_sweep(RL, grid, out, fixed={"solver.t_end": "2"}, quiet=True)
    assert first[0]["status"] == "ok"
    again = run_sweep(RL, grid, out, fixed={"solver.t_end": "3"}, quiet=True)
    assert again[0]["status"] == "ok"                         # another scene: not skipped
    assert Result.load(out / "payload.mass=25000" / "result.npz").t[-1] == pytest.approx(3.0)


def test_interrupt_keeps_finished_cases_and_writes_the_summary(tmp_path, local_ray):
    out = tmp_path / "rl"
    grid = {"booms.luffing_angle_deg": ["45", "50", "55", "60", "65", "70"]}
    fixed = {"solver.t_end": "2"}
    finished = []

    def stop(row, rec):
        finished.append(row["case"])
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(RL, grid, out, fixed=fixed, workers=1, quiet=True, on_case=stop)
    rows = read_rows(out / "summary.csv")
    assert len(rows) == 6 and len(finished) == 1
    status = {r["case"]: r["status"] for r in rows}
    assert status.pop(finished[0]) == "ok"
    assert set(status.values()) == {"interrupted"}
    assert [d.name for d in case_dirs(out)] == finished
    assert not [p for p in out.iterdir() if p.name.startswith(".")]
    assert completed_case(out / finished[0], json.loads(
        (out / finished[0] / "summary.json").read_text())["scene_sha256"]) is not None
    rows = run_sweep(RL, grid, out, fixed=fixed, workers=2, quiet=True)
    assert sorted(r["status"] for r in rows) == ["ok"] * 5 + ["skipped"]


def test_parquet_summary_matches_the_csv(tmp_path, local_ray):
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "rl"
    run_sweep(RL, {"payload.mass": ["20000", "30000"]}, out, fixed={"solver.t_end": "2"},
              quiet=True)
    table = pq.read_table(out / "summary.parquet").to_pylist()
    rows = read_rows(out / "summary.csv")
    assert [r["case"] for r in table] == [r["case"] for r in rows]
    assert [r["final_tip_z_m"] for r in table] == [float(r["final_tip_z_m"]) for r in rows]
