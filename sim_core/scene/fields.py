"""Typed scene-field helpers: each reads one key of a table, fills its default and raises a
:class:`sim_core.errors.SceneError` that names the dotted field, the value and the allowed range.
The system kinds' validators (``sim_core.systems.*.schema``) are written with them, and the scene
reference of the documentation is generated from those validators.
"""

from __future__ import annotations

import difflib
import math

from sim_core.errors import SceneError


def did_you_mean(word: object, options) -> str:
    """"; did you mean 'x'?" for the closest option (case-insensitive), or ""."""
    options = [str(o) for o in options]
    low = {o.lower(): o for o in options}
    w = str(word).lower()
    hit = [low[w]] if w in low else [low[m] for m in difflib.get_close_matches(w, list(low), n=1)]
    return f"; did you mean {hit[0]!r}?" if hit else ""


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

_SOLVER = {"t_end", "method", "jacobian", "rtol", "atol", "n_output", "max_step", "max_wall_s",
           "h", "h_max", "rho_inf", "newton_atol"}
SOLVER_METHODS = ("RK45", "BDF", "auto", "generalized_alpha")
JACOBIANS = ("structured", "finite_difference")
_ALPHA_KEYS = ("h", "h_max", "rho_inf", "newton_atol")
# the methods with error control, the stiffness switch and the stall monitor: the only ones for
# systems whose forces switch (friction stick-slip, contact) or that hold nonlinear constraints
ERROR_CONTROLLED = ("RK45", "BDF", "auto")


def solver_table(s: dict, t_end=None, atol: float = 1e-8, n_output: int = 201,
                 methods: tuple[str, ...] = SOLVER_METHODS, method: str = "RK45") -> dict:
    """The validated [solver] table shared by every scene kind: t_end s (> 0), method
    (``methods``, default ``method``, see :func:`sim_core.integrate.driver.integrate`), jacobian
    of the implicit method (``JACOBIANS``: "structured" = :mod:`sim_core.model.state_jacobian`,
    "finite_difference" = scipy's differences of the whole right-hand side), rtol (0, 1), atol
    (> 0), n_output (>= 2), optional max_step s (> 0) and max_wall_s s (> 0, wall-clock budget).
    With method "generalized_alpha": rho_inf (spectral radius at infinity, [0, 1], default
    0.9), and either h s (> 0, optional: a fixed step of at most h; rtol/atol then unused) or,
    without h, error-controlled steps from rtol/atol with an optional largest step h_max s
    (> 0); newton_atol m (> 0, the position error the Newton iteration may leave per step;
    default 1e-8 with h, atol / 10 without, below the error the step control allows).
    The arguments are the scene kind's defaults (t_end None: required)."""
    check_keys(s, _SOLVER, "solver")
    out = {"t_end": number(s, "t_end", "solver", t_end, lo=0.0, lo_open=True),
           "method": choice(s, "method", "solver", methods, method),
           "jacobian": choice(s, "jacobian", "solver", JACOBIANS, "structured"),
           "rtol": number(s, "rtol", "solver", 1e-6, lo=0.0, hi=1.0, lo_open=True, hi_open=True),
           "atol": number(s, "atol", "solver", atol, lo=0.0, lo_open=True),
           "n_output": number(s, "n_output", "solver", n_output, lo=2, integer=True)}
    for key in ("max_step", "max_wall_s"):
        if key in s:
            out[key] = number(s, key, "solver", lo=0.0, lo_open=True)
    if out["method"] == "generalized_alpha":
        if "h" in s:
            # at least 1e-7 s and at most 1e7 steps: a step below that cannot finish in any
            # wall budget (and one compiled call per output interval must return in time)
            h_lo = max(1e-7, out["t_end"] / 1e7)
            out["h"] = number(s, "h", "solver", lo=h_lo, hi=out["t_end"])
            if "h_max" in s:
                raise SceneError(f"solver.h_max = {s['h_max']!r}: only the error-controlled "
                                 f"steps (no solver.h) have an h_max; solver.h = {s['h']!r} "
                                 "fixes the step (remove one of them)")
        else:
            out["h_max"] = number(s, "h_max", "solver", out["t_end"], lo=0.0, hi=out["t_end"],
                                  lo_open=True)
        out["rho_inf"] = number(s, "rho_inf", "solver", 0.9, lo=0.0, hi=1.0)
        out["newton_atol"] = number(s, "newton_atol", "solver",
                                    1e-8 if "h" in out else 0.1 * out["atol"], lo=0.0,
                                    lo_open=True)
    else:
        for key in _ALPHA_KEYS:
            if key in s:
                raise SceneError(f"solver.{key} = {s[key]!r}: only method = 'generalized_alpha' "
                                 f"has a {key} (method is {out['method']!r})")
    return out
