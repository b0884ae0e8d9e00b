"""A sleeve end driven by the telescopic drive's cubic schedule (boundary.profile = "cubic").

The sleeve of a beam scene takes the same drive profiles as the telescopic cylinder
(Zhao-Qi-Wang 2024 Section 9, docs/model.md#input-drive; drive_profiles.sleeve_motion):
"constant" moves at ``speed`` from t = 0, "cubic" ramps the rate up over t_ramp by a smoothstep,
holds it to t_hold_end and ramps it down, so the travel by the end of the motion is
speed * t_hold_end.
"""

import numpy as np
import pytest

from sim_core import SceneError, load_scene, simulate
from sim_core.physics.drive_profiles import CubicSmoothstepSchedule

SCENE = "beam_through_sleeve"
CUBIC = {"boundary.0.profile": "cubic", "boundary.0.t_ramp": 0.5, "boundary.0.t_hold_end": 1.0}


def _err(overrides) -> str:
    with pytest.raises(SceneError) as info:
        load_scene(SCENE, overrides=overrides)
    return str(info.value)


def test_profile_keys_belong_to_a_sleeve_and_to_its_cubic_profile():
    assert "boundary[0].profile" in _err({"boundary.0.profile": "sine"})
    msg = _err({"boundary.0.t_ramp": 1.0})
    assert "profile = 'constant' with t_ramp" in msg
    msg = _err({**CUBIC, "boundary.0.t_hold_end": 0.2})
    assert "boundary[0].t_hold_end" in msg and "0.5" in msg


def test_cubic_travel_sets_the_allowed_speeds():
    """The travel by t_end is speed * t_hold_end once the motion has ended: the allowed speeds
    follow from the element the sleeve end runs into (breakpoints 8 and 12 m, s_1 = 8 m)."""
    msg = _err({**CUBIC, "boundary.0.speed": -9.0, "solver.t_end": 2.0})
    assert "boundary[0].speed = -9.0" in msg
    assert "allowed (-8, 4) m/s" in msg            # (0 - 8) / 1.0 and (12 - 8) / 1.0


def test_sleeve_end_follows_the_schedule_from_rest():
    sc = load_scene(SCENE, overrides={**CUBIC, "solver.t_end": 1.5})
    res = simulate(sc)
    speed = sc["boundary"][0]["speed"]
    sched = CubicSmoothstepSchedule(v_max=abs(speed), t_ramp=0.5, t_hold_end=1.0,
                                    sign=int(np.sign(speed)), s0=8.0)
    s_left = res["element_ends"][:, 0]
    # the sleeve end's material coordinate is prescribed: exact up to the constraint solve
    np.testing.assert_allclose(s_left, sched.sample(res.t).s, rtol=0, atol=1e-9)
    assert s_left[-1] == pytest.approx(8.0 + speed * 1.0, abs=1e-9)
    # from rest: no initial flow, so the tip starts at zero velocity
    assert np.max(np.abs(res["tip_velocity"][0])) < 1e-12
    assert not res.suspect, res.failed_checks()
