"""Actuator commands of the stepping API (:class:`sim_core.Simulation`), SI units.

A :class:`Command` is an actuator's motion from the start of an ``advance`` on: a list of
segments (acceleration, duration, velocity jump at its end), each of constant acceleration, the
position and rate continuous within a segment and the rate jumping by the segment's jump at its
end (an inelastic end stop: the jump -v brings the rate to 0).  After the last segment the
actuator keeps its rate (zero acceleration) until the next command.  ``Command.accelerate(a)``
is the constant acceleration a from then on (the plain float command ``{name: a}``).

A rate jump is exact in the actuator's kinematics; the full model follows it through its
drive constraint's stabilisation (:mod:`sim_core.systems.telescopic.stepping`).

``end`` (optional): the position and rate the actuator has at the end of the ``advance``, as
the caller's own kinematics have them (e.g. clamped exactly onto an end stop).  They replace the
segments' state there (a difference of round-off only: more than 1e-9 (1 + |x|) raises
CommandError, a ValueError) and the actuator coasts on from them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sim_core.errors import CommandError

__all__ = ["Command"]

#: the largest difference (relative to 1 + |x|) between ``Command.end`` and the segments' state
END_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Command:
    """An actuator's piecewise-constant acceleration history from the start of an advance
    (module docstring).  ``segments``: ((acceleration m/s^2 or rad/s^2, duration s >= 0 (inf
    for the last: held on), velocity jump m/s or rad/s at its end), ...); ``end``: (position,
    rate) at the end of the advance, or None."""

    segments: tuple[tuple[float, float, float], ...]
    end: tuple[float, float] | None = None

    def __post_init__(self):
        try:
            segs = tuple(tuple(float(x) for x in s) for s in self.segments)
        except (TypeError, ValueError):
            raise CommandError(f"segments = {self.segments!r}: a sequence of (acceleration, "
                             "duration, velocity jump) numbers") from None
        if not segs:
            raise CommandError("segments = (): at least one (acceleration, duration, velocity "
                             "jump) segment")
        for i, s in enumerate(segs):
            if len(s) != 3:
                raise CommandError(f"segments[{i}] = {s!r}: (acceleration, duration, velocity "
                                 "jump), three numbers")
            a, tau, jump = s
            last = i == len(segs) - 1
            if not (math.isfinite(a) and math.isfinite(jump)):
                raise CommandError(f"segments[{i}] = {s!r}: acceleration and velocity jump must "
                                 "be finite")
            if not (tau >= 0.0 and (math.isfinite(tau) or last)):
                raise CommandError(f"segments[{i}] duration = {tau!r} s: allowed [0, inf) "
                                 "(inf only for the last segment)")
            if math.isinf(tau) and jump != 0.0:
                raise CommandError(f"segments[{i}] = {s!r}: an endless segment has no velocity "
                                 "jump at its end")
        object.__setattr__(self, "segments", segs)
        if self.end is not None:
            try:
                end = tuple(float(x) for x in self.end)
            except (TypeError, ValueError):
                end = ()
            if len(end) != 2 or not all(math.isfinite(x) for x in end):
                raise CommandError(f"end = {self.end!r}: (position, rate), two finite numbers")
            object.__setattr__(self, "end", end)

    @classmethod
    def accelerate(cls, acceleration: float) -> Command:
        """The constant acceleration (m/s^2 or rad/s^2) from the advance's start on."""
        return cls(((float(acceleration), math.inf, 0.0),))

    def motion(self, s0: float, v0: float, t: float) -> tuple[float, float, float]:
        """(position, rate, acceleration) at time t (s) after the start, from position s0 and
        rate v0 there: the segments' exact kinematics (a rate jump counts from just after its
        segment's end), then the last rate held."""
        L, v = s0, v0
        for a, tau, jump in self.segments:
            if t <= tau:
                return (L + v * t + 0.5 * a * t * t, v + a * t, a)
            L, v, t = L + v * tau + 0.5 * a * tau * tau, v + a * tau + jump, t - tau
        return (L + v * t, v, 0.0)

    def pieces(self, dt: float) -> tuple[list[tuple[float, float, float]], Command | None]:
        """The segments over [0, dt] (s) as (acceleration, duration, jump) pieces, and the
        command for what follows dt (None: coast).  A segment that ends within round-off of dt
        (1e-12 (1 + dt)) is taken whole with its jump; a zero-duration piece is kept (a jump
        alone); a gap of more than round-off after the last segment is a coasting piece."""
        tol = 1e-12 * (1.0 + dt)
        out: list[tuple[float, float, float]] = []
        left = dt
        segs = list(self.segments)
        while segs:
            a, tau, jump = segs[0]
            if left <= tol and tau > tol:
                break
            if tau <= left + tol:
                out.append((a, tau, jump))
                segs.pop(0)
                left -= tau
            else:
                out.append((a, left, 0.0))
                segs[0] = (a, tau - left, jump)
                left = 0.0
        if left > tol:
            out.append((0.0, left, 0.0))
        return out, (Command(tuple(segs)) if segs else None)

    def check_end(self, s: float, v: float) -> None:
        """CommandError (a ValueError) unless ``end`` agrees with the segments' state (s, v) at
        the advance's end to END_TOLERANCE (1 + |x|)."""
        if self.end is None:
            return
        for name, want, got in (("position", self.end[0], s), ("rate", self.end[1], v)):
            if abs(want - got) > END_TOLERANCE * (1.0 + abs(got)):
                raise CommandError(f"end {name} = {want!r} differs from the segments' {got!r} by "
                                 f"more than round-off ({END_TOLERANCE:g} (1 + |x|))")
