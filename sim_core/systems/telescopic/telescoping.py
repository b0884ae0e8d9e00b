"""Telescoping sequences: every stage of a telescopic crane on its own extension profile, SI
units.

Two drives of ``[drive] mechanism`` give each stage k (boom k+2 in boom k+1, 0-based; the scene
numbers stages from 1) a length L_s,k(t) of its own, the distance of the two booms' left
sections, imposed as a rheonomic constraint of its own (``stage_12``, ``stage_23``, ... in
:func:`sim_core.systems.telescopic.build.drive_name`; its multiplier is the stage's axial force,
output ``drive_forces``):

* ``independent``: a cylinder per stage, each on the profile of its ``[[stage_drive]]`` table
  (``hold``, ``cubic``, ``trapezoid`` or ``table`` of :mod:`sim_core.physics.drive_profiles`)
  from its length ``length0`` at t = 0;
* ``single_cylinder``: one telescoping cylinder and locking pins (the single-cylinder
  telescoping system of mobile cranes).  ``[telescoping]`` states the pin positions as
  fractions of a stage's full stroke, where every stage is pinned at t = 0 and the sequence of
  moves (stage, target pin).  The cylinder moves one stage at a time on a smooth profile (the
  cubic schedule of Zhao-Qi-Wang 2024 Section 9 or the trapezoid of Biagiotti-Melchiorri 2008
  Sections 3.2-3.4), the others hold their pins; between two moves it dwells ``dwell`` seconds
  (unpinning, travelling to the next stage and pinning move no boom).

A stage's stroke in ``[telescoping]`` runs from booms.stroke0 (0 %) to booms.stroke0 +
full_stroke (100 %): the telescoping mode 0/46/92/92 % of a five-section crane is stage 1 at
stroke0, stage 2 at stroke0 + 0.46 full_stroke and stages 3 and 4 at stroke0 + 0.92
full_stroke.

A pinned stage is held by an exact constraint (its length is prescribed, constant): the pin
and the cylinder are rigid in the model, as the cylinders of the other drives.  A stiff spring
would need a pin stiffness and backlash the scene does not know, and it would add an axial mode
of sqrt(k / m) that limits the step of the integrator without adding information; the exact
constraint holds the pinned length to the constraint tolerance of the index-reduced solve and
its multiplier is the pin force.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.errors import SceneError
from sim_core.physics.drive_profiles import (
    CubicSmoothstepSchedule,
    HoldProfile,
    MotionSample,
    TrapezoidProfile,
)
from sim_core.scene.fields import (
    COMPUTED,
    OPTIONAL,
    REQUIRED,
    T_MAX,
    Field,
    Table,
    check_keys,
    table_of,
    tables_of,
)

__all__ = ["TELESCOPING", "StageSequence", "stage_moves", "cylinder_stage", "validate_stages",
           "stage_params", "stage_table"]

#: the longest stage stroke, m (the longest boom section of the scenes)
_L_MAX = 100.0
_CUBIC, _TRAP = ("cubic",), ("trapezoid",)

TELESCOPING = Table("telescoping", (
    Field("full_stroke", "number", "m", REQUIRED, lo=1e-3, hi=_L_MAX,
          note="a stage's stroke at 100 %: its length runs from booms.stroke0 (0 %) to "
               "booms.stroke0 + full_stroke (100 %)"),
    Field("pins", "numbers", "", REQUIRED, lo=0.0, hi=1.0, items=(1, 50),
          note="the pin positions of every stage, fractions of full_stroke, increasing "
               "(e.g. [0, 0.46, 0.92, 1])"),
    Field("start", "numbers", "", COMPUTED, lo=0.0, hi=1.0, items=(1, 5),
          default_text="the first pin, every stage",
          allowed="one pin per stage, stage 1 (boom 2 in boom 1) first",
          note="where every stage is pinned at t = 0"),
    Field("sequence", "rows", "", REQUIRED, items=(1, 100),
          columns=((1.0, 5.0, ""), (0.0, 1.0, "")),
          allowed="rows [stage 1..N-1, a pin other than the stage's current one]",
          note="the moves in order: [stage, target pin]; stage k is boom k+1 in boom k"),
    Field("profile", "choice", default="cubic", choices=("cubic", "trapezoid"),
          note="each move's profile: \"cubic\" the paper's schedule (Section 9) with ramps "
               "t_ramp, \"trapezoid\" acceleration-limited (jerk-limited with j_max)"),
    Field("v_max", "number", "m/s", 0.5, lo=1e-4, hi=5.0,
          note="peak stroke rate of a move (a short cubic move peaks lower: its travel / t_ramp)"),
    Field("t_ramp", "number", "s", 2.0, lo=1e-3, hi=T_MAX, when=_CUBIC,
          applies='profile "cubic"', note="each ramp of a cubic move"),
    Field("a_max", "number", "m/s^2", REQUIRED, lo=1e-4, hi=10.0, when=_TRAP,
          applies='profile "trapezoid"'),
    Field("j_max", "number", "m/s^3", OPTIONAL, lo=1e-4, hi=100.0, when=_TRAP,
          applies='profile "trapezoid"', note="a jerk-limited S-curve"),
    Field("t_start", "number", "s", 0.0, lo=0.0, hi=T_MAX, note="when the first move starts"),
    Field("dwell", "number", "s", 2.0, lo=0.0, hi=T_MAX,
          note="between two moves: unpinning, the cylinder travelling to the next stage and "
               "pinning move no boom"),
), note='the single-cylinder telescoping of drive.mechanism = "single_cylinder" (docs/'
        'user_guide.md, "Telescoping sequences")')


def stage_table(k: int) -> str:
    """The scene name of stage k's ``[[stage_drive]]`` table (0-based k)."""
    return f"stage_drive[{k}]"


