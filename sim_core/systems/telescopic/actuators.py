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

A ``table_file`` is confined: resolved (symbolic links followed), it lies inside the scene
file's folder or inside a folder named in the environment variable ``BOOM_SIM_DATA_DIR``
(several separated by ``os.pathsep``); it is a UTF-8 text file of at most
:data:`TABLE_FILE_MAX_BYTES` bytes and :data:`TABLE_FILE_MAX_ROWS` rows, and its rows are
range-checked exactly as inline ``table`` rows.  Errors name the field and the line, never the
file's contents.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from sim_core.errors import SceneError
from sim_core.systems.telescopic.params import MAX_BOOMS
from sim_core.systems.telescopic.telescoping import stage_table
from sim_core.physics.drive_profiles import (
    CubicSmoothstepSchedule,
    HoldProfile,
    TableProfile,
    TrapezoidProfile,
)
from sim_core.scene.fields import number

__all__ = ["ACTUATORS", "build_profile", "peak_rate_and_accel", "extremes", "check_limits",
           "table_rows", "DATA_DIR_ENV", "TABLE_FILE_MAX_BYTES", "TABLE_FILE_MAX_ROWS"]

#: environment variable naming further folders a ``table_file`` may lie in (os.pathsep-separated)
DATA_DIR_ENV = "BOOM_SIM_DATA_DIR"
#: the largest ``table_file`` read: 1 MiB and 20 000 rows (the inline ``table`` allows 100 000
#: rows; a recorded stroke history at 1 kHz over 20 s fits)
TABLE_FILE_MAX_BYTES = 1 << 20
TABLE_FILE_MAX_ROWS = 20000

#: scene table -> (actuator name, position unit in the scene, factor scene unit -> SI)
ACTUATORS = {
    "drive": ("telescopic cylinder", "m", 1.0),
    "luffing_drive": ("luffing cylinder", "deg", math.pi / 180.0),
    "slew_drive": ("slewing drive", "deg", math.pi / 180.0),
    "hoist_drive": ("hoist", "m", 1.0),
}
# the stage cylinders of drive.mechanism = "independent", one [[stage_drive]] table per stage
# (sim_core.systems.telescopic.telescoping)
ACTUATORS.update({stage_table(k): ("stage cylinder", "m", 1.0) for k in range(MAX_BOOMS - 1)})


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
        t, s = table_rows(d, source, table)
        field = f"{table}.{'table' if 'table' in d else 'table_file'}"
        try:
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                return TableProfile(t, s * k)
        except SceneError as exc:
            raise SceneError(f"{field}: {str(exc).removeprefix('table: ')}") from None
        except ValueError:              # scipy: slopes that overflow (rows too close in time)
            raise SceneError(f"{field}: the interpolant's slopes are not finite (rows too close "
                             "in time: a rate overflows); allowed: rows whose position changes "
                             "by a finite rate") from None
    raise SceneError(f"{table}.profile = {kind!r}: allowed 'cubic', 'trapezoid', 'table'")


