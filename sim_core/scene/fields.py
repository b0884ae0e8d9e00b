"""Declared scene fields: every key a scene kind accepts is declared once, as data (name, type,
SI unit, default, allowed range or values, note), and the validators read the keys through the
declarations, so the check and the documented range cannot drift apart.  The scene reference
of the documentation (``docs/hooks/scene_reference.py``) is rendered from the declarations only.

* :class:`Field` declares one key; :meth:`Field.read` reads it from a table, fills its default
  and raises a :class:`sim_core.errors.SceneError` that names the dotted field, the value and
  the allowed range with its unit.  Bounds that depend on other keys (a point load's position
  on its beam, a step at most ``solver.t_end``) are passed at the call and tighten the
  declared physical range; the declaration says them in words (``allowed``).
* :class:`Table` declares a scene table (``[solver]``, ``[[beams]]``, ``[beams.section]``):
  its fields, its sub-tables and a note; :meth:`Table.check_keys` refuses unknown keys with a
  "did you mean" hint.
* :class:`Schema` is one scene kind: its tables in page order and the rules across keys.

The lower-level helpers (:func:`number`, :func:`vector`, :func:`boolean`, :func:`choice`,
:func:`check_keys`, :func:`table_of`, :func:`tables_of`) do the checks.
"""

from __future__ import annotations

import difflib
import math
import sys
from dataclasses import dataclass, field as _dc_field
from typing import Any

from sim_core.errors import SceneError


def did_you_mean(word: object, options) -> str:
    """"; did you mean 'x'?" for the closest option (case-insensitive), or ""."""
    options = [str(o) for o in options]
    low = {o.lower(): o for o in options}
    w = str(word).lower()
    hit = [low[w]] if w in low else [low[m] for m in difflib.get_close_matches(w, list(low), n=1)]
    return f"; did you mean {hit[0]!r}?" if hit else ""


# -- validation helpers ------------------------------------------------------------------------

def check_keys(table: dict, allowed, where: str) -> None:
    for k in table:
        if not isinstance(k, str) or k not in allowed:
            more = did_you_mean(k, sorted(allowed))
            raise SceneError(f"{where}.{k}: unknown key (allowed: {', '.join(sorted(allowed))}){more}")


def _range(lo, hi, lo_open: bool, hi_open: bool) -> str:
    """Interval text, e.g. (0, inf) or [1, 10]; an infinite end is always open."""
    return (("(" if lo_open or lo is None else "[") + ("-inf" if lo is None else f"{lo:g}") + ", "
            + ("inf" if hi is None else f"{hi:g}") + (")" if hi_open or hi is None else "]"))


def _with_unit(rng: str, unit: str) -> str:
    return f"{rng} {unit}" if unit else rng


_FLOAT_MAX = sys.float_info.max


