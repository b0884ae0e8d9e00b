"""End-to-end: the shipped folding_boom scene through the CLI (tiny horizon, coarse mesh) and
the full 45 s scenario (@slow, ~50 s CPU with the scene's BDF -- not part of the default run;
benchmarks/results/folding_speed.md)."""

import json

import numpy as np
import pytest

from sim_core import load_scene, simulate
from sim_core.cli import main
from sim_core.result import Result


def test_cli_run_writes_result_and_figures(tmp_path):
    """~20 s CPU (static equilibrium at 2 sub-elements per boom + 4 RK45 steps)."""
    code = main(["run", "folding_boom", "--set", "solver.t_end=0.02", "--set", "booms.n_nodes=3",
                 "--set", "solver.n_output=3", "--out", str(tmp_path), "--quiet"])
    assert code == 0
    res = Result.load(tmp_path / "result.npz")
    for name in ("tip_position", "tip_velocity", "cylinder_forces", "slew_angle",
                 "constraint_violation"):
        assert name in res
    assert res["cylinder_forces"].shape == (3, 2)
    # static start: cylinder 1 pushes (carries both booms), violation at round-off level
    assert res["cylinder_forces"][0, 0] > 0
    assert res["constraint_violation"][0] < 1e-9
    assert json.loads((tmp_path / "summary.json").read_text())["scene"] == "folding_boom"
    for fig in ("tip_displacement.png", "tip_velocity_h.png", "folding_cylinders.png"):
        assert (tmp_path / fig).stat().st_size > 0


@pytest.mark.slow
def test_full_scenario():
    """Full 45 s run (8 sub-elements, h = 0.005 s, BDF).  Checks: prescribed slew reached exactly;
    constraint violation below the Baumgarte/integrator bound 1e-4 m (steps ~ 5e-3 s ->
    ~20 steps per 1/xi, times rtol 2L = 2.4e-5); final boom-2 tip height near the rigid value
    2 + 12 sin 60 deg + 12 = 24.4 m (gravity sag of the unfolded booms < 1.5 m: boom 1's static
    tip sag 0.16 m and the cantilever sag of the inclined, loaded booms)."""
    sc = load_scene("folding_boom")
    res = simulate(sc)
    assert res.error is None
    assert np.isclose(res["slew_angle"][-1], -np.pi / 2, atol=1e-9)
    assert np.max(res["constraint_violation"]) < 1e-4
    assert abs(res["tip_position"][-1, 0] - 24.39) < 1.5
