"""The telescopic crane advanced step by step (the stepping API of :class:`sim_core.Simulation`).

Two steppers, chosen by the scene's ``model.reduction``:

* ``"none"`` (:class:`TelescopicStepper`): the full model, built from the scene and brought to
  its static equilibrium as ``simulate`` does.  Every actuator the scene has (the telescopic
  stages, the luffing cylinder, the slewing drive where the scene slews, the hoist where the
  payload swings) is a :class:`Drive`: it follows its scene profile until a command takes it
  over.  Each ``advance`` integrates the model over [t, t + dt] with the scene's solver
  settings; the model's drives read the time relative to the step's start (a clock the stepper
  moves), so the integrator starts at 0 for every step.  With ``solver.method = "ROS2"`` one
  :class:`sim_core.integrate.rosenbrock.RosenbrockW2` serves every step and keeps its Jacobian
  from step to step (part of the saved state).
* ``"modal"`` (:class:`ModalStepper`): the stroke-parametric modal ROM
  (:mod:`sim_core.systems.telescopic.modal`) of the scene's crane, payload and luffing angle;
  one actuator, the telescopic stroke L_s.  Without a command it follows the scene's drive
  profile on the piecewise-constant mean accelerations of ``simulate_modal`` (sub-steps of at
  most 0.05 s), so stepping reproduces the scene's run.

A command (:class:`sim_core.commands.Command`, or a float: the constant acceleration from then
on) sets the actuator's acceleration history from the step's start: segments of constant
acceleration with a rate jump at each one's end, the position and rate continuous otherwise.
In the ROM a rate jump dv of the stroke gives the modal velocity jump dq' = -Gamma(L_s) dv of
q'' = -Gamma a (the impulse of the stroke acceleration, modal module docstring).  In the full
model an actuator is a constraint on the state: a rate jump changes its target, and the
constraint's Baumgarte stabilisation (``Model.baumgarte``, xi = 10 1/s, second seed Eq. 8)
brings the model's velocity to it within a few 0.1 s (no impulse is applied to the state).

Before each step every commanded actuator's motion over the step is held to its limits
(:func:`actuator_limits`, :func:`limited`): ``limit_mode`` "raise" refuses a command beyond
them, "clip" replaces the step's part of it by the motion of a drive at its limits.

``save_state`` returns everything the future of the run depends on (time, the integrated
state, every drive's mode and plan, the friction's warm starts); ``restore_state`` puts it
back, and the restored run repeats the original one to round-off.
"""

from __future__ import annotations

import copy
import math
import time
from dataclasses import dataclass

import numpy as np

from sim_core.commands import Command
from sim_core.errors import (ActuatorLimitError, CommandError, SceneError, SimulationError,
                             UnknownNameError, WallBudgetExhausted)
from sim_core.physics.drive_profiles import MotionSample

#: the command names of the actuators, in the scene's tables
ACTUATOR_TABLES = {"telescopic": "drive", "luffing": "luffing_drive", "slew": "slew_drive",
                   "hoist": "hoist_drive"}

#: outputs of :meth:`TelescopicStepper.outputs` that need neither the multipliers nor the
#: contact solution (``outputs(names)`` with only these skips the rest)
LIGHT_OUTPUTS = ("time", "actuators", "tip_position", "tip_velocity", "payload_position",
                 "payload_velocity", "sway_angle", "sway_rate", "telescopic_stroke")


def stepper_for(scene: dict):
    """The stepper of a validated telescopic scene: the modal ROM's or the full model's."""
    if scene.get("model", {}).get("reduction", "none") == "modal":
        return ModalStepper(scene)
    return TelescopicStepper(scene)


def as_command(name: str, value) -> Command:
    """A command value (a Command, or a number: the constant acceleration) as a Command;
    CommandError naming the actuator for anything else."""
    if isinstance(value, Command):
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise CommandError(f"commands[{name!r}] = {value!r}: an acceleration (a number) or a "
                           "sim_core.Command")
    if not math.isfinite(value):
        raise CommandError(f"commands[{name!r}] = {value!r}: must be a finite acceleration")
    return Command.accelerate(float(value))


def _check_commands(commands, names) -> dict[str, Command]:
    if commands is None:
        return {}
    if not isinstance(commands, dict):
        raise CommandError(f"commands = {commands!r}: a dict {{actuator: acceleration or "
                           f"sim_core.Command}} (actuators: {', '.join(sorted(names))}) or None")
    out = {}
    for name, value in commands.items():
        if not isinstance(name, str) or name not in names:
            raise UnknownNameError(f"commands[{name!r}]: no such actuator in this scene "
                                   f"(allowed: {', '.join(sorted(names))})")
        out[name] = as_command(name, value)
    return out


def _check_dt(dt) -> float:
    if isinstance(dt, bool) or not (isinstance(dt, (int, float, np.floating, np.integer))
                                    and dt > 0 and math.isfinite(dt)):
        raise CommandError(f"dt = {dt!r} s: allowed (0, inf)")
    return float(dt)


