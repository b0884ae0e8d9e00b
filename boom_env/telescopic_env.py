"""Telescopic-boom extraction / retraction with vibration suppression (Gymnasium environment).

The crane of Zhao-Qi-Wang 2024 (three nested flexible booms, 60 deg luffing angle, payload at
boom 3's tip) extends (or retracts) its telescopic cylinder from a start to a target piston
length L_s.  The agent commands the cylinder acceleration; the flexible booms respond.  The goal
is to reach the target quickly while leaving as little tip vibration as possible.

Boom count (``booms``)
----------------------
* ``3`` (default): the paper's crane; the tip moves 2 m per m of L_s.
* ``5``: five sections, the paper's three booms inside two larger ones of the same family
  (the U family of the paper's Table 2; scenes ``telescopic_extraction_5`` /
  ``telescopic_retraction_5``), synchronized drive: cylinders on stages 1-2 and 3-4 and rope
  units moving booms 3 and 5, every stage moving with the same L_s, so the tip moves 4 m per m
  of L_s (up to 2 m/s at v_max = 0.5 m/s) and the boom is 17-43 m long.  Payload 5-15 t
  (default 10 t); first in-plane bending mode 0.24-1.77 Hz over the tables (0.615 Hz at
  L_s = 5 m, 10 t, 60 deg; three booms at 25 t: 0.71 Hz).
Other counts raise ValueError: modal tables are shipped for 3 and 5 sections
(``sim_core.rom.TABLE_BOOMS``).  The spaces and the reward's form are the
same for both; the plant, the default payload, the payload range and the deflection scales of
the reward and the success test (10 times larger for five booms, see Reward) differ.

Dynamics (``fidelity``)
-----------------------
Every fidelity runs through sim_core's public stepping API (:class:`sim_core.Simulation`,
:class:`sim_core.Command`, :mod:`sim_core.rom`): each control step hands the plant the step's
stroke kinematics (below) as one command.

* ``"rl"`` (default): the stroke-parametric modal reduced-order model (in-plane modes of the
  full sim_core model, linearised about the static equilibrium at each L_s; tables shipped with
  sim_core, :mod:`sim_core.rom`) on the crane's modal scene (``telescopic_extraction_rl``; five
  booms: ``telescopic_extraction_5`` with ``model.reduction = "modal"``), :class:`ModalPlant`.
  ~2e4 env steps/s on one core, ~1000 times real time (benchmarks/results/env_speed.md).
* ``"paper"``: the full sim_core model (scene ``telescopic_extraction`` or
  ``telescopic_extraction_5``: ``booms`` sections, synchronized drive; frictionless by default,
  ``paper_friction``; ``paper_n_nodes`` nodes per spline element, default 3; RK45 at rtol 1e-6,
  atol 1e-7), :class:`boom_env.full_physics.FullPhysicsPlant`: for each control step every
  telescopic cylinder follows the env's stroke kinematics and the model is integrated from the
  current state.  Slow: ~50 env steps/s, a real-time factor of ~2.4 on one core at the default
  3 nodes frictionless, and a reset of ~0.3 s (benchmarks/results/env_speed.md); for checking
  policies, not for training.
* ``"converged"``: the full nonlinear model with the sliders' friction on (Section 8), at the
  settings chosen from the convergence table benchmarks/results/training_fidelity.md (mesh,
  tolerance and integrator, ``boom_env.full_physics.FIDELITIES["converged"]``: the paper's 8
  sub-elements per spline element, RK45 at rtol 1e-4, atol 1e-5): against the paper-accuracy
  run of the paper's extraction its tip is within 0.03 mm and its cylinder force within 0.5 %
  of the force's range.  A real-time factor of only ~0.5 on one core, slower than ``"paper"``
  (frictionless on 2 sub-elements): with friction the coarser meshes are millimetres off and
  no setting of the table within its error bounds reaches a real-time factor of 10.
  ``paper_n_nodes`` and ``paper_friction`` do not apply.
* ``"train"``: the full nonlinear model with friction, fast enough to train on (a real-time
  factor above 10 on one core; ``boom_env.full_physics.FIDELITIES["train"]``): 2 sub-elements
  per spline element, the Rosenbrock-W method ROS2 at the control step with the Jacobian
  renewed every 1 s (``solver.method = "ROS2"``), and the two regularisations relaxed (the
  friction law's stick band v_eps 0.05 m/s, the stress filter's window 0.03 s).  Against the
  paper-accuracy run its tip is off by centimetres (about the modal ROM's error) and the
  stick-slip pattern of its cylinder force differs (benchmarks/results/training_fidelity.md).
  ``paper_n_nodes`` and ``paper_friction`` do not apply.

Stroke kinematics (every fidelity)
----------------------------------
The action is held for one control step ``dt`` (s) (piecewise-constant acceleration), the env
integrates L_s, v exactly: velocity saturation |v| <= v_max (the cylinder's flow limit: the
acceleration is cut to 0 when the limit is reached, ``info["velocity_saturated"]``), end stops
L_min <= L_s <= L_max (inelastic: v -> 0 on contact, ``info["end_stop"]``; in the ROM the
velocity jump dv gives the modal velocity jump dq' = -Gamma dv of q'' = -Gamma a).

Action space
------------
``Box(-1, 1, (1,), float32)``: commanded cylinder acceleration a = action * a_max (m/s^2),
a_max = 0.25 m/s^2 by default (the paper's cubic schedule, docs/model.md#input-drive, peaks at
1.5 * 0.5 / 4 = 0.1875 m/s^2).  Non-finite actions raise ValueError; finite actions outside
[-1, 1] are clipped.

Observation space
-----------------
``Box(low, high, (9,), float32)``, SI units (``(11,)`` with ``observe_parameters=True``):

====  ===============================================  ==================
 idx  quantity                                          bounds
====  ===============================================  ==================
  0   piston length L_s (m)                             [L_min, L_max]
  1   stroke rate v = dL_s/dt (m/s)                     [-v_max, v_max]
  2   applied acceleration of the last step (m/s^2)     [-a_max, a_max]
  3   target piston length L* (m)                       [L_min, L_max]
  4   time left t_max - t (s)                           [0, t_max]
  5   tip deflection dX (m) from the static tip at L_s  [-1, 1]
  6   tip deflection dZ (m)                             [-1, 1]
  7   rate of dX (m/s)                                  [-10, 10]
  8   rate of dZ (m/s)                                  [-10, 10]
  9   payload, normalised (only observe_parameters)     [-1, 1]
 10   luffing angle, normalised (observe_parameters)    [-1, 1]
====  ===============================================  ==================

The deflection is the tip position (innermost boom N = ``booms``, s = 10 m) minus the
static-equilibrium tip of the same model at the current L_s (tables of the full model), i.e. the
vibration plus the quasi-static inertial deflection.  With ``fidelity="paper"`` or ``"converged"``
the reference is the full model's own equilibrium tip at reset moved by the tables' static tip
change (the tables interpolate between their stroke grid points, ~0.02 mm off the model's
equilibrium).
Deflections are mm-scale (cm with ``booms=5``): normalise observations (e.g. VecNormalize)
for learning.  A deflection outside its bounds counts as divergence.

``observe_parameters=True`` appends the episode's payload and luffing angle, mapped linearly
from the modal tables' range (``sim_core.rom.allowed_ranges``: 20-30 t with
3 booms, 5-15 t with 5; 45-75 deg) to [-1, 1] (x_n = (2 x - lo - hi) / (hi - lo); the middle
payload and 60 deg give 0).  With
``payload_range`` / ``angle_range`` the plant changes from episode to episode (first bending
frequency, quasi-static deflection); without these two entries a policy cannot tell which plant
it drives.  Default False: the 9-entry observation of the registered ids.

Reward (per step; all weights are constructor arguments)
--------------------------------------------------------
    r = reward_scale * (
        - w_time * dt                                        (slowness)
        - w_progress * |L_s - L*| / travel * dt              (distance to go)
        - w_deflection * (|d| / d_ref)^2 * dt                (tip deflection, d_ref = 1e-3 m)
        - w_rate * (|d'| / dv_ref)^2 * dt                     (tip vibration rate, dv_ref = 1e-2 m/s)
        - w_effort * (a / a_max)^2 * dt                       (actuator effort)
        - w_jerk * ((a - a_prev) / a_max)^2                   (jerk, per step)
        - w_end_stop * [end stop hit this step]
        + bonus)                                              (on success, see termination)
Defaults: w_time = 1, w_progress = 10, w_deflection = 1, w_rate = 1, w_effort = 0.1,
w_jerk = 0.1, w_end_stop = 10, bonus = 50, reward_scale = 0.01.  The progress weight makes
standing still (-11 per second unscaled) clearly worse than extracting: with w_progress = 1 a
PPO agent learned to stay at the start (return ~ -60 over 30 s) because the paper's cubic
schedule, which pays ~3 mm of tip deflection while decelerating, scores ~ -76 (agents/README
notes).

With ``booms=5`` the deflection scales d_ref, dv_ref (and the success tolerances below) are
10 times larger by default (1 cm, 0.1 m/s): the same stroke history deflects the
five-section tip about 8 times as much (the paper's cubic schedule: peak 30.4 mm at 10 t
against 3.7 mm for three booms at 25 t).  With the three-boom scales the schedule would score
-3549 unscaled, ten times worse than standing still (-330); with the scaled ones -144.4
(extraction; retraction -69.4 and successful), like the -158.8 of three booms, and the
weights keep their meaning for both counts.  ``d_ref``, ``dv_ref`` (m, m/s) are constructor
arguments (default None: the scale of the boom count).

``reward_scale`` multiplies every term and leaves their ratios, and so the ranking of any two
policies, unchanged.  Unscaled (``reward_scale=1``) a 30 s episode of uniform random actions
scores -5e3 to -3e4 (the quadratic vibration terms of a white-noise jerk), standing still
-330, the paper's cubic schedule -158.8; a learner with default settings (no reward
normalisation) fitted its value function to returns of that size (value loss ~2e6) and learned
nothing useful.  The default 0.01 brings these to -50...-300, -3.3 and -1.588, the range
default hyper-parameters are made for.  ``info["reward_unscaled"]`` carries the step's reward
before scaling.

Start state
-----------
Static equilibrium at rest at L_start (extraction: 2 m -> target 8 m; retraction: 8 m -> 2 m,
the paper's strokes, for both boom counts), q = 0; payload 25 t (``booms=3``) or 10 t
(``booms=5``) unless ``payload`` is given.  ``reset(seed=..., options=...)``: options may set
``payload`` (kg), ``luffing_angle_deg`` (deg), ``stroke_start``, ``stroke_target`` (m).  Domain
randomisation: ``payload_range=(lo, hi)`` / ``angle_range=(lo, hi)`` draw them uniformly from
``self.np_random`` at every reset (seeded through reset(seed)).  The ROM tables cover payload
20-30 t (5-15 t with ``booms=5``) and luffing angles 45-75 deg (tabulated at 45, 60, 75 deg and
interpolated linearly between them: first bending frequency within 0.7 % of the full model's at
52.5 deg, tests/env/test_modal.py; ``sim_core.rom.allowed_ranges``); values outside raise
ValueError.

Episode end
-----------
* terminated (success): |L_s - L*| < tol_stroke (5 mm), |v| < tol_speed (5 mm/s),
  |d| < tol_deflection (0.2 mm; 2 mm with ``booms=5``) and |d'| < tol_deflection_rate (2 mm/s;
  2 cm/s with ``booms=5``); bonus added.
* truncated: t >= t_max (30 s; also max_episode_steps = 600 of the registration), or the
  solver failed / produced non-finite or out-of-bounds values: ``info["diverged"] = True``
  with ``info["reason"]`` (the observation is then the last good one: never a NaN).

Rendering
---------
``render_mode="rgb_array"``: side view (X-Z plane) of the booms with the tip deflection
exaggerated (``render_exaggeration``, default 500x), numpy uint8 frames (H, W, 3), drawn with
matplotlib's Agg backend.  ``"human"`` shows the same frames in a matplotlib window.

Use
---
    import gymnasium as gym
    env = gym.make("boom_env:boom_env/TelescopicExtraction-v0")    # imports boom_env itself
    env = gym.make("boom_env/TelescopicExtraction-v0")             # after ``import boom_env``

The ``module:id`` form makes Gymnasium import ``boom_env`` (which registers the ids) before
the lookup, so no separate import is needed.  RL Zoo: ``python -m rl_zoo3.train --algo sac
--env boom_env/TelescopicExtraction-v0 --gym-packages boom_env --conf-file
agents/hyperparams/sac.yml`` (PPO and SAC hyper-parameter files in agents/hyperparams; what
they reach: agents/README.md).

Version history
---------------
The registered ids keep ``-v0``; their reward and observation changed as listed (newest last).

* Reward as above with w_progress = 1, no scale factor.
* w_progress = 10 (standing still scored better than the paper's cubic schedule with 1).
* reward_scale = 0.01 (all terms scaled, ratios unchanged; returns are 1/100 of the earlier
  ones: ``reward_scale=1`` gives those back), ``info["reward_unscaled"]``; the
  ``observe_parameters`` option (default off: the observation is unchanged).
* The ``booms`` option (3 default: unchanged; 5: the five-section crane, its own payload range
  and default payload, deflection scales and success tolerances 10 times the three-boom ones,
  ``info["booms"]``); ``d_ref``, ``dv_ref`` as constructor arguments.
* ``fidelity="converged"`` (an additive option: the full model with friction at the settings of
  benchmarks/results/training_fidelity.md); the default ``"rl"`` and ``"paper"`` are unchanged
  (their trajectories are pinned by tests/env/test_env_public_api.py).  Later, additive:
  ``fidelity="train"`` (the full model with friction at a real-time factor above 10).
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sim_core import Command, Simulation, SimulationError, load_scene
from sim_core.rom import TABLE_BOOMS, allowed_ranges, luffing_geometry, tables_for

from ._checks import number, range_pair
from .full_physics import FullPhysicsPlant

BOOM_LENGTH = 10.0          # m, docs/model.md#input-sections
BOOMS = tuple(TABLE_BOOMS)  # boom counts with modal tables: 3 (the paper's), 5
DEFAULT_PAYLOAD = {3: 25000.0, 5: 10000.0}   # kg: the paper scene's; the 5-section scenes'
# deflection scales of the reward and the success test for three booms (m, m/s); five booms
# take 10 times them: the paper's cubic schedule deflects the five-section tip 30.4 mm at
# 10 t against 3.7 mm for three booms at 25 t (ratio 8)
DEFLECTION_REFS = {"d_ref": 1e-3, "dv_ref": 1e-2, "tol_deflection": 2e-4,
                   "tol_deflection_rate": 2e-3}
DEFLECTION_SCALE = {3: 1.0, 5: 10.0}
FIDELITIES = ("rl", "paper", "converged", "train")
# the modal ROM's scene of each boom count (frictionless; model.reduction = "modal")
MODAL_SCENES = {3: ("telescopic_extraction_rl", {}),
                5: ("telescopic_extraction_5", {"model.reduction": "modal",
                                                "effects.friction": False})}


class ModalPlant:
    """The stroke-parametric modal ROM (fidelity "rl") as the env's plant: a
    :class:`sim_core.Simulation` of the crane's modal scene (``MODAL_SCENES``) with the
    episode's payload (kg), luffing angle (deg) and start stroke L0 (m), at rest in its static
    equilibrium.  ``L``, ``v``: the stroke (m) and its rate (m/s); ``q``, ``qd``: the modal
    coordinates and rates; ``tb``: the modal tables (:class:`sim_core.rom.ModalTables`)."""

    def __init__(self, booms: int, payload: float, angle_deg: float, stroke0: float,
                 n_modes: int):
        name, base = MODAL_SCENES[booms]
        L0 = float(stroke0)
        _, _, (L_lo, L_hi) = allowed_ranges(n_booms=booms)
        scene = load_scene(name, overrides={
            **base, "model.n_modes": int(n_modes), "payload.mass": float(payload),
            "booms.luffing_angle_deg": float(angle_deg), "booms.stroke0": L0,
            # the modal scene's drive is the cubic schedule from L0 (at rest there); a slow one
            # (1.2 m over 12 s) towards the tables' far end keeps its stroke history within
            # them from any L0.  The env commands the stroke from the first step on.
            "drive.v_max": 0.1, "drive.t_hold_end": 12.0,
            "drive.direction": "extraction" if L0 <= 0.5 * (L_lo + L_hi) else "retraction"})
        self.sim = Simulation(scene)
        self.tb = self.sim.system
        self.start = self.sim.save_state()

    def reset(self) -> None:
        """Back to the start state (rest, static equilibrium at L0)."""
        self.sim.restore_state(self.start)

    def advance(self, segments, dt: float, end: tuple[float, float]) -> None:
        """One control step of ``dt`` s along the stroke ``segments`` ((acceleration, duration,
        rate jump at its end), ...), ending at (L_s, L_s') = ``end``."""
        self.sim.advance(dt, {"telescopic": Command(tuple(segments), end)})

    def tip_deflection(self) -> tuple[float, float, float, float]:
        """(dX, dZ, dX', dZ') of the tip from the static tip at the current L_s (m, m/s)."""
        out = self.sim.outputs(("tip_deflection", "tip_deflection_rate"))
        d, dv = out["tip_deflection"], out["tip_deflection_rate"]
        return float(d[0]), float(d[2]), float(dv[0]), float(dv[2])

    def _state(self, key):
        return self.sim.outputs((key,))[key]

    @property
    def L(self) -> float:
        return self._state("actuators")["telescopic"][0]

    @property
    def v(self) -> float:
        return self._state("actuators")["telescopic"][1]

    @property
    def q(self) -> np.ndarray:
        return self._state("modal_coordinates")

    @property
    def qd(self) -> np.ndarray:
        return self._state("modal_rates")


class TelescopicBoomEnv(gym.Env):
    """See the module docstring for spaces, reward, start state and episode end."""

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 20}
    #: modal plants kept per configuration (booms, n_modes, payload, angle, L0): a reset with
    #: the same configuration restores the start state instead of rebuilding
    MODAL_CACHE = 4

    def __init__(self, task: str = "extraction", fidelity: str = "rl", render_mode=None,
                 dt: float = 0.05, a_max: float = 0.25, v_max: float = 0.5,
                 stroke_limits: tuple[float, float] | None = None, t_max: float = 30.0,
                 booms: int = 3, payload: float | None = None, luffing_angle_deg: float = 60.0,
                 payload_range: tuple[float, float] | None = None,
                 angle_range: tuple[float, float] | None = None,
                 n_modes: int = 3, paper_n_nodes: int = 3, paper_friction: bool = False,
                 w_time: float = 1.0, w_progress: float = 10.0, w_deflection: float = 1.0,
                 w_rate: float = 1.0, w_effort: float = 0.1, w_jerk: float = 0.1,
                 w_end_stop: float = 10.0, bonus: float = 50.0, reward_scale: float = 0.01,
                 observe_parameters: bool = False,
                 tol_stroke: float = 5e-3, tol_speed: float = 5e-3,
                 tol_deflection: float | None = None, tol_deflection_rate: float | None = None,
                 d_ref: float | None = None, dv_ref: float | None = None,
                 render_exaggeration: float = 500.0):
        if task not in ("extraction", "retraction"):
            raise ValueError(f"task = {task!r}: allowed 'extraction', 'retraction'")
        if fidelity not in FIDELITIES:
            raise ValueError(f"fidelity = {fidelity!r}: allowed "
                             f"{', '.join(map(repr, FIDELITIES))}")
        if isinstance(booms, bool) or booms not in BOOMS:
            raise ValueError(f"booms = {booms!r}: allowed {', '.join(map(str, BOOMS))} (the boom "
                             "counts with shipped modal tables, synchronized drive)")
        self.booms = int(booms)
        # every numeric argument: a real number (TypeError otherwise), finite and in its range
        # (ValueError), the message naming the argument
        for name, v, lo in (("dt", dt, 0.0), ("a_max", a_max, 0.0), ("v_max", v_max, 0.0),
                            ("t_max", t_max, 0.0), ("reward_scale", reward_scale, 0.0),
                            ("render_exaggeration", render_exaggeration, 0.0)):
            _real(name, v, lo, strict=True)
        for name, v in (("w_time", w_time), ("w_progress", w_progress),
                        ("w_deflection", w_deflection), ("w_rate", w_rate), ("w_effort", w_effort),
                        ("w_jerk", w_jerk), ("w_end_stop", w_end_stop), ("bonus", bonus),
                        ("tol_stroke", tol_stroke), ("tol_speed", tol_speed)):
            _real(name, v, 0.0)
        for name, v in (("tol_deflection", tol_deflection),
                        ("tol_deflection_rate", tol_deflection_rate)):
            if v is not None:
                _real(name, v, 0.0)
        for name, v in (("d_ref", d_ref), ("dv_ref", dv_ref)):
            if v is not None:
                _real(name, v, 0.0, strict=True)
        if payload is not None:
            _real("payload", payload)
        _real("luffing_angle_deg", luffing_angle_deg)
        for name, v in (("stroke_limits", stroke_limits), ("payload_range", payload_range),
                        ("angle_range", angle_range)):
            if v is not None:
                range_pair(name, v, -math.inf, math.inf)
        if isinstance(paper_n_nodes, bool) or not isinstance(paper_n_nodes, (int, np.integer)) \
                or not 3 <= paper_n_nodes <= 33:
            raise ValueError(f"paper_n_nodes = {paper_n_nodes!r}: allowed integers 3..33 "
                             "(the scene key booms.n_nodes)")
        if paper_friction not in (True, False):
            raise ValueError(f"paper_friction = {paper_friction!r}: allowed True, False")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode = {render_mode!r}: allowed {self.metadata['render_modes']}")
        for name, v in (("dt", dt), ("a_max", a_max), ("v_max", v_max), ("t_max", t_max),
                        ("reward_scale", reward_scale)):
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} = {v!r}: must be finite and > 0")
        self.task, self.fidelity, self.render_mode = task, fidelity, render_mode
        self.dt, self.a_max, self.v_max, self.t_max = float(dt), float(a_max), float(v_max), float(t_max)
        (p_lo, p_hi), (ang_lo, ang_hi), (L_lo, L_hi) = allowed_ranges(n_booms=self.booms)
        self._ranges = {"payload": (p_lo, p_hi), "luffing_angle_deg": (ang_lo, ang_hi)}
        self.L_min, self.L_max = stroke_limits if stroke_limits is not None else (L_lo, L_hi)
        if not L_lo - 1e-9 <= self.L_min < self.L_max <= L_hi + 1e-9:
            raise ValueError(f"stroke_limits = {stroke_limits!r}: must lie within the modal "
                             f"tables' range [{L_lo:g}, {L_hi:g}] m")
        self.L_start0, self.L_target0 = (2.0, 8.0) if task == "extraction" else (8.0, 2.0)
        if payload is None:
            payload = DEFAULT_PAYLOAD[self.booms]
        self.payload0, self.angle0 = float(payload), float(luffing_angle_deg)
        self.payload_range, self.angle_range = payload_range, angle_range
        for nm, arg, rng in (("payload", "payload_range", payload_range),
                             ("luffing_angle_deg", "angle_range", angle_range)):
            if rng is not None:
                self._check_range(nm, rng[0], arg)
                self._check_range(nm, rng[1], arg)
        self._check_range("payload", self.payload0)
        self._check_range("luffing_angle_deg", self.angle0)
        if not (isinstance(n_modes, (int, np.integer)) and 1 <= n_modes <= 4):
            raise ValueError(f"n_modes = {n_modes!r}: allowed 1..4 (the tabulated in-plane modes)")
        self.n_modes, self.paper_n_nodes, self.paper_friction = n_modes, paper_n_nodes, paper_friction
        self.w = dict(time=w_time, progress=w_progress, deflection=w_deflection, rate=w_rate,
                      effort=w_effort, jerk=w_jerk, end_stop=w_end_stop, bonus=bonus)
        scale = DEFLECTION_SCALE[self.booms]
        opt = dict(tol_deflection=tol_deflection, tol_deflection_rate=tol_deflection_rate,
                   d_ref=d_ref, dv_ref=dv_ref)
        for name, v in opt.items():
            if v is None:
                opt[name] = scale * DEFLECTION_REFS[name]
            elif name.startswith("tol_") and not (math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} = {v!r}: must be finite and >= 0 (0: never met)")
            elif not name.startswith("tol_") and not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} = {v!r}: must be finite and > 0")
        self.tol = dict(stroke=tol_stroke, speed=tol_speed, deflection=opt["tol_deflection"],
                        rate=opt["tol_deflection_rate"])
        self.reward_scale = float(reward_scale)
        if observe_parameters not in (True, False):
            raise ValueError(f"observe_parameters = {observe_parameters!r}: allowed True, False")
        self.observe_parameters = bool(observe_parameters)
        self.d_ref, self.dv_ref = opt["d_ref"], opt["dv_ref"]
        self.exaggeration = render_exaggeration
        self.action_space = spaces.Box(-1.0, 1.0, (1,), np.float32)
        low = np.array([self.L_min, -v_max, -a_max, self.L_min, 0.0, -1.0, -1.0, -10.0, -10.0],
                       np.float32)
        high = np.array([self.L_max, v_max, a_max, self.L_max, t_max, 1.0, 1.0, 10.0, 10.0],
                        np.float32)
        if self.observe_parameters:
            low = np.concatenate([low, np.full(2, -1.0, np.float32)])
            high = np.concatenate([high, np.full(2, 1.0, np.float32)])
        self.observation_space = spaces.Box(low, high, dtype=np.float32)
        self._fig = None
        self._state = None
        self.plant = None
        self._modal_plants: dict = {}
        self._L = self._v = 0.0

    # -- helpers ---------------------------------------------------------------------------
    @property
    def rom(self):
        """The plant (its former name): ``L``, ``v`` (m, m/s) and ``advance``; with fidelity
        "rl" the :class:`ModalPlant` (also ``q``, ``qd``, ``tb``)."""
        return self.plant

    @property
    def _ts(self):
        """The full model's system (fidelity "paper"/"converged"; diagnostics and tests)."""
        return self.plant.system

    @property
    def _y(self):
        """The full model's integrated state (z, z') (fidelity "paper"/"converged")."""
        return self.plant.state

    def _check_range(self, name, value, arg=None):
        """``value`` of quantity ``name`` within the tables' range; the error names ``arg`` (the
        argument that gave it, default ``name``)."""
        lo, hi = self._ranges[name]
        if not (math.isfinite(value) and lo - 1e-9 <= value <= hi + 1e-9):
            given = name if arg is None else f"{arg} entry {name}"
            raise ValueError(f"{given} = {value!r} outside the modal tables' range "
                             f"[{lo:g}, {hi:g}] of booms = {self.booms} "
                             "(sim_core.rom.allowed_ranges)")

    def _normalised(self, name, value):
        """``value`` mapped linearly from the tables' range of ``name`` to [-1, 1]."""
        lo, hi = self._ranges[name]
        return (2.0 * value - lo - hi) / (hi - lo)

    def _segments(self, L, v, a):
        """Exact stroke kinematics over one step: list of (a_eff s^-2, duration s, dv jump at
        its end m/s) with velocity saturation and inelastic end stops.  Returns (segments,
        L_end, v_end, saturated, end_stop)."""
        t_left, segs = self.dt, []
        sat = stop = False
        for _ in range(8):
            if t_left <= 1e-12:
                break
            at_max = L >= self.L_max - 1e-12 and v >= 0
            at_min = L <= self.L_min + 1e-12 and v <= 0
            ae = a
            if (v >= self.v_max - 1e-12 and a > 0) or (v <= -self.v_max + 1e-12 and a < 0):
                ae, sat = 0.0, True
            if (at_max and ae > 0) or (at_min and ae < 0):
                ae = 0.0
                stop = True
            t_v = math.inf
            if ae > 0:
                t_v = (self.v_max - v) / ae
            elif ae < 0:
                t_v = (-self.v_max - v) / ae
            t_s = min(_first_hit(L, v, ae, self.L_max), _first_hit(L, v, ae, self.L_min))
            tau = min(t_left, t_v, t_s)
            L = L + v * tau + 0.5 * ae * tau * tau
            v = v + ae * tau
            jump = 0.0
            if tau == t_s and tau < t_left + 1e-15:
                L = min(max(L, self.L_min), self.L_max)
                jump, v, stop = -v, 0.0, True
            elif tau == t_v:
                v = math.copysign(self.v_max, v)
                sat = True
            segs.append((ae, tau, jump))
            t_left -= tau
        if t_left > 1e-12:                                  # pathological: hold
            segs.append((0.0, t_left, 0.0))
        L = min(max(L, self.L_min), self.L_max)
        return segs, L, v, sat, stop

    # -- Gymnasium API -----------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        options = dict(options or {})
        unknown = set(options) - {"payload", "luffing_angle_deg", "stroke_start", "stroke_target"}
        if unknown:
            raise ValueError(f"reset options {sorted(unknown)} unknown; allowed payload, "
                             "luffing_angle_deg, stroke_start, stroke_target")
        payload = self.payload0
        angle = self.angle0
        if self.payload_range is not None:
            payload = float(self.np_random.uniform(*self.payload_range))
        if self.angle_range is not None:
            angle = float(self.np_random.uniform(*self.angle_range))
        payload = float(options.get("payload", payload))
        angle = float(options.get("luffing_angle_deg", angle))
        self._check_range("payload", payload)
        self._check_range("luffing_angle_deg", angle)
        L0 = float(options.get("stroke_start", self.L_start0))
        Lt = float(options.get("stroke_target", self.L_target0))
        for nm, x in (("stroke_start", L0), ("stroke_target", Lt)):
            if not (math.isfinite(x) and self.L_min <= x <= self.L_max):
                raise ValueError(f"{nm} = {x!r}: allowed [{self.L_min:g}, {self.L_max:g}] m")
        self.payload, self.angle = payload, angle
        self.L_target, self.travel = Lt, max(abs(Lt - L0), 1e-3)
        self.t, self.a_prev, self._a_applied = 0.0, 0.0, 0.0
        self._L, self._v = L0, 0.0
        if self.fidelity == "rl":
            self.plant = self._modal_plant(payload, angle, L0)
            self.tables = self.plant.tb
        else:
            self.plant = FullPhysicsPlant(
                booms=self.booms, fidelity=self.fidelity, payload=payload, angle_deg=angle,
                stroke0=L0, friction=self.paper_friction if self.fidelity == "paper" else True,
                n_nodes=self.paper_n_nodes if self.fidelity == "paper" else None)
            self.tables = tables_for(payload, angle, self.n_modes, n_booms=self.booms)
        self._defl = np.zeros(4)
        self._update_deflection()
        obs = self._obs()
        self._last_obs = obs
        if self.render_mode == "human":
            self.render()
        return obs, self._info(False, False)

    def _modal_plant(self, payload, angle, L0) -> ModalPlant:
        """The ROM plant of this configuration at its start state (kept for MODAL_CACHE
        configurations: a repeated configuration is restored, not rebuilt)."""
        key = (self.booms, self.n_modes, payload, angle, L0)
        plant = self._modal_plants.pop(key, None)
        if plant is None:
            plant = ModalPlant(self.booms, payload, angle, L0, self.n_modes)
        else:
            plant.reset()
        self._modal_plants[key] = plant                    # most recently used last
        while len(self._modal_plants) > self.MODAL_CACHE:
            self._modal_plants.pop(next(iter(self._modal_plants)))
        return plant

    def step(self, action):
        a_in = np.asarray(action, dtype=np.float64).reshape(-1)
        if a_in.shape != (1,):
            raise ValueError(f"action shape {np.shape(action)}: expected (1,)")
        if not np.all(np.isfinite(a_in)):
            raise ValueError(f"action = {action!r} is not finite")
        a = float(np.clip(a_in[0], -1.0, 1.0)) * self.a_max
        segs, L1, v1, sat, stop = self._segments(self._L, self._v, a)
        diverged, reason = False, ""
        try:
            self.plant.advance(segs, self.dt, (L1, v1))
            self._L, self._v = L1, v1
            self._update_deflection()
            if not math.isfinite(float(self._defl.sum())):
                raise FloatingPointError("non-finite plant state")
            dX, dZ, vX, vZ = self._defl
            if max(abs(dX), abs(dZ)) > 1.0 or max(abs(vX), abs(vZ)) > 10.0:
                raise FloatingPointError(f"tip deflection {self._defl} outside the observation bounds")
        except (SimulationError, FloatingPointError, np.linalg.LinAlgError) as exc:
            diverged, reason = True, f"{type(exc).__name__}: {exc}"
        self.t += self.dt
        a_applied = sum(ae * tau for ae, tau, _ in segs) / self.dt
        d = math.hypot(self._defl[0], self._defl[1])
        dv = math.hypot(self._defl[2], self._defl[3])
        w = self.w
        reward = -self.dt * (w["time"] + w["progress"] * abs(self._L - self.L_target) / self.travel
                             + w["effort"] * (a / self.a_max) ** 2)
        if not diverged:
            reward -= self.dt * (w["deflection"] * (d / self.d_ref) ** 2 + w["rate"] * (dv / self.dv_ref) ** 2)
        reward -= w["jerk"] * ((a - self.a_prev) / self.a_max) ** 2 + (w["end_stop"] if stop else 0.0)
        self.a_prev = a
        self._a_applied = a_applied
        settled = (not diverged and abs(self._L - self.L_target) < self.tol["stroke"]
                   and abs(self._v) < self.tol["speed"] and d < self.tol["deflection"]
                   and dv < self.tol["rate"])
        if settled:
            reward += w["bonus"]
        reward_unscaled = reward
        reward *= self.reward_scale
        truncated = diverged or self.t >= self.t_max - 1e-9
        if diverged:
            obs = self._last_obs
        else:
            obs = self._obs()
            self._last_obs = obs
        info = self._info(sat, stop)
        info.update(diverged=diverged, reason=reason, success=settled,
                    reward_unscaled=float(reward_unscaled))
        if self.render_mode == "human":
            self.render()
        return obs, float(reward), bool(settled), bool(truncated), info

    def _obs(self):
        a = self._a_applied
        o = [self._L, self._v, a, self.L_target, max(self.t_max - self.t, 0.0), *self._defl]
        if self.observe_parameters:
            o += [self._normalised("payload", self.payload),
                  self._normalised("luffing_angle_deg", self.angle)]
        o = np.array(o, dtype=np.float64)
        return np.clip(o, self.observation_space.low, self.observation_space.high).astype(np.float32)

    def _info(self, sat, stop):
        return {"time": self.t, "stroke": self._L, "stroke_rate": self._v,
                "velocity_saturated": bool(sat), "end_stop": bool(stop),
                "tip_deflection": self._defl[:2].copy(), "payload": self.payload,
                "luffing_angle_deg": self.angle, "fidelity": self.fidelity, "booms": self.booms,
                "diverged": False, "reason": ""}

    def _update_deflection(self):
        """self._defl = (dX, dZ, dX', dZ') of the tip relative to the static tip at L_s (m, m/s)."""
        self._defl = np.array(self.plant.tip_deflection(), dtype=np.float64)

    # -- rendering ---------------------------------------------------------------------------
    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; set render_mode='rgb_array' or 'human'")
            return None
        frame = self._draw()
        if self.render_mode == "rgb_array":
            return frame
        import matplotlib.pyplot as plt
        if getattr(self, "_human", None) is None:
            plt.ion()
            self._human = plt.figure("boom_env")
            self._human_im = self._human.add_subplot(111).imshow(frame)
            self._human.axes[0].axis("off")
        else:
            self._human_im.set_data(frame)
        plt.pause(1.0 / self.metadata["render_fps"])
        return None

    def _draw(self):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        if self._fig is None:
            self._fig = Figure(figsize=(4.8, 3.6), dpi=100)
            FigureCanvasAgg(self._fig)
            self._ax = self._fig.add_subplot(111)
        ax = self._ax
        ax.clear()
        geo = luffing_geometry(math.radians(self.angle))
        O, e = np.asarray(geo.origin)[[0, 2]], np.asarray(geo.e_s)[[0, 2]]
        L = self._L
        d = self.exaggeration * self._defl[:2]
        n = self.booms
        total = (n - 1) * L + BOOM_LENGTH                  # boom k's left end at k L_s (synchronized)
        colours = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")
        for k in range(n):
            s = np.linspace(k * L, k * L + BOOM_LENGTH, 20)
            x = s / total
            shape = 0.5 * x * x * (3 - x)          # cantilever-like interpolation of the tip deflection
            pts = O[None] + s[:, None] * e[None] + shape[:, None] * d[None]
            ax.plot(pts[:, 0], pts[:, 1], color=colours[k % len(colours)], lw=7 - 4 * k / (n - 1),
                    solid_capstyle="butt")
        tip = O + total * e + d
        ax.plot(*tip, "ks", ms=8)
        tgt = O + ((n - 1) * self.L_target + BOOM_LENGTH) * e
        ax.plot(*tgt, "r+", ms=12)
        reach = (n - 1) * self.L_max + BOOM_LENGTH + 2.0   # the longest boom fits
        ax.set_xlim(-2, max(16.0, O[0] + reach * e[0]))
        ax.set_ylim(-1, max(26.0, O[1] + reach * e[1]))
        ax.set_aspect("equal")
        ax.set_title(f"t = {self.t:5.2f} s  L_s = {L:5.3f} m  |d| = {1e3 * math.hypot(*self._defl[:2]):.2f} mm"
                     f" (x{self.exaggeration:g})", fontsize=8)
        ax.set_xlabel("X (m)", fontsize=8)
        ax.set_ylabel("Z (m)", fontsize=8)
        self._fig.canvas.draw()
        buf = np.asarray(self._fig.canvas.buffer_rgba())
        return np.ascontiguousarray(buf[:, :, :3]).astype(np.uint8)

    def close(self):
        if getattr(self, "_human", None) is not None:
            import matplotlib.pyplot as plt
            plt.close(self._human)
            self._human = None
        self._fig = None


