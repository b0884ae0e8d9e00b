"""Scene files (TOML): parsing, overrides and validation with field-naming errors.

A scene names its bodies, boundary conditions, loads, effects and solver settings, in SI units.
Shipped scenes live in ``sim_core/scenes/*.toml`` and load by name; any other path loads as a
file.  Overrides set dotted keys (``solver.t_end``, ``beams.0.section.E``; list items by index)
with values parsed as TOML (``"0.5"``, ``"false"``, ``"[0, 0, -1]"``).  Every value is checked:
an error names the dotted field, the value and the allowed range
(:class:`sim_core.errors.SceneError`); unknown keys and names get a "did you mean" suggestion.

Beam-scene schema (units):
  name, description
  [solver]   t_end s (> 0), method ("RK45", "BDF", "auto"), rtol (0, 1), atol (> 0), n_output (>= 2),
             max_step s (> 0, optional), max_wall_s s (> 0, optional: wall-clock budget; the
             run stops there with a SimulationError and a partial result)
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

import copy
import difflib
import math
import sys
from importlib import resources
from pathlib import Path
from typing import Any

from .errors import SceneError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def did_you_mean(word: object, options) -> str:
    """"; did you mean 'x'?" for the closest option (case-insensitive), or ""."""
    options = [str(o) for o in options]
    low = {o.lower(): o for o in options}
    w = str(word).lower()
    hit = [low[w]] if w in low else [low[m] for m in difflib.get_close_matches(w, list(low), n=1)]
    return f"; did you mean {hit[0]!r}?" if hit else ""


def shipped_scenes() -> dict[str, Path]:
    """Names and paths of the scenes shipped with the package."""
    folder = resources.files("sim_core") / "scenes"
    return {p.name[:-5]: Path(str(p)) for p in folder.iterdir() if p.name.endswith(".toml")}


def _read(name_or_path: str | Path) -> tuple[dict, str]:
    scenes = shipped_scenes()
    if str(name_or_path) in scenes:
        path = scenes[str(name_or_path)]
    else:
        path = Path(name_or_path)
        if not path.is_file():
            more = did_you_mean(name_or_path, scenes)
            raise SceneError(f"scene {str(name_or_path)!r}: not a shipped scene "
                             f"({', '.join(sorted(scenes))}) nor an existing file{more}")
    try:
        with open(path, "rb") as f:
            return tomllib.load(f), str(path)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path}: invalid TOML: {exc}") from None
    except OSError as exc:
        raise SceneError(f"scene {str(name_or_path)!r}: cannot read {path}: {exc.strerror}") from None


def parse_value(text: str) -> Any:
    """Parse an override value written as in TOML (numbers, booleans, strings, arrays)."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_overrides(raw: dict, overrides: dict[str, Any]) -> dict:
    """Set dotted keys, e.g. {"solver.t_end": 4, "beams.0.section.E": 2e11}.

    String values are parsed as TOML values (``"0.5"`` -> 0.5, ``"false"`` -> False,
    ``"[0, 0, -1]"`` -> a list); a string that is no TOML value stays a string.  List items are
    addressed by their index (0-based).  Missing tables are created (so a misspelt key reaches
    validation, which suggests the right one).
    """
    out = copy.deepcopy(raw)
    for key, value in overrides.items():
        if isinstance(value, str):
            value = parse_value(value)
        parts = str(key).split(".")
        if any(not p.strip() for p in parts):
            raise SceneError(f"override {key!r}: empty key part (expected e.g. solver.t_end)")
        node: Any = out
        for i, p in enumerate(parts):
            last = i == len(parts) - 1
            here = ".".join(parts[:i]) or "scene"
            if isinstance(node, list):
                try:
                    j = int(p)
                    if not 0 <= j < len(node):
                        raise IndexError
                except (ValueError, IndexError):
                    rng = f"0..{len(node) - 1}" if node else f"none: {here} is empty"
                    raise SceneError(f"override {key!r}: {p!r} is not a valid index of {here} "
                                     f"({rng})") from None
                if last:
                    node[j] = value
                else:
                    node = node[j]
            elif isinstance(node, dict):
                if last:
                    node[p] = value
                else:
                    node = node.setdefault(p, {})
            else:
                raise SceneError(f"override {key!r}: {here} = {node!r} is a value, not a table "
                                 f"or list (cannot set {p!r} inside it)")
    return out


# -- validation helpers ------------------------------------------------------------------------

def check_keys(table: dict, allowed: set[str], where: str) -> None:
    for k in table:
        if k not in allowed:
            more = did_you_mean(k, sorted(allowed))
            raise SceneError(f"{where}.{k}: unknown key (allowed: {', '.join(sorted(allowed))}){more}")


def _range(lo, hi, lo_open: bool, hi_open: bool) -> str:
    """Interval text, e.g. (0, inf) or [1, 10]; an infinite end is always open."""
    return (("(" if lo_open or lo is None else "[") + ("-inf" if lo is None else f"{lo:g}") + ", "
            + ("inf" if hi is None else f"{hi:g}") + (")" if hi_open or hi is None else "]"))