# -- actuator limits ---------------------------------------------------------------------------
@dataclass(frozen=True)
class ActuatorLimits:
    """An actuator's limits in SI units (m or rad): |acceleration| <= ``accel`` (per s^2),
    |rate| <= ``rate`` (per s), position in [``lo``, ``hi``] (its end stops); ``sources``: the
    scene key or rule each of the three comes from (for the messages)."""

    accel: float
    rate: float
    lo: float
    hi: float
    unit: str
    sources: tuple[str, str, str]


def actuator_limits(scene: dict, params, name: str, stroke_range=None) -> ActuatorLimits:
    """The limits of actuator ``name`` from the scene's actuator table (``ACTUATOR_TABLES``):

    * acceleration: ``max_accel`` where the table states it, else the trapezoid profile's
      ``a_max``, else the largest ``max_accel`` a scene may state (the schema's bound);
    * rate: ``max_rate``, else the trapezoid profile's ``v_max``, else the schema's bound of
      ``max_rate``;
    * position (end stops): the telescopic stage length 0 < L_s < the shortest boom length less
      the slider width (the sliders fit their overlap; for the modal ROM also within the
      tables' stroke grid ``stroke_range``), the luffing angle [0, 85] deg, the slew angle
      [-3600, 3600] deg, the hoist rope at least 0.1 m: the ranges the scene's profiles are
      validated against (the table's position column).

    Degrees of the luffing and slewing tables are converted to rad."""
    from sim_core.systems.telescopic.schema import ACTUATOR_TABLES as TABLES
    key = ACTUATOR_TABLES[name]
    d, fields = scene.get(key, {}), {f.key: f for f in TABLES[key].fields}
    k = math.pi / 180.0 if fields["travel"].unit == "deg" else 1.0
    trap = d.get("profile") == "trapezoid"
    bound = []
    for lim, prof in (("max_accel", "a_max"), ("max_rate", "v_max")):
        if lim in d:
            bound.append((k * d[lim], f"{key}.{lim}"))
        elif trap and prof in d:
            bound.append((k * d[prof], f"{key}.{prof} (trapezoid profile)"))
        else:
            bound.append((k * fields[lim].hi, f"the largest {key}.{lim} a scene may state"))
    if name == "telescopic":
        lo = 0.0
        hi = min(params.lengths) - max(o.slider_width for o in params.overlaps)
        where = "0 < L_s < the shortest boom length less the slider width"
        if stroke_range is not None:
            lo, hi = max(lo, stroke_range[0]), min(hi, stroke_range[1])
            where += " and within the modal tables' stroke range"
    else:
        lo, hi = (k * x for x in fields["table"].columns[1][:2])
        where = f"the position range of {key}"
    unit = "rad" if k != 1.0 else "m"
    return ActuatorLimits(bound[0][0], bound[1][0], lo, hi, unit,
                          (bound[0][1], bound[1][1], where))


def _window(cmd: Command, s0: float, v0: float, tau0: float, dt: float):
    """A command's motion over [tau0, tau0 + dt] (times after its start, where it was at (s0,
    v0)): the state at tau0, the (acceleration, duration, rate jump) pieces of the window and
    the command for what follows it (None: coast)."""
    rest, s, v = cmd, s0, v0
    if tau0 > 0.0:
        before, rest = cmd.pieces(tau0)
        for a, tau, jump in before:
            s, v = s + v * tau + 0.5 * a * tau * tau, v + a * tau + jump
    pieces, after = (rest or _COAST).pieces(dt)
    return s, v, pieces, after


def _reach(s: float, v: float, a: float, b: float) -> float:
    """The first time t >= 0 at which s + v t + a t^2 / 2 = b (the motion reaches b; b lies
    within its range over the piece)."""
    c = s - b
    if a == 0.0:
        return max(0.0, -c / v) if v != 0.0 else 0.0
    disc = max(v * v - 2.0 * a * c, 0.0)
    q = -(v + math.copysign(math.sqrt(disc), v if v != 0.0 else -a))
    roots = [x for x in (q / a if q != 0.0 else 0.0, (2.0 * c / q) if q != 0.0 else 0.0)
             if x >= 0.0]
    return min(roots) if roots else 0.0


