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

``save_state`` returns everything the future of the run depends on (time, the integrated
state, every drive's mode and plan, the friction's warm starts); ``restore_state`` puts it
back, and the restored run repeats the original one to round-off.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from sim_core.commands import Command
from sim_core.errors import SceneError, SimulationError
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
    ValueError naming the actuator for anything else."""
    if isinstance(value, Command):
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise ValueError(f"commands[{name!r}] = {value!r}: an acceleration (a number) or a "
                         "sim_core.Command")
    if not math.isfinite(value):
        raise ValueError(f"commands[{name!r}] = {value!r}: must be a finite acceleration")
    return Command.accelerate(float(value))


def _check_commands(commands, names) -> dict[str, Command]:
    out = {}
    for name, value in (commands or {}).items():
        if name not in names:
            raise KeyError(f"commands[{name!r}]: no such actuator in this scene (allowed: "
                           f"{', '.join(sorted(names))})")
        out[name] = as_command(name, value)
    return out


def _check_dt(dt) -> float:
    if not (isinstance(dt, (int, float, np.floating)) and dt > 0 and math.isfinite(dt)):
        raise ValueError(f"dt = {dt!r} s: allowed (0, inf)")
    return float(dt)


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

    # -- stepping ----------------------------------------------------------------------------
    def advance(self, dt: float, commands: dict | None = None) -> None:
        from sim_core.integrate.driver import integrate
        dt = _check_dt(dt)
        for name, cmd in _check_commands(commands, self.drives).items():
            self.drives[name].command(self.t, cmd)
        self.clock[0] = self.t
        if self.ros2 is not None:
            before = dict(self.ros2.stats)
            self.y = self.ros2.advance(0.0, self.y, dt, t_report=self.t)
            for k in self.stats:
                self.stats[k] += self.ros2.stats[k] - before[k]
        else:
            _, ys, st = integrate(self.ts.model, self.y, dt, self.sol)
            for k in self.stats:
                self.stats[k] += int(st.get(k, 0))
            self.y = np.asarray(ys[-1], dtype=float)
        self.t += dt
        for d in self.drives.values():
            d.settle(self.t)

    def outputs(self, names=None) -> dict:
        """The scene's outputs at the current state (those of a run's result at one time), or
        only ``names`` (a cheap path where every name is in LIGHT_OUTPUTS)."""
        if names is not None:
            names = tuple(names)
            if all(k in LIGHT_OUTPUTS for k in names):
                return self._light(names)
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
            out.update(self._light((("payload_velocity", "sway_rate")
                                    if self.ts.hoist is not None else ())
                                   + ("telescopic_stroke",)))
        finally:
            self.clock[0] = clock
        out["time"] = self.t
        out["actuators"] = self._actuators()
        return _selected(out, names, "this scene")

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
                    raise KeyError(f"outputs {sorted(sway & set(names))}: the scene has no "
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
        self.t = float(state["t"])
        self.y = np.array(state["y"], dtype=float)
        for k, plan in state["drives"].items():
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

    def advance(self, dt: float, commands: dict | None = None) -> None:
        dt = _check_dt(dt)
        cmds = _check_commands(commands, self.drives)
        if "telescopic" in cmds:
            self.command = cmds["telescopic"]
        rom = self.rom
        if self.command is None:
            n = max(1, int(math.ceil(dt / self.PROFILE_STEP - 1e-9)))
            h = dt / n
            v = self.profile.rate(self.t + h * np.arange(n + 1))
            for k in range(n):
                rom.advance(float(v[k + 1] - v[k]) / h, h)
        else:
            cmd = self.command
            pieces, rest = cmd.pieces(dt)
            for a, tau, jump in pieces:
                if tau > 0:
                    rom.advance(a, tau)
                if jump:
                    g = self.tables.coefficients(rom.L)[2]
                    rom.qd = rom.qd - g * jump
                    rom.v += jump
            if cmd.end is not None:
                cmd.check_end(rom.L, rom.v)
                rom.L, rom.v = cmd.end
                rest = None
            self.command = rest if rest is not None else _COAST
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
             else self.command.segments[0][0])
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
        self.t = float(state["t"])
        rom.L, rom.v = float(state["L"]), float(state["v"])
        rom.q = np.array(state["q"], dtype=float)
        rom.qd = np.array(state["qd"], dtype=float)
        self.command = state["command"]


def _selected(out: dict, names, source: str) -> dict:
    """``out`` (every output), or only ``names`` of it; a name it lacks raises KeyError naming
    ``source`` and the outputs it has."""
    if names is None:
        return out
    names = tuple(names)
    missing = [k for k in names if k not in out]
    if missing:
        raise KeyError(f"outputs {missing}: not outputs of {source} (allowed: "
                       f"{', '.join(sorted(out))})")
    return {k: out[k] for k in names}
