"""The actuators of a telescopic crane and their drive profiles (scene tables ``[drive]``,
``[luffing_drive]``, ``[slew_drive]``, ``[hoist_drive]``), SI units.

Each actuator follows a profile of :mod:`sim_core.physics.drive_profiles` in its own position
variable:

| actuator | table | position | unit in the scene | held without a profile |
|---|---|---|---|---|
| telescopic cylinders (stages) | ``[drive]`` | stage length L_s | m | (the cubic schedule is the default) |
| luffing cylinder | ``[luffing_drive]`` | luffing angle of the rigid crane | deg | ``booms.luffing_angle_deg`` |
| slewing drive | ``[slew_drive]`` | slew angle about the vertical | deg | 0 (no turntable built) |
| hoist | ``[hoist_drive]`` | hoist-rope length | m | ``hoist.length`` |

Profiles: ``cubic`` (the paper's schedule, Zhao-Qi-Wang 2024 Section 9:
:class:`~sim_core.physics.drive_profiles.CubicSmoothstepSchedule`), ``trapezoid``
(acceleration-limited, optionally jerk-limited:
:class:`~sim_core.physics.drive_profiles.TrapezoidProfile`) and ``table`` (time and position,
inline or from a CSV file relative to the scene file:
:class:`~sim_core.physics.drive_profiles.TableProfile`).  A profile's largest rate and
acceleration are checked against the actuator's limits (``max_rate``, ``max_accel``) with an
error naming the actuator and the time.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sim_core.errors import SceneError
from sim_core.physics.drive_profiles import (
    CubicSmoothstepSchedule,
    HoldProfile,
    TableProfile,
    TrapezoidProfile,
    read_table_csv,
)

__all__ = ["ACTUATORS", "build_profile", "peak_rate_and_accel", "extremes", "check_limits"]

#: scene table -> (actuator name, position unit in the scene, factor scene unit -> SI)
ACTUATORS = {
    "drive": ("telescopic cylinder", "m", 1.0),
    "luffing_drive": ("luffing cylinder", "deg", math.pi / 180.0),
    "slew_drive": ("slewing drive", "deg", math.pi / 180.0),
    "hoist_drive": ("hoist", "m", 1.0),
}


def build_profile(d: dict, s0: float, table: str, source: str | None = None):
    """The profile of a validated actuator table ``d`` starting from position ``s0`` (SI: m or
    rad), in SI units.  ``table`` names the scene table (its unit), ``source`` the scene file
    (a ``table_file`` is relative to its folder)."""
    _, _, k = ACTUATORS[table]
    kind = d.get("profile", "hold")
    if kind == "hold":
        return HoldProfile(s0=s0)
    if kind == "cubic":
        if table == "drive":
            return CubicSmoothstepSchedule(v_max=d["v_max"], t_ramp=d["t_ramp"],
                                           t_hold_end=d["t_hold_end"],
                                           sign=1 if d["direction"] == "extraction" else -1,
                                           s0=s0, t_start=d.get("t_start", 0.0))
        travel = d["travel"] * k
        return CubicSmoothstepSchedule(v_max=abs(travel) / d["t_hold_end"], t_ramp=d["t_ramp"],
                                       t_hold_end=d["t_hold_end"], sign=1 if travel > 0 else -1,
                                       s0=s0, t_start=d.get("t_start", 0.0))
    if kind == "trapezoid":
        travel = d["travel"] * k
        sign = 1 if travel > 0 else -1
        if table == "drive":
            sign = 1 if d["direction"] == "extraction" else -1
        jm = d.get("j_max")
        return TrapezoidProfile(travel=abs(travel), v_max=d["v_max"] * k, a_max=d["a_max"] * k,
                                j_max=None if jm is None else jm * k, sign=sign, s0=s0,
                                t_start=d.get("t_start", 0.0))
    if kind == "table":
        t, s = table_rows(d, source)
        try:
            return TableProfile(t, s * k)
        except SceneError as exc:
            raise SceneError(f"{table}.{'table' if 'table' in d else 'table_file'}: "
                             f"{str(exc).removeprefix('table: ')}") from None
    raise SceneError(f"{table}.profile = {kind!r}: allowed 'cubic', 'trapezoid', 'table'")


def table_rows(d: dict, source: str | None) -> tuple[np.ndarray, np.ndarray]:
    """(t, position) rows of a table profile in the scene's units: inline ``table`` or the CSV
    ``table_file`` (relative to the scene file's folder)."""
    if "table" in d:
        a = np.asarray(d["table"], dtype=float)
        return a[:, 0], a[:, 1]
    path = Path(d["table_file"])
    if not path.is_absolute() and source and not source.startswith("<"):
        path = Path(source).parent / path
    if not path.is_file():
        raise SceneError(f"{d.get('_table', 'drive')}.table_file = {d['table_file']!r}: no such "
                         f"file ({path}; a relative path is relative to the scene file)")
    return read_table_csv(path)


def peak_rate_and_accel(profile, t_end: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """((|v|max, t), (|a|max, t)) of a profile over [0, t_end]: exact for a table (its
    interpolant's own extremes), else from 20001 samples of the closed-form rate and
    acceleration (a smooth profile: the sampling error is far below the limits' precision)."""
    if isinstance(profile, TableProfile):
        return (profile.max_rate, profile.t_max_rate), (profile.max_accel, profile.t_max_accel)
    t = np.linspace(0.0, max(t_end, getattr(profile, "t_end", t_end)), 20001)
    smp = profile.sample(t)
    v, a = np.abs(np.asarray(smp.v)), np.abs(np.asarray(smp.a))
    iv, ia = int(np.argmax(v)), int(np.argmax(a))
    return (float(v[iv]), float(t[iv])), (float(a[ia]), float(t[ia]))


def extremes(profile, t_end: float) -> tuple[float, float]:
    """(min, max) of the position over [0, t_end] (SI), from the samples of a table and 20001
    samples of the interpolant (a monotone table piece does not overshoot its samples)."""
    t = np.linspace(0.0, t_end, 20001)
    s = np.asarray(profile.sample(t).s)
    if isinstance(profile, TableProfile):
        inside = profile.t_table <= t_end
        s = np.concatenate([s, profile.s_table[inside]])
    return float(np.min(s)), float(np.max(s))


def check_limits(table: str, d: dict, profile, t_end: float) -> dict:
    """Check the profile's largest rate and acceleration against the actuator's limits
    (``max_rate``, ``max_accel`` in the scene's units per s and per s^2); returns them in the
    scene's units for ``describe``."""
    name, unit, k = ACTUATORS[table]
    (v, tv), (a, ta) = peak_rate_and_accel(profile, t_end)
    v, a = v / k, a / k
    if d.get("max_rate") is not None and v > d["max_rate"] * (1 + 1e-12):
        raise SceneError(f"{table}: the {name}'s profile reaches a rate of {v:.4g} {unit}/s at "
                         f"t = {tv:.4g} s, above its {table}.max_rate = {d['max_rate']:g} "
                         f"{unit}/s (allowed: a slower profile or a larger limit)")
    if d.get("max_accel") is not None and a > d["max_accel"] * (1 + 1e-12):
        raise SceneError(f"{table}: the {name}'s profile reaches an acceleration of {a:.4g} "
                         f"{unit}/s^2 at t = {ta:.4g} s, above its {table}.max_accel = "
                         f"{d['max_accel']:g} {unit}/s^2 (allowed: a gentler profile or a "
                         "larger limit)")
    return {"max_rate": v, "t_max_rate": tv, "max_accel": a, "t_max_accel": ta,
            "unit": unit}
