"""Prescribed actuator motion profiles: stroke s(t), rate v(t), acceleration a(t), jerk j(t).

Sources
-------
* ``CubicSmoothstepSchedule``: Zhao, Qi, Wang (2024), Section 9 (work conditions (1)/(2),
  Figs. 14/15: "cubic polynomial interpolation" of v with a = 0 at the ramp ends) as fixed in
  docs/model.md#input-drive.  Default: 0.5 m/s, 4 s ramps, hold to 12 s, stop at 16 s, 6 m stroke.
* ``Eq52Profile``: folding long-boom manipulator (SIMULTECH 2020), Eq. 52, as transcribed in
  docs/model.md#input-folding-drive: cubic rise, constant hold, *linear* decay (as printed).

All methods accept a scalar or an array ``t`` (s) and return a float for scalar input, else an
array of the same shape.  Strokes are the exact integrals of the rates (no quadrature).
Jerk excludes the Dirac parts at discontinuities of a (Eq. 52 decay start/end).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple, Protocol, Union

import numpy as np

from sim_core.errors import SceneError

ArrayLike = Union[float, np.ndarray]


class MotionSample(NamedTuple):
    """Stroke s (m or rad), rate v (/s), acceleration a (/s^2), jerk j (/s^3) at times t."""

    s: ArrayLike
    v: ArrayLike
    a: ArrayLike
    j: ArrayLike


class DriveProfile(Protocol):
    """What consumers (scenes, closed-form references) need from a profile."""

    s0: float

    def stroke(self, t: ArrayLike) -> ArrayLike: ...
    def rate(self, t: ArrayLike) -> ArrayLike: ...
    def accel(self, t: ArrayLike) -> ArrayLike: ...


def _check(name: str, value: float, ok: bool, allowed: str) -> None:
    """Raise SceneError naming the parameter, its value and the allowed range."""
    if not ok or not math.isfinite(value):
        raise SceneError(f"{name} = {value!r} is invalid; allowed range: {allowed}")


def _out(x: np.ndarray, scalar: bool) -> ArrayLike:
    return float(x) if scalar else x


class _PiecewiseProfile:
    """Shared evaluation: subclasses define ``_unit(tl)`` -> (s, v, a, j) of the positive,
    unshifted profile at local time tl = t - t_start (array); sign and s0 are applied here."""

    t_start: float
    sign: int
    s0: float

    def _unit(self, tl: np.ndarray) -> tuple[np.ndarray, ...]:  # pragma: no cover - abstract
        raise NotImplementedError

    def sample(self, t: ArrayLike) -> MotionSample:
        """All four quantities at t (s): s = s0 + sign*s_unit, v/a/j = sign * unit values."""
        scalar = np.ndim(t) == 0
        if scalar and hasattr(self, "_unit_scalar"):
            s, v, a, j = self._unit_scalar(float(t) - self.t_start)
            return MotionSample(float(self.s0 + self.sign * s), float(self.sign * v),
                                float(self.sign * a), float(self.sign * j))
        tl = np.asarray(t, dtype=float) - self.t_start
        s, v, a, j = self._unit(tl)
        return MotionSample(_out(self.s0 + self.sign * s, scalar), _out(self.sign * v, scalar),
                            _out(self.sign * a, scalar), _out(self.sign * j, scalar))

    __call__ = sample

    def stroke(self, t: ArrayLike) -> ArrayLike:
        """Stroke s(t) including the offset s0."""
        return self.sample(t).s

    def rate(self, t: ArrayLike) -> ArrayLike:
        """Rate v(t) = ds/dt."""
        return self.sample(t).v

    def accel(self, t: ArrayLike) -> ArrayLike:
        """Acceleration a(t) = dv/dt."""
        return self.sample(t).a

    def jerk(self, t: ArrayLike) -> ArrayLike:
        """Jerk j(t) = da/dt (regular part)."""
        return self.sample(t).j


@dataclass(frozen=True)
class CubicSmoothstepSchedule(_PiecewiseProfile):
    """Smoothstep ramp-up / hold / mirrored ramp-down of the stroke rate.

    Source: Zhao-Qi-Wang 2024 Section 9, Figs. 14/15; docs/model.md#input-drive.
    With tau in [0, 1]:
      0 <= t < T:          v = V (3 tau^2 - 2 tau^3),      tau = t / T
      T <= t < t_h:        v = V
      t_h <= t < t_h + T:  v = V (1 - 3 tau^2 + 2 tau^3),  tau = (t - t_h) / T
      t >= t_h + T or t < 0: v = 0
    (t relative to ``t_start``).  v is C^1, a is C^0 (a = 0 at all four joints).  Total travel
    V * t_hold_end; peak |a| = 1.5 V / T at ramp mid-points.

    Parameters: v_max V (m/s) > 0, t_ramp T (s) > 0, t_hold_end t_h (s) >= T, sign +1 (extraction)
    or -1 (retraction), s0 stroke offset (m), t_start (s) time shift.
    """

    v_max: float = 0.5
    t_ramp: float = 4.0
    t_hold_end: float = 12.0
    sign: int = 1
    s0: float = 0.0
    t_start: float = 0.0

    def __post_init__(self) -> None:
        _check("v_max", self.v_max, self.v_max > 0, "v_max > 0 (finite), m/s")
        _check("t_ramp", self.t_ramp, self.t_ramp > 0, "t_ramp > 0 (finite), s")
        _check("t_hold_end", self.t_hold_end, self.t_hold_end >= self.t_ramp,
               f"t_hold_end >= t_ramp = {self.t_ramp!r} (finite), s")
        _check("sign", self.sign, self.sign in (1, -1), "+1 or -1")
        _check("s0", self.s0, True, "finite, m")
        _check("t_start", self.t_start, True, "finite, s")

    @property
    def t_end(self) -> float:
        """End of motion (absolute time), s."""
        return self.t_start + self.t_hold_end + self.t_ramp

    @property
    def travel(self) -> float:
        """Unsigned total stroke V * t_hold_end (docs/model.md#input-drive: 6 m), m."""
        return self.v_max * self.t_hold_end

    def _ramps(self, tu, td):
        """(s, v, a, j) of the ramp-up at tau = tu and of the ramp-down at tau = td
        (docs/model.md#input-drive; Zhao-Qi-Wang Sec. 9): up v = V(3tau^2 - 2tau^3),
        s = V T (tau^3 - tau^4/2); down mirrored, v = V(1 - 3tau^2 + 2tau^3),
        s = sh + V T (tau - tau^3 + tau^4/2)."""
        V, T = self.v_max, self.t_ramp
        sh = 0.5 * V * T + V * (self.t_hold_end - T)
        up = (V * T * (tu**3 - 0.5 * tu**4), V * (3 * tu**2 - 2 * tu**3),
              6 * V / T * tu * (1 - tu), 6 * V / T**2 * (1 - 2 * tu))
        down = (sh + V * T * (td - td**3 + 0.5 * td**4), V * (1 - 3 * td**2 + 2 * td**3),
                -6 * V / T * td * (1 - td), -6 * V / T**2 * (1 - 2 * td))
        return up, down

    def _unit(self, tl: np.ndarray) -> tuple[np.ndarray, ...]:
        V, T, th = self.v_max, self.t_ramp, self.t_hold_end
        s1 = 0.5 * V * T                      # stroke of one ramp, exact integral
        sh = s1 + V * (th - T)                # stroke at the start of the ramp-down
        tu = np.clip(tl / T, 0.0, 1.0)        # ramp-up tau
        td = np.clip((tl - th) / T, 0.0, 1.0)  # ramp-down tau
        up, hold, down = (tl >= 0) & (tl < T), (tl >= T) & (tl < th), (tl >= th) & (tl < th + T)
        U, D = self._ramps(tu, td)
        s = np.select([tl < 0, up, hold, down], [0.0, U[0], s1 + V * (tl - T), D[0]],
                      default=sh + s1)
        v = np.select([up, hold, down], [U[1], V, D[1]], default=0.0)
        a = np.select([up, down], [U[2], D[2]], 0.0)
        j = np.select([up, down], [U[3], D[3]], 0.0)
        return s, v, a, j

    def _unit_scalar(self, tl: float) -> tuple[float, ...]:
        """_unit at one time (the piece that holds it; the same formulas, without the array
        selects: the telescopic drive samples one time per right-hand side)."""
        V, T, th = self.v_max, self.t_ramp, self.t_hold_end
        s1 = 0.5 * V * T
        if tl < 0.0:
            return 0.0, 0.0, 0.0, 0.0
        if tl < T:
            return self._ramps(min(tl / T, 1.0), 0.0)[0]
        if tl < th:
            return s1 + V * (tl - T), V, 0.0, 0.0
        if tl < th + T:
            return self._ramps(0.0, min((tl - th) / T, 1.0))[1]
        return s1 + V * (th - T) + s1, 0.0, 0.0, 0.0


@dataclass(frozen=True)
class Eq52Profile(_PiecewiseProfile):
    """Cubic rise / hold / linear decay of the actuator rate (second seed, Eq. 52).

    Source: folding long-boom manipulator (SIMULTECH 2020) Eq. 52;
    docs/model.md#input-folding-drive.
    With t_a = t1, t_b = t1 + t2, t_c = t_b + t3 (relative to ``t_start``):
      0 <= t < t_a:     v = v0 t^2 (3 t1 - 2 t) / t1^3,  a = 6 v0 t (t1 - t) / t1^3
      t_a <= t < t_b:   v = v0,                          a = 0
      t_b <= t <= t_c:  v = v0 (t_c - t) / t3,           a = -v0 / t3   (linear, as printed)
      otherwise         v = 0,                           a = 0
    v is C^1 at t_a, only C^0 at t_b and t_c (a jumps there).  Travel v0 (t1/2 + t2 + t3/2).

    Parameters: v0 (m/s or rad/s) > 0, t1 > 0, t2 >= 0, t3 > 0 (s), t_start (s), sign +-1,
    s0 offset.
    """

    v0: float
    t1: float
    t2: float
    t3: float
    t_start: float = 0.0
    sign: int = 1
    s0: float = 0.0

    def __post_init__(self) -> None:
        _check("v0", self.v0, self.v0 > 0, "v0 > 0 (finite); use sign=-1 to reverse")
        _check("t1", self.t1, self.t1 > 0, "t1 > 0 (finite), s")
        _check("t2", self.t2, self.t2 >= 0, "t2 >= 0 (finite), s")
        _check("t3", self.t3, self.t3 > 0, "t3 > 0 (finite), s")
        _check("t_start", self.t_start, True, "finite, s")
        _check("sign", self.sign, self.sign in (1, -1), "+1 or -1")
        _check("s0", self.s0, True, "finite")

    @property
    def t_end(self) -> float:
        """End of motion t_start + t_c (absolute time), s."""
        return self.t_start + self.t1 + self.t2 + self.t3

    @property
    def travel(self) -> float:
        """Unsigned travel v0 (t1/2 + t2 + t3/2) (docs/model.md#input-folding-drive, Eq. 52
        integral)."""
        return self.v0 * (0.5 * self.t1 + self.t2 + 0.5 * self.t3)

    def _unit(self, tl: np.ndarray) -> tuple[np.ndarray, ...]:
        v0, t1, t3 = self.v0, self.t1, self.t3
        tb = t1 + self.t2
        tc = tb + t3
        sa = 0.5 * v0 * t1                     # stroke at t_a (exact integral of the cubic)
        sb = sa + v0 * self.t2                 # stroke at t_b
        r = np.clip(tl, 0.0, t1)               # local time in the rise
        d = np.clip(tl - tb, 0.0, t3)          # time since t_b in the decay
        rise, hold, decay = (tl >= 0) & (tl < t1), (tl >= t1) & (tl < tb), (tl >= tb) & (tl <= tc)
        # Eq. 52 rise: v = v0 r^2 (3 t1 - 2 r)/t1^3 -> s = v0 (r^3 t1 - r^4/2)/t1^3.
        # Eq. 52 decay: v = v0 (t_c - t)/t3 -> s = sb + v0 (d - d^2/(2 t3)).
        s = np.select([tl < 0, rise, hold, decay],
                      [0.0, v0 * (r**3 * t1 - 0.5 * r**4) / t1**3, sa + v0 * (tl - t1),
                       sb + v0 * (d - 0.5 * d**2 / t3)], default=self.travel)
        v = np.select([rise, hold, decay], [v0 * r**2 * (3 * t1 - 2 * r) / t1**3, v0,
                                            v0 * (t3 - d) / t3], default=0.0)
        a = np.select([rise, decay], [6 * v0 * r * (t1 - r) / t1**3, -v0 / t3], default=0.0)
        j = np.where(rise, 6 * v0 * (t1 - 2 * r) / t1**3, 0.0)
        return s, v, a, j


def sleeve_motion(bc: dict, s0: float = 0.0):
    """t -> (s, s_dot, s_ddot) of a sleeve end's material coordinate (m, m/s, m/s^2) from its
    validated ``[[boundary]]`` entry (sim_core.scene.io): profile "constant" moves at ``speed``
    from t = 0, s = s0 + speed t; profile "cubic" follows the telescopic drive's schedule of
    Zhao-Qi-Wang 2024 Section 9 (:class:`CubicSmoothstepSchedule`, docs/model.md#input-drive)
    with peak rate ``speed`` (its sign the direction), ramps of ``t_ramp`` and the hold up to
    ``t_hold_end``.  Either motion is monotone in t, so its extreme over [0, t_end] is at
    t_end."""
    v = float(bc["speed"])
    if bc.get("profile", "constant") == "constant" or v == 0.0:
        return lambda t: (s0 + v * t, v, 0.0)
    sched = CubicSmoothstepSchedule(v_max=abs(v), t_ramp=bc["t_ramp"],
                                    t_hold_end=bc["t_hold_end"], sign=1 if v > 0 else -1, s0=s0)

    def motion(t):
        smp = sched.sample(float(t))
        return smp.s, smp.v, smp.a
    return motion
