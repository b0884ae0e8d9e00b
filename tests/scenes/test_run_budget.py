"""``boom-sim run``'s wall budget over the whole run, Ctrl-C, the output folder's lock and
``--out`` naming a file (sim_core.run_control, sim_core.cli).

The budget tests run the command in-process and time ``cli.main`` (the budget counts from the
start of ``run``'s work); the stated margin is ``solver.max_wall_s + 5 s``
(docs/user_guide.md, "Budgets and interruption").  The Ctrl-C tests run it as a user does, in
a subprocess, and send SIGINT once the run holds its output folder's lock.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sim_core import cli, run_control
from sim_core.errors import RunInterrupted, WallBudgetExhausted
from sim_core.result import Result

ROOT = Path(__file__).resolve().parents[2]
MARGIN_S = 5.0            # the documented overrun of solver.max_wall_s
# the paper crane's statics from a 1 cm stroke: ~80 s of load continuation (the reproducer)
SLOW_STATICS = ["telescopic_extraction", "--set", "booms.stroke0=0.01"]
# the sleeve scene, unfiltered: steps of ~1e-5 s, so t_end = 0.2 s integrates for minutes
LONG_INTEGRATION = ["beam_through_sleeve", "--set", "effects.filtering=false",
                    "--set", "beams.0.n_nodes=5", "--set", "solver.t_end=0.2",
                    "--set", "solver.n_output=21"]


def _timed_run(capsys, args: list[str], out: Path) -> tuple[int, float, str]:
    t0 = time.perf_counter()
    rc = cli.main(["run", *args, "--out", str(out), "--quiet", "--no-report"])
    wall = time.perf_counter() - t0
    return rc, wall, capsys.readouterr().err


def _warm_up(capsys, args: list[str], out: Path) -> None:
    """A 1 ms run of the scene first: its compiled code loaded, so that the first step's wall
    time in the measured run is no stall to StallMonitor's pace test (which extrapolates
    from the steps taken)."""
    rc, _, err = _timed_run(capsys, [*args, "--set", "solver.t_end=0.001", "--set",
                                     "solver.n_output=2", "--no-plots"], out)
    assert rc == 0, err


def _error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_budget_stops_the_statics(capsys, tmp_path):
    """The reproducer: the static equilibrium that took 83 s stops at the budget with the
    typed error naming the budget and the phase; the run ends within the margin (exit 3),
    with summary.json and a result.npz without output times saying why."""
    budget = 3.0
    rc, wall, err = _timed_run(capsys, [*SLOW_STATICS, "--set", f"solver.max_wall_s={budget:g}"],
                               tmp_path)
    line = _error_line(err)
    assert rc == 3, err
    assert "max_wall_s = 3 s" in line and "statics" in line
    assert wall <= budget + MARGIN_S
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert "statics" in summary["error"] and summary["result_file"] == "result.npz"
    res = Result.load(tmp_path / "result.npz")
    assert len(res.t) == 0 and "max_wall_s" in res.error


def test_budget_stops_the_output_collection(capsys, tmp_path):
    """The per-output loop counts against the budget: 5000 output times of 0.01 s of the
    sleeve scene (8 steps, under 1 s with its statics; ~10 ms an output: ~50 s) stop at the
    budget; the outputs collected so far are the partial result."""
    budget = 5.0
    args = ["beam_through_sleeve", "--set", "solver.t_end=0.01"]
    _warm_up(capsys, args, tmp_path / "warm")
    args += ["--set", "solver.n_output=5000", "--set", f"solver.max_wall_s={budget:g}"]
    rc, wall, err = _timed_run(capsys, args, tmp_path / "run")
    tmp_path = tmp_path / "run"
    line = _error_line(err)
    assert rc == 3 and "max_wall_s = 5 s" in line and "outputs" in line, err
    assert wall <= budget + MARGIN_S
    res = Result.load(tmp_path / "result.npz")
    assert 1 <= len(res.t) < 5000 and "outputs" in res.error
    assert len(res["tip_position"]) == len(res.t) == len(res["state"])


def test_budget_bounds_the_partial_outputs_of_a_stopped_integration(capsys, tmp_path):
    """The crane reproducer's path: the integration stops at the budget (or its pace test
    stops it earlier), and the outputs up to the time reached -- here hundreds to thousands of
    output times at several ms each -- would outlast it; they are cut once the budget is
    spent and the collection has had run_control.PARTIAL_GRACE_S = 2 s, and the run still
    ends within the margin."""
    budget = 4.0
    _warm_up(capsys, LONG_INTEGRATION, tmp_path / "warm")
    args = [*LONG_INTEGRATION[:-2], "--set", "solver.n_output=200001",
            "--set", f"solver.max_wall_s={budget:g}"]
    tmp_path = tmp_path / "run"
    rc, wall, err = _timed_run(capsys, args, tmp_path)
    line = _error_line(err)
    assert rc == 3 and "max_wall_s = 4 s" in line, err
    assert wall <= budget + MARGIN_S
    res = Result.load(tmp_path / "result.npz")
    assert len(res.t) >= 1 and res.t[-1] < res.stats["outputs_cut_at_s"] <= float(
        json.loads((tmp_path / "summary.json").read_text())["t_fail_s"])


def test_budget_covers_the_figures(capsys, tmp_path, monkeypatch):
    """A budget spent while the figures are drawn ends the run (exit 3) at the next figure:
    the whole result is kept, marked with the error.  (The drawing here spends the budget by
    construction: it credits the run's budget with more than it holds.)"""
    import sim_core.figures as figures
    original = figures.plot_result

    def budget_spending_plot(result, out):
        run_control.current().credit(1e6)
        return original(result, out)

    monkeypatch.setattr("sim_core.systems.beam.kind.plot_result", budget_spending_plot)
    args = ["beam_through_sleeve", "--set", "solver.t_end=0.002", "--set",
            "effects.filtering=false", "--set", "beams.0.n_nodes=5",
            "--set", "solver.n_output=5", "--set", "initial.static_equilibrium=false",
            "--set", "solver.max_wall_s=1000"]
    rc, wall, err = _timed_run(capsys, args, tmp_path)
    line = _error_line(err)
    assert rc == 3 and "max_wall_s = 1000 s" in line and "figures" in line, err
    res = Result.load(tmp_path / "result.npz")
    assert len(res.t) == 5 and "figures" in res.error
    assert not list(tmp_path.glob("*.png"))


def test_budget_object_interrupt_and_deadline():
    """RunBudget: the interrupt flag wins over the budget; a resumed run's credit counts."""
    b = run_control.RunBudget(100.0)
    assert b.exceeded("statics") is None
    b.credit(150.0)
    exc = b.exceeded("integration", 1.5)
    assert isinstance(exc, WallBudgetExhausted) and exc.phase == "integration" and exc.t == 1.5
    b.interrupt()
    assert isinstance(b.exceeded("outputs"), RunInterrupted)
    with pytest.raises(RunInterrupted, match="Ctrl-C"):
        b.check("statics")


# -- Ctrl-C ------------------------------------------------------------------------------------

def _start(args: list[str], out: Path) -> subprocess.Popen:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    env["MPLBACKEND"] = "Agg"
    return subprocess.Popen([sys.executable, "-m", "sim_core.cli", "run", *args, "--out",
                             str(out), "--quiet", "--no-report", "--no-plots"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            cwd=ROOT)


def _wait_for_lock(proc: subprocess.Popen, out: Path, timeout: float = 120.0) -> None:
    """Until the run holds OUT's lock (its SIGINT handler is installed by then)."""
    lock = out / run_control.LOCK_FILE
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < timeout:
        assert proc.poll() is None, proc.communicate()
        if lock.is_file() and lock.read_text().strip() == str(proc.pid):
            return
        time.sleep(0.05)
    raise AssertionError("the run did not take its output folder's lock")


def _interrupt(args: list[str], out: Path, delay: float) -> tuple[str, Result]:
    proc = _start(args, out)
    try:
        _wait_for_lock(proc, out)
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 3, (proc.returncode, err)
    assert "Traceback" not in err and "SystemError" not in err, err
    line = _error_line(err)
    assert "interrupted by the user (Ctrl-C)" in line
    res = Result.load(out / "result.npz")
    assert "interrupted" in res.error
    return line, res


CTRL_C = [
    pytest.param(SLOW_STATICS, 0.5, "statics", id="statics-early"),
    pytest.param(SLOW_STATICS, 3.0, "statics", id="statics-late", marks=pytest.mark.slow),
    pytest.param(LONG_INTEGRATION, 4.0, "integration", id="integration-rk45"),
    pytest.param(["cantilever_release", "--set", "solver.t_end=200",
                  "--set", "solver.n_output=2001"], 4.0, "integration",
                 id="integration-compiled-alpha", marks=pytest.mark.slow),
]


@pytest.mark.parametrize("args, delay, phase", CTRL_C)
def test_ctrl_c_ends_with_status_3_and_a_partial_result(tmp_path, args, delay, phase):
    """SIGINT only sets the run's interrupt flag; the phase in progress stops at its next
    check: exit 3, one line, result.npz and summary.json, no traceback (the interrupt landing
    in compiled code raised SystemError before).  The phase is the one expected for the delay
    (the statics of the slow scene last ~80 s; the other scenes' statics well under 1 s)."""
    line, res = _interrupt(args, tmp_path, delay)
    assert phase in line
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert "interrupted" in summary["error"]
    if phase == "integration":
        assert len(res.t) >= 1 and res.t[-1] <= float(summary["t_fail_s"]) + 1e-12


# -- the output folder's lock and --out --------------------------------------------------------

def _no_simulation(monkeypatch):
    def refuse(*a, **k):
        raise AssertionError("the simulation ran")
    monkeypatch.setattr(cli, "simulate", refuse)


def test_second_writer_into_the_same_out_is_refused(tmp_path, capsys, monkeypatch):
    """While a run (here: the lock held as a run holds it) writes into OUT, a second ``run``
    and a ``sweep`` into OUT are refused at once: exit 2, one line naming --out."""
    _no_simulation(monkeypatch)
    with run_control.folder_lock(tmp_path):
        t0 = time.perf_counter()
        rc = cli.main(["run", "beam_through_sleeve", "--out", str(tmp_path), "--quiet"])
        line = _error_line(capsys.readouterr().err)
        assert rc == 2 and "--out" in line and "in use by another boom-sim" in line
        assert f"process {os.getpid()}" in line
        rc = cli.main(["sweep", "beam_through_sleeve", "--grid", "solver.t_end=0.001,0.002",
                       "--out", str(tmp_path), "--quiet"])
        line = _error_line(capsys.readouterr().err)
        assert rc == 2 and "in use by another boom-sim" in line
        assert time.perf_counter() - t0 < 10.0
    assert not (tmp_path / "summary.json").exists()


@pytest.mark.slow
def test_two_real_runs_into_one_out(tmp_path):
    """Two ``boom-sim run`` processes: the second exits 2 at once, the first runs on and ends
    normally (here by Ctrl-C) with its own files and its checkpoint policy intact."""
    first = _start(SLOW_STATICS, tmp_path)
    try:
        _wait_for_lock(first, tmp_path)
        env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
        second = subprocess.run([sys.executable, "-m", "sim_core.cli", "run",
                                 "beam_through_sleeve", "--out", str(tmp_path), "--quiet"],
                                capture_output=True, text=True, env=env, cwd=ROOT, timeout=120)
        assert second.returncode == 2, second.stderr
        assert "in use by another boom-sim" in _error_line(second.stderr)
        assert first.poll() is None
        first.send_signal(signal.SIGINT)
        _, err = first.communicate(timeout=60)
    finally:
        if first.poll() is None:
            first.kill()
    assert first.returncode == 3 and "statics" in err


@pytest.mark.parametrize("argv, option", [
    (["run", "beam_through_sleeve", "--out", "{file}", "--quiet"], "--out"),
    (["run", "beam_through_sleeve", "--out", "{file}/sub", "--quiet"], "--out"),
    (["sweep", "beam_through_sleeve", "--grid", "solver.t_end=0.001", "--out", "{file}",
      "--quiet"], "--out"),
    (["plot", "{result}", "--out", "{file}"], "--out"),
    (["export", "{result}", "--vtk", "{file}"], "--vtk"),
    (["report", "{result}", "--out", "{folder}"], "--out"),
    (["animate", "{result}", "--out", "{folder}"], "--out"),
])
def test_out_naming_the_wrong_kind_of_path_is_refused_first(tmp_path, capsys, monkeypatch,
                                                            argv, option):
    """``--out`` naming an existing file (a folder for report/animate) is refused before
    anything runs: exit 2, one line naming the option (the run used to simulate first, then
    crash with a traceback)."""
    _no_simulation(monkeypatch)
    (tmp_path / "a_file").write_text("x")
    (tmp_path / "a_folder").mkdir()
    result = tmp_path / "result.npz"
    import numpy as np
    Result(np.zeros(0), {}, {}, {"name": "x"}, None).save(result)
    subs = {"{file}": str(tmp_path / "a_file"), "{folder}": str(tmp_path / "a_folder"),
            "{result}": str(result)}
    args = []
    for a in argv:
        for k, v in subs.items():
            a = a.replace(k, v)
        args.append(a)
    rc = cli.main(args)
    line = _error_line(capsys.readouterr().err)
    assert rc == 2 and option in line, line
    assert (tmp_path / "a_file").read_text() == "x"