def number(table: dict, key: str, where: str, default=None, *, lo=None, hi=None,
           lo_open=False, hi_open=False, integer=False, unit: str = "") -> float:
    """A finite number in [lo, hi] (open ends if requested); errors name the field, the value
    and the range (with ``unit``)."""
    field = f"{where}.{key}" if where else key
    rng = _with_unit(_range(lo, hi, lo_open, hi_open), unit)
    kind = "an integer" if integer else "a number"
    if key not in table:
        if default is None:
            raise SceneError(f"{field}: missing (required, {kind} in {rng})")
        return default
    v = table[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise SceneError(f"{field} = {short_repr(v)}: must be {kind} in {rng}")
    if isinstance(v, int) and abs(v) > _FLOAT_MAX:     # float(v) would overflow
        raise SceneError(f"{field} = {short_repr(v)}: out of range (beyond a float's "
                         f"{_FLOAT_MAX:.4g}), allowed {rng}")
    if not math.isfinite(v):
        raise SceneError(f"{field} = {v!r}: must be finite (NaN/inf not allowed), allowed {rng}")
    if integer and int(v) != v:
        raise SceneError(f"{field} = {v!r}: must be an integer in {rng}")
    if lo is not None and (v < lo or (lo_open and v == lo)):
        raise SceneError(f"{field} = {short_repr(v)}: out of range, allowed {rng}")
    if hi is not None and (v > hi or (hi_open and v == hi)):
        raise SceneError(f"{field} = {short_repr(v)}: out of range, allowed {rng}")
    return int(v) if integer else float(v)


def vector(table: dict, key: str, where: str, default=None, n: int = 3,
           nonzero: bool = False, *, lo=None, hi=None, unit: str = "") -> list[float]:
    """A list of ``n`` finite numbers, each in [lo, hi]; ``nonzero``: not the zero vector."""
    field = f"{where}.{key}"
    if key not in table:
        if default is None:
            raise SceneError(f"{field}: missing (required, a list of {n} numbers)")
        return list(default)
    v = table[key]
    rng = _with_unit(_range(lo, hi, False, False), unit)
    if not isinstance(v, list) or len(v) != n:
        raise SceneError(f"{field} = {short_repr(v)}: must be a list of {n} finite numbers, "
                         f"each in {rng}")
    out = [number({f"{key}[{j}]": x}, f"{key}[{j}]", where, lo=lo, hi=hi, unit=unit)
           for j, x in enumerate(v)]
    if nonzero and math.fsum(x * x for x in out) < 1e-12:
        raise SceneError(f"{field} = {v!r}: must not be the zero vector "
                         f"(allowed: a nonzero {n}-vector, of length at least 1e-6)")
    return out


def table_of(parent: dict, key: str, where: str) -> dict:
    """A sub-table (TOML [key]); missing -> {}."""
    field = f"{where}.{key}" if where else key
    v = parent.get(key, {})
    if not isinstance(v, dict):
        raise SceneError(f"{field} = {short_repr(v)}: must be a table ([{field}])")
    return v


def tables_of(parent: dict, key: str) -> list[dict]:
    """An array of tables (TOML [[key]]); missing -> []."""
    v = parent.get(key, [])
    if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
        raise SceneError(f"{key} = {short_repr(v)}: must be an array of tables ([[{key}]])")
    return v


def boolean(table: dict, key: str, where: str, default: bool) -> bool:
    v = table.get(key, default)
    if not isinstance(v, bool):
        raise SceneError(f"{where}.{key} = {short_repr(v)}: must be true or false")
    return v


def choice(table: dict, key: str, where: str, allowed: tuple[str, ...], default=None) -> str:
    v = table.get(key, default)
    if v is None:
        raise SceneError(f"{where}.{key}: missing (allowed: {', '.join(allowed)})")
    if not isinstance(v, str) or v not in allowed:
        more = did_you_mean(v, allowed) if isinstance(v, str) else ""
        raise SceneError(f"{where}.{key} = {short_repr(v)}: allowed {', '.join(allowed)}{more}")
    return v


def short_repr(v, n: int = 80) -> str:
    """repr of a value, cut to n characters (a huge array or integer in an error message)."""
    try:
        r = repr(v)
    except ValueError:          # an integer past Python's digit limit for str(), or inside v
        return (f"<an integer of {v.bit_length()} bits>" if isinstance(v, int) else
                f"<a {type(v).__name__} holding an integer of over "
                f"{getattr(sys, 'get_int_max_str_digits', int)()} digits>")
    return r if len(r) <= n else r[:n - 5] + " ...]"


# -- declarations --------------------------------------------------------------------------------

class _Marker:
    def __init__(self, name: str):
        self.name = name

    def __repr__(self) -> str:
        return self.name


#: the key must be given
REQUIRED = _Marker("REQUIRED")
#: the key may be left out: then the feature it sets is not used
OPTIONAL = _Marker("OPTIONAL")
#: the validator computes the default from other keys (``Field.default_text`` says how)
COMPUTED = _Marker("COMPUTED")

TYPES = ("number", "integer", "boolean", "choice", "string", "vector", "numbers", "rows",
         "strings")


@dataclass(frozen=True)
class Field:
    """One scene key, declared once.

    type: "number", "integer", "boolean", "choice" (one of ``choices``), "string", "vector"
    (``n`` numbers, each in [lo, hi]), "numbers" (a list of ``items`` numbers in [lo, hi]),
    "rows" (a list of ``items`` rows of ``len(columns)`` numbers, column j in ``columns[j]`` =
    (lo, hi)) or "strings" (a list of ``items`` strings).  unit: the SI unit ("" = none).
    default: a value, REQUIRED, OPTIONAL or COMPUTED (``default_text`` says how).  lo, hi,
    lo_open, hi_open: the physical range (every number is bounded).  allowed: the range in
    words where other keys narrow it (``"(0, solver.t_end]"``).  applies: in words, when the key
    is read (``"shape = 'u'"``); ``when``: the same as tags the validator selects keys by."""

    key: str
    type: str
    unit: str = ""
    default: Any = REQUIRED
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple = ()
    n: int = 3
    items: tuple[int, int] = (1, 1)
    columns: tuple = ()
    nonzero: bool = False
    allowed: str = ""
    default_text: str = ""
    note: str = ""
    applies: str = ""
    when: tuple[str, ...] = ()

    def __post_init__(self):
        assert self.type in TYPES, self.type
        if self.type in ("number", "integer", "vector", "numbers"):
            assert self.lo is not None and self.hi is not None, f"{self.key}: unbounded"

    # -- what the reference shows
    def range_text(self) -> str:
        """The allowed values in words: the declared words, the interval, or the choices."""
        if self.allowed:
            return self.allowed
        if self.type in ("number", "integer"):
            return _with_unit(_range(self.lo, self.hi, self.lo_open, self.hi_open), self.unit)
        if self.type == "boolean":
            return "true, false"
        if self.type == "choice":
            return ", ".join(f'"{c}"' for c in self.choices)
        if self.type == "vector":
            rng = _with_unit(_range(self.lo, self.hi, False, False), self.unit)
            return f"each in {rng}" + (", not all zero" if self.nonzero else "")
        if self.type == "numbers":
            rng = _with_unit(_range(self.lo, self.hi, self.lo_open, self.hi_open), self.unit)
            return f"{self._count()} numbers, each in {rng}"
        if self.type == "rows":
            cols = ", ".join(_with_unit(_range(lo, hi, False, False), u)
                             for lo, hi, u in self.columns)
            return f"{self._count()} rows [{cols}]"
        if self.type == "strings":
            return f"{self._count()} names"
        return "any text"

    def _count(self) -> str:
        a, b = self.items
        return str(a) if a == b else f"{a} to {b}"

    def type_text(self) -> str:
        return {"vector": f"{self.n} numbers", "numbers": "list of numbers",
                "rows": "list of rows", "strings": "list of strings",
                "choice": "string"}.get(self.type, self.type)

    def default_shown(self) -> str:
        if self.default is REQUIRED:
            return "required"
        if self.default is OPTIONAL:
            return "optional (none)"
        if self.default is COMPUTED:
            return self.default_text
        return toml_text(self.default)

    # -- the check
    def bounds(self, lo=None, hi=None, lo_open=False, hi_open=False):
        """The declared range tightened by a bound from other keys (lo, hi; None: none)."""
        L, Lo, H, Ho = self.lo, self.lo_open, self.hi, self.hi_open
        if lo is not None and (L is None or lo > L or (lo == L and lo_open)):
            L, Lo = lo, lo_open
        if hi is not None and (H is None or hi < H or (hi == H and hi_open)):
            H, Ho = hi, hi_open
        return L, H, Lo, Ho

    def read(self, table: dict, where: str, *, default=None, lo=None, hi=None,
             lo_open=False, hi_open=False, choices=None, required=False):
        """The key's value from ``table`` (where: the table's dotted name) or its default; a
        bad value raises SceneError naming the field, the value and the allowed range.
        ``default``: the computed default of a COMPUTED field (or to replace the declared
        one); lo, hi (with lo_open, hi_open): bounds from other keys; choices: the allowed
        values where other keys give them (beam names); required: an OPTIONAL key that
        other keys make required."""
        if default is None and self.default not in (REQUIRED, OPTIONAL, COMPUTED):
            default = self.default
        if self.key not in table and default is None:
            if self.default is OPTIONAL and not required:
                return None
            if self.default is COMPUTED:
                raise AssertionError(f"{where}.{self.key}: computed default not given")
        t = self.type
        if t in ("number", "integer"):
            L, H, Lo, Ho = self.bounds(lo, hi, lo_open, hi_open)
            return number(table, self.key, where, default, lo=L, hi=H, lo_open=Lo, hi_open=Ho,
                          integer=t == "integer", unit=self.unit)
        if t == "boolean":
            return boolean(table, self.key, where, default)
        if t == "choice":
            return choice(table, self.key, where, tuple(choices or self.choices), default)
        if t == "string":
            v = table.get(self.key, default)
            if v is None:
                raise SceneError(f"{where}.{self.key}: missing (required, a string)")
            if not isinstance(v, str):
                raise SceneError(f"{where}.{self.key} = {short_repr(v)}: must be a string")
            return v
        if t == "vector":
            return vector(table, self.key, where, default, n=self.n, nonzero=self.nonzero,
                          lo=self.lo, hi=self.hi, unit=self.unit)
        if t == "numbers":
            return self._numbers(table, where, default, lo, hi, lo_open, hi_open)
        if t == "rows":
            return self._rows(table, where, default)
        return self._strings(table, where, default)

    def _items(self, v, where: str, what: str):
        field = f"{where}.{self.key}"
        a, b = self.items
        if not isinstance(v, list) or not a <= len(v) <= b:
            raise SceneError(f"{field} = {short_repr(v)}: must be a list of {self._count()} {what}")

    def _numbers(self, table, where, default, lo, hi, lo_open, hi_open):
        if self.key not in table:
            if default is None:
                raise SceneError(f"{where}.{self.key}: missing (required, "
                                 f"{self.range_text()})")
            return list(default)
        v = table[self.key]
        self._items(v, where, "numbers")
        L, H, Lo, Ho = self.bounds(lo, hi, lo_open, hi_open)
        return [number({f"{self.key}[{j}]": x}, f"{self.key}[{j}]", where, lo=L, hi=H,
                       lo_open=Lo, hi_open=Ho, unit=self.unit) for j, x in enumerate(v)]

    def _rows(self, table, where, default):
        if self.key not in table:
            if default is None:
                raise SceneError(f"{where}.{self.key}: missing (required, {self.range_text()})")
            return [list(r) for r in default]
        v = table[self.key]
        self._items(v, where, f"rows of {len(self.columns)} numbers")
        out = []
        for i, row in enumerate(v):
            if not isinstance(row, list) or len(row) != len(self.columns):
                raise SceneError(f"{where}.{self.key}[{i}] = {short_repr(row)}: must be a row of "
                                 f"{len(self.columns)} numbers ({self.range_text()})")
            out.append([number({f"{self.key}[{i}][{j}]": x}, f"{self.key}[{i}][{j}]", where,
                               lo=lo, hi=hi, unit=u)
                        for j, (x, (lo, hi, u)) in enumerate(zip(row, self.columns))])
        return out

    def _strings(self, table, where, default):
        if self.key not in table:
            if default is None:
                raise SceneError(f"{where}.{self.key}: missing (required, {self.range_text()})")
            return list(default)
        v = table[self.key]
        self._items(v, where, "strings")
        if not all(isinstance(x, str) for x in v):
            raise SceneError(f"{where}.{self.key} = {short_repr(v)}: must be a list of "
                             f"{self._count()} strings")
        return list(v)


def toml_text(v) -> str:
    """A value as written in TOML."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, float):
        return f"{v:g}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_text(x) for x in v) + "]"
    return str(v)


@dataclass(frozen=True)
class Table:
    """A scene table: ``path`` its dotted name ("" the top level, "beams[]" an array of tables,
    "beams[].section" a table inside each of them), its fields in order, the names of its
    sub-tables, a note (when the table is read, what it configures) and, for an array of
    tables, how many it may hold (``items``)."""

    path: str
    fields: tuple[Field, ...]
    tables: tuple[str, ...] = ()
    note: str = ""
    items: tuple[int, int] | None = None
    _index: dict = _dc_field(default=None, compare=False, repr=False)

    def __post_init__(self):
        object.__setattr__(self, "_index", {f.key: f for f in self.fields})
        assert len(self._index) == len(self.fields), f"{self.path}: a key declared twice"

    def __getitem__(self, key: str) -> Field:
        return self._index[key]

    def __contains__(self, key: str) -> bool:
        return key in self._index

    def keys(self, tag: str | None = None) -> set[str]:
        """The keys a table may hold: every field's (those with ``when`` only where ``tag`` is
        one of them) and the sub-tables'."""
        return ({f.key for f in self.fields if not f.when or tag in f.when}
                | set(self.tables))

    def all_keys(self) -> set[str]:
        """Every declared key and sub-table, whatever the tags."""
        return set(self._index) | set(self.tables)

    def check_keys(self, table: dict, where: str, tag: str | None = None, extra=()) -> None:
        check_keys(table, self.keys(tag) | set(extra), where or "scene")

    def read(self, table: dict, key: str, where: str, **kw):
        return self._index[key].read(table, where, **kw)

    def resolve(self, parent: dict, name: str, keys=None) -> dict:
        """The sub-table ``name`` of ``parent`` checked and read: its keys checked, then
        ``keys`` (default: every field without a ``when`` tag, in declared order) read with
        their defaults and ranges."""
        table = table_of(parent, name, "")
        self.check_keys(table, name)
        keys = [f.key for f in self.fields if not f.when] if keys is None else keys
        return {k: self.read(table, k, name) for k in keys}

    def array(self, parent: dict) -> list[dict]:
        """The array of tables this table declares (``[[name]]``) from its parent, its count
        within ``items``."""
        name = self.path.rsplit(".", 1)[-1].removesuffix("[]")
        out = tables_of(parent, name)
        lo, hi = self.items
        if not lo <= len(out) <= hi:
            raise SceneError(f"[[{name}]]: {len(out)} tables, allowed {lo} to {hi}")
        return out


