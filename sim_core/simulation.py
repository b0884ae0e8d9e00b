"""The stepping API: a simulation built from a scene, advanced by external actuator commands
and queried for its state and outputs, for co-simulation, controller-in-the-loop work and the
Gymnasium environments.

    from sim_core import Command, Simulation, load_scene
    sim = Simulation(load_scene("telescopic_extraction"))
    sim.advance(0.05, {"telescopic": 0.1})     # 50 ms with the stages accelerating at 0.1 m/s^2
    out = sim.outputs()                         # tip_position, forces, ... at sim.t
    tip = sim.outputs(["tip_position", "tip_velocity"])   # only these (cheaper)
    snapshot = sim.save_state()                 # everything the future depends on
    sim.restore_state(snapshot)                 # and back: the run repeats to round-off

    # a piecewise stroke history within one step: 30 ms at 0.2 m/s^2, then 20 ms at 0 with the
    # rate brought to 0 at its end (an inelastic end stop)
    sim.advance(0.05, {"telescopic": Command(((0.2, 0.03, 0.0), (0.0, 0.02, -0.506)))})

An actuator without a command follows its scene profile; a command takes it over from then on:
a number is the actuator's acceleration (m/s^2 or rad/s^2) held from the step's start on, a
:class:`sim_core.Command` a list of segments (acceleration, duration, rate jump at its end),
after which the actuator keeps its rate (:mod:`sim_core.commands`).

Fidelities (the system kinds that offer a ``stepper(scene)``; today the telescopic crane):

* the full model (``model.reduction = "none"``, flexible booms): every actuator of the scene
  (``telescopic``, ``luffing``, and ``slew`` and ``hoist`` where the scene has them), each
  ``advance`` integrated with the scene's [solver] settings from the current state;
* the modal reduced-order model (``model.reduction = "modal"``, e.g. the scene
  ``telescopic_extraction_rl``): the ``telescopic`` actuator; its outputs are the tip's
  position, velocity, deflection and deflection rate from the static tip at the current
  stroke, the stroke and the modal coordinates and rates
  (:class:`sim_core.systems.telescopic.stepping.ModalStepper`).
"""

from __future__ import annotations

from sim_core.commands import Command
from sim_core.errors import SceneError
from sim_core.registry import kind_name, system_kind

__all__ = ["Simulation", "Command"]


class Simulation:
    """A scene's model, advanced step by step (module docstring).

    ``actuators``: the names ``advance`` accepts in its commands; ``t``: the simulated time, s."""

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

    @property
    def system(self):
        """The assembled system the simulation advances (the full model's ``TelescopicSystem``
        with its ``model``, or the ROM's tables), for diagnostics: its attributes are sim_core
        internals, not part of the stable API."""
        impl = self._impl
        return impl.ts if hasattr(impl, "ts") else impl.tables

    @property
    def stats(self) -> dict:
        """The integrations' work since the start (the full model: ``n_steps``, ``n_rhs``,
        ``n_jacobians`` summed over the advances; the ROM's closed-form steps: empty).  Not
        part of the snapshot."""
        return dict(self._impl.stats)

    def advance(self, dt: float, commands: dict | None = None) -> None:
        """Integrate over dt (s); ``commands``: {actuator: acceleration (m/s^2 or rad/s^2) or
        :class:`Command`}.  Bad commands raise KeyError (no such actuator) or ValueError naming
        the actuator; a failed solve raises SimulationError with the time and the reason."""
        self._impl.advance(dt, commands)

    def outputs(self, names=None) -> dict:
        """The scene's outputs at the current time (SI units), ``time`` and every actuator's
        (position, rate, acceleration) under ``actuators``.  ``names`` (optional): only these
        outputs; for the full model, names among ``time``, ``actuators``, ``tip_position``,
        ``tip_velocity``, ``telescopic_stroke`` (the stages' L_s and L_s': with
        ``effects.oil_column`` they lag the commanded piston of ``actuators``) and, with a
        swinging payload, ``payload_position``, ``payload_velocity``, ``sway_angle``,
        ``sway_rate`` skip the forces and the contact solution.  KeyError for a name the scene does not output."""
        return self._impl.outputs(names)

    def save_state(self) -> dict:
        """A snapshot of everything the future of the run depends on (picklable)."""
        return self._impl.save_state()

    def restore_state(self, state: dict) -> None:
        """Return to a snapshot of :meth:`save_state` (of this simulation's scene)."""
        self._impl.restore_state(state)
