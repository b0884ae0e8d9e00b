"""Sweeps that survive their workers (:mod:`sim_core.sweep`, ``--retries``).

A local Ray with 2 CPUs runs a 6-case sweep of the short sleeve scene with checkpoints every
0.05 wall seconds.  The fault hook of :mod:`sim_core.checkpoint` (``SIM_CORE_CHECKPOINT_FAULT
= kill-after:MARKER``, in the Ray workers' environment) makes the first worker that writes a
checkpoint kill itself with SIGKILL, once per marker file: a worker process dies in the
middle of a case, as under the kernel's out-of-memory killer.

* With retries, Ray runs the case again in a new worker, which resumes from the checkpoint
  the dead one wrote: every case ends ok, the killed one resumed (``resumed_from_s``) and
  its result is bit-identical to an uninterrupted run.
* Without retries the killed case is recorded as failed with Ray's error type and the
  reason, the others finish, and running the sweep again runs only that case, which resumes
  from the checkpoint kept for it.

After every sweep no case folder is half-written: each holds its summary.json (and the
result of an ok case), nothing is left under a temporary name.
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path

import numpy as np
import pytest

from sim_core import load_scene, simulate
from sim_core.checkpoint import FAULT_ENV
from sim_core.result import Result
from sim_core.sweep import CHECKPOINTS, run_sweep

BEAM = "beam_through_sleeve"
SHORT = {"effects.filtering": "false", "beams.0.n_nodes": "5", "solver.n_output": "5"}
GRID = {"solver.t_end": ["0.006", "0.007", "0.008", "0.009", "0.010", "0.011"]}


@pytest.fixture(scope="module")
def faulty_ray(tmp_path_factory):
    """A local Ray (2 CPUs) whose workers carry the fault hook; yields the marker path (a
    test removes it to arm the hook: the next checkpoint's worker dies)."""
    ray = pytest.importorskip("ray")
    if ray.is_initialized():
        ray.shutdown()
    marker = tmp_path_factory.mktemp("fault") / "killed"
    marker.touch()                                   # disarmed until a test removes it
    old = os.environ.get(FAULT_ENV)
    os.environ[FAULT_ENV] = f"kill-after:{marker}"   # inherited by the raylet and its workers
    try:
        ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False,
                 logging_level=logging.ERROR)
    finally:
        if old is None:
            os.environ.pop(FAULT_ENV)
        else:
            os.environ[FAULT_ENV] = old
    yield marker
    ray.shutdown()


def arm(marker: Path) -> None:
    marker.unlink(missing_ok=True)


def summaries(out: Path) -> dict[str, dict]:
    return {d.name: json.loads((d / "summary.json").read_text())
            for d in out.iterdir() if d.is_dir() and not d.name.startswith(".")}


def assert_whole_folders(out: Path, n_cases: int) -> None:
    """Every case folder complete (summary.json, and result.npz for an ok case); nothing
    under a temporary name."""
    cases = summaries(out)
    assert len(cases) == n_cases
    for name, s in cases.items():
        assert s["case"] == name
        if s["status"] == "ok":
            assert Result.load(out / name / "result.npz").t[-1] > 0
    hidden = [p.name for p in out.iterdir() if p.name.startswith(".") and p.name != CHECKPOINTS]
    assert hidden == []


def uninterrupted(t_end: str) -> Result:
    return simulate(load_scene(BEAM, {**SHORT, "solver.t_end": t_end}))


def assert_same_result(a: Result, b: Result) -> None:
    assert np.array_equal(a.t, b.t) and sorted(a.keys()) == sorted(b.keys())
    for k in a.keys():
        assert np.array_equal(np.asarray(a[k]), np.asarray(b[k]), equal_nan=True), k


def test_killed_worker_is_retried_and_resumes_from_its_checkpoint(tmp_path, faulty_ray):
    out = tmp_path / "sweep"
    arm(faulty_ray)
    rows = run_sweep(BEAM, GRID, out, fixed=SHORT, workers=2, quiet=True, retries=1,
                     checkpoint_every=0.05)
    assert faulty_ray.exists()                                  # a worker was killed
    assert [r["status"] for r in rows] == ["ok"] * 6
    assert_whole_folders(out, 6)
    assert not (out / CHECKPOINTS).exists()                     # every case done: removed
    resumed = {n: s for n, s in summaries(out).items() if "resumed_from_s" in s}
    assert len(resumed) == 1                                    # the killed case, retried
    name, s = next(iter(resumed.items()))
    t_end = s["overrides"]["solver.t_end"]
    assert 0.0 < s["resumed_from_s"] < float(t_end)
    assert_same_result(uninterrupted(t_end), Result.load(out / name / "result.npz"))


@pytest.mark.slow
def test_without_retries_the_killed_case_fails_and_a_rerun_runs_only_it(tmp_path, faulty_ray):
    out = tmp_path / "sweep"
    arm(faulty_ray)
    rows = run_sweep(BEAM, GRID, out, fixed=SHORT, workers=2, quiet=True, retries=0,
                     checkpoint_every=0.05)
    assert faulty_ray.exists()
    failed = [r for r in rows if r["status"] == "failed"]
    assert len(failed) == 1 and [r["status"] for r in rows].count("ok") == 5
    row = failed[0]
    assert row["error_type"] == "WorkerCrashedError", row
    assert "worker process died (0 retries allowed" in row["error"]
    assert "\n" not in row["error"]
    assert_whole_folders(out, 6)
    case = summaries(out)[row["case"]]
    assert case["status"] == "failed" and case["error_type"] == "WorkerCrashedError"
    assert not (out / row["case"] / "result.npz").exists()
    # its checkpoint is kept for the re-run; the finished cases' are removed
    assert [p.name for p in (out / CHECKPOINTS).iterdir()] == [f"{row['case']}.pkl"]

    again = run_sweep(BEAM, GRID, out, fixed=SHORT, workers=2, quiet=True, retries=0,
                      checkpoint_every=0.05)
    status = {r["case"]: r["status"] for r in again}
    assert status.pop(row["case"]) == "ok"
    assert set(status.values()) == {"skipped"}                  # only the failed case ran
    assert_whole_folders(out, 6)
    assert not (out / CHECKPOINTS).exists()
    rerun = summaries(out)[row["case"]]
    assert rerun["status"] == "ok" and rerun["resumed_from_s"] > 0.0
    t_end = rerun["overrides"]["solver.t_end"]
    assert_same_result(uninterrupted(t_end), Result.load(out / row["case"] / "result.npz"))
