"""The folding long-boom manipulator kind (``kind = "folding"``, the SIMULTECH 2020 paper)."""

from __future__ import annotations

from pathlib import Path

from sim_core import run_control
from sim_core.figures import plot_result
from sim_core.result import Result
from sim_core.systems.folding.build import build_folding, simulate_folding
from sim_core.systems.folding.plots import plot_folding
from sim_core.systems.folding.schema import params_from_scene
from sim_core.systems.folding.schema import validate_folding as validate

__all__ = ["validate", "build", "run", "describe", "figures"]


def build(scene: dict):
    """The FoldingSystem of a validated folding scene."""
    return build_folding(params_from_scene(scene))


@run_control.budgeted
def run(scene: dict, progress=None, checkpoint=None) -> Result:
    """The manipulator from its static equilibrium through the drive stages; ``checkpoint``
    (:class:`sim_core.checkpoint.Checkpointer` or None): the integration writes to it and
    resumes from it."""
    return simulate_folding(params_from_scene(scene), progress=progress, solver=scene["solver"],
                            scene=scene, checkpoint=checkpoint)


def describe(scene: dict) -> list[str]:
    """What the scene assembles: effects, rigid bodies, joints and coordinates."""
    return build(scene).model.describe()


def figures(result: Result, out: Path) -> list[Path]:
    """Tip motion, cylinder forces and lengths, slew and boom angles."""
    return plot_result(result, out) + plot_folding(result, out)
