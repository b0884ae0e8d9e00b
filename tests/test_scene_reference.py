"""The committed scene reference (``docs/scene_reference.md``) equals the one generated from the
declared scene fields, so a checkout reads the same tables the validators enforce.

Regenerate with ``python docs/hooks/scene_reference.py --write``.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _hook():
    spec = importlib.util.spec_from_file_location(
        "scene_reference_hook", ROOT / "docs" / "hooks" / "scene_reference.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_committed_scene_reference_equals_the_generated_one():
    hook = _hook()
    text = hook.REFERENCE.read_text(encoding="utf-8")
    assert text == hook.generated_page(text), (
        "docs/scene_reference.md is stale: run `python docs/hooks/scene_reference.py --write`")


def test_every_declared_key_is_in_the_committed_reference():
    from sim_core.systems.telescopic.schema import SCHEMA
    hook = _hook()
    text = (ROOT / "docs" / "scene_reference.md").read_text(encoding="utf-8")
    for table in SCHEMA.tables:
        for field in table.fields:
            assert f"`{hook._dotted(table.path, field.key)}`" in text, field.key


def test_write_repairs_a_stale_reference(tmp_path):
    hook = _hook()
    good = hook.REFERENCE.read_text(encoding="utf-8")
    stale = tmp_path / "scene_reference.md"
    stale.write_text(good.replace("| `solver.t_end` |", "| `solver.t_stop` |"), encoding="utf-8")
    assert stale.read_text(encoding="utf-8") != good
    assert hook.write(stale) is True
    assert stale.read_text(encoding="utf-8") == good
    assert hook.write(stale) is False
