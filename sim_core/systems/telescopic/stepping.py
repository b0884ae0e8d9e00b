"""The telescopic crane advanced step by step (the stepping API of :class:`sim_core.Simulation`).

The model is built from the scene and brought to its static equilibrium as ``simulate`` does.
Every actuator the scene has (the telescopic stages, the luffing cylinder, the slewing drive
where the scene slews, the hoist where the payload swings) is a :class:`Drive`: it follows its
scene profile until a command takes it over; a command is the actuator's acceleration (m/s^2
or rad/s^2), held over the step (``advance(dt, {"telescopic": a})``), so the position and the
rate stay continuous.  Each ``advance`` integrates the model over [t, t + dt] with the scene's
solver settings; the model's drives read the time relative to the step's start (a clock the
stepper moves), so the integrator starts at 0 for every step.

``save_state`` returns everything the future of the run depends on (time, the integrated
state, every drive's mode and segment, the friction's warm starts); ``restore_state`` puts it
back, and the restored run repeats the original one to round-off.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from sim_core.errors import SceneError
from sim_core.physics.drive_profiles import MotionSample

#: the command names of the actuators, in the scene's tables
ACTUATOR_TABLES = {"telescopic": "drive", "luffing": "luffing_drive", "slew": "slew_drive",
                   "hoist": "hoist_drive"}


class Drive:
    """An actuator's position s(t) (m or rad): its profile, or from a command on a constant
    acceleration a from (s0, v0) at t0.  ``clock[0]`` is the absolute time of the current
    step's start: the model asks at local times, ``sample(tau)`` answers for clock + tau."""

    def __init__(self, profile, clock):
        self.profile, self.clock = profile, clock
        self.segment = None            # (t0, s0, v0, a) once commanded

    def at(self, t: float) -> MotionSample:
        """The drive at absolute time t."""
        if self.segment is None:
            return self.profile.sample(t)
        t0, s0, v0, a = self.segment
        d = t - t0
        return MotionSample(s0 + v0 * d + 0.5 * a * d * d, v0 + a * d, a, 0.0)

    def sample(self, tau: float) -> MotionSample:
        return self.at(self.clock[0] + float(tau))

    def command(self, t: float, a: float) -> None:
        """From absolute time t on, the acceleration a (position and rate continuous)."""
        smp = self.at(t)
        self.segment = (float(t), float(smp.s), float(smp.v), float(a))


class TelescopicStepper:
    """A telescopic scene's model advanced by external actuator commands (module docstring)."""

    def __init__(self, scene: dict):
        from sim_core.physics.drive_profiles import HoldProfile
        from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
        from sim_core.systems.telescopic.schema import params_from_scene
        if scene.get("model", {}).get("reduction", "none") != "none" or \
                not scene["effects"]["flexible"]:
            raise SceneError("the stepping API runs the full model: model.reduction = 'none' "
                             "and effects.flexible = true (allowed)")
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
        m = ts.model
        self.drives: dict[str, Drive] = {}
        from sim_core.systems.telescopic.build import _length_of, _slew_signal
        from sim_core.systems.telescopic.luffing import cylinder_drive
        tel = Drive(ts.schedule, self.clock)
        self.drives["telescopic"] = tel
        for c in m.nonlinear:
            if c.name in ts.drives:
                c.target = _length_of(tel)
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
        if not (dt > 0 and math.isfinite(dt)):
            raise ValueError(f"dt = {dt!r} s: allowed (0, inf)")
        for name, a in (commands or {}).items():
            if name not in self.drives:
                raise KeyError(f"commands[{name!r}]: no such actuator in this scene (allowed: "
                               f"{', '.join(sorted(self.drives))})")
            if not math.isfinite(a):
                raise ValueError(f"commands[{name!r}] = {a!r}: must be a finite acceleration")
            self.drives[name].command(self.t, float(a))
        self.clock[0] = self.t
        _, ys, _ = integrate(self.ts.model, self.y, dt, self.sol)
        self.y = np.asarray(ys[-1], dtype=float)
        self.t += dt

    def outputs(self) -> dict:
        """The scene's outputs at the current state (those of a run's result at one time)."""
        from sim_core.systems.telescopic.build import _telescopic_result
        self.clock[0] = self.t
        res = _telescopic_result(self.ts, np.array([0.0]), [self.y], {}, None, self.scene)
        out = {k: np.asarray(res[k])[0] for k in res.keys() if k != "state"}
        out["time"] = self.t
        out["actuators"] = {k: tuple(float(x) for x in d.at(self.t)[:3])
                            for k, d in self.drives.items()}
        return out

    # -- checkpoints ---------------------------------------------------------------------------
    def save_state(self) -> dict:
        contact = self.ts.contact
        return {"t": self.t, "y": self.y.copy(),
                "drives": {k: d.segment for k, d in self.drives.items()},
                "friction_warm": copy.deepcopy(getattr(contact, "_x0", None)),
                "model_warm": copy.deepcopy(self.ts.model.__dict__.get("_g_warm"))}

    def restore_state(self, state: dict) -> None:
        self.t = float(state["t"])
        self.y = np.array(state["y"], dtype=float)
        for k, seg in state["drives"].items():
            self.drives[k].segment = seg
        if state.get("friction_warm") is not None and self.ts.contact is not None:
            self.ts.contact._x0 = copy.deepcopy(state["friction_warm"])
        if state.get("model_warm") is not None:
            self.ts.model.__dict__["_g_warm"] = copy.deepcopy(state["model_warm"])
