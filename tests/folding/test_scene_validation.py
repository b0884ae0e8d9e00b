"""Scene validation of kind = "folding": one bad value per rule, message names field and range."""

import pytest

from sim_core import load_scene
from sim_core.errors import SceneError

CASES = [
    ({"solver.t_end": 0}, "solver.t_end = 0: out of range, allowed [1e-06, 3600] s"),
    ({"solver.rtol": 1.5}, "solver.rtol = 1.5: out of range, allowed [1e-12, 0.1]"),
    ({"solver.method": "Radau"}, "solver.method"),
    ({"solver.n_output": 1}, "solver.n_output = 1: out of range, allowed [2, 200001]"),
    ({"booms.length": 0.5}, "booms.length = 0.5: out of range, allowed (1, 100] m"),
    ({"booms.E": -1.0}, "booms.E = -1.0: out of range, allowed [1e+08, 1e+15] Pa"),
    ({"booms.nu": 0.5}, "booms.nu = 0.5: out of range, allowed (-1, 0.5)"),
    ({"booms.n_nodes": 2}, "booms.n_nodes = 2: out of range, allowed [3, 33]"),
    ({"booms.n_gauss": 2.5}, "booms.n_gauss = 2.5: must be an integer"),
    ({"cylinders.k": 0}, "cylinders.k = 0: out of range, allowed [1000, 1e+12] N/m"),
    ({"cylinders.c": -1}, "cylinders.c = -1: out of range, allowed [0, 1e+10] N s/m"),
    ({"drive.t1": 0}, "drive.t1 = 0: out of range, allowed [0.001, 3600] s"),
    ({"drive.t2": -1}, "drive.t2 = -1: out of range, allowed [0, 3600] s"),
    ({"drive.stage_starts": "[0, 15]"}, "drive.stage_starts = [0, 15]: must be a list of 3"),
    ({"drive.stage_starts": "[0, 10, 30]"}, "stage 2 starts at 10 s before stage 1 ends at 12 s"),
    ({"drive.stage_starts": "[-1, 15, 30]"}, "drive.stage_starts[0] = -1: out of range, allowed [0, 3600] s"),
    ({"drive.slew_angle_deg": 270}, "drive.slew_angle_deg = 270: out of range, allowed [-180, 180]"),
    ({"drive.slew_angle_deg": 0}, "drive.slew_angle_deg = 0: must be non-zero"),
    ({"drive.cyl1_stroke": 3.0}, "drive.cyl1_stroke = 3.0: boom 1 would pass 85 deg elevation"),
    ({"drive.cyl2_stroke": 2.5}, "drive.cyl2_stroke = 2.5: the links cannot be assembled"),
    ({"rest.k": -1}, "rest.k = -1: out of range, allowed [0, 1e+12] N/m"),
    ({"effects.gravity": 1}, "effects.gravity"),
    ({"filtering.h": 0}, "filtering.h = 0: out of range, allowed [0.0001, 1] s"),
    ({"gravity.g": -9.81}, "gravity.g = -9.81: out of range, allowed (0, 100] m/s^2"),
    ({"drive.speed": 1}, "drive.speed: unknown key"),
    ({"cylinder.k": 1}, "scene.cylinder: unknown key"),
]


@pytest.mark.parametrize("overrides,message", CASES)
def test_bad_value(overrides, message):
    with pytest.raises(SceneError) as exc:
        load_scene("folding_boom", overrides)
    assert message in str(exc.value)


def test_shipped_scene_is_valid():
    sc = load_scene("folding_boom")
    assert sc["kind"] == "folding"
    assert sc["drive"]["stage_starts"] == [0.0, 15.0, 30.0]
    assert sc["filtering"]["h"] == 0.005