@dataclass(frozen=True)
class Schema:
    """One scene kind: ``kind`` (the value of the top-level key; None: the beam scenes),
    ``title``, ``validator`` (its dotted name), the tables in the reference's order and the
    rules across keys (each one sentence)."""

    kind: str | None
    title: str
    validator: str
    tables: tuple[Table, ...]
    rules: tuple[str, ...] = ()

    def table(self, path: str) -> Table:
        for t in self.tables:
            if t.path == path:
                return t
        raise KeyError(path)


# -- shared declarations -----------------------------------------------------------------------

#: the longest time any scene takes, s: one hour of crane operation
T_MAX = 3600.0


def time_field(key: str, default=REQUIRED, note: str = "", lo: float = 0.0, **kw) -> Field:
    """A time in [lo, T_MAX] s (a duration that divides: lo > 0)."""
    return Field(key, "number", "s", default, lo=lo, hi=T_MAX, note=note, **kw)


def text_fields(name_default: str, name_text: str = "") -> tuple[Field, ...]:
    """name, description and notes of a scene (the top level)."""
    name = (Field("name", "string", default=COMPUTED, default_text=name_text)
            if name_text else Field("name", "string", default=name_default))
    return (name,
            Field("description", "string", default="", note="one line, shown by boom-sim list"),
            Field("notes", "string", default=OPTIONAL, note="free text"))