def limited(name: str, lim: ActuatorLimits, s: float, v: float, pieces, clip: bool):
    """The pieces ((acceleration, duration, rate jump), ...) of an actuator's motion from (s, v)
    held to its limits: with ``clip`` False the first piece beyond a limit raises
    :class:`ActuatorLimitError`; with ``clip`` True the motion is what the drive does at its
    limits: the acceleration cut to +-accel, the rate held at +-rate once reached (the
    acceleration then 0), an end stop reached stops the actuator there (a rate jump to 0: an
    inelastic stop) and holds it while the command pushes into it, and a rate jump only brings
    the rate towards 0 (an inelastic stop; any other jump is an infinite acceleration).
    Returns (pieces, the limits hit: "acceleration", "rate", "position", "rate jump")."""
    A, V, lo, hi = lim.accel, lim.rate, lim.lo, lim.hi
    tol_a, tol_v = 1e-12 * (1.0 + A), 1e-9 * (1.0 + V)
    tol_s = 1e-9 * (1.0 + max(abs(lo), abs(hi)))
    out, hit = [], []

    def over(quantity, value, allowed, source):
        if not clip:
            raise ActuatorLimitError(
                f"commands[{name!r}]: {quantity} {value:.6g} {lim.unit}"
                f"{_PER[quantity]} beyond the limit [{allowed[0]:.6g}, {allowed[1]:.6g}] "
                f"{lim.unit}{_PER[quantity]} ({source}); command within it, or "
                "Simulation(scene, limits='clip')", name, quantity, value, allowed)
        if quantity not in hit:
            hit.append(quantity)

    work = list(pieces)
    while work:
        a, tau, jump = work.pop(0)
        if abs(v) > V + tol_v:                 # a rate beyond the limit at the piece's start
            over("rate", v, (-V, V), lim.sources[1])
            out.append((0.0, 0.0, math.copysign(V, v) - v))
            v = math.copysign(V, v)
        if abs(a) > A + tol_a:
            over("acceleration", a, (-A, A), lim.sources[0])
            a = math.copysign(A, a)
        stop = hi if a > 0.0 else lo
        if tau > 0.0 and v == 0.0 and a != 0.0 and abs(s - stop) <= tol_s:
            over("position", s + 0.5 * a * tau * tau, (lo, hi), lim.sources[2])
            a = 0.0                                       # held at the end stop
        v1 = v + a * tau
        if tau > 0.0 and abs(v1) > V + tol_v:
            over("rate", v1, (-V, V), lim.sources[1])
            t_v = min(tau, max(0.0, (math.copysign(V, a) - v) / a))
            work.insert(0, (0.0, tau - t_v, jump))        # then on at the limit rate
            tau, jump = t_v, 0.0
        # the position's range over the piece: its ends and, where the rate changes sign, the
        # turning point
        ends = [s, s + v * tau + 0.5 * a * tau * tau]
        if a != 0.0 and v * v1 < 0.0:
            ends.append(s - v * v / (2.0 * a))
        for b, beyond in ((hi, max(ends) > hi + tol_s), (lo, min(ends) < lo - tol_s)):
            if beyond:
                over("position", max(ends) if b == hi else min(ends), (lo, hi), lim.sources[2])
                t_b = min(tau, _reach(s, v, a, b))
                work.insert(0, (a, tau - t_b, jump))      # the rest, from the stop
                tau, jump = t_b, -(v + a * t_b)
                break
        v1 = v + a * tau
        top = (min(0.0, -v1), max(0.0, -v1))              # towards 0, not beyond
        if not top[0] - 1e-12 * (1.0 + abs(v1)) <= jump <= top[1] + 1e-12 * (1.0 + abs(v1)):
            over("rate jump", jump, top, "a rate jump only stops the actuator")
            jump = min(max(jump, top[0]), top[1])
        if tau > 0.0 or jump != 0.0:
            out.append((a, tau, jump))
        s, v = s + v * tau + 0.5 * a * tau * tau, v + a * tau + jump
    return out, hit


_PER = {"acceleration": "/s^2", "rate": "/s", "position": "", "rate jump": "/s"}


def held_to_limits(name: str, lim: ActuatorLimits, cmd: Command, s0: float, v0: float,
                   tau0: float, dt: float, clip: bool):
    """An actuator's command checked over the step [tau0, tau0 + dt] of it (:func:`limited`):
    (None, ()) where its motion stays within the limits, else ((s, v, command), limits hit):
    the state at the step's start and the clipped command from there (its ``end`` dropped:
    the caller's kinematics are not the clipped ones), followed by the command's rest."""
    s, v, pieces, after = _window(cmd, s0, v0, tau0, dt)
    segs, hit = limited(name, lim, s, v, pieces, clip)
    if not hit:
        return None, ()
    segs = tuple(segs) + (after.segments if after is not None else ())
    return (s, v, Command(segs) if segs else _COAST), tuple(hit)


class Drive:
    """An actuator's position s(t) (m or rad): its profile, or a command's motion from (s0, v0)
    at t0 (``plan`` = (t0, s0, v0, Command)).  ``clock[0]`` is the absolute time of the current
    step's start: the model asks at local times, ``sample(tau)`` answers for clock + tau."""

    def __init__(self, profile, clock):
        self.profile, self.clock = profile, clock
        self.plan = None               # (t0, s0, v0, Command) once commanded

    def at(self, t: float) -> MotionSample:
        """The drive at absolute time t."""
        if self.plan is None:
            return self.profile.sample(t)
        t0, s0, v0, cmd = self.plan
        return MotionSample(*cmd.motion(s0, v0, t - t0), 0.0)

    def sample(self, tau: float) -> MotionSample:
        if self.plan is None:
            return self.profile.sample(self.clock[0] + float(tau))
        t0, s0, v0, cmd = self.plan
        # the local time itself where the plan starts at this step (no round-off of clock + tau)
        return MotionSample(*cmd.motion(s0, v0, float(tau) + (self.clock[0] - t0)), 0.0)

    def command(self, t: float, cmd: Command) -> None:
        """From absolute time t on, the command's motion (position and rate continuous)."""
        smp = self.at(t)
        self.plan = (float(t), float(smp.s), float(smp.v), cmd)

    def settle(self, t: float) -> None:
        """At absolute time t (a step's end), put the plan's ``end`` state in place (checked
        against the segments' state there) and coast on from it."""
        if self.plan is None or self.plan[3].end is None:
            return
        t0, s0, v0, cmd = self.plan
        s, v, _ = cmd.motion(s0, v0, t - t0)
        cmd.check_end(s, v)
        self.plan = (float(t), cmd.end[0], cmd.end[1], _COAST)


