"""The stepping API: a simulation built from a scene, advanced by external actuator commands
and queried for its state and outputs, for co-simulation, controller-in-the-loop work and the
Gymnasium environments.

    from sim_core import Simulation, load_scene
    sim = Simulation(load_scene("telescopic_extraction"))
    sim.advance(0.05, {"telescopic": 0.1})     # 50 ms with the stages accelerating at 0.1 m/s^2
    out = sim.outputs()                         # tip_position, forces, ... at sim.t
    snapshot = sim.save_state()                 # everything the future depends on
    sim.restore_state(snapshot)                 # and back: the run repeats to round-off

An actuator without a command follows its scene profile; a command (its acceleration, held
over the step) takes it over from then on.  The system kinds that offer a ``stepper(scene)``
support it (today: the telescopic crane's full model).
"""

from __future__ import annotations

from sim_core.errors import SceneError
from sim_core.registry import kind_name, system_kind

__all__ = ["Simulation"]


class Simulation:
    """A scene's model, advanced step by step (module docstring).

    ``actuators``: the names ``advance`` accepts in its commands (telescopic, luffing, and
    slew and hoist where the scene has them); ``t``: the simulated time, s."""

    def __init__(self, scene: dict):
        kind = system_kind(scene)
        if not hasattr(kind, "stepper"):
            raise SceneError(f"kind = {kind_name(scene)!r}: the stepping API supports the "
                             "telescopic kind (allowed: kind = 'telescopic')")
        self._impl = kind.stepper(scene)
        self.scene = scene

    @property
    def t(self) -> float:
        return self._impl.t

    @property
    def actuators(self) -> tuple[str, ...]:
        return tuple(self._impl.drives)

    def advance(self, dt: float, commands: dict | None = None) -> None:
        """Integrate over dt (s); ``commands``: {actuator: acceleration (m/s^2 or rad/s^2)}.
        A failed solve raises SimulationError with the time and the reason."""
        self._impl.advance(dt, commands)

    def outputs(self) -> dict:
        """The scene's outputs at the current time (SI units), ``time`` and every actuator's
        (position, rate, acceleration)."""
        return self._impl.outputs()

    def save_state(self) -> dict:
        """A snapshot of everything the future of the run depends on (picklable)."""
        return self._impl.save_state()

    def restore_state(self, state: dict) -> None:
        """Return to a snapshot of :meth:`save_state` (of this simulation's scene)."""
        self._impl.restore_state(state)