class StageSequence:
    """The length L_s(t) of one stage under the single cylinder: s0 plus the travel of each of
    its moves (profiles from 0, at rest outside their windows, which do not overlap), m."""

    sign = 1

    def __init__(self, s0: float, moves=()):
        self.s0 = float(s0)
        self.moves = tuple(moves)
        self.t_start = min((m.t_start for m in self.moves), default=0.0)

    @property
    def t_end(self) -> float:
        return max((m.t_end for m in self.moves), default=self.t_start)

    def sample(self, t) -> MotionSample:
        scalar = np.ndim(t) == 0
        s, v, a, j = (0.0, 0.0, 0.0, 0.0) if scalar else (np.zeros(np.shape(t)),) * 4
        for m in self.moves:
            x = m.sample(t)
            s, v, a, j = s + x.s, v + x.v, a + x.a, j + x.j
        return MotionSample(self.s0 + s, v, a, j)

    __call__ = sample

    def stroke(self, t):
        return self.sample(t).s

    def rate(self, t):
        return self.sample(t).v

    def accel(self, t):
        return self.sample(t).a


def _move(tel: dict, travel: float, t0: float):
    """One move of ``travel`` m (signed) starting at t0 s on the profile of ``[telescoping]``."""
    D, sign = abs(travel), 1 if travel > 0 else -1
    if tel["profile"] == "trapezoid":
        return TrapezoidProfile(travel=D, v_max=tel["v_max"], a_max=tel["a_max"],
                                j_max=tel.get("j_max"), sign=sign, s0=0.0, t_start=t0)
    # the cubic schedule travels V t_hold_end with t_hold_end >= t_ramp: a move shorter than
    # v_max t_ramp is two ramps at the peak rate D / t_ramp
    T = tel["t_ramp"]
    th = max(D / tel["v_max"], T)
    return CubicSmoothstepSchedule(v_max=D / th, t_ramp=T, t_hold_end=th, sign=sign, s0=0.0,
                                   t_start=t0)


def stage_moves(tel: dict, n_stages: int, stroke0: float):
    """(stage profiles, cylinder moves) of a validated ``[telescoping]`` table: the length
    L_s,k(t) of every stage (:class:`StageSequence`, m) and the single cylinder's moves
    (t_start s, t_end s, stage 0-based) in order."""
    F = tel["full_stroke"]
    at = list(tel["start"])
    moves = [[] for _ in range(n_stages)]
    timeline = []
    t = tel["t_start"]
    for stage, target in tel["sequence"]:
        k = int(stage) - 1
        m = _move(tel, (target - at[k]) * F, t)
        moves[k].append(m)
        timeline.append((t, m.t_end, k))
        at[k] = target
        t = m.t_end + tel["dwell"]
    profiles = tuple(StageSequence(stroke0 + f0 * F, mv) for f0, mv in zip(tel["start"], moves))
    return profiles, tuple(timeline)


