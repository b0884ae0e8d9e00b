"""The full nonlinear sim_core model as an environment's plant: :class:`FullPhysicsPlant`.

The plant wraps :class:`sim_core.Simulation` on the telescopic crane (``booms`` = 3: the paper's
scene ``telescopic_extraction``; 5: ``telescopic_extraction_5``; synchronized drive: every
cylinder follows the one piston length L_s) at one of three fidelities (``FIDELITIES``):

* ``"paper"``: ``n_nodes`` = 3 nodes per spline element (2 sub-elements), RK45 at rtol 1e-6,
  atol 1e-7: the settings of ``TelescopicBoomEnv(fidelity="paper")``, a real-time factor of
  about 2.4 on one core frictionless (benchmarks/results/env_speed.md);
* ``"converged"``: the paper's mesh at a training tolerance, chosen from the convergence table
  benchmarks/results/training_fidelity.md (mesh, tolerance and integrator: ``FIDELITIES``),
  meant with friction on: the paper's 8 sub-elements per spline element, RK45 at rtol 1e-4,
  atol 1e-5; against the paper-accuracy run (the paper scene's own settings, rtol 1e-6) on the
  paper's extraction its tip is within 0.03 mm and its cylinder force within 0.5 % of the
  force's range, at a real-time factor of only ~0.5 on one core (no setting within those
  bounds reaches 10 with friction: the table);
* ``"train"``: the full model fast enough to train on, from the same table: of the cases
  above a real-time factor of 10 on one core the one with the least tip error, 2 sub-elements, the
  Rosenbrock-W method ROS2 at the control step (:mod:`sim_core.integrate.rosenbrock`) and the
  friction law's stick band and the stress filter's window relaxed; its tip is centimetres off
  the paper-accuracy run (about the modal ROM's error) and its cylinder force's stick-slip
  pattern differs (the table states both).

Each control step the caller hands the stroke kinematics of the step
(:meth:`FullPhysicsPlant.advance`: segments of constant piston acceleration with a rate jump
at each one's end, the env's end stops), the model is integrated over the step from its
current state, and the tip deflection is read relative to the static tip:

    d = r_tip - r_s(L_s) - (r_tip(0) - r_s(L_s(0))),   d' = v_tip - r_s'(L_s) L_s'

with r_s the static-equilibrium tip of the modal tables (:func:`sim_core.rom.tables_for`), the
offset taken once at the start so that the model starts at d = 0 in its own equilibrium (the
tables interpolate between their stroke grid points, ~0.02 mm off the model's equilibrium at
other strokes).  With ``payload_swing`` the payload hangs on the hoist rope (length
``rope_length``, m, default the scene's 10 m, a 500 kg hook) as a spherical pendulum under the
boom tip (``effects.payload_swing``, :mod:`sim_core.physics.hoist`) and :meth:`sway` gives its
angles from the vertical and their rates.  The payload and luffing angle must lie in the modal
tables' ranges (:func:`sim_core.rom.allowed_ranges`), which the static tip comes from.

With ``oil_column`` the stroke kinematics are the piston's: the cylinder drives the stages
through its oil column (``effects.oil_column``, :mod:`sim_core.physics.hydraulic_cylinder`), so
with friction they stick and slip behind it; :meth:`FullPhysicsPlant.stroke` gives the stages'
L_s and rate, and the deflection is read against the static tip at the stages' L_s.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core import Command, Simulation, load_scene
from sim_core.rom import allowed_ranges, tables_for

#: fidelity -> full-model settings: nodes per spline element (n_nodes - 1 sub-elements) and
#: the [solver] table.  "converged": the fastest case of benchmarks/results/training_fidelity.md
#: within its error bounds on the paper's extraction with friction (tip within the env's 0.2 mm
#: success tolerance, cylinder force within 5 % of its range, of the paper scene's own
#: settings): the paper's mesh (coarser meshes ring at other frequencies: 3-18 mm of tip
#: error) at a tenth of its tolerance; the explicit steps are stability-limited by the stress
#: filter, so the looser tolerance saves only ~10 % and BDF/auto do not pay.  A real-time
#: factor of ~0.5 on one core, far below the goal of 10 (see the table).
#: "train": the full model fast enough to train on (a real-time factor above 10 on one core),
#: chosen from the same table: the coarsest mesh, the Rosenbrock-W method ROS2 at the control
#: step with the structured Jacobian renewed every 1 s (:mod:`sim_core.integrate.
#: rosenbrock`), and the model's two regularisations relaxed (``model``: the friction law's
#: stick band v_eps 0.01 -> 0.05 m/s, the stress filter's window 0.01 -> 0.03 s): of the
#: table's cases at that speed the least tip error (the rule: the table's "Training choice");
#: its errors are in the table (centimetres at the tip, as the modal ROM's, and the
#: stick-slip pattern of the cylinder force changed).
FIDELITIES = {
    "paper": {"n_nodes": 3, "solver": {"rtol": 1e-6, "atol": 1e-7, "method": "RK45"}},
    "converged": {"n_nodes": 9, "solver": {"rtol": 1e-4, "atol": 1e-5, "method": "RK45"}},
    "train": {"n_nodes": 3, "solver": {"method": "ROS2", "h": 0.05, "jacobian_interval": 1.0},
              "model": {"contact.v_eps": 0.05, "filtering.h": 0.03}},
}
SCENES = {3: "telescopic_extraction", 5: "telescopic_extraction_5"}
DEFAULT_PAYLOAD = {3: 25000.0, 5: 10000.0}   # kg: the scenes'


class FullPhysicsPlant:
    """The full sim_core model of the telescopic crane, advanced one control step at a time
    along a prescribed stroke history (module docstring).

    ``booms``: 3 or 5; ``fidelity``: "paper", "converged" or "train" (``FIDELITIES``); ``payload`` kg
    (default 25 t for 3 booms, 10 t for 5) and ``angle_deg`` (luffing angle, deg) within the
    modal tables' ranges; ``stroke0``: the piston length L_s at the start (m, at rest in static
    equilibrium); ``friction``: the sliders' Coulomb friction (Section 8; ``mu_static``,
    ``mu_dynamic``: its coefficients, None the scene's 0.15, 0.1); ``oil_column``: the telescopic
    cylinder drives the stages through its oil column (``effects.oil_column``; ``hydraulics``:
    the ``[oil_column]`` table's cylinder_area, bulk_modulus, dead_length, damping_ratio, default
    the scene's), so that the commanded stroke is the piston's and the stages lag it, sticking
    and slipping with friction (:meth:`stroke`); ``payload_swing``, ``rope_length`` (m): the
    payload on the hoist rope; ``n_nodes``: overrides the fidelity's nodes per spline element
    (3..33)."""

    def __init__(self, booms: int = 3, fidelity: str = "converged", payload: float | None = None,
                 angle_deg: float = 60.0, stroke0: float = 2.0, friction: bool = True,
                 payload_swing: bool = False, rope_length: float | None = None,
                 n_nodes: int | None = None, oil_column: bool = False,
                 hydraulics: dict | None = None, mu_static: float | None = None,
                 mu_dynamic: float | None = None):
        if fidelity not in FIDELITIES:
            raise ValueError(f"fidelity = {fidelity!r}: allowed {', '.join(map(repr, FIDELITIES))}")
        if isinstance(booms, bool) or booms not in SCENES:
            raise ValueError(f"booms = {booms!r}: allowed {', '.join(map(str, SCENES))}")
        if rope_length is not None and not payload_swing:
            raise ValueError("rope_length is the hoist rope of a swinging payload: set "
                             "payload_swing=True (or leave rope_length None)")
        payload = DEFAULT_PAYLOAD[booms] if payload is None else float(payload)
        (p_lo, p_hi), (a_lo, a_hi), (L_lo, L_hi) = allowed_ranges(n_booms=booms)
        for name, x, lo, hi in (("payload", payload, p_lo, p_hi),
                                ("angle_deg", angle_deg, a_lo, a_hi),
                                ("stroke0", stroke0, L_lo, L_hi)):
            if not (math.isfinite(x) and lo - 1e-9 <= x <= hi + 1e-9):
                raise ValueError(f"{name} = {x!r} outside the modal tables' range [{lo:g}, "
                                 f"{hi:g}] of booms = {booms} (sim_core.rom.allowed_ranges)")
        cfg = FIDELITIES[fidelity]
        L0 = float(stroke0)
        overrides = {"booms.n_nodes": int(n_nodes if n_nodes is not None else cfg["n_nodes"]),
                     "booms.luffing_angle_deg": float(angle_deg), "payload.mass": payload,
                     "effects.friction": bool(friction), "booms.stroke0": L0,
                     # the stages hold L_s until the first command
                     "drive.profile": "table", "drive.table": [[0.0, L0], [1.0, L0]],
                     **{f"solver.{k}": v for k, v in cfg["solver"].items()},
                     **cfg.get("model", {})}
        if payload_swing:
            overrides["effects.payload_swing"] = True
            if rope_length is not None:
                overrides["hoist.length"] = float(rope_length)
        if hydraulics is not None and not oil_column:
            raise ValueError("hydraulics configures the oil column: set oil_column=True (or "
                             "leave hydraulics None)")
        if oil_column:
            overrides["effects.oil_column"] = True
            overrides.update({f"oil_column.{k}": float(v) for k, v in (hydraulics or {}).items()})
        for name, mu in (("mu_static", mu_static), ("mu_dynamic", mu_dynamic)):
            if mu is not None:
                overrides[f"contact.{name}"] = float(mu)
        self.booms, self.fidelity, self.payload_swing = booms, fidelity, bool(payload_swing)
        self.oil_column = bool(oil_column)
        self.scene = load_scene(SCENES[booms], overrides=overrides)
        self.sim = Simulation(self.scene)
        self.tables = tables_for(payload, float(angle_deg), 1, n_booms=booms)
        r0, _ = self._tip()
        self._tip_offset = r0 - self.tables.static_tip(L0)[0]

    # -- stepping ----------------------------------------------------------------------------
    def advance(self, segments, dt: float | None = None,
                end: tuple[float, float] | None = None) -> None:
        """One control step: the stroke follows ``segments`` ((acceleration m/s^2, duration s,
        rate jump m/s at its end), ...) from the current L_s, L_s'; ``dt`` (s): the step
        (default: the segments' total duration); ``end``: the (L_s, L_s') the caller's own
        kinematics have at the step's end (replaces the segments' round-off,
        :class:`sim_core.Command`).  SimulationError where the solve fails."""
        segs = tuple(tuple(s) for s in segments)
        if dt is None:
            dt = sum(s[1] for s in segs)
        self.sim.advance(dt, {"telescopic": Command(segs, end)})

    # -- outputs -------------------------------------------------------------------------------
    @property
    def L(self) -> float:
        """Piston length L_s (m) now."""
        return self.sim.outputs(("actuators",))["actuators"]["telescopic"][0]

    @property
    def v(self) -> float:
        """Stroke rate L_s' (m/s) now."""
        return self.sim.outputs(("actuators",))["actuators"]["telescopic"][1]

    def stroke(self) -> tuple[float, float]:
        """(L_s, L_s'): the stages' stroke (m, the first cylinder's length) and rate (m/s)
        now; with the oil column they lag the commanded piston (:attr:`L`, :attr:`v`), else
        they equal it (to the constraint's round-off)."""
        L, Ld = self.sim.outputs(("telescopic_stroke",))["telescopic_stroke"]
        return float(L), float(Ld)

    @property
    def t(self) -> float:
        """Simulated time since the start, s."""
        return self.sim.t

    def _tip(self):
        out = self.sim.outputs(("tip_position", "tip_velocity"))
        return out["tip_position"], out["tip_velocity"]

    def tip_deflection(self) -> tuple[float, float, float, float]:
        """(dX, dZ, dX', dZ') of the tip relative to the static tip at the current L_s (m, m/s;
        module docstring; with the oil column the stages' L_s), global X (horizontal, in the
        luffing plane) and Z (up)."""
        if self.oil_column:      # the static tip of the stages' stroke, not the piston's
            out = self.sim.outputs(("tip_position", "tip_velocity", "telescopic_stroke"))
            L, Ld = out["telescopic_stroke"]
        else:
            out = self.sim.outputs(("tip_position", "tip_velocity", "actuators"))
            L, Ld, _ = out["actuators"]["telescopic"]
        rs, drs = self.tables.static_tip(L)
        d = out["tip_position"] - rs - self._tip_offset
        dv = out["tip_velocity"] - drs * Ld
        return float(d[0]), float(d[2]), float(dv[0]), float(dv[2])

    def sway(self) -> tuple[float, float, float, float]:
        """(angle_x, angle_y, rate_x, rate_y) of the hoist rope from the vertical (rad, rad/s):
        in the luffing plane (positive towards +X, away from the crane) and across it (+Y);
        ValueError without ``payload_swing``."""
        if not self.payload_swing:
            raise ValueError("sway(): the payload does not swing (payload_swing=False)")
        out = self.sim.outputs(("sway_angle", "sway_rate"))
        a, r = out["sway_angle"], out["sway_rate"]
        return float(a[0]), float(a[1]), float(r[0]), float(r[1])

    # -- checkpoints ---------------------------------------------------------------------------
    def save_state(self) -> dict:
        """A snapshot of the plant (picklable): restore_state repeats the run to round-off."""
        return {"sim": self.sim.save_state()}

    def restore_state(self, state: dict) -> None:
        self.sim.restore_state(state["sim"])

    @property
    def system(self):
        """The assembled full model (diagnostics; sim_core internals)."""
        return self.sim.system

    @property
    def state(self) -> np.ndarray:
        """The integrated state (z, z') now (a copy)."""
        return self.sim.save_state()["y"]
