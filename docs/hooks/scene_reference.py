"""The scene reference, generated from the declared scene fields into ``docs/scene_reference.md``.

``docs/scene_reference.md`` holds its introduction, the marker line ``<!-- scene-reference -->``
and below it one generated section per scene kind, committed so that the file reads complete
in a checkout.  ``python docs/hooks/scene_reference.py --write`` regenerates the part below the
marker (written atomically); as an MkDocs hook, ``on_page_markdown`` warns (so a strict build
fails) when the committed part differs from the generated one, and the page shows the
generated part either way.  Everything comes from the declarations the validators check with (:mod:`sim_core.scene.fields`: each kind's ``SCHEMA``, the effect
plug-ins' tables), nothing from the validators' source:

* one table per scene table, with every key's type, unit, default, allowed range or values and
  note, in the declared order;
* the rules across keys (``Schema.rules``);
* what every shipped scene (``sim_core/scenes/*.toml``) sets differently from the declared
  defaults, read from its file (and the scene loaded once, so a scene the validator refuses
  stops a strict build).

A key added to a declaration appears on the next build; a key the validator reads is declared
(the validator reads it through its declaration).
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path

log = logging.getLogger("mkdocs.hooks.scene_reference")

MARKER = "<!-- scene-reference -->"
ROOT = Path(__file__).resolve().parents[2]


def _schemas():
    from sim_core.systems.beam.schema import SCHEMA as beam
    from sim_core.systems.folding.schema import SCHEMA as folding
    from sim_core.systems.telescopic.schema import SCHEMA as telescopic
    return [beam, telescopic, folding]


def _cell(text) -> str:
    return str(text).replace("|", "\\|")


def _header(path: str) -> str:
    if not path:
        return "Top level"
    name = path.replace("[]", "")
    return f"`[[{name}]]`" if path.endswith("[]") else f"`[{name}]`"


def _dotted(path: str, key: str) -> str:
    base = path.replace("[]", ".0")
    return f"{base}.{key}" if base else key


def _flatten(node, prefix="") -> dict[str, object]:
    """Dotted keys of a raw scene table: arrays of tables by index, other values as leaves."""
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


def _declared_defaults(schema) -> dict[str, object]:
    """Dotted key (items of arrays of tables as ``*``) -> declared literal default."""
    from sim_core.scene.fields import COMPUTED, OPTIONAL, REQUIRED
    out = {}
    for table in schema.tables:
        base = table.path.replace("[]", ".*")
        for f in table.fields:
            if f.default not in (REQUIRED, OPTIONAL, COMPUTED):
                out[f"{base}.{f.key}" if base else f.key] = f.default
    return out


def _generic(key: str) -> str:
    parts = key.split(".")
    return ".".join("*" if p.isdigit() else p for p in parts)


def _table_lines(table) -> list[str]:
    lines = [f"### {_header(table.path)}", ""]
    text = table.note[0].upper() + table.note[1:] + "." if table.note else ""
    if table.items:
        lo, hi = table.items
        text += f" {lo} to {hi} tables." if text else f"{lo} to {hi} tables."
    if text:
        lines += [text, ""]
    lines += ["| key (`--set`) | type | unit | default | allowed | notes |",
              "|---|---|---|---|---|---|"]
    for f in table.fields:
        note = f.note
        if f.applies:
            note = f"with {f.applies}" + (f": {note}" if note else "")
        lines.append(f"| `{_cell(_dotted(table.path, f.key))}` | {f.type_text()} | "
                     f"{_cell(f.unit) or '–'} | {_cell(f.default_shown())} | "
                     f"{_cell(f.range_text())} | {_cell(note)} |")
    return lines + [""]


def _shipped_lines(schema) -> list[str]:
    from sim_core import load_scene
    from sim_core.scene.fields import toml_text
    from sim_core.scene.io import read_scene, shipped_scenes
    defaults = _declared_defaults(schema)
    rows = []
    for name in sorted(shipped_scenes()):
        raw, _ = read_scene(name)
        if raw.get("kind") != schema.kind:
            continue
        try:
            load_scene(name)
        except Exception as exc:  # noqa: BLE001 - a broken shipped scene is a build warning
            log.warning("scene reference: shipped scene %s does not load: %s", name, exc)
            continue
        flat = _flatten({k: v for k, v in raw.items()
                         if k not in ("name", "description", "notes", "kind")})
        diff = [f"`{k} = {_cell(toml_text(v))}`" for k, v in flat.items()
                if _generic(k) not in defaults or defaults[_generic(k)] != v]
        rows.append(f"| `{name}` | {_cell(raw.get('description', ''))} | "
                    f"{', '.join(diff) if diff else 'all defaults'} |")
    if not rows:
        return []
    return ["### Shipped scenes of this kind", "",
            "What each shipped scene's file sets differently from the declared defaults:", "",
            "| scene | description | values other than the defaults |", "|---|---|---|",
            *rows, ""]


def kind_section(schema) -> str:
    lines = [f"## {schema.title}", ""]
    which = (f'with `kind = "{schema.kind}"`' if schema.kind else "without `kind`")
    lines += [f"A scene file {which} is checked by `{schema.validator}`.", ""]
    for table in schema.tables:
        lines += _table_lines(table)
    if schema.rules:
        lines += ["### Rules across keys", ""]
        lines += [f"* {_cell(r)}" for r in schema.rules]
        lines.append("")
    lines += _shipped_lines(schema)
    return "\n".join(lines)


def scene_reference() -> str:
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    return "\n".join(kind_section(s) for s in _schemas())


REFERENCE = ROOT / "docs" / "scene_reference.md"
COMMAND = "python docs/hooks/scene_reference.py --write"


def split(text: str) -> tuple[str, str]:
    """(the page up to and including the marker line, the generated part below it)."""
    at = text.find(MARKER)
    if at < 0:
        raise ValueError(f"{REFERENCE.name} has no line {MARKER}")
    end = at + len(MARKER)
    return text[:end] + "\n", text[end:].lstrip("\n")


def generated_page(text: str) -> str:
    """The page ``text`` with its part below the marker generated anew."""
    head, _ = split(text)
    return f"{head}\n{scene_reference().rstrip()}\n"


def write(path: Path = REFERENCE) -> bool:
    """Regenerate ``path`` below its marker; True where its content changed."""
    old = path.read_text(encoding="utf-8")
    new = generated_page(old)
    if new == old:
        return False
    from sim_core.result import atomic_path
    with atomic_path(path) as tmp:
        Path(tmp).write_text(new, encoding="utf-8")
    return True


def on_page_markdown(markdown, page, config, files, **kwargs):
    if page.file.src_uri != "scene_reference.md" or MARKER not in markdown:
        return markdown
    new = generated_page(markdown)
    if new != markdown:
        log.warning("docs/scene_reference.md differs from the declared scene fields: "
                    "regenerate it with `%s`", COMMAND)
    return new


if __name__ == "__main__":       # python docs/hooks/scene_reference.py [--write]
    if sys.argv[1:] == ["--write"]:
        print(f"{REFERENCE}: {'rewritten' if write() else 'up to date'}")
    elif sys.argv[1:]:
        sys.exit(f"usage: {COMMAND} (without --write: print the generated part)")
    else:
        print(scene_reference())