def cylinder_stage(moves, t: float) -> int:
    """The stage (0-based) the single cylinder is on at time t: that of the last move started by
    t (it stays there until it unpins for the next move); before the first move, the first
    move's stage."""
    k = moves[0][2]
    for t0, _, stage in moves:
        if t0 > t:
            break
        k = stage
    return k


def _pin_index(pins, x: float, where: str) -> int:
    """The index of pin position x in pins (within 1e-9), or a SceneError naming the field."""
    for i, p in enumerate(pins):
        if abs(p - x) <= 1e-9:
            return i
    raise SceneError(f"{where} = {x:g}: not a pin position (allowed: one of telescoping.pins = "
                     f"{list(pins)})")


def _check_telescoping(t: dict, n_stages: int) -> dict:
    """The ``[telescoping]`` table read and checked: pins increasing, a start pin per stage, every
    move of an existing stage to another pin."""
    w = "telescoping"
    profile = TELESCOPING.read(t, "profile", w)
    # every profile's keys, as the drive tables: a --set of the profile keeps the table valid
    check_keys(t, TELESCOPING.all_keys(), w)
    out = {k: TELESCOPING.read(t, k, w) for k in ("full_stroke", "pins", "sequence", "v_max",
                                                   "t_start", "dwell")}
    out["profile"] = profile
    if profile == "cubic":
        out["t_ramp"] = TELESCOPING.read(t, "t_ramp", w)
    else:
        out["a_max"] = TELESCOPING.read(t, "a_max", w)
        if "j_max" in t:
            out["j_max"] = TELESCOPING.read(t, "j_max", w)
    pins = out["pins"]
    if any(b <= a for a, b in zip(pins, pins[1:])):
        raise SceneError(f"telescoping.pins = {pins}: not increasing (allowed: distinct pin "
                         "positions in [0, 1], increasing)")
    start = TELESCOPING.read(t, "start", w, default=[pins[0]] * n_stages)
    if len(start) != n_stages:
        raise SceneError(f"telescoping.start: {len(start)} positions for {n_stages} stages "
                         f"(allowed: one pin per stage, {n_stages} numbers)")
    at = [_pin_index(pins, x, f"telescoping.start[{k}]") for k, x in enumerate(start)]
    for i, (stage, target) in enumerate(out["sequence"]):
        where = f"telescoping.sequence[{i}]"
        if stage != int(stage) or not 1 <= stage <= n_stages:
            raise SceneError(f"{where}[0] = {stage:g}: no stage of this crane (allowed: an integer "
                             f"in [1, {n_stages}]; stage k is boom k+1 in boom k)")
        k = int(stage) - 1
        j = _pin_index(pins, target, f"{where}[1]")
        if j == at[k]:
            raise SceneError(f"{where} = [{int(stage)}, {target:g}]: stage {int(stage)} is "
                             f"already pinned at {pins[j]:g} (allowed: a pin other than the "
                             "stage's current one)")
        at[k] = j
    # the positions as the pins' own values (equal within 1e-9)
    out["start"] = [float(pins[_pin_index(pins, x, "")]) for x in start]
    out["sequence"] = [[int(s), float(pins[_pin_index(pins, x, "")])]
                       for s, x in out["sequence"]]
    return out


def _check_stage_drives(tables: list, sc: dict, source: str) -> list[dict]:
    """The ``[[stage_drive]]`` tables, one per stage: each an actuator profile of the stage's
    length (sim_core.systems.telescopic.actuators) from its ``length0``."""
    from sim_core.systems.telescopic.schema import STAGE_DRIVE, _check_actuator
    n = sc["booms"]["count"] - 1
    if len(tables) != n:
        raise SceneError(f"[[stage_drive]]: {len(tables)} tables for {n} stages (allowed: one "
                         "per stage, stage 1 (boom 2 in boom 1) first)")
    out = []
    for k, t in enumerate(tables):
        w = stage_table(k)
        check_keys(t, STAGE_DRIVE.all_keys(), w)      # the profile's own keys: _check_actuator
        d = _check_actuator({key: v for key, v in t.items() if key != "length0"}, w)
        d["length0"] = STAGE_DRIVE.read(t, "length0", w, default=sc["booms"]["stroke0"])
        if d["profile"] == "table":
            from sim_core.systems.telescopic import actuators
            _, s = actuators.table_rows({**d, "_table": w}, source)
            if "length0" in t and t["length0"] != s[0]:
                raise SceneError(f"{w}.length0 = {t['length0']:g} m and the table starts at "
                                 f"{s[0]:g} m (allowed: equal, or leave length0 out)")
            d["length0"] = float(s[0])
        out.append(d)
    return out