def number(table: dict, key: str, where: str, default=None, *, lo=None, hi=None,
           lo_open=False, hi_open=False, integer=False) -> float:
    """A finite number in [lo, hi] (open ends if requested); errors name the field."""
    field = f"{where}.{key}" if where else key
    rng = _range(lo, hi, lo_open, hi_open)
    kind = "an integer" if integer else "a number"
    if key not in table:
        if default is None:
            raise SceneError(f"{field}: missing (required, {kind} in {rng})")
        return default
    v = table[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise SceneError(f"{field} = {v!r}: must be {kind} in {rng}")
    if not math.isfinite(v):
        raise SceneError(f"{field} = {v!r}: must be finite (NaN/inf not allowed), allowed {rng}")
    if integer and int(v) != v:
        raise SceneError(f"{field} = {v!r}: must be an integer in {rng}")
    if lo is not None and (v < lo or (lo_open and v == lo)):
        raise SceneError(f"{field} = {v!r}: out of range, allowed {rng}")
    if hi is not None and (v > hi or (hi_open and v == hi)):
        raise SceneError(f"{field} = {v!r}: out of range, allowed {rng}")
    return int(v) if integer else float(v)


def vector(table: dict, key: str, where: str, default=None, n: int = 3,
           nonzero: bool = False) -> list[float]:
    field = f"{where}.{key}"
    if key not in table:
        if default is None:
            raise SceneError(f"{field}: missing (required)")
        return list(default)
    v = table[key]
    if not isinstance(v, list) or len(v) != n:
        raise SceneError(f"{field} = {v!r}: must be a list of {n} finite numbers")
    out = [number({f"{key}[{j}]": x}, f"{key}[{j}]", where) for j, x in enumerate(v)]
    if nonzero and all(x == 0 for x in out):
        raise SceneError(f"{field} = {v!r}: must not be the zero vector "
                         f"(allowed: any nonzero {n}-vector)")
    return out


def table_of(parent: dict, key: str, where: str) -> dict:
    """A sub-table (TOML [key]); missing -> {}."""
    field = f"{where}.{key}" if where else key
    v = parent.get(key, {})
    if not isinstance(v, dict):
        raise SceneError(f"{field} = {v!r}: must be a table ([{field}])")
    return v


def tables_of(parent: dict, key: str) -> list[dict]:
    """An array of tables (TOML [[key]]); missing -> []."""
    v = parent.get(key, [])
    if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
        raise SceneError(f"{key} = {v!r}: must be an array of tables ([[{key}]])")
    return v


def boolean(table: dict, key: str, where: str, default: bool) -> bool:
    v = table.get(key, default)
    if not isinstance(v, bool):
        raise SceneError(f"{where}.{key} = {v!r}: must be true or false")
    return v


def choice(table: dict, key: str, where: str, allowed: tuple[str, ...], default=None) -> str:
    v = table.get(key, default)
    if v is None:
        raise SceneError(f"{where}.{key}: missing (allowed: {', '.join(allowed)})")
    if v not in allowed:
        more = did_you_mean(v, allowed)
        raise SceneError(f"{where}.{key} = {v!r}: allowed {', '.join(allowed)}{more}")
    return v


# -- the solver table (all scene kinds) ----------------------------------------------------------

_SOLVER = {"t_end", "method", "jacobian", "rtol", "atol", "n_output", "max_step", "max_wall_s"}
SOLVER_METHODS = ("RK45", "BDF", "auto")
JACOBIANS = ("structured", "finite_difference")


def solver_table(s: dict, t_end=None, atol: float = 1e-8, n_output: int = 201) -> dict:
    """The validated [solver] table shared by every scene kind: t_end s (> 0), method
    (``SOLVER_METHODS``, see :func:`sim_core.simulate.integrate`), jacobian of the implicit
    method (``JACOBIANS``: "structured" = :mod:`sim_core.state_jacobian`, "finite_difference" =
    scipy's differences of the whole right-hand side), rtol (0, 1), atol (> 0),
    n_output (>= 2), optional max_step s (> 0) and max_wall_s s (> 0, wall-clock budget).
    The arguments are the scene kind's defaults (t_end None: required)."""
    check_keys(s, _SOLVER, "solver")
    out = {"t_end": number(s, "t_end", "solver", t_end, lo=0.0, lo_open=True),
           "method": choice(s, "method", "solver", SOLVER_METHODS, "RK45"),
           "jacobian": choice(s, "jacobian", "solver", JACOBIANS, "structured"),
           "rtol": number(s, "rtol", "solver", 1e-6, lo=0.0, hi=1.0, lo_open=True, hi_open=True),
           "atol": number(s, "atol", "solver", atol, lo=0.0, lo_open=True),
           "n_output": number(s, "n_output", "solver", n_output, lo=2, integer=True)}
    for key in ("max_step", "max_wall_s"):
        if key in s:
            out[key] = number(s, key, "solver", lo=0.0, lo_open=True)
    return out


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
    solver = solver_table(table_of(raw, "solver", ""))
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
    from .drive_profiles import sleeve_motion
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
    from .drive_profiles import sleeve_motion

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


def load_scene(name_or_path: str | Path, overrides: dict[str, Any] | None = None) -> dict:
    """Load, override and validate a scene (shipped name or TOML path)."""
    raw, source = _read(name_or_path)
    if overrides:
        raw = apply_overrides(raw, overrides)
    if raw.get("kind") == "telescopic":
        from .telescopic_scene import validate_telescopic
        return validate_telescopic(raw, source)
    if raw.get("kind") == "folding":
        from .folding_scene import validate_folding
        return validate_folding(raw, source)
    return validate(raw, source)