def read_text(raw: dict, table: Table, sc: dict, name_default: str) -> None:
    """name, description (into sc) and notes (checked only) of a scene's top level."""
    sc["name"] = table.read(raw, "name", "scene", default=name_default)
    sc["description"] = table.read(raw, "description", "scene")
    table.read(raw, "notes", "scene")


# -- the solver table (all scene kinds) ----------------------------------------------------------

SOLVER_METHODS = ("RK45", "BDF", "auto", "generalized_alpha")
#: every method the driver knows: SOLVER_METHODS (the default of a scene kind) and the
#: Rosenbrock-W training integrator "ROS2", which a kind offers by name (the telescopic one)
INTEGRATORS = SOLVER_METHODS + ("ROS2",)
JACOBIANS = ("structured", "finite_difference")
#: the [solver] keys that only some methods take
_METHOD_KEYS = {"generalized_alpha": ("h", "h_max", "rho_inf", "newton_atol"),
                "ROS2": ("h", "jacobian_interval")}
# the methods with error control, the stiffness switch and the stall monitor: the only ones for
# systems whose forces switch (friction stick-slip, contact) or that hold nonlinear constraints
ERROR_CONTROLLED = ("RK45", "BDF", "auto")
#: the shortest fixed generalized-alpha step, s, and the most fixed steps of one run: a step
#: below them cannot finish in any wall budget
H_MIN, MAX_FIXED_STEPS = 1e-7, 1e7


