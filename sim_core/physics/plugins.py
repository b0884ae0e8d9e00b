"""Effects as plug-ins: an effect beyond the built-in ones is one module in ``sim_core/physics``
that defines ``PLUGIN = EffectPlugin(...)``, plus its module name in :data:`EFFECT_PLUGINS`.

The registration carries everything a scene and a run need from the effect:

* ``name``: the switch ``effects.<name>`` (default false) and the scene table ``[<name>]``;
* ``fields``: the declared scene table ``[<name>]`` (:class:`sim_core.scene.fields.Table`:
  every key's type, unit, default, range and note), which the scene reference lists;
* ``validate(table, scene)``: the resolved table (SceneError naming the key and its range),
  read through ``fields``;
* ``build(table, system)``: the :class:`~sim_core.physics.effects.Effect` added to the model
  (``system``: the assembled system, whose model, beams and parameters it may read);
* ``power(effect, model, t, Q, Qd)``: the power (W) the effect feeds into the system, which
  the energy audit integrates as the effect's work (None: a conservative effect whose energy
  the model's energies already hold);
* ``figures(result, out)``: extra figures, or None.

An effect whose class offers no compiled kernel runs on the elements' numpy path; the model
says so once (:func:`sim_core.model.model.Model` warns and the result's stats name it).
``docs/architecture.md`` ("Adding an effect") walks through the wind load as the example.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any, Callable

__all__ = ["EffectPlugin", "EFFECT_PLUGINS", "effect_plugins"]

#: the modules of the registered effect plug-ins (one line each)
EFFECT_PLUGINS = (
    "sim_core.physics.wind",
)


@dataclass(frozen=True)
class EffectPlugin:
    """The registration of an effect plug-in (see the module docstring)."""

    name: str
    validate: Callable
    build: Callable
    power: Callable | None = None
    figures: Callable | None = None
    description: str = ""
    fields: Any = None


def effect_plugins() -> dict[str, EffectPlugin]:
    """The registered plug-ins by name (their modules imported on first use)."""
    out = {}
    for mod in EFFECT_PLUGINS:
        plugin = importlib.import_module(mod).PLUGIN
        out[plugin.name] = plugin
    return out
