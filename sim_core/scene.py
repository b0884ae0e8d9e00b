"""Scene files (TOML): parsing, overrides and validation with field-naming errors.

A scene names its bodies, boundary conditions, loads, effects and solver settings, in SI units.
Shipped scenes live in ``sim_core/scenes/*.toml`` and load by name; any other path loads as a
file.  Every value is checked: an error names the dotted field, the value and the allowed range
(:class:`sim_core.errors.SceneError`); unknown keys get a "did you mean" suggestion.

Beam-scene schema (units):
  name, description
  [solver]   t_end s (> 0), method ("RK45"), rtol (0, 1), atol (> 0), n_output (>= 2),
             max_step s (> 0, optional)
  [effects]  gravity, torsion, filtering: booleans (what is off is not computed)
  [filtering] h s (> 0): stress-averaging window (second seed Eq. 53)
  [gravity]  g m/s^2 (3-vector)
  [[beams]]  name, length m, breakpoints m (increasing, element ends), n_nodes (>= 3),
             n_gauss (1..10), origin m (position of material point s = 0 when straight),
             direction (axis), [beams.section] E Pa, G Pa, rho kg/m^3, A m^2, I_t m^4, I_b m^4,
             J m^4 (torsion constant); optional I_p m^4 (polar, default I_t + I_b) and
             rotary_bending (bool, default true: rotary inertia rho I_t, rho I_b included)
  [[boundary]] beam, end ("left"/"right"), kind ("clamped", "pinned", "roller", "free",
             "sleeve"), position m, direction, speed m/s (sleeve: rate of the end's material
             coordinate)
  [[point_loads]] beam, s m (material coordinate at t = 0), speed m/s (moving load, default 0),
             force N (3-vector, global), start s (load switched on at t >= start)
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
        if not path.exists():
            hint = difflib.get_close_matches(str(name_or_path), list(scenes), n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise SceneError(f"scene {str(name_or_path)!r}: not a shipped scene "
                             f"({', '.join(sorted(scenes))}) nor an existing file{more}")
    try:
        with open(path, "rb") as f:
            return tomllib.load(f), str(path)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: invalid TOML: {exc}") from None


def parse_value(text: str) -> Any:
    """Parse an override value written as in TOML (numbers, booleans, strings, arrays)."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_overrides(raw: dict, overrides: dict[str, Any]) -> dict:
    """Set dotted keys, e.g. {"solver.t_end": 4, "beams.0.section.E": 2e11}."""
    out = copy.deepcopy(raw)
    for key, value in overrides.items():
        if isinstance(value, str):
            value = parse_value(value)
        parts = key.split(".")
        node: Any = out
        for i, p in enumerate(parts[:-1]):
            if isinstance(node, list):
                try:
                    node = node[int(p)]
                except (ValueError, IndexError):
                    raise SceneError(f"override {key!r}: {p!r} is not a valid index "
                                     f"(0..{len(node) - 1})") from None
            else:
                node = node.setdefault(p, {})
        last = parts[-1]
        if isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
    return out


# -- validation helpers ------------------------------------------------------------------------