def solver_fields(t_end=None, atol: float = 1e-8, n_output: int = 201,
                  methods: tuple[str, ...] = SOLVER_METHODS, method: str = "RK45") -> Table:
    """The declared [solver] table of a scene kind: its defaults (t_end None: required) and
    its methods; the generalized-alpha keys only where the kind has that method."""
    fields = [
        Field("t_end", "number", "s", REQUIRED if t_end is None else t_end, lo=1e-6, hi=T_MAX,
              note="end of the simulated time"),
        Field("method", "choice", default=method, choices=methods,
              note="the integrator (sim_core.integrate.driver.integrate): \"RK45\" explicit, "
                   "\"BDF\" implicit for stiff runs, \"auto\" switches between the two"
                   + (", \"generalized_alpha\" implicit second-order for beams without "
                      "switching forces" if "generalized_alpha" in methods else "")
                   + (", \"ROS2\" the Rosenbrock-W training integrator at a fixed step "
                      "(sim_core.integrate.rosenbrock)" if "ROS2" in methods else "")),
        Field("jacobian", "choice", default="structured", choices=JACOBIANS,
              note="the implicit methods' Jacobian: \"structured\" by implicit "
                   "differentiation (sim_core.model.state_jacobian), \"finite_difference\" "
                   "by differences of the whole right-hand side"),
        Field("rtol", "number", "", 1e-6, lo=1e-12, hi=0.1,
              note="relative tolerance of the error-controlled steps"),
        Field("atol", "number", "m", atol, lo=1e-14, hi=1e-2,
              note="absolute tolerance of the error-controlled steps (on positions in m, "
                   "velocities in m/s and angles in rad alike)"),
        Field("n_output", "integer", "", n_output, lo=2, hi=200001,
              note="equally spaced output times from 0 to t_end"),
        Field("max_step", "number", "s", OPTIONAL, lo=H_MIN, hi=T_MAX,
              allowed="[1e-07, solver.t_end] s", note="largest step of RK45/BDF"),
        Field("max_wall_s", "number", "s", OPTIONAL, lo=0.0, hi=86400.0, lo_open=True,
              note="wall-clock budget: the run stops there with a SimulationError and the "
                   "partial result"),
    ]
    if "ROS2" in methods and "generalized_alpha" not in methods:
        fields += [
            Field("h", "number", "s", 0.05, lo=1e-4, hi=T_MAX,
                  allowed="[1e-4 s, solver.t_end]", applies="method = \"ROS2\"",
                  note="fixed step: each output interval (each Simulation.advance) cut into "
                       "equal steps of at most h (rtol and atol then unused)"),
            Field("jacobian_interval", "number", "s", 0.5, lo=0.0, hi=T_MAX,
                  applies="method = \"ROS2\"",
                  note="simulated time between fresh structured Jacobians (0: every step); "
                       "a step across the friction law's slope band renews it at once"),
        ]
    if "generalized_alpha" in methods:
        fields += [
            Field("h", "number", "s", OPTIONAL, lo=H_MIN, hi=T_MAX,
                  allowed="[max(1e-7, solver.t_end / 1e7), solver.t_end] s",
                  applies="method = \"generalized_alpha\"",
                  note="fixed step: each output interval cut into equal steps of at most h "
                       "(rtol and atol then unused); without it the steps follow rtol/atol"),
            Field("h_max", "number", "s", COMPUTED, lo=H_MIN, hi=T_MAX,
                  allowed="[1e-07, solver.t_end] s", default_text="solver.t_end",
                  applies="method = \"generalized_alpha\" without h",
                  note="largest error-controlled step"),
            Field("rho_inf", "number", "", 0.9, lo=0.0, hi=1.0,
                  applies="method = \"generalized_alpha\"",
                  note="spectral radius at infinite frequency: 1 keeps every mode, 0 damps "
                       "the unresolved ones fastest"),
            Field("newton_atol", "number", "m", COMPUTED, lo=1e-15, hi=1e-2,
                  default_text="1e-8 with solver.h, else solver.atol / 10",
                  applies="method = \"generalized_alpha\"",
                  note="position error the Newton iteration may leave per step"),
        ]
    return Table("solver", tuple(fields), note="the time integration")