_COAST = Command(((0.0, math.inf, 0.0),))


def budget_of(max_wall_s, scene_budget) -> float | None:
    """The wall-clock budget of one advance, s: the smaller of the call's ``max_wall_s`` and
    the scene's solver.max_wall_s (None where neither is given); CommandError for a
    ``max_wall_s`` that is not a positive number."""
    if max_wall_s is not None:
        if isinstance(max_wall_s, bool) or not isinstance(
                max_wall_s, (int, float, np.floating, np.integer)) or not max_wall_s > 0:
            raise CommandError(f"max_wall_s = {max_wall_s!r} s: allowed (0, inf] or None")
        max_wall_s = float(max_wall_s)
    given = [b for b in (max_wall_s, scene_budget) if b is not None]
    return min(given) if given else None


def _budgeted(rhs, budget: float, t_report: float, h: float):
    """``rhs`` that raises SimulationError (at the step's start ``t_report`` + the model time)
    once ``budget`` s of wall time have passed since this call."""
    wall0 = time.perf_counter()

    def f(t, y):
        spent = time.perf_counter() - wall0
        if spent > budget:
            raise WallBudgetExhausted(t_report + t, budget, "integration", spent, step=h,
                                      last_state=y)
        return rhs(t, y)
    return f


class TelescopicStepper:
    """A telescopic scene's full model advanced by external actuator commands (module
    docstring)."""

    def __init__(self, scene: dict):
        from sim_core.physics.drive_profiles import HoldProfile
        from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
        from sim_core.systems.telescopic.schema import params_from_scene
        if scene.get("model", {}).get("reduction", "none") != "none" or \
                not scene["effects"]["flexible"]:
            raise SceneError("the stepping API runs the full model (model.reduction = 'none' "
                             "and effects.flexible = true) or the modal ROM (model.reduction = "
                             "'modal'); effects.flexible = false is not supported (allowed: true)")
        p = params_from_scene(scene)
        if p.mechanism != "synchronized":
            raise SceneError("the stepping API drives the synchronized mechanism (allowed: "
                             "drive.mechanism = 'synchronized')")
        self.scene, self.params = scene, p
        self.ts = ts = build_telescopic(p)
        z, _ = initial_equilibrium(ts)
        self.y = np.concatenate([z, np.zeros_like(z)])
        self.t = 0.0
        self.clock = [0.0]
        self.sol = {k: v for k, v in scene["solver"].items()
                    if k in ("rtol", "atol", "method", "jacobian", "max_step")}
        self.sol["n_output"] = 2
        #: ROS2 keeps its Jacobian from one advance to the next (its jacobian_interval)
        self.ros2 = None
        if self.sol["method"] == "ROS2":
            from sim_core.integrate.rosenbrock import RosenbrockW2
            self.ros2 = RosenbrockW2(ts.model, scene["solver"]["h"],
                                     scene["solver"]["jacobian_interval"])
        #: the integrations' work so far: accepted steps, right-hand sides, Jacobians
        self.stats = {"n_steps": 0, "n_rhs": 0, "n_jacobians": 0}
        m = ts.model
        self.drives: dict[str, Drive] = {}
        from sim_core.systems.telescopic.build import _length_of, _slew_signal
        from sim_core.systems.telescopic.luffing import cylinder_drive
        tel = Drive(ts.schedule, self.clock)
        self.drives["telescopic"] = tel
        for c in m.nonlinear:
            if c.name in ts.drives:
                c.target = _length_of(tel)
        for col in ts.oil_columns.values():          # the piston the oil column follows
            col.command = _length_of(tel)
        luff = Drive(p.luffing_profile or HoldProfile(s0=math.radians(p.luffing_angle_deg)),
                     self.clock)
        self.drives["luffing"] = luff
        cyl = next(c for c in m.nonlinear if c.name == "luffing_cylinder")
        cyl.target = cylinder_drive(luff, p.luffing.points())
        if ts.i_phi is not None:
            slew = Drive(p.slew_profile, self.clock)
            self.drives["slew"] = slew
            m.constraints = [(_slew_signal(slew, ts.i_phi) if lc.name == "slew" else lc)
                             for lc in m.constraints]
            ts.slew_angle = lambda tau: float(slew.sample(tau).s)
        if ts.hoist is not None:
            hoist = Drive(p.hoist_profile or HoldProfile(s0=p.hoist_length), self.clock)
            self.drives["hoist"] = hoist
            ts.hoist.length = _length_of(hoist)
        #: the actuators' limits; ``limit_mode``: "raise" or "clip" (:func:`limited`)
        self.limits = {k: actuator_limits(scene, p, k) for k in self.drives}
        self.limit_mode = "raise"
        #: the limits each actuator's command hit in the last advance (limit_mode "clip")
        self.clipped: dict[str, tuple[str, ...]] = {}
        #: the scene's wall-clock budget of one advance, s (None: none)
        self.max_wall_s = scene["solver"].get("max_wall_s")

    # -- stepping ----------------------------------------------------------------------------
    def advance(self, dt: float, commands: dict | None = None,
                max_wall_s: float | None = None) -> None:
        """Integrate over dt (s) with the commands (module docstring), each commanded
        actuator's motion over the step held to its limits first (``limit_mode``).  The wall
        time is bounded by the smaller of ``max_wall_s`` and the scene's solver.max_wall_s
        (:func:`budget_of`).  On any error the stepper stays at the step's start: its time,
        state and drive plans are those before the call."""
        dt = _check_dt(dt)
        budget = budget_of(max_wall_s, self.max_wall_s)
        cmds = _check_commands(commands, self.drives)
        plans = {k: d.plan for k, d in self.drives.items()}
        try:
            for name, cmd in cmds.items():
                self.drives[name].command(self.t, cmd)
            self.clipped = {}
            for name, d in self.drives.items():
                if d.plan is None:                # the scene's own (validated) profile
                    continue
                t0, s0, v0, cmd = d.plan
                plan, hit = held_to_limits(name, self.limits[name], cmd, s0, v0, self.t - t0,
                                           dt, self.limit_mode == "clip")
                if plan is not None:
                    d.plan = (self.t, *plan)
                    self.clipped[name] = hit
            self.clock[0] = self.t
            self._integrate(dt, budget)
        except BaseException:
            for k, d in self.drives.items():
                d.plan = plans[k]
            raise
        self.t += dt
        for d in self.drives.values():
            d.settle(self.t)

    def _integrate(self, dt: float, budget: float | None) -> None:
        """self.y over [t, t + dt] (the model's clock at the step's start); a failure or an
        exhausted budget raises SimulationError at the absolute time."""
        from sim_core.integrate.driver import integrate
        if self.ros2 is not None:
            before = dict(self.ros2.stats)
            rhs = self.ros2.__dict__.get("rhs")
            if budget is not None:                # the budget checked at every right-hand side
                self.ros2.rhs = _budgeted(self.ros2.rhs, budget, self.t, self.ros2.h)
            try:
                y = self.ros2.advance(0.0, self.y, dt, t_report=self.t)
            finally:
                if budget is not None:
                    if rhs is None:
                        del self.ros2.rhs
                    else:
                        self.ros2.rhs = rhs
            for k in self.stats:
                self.stats[k] += self.ros2.stats[k] - before[k]
            self.y = y
            return
        sol = self.sol if budget is None else {**self.sol, "max_wall_s": budget}
        try:
            _, ys, st = integrate(self.ts.model, self.y, dt, sol)
        except SimulationError as exc:
            # the driver's times are the step's own: the absolute time, the type and its
            # attributes kept
            SimulationError.__init__(exc, self.t + exc.t, exc.reason, step=exc.step,
                                     last_state=exc.last_state)
            raise
        for k in self.stats:
            self.stats[k] += int(st.get(k, 0))
        self.y = np.asarray(ys[-1], dtype=float)

    def outputs(self, names=None) -> dict:
        """The scene's outputs at the current state (those of a run's result at one time), or
        only ``names`` (a cheap path where every name is in LIGHT_OUTPUTS)."""
        if names is not None:
            names = tuple(names)
            if all(k in LIGHT_OUTPUTS for k in names):
                return self._light(names)
            if "slew_torque" in names and self.ts.i_phi is not None and \
                    all(k in LIGHT_OUTPUTS or k == "slew_torque" for k in names):
                out = self._light(tuple(k for k in names if k != "slew_torque"))
                clock = self.clock[0]
                self.clock[0] = self.t
                try:
                    out["slew_torque"] = self._slew_torque()
                finally:
                    self.clock[0] = clock
                return {k: out[k] for k in names}
        from sim_core.systems.telescopic.build import _telescopic_result
        clock = self.clock[0]
        self.clock[0] = self.t
        try:
            try:
                res = _telescopic_result(self.ts, np.array([0.0]), [self.y], {}, None,
                                         self.scene)
            except (ArithmeticError, np.linalg.LinAlgError, ValueError) as exc:
                raise SimulationError(self.t, "the model's solve failed at the current state "
                                      f"({type(exc).__name__}: {exc})",
                                      last_state=self.y) from None
            out = {k: np.asarray(res[k])[0] for k in res.keys() if k != "state"}
            if self.ts.i_phi is not None:
                out["slew_torque"] = self._slew_torque()
            out.update(self._light((("payload_velocity", "sway_rate")
                                    if self.ts.hoist is not None else ())
                                   + ("telescopic_stroke",)))
        finally:
            self.clock[0] = clock
        out["time"] = self.t
        out["actuators"] = self._actuators()
        return _selected(out, names, "this scene")

    def _slew_torque(self) -> float:
        """The slewing drive's torque on the turntable about the vertical +Z, N m (positive
        turns the slew angle up): the multiplier of the slew constraint phi = phi(t) on the
        slew-angle coordinate (A^T lambda = M Q'' - F, :meth:`sim_core.model.model.Model.
        reactions`).  The model's clock must stand at the current time."""
        m = self.ts.model
        n = m.n_dof
        try:
            lam = m.reactions(0.0, self.y[:n], self.y[n:])
        except (ArithmeticError, np.linalg.LinAlgError, ValueError) as exc:
            raise SimulationError(self.t, "the model's solve failed at the current state "
                                  f"({type(exc).__name__}: {exc})", last_state=self.y) from None
        row = 0
        for c in m.constraints:
            if c.name == "slew":
                return float(lam[row])
            row += len(c.rows) if isinstance(c.rows, list) else int(np.shape(c.rows)[0])
        raise AssertionError("the slewing scene's model has no slew constraint")

    def _actuators(self) -> dict:
        return {k: tuple(float(x) for x in d.at(self.t)[:3]) for k, d in self.drives.items()}

    def _light(self, names) -> dict:
        """The tip (and the swinging payload's) position and velocity at the current state,
        without the multipliers and the contact solution."""
        m, n = self.ts.model, self.ts.model.n_dof
        out: dict = {}
        clock = self.clock[0]
        self.clock[0] = self.t
        try:
            Q, Qd = m.full_state(0.0, self.y[:n], self.y[n:])
            r, J, _, _ = self.ts.tip(Q)
            r, v = np.real(r), np.real(J @ Qd)
            sway = {"payload_position", "payload_velocity", "sway_angle", "sway_rate"}
            if sway & set(names):
                if self.ts.hoist is None:
                    raise UnknownNameError(f"outputs {sorted(sway & set(names))}: the scene has no "
                                   "swinging payload (effects.payload_swing = false)")
                out.update(self._sway(Q, Qd, r, v))
        finally:
            self.clock[0] = clock
        out["tip_position"], out["tip_velocity"] = r, v
        if "telescopic_stroke" in names:
            out["telescopic_stroke"] = self._stroke(Q, Qd)
        out["time"] = self.t
        if "actuators" in names:
            out["actuators"] = self._actuators()
        return {k: out[k] for k in names}

    def _stroke(self, Q, Qd) -> np.ndarray:
        """(L_s, L_s'): the first cylinder's stage length, m (the distance of boom 2's left
        section from boom 1's, the drive's piston length where the stage follows it exactly)
        and its rate, m/s; with the oil column the stage lags the commanded piston (the
        ``actuators`` output)."""
        from sim_core.physics.constraints import material_point
        from sim_core.physics.point_effects import path_length
        m = self.ts.model
        ell, grad = path_length((material_point(m, 1, s_fixed=0.0),
                                 material_point(m, 0, s_fixed=0.0)), Q)
        return np.array([float(np.real(ell)), float(np.real(grad) @ np.real(Qd))])

    def _sway(self, Q, Qd, r_tip, v_tip) -> dict:
        """payload_position, payload_velocity (m, m/s), sway_angle (rad: from the vertical in the
        luffing plane and across it, the plane turned by the slew angle, as the run's outputs)
        and sway_rate (rad/s: their time derivatives, d/dt atan2(d.u, -d_z) with the slewing
        plane's own rotation included)."""
        h = self.ts.hoist
        rp, Jp, _, _ = h.bottom(Q)
        rp, vp = np.real(rp), np.real(Jp @ Qd)
        d, dd = rp - r_tip, vp - v_tip
        if self.ts.slew_angle is not None:
            phi = self.ts.slew_angle(0.0)
            phid = float(self.drives["slew"].sample(0.0).v) if "slew" in self.drives else 0.0
        else:
            phi, phid = 0.0, 0.0
        u = np.array([math.cos(phi), math.sin(phi), 0.0])
        w = np.array([-math.sin(phi), math.cos(phi), 0.0])
        ud, wd = phid * w, -phid * u
        den, dden = -d[2], -dd[2]
        ang, rate = [], []
        for e, ed in ((u, ud), (w, wd)):
            num, dnum = float(d @ e), float(dd @ e + d @ ed)
            ang.append(math.atan2(num, den))
            rate.append((den * dnum - num * dden) / (num * num + den * den))
        return {"payload_position": rp, "payload_velocity": vp,
                "sway_angle": np.array(ang), "sway_rate": np.array(rate)}

    # -- checkpoints ---------------------------------------------------------------------------
    def save_state(self) -> dict:
        contact = self.ts.contact
        return {"t": self.t, "y": self.y.copy(),
                "drives": {k: d.plan for k, d in self.drives.items()},
                "friction_warm": copy.deepcopy(getattr(contact, "_x0", None)),
                "model_warm": copy.deepcopy(self.ts.model.__dict__.get("_g_warm")),
                "ros2": self.ros2.state() if self.ros2 is not None else None,
                "stats": dict(self.stats)}

    def restore_state(self, state: dict) -> None:
        _check_keys(state, ("t", "y", "drives"), "the full model")
        t = _time_of(state)
        y = _array_of(state, "y", self.y.shape)
        plans = state["drives"]
        if not isinstance(plans, dict) or not set(plans) <= set(self.drives) or \
                not all(_is_plan(x) for x in plans.values()):
            raise CommandError(f"state['drives'] = {plans!r}: {{actuator: None or (t0, s0, v0, "
                               f"Command)}} of this scene's actuators ({', '.join(self.drives)})")
        ros2 = state.get("ros2")
        keys = {"age", "band", "Jzz", "Jzv", "ft", "stats"}
        if self.ros2 is not None and ros2 is not None and not (
                isinstance(ros2, dict) and keys <= set(ros2)):
            raise CommandError("state['ros2']: the ROS2 integrator's snapshot (a dict of age, "
                               "band, Jzz, Jzv, ft, stats) or None")
        if not isinstance(state.get("stats"), (dict, type(None))):
            raise CommandError(f"state['stats'] = {state['stats']!r}: a dict or None")
        self.t, self.y, self.clipped = t, y, {}
        for k, plan in plans.items():
            self.drives[k].plan = plan
        if state.get("friction_warm") is not None and self.ts.contact is not None:
            self.ts.contact._x0 = copy.deepcopy(state["friction_warm"])
        if state.get("model_warm") is not None:
            self.ts.model.__dict__["_g_warm"] = copy.deepcopy(state["model_warm"])
        if self.ros2 is not None and state.get("ros2") is not None:
            self.ros2.restore(state["ros2"])
        if state.get("stats") is not None:
            self.stats = dict(state["stats"])


