"""Scene files (TOML): the shipped scenes, reading and dotted-key overrides.

A scene names its bodies, boundary conditions, loads, effects and solver settings, in SI units.
Shipped scenes live in ``sim_core/scenes/*.toml`` and load by name; any other path loads as a
file.  Overrides set dotted keys (``solver.t_end``, ``beams.0.section.E``; list items by index)
with values parsed as TOML (``"0.5"``, ``"false"``, ``"[0, 0, -1]"``).  Validation belongs to
each system kind (``sim_core.registry``); :func:`sim_core.load_scene` joins the two.
"""

from __future__ import annotations

import copy
import math
import os
import sys
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

from sim_core.errors import SceneError
from sim_core.scene.fields import did_you_mean, short_repr

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def shipped_scenes() -> dict[str, Path]:
    """Names and paths of the scenes shipped with the package."""
    folder = resources.files("sim_core") / "scenes"
    return {p.name[:-5]: Path(str(p)) for p in folder.iterdir() if p.name.endswith(".toml")}


def read_scene(name_or_path: str | Path) -> tuple[dict, str]:
    """The raw table of a shipped scene (by name) or a TOML file, and its source path."""
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise SceneError(f"scene = {short_repr(name_or_path)}: must be a shipped scene's name "
                         f"or a path (str or os.PathLike), not {type(name_or_path).__name__}")
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
    except ValueError as exc:   # an integer past Python's digit limit for int(str)
        raise SceneError(f"{path}: unreadable number: {exc}") from None
    except OSError as exc:
        raise SceneError(f"scene {str(name_or_path)!r}: cannot read {path}: {exc.strerror}") from None


def parse_value(text: str) -> Any:
    """Parse an override value written as in TOML (numbers, booleans, strings, arrays); text
    that is no TOML value (or a numeral past Python's digit limit for int(str)) stays text."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except (tomllib.TOMLDecodeError, ValueError):
        return text


def _huge_int(v) -> int | None:
    """The bit length of the first integer in v (a value, list or table) too long to print
    (over ``sys.get_int_max_str_digits()`` digits), else None."""
    if isinstance(v, int) and not isinstance(v, bool):
        return v.bit_length() if v.bit_length() > _PRINTABLE_BITS else None
    items = v.values() if isinstance(v, dict) else v if isinstance(v, (list, tuple)) else ()
    for x in items:
        bits = _huge_int(x)
        if bits is not None:
            return bits
    return None


# bits of the longest integer str() prints (Python refuses integers of more decimal digits
# than sys.get_int_max_str_digits(), 4300 by default; 0 means no limit)
_PRINTABLE_BITS = int((getattr(sys, "get_int_max_str_digits", int)() or 10 ** 9)
                      / math.log10(2)) - 1


def apply_overrides(raw: dict, overrides: dict[str, Any]) -> dict:
    """Set dotted keys, e.g. {"solver.t_end": 4, "beams.0.section.E": 2e11}.

    String values are parsed as TOML values (``"0.5"`` -> 0.5, ``"false"`` -> False,
    ``"[0, 0, -1]"`` -> a list); a string that is no TOML value stays a string.  List items are
    addressed by their index (0-based).  Missing tables are created (so a misspelt key reaches
    validation, which suggests the right one).  ``overrides`` must be a mapping whose keys are
    strings (:class:`SceneError` otherwise); the values are checked by the scene's validation.
    """
    if not isinstance(overrides, Mapping):
        raise SceneError(f"overrides = {short_repr(overrides)}: must be a mapping of dotted keys "
                         f"to values, e.g. {{'solver.t_end': 4}} (not "
                         f"{type(overrides).__name__})")
    out = copy.deepcopy(raw)
    for key, value in overrides.items():
        if not isinstance(key, str):
            raise SceneError(f"override {short_repr(key)}: the key must be a dotted string, "
                             f"e.g. 'solver.t_end' (not {type(key).__name__})")
        if isinstance(value, str):
            value = parse_value(value)
        bits = _huge_int(value)
        if bits is not None:
            raise SceneError(f"override {key!r}: an integer of {bits} bits is out of range "
                             f"(numbers are floats, |x| <= {sys.float_info.max:.4g})")
        parts = key.split(".")
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
