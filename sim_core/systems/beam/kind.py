"""The beam system kind (scenes without a ``kind`` key): the five entries of the registry."""

from __future__ import annotations

from pathlib import Path

from sim_core.figures import plot_result
from sim_core.result import Result
from sim_core.systems.beam.build import build_model
from sim_core.systems.beam.run import run
from sim_core.systems.beam.schema import validate

__all__ = ["validate", "build", "run", "describe", "figures"]


def build(scene: dict):
    """The assembled :class:`sim_core.model.model.Model` of a validated beam scene."""
    return build_model(scene)[0]


def describe(scene: dict) -> list[str]:
    """What the scene assembles: its effects, contributions, coordinates and constraints."""
    return build(scene).describe()


def figures(result: Result, out: Path) -> list[Path]:
    """Tip motion and energies against time."""
    return plot_result(result, out)
