"""``boom-sim dynamic-factor``: the hoisting load case over a grid (sim_core.dynamic_factor).

The table is checked against the case's own result file (the peak rope force over the static
force of payload and hook, the working radius of the payload at t = 0, the tip's deflection)
and the cell's start against its definition (the rope ``--slack`` m slack, the run ``--after``
s past the time the hoist has wound that in).  The physics of phi2 is validated in
tests/telescopic/test_lift_off.py.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from sim_core.api import load_scene
from sim_core.cli import main
from sim_core.dynamic_factor import HOISTING_CLASSES, peak
from sim_core.result import Result

FAST = ["--set", "hoist_drive.t_start=0.0", "--set", "solver.n_output=31"]


def _table(out: Path) -> list[dict]:
    with open(out / "dynamic_factor.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_dynamic_factor_writes_the_table_and_chart_of_its_cells(tmp_path, capsys):
    out = tmp_path / "phi2"
    rc = main(["dynamic-factor", "crane_lift_off", "--grid", "hoist_drive.v_max=0.5",
               "--out", str(out), "--serial", "--slack", "0.01", "--after", "0.35", *FAST])
    assert rc == 0, capsys.readouterr().err
    (row,) = _table(out)
    assert row["status"] == "ok" and row["hoist_drive.v_max"] == "0.5"
    res = Result.load(out / row["case"] / "result.npz")
    sc = load_scene("crane_lift_off", {"hoist_drive.v_max": 0.5, "hoist_drive.t_start": 0.0,
                                       "hoist.length": float(row["hoist.length"])})
    m = sc["payload"]["mass"] + sc["hoist"]["hook_mass"]
    W = m * sc["gravity"]["g"]
    T = np.asarray(res["hoist_rope_force"])
    # the cell starts with the payload on the ground and the rope 1 cm slack: the hoist
    # (accelerating at 10 m/s^2 to 0.5 m/s) has wound that in at sqrt(2 * 0.01 / 10) s, and
    # the run ends 0.35 s later
    tip0 = np.asarray(res["tip_position"])[0]
    drop = tip0[2] - sc["ground"]["height"]
    # (the statics lower the tip by the booms' own weight, ~1 cm, below the straight booms')
    assert float(row["hoist.length"]) == pytest.approx(drop + 0.01, abs=0.02)
    assert res.t[-1] == pytest.approx(math.sqrt(0.002) + 0.35, abs=2e-3)
    assert np.asarray(res["payload_ground_force"])[0] == pytest.approx(W, rel=1e-6)
    assert T[0] == 0.0 and T.max() > W
    assert float(row["phi2"]) == pytest.approx(peak(res.t, T)[1] / W, rel=1e-5)
    assert float(row["static_rope_force_N"]) == pytest.approx(W, rel=1e-5)
    r_p = np.asarray(res["payload_position"])[0]
    assert float(row["working_radius_m"]) == pytest.approx(math.hypot(r_p[0], r_p[1]), rel=1e-5)
    tip = np.asarray(res["tip_position"])
    assert float(row["tip_deflection_m"]) == pytest.approx(
        np.max(np.linalg.norm(tip - tip0, axis=1)), rel=1e-5)
    assert float(row["v_h_m_s"]) == pytest.approx(0.5, rel=1e-9)
    for hc, (beta2, phi2_min) in HOISTING_CLASSES.items():
        assert float(row[f"phi2_{hc}"]) == pytest.approx(phi2_min + beta2 * 0.5, rel=1e-5)
    md = (out / "dynamic_factor.md").read_text()
    assert row["case"] in md and row["phi2"] in md
    assert (out / "dynamic_factor.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("args, match", [
    (["cantilever_release"], "effects.ground"),
    (["crane_lift_off", "--slack", "-1"], "--slack"),
    (["crane_lift_off", "--after", "0"], "--after"),
    (["crane_lift_off", "--grid", "ground.stiffness=1"], "stiffness"),
    (["crane_lift_off", "--grid", "hoist.EA=1e8", "--set", "hoist.EA=2e8"], "either swept"),
])
def test_bad_input_exits_2_naming_it_before_anything_runs(tmp_path, capsys, args, match):
    rc = main(["dynamic-factor", *args, "--out", str(tmp_path / "o"), "--serial"])
    assert rc == 2
    assert match in capsys.readouterr().err
    assert not list((tmp_path / "o").glob("*/result.npz"))


@pytest.mark.slow
def test_dynamic_factor_runs_its_cells_as_a_ray_sweep(tmp_path, capsys):
    """Two cells as Ray tasks: the same table as the serial run, row by row in grid order."""
    pytest.importorskip("ray")
    common = ["--slack", "0.01", "--after", "0.35", *FAST]
    grid = ["--grid", "hoist_drive.v_max=0.4,0.5"]
    assert main(["dynamic-factor", "crane_lift_off", *grid, "--out", str(tmp_path / "ray"),
                 "--workers", "2", "--quiet", *common]) == 0
    assert main(["dynamic-factor", "crane_lift_off", *grid, "--out", str(tmp_path / "ser"),
                 "--serial", *common]) == 0
    ray_rows, ser_rows = _table(tmp_path / "ray"), _table(tmp_path / "ser")
    assert [r["hoist_drive.v_max"] for r in ray_rows] == ["0.4", "0.5"]
    for a, b in zip(ray_rows, ser_rows):
        assert float(a["phi2"]) == pytest.approx(float(b["phi2"]), rel=1e-9)
    # a faster hoist lifts harder
    assert float(ray_rows[1]["phi2"]) > float(ray_rows[0]["phi2"])
