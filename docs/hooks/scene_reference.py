"""MkDocs hook: the scene reference, generated from the scene validators at build time.

``docs/scene_reference.md`` is a stub holding the marker ``<!-- scene-reference -->``;
``on_page_markdown`` replaces it with one section per scene kind.  Nothing is written by hand:

* keys, types, defaults and allowed ranges come from the validators' source, read with ``ast``:
  every call of the helpers of :mod:`sim_core.scene.fields` (``number``, ``boolean``, ``choice``,
  ``vector``) and every ``check_keys`` set of the validator functions
  (``sim_core.systems.beam.schema.validate`` with ``solver_table``, ``sim_core.systems.telescopic.schema.
  validate_telescopic``, ``sim_core.systems.folding.schema.validate_folding``, and the ``_check*``
  helpers they call);
* defaults that the source computes (for example the [solver] defaults of each scene kind) are
  read from the validator's own output for a minimal scene;
* units and the short notes come from the schema in each validator module's docstring
  (``key unit (notes)``);
* the cross-field rules are the ``SceneError`` messages raised in the validator functions;
* the last table of each kind lists what every shipped scene (``sim_core/scenes/*.toml``) sets
  differently from the defaults, from loading it.

A key added to a validator therefore appears on the next build without touching the docs.
"""

from __future__ import annotations

import ast
import importlib
import logging
import math
import re
import sys
from pathlib import Path

log = logging.getLogger("mkdocs.hooks.scene_reference")

MARKER = "<!-- scene-reference -->"
ROOT = Path(__file__).resolve().parents[2]
HELPERS = {"number", "boolean", "choice", "vector"}
UNIT_ATOM = r"(?:N|m|s|Pa|kg|rad|deg|Hz)(?:\^-?\d)?"
UNIT = rf"{UNIT_ATOM}(?:/{UNIT_ATOM})*(?:\s{UNIT_ATOM}(?:/{UNIT_ATOM})*)*"

# (title, value of ``kind``, module, validator, minimal raw scene).  Keys given in the minimal
# scene are the required ones (the validator rejects a scene without them).
KINDS = [
    ("Beam scenes (no `kind`)", None, "sim_core.systems.beam.schema", "validate",
     {"solver": {"t_end": 1.0},
      "beams": [{"length": 1.0, "section": {k: 1.0 for k in
                                            ("E", "G", "rho", "A", "I_t", "I_b", "J")}}],
      "boundary": [{"end": "left", "kind": "clamped"}],
      "point_loads": [{"s": 0.5, "force": [0.0, 0.0, -1.0]}]}),
    ("Telescopic scenes (`kind = \"telescopic\"`)", "telescopic", "sim_core.systems.telescopic.schema",
     "validate_telescopic", {"kind": "telescopic"}),
    ("Folding scenes (`kind = \"folding\"`)", "folding", "sim_core.systems.folding.schema",
     "validate_folding", {"kind": "folding"}),
]


# -- source analysis ---------------------------------------------------------------------------

def _module_info(modname: str):
    mod = importlib.import_module(modname)
    tree = ast.parse(Path(mod.__file__).read_text(encoding="utf-8"))
    funcs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    consts = {}
    for n in tree.body:
        if (isinstance(n, ast.Assign) and len(n.targets) == 1 and isinstance(n.targets[0], ast.Name)
                and isinstance(n.value, (ast.Set, ast.Tuple, ast.List))):
            vals = [e.value for e in n.value.elts if isinstance(e, ast.Constant)]
            if len(vals) == len(n.value.elts):
                consts[n.targets[0].id] = vals
    return mod, funcs, consts


