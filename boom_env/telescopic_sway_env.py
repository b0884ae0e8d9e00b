"""Telescopic-boom extraction / retraction with a swinging payload (Gymnasium environment, v1).

The crane of Zhao-Qi-Wang 2024 (three nested flexible booms, or five sections with
``booms=5``) extends or retracts its telescopic cylinder from a start to a target piston
length L_s while the payload hangs on its hoist rope below the boom tip.  The agent commands
the cylinder acceleration; the flexible booms vibrate and the payload sways.  The goal is to
reach the target quickly and leave as little tip vibration and payload sway as possible.

The ids ``boom_env/TelescopicExtraction-v1`` and ``boom_env/TelescopicRetraction-v1`` make
:class:`TelescopicSwayEnv`; ``gym.make_vec(id, num_envs=N)`` (vectorization mode
``"vector_entry_point"``, the default for these ids) makes the native vector env
:class:`boom_env.vector_env.TelescopicSwayVectorEnv`, which steps all N cranes in one array
call.  Both run the same code: the scalar env is the batch of one, so their trajectories agree
to round-off (tests/env/test_vector_env.py).

Dynamics
--------
The plant is :class:`sim_core.vector_rom.VectorROM`: the stroke-parametric modal ROM of the full
sim_core model (``sim_core.systems.telescopic.modal``, the v0 plant) with the payload (mass m,
payload and hook) on a rope of length l as a pendulum coupled to the tip
(``sim_core.systems.telescopic.modal_batch``, module docstring: the Lagrange equations, the
Ritz argument, the small-angle range).  Vertically the payload moves with the tip (the rope is
stiff along its length), horizontally it is held by the rope's inclination: its horizontal
inertia leaves the bending modes (the three-boom first in-plane frequency at 25 t, 60 deg,
L_s = 5 m rises from 0.71 Hz with the payload fixed at the tip to 1.23 Hz hanging) and a
pendulum mode near sqrt(g / l) / (2 pi) appears (0.216 Hz at l = 5 m; full model with
``payload_swing``: 0.2155 Hz).  The out-of-plane sway is a free pendulum (the tables hold no
lateral boom modes), excited only by a start sway (reset option ``sway``).

Stroke friction (``friction=True``, default): the stages stick and slip on their sliders
behind the telescopic cylinder's oil column (``sim_core.systems.telescopic.modal_batch``,
Stroke friction): the action accelerates the piston; the stages follow it through the oil
column's stiffness and damping against the sliders' Coulomb friction mu N (mu_static = 0.15,
mu_dynamic = 0.1 of the paper and the scene defaults; N the sliders' total normal load of the
full model's static equilibria, 330-875 kN for three booms at 25 t, 60 deg).  A held stage
breaks away when the oil column's force reaches mu_static N (the piston then leads it by up to
mu_static N / k_h: 6 mm at L_s = 2 m, 5 cm at 8 m) and lurches forward when the friction drops to
mu_dynamic N: stick-slip.  Hydraulic parameters (constructor arguments): ``cylinder_area``
0.02 m^2, ``bulk_modulus`` 1e9 Pa, ``dead_length`` 0.5 m, ``hydraulic_damping`` 0.2;
``mu_static``, ``mu_dynamic``.  ``friction=False``: the stages follow the piston exactly (v0's
kinematics).  ``friction_law``: ``"coulomb"`` (default) the stick and slip above;
``"regularised"`` the full model's own law (a damper mu_static N / v_eps below v_eps =
0.01 m/s, the cubic blend to mu_dynamic up to 2 v_eps): a stage whose column force stays below
breakaway creeps after the piston with the time constant (mu_static N / v_eps) / k_h, 0.6-5 s
over the stroke at 25 t, instead of standing still (``info["stuck"]`` then means |L_s'| <
v_eps, as on the full model).  The full-model fidelities always use the regularised law.

Stroke kinematics of the piston as v0: the action is held for ``dt`` (piecewise-constant
acceleration), exact integration with velocity saturation |v| <= v_max
(``info["velocity_saturated"]``) and inelastic end stops (``info["end_stop"]``).

Fidelity (``fidelity``)
-----------------------
* ``"rl"`` (default): the batched ROM above (one compiled call per step for all cranes of the
  native vector env; env steps per second on one core: benchmarks/results/vector_env_speed.md).
* ``"paper"``, ``"converged"``, ``"train"``: the full sim_core model with the payload on its hoist rope
  (``boom_env.full_physics.FullPhysicsPlant``, its fidelities; the scene's 500 kg hook hangs
  with the payload, the rope's unstretched length is the loaded ``rope_length`` over
  1 + m g / EA) driven along the piston kinematics.  With ``friction=True`` the full model's
  cylinder drives the stages through its oil column (``effects.oil_column``: the same
  ``cylinder_area``, ``bulk_modulus``, ``dead_length``, ``hydraulic_damping`` and friction
  coefficients as the ROM's stroke friction) against its own slider friction (Section 8), so
  its stages stick and slip behind the piston as the ROM's do; the observed L_s, its rate and
  the applied acceleration are then its stages' (``info["stuck"]``: their rate within the
  friction law's stick band, |L_s'| < v_eps = 0.01 m/s).  ``friction=False``: the stages
  follow the piston exactly.  The scalar env only.  ``"paper"`` and ``"converged"`` are slow
  (a few env steps per second): for checking policies; ``"train"`` (the coarse mesh, ROS2 at
  the control step and the relaxed regularisations of ``boom_env.full_physics.FIDELITIES``)
  runs about ten times faster than real time, for fine-tuning on the full model.

Action space
------------
``Box(-1, 1, (1,), float32)``: commanded cylinder acceleration a = action * a_max (m/s^2),
a_max = 0.25 m/s^2 by default.  Non-finite actions raise ValueError; finite actions outside
[-1, 1] are clipped.

Observation space
-----------------
``Box(low, high, (13,), float32)``, SI units (``(16,)`` with ``observe_parameters=True``):

====  ===============================================  ===============================
 idx  quantity                                          bounds
====  ===============================================  ===============================
  0   piston length L_s (m)                             [L_min, L_max]
  1   stroke rate v = dL_s/dt (m/s)                     [-v_max, v_max]
  2   applied acceleration of the last step (m/s^2)     [-a_max, a_max]
  3   target piston length L* (m)                       [L_min, L_max]
  4   time left t_max - t (s)                           [0, t_max]
  5   tip deflection dX (m) from the static tip at L_s  [-1, 1]
  6   tip deflection dZ (m)                             [-1, 1]
  7   rate of dX (m/s)                                  [-10, 10]
  8   rate of dZ (m/s)                                  [-10, 10]
  9   sway angle in the luffing plane theta (rad)       [-sway_limit, sway_limit]
 10   sway angle across the luffing plane psi (rad)     [-sway_limit, sway_limit]
 11   rate of theta (rad/s)                             [-r_max, r_max]
 12   rate of psi (rad/s)                               [-r_max, r_max]
 13   payload, normalised (only observe_parameters)     [-1, 1]
 14   luffing angle, normalised (observe_parameters)    [-1, 1]
 15   rope length, normalised (observe_parameters)      [-1, 1]
====  ===============================================  ===============================

Entries 0-8 are v0's; L_s and its rate are the stages' (with friction the piston leads them by
the oil column's compression): the rate is exactly 0 while the stages stick, which tells stick
from slip (``info["stuck"]`` says it too).  The applied acceleration (2) is the stages' mean
acceleration over the step.  The sway angles are those of the rope from the vertical (theta positive
towards +X, away from the crane; psi towards +Y), as the full model's ``sway_angle`` output.
sway_limit = 0.3 rad (the small-angle range of the pendulum model, a constructor argument <=
0.3); r_max = 2 sway_limit sqrt(g / l_min), l_min = 1 m: twice the largest rate of a free
swing of amplitude sway_limit.  A deflection, sway or rate outside its bounds ends the episode
(truncated, ``info["reason"]``).  Entries 13-15 map the episode's payload, angle and rope length
linearly from their ranges (the tables' payload and angle ranges,
``sim_core.systems.telescopic.modal.allowed_ranges``, and ``ROPE_RANGE`` = 1-10 m) to [-1, 1].

Reward (per step; all weights are constructor arguments)
--------------------------------------------------------
    r = reward_scale * (
        v0's terms: - w_time dt - w_progress |L_s - L*| / travel dt
                    - w_deflection (|d| / d_ref)^2 dt - w_rate (|d'| / dv_ref)^2 dt
                    - w_effort (a / a_max)^2 dt - w_jerk ((a - a_prev) / a_max)^2
                    - w_end_stop [end stop hit this step]
        - w_sway (|s| / sway_ref)^2 dt                      (payload sway, |s|^2 = theta^2 + psi^2)
        - w_sway_rate (|s'| / sway_rate_ref)^2 dt           (sway rate)
        + bonus [success])
Defaults: v0's weights (w_time = 1, w_progress = 10, w_deflection = 1, w_rate = 1,
w_effort = 0.1, w_jerk = 0.1, w_end_stop = 10, bonus = 50, reward_scale = 0.01) and w_sway = 1,
w_sway_rate = 1.  Reference scales (``d_ref``, ``dv_ref``, ``sway_ref``, ``sway_rate_ref``): 5 cm,
8 cm/s, 0.05 rad, 0.07 rad/s for three booms; 15 cm, 24 cm/s, 0.1 rad, 0.14 rad/s for five.
They are larger than v0's because the hanging payload pulls the tip sideways by m g theta:
the tip deflection follows the sway (about 1 m of deflection per rad of sway for three booms,
2 m for five), cm-scale where v0's was mm-scale.  They are chosen so that moving to the target
on the reference schedules scores better than standing still (-330 unscaled for every variant):
the paper's cubic schedule (agents.schedules) scores -168.9 (extraction, three booms), -172.6
(five booms), -339.8 and -322.4 (retraction, where the breakaway from 8 m, against the largest
normal load, lurches the stages and leaves ~0.07 rad of sway); the constant-acceleration
trapezoid of the same duration -135.4, -126.9, -253.1, -234.5 (its 4 s ramps are close to the
pendulum period, ~4.5-5 s, and leave little sway).
``info["reward_unscaled"]`` is the step's reward before scaling.

Start state
-----------
Static equilibrium at rest at L_start (extraction 2 m -> 8 m, retraction 8 m -> 2 m), payload
hanging still (no sway), payload 25 t (``booms=3``) or 10 t (``booms=5``), rope length 5 m,
luffing angle 60 deg unless given.  ``reset(seed=..., options=...)``: options may set
``payload`` (kg), ``luffing_angle_deg`` (deg), ``rope_length`` (m), ``stroke_start``,
``stroke_target`` (m) and ``sway`` ((theta, psi) rad: a start sway, payload at rest).  Domain
randomisation: ``payload_range``, ``angle_range``, ``rope_range`` ((lo, hi)) draw them uniformly
from ``self.np_random`` at every reset, in that order (seeded through reset(seed)).

Episode end
-----------
* terminated (success): |L_s - L*| < tol_stroke (5 mm), |v| < tol_speed (5 mm/s),
  |d| < tol_deflection (1 cm; 3 cm with ``booms=5``), |d'| < tol_deflection_rate (2 cm/s;
  6 cm/s), |s| < tol_sway (0.005 rad, 2.5 cm of payload at 5 m) and |s'| < tol_sway_rate
  (0.007 rad/s); bonus added.
* truncated: t >= t_max (30 s; also max_episode_steps = 600 of the registration), or a
  non-finite or out-of-bounds state: ``info["diverged"] = True`` with ``info["reason"]``; the
  observation is then the last good one: never a NaN.

Rendering
---------
``render_mode="rgb_array"``: side view (X-Z plane) of the booms, tip deflection exaggerated
(``render_exaggeration``, default 20x: v1 deflections are cm-scale), the rope and the payload at their true sway angle
times ``render_sway_exaggeration`` (default 5x; a 0.02 rad swing is 10 cm on a 30 m picture),
uint8 frames (H, W, 3) drawn with matplotlib's Agg backend.  The vector env renders its first
sub-env.

Version history
---------------
* v1: the payload hangs on its hoist rope and sways (in and out of the luffing plane, coupled
  to the tip's modes; the payload's horizontal inertia leaves the bending modes, which raises
  their frequencies); observation entries 9-12 (sway angles and rates) and, with
  ``observe_parameters``, the rope length (entry 15); reward terms w_sway, w_sway_rate and the
  sway tolerances of success; ``rope_length`` / ``rope_range``, ``sway_limit``, reset options
  ``rope_length`` and ``sway``; truncation beyond the sway bounds; stick-slip friction of the
  stages behind the oil column (``friction``, on by default; ``info["stuck"]``); reference
  scales and success tolerances of the deflection for cm-scale deflections; a native vector
  env (``vector_entry_point``, autoreset NEXT_STEP); fidelities "rl" (ROM) and "paper" /
  "converged" (full model, scalar env); render exaggeration 20x.  The full-model fidelities
  with friction drive the stages through the cylinder's oil column, as the ROM does (before,
  the full model's stages followed the piston exactly while the ROM's stuck and slipped).
  Option ``friction_law="regularised"`` (the default ``"coulomb"`` unchanged); fidelity
  ``"train"`` (additive).
* v0: ``boom_env.telescopic_env`` (payload fixed at the tip; its own version history).
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sim_core.vector_rom import ROPE_RANGE, SWAY_LIMIT, TABLE_BOOMS, VectorROM, allowed_ranges

from . import _sway_kernel as kernel
from ._checks import flag as _flag
from ._checks import in_range as _in_range
from ._checks import integer as _integer
from ._checks import nonneg as _nonneg
from ._checks import positive as _positive
from ._checks import range_pair as _range_pair

BOOM_LENGTH = 10.0                            # m, docs/model.md#input-sections
DEFAULT_PAYLOAD = {3: 25000.0, 5: 10000.0}    # kg, as v0
DEFAULT_ROPE = 5.0                            # m
# reference scales of the reward and success tolerances per boom count (module docstring,
# Reward): m, m/s, rad, rad/s
REFS = {3: {"d_ref": 0.05, "dv_ref": 0.08, "sway_ref": 0.05, "sway_rate_ref": 0.07,
            "tol_deflection": 0.01, "tol_deflection_rate": 0.02, "tol_sway": 0.005,
            "tol_sway_rate": 0.007},
        5: {"d_ref": 0.15, "dv_ref": 0.24, "sway_ref": 0.1, "sway_rate_ref": 0.14,
            "tol_deflection": 0.03, "tol_deflection_rate": 0.06, "tol_sway": 0.005,
            "tol_sway_rate": 0.007}}
G = 9.81
RESET_OPTIONS = ("payload", "luffing_angle_deg", "rope_length", "stroke_start",
                 "stroke_target", "sway")
FIDELITIES = ("rl", "paper", "converged", "train")
HOIST_EA, HOOK_MASS = 2e8, 500.0             # N, kg: the crane scenes' hoist rope and hook


class SwayTask:
    """The v1 task for N cranes at once: configuration, per-crane random generators, the
    plant (VectorROM), observation, reward and episode end as arrays.  The scalar env is a
    SwayTask of one crane, the vector env one of N (module docstring for the definitions)."""

    def __init__(self, n_envs: int, task: str = "extraction", fidelity: str = "rl",
                 dt: float = 0.05, a_max: float = 0.25, v_max: float = 0.5,
                 stroke_limits=None, t_max: float = 30.0, booms: int = 3, payload=None,
                 luffing_angle_deg: float = 60.0, rope_length: float = DEFAULT_ROPE,
                 payload_range=None, angle_range=None, rope_range=None, n_modes: int = 3,
                 w_time: float = 1.0, w_progress: float = 10.0, w_deflection: float = 1.0,
                 w_rate: float = 1.0, w_effort: float = 0.1, w_jerk: float = 0.1,
                 w_end_stop: float = 10.0, w_sway: float = 1.0, w_sway_rate: float = 1.0,
                 bonus: float = 50.0, reward_scale: float = 0.01,
                 observe_parameters: bool = False, tol_stroke: float = 5e-3,
                 tol_speed: float = 5e-3, tol_deflection=None, tol_deflection_rate=None,
                 tol_sway=None, tol_sway_rate=None, d_ref=None, dv_ref=None, sway_ref=None,
                 sway_rate_ref=None, sway_limit: float = SWAY_LIMIT, friction: bool = True,
                 mu_static=None, mu_dynamic=None, cylinder_area: float = 0.02,
                 bulk_modulus: float = 1.0e9, dead_length: float = 0.5,
                 hydraulic_damping: float = 0.2, friction_law: str = "coulomb",
                 max_episode_steps=None):
        if not isinstance(task, str) or task not in ("extraction", "retraction"):
            raise ValueError(f"task = {task!r}: allowed 'extraction', 'retraction'")
        if not isinstance(fidelity, str) or fidelity not in FIDELITIES:
            raise ValueError(f"fidelity = {fidelity!r}: allowed {', '.join(map(repr, FIDELITIES))}")
        if fidelity != "rl" and n_envs != 1:
            raise ValueError(f"fidelity = {fidelity!r} steps the full model: one env at a time "
                             "(the scalar env; the vector env is fidelity 'rl' only)")
        self.booms = _integer("booms", booms, tuple(TABLE_BOOMS))
        self.n_modes = _integer("n_modes", n_modes, (1, 2, 3, 4))
        self.task, self.fidelity = task, fidelity
        self.dt = _positive("dt", dt, 1.0)
        self.a_max = _positive("a_max", a_max, 10.0)
        self.v_max = _positive("v_max", v_max, 10.0)
        self.t_max = _positive("t_max", t_max, 1e5)
        self.reward_scale = _positive("reward_scale", reward_scale)
        self.sway_limit = _positive("sway_limit", sway_limit, SWAY_LIMIT)
        if max_episode_steps is not None:
            max_episode_steps = _integer("max_episode_steps", max_episode_steps,
                                         range(1, 10 ** 9))
        self.max_episode_steps = max_episode_steps
        (p_lo, p_hi), (a_lo, a_hi), (L_lo, L_hi) = allowed_ranges(n_booms=self.booms)
        self.ranges = {"payload": (p_lo, p_hi), "luffing_angle_deg": (a_lo, a_hi),
                       "rope_length": ROPE_RANGE}
        if stroke_limits is None:
            self.L_min, self.L_max = L_lo, L_hi
        else:
            lims = _range_pair("stroke_limits", stroke_limits, L_lo, L_hi)
            if lims[0] >= lims[1]:
                raise ValueError(f"stroke_limits = {stroke_limits!r}: L_min < L_max needed")
            self.L_min, self.L_max = lims
        self.L_start0, self.L_target0 = (2.0, 8.0) if task == "extraction" else (8.0, 2.0)
        if not (self.L_min <= min(self.L_start0, self.L_target0)
                and max(self.L_start0, self.L_target0) <= self.L_max):
            self.L_start0 = min(max(self.L_start0, self.L_min), self.L_max)
            self.L_target0 = min(max(self.L_target0, self.L_min), self.L_max)
        self.payload0 = _in_range("payload", DEFAULT_PAYLOAD[self.booms] if payload is None
                                  else payload, p_lo, p_hi)
        self.angle0 = _in_range("luffing_angle_deg", luffing_angle_deg, a_lo, a_hi)
        self.rope0 = _in_range("rope_length", rope_length, *ROPE_RANGE)
        self.payload_range = _range_pair("payload_range", payload_range, p_lo, p_hi)
        self.angle_range = _range_pair("angle_range", angle_range, a_lo, a_hi)
        self.rope_range = _range_pair("rope_range", rope_range, *ROPE_RANGE)
        w = dict(time=w_time, progress=w_progress, deflection=w_deflection, rate=w_rate,
                 effort=w_effort, jerk=w_jerk, end_stop=w_end_stop, sway=w_sway,
                 sway_rate=w_sway_rate, bonus=bonus)
        self.w = {k: _nonneg(("w_" + k) if k != "bonus" else k, v) for k, v in w.items()}
        opt = dict(tol_deflection=tol_deflection, tol_deflection_rate=tol_deflection_rate,
                   tol_sway=tol_sway, tol_sway_rate=tol_sway_rate, d_ref=d_ref, dv_ref=dv_ref,
                   sway_ref=sway_ref, sway_rate_ref=sway_rate_ref)
        for name, v in opt.items():
            if v is None:
                opt[name] = REFS[self.booms][name]
            elif name.startswith("tol_"):
                opt[name] = _nonneg(name, v)
            else:
                opt[name] = _positive(name, v)
        self.tol = dict(stroke=_nonneg("tol_stroke", tol_stroke),
                        speed=_nonneg("tol_speed", tol_speed),
                        deflection=opt["tol_deflection"], rate=opt["tol_deflection_rate"],
                        sway=opt["tol_sway"], sway_rate=opt["tol_sway_rate"])
        self.d_ref, self.dv_ref = opt["d_ref"], opt["dv_ref"]
        self.sway_ref, self.sway_rate_ref = opt["sway_ref"], opt["sway_rate_ref"]
        self.observe_parameters = _flag("observe_parameters", observe_parameters)
        self.n = int(n_envs)
        self.friction = _flag("friction", friction)
        fr = {}
        if self.friction:
            for name, v in (("mu_static", mu_static), ("mu_dynamic", mu_dynamic)):
                if v is not None:
                    fr[name] = _in_range(name, v, 0.0, 2.0)
            fr.update(cylinder_area=_positive("cylinder_area", cylinder_area, 1.0),
                      bulk_modulus=_positive("bulk_modulus", bulk_modulus, 1e11),
                      dead_length=_positive("dead_length", dead_length, 100.0),
                      hydraulic_damping=_positive("hydraulic_damping", hydraulic_damping, 0.99))
        self.full = fidelity != "rl"
        self.plant = None
        # the full model with friction drives its stages through the oil column of the same
        # hydraulic parameters and friction coefficients as the ROM's stroke friction
        self._plant_kw = {}
        if self.full and self.friction:
            self._plant_kw = dict(
                oil_column=True, mu_static=fr.get("mu_static"), mu_dynamic=fr.get("mu_dynamic"),
                hydraulics=dict(cylinder_area=fr["cylinder_area"],
                                bulk_modulus=fr["bulk_modulus"], dead_length=fr["dead_length"],
                                damping_ratio=fr["hydraulic_damping"]))
        # the stages' stroke and rate (m, m/s) where the full model's oil column sets them
        self.stage = np.zeros((self.n, 2))
        # the full model takes its friction itself; the ROM then only provides the kinematics
        # (VectorROM checks friction_law in every case)
        rom_friction = self.friction and not self.full
        self.rom = VectorROM(self.n, booms=self.booms, n_modes=self.n_modes, payload_swing=True,
                             dt=self.dt, v_max=self.v_max, stroke_limits=(self.L_min, self.L_max),
                             friction=rom_friction, friction_law=friction_law,
                             **(fr if rom_friction else {}))
        self.rate_max = 2.0 * self.sway_limit * math.sqrt(G / ROPE_RANGE[0])
        low = [self.L_min, -self.v_max, -self.a_max, self.L_min, 0.0, -1.0, -1.0, -10.0, -10.0,
               -self.sway_limit, -self.sway_limit, -self.rate_max, -self.rate_max]
        high = [self.L_max, self.v_max, self.a_max, self.L_max, self.t_max, 1.0, 1.0, 10.0, 10.0,
                self.sway_limit, self.sway_limit, self.rate_max, self.rate_max]
        if self.observe_parameters:
            low += [-1.0] * 3
            high += [1.0] * 3
        self.obs_low = np.array(low, np.float32)
        self.obs_high = np.array(high, np.float32)
        self._low64 = self.obs_low.astype(np.float64)
        self._high64 = self.obs_high.astype(np.float64)
        n = self.n
        self.rngs = [None] * n
        self.t = np.zeros(n)
        self.steps = np.zeros(n, np.int64)
        self.a_prev = np.zeros(n)
        self.a_applied = np.zeros(n)
        self.L_target = np.full(n, self.L_target0)
        self.travel = np.ones(n)
        self.defl = np.zeros((n, 4))
        self.sway = np.zeros((n, 4))
        self.last_obs = np.zeros((n, len(low)), np.float32)
        self.sat = np.zeros(n, bool)
        self.stop = np.zeros(n, bool)
        self.params = np.zeros((n, 3 if self.observe_parameters else 0))
        self.reward_unscaled = np.zeros(n)
        self._booms = np.full(n, self.booms)         # info arrays copied at every step
        self._no_reason = np.full(n, "", dtype=object)
        vals = dict(dt=self.dt, a_max=self.a_max, t_max=self.t_max,
                    max_steps=-1.0 if max_episode_steps is None else float(max_episode_steps),
                    **{"w_" + k: v for k, v in self.w.items() if k != "bonus"},
                    bonus=self.w["bonus"], d_ref=self.d_ref, dv_ref=self.dv_ref,
                    sway_ref=self.sway_ref, sway_rate_ref=self.sway_rate_ref,
                    **{"tol_" + k: v for k, v in self.tol.items()}, sway_limit=self.sway_limit,
                    rate_max=self.rate_max, reward_scale=self.reward_scale)
        vals["tol_deflection_rate"] = vals.pop("tol_rate")
        self.par = np.array([vals[k] for k in kernel.PAR], float)

    # -- reset ---------------------------------------------------------------------------------
    def _normalised(self, name, x):
        lo, hi = self.ranges[name]
        return (2.0 * x - lo - hi) / (hi - lo)

    def reset_envs(self, ids, options=None):
        """Reset the cranes ``ids`` (each drawing from its own generator self.rngs[i]) with
        the reset ``options`` (module docstring); returns their observations (k, d)."""
        ids = np.asarray(ids, int).reshape(-1)
        options = dict(options or {})
        unknown = set(options) - set(RESET_OPTIONS)
        if unknown:
            raise ValueError(f"reset options {sorted(unknown)} unknown; allowed "
                             f"{', '.join(RESET_OPTIONS)}")
        k = ids.size
        m = np.full(k, self.payload0)
        ang = np.full(k, self.angle0)
        ell = np.full(k, self.rope0)
        for j, i in enumerate(ids):
            rng = self.rngs[i]
            if self.payload_range is not None:
                m[j] = float(rng.uniform(*self.payload_range))
            if self.angle_range is not None:
                ang[j] = float(rng.uniform(*self.angle_range))
            if self.rope_range is not None:
                ell[j] = float(rng.uniform(*self.rope_range))
        if "payload" in options:
            m[:] = _in_range("payload", options["payload"], *self.ranges["payload"])
        if "luffing_angle_deg" in options:
            ang[:] = _in_range("luffing_angle_deg", options["luffing_angle_deg"],
                               *self.ranges["luffing_angle_deg"])
        if "rope_length" in options:
            ell[:] = _in_range("rope_length", options["rope_length"], *ROPE_RANGE)
        L0 = _in_range("stroke_start", options.get("stroke_start", self.L_start0),
                       self.L_min, self.L_max)
        Lt = _in_range("stroke_target", options.get("stroke_target", self.L_target0),
                       self.L_min, self.L_max)
        sway = options.get("sway")
        if sway is not None:
            s = np.asarray(sway, dtype=float)
            if s.shape != (2,) or not np.all(np.isfinite(s)) \
                    or np.any(np.abs(s) > self.sway_limit):
                raise ValueError(f"sway = {sway!r}: two angles (theta, psi) rad with |angle| "
                                 f"<= sway_limit = {self.sway_limit:g}")
        self.rom.configure(m, ang, ell, envs=ids)
        self.rom.reset(L0, envs=ids, sway=sway)
        if self.full:
            if sway is not None:
                raise ValueError("sway: a start sway is a reset option of fidelity 'rl' only")
            from .full_physics import FullPhysicsPlant
            # the scene's hook (500 kg) hangs with the payload; its unstretched rope is the
            # loaded length l over (1 + m g / EA)
            L0_rope = float(ell[0]) / (1.0 + (m[0] + HOOK_MASS) * G / HOIST_EA)
            self.plant = FullPhysicsPlant(self.booms, self.fidelity, float(m[0]), float(ang[0]),
                                          stroke0=L0, friction=self.friction,
                                          payload_swing=True, rope_length=L0_rope,
                                          **self._plant_kw)
            self.stage[0] = self.plant.stroke()
        self.L_target[ids] = Lt
        self.travel[ids] = max(abs(Lt - L0), 1e-3)
        self.t[ids] = 0.0
        self.steps[ids] = 0
        self.a_prev[ids] = 0.0
        self.a_applied[ids] = 0.0
        self.sat[ids] = False
        self.stop[ids] = False
        d, s = self.rom.outputs(ids)
        self.defl[ids] = d
        self.sway[ids] = s
        if self.observe_parameters:
            self.params[ids] = np.stack([self._normalised("payload", m),
                                         self._normalised("luffing_angle_deg", ang),
                                         self._normalised("rope_length", ell)], axis=1)
        obs = self._obs(ids)
        self.last_obs[ids] = obs
        return obs

    # -- step ----------------------------------------------------------------------------------
    def check_actions(self, actions):
        a = np.asarray(actions, dtype=np.float64)
        if a.size != self.n:
            raise ValueError(f"action shape {np.shape(actions)}: expected ({self.n}, 1)")
        a = a.reshape(self.n)
        if not np.all(np.isfinite(a)):
            raise ValueError(f"action = {actions!r} is not finite")
        return np.clip(a, -1.0, 1.0) * self.a_max

    def step(self, a):
        """Advance every crane with the accelerations a (n,) m/s^2 (checked, clipped).
        Returns (obs (n, d) float32, reward (n,), terminated (n,), truncated (n,), diverged
        (n,), reason (list of str)): the arrays the envs hand out."""
        failed = ""
        if self.full:
            from sim_core.vector_rom import stroke_segments
            segs, L1, v1 = stroke_segments(float(self.rom.stroke[0]),
                                           float(self.rom.stroke_rate[0]), float(a[0]), self.dt,
                                           self.v_max, self.L_min, self.L_max)
        sat, stop, acc, defl_new, sway_new = self.rom.step_outputs(a)
        if self.full:
            from sim_core import SimulationError
            try:
                self.plant.advance(segs, self.dt, end=(L1, v1))
                defl_new = np.array([self.plant.tip_deflection()])
                sway_new = np.array([self.plant.sway()])
                if self._plant_kw:
                    # the stages behind the oil column: their mean acceleration over the step
                    L_st, v_st = self.plant.stroke()
                    acc = np.array([(v_st - self.stage[0, 1]) / self.dt])
                    self.stage[0] = L_st, v_st
            except (SimulationError, FloatingPointError, np.linalg.LinAlgError) as exc:
                failed = f"{type(exc).__name__}: {exc}"
                defl_new = np.full((1, 4), np.nan)
                sway_new = np.full((1, 4), np.nan)
        self.sat, self.stop, self.a_applied = sat, stop, acc
        n = self.n
        obs = np.empty((n, len(self.obs_low)), np.float32)
        reward = np.empty(n)
        ru = np.empty(n)
        settled = np.empty(n, bool)
        truncated = np.empty(n, bool)
        code = np.empty(n, np.int8)
        L, v = self._stroke()
        kernel.task_step(self.par, L, v, acc, stop, defl_new,
                         sway_new, self.defl, self.sway, a, self.a_prev, self.L_target,
                         self.travel, self.t, self.steps, self.params, self._low64,
                         self._high64, obs, self.last_obs, reward, ru, settled, truncated, code)
        self.reward_unscaled = ru
        diverged = code != kernel.OK
        reason = self._no_reason.copy()
        if diverged.any():
            for i in np.flatnonzero(diverged):
                if code[i] == kernel.NON_FINITE:
                    reason[i] = failed or "FloatingPointError: non-finite modal state"
                elif code[i] == kernel.DEFLECTION:
                    reason[i] = (f"tip deflection {defl_new[i]} outside the observation bounds "
                                 "(1 m, 10 m/s)")
                else:
                    reason[i] = (f"sway {sway_new[i]} outside the small-angle range (sway_limit "
                                 f"{self.sway_limit:g} rad, rate {self.rate_max:.3g} rad/s)")
        return obs, reward, settled, truncated, diverged, reason

    def _stroke(self):
        """(L_s, L_s') arrays (n,) of the stages: the full model's behind its oil column, else
        the ROM's."""
        if self._plant_kw:
            return self.stage[:, 0].copy(), self.stage[:, 1].copy()
        return self.rom.stroke, self.rom.stroke_rate

    def _obs(self, ids):
        L, v = self._stroke()
        out = np.empty((len(ids), len(self.obs_low)))
        kernel.observe(L[ids], v[ids], self.a_applied[ids],
                       self.L_target[ids], self.t[ids], self.t_max, self.defl[ids],
                       self.sway[ids], self.params[ids], self._low64, self._high64, out)
        return out.astype(np.float32)

    def info_arrays(self, diverged, reason, success, reward_unscaled):
        """Per-crane info as arrays (n, ...)."""
        rom = self.rom
        L, v = self._stroke()
        # stuck: the ROM's stick state, or the full model's stages within its friction law's
        # stick band |L_s'| < v_eps (the plant scene's contact.v_eps)
        stuck = (np.abs(v) < self.plant.scene["contact"]["v_eps"] if self._plant_kw
                 else rom.stuck)
        return {"time": self.t.copy(), "stroke": np.array(L), "stroke_rate": np.array(v),
                "velocity_saturated": self.sat.copy(),
                "end_stop": self.stop.copy(), "tip_deflection": self.defl[:, :2].copy(),
                "sway": self.sway[:, :2].copy(), "payload": rom.payload.copy(),
                "luffing_angle_deg": rom.luffing_angle_deg.copy(),
                "rope_length": rom.rope_length.copy(), "booms": self._booms.copy(),
                "stuck": stuck,
                "diverged": np.array(diverged, bool),
                "reason": np.array(reason, dtype=object),
                "success": np.array(success, bool),
                "reward_unscaled": np.array(reward_unscaled, float)}

    # -- drawing -------------------------------------------------------------------------------
    def draw(self, fig_holder: dict, i: int, exaggeration: float, sway_exaggeration: float):
        """RGB frame (H, W, 3) uint8 of crane i (module docstring, Rendering)."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from sim_core.vector_rom import luffing_frame
        if fig_holder.get("fig") is None:
            fig = Figure(figsize=(4.8, 3.6), dpi=100)
            FigureCanvasAgg(fig)
            fig_holder["fig"], fig_holder["ax"] = fig, fig.add_subplot(111)
        fig, ax = fig_holder["fig"], fig_holder["ax"]
        ax.clear()
        ang = float(self.rom.luffing_angle_deg[i])
        O, e = luffing_frame(ang)
        L = float(self._stroke()[0][i])
        d = exaggeration * self.defl[i, :2]
        n = self.booms
        total = (n - 1) * L + BOOM_LENGTH
        colours = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")
        for k in range(n):
            s = np.linspace(k * L, k * L + BOOM_LENGTH, 20)
            x = s / total
            shape = 0.5 * x * x * (3 - x)
            pts = O[None] + s[:, None] * e[None] + shape[:, None] * d[None]
            ax.plot(pts[:, 0], pts[:, 1], color=colours[k % len(colours)],
                    lw=7 - 4 * k / (n - 1), solid_capstyle="butt")
        tip = O + total * e + d
        ell = float(self.rom.rope_length[i])
        th = sway_exaggeration * float(self.sway[i, 0])
        pay = tip + ell * np.array([math.sin(th), -math.cos(th)])
        ax.plot([tip[0], pay[0]], [tip[1], pay[1]], color="0.3", lw=1)
        ax.plot(*pay, "s", color="tab:brown", ms=10)
        ax.plot(*tip, "ks", ms=5)
        tgt = O + ((n - 1) * self.L_target[i] + BOOM_LENGTH) * e
        ax.plot(*tgt, "r+", ms=12)
        reach = (n - 1) * self.L_max + BOOM_LENGTH + 2.0
        ax.set_xlim(-2, max(16.0, O[0] + reach * e[0]) + 2.0)
        ax.set_ylim(-1, max(26.0, O[1] + reach * e[1]))
        ax.set_aspect("equal")
        ax.set_title(f"t = {self.t[i]:5.2f} s  L_s = {L:5.3f} m  |d| = "
                     f"{1e3 * math.hypot(*self.defl[i, :2]):.2f} mm (x{exaggeration:g})  "
                     f"sway {math.degrees(self.sway[i, 0]):+.2f} deg (x{sway_exaggeration:g})",
                     fontsize=7)
        ax.set_xlabel("X (m)", fontsize=8)
        ax.set_ylabel("Z (m)", fontsize=8)
        fig.canvas.draw()
        buf = np.asarray(fig.canvas.buffer_rgba())
        return np.ascontiguousarray(buf[:, :, :3]).astype(np.uint8)


class TelescopicSwayEnv(gym.Env):
    """Extraction / retraction with payload sway, one crane (module docstring); the batch of
    one of :class:`SwayTask` that the native vector env runs N at a time."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(self, render_mode=None, render_exaggeration: float = 20.0,
                 render_sway_exaggeration: float = 5.0, **kwargs):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode = {render_mode!r}: allowed "
                             f"{self.metadata['render_modes']}")
        self.render_mode = render_mode
        self.exaggeration = _positive("render_exaggeration", render_exaggeration)
        self.sway_exaggeration = _positive("render_sway_exaggeration", render_sway_exaggeration)
        self.core = SwayTask(1, **kwargs)
        self.action_space = spaces.Box(-1.0, 1.0, (1,), np.float32)
        self.observation_space = spaces.Box(self.core.obs_low, self.core.obs_high,
                                            dtype=np.float32)
        self._fig = {}

    @property
    def dt(self) -> float:
        """Control step, s."""
        return self.core.dt

    @property
    def a_max(self) -> float:
        """Acceleration of action 1, m/s^2."""
        return self.core.a_max

    @property
    def t_max(self) -> float:
        """Episode length, s."""
        return self.core.t_max

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.core.rngs[0] = self.np_random
        obs = self.core.reset_envs([0], options)[0]
        return obs, self._info(False, "", False, 0.0)

    def step(self, action):
        a = self.core.check_actions(action)
        obs, r, term, trunc, div, reason = self.core.step(a)
        info = self._info(bool(div[0]), reason[0], bool(term[0]),
                          float(self.core.reward_unscaled[0]))
        return obs[0], float(r[0]), bool(term[0]), bool(trunc[0]), info

    def _info(self, diverged, reason, success, reward_unscaled):
        arr = self.core.info_arrays([diverged], [reason], [success], [reward_unscaled])
        info = {}
        for k, v in arr.items():
            x = v[0]
            info[k] = x.copy() if isinstance(x, np.ndarray) else (x.item() if hasattr(x, "item")
                                                                   else x)
        info["fidelity"] = self.core.fidelity
        return info

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without render_mode; set render_mode='rgb_array'")
            return None
        return self.core.draw(self._fig, 0, self.exaggeration, self.sway_exaggeration)

    def close(self):
        self._fig = {}