class ModalStepper:
    """A modal-ROM scene (``model.reduction = "modal"``) advanced by stroke commands (module
    docstring).  ``drives``: the one actuator, "telescopic"."""

    #: longest sub-step of the scene profile's mean accelerations (simulate_modal's dt_max), s
    PROFILE_STEP = 0.05

    def __init__(self, scene: dict):
        from sim_core.physics.drive_profiles import CubicSmoothstepSchedule
        from sim_core.systems.telescopic.modal import ModalROM, check_params, tables_for
        from sim_core.systems.telescopic.schema import params_from_scene
        p = params_from_scene(scene)
        try:
            check_params(p)
            tables = tables_for(p.payload, p.luffing_angle_deg, scene["model"]["n_modes"],
                                n_booms=p.n_booms)
        except ValueError as exc:
            raise SceneError(f"model.reduction = 'modal': {exc}") from None
        self.scene, self.params, self.tables = scene, p, tables
        self.profile = p.drive_profile or CubicSmoothstepSchedule(
            v_max=p.v_max, t_ramp=p.t_ramp, t_hold_end=p.t_hold_end, sign=p.direction,
            s0=p.stroke0)
        self.rom = ModalROM(tables, p.stroke0, 0.0)
        self.t = 0.0
        self.command: Command | None = None       # None: the scene profile
        self.drives = ("telescopic",)
        self.stats: dict = {}                     # closed-form steps: nothing to count
        self.limits = {"telescopic": actuator_limits(
            scene, p, "telescopic", tables.L_range)}
        self.limit_mode = "raise"
        self.clipped: dict[str, tuple[str, ...]] = {}
        self.accel: float | None = None
        self.max_wall_s = scene["solver"].get("max_wall_s")

    def advance(self, dt: float, commands: dict | None = None,
                max_wall_s: float | None = None) -> None:
        """The closed-form steps over dt (s); the command's motion over the step held to the
        stroke's limits first (as the full model's).  ``max_wall_s`` is checked and accepted:
        the steps take microseconds."""
        dt = _check_dt(dt)
        budget_of(max_wall_s, self.max_wall_s)
        cmds = _check_commands(commands, self.drives)
        command = cmds.get("telescopic", self.command)
        self.clipped = {}
        if command is not None:
            rom = self.rom
            plan, hit = held_to_limits("telescopic", self.limits["telescopic"], command,
                                       float(rom.L), float(rom.v), 0.0, dt,
                                       self.limit_mode == "clip")
            if plan is not None:
                command = plan[2]
                self.clipped["telescopic"] = hit
        rom = self.rom
        if command is None:
            n = max(1, int(math.ceil(dt / self.PROFILE_STEP - 1e-9)))
            h = dt / n
            v = self.profile.rate(self.t + h * np.arange(n + 1))
            for k in range(n):
                rom.advance(float(v[k + 1] - v[k]) / h, h)
        else:
            start = (rom.L, rom.v, rom.q.copy(), rom.qd.copy())
            try:
                pieces, rest = command.pieces(dt)
                for a, tau, jump in pieces:
                    if tau > 0:
                        rom.advance(a, tau)
                    if jump:
                        g = self.tables.coefficients(rom.L)[2]
                        rom.qd = rom.qd - g * jump
                        rom.v += jump
                if command.end is not None:
                    command.check_end(rom.L, rom.v)
                    rom.L, rom.v = command.end
                    rest = None
            except BaseException:
                rom.L, rom.v, rom.q, rom.qd = start
                raise
            self.command = rest if rest is not None else _COAST
            # the acceleration the actuator has at the step's end where the limits cut it
            self.accel = pieces[-1][0] if self.clipped else None
        self.t += dt

    def outputs(self, names=None) -> dict:
        """At the current time: ``tip_position``, ``tip_velocity`` (m, m/s: the static tip of
        the tables plus the modes), ``tip_deflection``, ``tip_deflection_rate`` (m, m/s: from
        the static tip at the current L_s; Y = 0, in-plane modes), ``piston_stroke`` (L_s -
        stroke0, m), ``modal_coordinates`` q and ``modal_rates`` q' (kg^0.5 m), ``time`` and
        ``actuators`` {"telescopic": (L_s m, L_s' m/s, acceleration m/s^2)}."""
        rom = self.rom
        r, v, d, dv = rom.tip()
        a = (float(self.profile.accel(self.t)) if self.command is None
             else self.accel if self.accel is not None else self.command.segments[0][0])
        out = {"time": self.t, "tip_position": r, "tip_velocity": v, "tip_deflection": d,
               "tip_deflection_rate": dv, "piston_stroke": rom.L - self.params.stroke0,
               "modal_coordinates": rom.q.copy(), "modal_rates": rom.qd.copy(),
               "actuators": {"telescopic": (float(rom.L), float(rom.v), float(a))}}
        return _selected(out, names, "the modal ROM")

    def save_state(self) -> dict:
        rom = self.rom
        return {"t": self.t, "L": rom.L, "v": rom.v, "q": rom.q.copy(), "qd": rom.qd.copy(),
                "command": self.command}

    def restore_state(self, state: dict) -> None:
        rom = self.rom
        _check_keys(state, ("t", "L", "v", "q", "qd", "command"), "the modal ROM")
        t = _time_of(state)
        L, v = (float(_array_of(state, k, ())) for k in ("L", "v"))
        q, qd = (_array_of(state, k, rom.q.shape) for k in ("q", "qd"))
        if state["command"] is not None and not isinstance(state["command"], Command):
            raise CommandError(f"state['command'] = {state['command']!r}: None or a "
                               "sim_core.Command")
        self.t, rom.L, rom.v, rom.q, rom.qd = t, L, v, q, qd
        self.command, self.accel, self.clipped = state["command"], None, {}


