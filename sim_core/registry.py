"""The system kinds a scene can name, each with its five entries: ``validate(raw, source)``
(the resolved scene), ``build(scene)`` (the assembled system), ``run(scene, progress)`` (a
:class:`sim_core.Result`), ``describe(scene)`` (lines for ``boom-sim describe``) and
``figures(result, out)`` (the PNG paths written).

A scene picks its kind with the top-level key ``kind``; a scene without one is a beam scene.
The command line, the sweeps and :func:`sim_core.simulate` ask this registry and never
dispatch on the kind themselves.
"""

from __future__ import annotations

from types import ModuleType

from sim_core.errors import SceneError
from sim_core.scene.fields import did_you_mean
from sim_core.systems.beam import kind as beam
from sim_core.systems.folding import kind as folding
from sim_core.systems.telescopic import kind as telescopic

KINDS: dict[str, ModuleType] = {"beam": beam, "telescopic": telescopic, "folding": folding}
DEFAULT_KIND = "beam"


def kind_name(scene: dict) -> str:
    """The kind a raw or resolved scene names (``DEFAULT_KIND`` where it names none).  A result
    loaded from a file records its scene; one run from parameters records ``kind`` too."""
    kind = scene.get("kind", DEFAULT_KIND) if isinstance(scene, dict) else DEFAULT_KIND
    if not isinstance(kind, str) or kind not in KINDS:
        raise SceneError(f"kind = {kind!r}: no such system kind (allowed: "
                         f"{', '.join(sorted(KINDS))}){did_you_mean(kind, KINDS)}")
    return kind


def system_kind(scene: dict) -> ModuleType:
    """The kind module of a scene: ``validate``, ``build``, ``run``, ``describe``, ``figures``."""
    return KINDS[kind_name(scene)]