def table_rows(d: dict, source: str | None,
               table: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(t, position) rows of a table profile in the scene's units: inline ``table`` or the CSV
    ``table_file`` (relative to the scene file's folder; confined, capped and range-checked as
    the module docstring states).  ``table`` names the scene table (default: ``d["_table"]``
    or "drive")."""
    if "table" in d:
        a = np.asarray(d["table"], dtype=float)
        return a[:, 0], a[:, 1]
    table = table or d.get("_table", "drive")
    path = _table_file_path(d["table_file"], source, f"{table}.table_file")
    return _read_table_file(path, table)


def _roots(source: str | None) -> list[Path]:
    """The folders a table file may lie in, resolved: the scene file's folder (the working
    folder for a scene without a file) and those of ``BOOM_SIM_DATA_DIR``."""
    base = (Path(source).parent if source and not source.startswith("<") else Path.cwd())
    extra = [Path(x) for x in os.environ.get(DATA_DIR_ENV, "").split(os.pathsep) if x.strip()]
    return [p.resolve() for p in [base, *extra]]


def _table_file_path(name: str, source: str | None, field: str) -> Path:
    """The resolved path of a ``table_file``: relative names are looked up in the scene file's
    folder, then in the data folders; the resolved file (symbolic links followed) must lie
    inside one of them and be a regular file."""
    roots = _roots(source)
    where = ("the scene file's folder" + (f" or {DATA_DIR_ENV}" if len(roots) > 1 else ""))
    allowed = (f"allowed: a file inside {where} ({', '.join(str(r) for r in roots)}); name "
               f"another folder in the environment variable {DATA_DIR_ENV}")
    candidates = [Path(name)] if Path(name).is_absolute() else [r / name for r in roots]
    for cand in candidates:
        try:
            real = cand.resolve(strict=True)
        except (OSError, RuntimeError):         # missing, a link loop, no permission
            continue
        # a file outside gets the message of a missing one: no probing of other folders
        if any(real.is_relative_to(r) for r in roots) and real.is_file():
            return real
    raise SceneError(f"{field} = {name!r}: no such file inside the allowed folders (resolved, "
                     f"symbolic links followed; a relative path is relative to the scene "
                     f"file); {allowed}")


def _read_table_file(path: Path, table: str) -> tuple[np.ndarray, np.ndarray]:
    """(t, position) of a CSV file of two columns, time (s) and position (scene unit): a first
    line that is not numeric is a header, lines starting with '#' are comments, ';' separates
    like ','.  Each value is range-checked as the inline ``table`` column (the schema's
    declaration)."""
    from sim_core.systems.telescopic.schema import ACTUATOR_TABLES
    field = f"{table}.table_file"
    columns = ACTUATOR_TABLES[table]["table"].columns
    limits = (f"allowed: a UTF-8 CSV file of at most {TABLE_FILE_MAX_BYTES} bytes (1 MiB) and "
              f"{TABLE_FILE_MAX_ROWS} rows of (time s, position)")
    try:
        with open(path, "rb") as f:
            data = f.read(TABLE_FILE_MAX_BYTES + 1)
    except OSError as exc:
        raise SceneError(f"{field}: cannot read {path.name} ({exc.strerror or 'error'})") from None
    if len(data) > TABLE_FILE_MAX_BYTES:
        raise SceneError(f"{field}: {path.name} is larger than {TABLE_FILE_MAX_BYTES} bytes; "
                         f"{limits}")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise SceneError(f"{field}: {path.name} line {line} is not UTF-8 text (a binary "
                         f"file?); {limits}") from None
    if "\x00" in text:
        line = text.count("\n", 0, text.index("\x00")) + 1
        raise SceneError(f"{field}: {path.name} line {line} holds a NUL byte (a binary "
                         f"file?); {limits}")
    rows, first = [], True
    for i, line in enumerate(text.splitlines()):
        body = line.strip()
        if not body or body.startswith("#"):
            continue
        parts = body.replace(";", ",").split(",")
        header, first = first, False
        try:
            vals = [float(x) for x in parts]
        except ValueError:
            if header:
                continue                          # the header
            raise SceneError(f"{field}: {path.name} line {i + 1} is not two numbers "
                             "(time s, position); the line is not shown") from None
        if len(vals) != 2:
            raise SceneError(f"{field}: {path.name} line {i + 1} has {len(vals)} columns; "
                             "allowed: two (time s, position)")
        if len(rows) == TABLE_FILE_MAX_ROWS:
            raise SceneError(f"{field}: {path.name} has more than {TABLE_FILE_MAX_ROWS} rows; "
                             f"{limits}")
        rows.append([number({f"line {i + 1} {what}": x}, f"line {i + 1} {what}", field,
                            lo=lo, hi=hi, unit=unit)
                     for x, what, (lo, hi, unit) in zip(vals, ("time", "position"), columns)])
    if len(rows) < 2:
        raise SceneError(f"{field}: {path.name} has {len(rows)} rows of (time, position); "
                         "allowed: two or more")
    a = np.array(rows)
    return a[:, 0], a[:, 1]


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
    # "not v <= limit": a NaN rate (an overflowing table) fails the check too
    if d.get("max_rate") is not None and not v <= d["max_rate"] * (1 + 1e-12):
        raise SceneError(f"{table}: the {name}'s profile reaches a rate of {v:.4g} {unit}/s at "
                         f"t = {tv:.4g} s, above its {table}.max_rate = {d['max_rate']:g} "
                         f"{unit}/s (allowed: a slower profile or a larger limit)")
    if d.get("max_accel") is not None and not a <= d["max_accel"] * (1 + 1e-12):
        raise SceneError(f"{table}: the {name}'s profile reaches an acceleration of {a:.4g} "
                         f"{unit}/s^2 at t = {ta:.4g} s, above its {table}.max_accel = "
                         f"{d['max_accel']:g} {unit}/s^2 (allowed: a gentler profile or a "
                         "larger limit)")
    return {"max_rate": v, "t_max_rate": tv, "max_accel": a, "t_max_accel": ta,
            "unit": unit}
