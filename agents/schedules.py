"""Scripted extraction schedules driven through the same Gymnasium env as the PPO policy.

Every schedule is a stroke-rate profile v(t) (m/s) of the telescopic cylinder.  The env takes a
piecewise-constant acceleration per control step dt, so a schedule is turned into actions by
the *mean* acceleration of each step, a_k = (v(t_{k+1}) - v(t_k)) / dt: the env's stroke rate then
equals v(t) exactly at every step boundary and the stroke is the trapezoidal integral of v (its
error is O(dt^2) times the jump of dv/dt across a kink; zero for the C^1 cubic).

Schedules (all extract 2 -> 8 m, i.e. travel 6 m; times in s):

* ``cubic``: the paper's schedule (Zhao-Qi-Wang 2024 Sec. 9, docs/model.md#input-drive):
  smoothstep ramp 0 -> 0.5 m/s in 4 s, hold to 12 s, mirrored ramp-down to rest at 16 s
  (``sim_core.profiles.CubicSmoothstepSchedule``).
* ``trapezoid``: the same duration (16 s), top speed and travel with constant accelerations:
  V (D - t_a) = travel gives t_a = 4 s, a = +-0.125 m/s^2.
* ``zv_trapezoid``: a zero-vibration (ZV) input shaper (Singer & Seering 1990) applied to a
  shorter trapezoid so that the shaped command has the same 16 s duration: the base command is
  convolved with two impulses A_1 = 1 / (1 + K), A_2 = K / (1 + K) at 0 and T_d / 2,
  K = exp(-zeta pi / sqrt(1 - zeta^2)), T_d = 2 pi / omega_d, tuned to the first in-plane
  bending mode of the full sim_core model at the *target* stroke (the modal tables,
  ``sim_core.rom``: 0.43 Hz, zeta 0.7 % at L_s = 8 m with 25 t).  The residual vibration after the stop is
  the response of the mode at the end of the motion, so that is the frequency to cancel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from sim_core.profiles import CubicSmoothstepSchedule

V_MAX = 0.5          # m/s, docs/model.md#input-drive
DURATION = 16.0      # s, end of the paper's cubic schedule
TRAVEL = 6.0         # m, 2 -> 8 m


@dataclass(frozen=True)
class RateSchedule:
    """A scripted stroke-rate profile v(t) (m/s, signed) ending at rest at ``t_end`` (s)."""

    name: str
    rate: Callable[[float], float]
    t_end: float

    def actions(self, dt: float, a_max: float, n_steps: int) -> np.ndarray:
        """Normalised env actions (n_steps,): mean acceleration of every step / a_max."""
        t = dt * np.arange(n_steps + 1)
        v = np.array([self.rate(tk) for tk in t])
        a = np.diff(v) / dt / a_max
        if np.max(np.abs(a)) > 1.0 + 1e-9:
            raise ValueError(f"schedule {self.name!r} needs |a| = {np.max(np.abs(a)) * a_max:.3g} "
                             f"m/s^2 > a_max = {a_max:g} m/s^2")
        return np.clip(a, -1.0, 1.0)


def cubic(v_max: float = V_MAX, t_ramp: float = 4.0, t_hold_end: float = 12.0,
          sign: int = 1) -> RateSchedule:
    """The paper's smoothstep schedule (Zhao-Qi-Wang 2024 Sec. 9; docs/model.md#input-drive)."""
    s = CubicSmoothstepSchedule(v_max=v_max, t_ramp=t_ramp, t_hold_end=t_hold_end, sign=sign)
    return RateSchedule("cubic", lambda t: float(s.rate(t)), s.t_end)


def trapezoid_rate(v_max: float, travel: float, duration: float) -> Callable[[float], float]:
    """Rate of the constant-acceleration trapezoid of top speed v_max (m/s) covering ``travel``
    (m) in ``duration`` (s): ramp time t_a = duration - travel / v_max."""
    t_a = duration - travel / v_max
    if not 0 < t_a <= duration / 2:
        raise ValueError(f"trapezoid: travel {travel} m in {duration} s at {v_max} m/s needs "
                         f"ramp time {t_a:.3g} s; allowed (0, duration/2]")

    def v(t: float) -> float:
        if t <= 0 or t >= duration:
            return 0.0
        return v_max * min(t / t_a, 1.0, (duration - t) / t_a)
    return v


def trapezoid(v_max: float = V_MAX, travel: float = TRAVEL, duration: float = DURATION) -> RateSchedule:
    return RateSchedule("trapezoid", trapezoid_rate(v_max, travel, duration), duration)


def zv_impulses(omega: float, zeta: float) -> tuple[np.ndarray, np.ndarray]:
    """ZV shaper (Singer & Seering 1990): impulse times (s) and amplitudes for a mode of
    natural frequency omega (rad/s) and damping ratio zeta."""
    wd = omega * math.sqrt(1.0 - zeta * zeta)
    K = math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta * zeta))
    return np.array([0.0, math.pi / wd]), np.array([1.0, K]) / (1.0 + K)


def first_mode(payload: float = 25000.0, angle_deg: float = 60.0, stroke: float = 8.0):
    """(omega rad/s, zeta) of the first in-plane mode of the full model at piston length
    ``stroke`` (m), from the modal tables (sim_core.rom)."""
    from sim_core.rom import tables_for
    c = tables_for(payload, angle_deg, 1).coefficients(stroke)
    return float(c[0, 0]), float(c[1, 0])


def zv_trapezoid(v_max: float = V_MAX, travel: float = TRAVEL, duration: float = DURATION,
                 payload: float = 25000.0, angle_deg: float = 60.0,
                 stroke_target: float = 8.0) -> RateSchedule:
    """ZV-shaped trapezoid of total duration ``duration`` (s): base trapezoid of duration
    duration - T_d/2, convolved with the ZV impulses of the first mode at the target stroke."""
    omega, zeta = first_mode(payload, angle_deg, stroke_target)
    times, amps = zv_impulses(omega, zeta)
    base = trapezoid_rate(v_max, travel, duration - times[-1])

    def v(t: float) -> float:
        return float(sum(A * base(t - ti) for ti, A in zip(times, amps)))
    return RateSchedule("zv_trapezoid", v, duration)


NAMES = ("cubic", "trapezoid", "zv_trapezoid")      # report order


def by_name(name: str, payload: float = 25000.0, angle_deg: float = 60.0) -> RateSchedule:
    """The scripted baseline called ``name`` (one of ``NAMES``; the ZV shaper is tuned to the
    payload kg and luffing angle deg)."""
    if name == "cubic":
        return cubic()
    if name == "trapezoid":
        return trapezoid()
    if name == "zv_trapezoid":
        return zv_trapezoid(payload=payload, angle_deg=angle_deg)
    raise ValueError(f"schedule = {name!r}: allowed {list(NAMES)}")


def all_schedules(payload: float = 25000.0, angle_deg: float = 60.0) -> list[RateSchedule]:
    """The scripted baselines of the comparison, in report order."""
    return [by_name(n, payload, angle_deg) for n in NAMES]
