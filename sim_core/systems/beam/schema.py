"""The beam scene (no ``kind`` key): beams with boundary conditions, sleeves and point loads.

Every value is checked: an error names the dotted field, the value and the allowed range
(:class:`sim_core.errors.SceneError`); unknown keys and names get a "did you mean" suggestion.

Beam-scene schema (units):
  name, description
  [solver]   t_end s (> 0), method ("generalized_alpha" by default, "RK45", "BDF", "auto"),
             rtol (0, 1), atol (> 0), n_output (>= 2), max_step s (> 0, optional), max_wall_s
             s (> 0, optional: wall-clock budget; the run stops there with a SimulationError
             and a partial result); generalized_alpha: h s (optional fixed step; without it
             the steps follow rtol/atol, at most h_max s), rho_inf [0, 1], newton_atol m
  [effects]  gravity, torsion, filtering: booleans (what is off is not computed)
  [filtering] h s (> 0): stress-averaging window (second seed Eq. 53)
  [gravity]  g m/s^2 (3-vector)
  [[beams]]  name, length m, breakpoints m (increasing, element ends), n_nodes (>= 3),
             n_gauss (1..10), origin m (position of material point s = 0 when straight),
             direction (axis), [beams.section] E Pa, G Pa, rho kg/m^3, A m^2, I_t m^4, I_b m^4,
             J m^4 (torsion constant); optional I_p m^4 (polar, default I_t + I_b) and
             rotary_bending (bool, default true: rotary inertia rho I_t, rho I_b included)
  [[boundary]] beam, end ("left"/"right"), kind ("clamped", "pinned", "roller", "free",
             "sleeve"), position m, direction, speed m/s (sleeve only: rate of the end's
             material coordinate), profile (sleeve only: "constant" = speed from t = 0,
             "cubic" = the telescopic drive's schedule of Section 9 with peak rate speed,
             t_ramp s (> 0, default 4) and t_hold_end s (>= t_ramp, default 3 t_ramp)); one
             condition per beam end.  A sleeve end may not run out of material nor collapse
             its element within t_end: left end s_1 + travel(t_end) in (0, breakpoints[1]),
             right end s_n + travel(t_end) in (breakpoints[-2], length)
  [[point_loads]] beam, s m (material coordinate at t = 0), speed m/s (moving load, default 0),
             force N (3-vector, global), start s (load switched on at t >= start); the load
             stays on the beam, s + speed t_end in [0, length], and on its modelled part
             (between the first and last breakpoint, moved by any sleeve) for t in [0, t_end]
  [initial]  static_equilibrium (bool): start from the static equilibrium at t = 0
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from sim_core.errors import SceneError
from sim_core.physics.drive_profiles import sleeve_motion
from sim_core.scene.fields import (
    boolean,
    check_keys,
    choice,
    did_you_mean,
    number,
    solver_table,
    table_of,
    tables_of,
    vector,
)

# -- the scene ---------------------------------------------------------------------------------

_TOP = {"name", "description", "solver", "effects", "filtering", "gravity", "beams",
        "boundary", "point_loads", "initial", "notes"}
_EFFECTS = {"gravity", "torsion", "filtering"}
_BEAM = {"name", "length", "breakpoints", "n_nodes", "n_gauss", "origin", "direction", "section"}
_SECTION = {"E", "G", "rho", "A", "I_t", "I_b", "J", "I_p", "rotary_bending"}
_BOUNDARY = {"beam", "end", "kind", "position", "direction", "speed", "profile", "t_ramp",
             "t_hold_end"}
_LOAD = {"beam", "s", "speed", "force", "start"}


def validate(raw: dict, source: str = "<scene>") -> dict:
    """Return the resolved scene (a plain dict with every default filled in)."""
    if not isinstance(raw, dict):
        raise SceneError(f"scene = {raw!r}: must be a table")
    check_keys(raw, _TOP, "scene")
    for key in ("name", "description"):
        if key in raw and not isinstance(raw[key], str):
            raise SceneError(f"scene.{key} = {raw[key]!r}: must be a string")
    sc: dict[str, Any] = {"name": raw.get("name", Path(source).stem),
                          "description": raw.get("description", ""), "source": source}
    # generalized-alpha, error-controlled, by default: no beam scene switches forces (the
    # sleeves are frictionless, the point loads smooth or switched on once at ``start``, a
    # jump the error test resolves by short steps), and the implicit step is not bound by
    # the stiffest bending and axial modes as RK45's is (sim_core.integrate.driver.integrate)
    solver = solver_table(table_of(raw, "solver", ""), method="generalized_alpha")
    sc["solver"] = solver
    t_end = solver["t_end"]

    e = table_of(raw, "effects", "")
    check_keys(e, _EFFECTS, "effects")
    sc["effects"] = {"gravity": boolean(e, "gravity", "effects", False),
                     "torsion": boolean(e, "torsion", "effects", True),
                     "filtering": boolean(e, "filtering", "effects", False)}
    f = table_of(raw, "filtering", "")
    check_keys(f, {"h"}, "filtering")
    sc["filtering"] = {"h": number(f, "h", "filtering", 0.01, lo=0.0, lo_open=True)}
    g = table_of(raw, "gravity", "")
    check_keys(g, {"g"}, "gravity")
    sc["gravity"] = {"g": vector(g, "g", "gravity", [0.0, 0.0, -9.81])}

    beams = raw.get("beams")
    if not isinstance(beams, list) or not beams:
        raise SceneError(f"beams = {beams!r}: at least one [[beams]] table is required")
    beams = tables_of(raw, "beams")
    sc["beams"] = []
    names: list[str] = []
    for i, b in enumerate(beams):
        w = f"beams[{i}]"
        check_keys(b, _BEAM, w)
        L = number(b, "length", w, lo=0.0, lo_open=True)
        bps = b.get("breakpoints", [0.0, L])
        if (not isinstance(bps, list) or len(bps) < 2
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                           and math.isfinite(x) for x in bps)):
            raise SceneError(f"{w}.breakpoints = {bps!r}: must be a list of >= 2 finite numbers, "
                             f"increasing strictly within [0, {L:g}]")
        if any(b1 <= b0 for b0, b1 in zip(bps[:-1], bps[1:])) or bps[0] < 0 or bps[-1] > L:
            raise SceneError(f"{w}.breakpoints = {bps!r}: must increase strictly within [0, {L:g}]")
        sec = table_of(b, "section", w)
        ws = f"{w}.section"
        check_keys(sec, _SECTION, ws)
        section = {k: number(sec, k, ws, lo=0.0, lo_open=True)
                   for k in ("E", "G", "rho", "A", "I_t", "I_b", "J")}
        section["I_p"] = number(sec, "I_p", ws, section["I_t"] + section["I_b"], lo=0.0, lo_open=True)
        section["rotary_bending"] = boolean(sec, "rotary_bending", ws, True)
        name = str(b.get("name", f"beam{i}"))
        if name in names:
            raise SceneError(f"{w}.name = {name!r}: already used by beams[{names.index(name)}] "
                             f"(beam names must be unique)")
        names.append(name)
        sc["beams"].append({
            "name": name, "length": L, "breakpoints": [float(x) for x in bps],
            "n_nodes": number(b, "n_nodes", w, 9, lo=3, hi=65, integer=True),
            "n_gauss": number(b, "n_gauss", w, 5, lo=1, hi=10, integer=True),
            "origin": vector(b, "origin", w, [0.0, 0.0, 0.0]),
            "direction": vector(b, "direction", w, [1.0, 0.0, 0.0], nonzero=True),
            "section": section})

    def beam_ref(t: dict, where: str) -> int:
        nm = t.get("beam", names[0])
        if nm not in names:
            more = did_you_mean(nm, names)
            raise SceneError(f"{where}.beam = {nm!r}: no such beam ({', '.join(names)}){more}")
        return names.index(nm)

    sc["boundary"] = []
    taken: dict[tuple[int, str], int] = {}
    for i, bc in enumerate(tables_of(raw, "boundary")):
        w = f"boundary[{i}]"
        check_keys(bc, _BOUNDARY, w)
        ib = beam_ref(bc, w)
        kind = choice(bc, "kind", w, ("clamped", "pinned", "roller", "free", "sleeve"))
        end = choice(bc, "end", w, ("left", "right"))
        if (ib, end) in taken:
            raise SceneError(f"{w}.end = {end!r}: the {end} end of beam {names[ib]!r} already has a "
                             f"condition (boundary[{taken[(ib, end)]}]); one condition per beam end")
        taken[(ib, end)] = i
        speed = number(bc, "speed", w, 0.0)
        for key in ("speed", "profile", "t_ramp", "t_hold_end"):
            if kind != "sleeve" and key in bc:
                raise SceneError(f"{w}.{key} = {bc[key]!r}: only a 'sleeve' end has a {key} "
                                 f"(this end is {kind!r}); remove it or use kind = 'sleeve'")
        profile = choice(bc, "profile", w, ("constant", "cubic"), "constant")
        if profile == "constant" and ("t_ramp" in bc or "t_hold_end" in bc):
            raise SceneError(f"{w}.profile = 'constant' with t_ramp/t_hold_end: the ramps belong "
                             "to the cubic profile (set profile = 'cubic' or remove them)")
        t_ramp = number(bc, "t_ramp", w, 4.0, lo=0.0, lo_open=True)
        item = {"beam": ib, "end": end, "kind": kind,
                "position": vector(bc, "position", w, []) if "position" in bc else None,
                "direction": vector(bc, "direction", w, [], nonzero=True) if "direction" in bc else None,
                "speed": speed, "profile": profile, "t_ramp": t_ramp,
                "t_hold_end": number(bc, "t_hold_end", w, 3.0 * t_ramp, lo=t_ramp)}
        sc["boundary"].append(item)
    _check_sleeve_travel(sc, t_end)

    sc["point_loads"] = []
    for i, pl in enumerate(tables_of(raw, "point_loads")):
        w = f"point_loads[{i}]"
        check_keys(pl, _LOAD, w)
        ib = beam_ref(pl, w)
        L = sc["beams"][ib]["length"]
        s0 = number(pl, "s", w, lo=0.0, hi=L)
        speed = number(pl, "speed", w, 0.0)
        sc["point_loads"].append({
            "beam": ib, "s": s0, "speed": speed,
            "force": vector(pl, "force", w), "start": number(pl, "start", w, 0.0, lo=0.0)})
        _check_load_travel(sc, i, t_end)
    ini = table_of(raw, "initial", "")
    check_keys(ini, {"static_equilibrium"}, "initial")
    sc["initial"] = {"static_equilibrium": boolean(ini, "static_equilibrium", "initial", False)}
    return sc


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
