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

import bisect
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
            # the last scalar sample is kept: a model asks for the same time several times
            # per right-hand side (the value, rate and acceleration of a signal)
            t = float(t)
            last = self.__dict__.get("_last")
            if last is not None and last[0] == t:
                return last[1]
            s, v, a, j = self._unit_scalar(t - self.t_start)
            smp = MotionSample(float(self.s0 + self.sign * s), float(self.sign * v),
                               float(self.sign * a), float(self.sign * j))
            self.__dict__["_last"] = (t, smp)
            return smp
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
    """Cubic rise / hold / linear decay of the actuator rate (SIMULTECH 2020, Eq. 52).

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


@dataclass(frozen=True)
class HoldProfile(_PiecewiseProfile):
    """An actuator that holds its position s0 (no profile given): v = a = j = 0."""

    s0: float = 0.0
    sign: int = 1
    t_start: float = 0.0

    @property
    def t_end(self) -> float:
        return self.t_start

    def _unit(self, tl):
        z = np.zeros_like(tl)
        return z, z, z, z

    def _unit_scalar(self, tl):
        return 0.0, 0.0, 0.0, 0.0


class _JerkSegments:
    """Exact evaluation of a motion made of segments of constant jerk (durations d_i >= 0,
    jerks j_i): a, v, s are the exact integrals from rest at s = 0 (piecewise cubic s)."""

    def _build(self, durations, jerks):
        knots = [0.0]
        state = [(0.0, 0.0, 0.0)]                         # (s, v, a) at each knot
        for d, j in zip(durations, jerks):
            s, v, a = state[-1]
            state.append((s + v * d + a * d * d / 2 + j * d ** 3 / 6, v + a * d + j * d * d / 2,
                          a + j * d))
            knots.append(knots[-1] + d)
        object.__setattr__(self, "_knots", np.array(knots))
        object.__setattr__(self, "_state", np.array(state))
        object.__setattr__(self, "_jerks", np.array(list(jerks) + [0.0]))

    def _segments_scalar(self, tl: float):
        """_unit of one time (bisect into the knots; the same formulas)."""
        if tl < 0.0:
            return 0.0, 0.0, 0.0, 0.0
        knots = self._knots
        k = bisect.bisect_right(knots, tl) - 1
        s0, v0, a0 = self._state[k]
        if k == len(knots) - 1:
            return float(s0), 0.0, 0.0, 0.0
        dt, j = tl - knots[k], self._jerks[k]
        return (float(s0 + v0 * dt + a0 * dt * dt / 2 + j * dt ** 3 / 6),
                float(v0 + a0 * dt + j * dt * dt / 2), float(a0 + j * dt), float(j))

    def _unit(self, tl):
        tl = np.asarray(tl, dtype=float)
        k = np.clip(np.searchsorted(self._knots, tl, side="right") - 1, 0, len(self._knots) - 1)
        dt = np.where(tl < 0, 0.0, tl - self._knots[k])
        s0, v0, a0 = (self._state[k, i] for i in range(3))
        j = np.where((tl < 0) | (k == len(self._knots) - 1), 0.0, self._jerks[k])
        a0 = np.where(k == len(self._knots) - 1, 0.0, a0)
        v0 = np.where(k == len(self._knots) - 1, 0.0, v0)
        s = s0 + v0 * dt + a0 * dt * dt / 2 + j * dt ** 3 / 6
        return (np.where(tl < 0, 0.0, s), np.where(tl < 0, 0.0, v0 + a0 * dt + j * dt * dt / 2),
                np.where(tl < 0, 0.0, a0 + j * dt), j)


@dataclass(frozen=True)
class TrapezoidProfile(_JerkSegments, _PiecewiseProfile):
    """Point-to-point move of ``travel`` (m or rad, > 0) with the rate limited to v_max and the
    acceleration to a_max, optionally with the jerk limited to j_max (an S-curve); sign +-1
    gives the direction, s0 the start, t_start the start time.

    Without j_max the acceleration is +a_max, 0, -a_max (v trapezoidal, or triangular where
    the travel is too short to reach v_max); with j_max each acceleration change is a ramp of
    jerk +-j_max (seven phases: jerk up, constant acceleration, jerk down, cruise and the
    mirrored braking; the constant-acceleration phase vanishes where v_max < a_max^2 / j_max,
    and the peak rate drops below v_max where the travel is short).  Standard point-to-point
    motion law of drives (Biagiotti and Melchiorri, "Trajectory Planning for Automatic
    Machines and Robots", Springer 2008, Sections 3.2-3.4); evaluated exactly as segments of
    constant jerk."""

    travel: float = 1.0
    v_max: float = 0.5
    a_max: float = 0.25
    j_max: float | None = None
    sign: int = 1
    s0: float = 0.0
    t_start: float = 0.0

    def __post_init__(self) -> None:
        _check("travel", self.travel, self.travel > 0, "travel > 0 (finite)")
        _check("v_max", self.v_max, self.v_max > 0, "v_max > 0 (finite)")
        _check("a_max", self.a_max, self.a_max > 0, "a_max > 0 (finite)")
        if self.j_max is not None:
            _check("j_max", self.j_max, self.j_max > 0, "j_max > 0 (finite)")
        _check("sign", self.sign, self.sign in (1, -1), "+1 or -1")
        D = self.travel

        def accel_phase(v):              # (durations, jerks, time) of reaching rate v from rest
            if self.j_max is None:
                return [v / self.a_max], [None], v / self.a_max
            ap = min(self.a_max, math.sqrt(v * self.j_max))
            tj = ap / self.j_max
            ta = v / ap - tj
            return [tj, ta, tj], [self.j_max, 0.0, -self.j_max], 2 * tj + ta

        v = self.v_max
        if v * accel_phase(v)[2] > D:     # v_max not reached: the peak rate by bisection
            lo, hi = 0.0, v
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if mid * accel_phase(mid)[2] <= D else (lo, mid)
            v = lo
        d_acc, j_acc, t_acc = accel_phase(v)
        cruise = max(D / v - t_acc, 0.0)
        if self.j_max is None:              # constant-acceleration phases as infinite jerk:
            object.__setattr__(self, "_trap", (t_acc, cruise, v))   # evaluated in closed form
        else:
            object.__setattr__(self, "_trap", None)
            self._build(d_acc + [cruise] + d_acc[::-1],
                        j_acc + [0.0] + [-x for x in j_acc])
        object.__setattr__(self, "v_peak", v)

    def _unit_scalar(self, tl: float):
        if self._trap is None:
            return self._segments_scalar(tl)
        ta, tc, v = self._trap
        a = v / ta
        if tl < 0.0:
            return 0.0, 0.0, 0.0, 0.0
        if tl < ta:
            return a * tl * tl / 2, a * tl, a, 0.0
        if tl < ta + tc:
            return v * ta / 2 + v * (tl - ta), v, 0.0, 0.0
        if tl < 2 * ta + tc:
            d = tl - ta - tc
            return v * ta / 2 + v * tc + v * d - a * d * d / 2, v - a * d, -a, 0.0
        return v * ta + v * tc, 0.0, 0.0, 0.0

    @property
    def t_end(self) -> float:
        if self._trap is not None:
            ta, tc, _ = self._trap
            return self.t_start + 2 * ta + tc
        return self.t_start + float(self._knots[-1])

    def _unit(self, tl):
        if self._trap is None:
            return _JerkSegments._unit(self, tl)
        ta, tc, v = self._trap
        a = v / ta
        tl = np.asarray(tl, dtype=float)
        t1, t2, t3 = ta, ta + tc, 2 * ta + tc
        s = np.select([tl < 0, tl < t1, tl < t2, tl < t3],
                      [0.0, a * tl ** 2 / 2, v * ta / 2 + v * (tl - t1),
                       v * ta / 2 + v * tc + v * (tl - t2) - a * (tl - t2) ** 2 / 2],
                      default=v * ta + v * tc)
        vel = np.select([tl < 0, tl < t1, tl < t2, tl < t3], [0.0, a * tl, v, v - a * (tl - t2)],
                        default=0.0)
        acc = np.select([tl < 0, tl < t1, tl < t2, tl < t3], [0.0, a, 0.0, -a], default=0.0)
        return s, vel, acc, np.zeros_like(tl)


class TableProfile(_PiecewiseProfile):
    """A measured or planned history (t_i, s_i) of an actuator, interpolated by the monotone
    piecewise cubic Hermite interpolant of Fritsch and Carlson (1980, SIAM J. Numer. Anal. 17,
    238-246; scipy.interpolate.PchipInterpolator's slopes): s is C^1 (the rate is continuous),
    the acceleration is piecewise linear and bounded, and the interpolant does not overshoot
    between samples (a monotone stretch of the table stays monotone).  The slopes at the first
    and last sample are zero: the actuator holds s_0 before the table and s_n after it, so the
    rate is continuous there too.

    ``max_rate`` and ``max_accel`` (with the times where they occur) are the interpolant's
    largest |v| and |a|, exact: a is linear on every piece (its extremes at the samples), v
    quadratic (its extremes at the samples or at the vertex inside a piece)."""

    sign = 1
    t_start = 0.0

    def __init__(self, t, s):
        from scipy.interpolate import CubicHermiteSpline, PchipInterpolator
        t = np.asarray(t, dtype=float)
        s = np.asarray(s, dtype=float)
        if t.ndim != 1 or t.shape != s.shape or t.size < 2:
            raise SceneError(f"table: {t.size} times and {s.size} positions; allowed: two or "
                             "more rows of (time, position)")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(s))):
            raise SceneError("table: a time or position is not finite (NaN/inf not allowed)")
        bad = np.nonzero(np.diff(t) <= 0)[0]
        if bad.size:
            k = int(bad[0])
            raise SceneError(f"table: time {t[k + 1]:g} s at row {k + 1} does not increase "
                             f"after {t[k]:g} s (allowed: strictly increasing times)")
        slopes = (PchipInterpolator(t, s).derivative()(t) if t.size > 2
                  else np.full(2, (s[1] - s[0]) / (t[1] - t[0])))
        slopes[0] = slopes[-1] = 0.0
        self._spline = CubicHermiteSpline(t, s, slopes)
        self._d = [self._spline.derivative(k) for k in (1, 2, 3)]
        self.t_table, self.s_table = t, s
        self.s0 = float(s[0])
        # largest |a|: at the ends of the pieces (one-sided values)
        c = self._spline.c                      # (4, pieces): s = c0 dt^3 + c1 dt^2 + c2 dt + c3
        h = np.diff(t)
        a_left, a_right = 2 * c[1], 6 * c[0] * h + 2 * c[1]
        ends = np.concatenate([a_left, a_right])
        k = int(np.argmax(np.abs(ends)))
        self.max_accel = float(abs(ends[k]))
        self.t_max_accel = float(t[k] if k < h.size else t[k - h.size + 1])
        # largest |v|: at the samples or at the vertex of a piece's quadratic rate
        cand_t = list(t)
        with np.errstate(divide="ignore", invalid="ignore"):
            tv = -c[1] / (3 * c[0])
        for i in range(h.size):
            if c[0, i] != 0 and 0 < tv[i] < h[i]:
                cand_t.append(t[i] + tv[i])
        cand_t = np.array(cand_t)
        vv = np.abs(self._d[0](cand_t))
        k = int(np.argmax(vv))
        self.max_rate, self.t_max_rate = float(vv[k]), float(cand_t[k])

    @property
    def t_end(self) -> float:
        return float(self.t_table[-1])

    def _unit(self, tl):
        tl = np.asarray(tl, dtype=float)
        tc = np.clip(tl, self.t_table[0], self.t_table[-1])
        inside = (tl >= self.t_table[0]) & (tl <= self.t_table[-1])
        s = self._spline(tc) - self.s0
        v, a, j = (np.where(inside, d(tc), 0.0) for d in self._d)
        return s, v, a, j

    def _unit_scalar(self, tl):
        """_unit of one time: the cubic piece that holds it, evaluated by Horner's rule."""
        t = self.t_table
        if tl <= t[0] or tl >= t[-1]:
            return float(self._spline(min(max(tl, t[0]), t[-1])) - self.s0), 0.0, 0.0, 0.0
        i = bisect.bisect_right(t, tl) - 1
        c0, c1, c2, c3 = self._spline.c[:, i]
        x = tl - t[i]
        return (float(((c0 * x + c1) * x + c2) * x + c3 - self.s0),
                float((3 * c0 * x + 2 * c1) * x + c2), float(6 * c0 * x + 2 * c1), float(6 * c0))


def read_table_csv(path) -> tuple[np.ndarray, np.ndarray]:
    """(t, s) of a CSV file of two columns, time (s) and position; a first line that is not
    numeric is a header, and lines starting with '#' are comments."""
    rows = []
    with open(path, encoding="utf-8") as f:
        for i, line in enumerate(f):
            text = line.strip()
            if not text or text.startswith("#"):
                continue
            parts = [x.strip() for x in text.replace(";", ",").split(",")]
            try:
                vals = [float(x) for x in parts]
            except ValueError:
                if not rows:
                    continue                      # the header
                raise SceneError(f"{path}: line {i + 1} is not two numbers: {text!r}") from None
            if len(vals) != 2:
                raise SceneError(f"{path}: line {i + 1} has {len(vals)} columns; allowed: two "
                                 "(time s, position)")
            rows.append(vals)
    if len(rows) < 2:
        raise SceneError(f"{path}: {len(rows)} rows of (time, position); allowed: two or more")
    a = np.array(rows)
    return a[:, 0], a[:, 1]


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
