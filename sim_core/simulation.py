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
after which the actuator keeps its rate (:mod:`sim_core.commands`).  Every commanded motion is
checked over each step against the actuator's limits of the scene (acceleration, rate, end
stops): beyond them ``advance`` raises, or with ``Simulation(scene, limits="clip")`` the drive
stops at its limits.  Frames, units and signs of the outputs, the limits and the errors of bad
input: docs/stepping.md.

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
from sim_core.errors import CommandError, SceneError
from sim_core.registry import kind_name, system_kind

__all__ = ["Simulation", "Command"]

#: the modes of ``Simulation(scene, limits=...)``
LIMIT_MODES = ("raise", "clip")


class Simulation:
    """A scene's model, advanced step by step (module docstring).

    ``scene``: a validated scene (:func:`sim_core.load_scene`), or a scene's name or file path,
    which is loaded with ``load_scene``.  ``limits``: what a command beyond an actuator's limit
    does (acceleration, rate, end stops: :func:`sim_core.systems.telescopic.stepping.
    actuator_limits`): ``"raise"`` (default) raises :class:`sim_core.errors.ActuatorLimitError`
    naming the actuator, the value and the allowed range before the step starts; ``"clip"``
    runs the motion the drive makes at its limits (the acceleration cut, the rate held at its
    limit, an inelastic stop at an end stop) and records in :attr:`clipped` which limits each
    actuator hit in the last advance.

    ``actuators``: the names ``advance`` accepts in its commands; ``t``: the simulated time, s;
    ``limits``: {actuator: its limits in SI units}."""

    def __init__(self, scene: dict | str, limits: str = "raise"):
        if isinstance(scene, str):                  # as sim_core.load_scene(scene)
            from sim_core.scene.io import read_scene
            raw, source = read_scene(scene)
            scene = system_kind(raw).validate(raw, source)
        if not isinstance(scene, dict):
            raise CommandError(f"scene = {scene!r:.80}: a scene dict from sim_core.load_scene, or "
                               "a scene's name or file path")
        if not isinstance(limits, str) or limits not in LIMIT_MODES:
            raise CommandError(f"limits = {limits!r}: allowed {', '.join(map(repr, LIMIT_MODES))}")
        kind = system_kind(scene)
        if not hasattr(kind, "stepper"):
            raise SceneError(f"kind = {kind_name(scene)!r}: the stepping API supports the "
                             "telescopic kind (allowed: kind = 'telescopic')")
        try:
            self._impl = kind.stepper(scene)
        except (KeyError, TypeError) as exc:
            raise CommandError(f"scene: not a validated scene ({type(exc).__name__}: {exc}); "
                               "load it with sim_core.load_scene") from exc
        self._impl.limit_mode = limits
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

    @property
    def limits(self) -> dict:
        """{actuator: :class:`sim_core.systems.telescopic.stepping.ActuatorLimits`}: its
        acceleration, rate and end stops in SI units (m or rad) and the scene keys they come
        from."""
        return dict(self._impl.limits)

    @property
    def clipped(self) -> dict:
        """{actuator: the limits its command hit in the last advance ("acceleration", "rate",
        "position", "rate jump")}: the actuators ``limits="clip"`` held to their limits; empty
        where none was."""
        return dict(self._impl.clipped)

    def advance(self, dt: float, commands: dict | None = None, *,
                max_wall_s: float | None = None) -> None:
        """Integrate over dt (s); ``commands``: {actuator: acceleration (m/s^2 or rad/s^2) or
        :class:`Command`}, or None.  ``max_wall_s`` (s): a wall-clock budget of this advance
        (the smaller of it and the scene's solver.max_wall_s holds); past it the integration
        stops with a SimulationError.

        Bad input raises a :class:`sim_core.errors.CommandError` (a ValueError) naming the
        argument: an unknown actuator an :class:`sim_core.errors.UnknownNameError` (also a
        KeyError), a command beyond an actuator's limit with ``limits="raise"`` an
        :class:`sim_core.errors.ActuatorLimitError`; a failed solve or an exhausted budget a
        SimulationError with the time and the reason.  After any error the simulation is as
        before the call (its time, state and actuators' plans; only the solvers' warm starts
        may have moved)."""
        self._impl.advance(dt, commands, max_wall_s=max_wall_s)

    def outputs(self, names=None) -> dict:
        """The scene's outputs at the current time (SI units), ``time`` and every actuator's
        (position, rate, acceleration) under ``actuators``.  ``names`` (optional): only these
        outputs; for the full model, names among ``time``, ``actuators``, ``tip_position``,
        ``tip_velocity``, ``telescopic_stroke`` (the stages' L_s and L_s': with
        ``effects.oil_column`` they lag the commanded piston of ``actuators``) and, with a
        swinging payload, ``payload_position``, ``payload_velocity``, ``sway_angle``,
        ``sway_rate`` skip the forces and the contact solution (with them ``slew_torque``
        costs one solve of the multipliers).  The drives' forces:
        ``telescopic_cylinder_force``, ``drive_forces``, ``luffing_cylinder_force``,
        ``slew_torque`` and ``hoist_rope_force`` where the scene has them.  Frames, units and
        signs: docs/stepping.md.  :class:`sim_core.errors.UnknownNameError` (a KeyError) for a
        name the scene does not output."""
        if names is not None and (isinstance(names, (str, bytes))
                                  or not hasattr(names, "__iter__")):
            raise CommandError(f"names = {names!r}: a sequence of output names (e.g. "
                               "['tip_position']) or None")
        return self._impl.outputs(names)

    def save_state(self) -> dict:
        """A snapshot of everything the future of the run depends on (picklable)."""
        return self._impl.save_state()

    def restore_state(self, state: dict) -> None:
        """Return to a snapshot of :meth:`save_state` (of this simulation's scene);
        :class:`sim_core.errors.CommandError` for anything else (nothing is changed then)."""
        self._impl.restore_state(state)