class _Walker(ast.NodeVisitor):
    """Walks a validator in source order, tracking what its local names stand for:
    ("path", table path) for ``where`` strings, ("keys", [...]) for loop variables over key
    names, ("key", name) for a value validated under that key."""

    def __init__(self, modules, funcs, consts, out, params=()):
        self.modules, self.funcs, self.consts, self.out = modules, funcs, consts, out
        self.env: dict[str, tuple] = {}
        self.params = set(params)
        self.guards: list[ast.AST] = []

    # -- name resolution
    def path_of(self, node) -> str | None:
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            return node.value
        if isinstance(node, ast.Name) and self.env.get(node.id, ("",))[0] == "path":
            return self.env[node.id][1]
        if isinstance(node, ast.JoinedStr):
            return self.joined(node, lambda path: path, "{}")
        return None

    def joined(self, node: ast.JoinedStr, show_path, other: str) -> str:
        """An f-string's text: its constant parts, table paths held by local names through
        ``show_path``, and ``other`` for any other placeholder."""
        parts = []
        for v in node.values:
            if isinstance(v, ast.Constant):
                parts.append(str(v.value))
            elif isinstance(v.value, ast.Name) and self.env.get(v.value.id, ("",))[0] == "path":
                parts.append(show_path(self.env[v.value.id][1]))
            else:
                parts.append(other)
        return "".join(parts)

    def keys_of(self, node) -> list[str]:
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            return [node.value]
        if isinstance(node, ast.Name) and self.env.get(node.id, ("",))[0] == "keys":
            return list(self.env[node.id][1])
        return []

    def expr(self, node) -> str:
        """Source of an expression, with local names that hold a key's value shown as that key
        and subscripts ``a["b"]`` as ``a.b``."""
        walker = self

        class Sub(ast.NodeTransformer):
            def visit_Name(self, n):
                kind = walker.env.get(n.id, ("",))
                if kind[0] == "key":
                    return ast.copy_location(ast.Name(id=kind[1]), n)
                return n

        text = ast.unparse(Sub().visit(ast.parse(ast.unparse(node), mode="eval")))
        prev = None
        while prev != text:
            prev, text = text, re.sub(r"(\w+)\[['\"](\w+)['\"]\]", r"\1.\2", text)
        return re.sub(r"\b(sc|section|self)\.", "", text)

    def guarded(self, keys) -> bool:
        """Inside ``if "key" in table`` / ``for key in (...): if key in table`` (optional key)."""
        for g in self.guards:
            for c in ast.walk(g):
                if isinstance(c, ast.Compare) and any(isinstance(o, ast.In) for o in c.ops):
                    left = self.keys_of(c.left)
                    if set(left) & set(keys):
                        return True
        return False

    # -- statements that bind names
    def visit_Assign(self, node):
        self.visit(node.value)
        if len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            name, v = node.targets[0].id, node.value
            path = self.path_of(v) if isinstance(v, (ast.JoinedStr, ast.Constant)) else None
            if path is not None and re.fullmatch(r"[\w.\[\]{}]*", path):
                self.env[name] = ("path", path)
            elif (isinstance(v, ast.Subscript) and isinstance(v.slice, ast.Constant)
                  and isinstance(v.slice.value, str)):
                self.env[name] = ("key", v.slice.value)     # L = sc["beams"][ib]["length"]
            elif (isinstance(v, ast.Call) and isinstance(v.func, ast.Name) and v.func.id in HELPERS
                  and len(v.args) >= 2 and self.keys_of(v.args[1])):
                self.env[name] = ("key", self.keys_of(v.args[1])[0])
            else:
                self.env.pop(name, None)

    def _bind_loop(self, target, it):
        if isinstance(target, ast.Name) and isinstance(it, (ast.Tuple, ast.List, ast.Set)):
            vals = [e.value for e in it.elts if isinstance(e, ast.Constant)]
            if vals and len(vals) == len(it.elts):
                self.env[target.id] = ("keys", vals)

    def visit_For(self, node):
        self._bind_loop(node.target, node.iter)
        self.visit(node.iter)
        self.guards.append(ast.Constant(value=None))     # placeholder: loops do not guard
        self.guards.pop()
        for s in node.body + node.orelse:
            self.visit(s)

    def _comp(self, node, parts):
        for g in node.generators:
            self._bind_loop(g.target, g.iter)
        for p in parts:
            self.visit(p)

    def visit_DictComp(self, node):
        self._comp(node, [node.key, node.value])

    def visit_ListComp(self, node):
        self._comp(node, [node.elt])

    def visit_If(self, node):
        self.visit(node.test)
        self.guards.append(node.test)
        for s in node.body:
            self.visit(s)
        self.guards.pop()
        for s in node.orelse:
            self.visit(s)

    def visit_IfExp(self, node):
        self.visit(node.test)
        self.guards.append(node.test)
        self.visit(node.body)
        self.guards.pop()
        self.visit(node.orelse)

    # -- the calls that define the schema
    def visit_Call(self, node):
        f = node.func.id if isinstance(node.func, ast.Name) else None
        if f in HELPERS and len(node.args) >= 3:
            where = self.path_of(node.args[2])
            for key in self.keys_of(node.args[1]):
                if where is not None:
                    self.record(f, where, key, node)
        elif f == "check_keys" and len(node.args) >= 3:
            where = self.path_of(node.args[2])
            keys = []
            a = node.args[1]
            if isinstance(a, (ast.Set, ast.Tuple, ast.List)):
                keys = [e.value for e in a.elts if isinstance(e, ast.Constant)]
            elif isinstance(a, ast.Name):
                keys = self.consts.get(a.id, [])
            if where is not None:
                self.out["allowed"].setdefault(_norm(where), []).extend(
                    k for k in keys if k not in self.out["allowed"].get(_norm(where), []))
        elif (isinstance(node.func, ast.Attribute) and node.func.attr == "get"
              and len(node.args) == 2 and isinstance(node.args[0], ast.Constant)
              and isinstance(node.args[0].value, str)):
            d = node.args[1]
            try:
                self.out["gets"].setdefault(node.args[0].value, _fmt(ast.literal_eval(d)))
            except ValueError:
                text = self.expr(d)
                if re.fullmatch(r"\[[\w., ]*\]", text):          # e.g. [0.0, length]
                    self.out["gets"].setdefault(node.args[0].value, text)
        elif f is not None and f in self.funcs and (f == "solver_table" or f.startswith("_check")):
            fn, _, mod_consts = self.funcs[f]
            # a table path passed as an argument (``_check_actuator(d, "luffing_drive")``, or a
            # loop variable over such names) names the table of the keys the helper checks:
            # one walk per path
            bindings = [{}]
            for formal, actual in zip(fn.args.args, node.args):
                path = self.path_of(actual)
                if path is not None and re.fullmatch(r"[\w.\[\]{}]*", path):
                    bindings = [{**b, formal.arg: ("path", path)} for b in bindings]
                elif self.keys_of(actual) and isinstance(actual, ast.Name):
                    bindings = [{**b, formal.arg: ("path", k)} for b in bindings
                                for k in self.keys_of(actual)]
            for env in bindings:
                # the registry goes down with the walk, so a _check helper may call another
                sub = _Walker(self.modules, self.funcs, mod_consts, self.out,
                              params=[a.arg for a in fn.args.args])
                sub.env.update(env)
                for s in fn.body:
                    sub.visit(s)
        self.generic_visit(node)

    def visit_Raise(self, node):
        exc = node.exc
        if (isinstance(exc, ast.Call) and isinstance(exc.func, ast.Name)
                and exc.func.id == "SceneError" and exc.args):
            text = self.message(exc.args[0])
            if text and text not in self.out["rules"]:
                self.out["rules"].append(text)
        self.generic_visit(node)

    def message(self, node) -> str:
        if isinstance(node, ast.Constant):
            return str(node.value)
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
            return self.message(node.left) + self.message(node.right)
        if isinstance(node, ast.JoinedStr):
            return self.joined(node, _display_path, "…")
        return ""

    def record(self, helper, where, key, node):
        kw = {k.arg: k.value for k in node.keywords}
        default = node.args[3] if len(node.args) > 3 else kw.get("default")
        if helper == "choice":
            default = node.args[4] if len(node.args) > 4 else kw.get("default")
        item = {"helper": helper, "where": _norm(where), "key": key, "optional": False,
                "default": None, "default_kind": "none", "range": "", "type": ""}
        if self.guarded([key]):
            item["optional"] = True
        if default is None or (isinstance(default, ast.Constant) and default.value is None):
            item["default_kind"] = "none"
        elif isinstance(default, ast.Constant) or (
                isinstance(default, (ast.List, ast.Tuple, ast.UnaryOp))
                and all(isinstance(e, (ast.Constant, ast.UnaryOp)) for e in ast.walk(default)
                        if isinstance(e, ast.expr) and e is not default)):
            item["default_kind"] = "literal"
            item["default"] = ast.literal_eval(default)
        elif isinstance(default, ast.Name) and default.id in self.params:
            item["default_kind"] = "param"
        elif isinstance(default, ast.Name) and self.env.get(default.id, ("",))[0] != "key":
            item["default_kind"] = "local"
            item["default"] = default.id
        else:
            item["default_kind"] = "expr"
            item["default"] = self.expr(default)
        if helper == "number":
            integer = isinstance(kw.get("integer"), ast.Constant) and kw["integer"].value
            item["type"] = "integer" if integer else "number"
            item["range"] = self.interval(kw)
        elif helper == "boolean":
            item["type"], item["range"] = "boolean", "true, false"
        elif helper == "choice":
            allowed = node.args[3] if len(node.args) > 3 else kw.get("allowed")
            vals = None
            if isinstance(allowed, (ast.Tuple, ast.List)):
                vals = [e.value for e in allowed.elts if isinstance(e, ast.Constant)]
            elif isinstance(allowed, ast.Name):
                vals = self.consts.get(allowed.id)
                if vals is None:
                    for m in self.modules:
                        if hasattr(m, allowed.id):
                            vals = list(getattr(m, allowed.id))
                            break
            item["type"] = "string"
            item["range"] = ", ".join(f'"{v}"' for v in vals) if vals else self.expr(allowed)
        elif helper == "vector":
            n = kw.get("n")
            n = n.value if isinstance(n, ast.Constant) else 3
            item["type"] = f"{n} numbers"
            nz = isinstance(kw.get("nonzero"), ast.Constant) and kw["nonzero"].value
            item["range"] = "any, not all zero" if nz else "any finite"
        self.out["items"].append(item)

    def interval(self, kw) -> str:
        def end(node):
            if node is None or (isinstance(node, ast.Constant) and node.value is None):
                return None
            if isinstance(node, ast.Constant):
                return f"{node.value:g}"
            if isinstance(node, ast.UnaryOp) and isinstance(node.operand, ast.Constant):
                return f"{ast.literal_eval(node):g}"
            return self.expr(node)

        def flag(name):
            v = kw.get(name)
            return isinstance(v, ast.Constant) and bool(v.value)

        lo, hi = end(kw.get("lo")), end(kw.get("hi"))
        lo_open, hi_open = flag("lo_open") or lo is None, flag("hi_open") or hi is None
        return (("(" if lo_open else "[") + ("-inf" if lo is None else lo) + ", "
                + ("inf" if hi is None else hi) + (")" if hi_open else "]"))