def _stage_profiles(sc: dict, source: str | None):
    """(stage profiles, cylinder moves or None) of a validated scene's stagewise drive."""
    n = sc["booms"]["count"] - 1
    if sc["drive"]["mechanism"] == "single_cylinder":
        return stage_moves(sc["telescoping"], n, sc["booms"]["stroke0"])
    from sim_core.systems.telescopic import actuators
    return tuple(actuators.build_profile({**d, "_table": stage_table(k)}, d["length0"],
                                         stage_table(k), source)
                 for k, d in enumerate(sc["stage_drive"])), None


def check_tables_belong(raw: dict, mechanism: str) -> None:
    """``[[stage_drive]]`` and ``[telescoping]`` only with the drives that read them."""
    for name, own in (("stage_drive", "independent"), ("telescoping", "single_cylinder")):
        if raw.get(name) and mechanism != own:
            brackets = "[[stage_drive]]" if name == "stage_drive" else "[telescoping]"
            raise SceneError(f"{brackets} with drive.mechanism = {mechanism!r}: the table "
                             f"drives the stages of mechanism {own!r} (allowed: "
                             f"drive.mechanism = {own!r}, or leave it out)")


def validate_stages(raw: dict, sc: dict, d: dict, L: float, what: str) -> tuple[float, float]:
    """Validate the stagewise drives' tables into ``sc`` (``[[stage_drive]]`` or
    ``[telescoping]``; ``d`` the raw ``[drive]`` table, L the shortest boom length named by
    ``what``) and return the range (min, max) of the stage lengths over [0, solver.t_end], m."""
    from sim_core.systems.telescopic import actuators
    mech = sc["drive"]["mechanism"]
    extra = sorted(set(d) - {"mechanism"})
    if extra:
        own = "[[stage_drive]]" if mech == "independent" else "[telescoping]"
        raise SceneError(f"drive.{extra[0]} with drive.mechanism = {mech!r}: the stages follow "
                         f"{own} (allowed in [drive]: mechanism only)")
    stage_tables, tel = tables_of(raw, "stage_drive"), table_of(raw, "telescoping", "")
    n = sc["booms"]["count"] - 1
    source = sc.get("source")
    if mech == "independent":
        sc["stage_drive"] = _check_stage_drives(stage_tables, sc, source)
    else:
        if not tel:
            raise SceneError("drive.mechanism = 'single_cylinder' without [telescoping]: the "
                             "pins and the sequence of moves are required")
        sc["telescoping"] = _check_telescoping(tel, n)
    t_end = sc["solver"]["t_end"]
    profiles, _ = _stage_profiles(sc, source)
    lo, hi = math.inf, -math.inf
    for k, prof in enumerate(profiles):
        a, b = actuators.extremes(prof, max(t_end, prof.t_end))
        if not 0.0 < a <= b < L:
            where = (stage_table(k) if mech == "independent" else
                     f"telescoping (stage {k + 1})")
            raise SceneError(f"{where}: the stage length moves between {a:g} and {b:g} m, "
                             f"outside the allowed (0, {L:g}) m ({what}): a boom would leave "
                             "its neighbour")
        if mech == "independent":
            actuators.check_limits(stage_table(k), sc["stage_drive"][k], prof, t_end)
        lo, hi = min(lo, a), max(hi, b)
    return lo, hi


def stage_params(sc: dict) -> dict:
    """The TelescopicParams entries of a validated scene's stagewise drive (none for the
    synchronized and sequential drives)."""
    if sc["drive"]["mechanism"] not in ("independent", "single_cylinder"):
        return {}
    profiles, moves = _stage_profiles(sc, sc.get("source"))
    return {"stage_profiles": profiles, "cylinder_moves": moves}


def hold_profiles(lengths) -> tuple:
    """Stage profiles that hold the given lengths (m): a telescoping mode at rest."""
    return tuple(HoldProfile(s0=float(x)) for x in lengths)