def solver_table(s: dict, t_end=None, atol: float = 1e-8, n_output: int = 201,
                 methods: tuple[str, ...] = SOLVER_METHODS, method: str = "RK45") -> dict:
    """The validated [solver] table shared by every scene kind (declared by
    :func:`solver_fields` with the kind's defaults ``t_end`` (None: required), ``atol``,
    ``n_output``, ``methods`` and ``method``).  With method "generalized_alpha": either h s (a
    fixed step of at most h) or error-controlled steps from rtol/atol of at most h_max s;
    rho_inf, and newton_atol m (default 1e-8 with h, atol / 10 without)."""
    T = solver_fields(t_end, atol, n_output, methods, method)
    if not isinstance(s, dict):
        raise SceneError(f"solver = {short_repr(s)}: must be a table ([solver])")
    for key in s:                   # a method's key in a kind without any method taking it
        owners = _owners(key, INTEGRATORS)
        if owners and not _owners(key, methods):
            raise SceneError(f"solver.{key} = {short_repr(s[key])}: only method = {owners} has "
                             f"a {key}, which this scene kind does not take (allowed methods: "
                             f"{', '.join(methods)})")
    T.check_keys(s, "solver")
    out = {"t_end": T.read(s, "t_end", "solver"),
           "method": T.read(s, "method", "solver"),
           "jacobian": T.read(s, "jacobian", "solver"),
           "rtol": T.read(s, "rtol", "solver"),
           "atol": T.read(s, "atol", "solver"),
           "n_output": T.read(s, "n_output", "solver")}
    if "max_step" in s:
        out["max_step"] = T.read(s, "max_step", "solver", hi=out["t_end"])
    if "max_wall_s" in s:
        out["max_wall_s"] = T.read(s, "max_wall_s", "solver")
    for key in s:                   # a method's key with another method of the kind
        owners = _owners(key, methods)
        if owners and key not in _METHOD_KEYS.get(out["method"], ()):
            raise SceneError(f"solver.{key} = {short_repr(s[key])}: only method = {owners} has "
                             f"a {key} (method is {out['method']!r})")
    if out["method"] == "generalized_alpha":
        if "h" in s:
            out["h"] = T.read(s, "h", "solver", lo=max(H_MIN, out["t_end"] / MAX_FIXED_STEPS),
                              hi=out["t_end"])
            if "h_max" in s:
                raise SceneError(f"solver.h_max = {s['h_max']!r}: only the error-controlled "
                                 f"steps (no solver.h) have an h_max; solver.h = {s['h']!r} "
                                 "fixes the step (remove one of them)")
        else:
            out["h_max"] = T.read(s, "h_max", "solver", default=out["t_end"], hi=out["t_end"])
        out["rho_inf"] = T.read(s, "rho_inf", "solver")
        out["newton_atol"] = T.read(s, "newton_atol", "solver",
                                    default=1e-8 if "h" in out else 0.1 * out["atol"])
    elif out["method"] == "ROS2":
        out["h"] = T.read(s, "h", "solver", hi=out["t_end"])
        out["jacobian_interval"] = T.read(s, "jacobian_interval", "solver")
    return out


def _owners(key: str, methods) -> str:
    """The methods among ``methods`` that take the [solver] key ``key`` (_METHOD_KEYS), quoted
    and joined by "or"; "" where none does."""
    return " or ".join(f"'{m}'" for m in methods if key in _METHOD_KEYS.get(m, ()))