def _real(name, value, lo=-math.inf, strict=False):
    """``value`` as a float (a real, finite number: :func:`boom_env._checks.number`), >= lo
    (> lo with ``strict``; ValueError otherwise), the message naming the argument."""
    v = number(name, value)
    if v < lo or (strict and v == lo):
        bound = f"> {lo:g}" if strict else f">= {lo:g}"
        raise ValueError(f"{name} = {value!r}: must be finite and {bound}")
    return v


def _first_hit(L, v, a, stop):
    """Smallest t > 0 with L + v t + a t^2 / 2 = stop moving towards it (inf if never)."""
    if (stop > L and v <= 0 and a <= 0) or (stop < L and v >= 0 and a >= 0) or stop == L:
        return math.inf
    if abs(a) < 1e-15:
        # linear; a stop behind the motion is never hit (this returned a negative time, and a
        # 1e-15 m/s^2 braking command at full speed jumped the stroke to the far end stop)
        t = (stop - L) / v if v != 0 else math.inf
        return t if t > 0 else math.inf
    disc = v * v + 2 * a * (stop - L)
    if disc < 0:
        return math.inf
    # a t^2/2 + v t + (L - stop) = 0 in the cancellation-free form q = -(v + sign(v) r)
    r = math.sqrt(disc)
    q = -(v + math.copysign(r, v))
    cands = [q / a]
    if q != 0.0:
        cands.append(2.0 * (L - stop) / q)
    roots = [t for t in cands if t > 1e-15]
    return min(roots) if roots else math.inf
