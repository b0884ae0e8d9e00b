"""Tests of sim_core.physics.drive_profiles (cubic schedule of docs/model.md#input-drive, Eq. 52
profile of docs/model.md#input-folding-drive)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from sim_core.errors import SceneError
from sim_core.physics.drive_profiles import CubicSmoothstepSchedule, Eq52Profile, MotionSample

H = 1e-6  # finite-difference step, s


def _fd(f, t, h=H):
    return (f(t + h) - f(t - h)) / (2 * h)


# ----------------------------------------------------------------------------- cubic schedule
def test_cubic_totals_and_peak_acceleration():
    sch = CubicSmoothstepSchedule()
    assert sch.travel == pytest.approx(6.0)
    assert sch.stroke(16.0) == pytest.approx(6.0, abs=1e-14)
    assert sch.stroke(20.0) == pytest.approx(6.0, abs=1e-14)
    assert sch.t_end == 16.0
    t = np.linspace(0.0, 20.0, 20001)
    a = sch.accel(t)
    assert np.max(np.abs(a)) == pytest.approx(0.1875, rel=1e-12)
    assert t[np.argmax(a)] == pytest.approx(2.0)
    assert t[np.argmin(a)] == pytest.approx(14.0)
    assert sch.accel(2.0) == pytest.approx(0.1875) and sch.accel(14.0) == pytest.approx(-0.1875)


def test_cubic_matches_scenarios_a4_pieces():
    sch = CubicSmoothstepSchedule()
    t = np.linspace(0.0, 4.0, 101)
    np.testing.assert_allclose(sch.stroke(t), 0.5 * (t**3 / 16 - t**4 / 128), atol=1e-15)
    np.testing.assert_allclose(sch.rate(t), 0.5 * (3 * (t / 4) ** 2 - 2 * (t / 4) ** 3), atol=1e-15)
    td = np.linspace(12.0, 16.0, 101)
    tau = (td - 12) / 4
    np.testing.assert_allclose(sch.rate(td), 0.5 * (1 - 3 * tau**2 + 2 * tau**3), atol=1e-15)
    assert sch.stroke(4.0) == pytest.approx(1.0) and sch.stroke(12.0) == pytest.approx(5.0)
    assert sch.rate(8.0) == 0.5 and sch.rate(-1.0) == 0.0 and sch.stroke(-1.0) == 0.0


@pytest.mark.parametrize("tj", [0.0, 4.0, 12.0, 16.0])
def test_cubic_c1_at_joints(tj):
    sch = CubicSmoothstepSchedule()
    e = 1e-9
    for f in (sch.stroke, sch.rate, sch.accel):
        assert f(tj + e) == pytest.approx(f(tj - e), abs=1e-8)
    assert sch.accel(tj) == pytest.approx(0.0, abs=1e-15)


def test_cubic_derivatives_by_finite_differences_and_quadrature():
    sch = CubicSmoothstepSchedule()
    t = np.linspace(0.05, 19.95, 400)
    t = t[np.min(np.abs(t[:, None] - np.array([0.0, 4.0, 12.0, 16.0])), axis=1) > 1e-3]
    np.testing.assert_allclose(_fd(sch.stroke, t), sch.rate(t), atol=1e-8)
    np.testing.assert_allclose(_fd(sch.rate, t), sch.accel(t), atol=1e-8)
    np.testing.assert_allclose(_fd(sch.accel, t), sch.jerk(t), atol=1e-7)
    for tt in (3.0, 9.5, 14.2, 18.0):
        val, _ = quad(sch.rate, 0.0, tt, points=[4.0, 12.0, 16.0], epsabs=1e-13)
        assert sch.stroke(tt) == pytest.approx(val, abs=1e-11)


def test_cubic_sign_offset_shift_and_shapes():
    ext = CubicSmoothstepSchedule(s0=2.0)
    ret = CubicSmoothstepSchedule(sign=-1, s0=8.0)
    assert ext.stroke(20.0) == pytest.approx(8.0) and ret.stroke(20.0) == pytest.approx(2.0)
    assert ret.rate(8.0) == -0.5 and ret.accel(2.0) == pytest.approx(-0.1875)
    shifted = CubicSmoothstepSchedule(t_start=5.0)
    assert shifted.rate(7.0) == pytest.approx(CubicSmoothstepSchedule().rate(2.0))
    assert isinstance(ext.stroke(1.0), float)
    t = np.linspace(0, 20, 12).reshape(3, 4)
    smp = ext(t)
    assert isinstance(smp, MotionSample) and all(np.shape(q) == (3, 4) for q in smp)


# ----------------------------------------------------------------------------- Eq. 52
def test_eq52_travel_and_pieces():
    v0 = 1.328 / 9
    p = Eq52Profile(v0=v0, t1=3.0, t2=6.0, t3=3.0)
    assert p.travel == pytest.approx(v0 * (1.5 + 6.0 + 1.5))
    assert p.travel == pytest.approx(1.328)
    assert p.stroke(12.0) == pytest.approx(p.travel, abs=1e-15)
    assert p.stroke(30.0) == pytest.approx(p.travel, abs=1e-15)
    t = np.linspace(0, 3, 31)
    np.testing.assert_allclose(p.rate(t), v0 * t**2 * (3 * 3 - 2 * t) / 27, atol=1e-15)
    np.testing.assert_allclose(p.accel(t[:-1]), 6 * v0 * t[:-1] * (3 - t[:-1]) / 27, atol=1e-15)
    assert p.rate(10.5) == pytest.approx(v0 / 2)         # linear decay, as printed
    assert p.accel(10.5) == pytest.approx(-v0 / 3)
    other = Eq52Profile(v0=0.2, t1=1.0, t2=0.0, t3=4.0)
    val, _ = quad(other.rate, 0, 6, points=[1.0, 5.0], epsabs=1e-13)
    assert other.travel == pytest.approx(0.2 * (0.5 + 2.0)) and val == pytest.approx(other.travel)


def test_eq52_continuity_and_derivatives():
    p = Eq52Profile(v0=0.1745, t1=3.0, t2=6.0, t3=3.0, t_start=15.0)
    e = 1e-9
    for tj in (15.0, 18.0, 24.0, 27.0):                  # v and s continuous everywhere
        assert p.rate(tj + e) == pytest.approx(p.rate(tj - e), abs=1e-8)
        assert p.stroke(tj + e) == pytest.approx(p.stroke(tj - e), abs=1e-8)
    for tj in (15.0, 18.0):                              # C^1 at the rise ends
        assert p.accel(tj + e) == pytest.approx(p.accel(tj - e), abs=1e-8)
    assert p.accel(24.0 + e) - p.accel(24.0 - e) == pytest.approx(-0.1745 / 3)  # printed jump
    t = np.linspace(14.0, 30.0, 500)
    t = t[np.min(np.abs(t[:, None] - np.array([15.0, 18.0, 24.0, 27.0])), axis=1) > 1e-3]
    np.testing.assert_allclose(_fd(p.stroke, t), p.rate(t), atol=1e-8)
    np.testing.assert_allclose(_fd(p.rate, t), p.accel(t), atol=1e-8)
    np.testing.assert_allclose(_fd(p.accel, t), p.jerk(t), atol=1e-7)
    for tt in (16.0, 20.0, 25.5, 29.0):
        val, _ = quad(p.rate, 14.0, tt, points=[15.0, 18.0, 24.0, 27.0], epsabs=1e-13)
        assert p.stroke(tt) == pytest.approx(val, abs=1e-11)


# ----------------------------------------------------------------------------- validation
@pytest.mark.parametrize("cls, kwargs, name", [
    (CubicSmoothstepSchedule, dict(v_max=0.0), "v_max"),
    (CubicSmoothstepSchedule, dict(v_max=-0.5), "v_max"),
    (CubicSmoothstepSchedule, dict(v_max=math.nan), "v_max"),
    (CubicSmoothstepSchedule, dict(t_ramp=0.0), "t_ramp"),
    (CubicSmoothstepSchedule, dict(t_ramp=math.inf), "t_ramp"),
    (CubicSmoothstepSchedule, dict(t_hold_end=3.0), "t_hold_end"),
    (CubicSmoothstepSchedule, dict(sign=0), "sign"),
    (CubicSmoothstepSchedule, dict(s0=math.nan), "s0"),
    (Eq52Profile, dict(v0=0.0, t1=3, t2=6, t3=3), "v0"),
    (Eq52Profile, dict(v0=math.nan, t1=3, t2=6, t3=3), "v0"),
    (Eq52Profile, dict(v0=0.1, t1=-1.0, t2=6, t3=3), "t1"),
    (Eq52Profile, dict(v0=0.1, t1=3, t2=-6.0, t3=3), "t2"),
    (Eq52Profile, dict(v0=0.1, t1=3, t2=6, t3=0.0), "t3"),
    (Eq52Profile, dict(v0=0.1, t1=3, t2=6, t3=3, t_start=math.nan), "t_start"),
])
def test_validation_errors_name_parameter(cls, kwargs, name):
    with pytest.raises(SceneError) as exc:
        cls(**kwargs)
    msg = str(exc.value)
    assert msg.startswith(f"{name} = {kwargs[name]!r}") and "allowed range" in msg


def test_cubic_one_time_equals_the_array_evaluation():
    """sample(t) at one time (the scalar path the telescopic drive takes per right-hand side)
    gives the array evaluation's values, on every piece and at the joints."""
    sched = CubicSmoothstepSchedule(v_max=0.5, t_ramp=4.0, t_hold_end=12.0, sign=-1, s0=2.0,
                                    t_start=0.3)
    t = np.concatenate([np.linspace(-1.0, 18.0, 1901),
                        0.3 + np.array([0.0, 4.0, 12.0, 16.0])])
    arr = sched.sample(t)
    for k, tk in enumerate(t):
        one = sched.sample(float(tk))
        for a, b in zip(one, arr):
            assert isinstance(a, float)
            assert a == pytest.approx(float(b[k]), rel=1e-14, abs=1e-14)
