"""Public drive profiles (SI units): the stroke histories the scenes use, for scripted
controllers and references.

* :class:`CubicSmoothstepSchedule`: the paper's smoothstep ramp-up / hold / ramp-down of the
  stroke rate (Zhao-Qi-Wang 2024 Section 9, docs/model.md#input-drive): ``stroke(t)``,
  ``rate(t)``, ``accel(t)``, ``sample(t)`` -> :class:`MotionSample` (s, v, a, j).

These names are stable; the module behind them (``sim_core.physics.drive_profiles``) is not.
"""

from sim_core.physics.drive_profiles import CubicSmoothstepSchedule, MotionSample

__all__ = ["CubicSmoothstepSchedule", "MotionSample"]