def _selected(out: dict, names, source: str) -> dict:
    """``out`` (every output), or only ``names`` of it; a name it lacks raises UnknownNameError
    (a KeyError) naming ``source`` and the outputs it has."""
    if names is None:
        return out
    names = tuple(names)
    missing = [k for k in names if k not in out]
    if missing:
        raise UnknownNameError(f"outputs {missing}: not outputs of {source} (allowed: "
                               f"{', '.join(sorted(out))})")
    return {k: out[k] for k in names}


# -- snapshots -------------------------------------------------------------------------------
def _check_keys(state, keys, source: str) -> None:
    """CommandError unless ``state`` is a dict with ``keys`` (a snapshot of ``source``)."""
    if not isinstance(state, dict) or not all(k in state for k in keys):
        got = sorted(map(repr, state)) if isinstance(state, dict) else type(state).__name__
        raise CommandError(f"state: a snapshot of {source} from save_state(), a dict with the "
                           f"keys {', '.join(keys)} (got {got})")


def _array_of(state: dict, key: str, shape) -> np.ndarray:
    """state[key] as a finite float array of ``shape``; CommandError otherwise."""
    try:
        x = np.array(state[key], dtype=float)
    except (TypeError, ValueError):
        x = None
    if x is None or x.shape != tuple(shape) or not np.all(np.isfinite(x)):
        raise CommandError(f"state[{key!r}]: finite numbers of shape {tuple(shape)} (a snapshot "
                           "of this simulation's scene)")
    return x


def _time_of(state: dict) -> float:
    t = float(_array_of(state, "t", ()))
    if t < 0.0:
        raise CommandError(f"state['t'] = {t!r} s: allowed [0, inf)")
    return t


def _is_plan(plan) -> bool:
    """A drive's plan: None (its profile) or (t0, s0, v0, Command) with finite numbers."""
    if plan is None:
        return True
    return (isinstance(plan, tuple) and len(plan) == 4 and isinstance(plan[3], Command)
            and all(isinstance(x, (int, float, np.floating)) and not isinstance(x, bool)
                    and math.isfinite(x) for x in plan[:3]))
