"""The ``boom-sim`` command line, run as a user would (``python -m sim_core.cli`` in a
subprocess), plus in-process checks of the failed-solve path (exit status 3)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sim_core import cli
from sim_core.errors import SimulationError
from sim_core.result import Result

ROOT = Path(__file__).resolve().parents[2]
SCENE = "beam_through_sleeve"
# a short run: without the stress filter the explicit step is ~1e-5 s, so keep t_end tiny
SHORT_RUN = ["--set", "solver.t_end=0.002", "--set", "effects.filtering=false",
             "--set", "beams.0.n_nodes=5", "--set", "solver.n_output=5"]


def boom_sim(*args: str, cwd: Path | None = None, timeout: float = 120.0):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    env["MPLBACKEND"] = "Agg"
    return subprocess.run([sys.executable, "-m", "sim_core.cli", *args], capture_output=True,
                          text=True, env=env, cwd=cwd or ROOT, timeout=timeout)


def dof(stdout: str) -> int:
    m = re.search(r"DOF: (\d+)", stdout)
    assert m, stdout
    return int(m.group(1))


def assert_one_line_error(proc, status: int, *parts: str) -> str:
    assert proc.returncode == status, (proc.returncode, proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    for p in parts:
        assert p in lines[0], (p, lines[0])
    return lines[0]


# -- list / describe ------------------------------------------------------------------------

def test_list_prints_the_shipped_scene_with_its_description():
    proc = boom_sim("list")
    assert proc.returncode == 0, proc.stderr
    line = next(ln for ln in proc.stdout.splitlines() if ln.startswith(SCENE))
    assert "Steel rod pushed out of a rigid frictionless sleeve" in line


def test_describe_prints_effects_and_dof_count():
    proc = boom_sim("describe", SCENE)
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert "effects: gravity=on, torsion=on, filtering=on" in out
    assert "inertia" in out and "elasticity" in out and "filtering" in out and "gravity" in out
    assert dof(out) > 0
    # the resolved scene is printed as JSON after the summary lines
    resolved = json.loads(out[out.index("{"):])
    assert resolved["solver"]["t_end"] == 8.0 and resolved["beams"][0]["name"] == "rod"


def test_describe_without_torsion_has_fewer_dof():
    with_t = boom_sim("describe", SCENE)
    without = boom_sim("describe", SCENE, "--set", "effects.torsion=false")
    assert with_t.returncode == 0 and without.returncode == 0, without.stderr
    assert "torsion=off" in without.stdout
    assert dof(without.stdout) < dof(with_t.stdout)


def test_describe_applies_overrides_parsed_as_toml():
    proc = boom_sim("describe", SCENE, "--set", "effects.gravity=false", "--set",
                    "solver.t_end=0.5", "--set", "beams.0.n_nodes=5")
    assert proc.returncode == 0, proc.stderr
    assert "gravity=off" in proc.stdout
    resolved = json.loads(proc.stdout[proc.stdout.index("{"):])
    assert resolved["solver"]["t_end"] == 0.5 and resolved["effects"]["gravity"] is False
    assert resolved["beams"][0]["n_nodes"] == 5


# -- scene errors: status 2, one line, no traceback -----------------------------------------

@pytest.mark.parametrize("args, parts", [
    (["describe", SCENE, "--set", "solver.t_end=-1"], ["solver.t_end", "-1", "[1e-06, 3600] s"]),
    (["run", SCENE, "--set", "boundary.0.speed=-2", "--quiet"],
     ["boundary[0].speed", "-2", "allowed (-1, 0.5)"]),
])
def test_scene_error_exits_2_with_one_line(args, parts, tmp_path):
    if args[0] == "run":
        args = [*args, "--out", str(tmp_path / "out")]
    line = assert_one_line_error(boom_sim(*args), 2, *parts)
    assert line.startswith("boom-sim: scene error: ")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("args, parts", [
    (["describe", SCENE, "--set", "solver.tend=0.5"], ["solver.tend", "did you mean 't_end'?"]),
    (["describe", SCENE, "--set", "beams.3.n_nodes=5"], ["beams.3.n_nodes", "not a valid index"]),
    (["describe", SCENE, "--set", "solver.t_end"], ["--set", "KEY=VALUE"]),
    (["describe", SCENE, "--set", "gravity.g=[0, 0, nan]"], ["gravity.g[2]", "nan", "finite"]),
    (["describe", SCENE, "--set", "effects.gravity=flase"], ["effects.gravity", "'flase'",
                                                              "true or false"]),
    (["describe", "beam_thru_sleeve"], ["did you mean 'beam_through_sleeve'?"]),
    (["run", SCENE, "--set", "point_loads.0.s=13", "--quiet"], ["point_loads[0].s", "[0, 12]"]),
])
def test_scene_error_in_process(args, parts, tmp_path, capsys):
    """The same contract through cli.main (fast: no interpreter start-up per case)."""
    if args[0] == "run":
        args = [*args, "--out", str(tmp_path / "out")]
    assert cli.main(args) == 2
    cap = capsys.readouterr()
    lines = cap.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("boom-sim: scene error: "), cap.err
    for p in parts:
        assert p in lines[0], (p, lines[0])
    assert not (tmp_path / "out").exists()


def test_invalid_toml_file_exits_2_with_one_line(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[solver\nt_end = 1\n")
    assert_one_line_error(boom_sim("describe", str(p)), 2, str(p), "invalid TOML")


def test_plot_of_a_missing_file_exits_2(tmp_path):
    assert_one_line_error(boom_sim("plot", str(tmp_path / "nope.npz")), 2, "nope.npz")


# -- run and plot ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "out"
    proc = boom_sim("run", SCENE, *SHORT_RUN, "--out", str(out), "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    assert "0.002 s simulated" in proc.stdout
    return out


def test_run_writes_result_summary_and_figures(run_dir):
    files = {p.name for p in run_dir.iterdir()}
    assert {"result.npz", "summary.json", "tip.png", "energy.png"} <= files
    assert not [f for f in files if f.endswith(".tmp")]          # atomic writes left no temp file
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["scene"] == SCENE
    for key in ("wall_time_s", "n_steps", "n_rhs", "min_step_s", "max_step_s"):
        assert key in summary and summary[key] > 0, key
    assert summary["min_step_s"] <= summary["max_step_s"]
    assert summary["n_rhs"] >= summary["n_steps"]
    res = Result.load(run_dir / "result.npz")
    assert res.t[0] == 0.0 and res.t[-1] == pytest.approx(0.002)
    assert res["tip_position"].shape == (5, 3)
    assert np.all(np.isfinite(res["tip_position"]))
    assert res.scene["solver"]["t_end"] == 0.002 and res.scene["effects"]["filtering"] is False
    assert res.scene["beams"][0]["n_nodes"] == 5
    assert res.stats["n_steps"] == summary["n_steps"] and res.error is None
    for png in ("tip.png", "energy.png"):
        assert (run_dir / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_regenerates_figures(run_dir):
    for png in run_dir.glob("*.png"):
        png.unlink()
    proc = boom_sim("plot", str(run_dir / "result.npz"))
    assert proc.returncode == 0, proc.stderr
    assert "wrote 2 figures" in proc.stdout
    assert (run_dir / "tip.png").exists() and (run_dir / "energy.png").exists()


def test_plot_out_puts_figures_elsewhere(run_dir, tmp_path, capsys):
    assert cli.main(["plot", str(run_dir / "result.npz"), "--out", str(tmp_path / "figs")]) == 0
    assert "wrote 2 figures" in capsys.readouterr().out
    assert sorted(p.name for p in (tmp_path / "figs").iterdir()) == ["energy.png", "tip.png"]


# -- failed solve: status 3, one line, partial result kept -----------------------------------

def _fail(monkeypatch, partial: Result | None = None):
    # the command line calls sim_core.api.simulate through its own name
    simulate_mod = sys.modules["sim_core.cli"]

    def failing(scene, progress=None):
        exc = SimulationError(0.0125, "non-finite accelerations", step=1e-6,
                              last_state=np.zeros(4))
        if partial is not None:
            exc.result = partial
        raise exc

    monkeypatch.setattr(simulate_mod, "simulate", failing)


def test_failed_solve_exits_3_with_one_line_and_a_summary(monkeypatch, capsys, tmp_path):
    _fail(monkeypatch)
    out = tmp_path / "out"
    rc = cli.main(["run", SCENE, "--set", "solver.t_end=0.05", "--out", str(out), "--quiet"])
    assert rc == 3
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert "simulation failed at t = 0.0125 s: non-finite accelerations" in lines[0]
    assert "no partial result" in lines[0]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["error"].startswith("simulation failed at t = 0.0125 s")
    assert summary["t_fail_s"] == 0.0125 and summary["result_file"] is None
    assert not (out / "result.npz").exists()


def test_failed_solve_keeps_the_partial_result(monkeypatch, capsys, tmp_path):
    t = np.linspace(0.0, 0.01, 3)
    partial = Result(t, {"tip_position": np.ones((3, 3))}, {"n_steps": 7, "n_rhs": 50})
    _fail(monkeypatch, partial)
    out = tmp_path / "out"
    rc = cli.main(["run", SCENE, "--out", str(out), "--quiet"])
    assert rc == 3
    line = capsys.readouterr().err.strip()
    assert "\n" not in line and "partial result up to t = 0.01 s" in line
    res = Result.load(out / "result.npz")
    np.testing.assert_array_equal(res.t, t)
    np.testing.assert_array_equal(res["tip_position"], np.ones((3, 3)))
    assert res.error.startswith("simulation failed at t = 0.0125 s")
    assert res.scene["name"] == SCENE
    summary = json.loads((out / "summary.json").read_text())
    assert summary["result_file"] == "result.npz" and summary["n_steps"] == 7


def test_failed_solve_in_a_real_process_exits_3_without_traceback(tmp_path):
    """The same through the interpreter's exit status (the failure is injected)."""
    code = (
        "import sys, sim_core\n"
        "import sim_core.cli\n"
        "m = sys.modules['sim_core.cli']\n"
        "from sim_core.errors import SimulationError\n"
        "def f(scene, progress=None):\n"
        "    raise SimulationError(0.5, 'RK45 failed: step size too small', step=1e-12)\n"
        "m.simulate = f\n"
        "from sim_core.cli import main\n"
        f"sys.exit(main(['run', {SCENE!r}, '--out', {str(tmp_path)!r}, '--quiet']))\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          timeout=60)
    assert_one_line_error(proc, 3, "simulation failed at t = 0.5 s", "step size too small")


def test_run_without_matplotlib_keeps_results_and_skips_figures(monkeypatch, capsys, tmp_path):
    t = np.linspace(0.0, 0.05, 3)
    stats = {"wall_time_s": 0.1, "n_steps": 3, "n_rhs": 20, "min_step_s": 0.01,
             "max_step_s": 0.02, "real_time_factor": 0.5}
    monkeypatch.setattr(sys.modules["sim_core.cli"], "simulate",
                        lambda scene, progress=None: Result(t, {"tip_position": np.zeros((3, 3))},
                                                            dict(stats), scene))
    monkeypatch.setitem(sys.modules, "matplotlib", None)          # import matplotlib fails
    out = tmp_path / "out"
    assert cli.main(["run", SCENE, "--set", "solver.t_end=0.05", "--out", str(out), "--quiet"]) == 0
    cap = capsys.readouterr()
    assert "matplotlib is not installed, figures skipped" in cap.err
    # the report needs plotly, not matplotlib
    assert sorted(p.name for p in out.iterdir()) == ["report.html", "result.npz", "summary.json"]
    assert json.loads((out / "summary.json").read_text())["n_rhs"] == 20
    assert cli.main(["plot", str(out / "result.npz")]) == 2
    assert "matplotlib is not installed" in capsys.readouterr().err