def _norm(where: str) -> str:
    """Table path of a validator's ``where`` string: '' or 'scene' = top level,
    'beams[{}].section' -> 'beams[].section'."""
    where = "" if where in ("", "scene") else where
    return re.sub(r"\[[^\]]*\]", "[]", where)


def _display_path(where: str) -> str:
    return re.sub(r"\[[^\]]*\]", "[i]", where)


def _table_header(path: str) -> str:
    if not path:
        return "top level"
    names = path.replace("[]", "")
    return f"[[{names}]]" if path.endswith("[]") else f"[{names}]"


def _dotted(path: str, key: str) -> str:
    base = path.replace("[]", ".0")
    return f"{base}.{key}" if base else key


# -- the schema in the module docstrings ---------------------------------------------------------

def _segments(doc: str) -> dict[str, str]:
    """Docstring text per table header ``[name]`` / ``[[name]]`` (headers at parenthesis
    depth 0 only, so that a table named inside a note does not split it)."""
    text = " ".join(doc.split())
    out, depth, start, name, i = {}, 0, 0, "", 0
    header = re.compile(r"\[\[?([A-Za-z_][\w.]*)\]\]?")
    while i < len(text):
        ch = text[i]
        if ch == "[" and depth == 0:
            m = header.match(text, i)
            if m:
                out.setdefault(name, text[start:i])
                name, start, i = m.group(1), m.end(), m.end()
                continue
        depth = max(0, depth + _OPEN.get(ch, 0))
        i += 1
    out.setdefault(name, text[start:])
    return out


