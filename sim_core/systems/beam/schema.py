"""The beam scene (no ``kind`` key): beams with boundary conditions, sleeves and point loads,
SI units.

Every key is declared once in :data:`SCHEMA` (type, unit, default, allowed range, note); the
validator reads the keys through those declarations, so an error names the dotted field, the
value and the declared range (:class:`sim_core.errors.SceneError`), unknown keys and names get
a "did you mean" suggestion, and the scene reference of the documentation is rendered from the
same declarations.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from sim_core.errors import SceneError
from sim_core.physics.drive_profiles import sleeve_motion
from sim_core.scene.fields import (
    COMPUTED,
    OPTIONAL,
    REQUIRED,
    T_MAX,
    Field,
    Schema,
    Table,
    did_you_mean,
    read_text,
    short_repr,
    solver_fields,
    solver_table,
    table_of,
    text_fields,
    time_field,
)

# -- the declarations ---------------------------------------------------------------------------

#: the longest beam, m, and the farthest point of a scene from the origin, m
L_MAX, X_MAX = 1000.0, 1000.0
#: the most nodes of all beams together (a beam has n_nodes - 1 per element, plus one): about
#: 1300 coordinates, whose dense mass and iteration matrices an implicit step inverts
MAX_NODES = 257

TOP = Table("", text_fields("", "the file name"),
            tables=("solver", "effects", "filtering", "gravity", "beams", "boundary",
                    "point_loads", "initial"))
SOLVER = solver_fields(method="generalized_alpha")
EFFECTS = Table("effects", (
    Field("gravity", "boolean", default=False, note="the weight of the beams"),
    Field("torsion", "boolean", default=True,
          note="false: torsion angles held at zero (what is off is not computed)"),
    Field("filtering", "boolean", default=False,
          note="stress averaging over [filtering] h (SIMULTECH 2020 Eq. 53)"),
), note="switches of the model's contributions")
FILTERING = Table("filtering", (
    Field("h", "number", "s", 0.01, lo=1e-4, hi=1.0,
          note="stress-averaging window (SIMULTECH 2020 Eq. 53)"),
))
GRAVITY = Table("gravity", (
    Field("g", "vector", "m/s^2", [0.0, 0.0, -9.81], lo=-100.0, hi=100.0,
          note="gravitational acceleration (global)"),
))
BEAMS = Table("beams[]", (
    Field("name", "string", default=COMPUTED, default_text="beam0, beam1, ...",
          note="unique; [[boundary]] and [[point_loads]] refer to it"),
    Field("length", "number", "m", REQUIRED, lo=1e-3, hi=L_MAX),
    Field("breakpoints", "numbers", "m", COMPUTED, lo=0.0, hi=L_MAX, items=(2, 33),
          allowed="2 to 33 numbers increasing strictly within [0, length] m",
          default_text="[0, length]",
          note="element ends (material coordinates); material outside them is not modelled"),
    Field("n_nodes", "integer", "", 9, lo=3, hi=65, note="nodes per spline element"),
    Field("n_gauss", "integer", "", 5, lo=1, hi=10, note="Gauss points per sub-element"),
    Field("origin", "vector", "m", [0.0, 0.0, 0.0], lo=-X_MAX, hi=X_MAX,
          note="position of the material point s = 0 when straight"),
    Field("direction", "vector", "", [1.0, 0.0, 0.0], lo=-1e3, hi=1e3, nonzero=True,
          note="axis of the straight beam (normalised)"),
), tables=("section",), items=(1, 85), note="one table per beam")
SECTION = Table("beams[].section", (
    Field("E", "number", "Pa", REQUIRED, lo=1e8, hi=1e15, note="Young's modulus"),
    Field("G", "number", "Pa", REQUIRED, lo=1e7, hi=1e15, note="shear modulus"),
    Field("rho", "number", "kg/m^3", REQUIRED, lo=10.0, hi=1e5, note="density"),
    Field("A", "number", "m^2", REQUIRED, lo=1e-8, hi=10.0, note="cross-section area"),
    Field("I_t", "number", "m^4", REQUIRED, lo=1e-16, hi=100.0,
          note="second moment of area about the section's t axis"),
    Field("I_b", "number", "m^4", REQUIRED, lo=1e-16, hi=100.0,
          note="second moment of area about the section's b axis"),
    Field("J", "number", "m^4", REQUIRED, lo=1e-16, hi=100.0, note="torsion constant"),
    Field("I_p", "number", "m^4", COMPUTED, lo=1e-16, hi=200.0, default_text="I_t + I_b",
          note="polar moment (rotary inertia of torsion)"),
    Field("rotary_bending", "boolean", default=True,
          note="rotary inertia rho I_t, rho I_b of bending included"),
), note="the beam's material and section constants")
BOUNDARY = Table("boundary[]", (
    Field("beam", "choice", default=COMPUTED, default_text="the first beam",
          allowed="a name of [[beams]]"),
    Field("end", "choice", default=REQUIRED, choices=("left", "right")),
    Field("kind", "choice", default=REQUIRED,
          choices=("clamped", "pinned", "roller", "free", "sleeve"),
          note="\"sleeve\": the end slides through a rigid frictionless sleeve"),
    Field("position", "vector", "m", OPTIONAL, lo=-X_MAX, hi=X_MAX,
          note="where the end is held (default: where the straight beam puts it)"),
    Field("direction", "vector", "", OPTIONAL, lo=-1e3, hi=1e3, nonzero=True,
          note="axis the end is held along (default: the beam's direction)"),
    Field("speed", "number", "m/s", 0.0, lo=-10.0, hi=10.0, applies='kind = "sleeve"',
          allowed="[-10, 10] m/s, and the sleeve end stays within its element up to "
                  "solver.t_end",
          note="rate of the end's material coordinate (peak rate of the cubic profile)"),
    Field("profile", "choice", default="constant", choices=("constant", "cubic"),
          applies='kind = "sleeve"',
          note='"constant": speed from t = 0; "cubic": the telescopic drive\'s schedule of '
               "Section 9 with peak rate speed"),
    Field("t_ramp", "number", "s", 4.0, lo=1e-3, hi=T_MAX,
          applies='profile = "cubic"', note="length of each ramp of the cubic profile"),
    Field("t_hold_end", "number", "s", COMPUTED, lo=1e-3, hi=T_MAX,
          allowed=f"[t_ramp, {T_MAX:g}] s", default_text="3 t_ramp",
          applies='profile = "cubic"', note="end of the constant-rate hold"),
), items=(0, 170), note="one condition per beam end")
POINT_LOADS = Table("point_loads[]", (
    Field("beam", "choice", default=COMPUTED, default_text="the first beam",
          allowed="a name of [[beams]]"),
    Field("s", "number", "m", REQUIRED, lo=0.0, hi=L_MAX,
          allowed="[0, length] m, on the modelled part of the beam",
          note="material coordinate at t = 0"),
    Field("speed", "number", "m/s", 0.0, lo=-10.0, hi=10.0,
          allowed="[-10, 10] m/s, and the load stays on the modelled part up to solver.t_end",
          note="rate of the load's material coordinate (a moving load)"),
    Field("force", "vector", "N", REQUIRED, lo=-1e8, hi=1e8, note="global components"),
    time_field("start", 0.0, note="the load is switched on at t >= start"),
), items=(0, 64))
INITIAL = Table("initial", (
    Field("static_equilibrium", "boolean", default=False,
          note="start from the static equilibrium at t = 0 (else straight and at rest)"),
))

SCHEMA = Schema(
    None, "Beam scenes (no `kind`)", "sim_core.systems.beam.schema.validate",
    (TOP, SOLVER, EFFECTS, FILTERING, GRAVITY, BEAMS, SECTION, BOUNDARY, POINT_LOADS, INITIAL),
    rules=(
        "At least one [[beams]] table; beam names are unique.",
        f"The beams have at most {MAX_NODES} nodes in all (a beam has n_nodes - 1 per element "
        "between its breakpoints, plus one).",
        "The breakpoints of a beam increase strictly within [0, length].",
        "One [[boundary]] condition per beam end; its position and direction are the "
        "straight beam's end and axis (the model starts straight and at rest).",
        "speed, profile, t_ramp and t_hold_end belong to a \"sleeve\" end; t_ramp and "
        "t_hold_end to its \"cubic\" profile.",
        "A sleeve end may not run out of material nor collapse its element by solver.t_end: "
        "a left end stays in (0, the next breakpoint), a right end in (the previous "
        "breakpoint, length); the error gives the speeds that fit.",
        "A point load stays on its beam and on the modelled part (between the first and last "
        "breakpoint, moved by any sleeve) for t in [0, solver.t_end].",
        "solver.h and solver.h_max exclude each other; the generalized-alpha keys (h, h_max, "
        "rho_inf, newton_atol) need method = \"generalized_alpha\".",
    ))


# -- the validator --------------------------------------------------------------------------

def validate(raw: dict, source: str = "<scene>") -> dict:
    """Return the resolved scene (a plain dict with every default filled in)."""
    if not isinstance(raw, dict):
        raise SceneError(f"scene = {raw!r}: must be a table")
    TOP.check_keys(raw, "scene")
    sc: dict[str, Any] = {}
    read_text(raw, TOP, sc, Path(source).stem)
    sc["source"] = source
    # generalized-alpha, error-controlled, by default: no beam scene switches forces (the
    # sleeves are frictionless, the point loads smooth or switched on once at ``start``, a
    # jump the error test resolves by short steps), and the implicit step is not bound by
    # the stiffest bending and axial modes as RK45's is (sim_core.integrate.driver.integrate)
    solver = solver_table(table_of(raw, "solver", ""), method="generalized_alpha")
    sc["solver"] = solver
    t_end = solver["t_end"]

    e = table_of(raw, "effects", "")
    EFFECTS.check_keys(e, "effects")
    sc["effects"] = {k: EFFECTS.read(e, k, "effects") for k in ("gravity", "torsion", "filtering")}
    sc["filtering"] = FILTERING.resolve(raw, "filtering", ("h",))
    sc["gravity"] = GRAVITY.resolve(raw, "gravity", ("g",))

    beams = raw.get("beams")
    if not isinstance(beams, list) or not beams:
        raise SceneError(f"beams = {short_repr(beams)}: at least one [[beams]] table is "
                         "required")
    beams = BEAMS.array(raw)
    nodes = 0
    sc["beams"] = []
    names: list[str] = []
    for i, b in enumerate(beams):
        w = f"beams[{i}]"
        BEAMS.check_keys(b, w)
        L = BEAMS.read(b, "length", w)
        bps = BEAMS.read(b, "breakpoints", w, default=[0.0, L], hi=L)
        if any(b1 <= b0 for b0, b1 in zip(bps[:-1], bps[1:])):
            raise SceneError(f"{w}.breakpoints = {b['breakpoints']!r}: must increase strictly "
                             f"within [0, {L:g}] m")
        sec = table_of(b, "section", w)
        ws = f"{w}.section"
        SECTION.check_keys(sec, ws)
        section = {k: SECTION.read(sec, k, ws) for k in ("E", "G", "rho", "A", "I_t", "I_b", "J")}
        section["I_p"] = SECTION.read(sec, "I_p", ws, default=section["I_t"] + section["I_b"])
        section["rotary_bending"] = SECTION.read(sec, "rotary_bending", ws)
        name = BEAMS.read(b, "name", w, default=f"beam{i}")
        if name in names:
            raise SceneError(f"{w}.name = {name!r}: already used by beams[{names.index(name)}] "
                             f"(beam names must be unique)")
        names.append(name)
        n_nodes = BEAMS.read(b, "n_nodes", w)
        nodes += (n_nodes - 1) * (len(bps) - 1) + 1
        if nodes > MAX_NODES:
            raise SceneError(f"{w}.n_nodes = {n_nodes} with {len(bps) - 1} elements: the beams "
                             f"have {nodes} nodes in all, allowed at most {MAX_NODES} (fewer "
                             "nodes per element, fewer breakpoints or fewer beams)")
        sc["beams"].append({
            "name": name, "length": L, "breakpoints": [float(x) for x in bps],
            "n_nodes": n_nodes,
            "n_gauss": BEAMS.read(b, "n_gauss", w),
            "origin": BEAMS.read(b, "origin", w),
            "direction": BEAMS.read(b, "direction", w),
            "section": section})

    def beam_ref(table: Table, t: dict, where: str) -> int:
        nm = t.get("beam", names[0])
        if not isinstance(nm, str) or nm not in names:
            more = did_you_mean(nm, names) if isinstance(nm, str) else ""
            raise SceneError(f"{where}.beam = {short_repr(nm)}: no such beam ({', '.join(names)})"
                             f"{more}")
        return names.index(nm)

    sc["boundary"] = []
    taken: dict[tuple[int, str], int] = {}
    for i, bc in enumerate(BOUNDARY.array(raw)):
        w = f"boundary[{i}]"
        BOUNDARY.check_keys(bc, w)
        ib = beam_ref(BOUNDARY, bc, w)
        kind = BOUNDARY.read(bc, "kind", w)
        end = BOUNDARY.read(bc, "end", w)
        if (ib, end) in taken:
            raise SceneError(f"{w}.end = {end!r}: the {end} end of beam {names[ib]!r} already has a "
                             f"condition (boundary[{taken[(ib, end)]}]); one condition per beam end")
        taken[(ib, end)] = i
        speed = BOUNDARY.read(bc, "speed", w)
        for key in ("speed", "profile", "t_ramp", "t_hold_end"):
            if kind != "sleeve" and key in bc:
                raise SceneError(f"{w}.{key} = {short_repr(bc[key])}: only a 'sleeve' end has a "
                                 f"{key} (this end is {kind!r}); remove it or use kind = 'sleeve'")
        profile = BOUNDARY.read(bc, "profile", w)
        if profile == "constant" and ("t_ramp" in bc or "t_hold_end" in bc):
            raise SceneError(f"{w}.profile = 'constant' with t_ramp/t_hold_end: the ramps belong "
                             "to the cubic profile (set profile = 'cubic' or remove them)")
        t_ramp = BOUNDARY.read(bc, "t_ramp", w)
        item = {"beam": ib, "end": end, "kind": kind,
                "position": BOUNDARY.read(bc, "position", w),
                "direction": BOUNDARY.read(bc, "direction", w),
                "speed": speed, "profile": profile, "t_ramp": t_ramp,
                "t_hold_end": BOUNDARY.read(bc, "t_hold_end", w, default=3.0 * t_ramp,
                                            lo=t_ramp)}
        _check_held_at_the_straight_end(sc, item, i)
        sc["boundary"].append(item)
    _check_sleeve_travel(sc, t_end)

    sc["point_loads"] = []
    for i, pl in enumerate(POINT_LOADS.array(raw)):
        w = f"point_loads[{i}]"
        POINT_LOADS.check_keys(pl, w)
        ib = beam_ref(POINT_LOADS, pl, w)
        L = sc["beams"][ib]["length"]
        s0 = POINT_LOADS.read(pl, "s", w, hi=L)
        speed = POINT_LOADS.read(pl, "speed", w)
        sc["point_loads"].append({
            "beam": ib, "s": s0, "speed": speed,
            "force": POINT_LOADS.read(pl, "force", w),
            "start": POINT_LOADS.read(pl, "start", w)})
        _check_load_travel(sc, i, t_end)
    ini = table_of(raw, "initial", "")
    INITIAL.check_keys(ini, "initial")
    sc["initial"] = {"static_equilibrium": INITIAL.read(ini, "static_equilibrium", "initial")}
    return sc


def _check_held_at_the_straight_end(sc: dict, bc: dict, i: int) -> None:
    """The model starts straight and at rest (sim_core.systems.beam.build): a boundary's
    position and direction are where the straight beam has its end and its axis (within 1e-6
    of the beam's length and 1e-6 rad), else the first state breaks the condition."""
    b = sc["beams"][bc["beam"]]
    d = [x / math.sqrt(math.fsum(y * y for y in b["direction"])) for x in b["direction"]]
    s_end = b["breakpoints"][0] if bc["end"] == "left" else b["breakpoints"][-1]
    end = [o + s_end * x for o, x in zip(b["origin"], d)]
    w = f"boundary[{i}]"
    if bc["position"] is not None and math.dist(bc["position"], end) > 1e-6 * b["length"]:
        raise SceneError(f"{w}.position = {bc['position']!r}: the straight beam {b['name']!r} "
                         f"has its {bc['end']} end at [{', '.join(f'{x:g}' for x in end)}] m "
                         "(allowed: that point, or leave position out: the model starts "
                         "straight and at rest)")
    if bc["direction"] is not None:
        e = [x / math.sqrt(math.fsum(y * y for y in bc["direction"])) for x in bc["direction"]]
        if math.dist(e, d) > 1e-6:
            raise SceneError(f"{w}.direction = {bc['direction']!r}: the straight beam "
                             f"{b['name']!r} points along [{', '.join(f'{x:.6g}' for x in d)}] "
                             "(allowed: that axis, or leave direction out: the model starts "
                             "straight and at rest)")


def _modelled_ends(sc: dict, ib: int):
    """Material coordinates of the first and last breakpoint of beam ``ib`` as functions of t:
    a sleeve end moves at its speed, every other end is a material point."""
    bps = sc["beams"][ib]["breakpoints"]
    m = {bc["end"]: bc for bc in sc["boundary"] if bc["beam"] == ib and bc["kind"] == "sleeve"}
    fixed = {"speed": 0.0}
    left = sleeve_motion(m.get("left", fixed), bps[0])
    right = sleeve_motion(m.get("right", fixed), bps[-1])
    return (lambda t: left(t)[0]), (lambda t: right(t)[0])


def _check_sleeve_travel(sc: dict, t_end: float) -> None:
    """A sleeve end s(t) (drive_profiles.sleeve_motion: s0 + speed t, or the cubic schedule)
    must stay strictly inside the material (0, length) and before the next breakpoint (the
    element must not collapse) up to t_end.  The motion is monotone, so checking t_end
    suffices; its travel is proportional to ``speed``, which gives the allowed speeds."""
    def travel(bc, speed=None):
        return sleeve_motion(bc if speed is None else {**bc, "speed": speed})(t_end)[0]
    for i, bc in enumerate(sc["boundary"]):
        if bc["kind"] != "sleeve":
            continue
        b = sc["beams"][bc["beam"]]
        bps, L = b["breakpoints"], b["length"]
        other = [o for o in sc["boundary"] if o["beam"] == bc["beam"] and o is not bc
                 and o["kind"] == "sleeve"]
        single = len(bps) == 2 and other          # one element between two sleeves
        if bc["end"] == "left":
            s0, lo = bps[0], 0.0
            hi = bps[1] + (travel(other[0]) if single else 0.0)
            what = ("left sleeve end must stay after the beam's start s = 0 and before the next "
                    "element end")
        else:
            s0, hi = bps[-1], L
            lo = bps[-2] + (travel(other[0]) if single else 0.0)
            what = (f"right sleeve end must stay after the previous element end and before the "
                    f"beam's end s = {L:g}")
        s_end = s0 + travel(bc)
        if not lo < s_end < hi:
            unit = travel(bc, 1.0)                  # travel by t_end per m/s of speed
            vlo, vhi = (lo - s0) / unit, (hi - s0) / unit
            raise SceneError(f"boundary[{i}].speed = {bc['speed']!r}: the sleeve end would move from "
                             f"s = {s0:g} to s = {s_end:g} by t_end = {t_end:g} s, outside "
                             f"({lo:g}, {hi:g}) (the {what}); allowed ({vlo:g}, {vhi:g}) m/s")


def _check_load_travel(sc: dict, i: int, t_end: float) -> None:
    """A point load must stay on the beam, s + speed t in [0, length], and on its modelled part
    (between the first and last breakpoint, which move with a sleeve) for t in [0, t_end]."""
    pl = sc["point_loads"][i]
    w = f"point_loads[{i}]"
    b = sc["beams"][pl["beam"]]
    L, s0, v = b["length"], pl["s"], pl["speed"]
    s_end = s0 + v * t_end
    if not 0.0 <= s_end <= L:
        raise SceneError(f"{w}.speed = {v!r}: the load would reach s = {s_end:g} at t_end = "
                         f"{t_end:g} s, off the beam [0, {L:g}]; allowed "
                         f"[{-s0 / t_end:g}, {(L - s0) / t_end:g}] m/s")
    first, last = _modelled_ends(sc, pl["beam"])
    tol = 1e-12 * L
    if not first(0.0) - tol <= s0 <= last(0.0) + tol:
        raise SceneError(f"{w}.s = {s0!r}: outside the modelled part of beam {b['name']!r} at t = 0 "
                         f"(material behind a sleeve is not modelled); allowed "
                         f"[{first(0.0):g}, {last(0.0):g}]")
    lo_t, hi_t = first(t_end), last(t_end)
    if not lo_t - tol <= s_end <= hi_t + tol:
        # s0 + v t_end in [lo_t, hi_t]  <=>  v in [(lo_t - s0)/t_end, (hi_t - s0)/t_end]
        raise SceneError(f"{w}.speed = {v!r}: the load would reach s = {s_end:g} at t_end = "
                         f"{t_end:g} s, outside the modelled part of beam {b['name']!r} "
                         f"[{lo_t:g}, {hi_t:g}] at that time; allowed "
                         f"[{(lo_t - s0) / t_end:g}, {(hi_t - s0) / t_end:g}] m/s")
