"""Work regressions without timing: every shipped scene, run to a short ``solver.t_end``, takes
no more steps, right-hand sides, Jacobians and factorisations than the committed counts
(tests/data/work_counters.json, written by ``python benchmarks/work_counters.py --write``).

The counts are deterministic on one machine; another BLAS/libm may accept a step near the
tolerance differently, so a counter may rise by 10 % or 2 counts, whichever is larger
(``benchmarks.work_counters.RISE``, ``RISE_ABS``); a decrease passes with a warning (the
committed counts are then out of date: regenerate them).  Each scene's ``solver.t_end`` is in
the file (``benchmarks.work_counters.T_END``): the set runs in about a minute, most of it the
models' build and statics."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest

from benchmarks.work_counters import (
    DATA,
    HOW_TO_REGENERATE,
    RISE,
    RISE_ABS,
    T_END,
    compare,
    counters,
)
from sim_core.scene.io import shipped_scenes

COMMITTED = json.loads(Path(DATA).read_text())


class WorkDecreased(UserWarning):
    """A scene's work counter fell below the committed count."""


def test_every_shipped_scene_has_committed_counters():
    assert set(T_END) == set(shipped_scenes()), "benchmarks/work_counters.py T_END: a t_end " \
        "for every shipped scene"
    assert set(COMMITTED["scenes"]) == set(shipped_scenes()), HOW_TO_REGENERATE
    assert {k: v["t_end"] for k, v in COMMITTED["scenes"].items()} == T_END, HOW_TO_REGENERATE
    assert COMMITTED["rise_allowed"] == {"relative": RISE, "absolute": RISE_ABS}
    # a run long enough to matter: tens of steps where an integrator counts them
    for name, rec in COMMITTED["scenes"].items():
        c = rec["counters"]
        if "n_steps" in c:
            assert c["n_steps"] >= 10, name
        # BDF factorises its Newton matrix after every new Jacobian (and on step changes)
        if "n_jacobians" in c:
            assert c["n_lu"] >= c["n_jacobians"], name


def test_compare_fails_on_a_rise_and_notes_a_decrease():
    ref = {"method": "auto", "counters": {"n_steps": 100, "n_lu": 3}}
    ok = {"method": "auto", "counters": {"n_steps": 110, "n_lu": 5}}
    assert compare("s", ok, ref) == ([], [])
    fail, _ = compare("s", {"method": "auto", "counters": {"n_steps": 111, "n_lu": 3}}, ref)
    assert len(fail) == 1 and "n_steps = 111" in fail[0]
    fail, _ = compare("s", {"method": "auto", "counters": {"n_steps": 100, "n_lu": 6}}, ref)
    assert len(fail) == 1 and "n_lu = 6" in fail[0]
    fail, note = compare("s", {"method": "auto", "counters": {"n_steps": 90, "n_lu": 3}}, ref)
    assert fail == [] and note == ["s: n_steps = 90 fell from 100"]
    fail, _ = compare("s", {"method": "BDF", "counters": {"n_steps": 100, "n_lu": 3}}, ref)
    assert len(fail) == 1
    fail, _ = compare("s", {"method": "auto", "counters": {"n_steps": 100}}, ref)
    assert len(fail) == 1


@pytest.mark.parametrize("scene", sorted(T_END))
def test_work_counters_do_not_rise(scene):
    ref = COMMITTED["scenes"][scene]
    got = counters(scene, ref["t_end"])
    fail, note = compare(scene, got, ref)
    for line in note:
        warnings.warn(WorkDecreased(f"{line}: the committed counts are out of date; "
                                    f"{HOW_TO_REGENERATE}"))
    assert not fail, "\n".join(fail) + "\nAn unexplained rise is a regression; for " + \
        HOW_TO_REGENERATE