# brackets of notes and intervals: "(0, 0.05]" and "[t_ramp, inf)" are balanced
_OPEN = {"(": 1, "[": 1, ")": -1, "]": -1}


def _depth(text: str) -> int:
    return sum(_OPEN.get(c, 0) for c in text)


def _depth0_find(text: str, key: str):
    """First mention of ``key`` outside brackets, else the first one inside a note."""
    hits = list(re.finditer(rf"(?<![\w.\[]){re.escape(key)}\b", text))
    for m in hits:
        if _depth(text[:m.start()]) == 0:
            return m
    return hits[0] if hits else None


def _doc_entry(segment: str, key: str, siblings) -> tuple[str, str]:
    """(unit, note) of ``key`` in a docstring segment: ``key [unit] [(note)]``."""
    m = _depth0_find(segment, key)
    if not m:
        return "", ""
    rest = segment[m.end():]
    unit = ""
    u = re.match(rf"\s+({UNIT})(?=\s*(?:\(|,|;|$|--|and\b|\)))", rest)
    if u:
        unit, rest = u.group(1), rest[u.end():]
    elif re.match(r"\s*,", rest):
        # "barrel_mass, rod_mass kg (> 0)": one unit for keys of the same kind (same suffix)
        nxt = re.match(rf",\s*(\w+)\s+({UNIT})(?=\s*(?:\(|,|;|$))", rest)
        if (nxt and nxt.group(1) in siblings and "_" in key
                and nxt.group(1).rsplit("_", 1)[-1] == key.rsplit("_", 1)[-1]):
            unit = nxt.group(2)
    note = ""
    p = re.match(r"\s*\(", rest)
    if p:
        depth, j = 0, p.end() - 1
        for j in range(p.end() - 1, len(rest)):
            depth += _OPEN.get(rest[j], 0)
            if depth == 0:
                break
        note = rest[p.end():j].strip()
    return unit, note


