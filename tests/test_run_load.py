"""A run records its CPU time beside its wall time and the load it ran under.

``sim_core.simulate`` adds ``wall_s`` (the whole call), ``cpu_s`` (``time.process_time``),
``load_start`` / ``load_end`` (``os.getloadavg``) and ``usable_cpus``
(``os.sched_getaffinity``) to the Result's stats; ``boom-sim run`` writes them to
summary.json and the report shows them.
"""

from __future__ import annotations

import json
import os
import time

import numpy as np
import pytest

import sim_core.api as api
from sim_core import cli
from sim_core.errors import SimulationError
from sim_core.report import write_report
from sim_core.result import Result

BUSY_S = 0.3       # s of CPU the fake run burns
IDLE_S = 0.3       # s it sleeps (wall time without CPU)


class _FakeKind:
    """A system kind whose run burns BUSY_S of CPU, sleeps IDLE_S and returns a tiny Result
    (or raises a SimulationError carrying it)."""

    def __init__(self, fail: bool = False):
        self.fail = fail

    def run(self, scene, progress=None, **kw):
        end = time.process_time() + BUSY_S
        x = 0.0
        while time.process_time() < end:
            x += 1.0
        time.sleep(IDLE_S)
        res = Result(np.linspace(0.0, 1.0, 3), {"tip_position": np.zeros((3, 3))},
                     {"wall_time_s": 0.1, "n_steps": 2}, scene)
        if self.fail:
            exc = SimulationError(0.5, "non-finite accelerations")
            exc.result = res
            raise exc
        return res


def _scene():
    return {"name": "fake", "kind": "fake", "solver": {"t_end": 1.0}}


def test_cpu_and_wall_time_are_told_apart(monkeypatch):
    monkeypatch.setattr(api, "system_kind", lambda scene: _FakeKind())
    st = api.simulate(_scene()).stats
    # the sleep counts in the wall time only; the busy loop in both (scheduler and timer
    # granularity: a few ms; a loaded machine only lengthens the wall time)
    assert st["wall_s"] >= BUSY_S + IDLE_S - 0.01
    assert BUSY_S - 0.01 <= st["cpu_s"] <= st["wall_s"] - IDLE_S + 0.05
    assert st["usable_cpus"] == len(os.sched_getaffinity(0))
    for key in ("load_start", "load_end"):
        assert len(st[key]) == 3 and all(x >= 0.0 for x in st[key]), key


def test_a_failed_run_keeps_its_timing_on_the_partial_result(monkeypatch):
    monkeypatch.setattr(api, "system_kind", lambda scene: _FakeKind(fail=True))
    with pytest.raises(SimulationError) as info:
        api.simulate(_scene())
    st = info.value.result.stats
    assert st["cpu_s"] >= BUSY_S - 0.01 and st["wall_s"] >= BUSY_S + IDLE_S - 0.01


def test_summary_json_and_report_carry_cpu_time_and_load(tmp_path, capsys):
    out = tmp_path / "out"
    rc = cli.main(["run", "beam_through_sleeve", "--set", "solver.t_end=0.002",
                   "--set", "effects.filtering=false", "--set", "beams.0.n_nodes=5",
                   "--set", "solver.n_output=5", "--out", str(out), "--quiet", "--no-plots"])
    assert rc == 0
    line = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert summary["cpu_s"] > 0.0
    # the whole call holds the integration
    assert summary["wall_s"] >= summary["wall_time_s"]
    assert summary["usable_cpus"] == len(os.sched_getaffinity(0))
    assert len(summary["load_start"]) == 3 and len(summary["load_end"]) == 3
    assert f"{summary['cpu_s']:.1f} s CPU" in line
    page = (out / "report.html").read_text()
    assert "whole run: wall, CPU" in page
    assert f"{summary['cpu_s']:.3g} s" in page
    assert f"on {summary['usable_cpus']} usable CPUs" in page


def test_the_report_shows_no_load_row_for_a_result_without_it(tmp_path):
    res = Result(np.linspace(0.0, 1.0, 3), {"tip_position": np.zeros((3, 3))},
                 {"wall_time_s": 0.1}, {"name": "old"})
    page = write_report(res, tmp_path / "r.html").read_text()
    assert "whole run: wall, CPU" not in page