def check_keys(table: dict, allowed: set[str], where: str) -> None:
    for k in table:
        if k not in allowed:
            hint = difflib.get_close_matches(k, sorted(allowed), n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise SceneError(f"{where}.{k}: unknown key (allowed: {', '.join(sorted(allowed))}){more}")


def number(table: dict, key: str, where: str, default=None, *, lo=None, hi=None,
           lo_open=False, hi_open=False, integer=False) -> float:
    """A finite number in [lo, hi] (open ends if requested); errors name the field."""
    field = f"{where}.{key}" if where else key
    if key not in table:
        if default is None:
            raise SceneError(f"{field}: missing (required)")
        return default
    v = table[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise SceneError(f"{field} = {v!r}: must be a number")
    if integer and int(v) != v:
        raise SceneError(f"{field} = {v!r}: must be an integer")
    if not math.isfinite(v):
        raise SceneError(f"{field} = {v!r}: must be finite (NaN/inf not allowed)")
    rng = (("(" if lo_open else "[") + ("-inf" if lo is None else f"{lo:g}") + ", "
           + ("inf" if hi is None else f"{hi:g}") + (")" if hi_open else "]"))
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
        raise SceneError(f"{field} = {v!r}: must be a list of {n} numbers")
    out = [number({f"{key}[{j}]": x}, f"{key}[{j}]", where) for j, x in enumerate(v)]
    if nonzero and all(x == 0 for x in out):
        raise SceneError(f"{field} = {v!r}: must not be the zero vector")
    return out


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
        hint = difflib.get_close_matches(str(v), allowed, n=1)
        more = f"; did you mean {hint[0]!r}?" if hint else ""
        raise SceneError(f"{where}.{key} = {v!r}: allowed {', '.join(allowed)}{more}")
    return v


# -- the scene ---------------------------------------------------------------------------------

_TOP = {"name", "description", "solver", "effects", "filtering", "gravity", "beams",
        "boundary", "point_loads", "initial", "notes"}
_SOLVER = {"t_end", "method", "rtol", "atol", "n_output", "max_step"}
_EFFECTS = {"gravity", "torsion", "filtering"}
_BEAM = {"name", "length", "breakpoints", "n_nodes", "n_gauss", "origin", "direction", "section"}
_SECTION = {"E", "G", "rho", "A", "I_t", "I_b", "J", "I_p", "rotary_bending"}
_BOUNDARY = {"beam", "end", "kind", "position", "direction", "speed"}
_LOAD = {"beam", "s", "speed", "force", "start"}


def validate(raw: dict, source: str = "<scene>") -> dict:
    """Return the resolved scene (a plain dict with every default filled in)."""
    check_keys(raw, _TOP, "scene")
    sc: dict[str, Any] = {"name": str(raw.get("name", Path(source).stem)),
                          "description": str(raw.get("description", "")), "source": source}
    s = raw.get("solver", {})
    check_keys(s, _SOLVER, "solver")
    solver = {
        "t_end": number(s, "t_end", "solver", lo=0.0, lo_open=True),
        "method": choice(s, "method", "solver", ("RK45",), "RK45"),
        "rtol": number(s, "rtol", "solver", 1e-6, lo=0.0, hi=1.0, lo_open=True, hi_open=True),
        "atol": number(s, "atol", "solver", 1e-8, lo=0.0, lo_open=True),
        "n_output": number(s, "n_output", "solver", 201, lo=2, integer=True),
    }
    if "max_step" in s:
        solver["max_step"] = number(s, "max_step", "solver", lo=0.0, lo_open=True)
    sc["solver"] = solver

    e = raw.get("effects", {})
    check_keys(e, _EFFECTS, "effects")
    sc["effects"] = {"gravity": boolean(e, "gravity", "effects", False),
                     "torsion": boolean(e, "torsion", "effects", True),
                     "filtering": boolean(e, "filtering", "effects", False)}
    f = raw.get("filtering", {})
    check_keys(f, {"h"}, "filtering")
    sc["filtering"] = {"h": number(f, "h", "filtering", 0.01, lo=0.0, lo_open=True)}
    g = raw.get("gravity", {})
    check_keys(g, {"g"}, "gravity")
    sc["gravity"] = {"g": vector(g, "g", "gravity", [0.0, 0.0, -9.81])}

    beams = raw.get("beams")
    if not isinstance(beams, list) or not beams:
        raise SceneError("beams: at least one [[beams]] table is required")
    sc["beams"] = []
    names = []
    for i, b in enumerate(beams):
        w = f"beams[{i}]"
        check_keys(b, _BEAM, w)
        L = number(b, "length", w, lo=0.0, lo_open=True)
        bps = b.get("breakpoints", [0.0, L])
        if (not isinstance(bps, list) or len(bps) < 2
                or not all(isinstance(x, (int, float)) and math.isfinite(x) for x in bps)):
            raise SceneError(f"{w}.breakpoints = {bps!r}: must be a list of >= 2 finite numbers")
        if any(b1 <= b0 for b0, b1 in zip(bps[:-1], bps[1:])) or bps[0] < 0 or bps[-1] > L:
            raise SceneError(f"{w}.breakpoints = {bps!r}: must increase strictly within [0, {L:g}]")
        sec = b.get("section", {})
        check_keys(sec, _SECTION, f"{w}.section")
        ws = f"{w}.section"
        section = {k: number(sec, k, ws, lo=0.0, lo_open=True)
                   for k in ("E", "G", "rho", "A", "I_t", "I_b", "J")}
        section["I_p"] = number(sec, "I_p", ws, section["I_t"] + section["I_b"], lo=0.0, lo_open=True)
        section["rotary_bending"] = boolean(sec, "rotary_bending", ws, True)
        name = str(b.get("name", f"beam{i}"))
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
            hint = difflib.get_close_matches(str(nm), names, n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise SceneError(f"{where}.beam = {nm!r}: no such beam ({', '.join(names)}){more}")
        return names.index(nm)

    sc["boundary"] = []
    for i, bc in enumerate(raw.get("boundary", [])):
        w = f"boundary[{i}]"
        check_keys(bc, _BOUNDARY, w)
        ib = beam_ref(bc, w)
        kind = choice(bc, "kind", w, ("clamped", "pinned", "roller", "free", "sleeve"))
        end = choice(bc, "end", w, ("left", "right"))
        item = {"beam": ib, "end": end, "kind": kind,
                "position": vector(bc, "position", w, []) if "position" in bc else None,
                "direction": vector(bc, "direction", w, [], nonzero=True) if "direction" in bc else None,
                "speed": number(bc, "speed", w, 0.0)}
        if kind != "sleeve" and "speed" in bc:
            raise SceneError(f"{w}.speed: only a 'sleeve' end has a speed")
        sc["boundary"].append(item)
    ends = [(b["beam"], b["end"]) for b in sc["boundary"]]
    if len(set(ends)) != len(ends):
        raise SceneError("boundary: two conditions on the same beam end")

    sc["point_loads"] = []
    for i, pl in enumerate(raw.get("point_loads", [])):
        w = f"point_loads[{i}]"
        check_keys(pl, _LOAD, w)
        ib = beam_ref(pl, w)
        L = sc["beams"][ib]["length"]
        sc["point_loads"].append({
            "beam": ib, "s": number(pl, "s", w, lo=0.0, hi=L), "speed": number(pl, "speed", w, 0.0),
            "force": vector(pl, "force", w), "start": number(pl, "start", w, 0.0, lo=0.0)})
    ini = raw.get("initial", {})
    check_keys(ini, {"static_equilibrium"}, "initial")
    sc["initial"] = {"static_equilibrium": boolean(ini, "static_equilibrium", "initial", False)}
    return sc


def load_scene(name_or_path: str | Path, overrides: dict[str, Any] | None = None) -> dict:
    """Load, override and validate a scene (shipped name or TOML path)."""
    raw, source = _read(name_or_path)
    if overrides:
        raw = apply_overrides(raw, overrides)
    return validate(raw, source)