_NOISE = re.compile(r"^(?:[\s\d.,<>=()\[\]+\-e]*|\d+\.\.\d+|\d+-vector|bool|optional|"
                    r"(?:-?[\d.]+|\w+)\.\.(?:-?[\d.]+|\w+))$")


def _clean_note(note: str, allowed: str) -> str:
    """The note without what the other columns say (intervals, 'bool', 'optional', the list of
    allowed values)."""
    if allowed and re.sub(r"\W", "", note) == re.sub(r"\W", "", allowed):
        return ""
    parts = re.split(r"([,;]\s+)", note)
    out = ""
    for frag, sep in zip(parts[0::2], [""] + parts[1::2]):
        f = re.sub(r"^(?:bool|optional)\b[:,;]?\s*", "", frag.strip())
        if not f or _NOISE.match(f):
            continue
        out += (sep if out else "") + f
    return out


def _geometry_rules(doc: str) -> str:
    m = re.search(r"Geometry rules.*", " ".join(doc.split()))
    return m.group(0) if m else ""


# -- runtime values -------------------------------------------------------------------------------

def _lookup(resolved, path: str, key: str):
    node = resolved
    if path:
        for part in path.split("."):
            name = part.replace("[]", "")
            node = node.get(name) if isinstance(node, dict) else None
            if part.endswith("[]"):
                node = node[0] if isinstance(node, list) and node else None
            if node is None:
                return None, False
    if isinstance(node, dict) and key in node:
        return node[key], True
    return None, False


def _fmt(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, float):
        return f"{v:g}" if math.isfinite(v) else str(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    if v is None:
        return "–"
    return str(v)


def _flatten(node, prefix="") -> dict[str, object]:
    out = {}
    if isinstance(node, dict):
        for k, v in node.items():
            out.update(_flatten(v, f"{prefix}.{k}" if prefix else str(k)))
    elif isinstance(node, list) and node and all(isinstance(x, dict) for x in node):
        for i, v in enumerate(node):
            out.update(_flatten(v, f"{prefix}.{i}"))
    else:
        out[prefix] = node
    return out


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|")


# -- the page -------------------------------------------------------------------------------------

def _kind_section(title, kind, modname, funcname, minimal) -> str:
    from sim_core import load_scene
    from sim_core.scene.io import shipped_scenes

    scene_mod, scene_funcs, scene_consts = _module_info("sim_core.scene.fields")
    mod, funcs, consts = _module_info(modname)
    registry = {n: (fn, scene_funcs, scene_consts) for n, fn in scene_funcs.items()}
    registry.update({n: (fn, funcs, consts) for n, fn in funcs.items()})
    out = {"items": [], "allowed": {}, "rules": [], "gets": {}}
    walker = _Walker([mod, scene_mod], registry, consts, out)
    for s in funcs[funcname].body:
        walker.visit(s)
    # effect plug-ins (sim_core.physics.plugins) of the telescopic kind: their validators'
    # keys, and their units from the validator's docstring as the segment of their table
    plugin_docs = {}
    if kind == "telescopic":
        from sim_core.physics.plugins import effect_plugins
        for name, plugin in effect_plugins().items():
            pmod, pfuncs, pconsts = _module_info(plugin.validate.__module__)
            preg = dict(registry)
            preg.update({n: (fn, pfuncs, pconsts) for n, fn in pfuncs.items()})
            pwalker = _Walker([pmod, scene_mod], preg, pconsts, out)
            for st in pfuncs[plugin.validate.__name__].body:
                pwalker.visit(st)
            doc = " ".join((plugin.validate.__doc__ or "").split())
            plugin_docs[name] = doc.split(":", 1)[1] if ":" in doc else doc
            out["items"].append({"helper": "boolean", "where": "effects", "key": name,
                                 "optional": False, "default": False,
                                 "default_kind": "literal", "range": "true, false",
                                 "type": "boolean"})

    validate = getattr(mod, funcname)
    try:
        resolved = validate(minimal, "<file name>.toml")
    except Exception as exc:  # noqa: BLE001 - shown on the page and as a build warning
        log.warning("scene reference: the minimal %s scene does not validate (%s); defaults "
                    "are read from the source only", kind or "beam", exc)
        resolved = {}
    required = set(_flatten(minimal))

    docs = {}
    # the [solver] units are written once, in the beam schema's docstring
    for m in (mod, importlib.import_module("sim_core.systems.beam.schema")):
        for name, text in _segments(m.__doc__ or "").items():
            docs.setdefault(name, text)
    own_docs = _segments(mod.__doc__ or "")
    own_docs.update(plugin_docs)

    # tables in order of first appearance, keys in the order of the table's check_keys set;
    # keys of a check_keys set without a typed helper call get a row too
    tables: dict[str, list] = {}
    for it in out["items"]:
        tables.setdefault(it["where"], [])
        if all(x["key"] != it["key"] for x in tables[it["where"]]):
            tables[it["where"]].append(it)
    for where in out["allowed"]:
        tables.setdefault(where, [])

    def is_table(where, key):
        sub = f"{where}.{key}" if where else key
        return any(t in (sub, sub + "[]") for t in tables)

    for where, keys in out["allowed"].items():
        for k in keys:
            if not is_table(where, k) and all(x["key"] != k for x in tables[where]):
                tables[where].append({"helper": None, "where": where, "key": k,
                                      "optional": False, "default": None,
                                      "default_kind": "none", "range": "", "type": ""})
        rank = {k: i for i, k in enumerate(keys)}
        tables[where].sort(key=lambda r: rank.get(r["key"], len(rank)))
    order = [""] + [t for t in tables if t]

    lines = [f"## {title}", ""]
    if kind:
        lines += [f'A scene file with `kind = "{kind}"` is checked by '
                  f"`{modname}.{funcname}`.", ""]
    else:
        lines += [f"A scene file without `kind` is checked by `{modname}.{funcname}`.", ""]
    for where in order:
        rows = tables.get(where, [])
        if not rows:
            continue
        seg_name = where.replace("[]", "")
        segment = own_docs.get(seg_name, docs.get(seg_name, "") if seg_name == "solver" else "")
        siblings = {r["key"] for r in rows}
        lines += [f"### `{_table_header(where)}`" if where else "### Top level", "",
                  "| key (`--set`) | type | unit | default | allowed | notes |",
                  "|---|---|---|---|---|---|"]
        for r in rows:
            key = r["key"]
            unit, note = _doc_entry(segment or "", key, siblings)
            if not unit and key.endswith("_deg"):
                unit = "deg"
            value, found = _lookup(resolved, where, key)
            dotted = _dotted(where, key)
            allowed = r["range"]
            if key == "kind" and not where and kind:
                allowed = f'"{kind}"'
            if dotted in required or (r["helper"] and r["default_kind"] == "none"
                                       and not r["optional"]):
                default = "required"
            elif r["optional"]:
                default = "optional (none)"
            elif r["default_kind"] == "literal":
                default = _fmt(r["default"])
            elif r["default_kind"] in ("param", "local") and found:
                default = _fmt(value) + (f" (`{r['default']}`)" if r["default_kind"] == "local"
                                         else "")
            elif r["default_kind"] == "expr":
                default = f"`{r['default']}`"
            elif r["helper"] is None and key in out["gets"]:
                default = out["gets"][key]
            elif r["helper"] is None and found and isinstance(value, str) and value:
                default = _fmt(value)
            else:
                default = "–"
            typ = r["type"]
            if not typ and found:
                typ = ("string" if isinstance(value, str) else
                       "list" if isinstance(value, list) else "")
            if not typ and key in ("name", "description", "notes"):
                typ = "string"
            note = _clean_note(note, allowed)
            lines.append(f"| `{_cell(dotted)}` | {typ or '–'} | {_cell(unit) or '–'} | "
                         f"{_cell(default)} | {_cell(allowed) or '–'} | {_cell(note)} |")
        lines.append("")

    rules = [r for r in out["rules"]]
    geo = _geometry_rules(mod.__doc__ or "")
    if rules or geo:
        lines += ["### Rules across keys", ""]
        if geo:
            lines += [geo, ""]
        lines += ["The validator rejects a scene with these messages (`…` stands for the "
                  "values of the scene):", ""]
        lines += [f"* {_cell(r)}" for r in rules]
        lines.append("")

    # shipped scenes of this kind, what they set differently from the defaults
    defaults = _flatten({k: v for k, v in resolved.items() if k not in ("name", "description",
                                                                        "source")})
    shipped = []
    for name in sorted(shipped_scenes()):
        try:
            sc = load_scene(name)
        except Exception as exc:  # noqa: BLE001 - a broken shipped scene is a build warning
            log.warning("scene reference: shipped scene %s does not load: %s", name, exc)
            continue
        if sc.get("kind") != kind:
            continue
        flat = _flatten({k: v for k, v in sc.items()
                         if k not in ("name", "description", "source", "kind")})
        diff = [f"`{k} = {_fmt(v)}`" for k, v in flat.items()
                if k not in defaults or defaults[k] != v]
        shipped.append(f"| `{name}` | {_cell(sc['description'])} | "
                       f"{', '.join(diff) if diff else 'all defaults'} |")
    if shipped:
        lines += ["### Shipped scenes of this kind", "",
                  "What each shipped scene sets differently from the defaults above "
                  "(read by loading it):", "",
                  "| scene | description | values other than the defaults |", "|---|---|---|"]
        lines += shipped + [""]
    return "\n".join(lines)


def scene_reference() -> str:
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    return "\n".join(_kind_section(*k) for k in KINDS)


def on_page_markdown(markdown, page, config, files, **kwargs):
    if page.file.src_uri == "scene_reference.md" and MARKER in markdown:
        return markdown.replace(MARKER, scene_reference())
    return markdown


if __name__ == "__main__":       # preview: python docs/hooks/scene_reference.py
    print(scene_reference())
