"""The telescopic system kind (``kind = "telescopic"``): flexible booms with contact, their rigid
limit (``effects.flexible = false``) and the modal reduced-order model
(``model.reduction = "modal"``)."""

from __future__ import annotations

from pathlib import Path

from sim_core.figures import plot_result
from sim_core.result import Result
from sim_core.systems.telescopic.build import build_telescopic, simulate_telescopic
from sim_core.systems.telescopic.modal import simulate_modal
from sim_core.systems.telescopic.plots import plot_telescopic
from sim_core.systems.telescopic.rigid import RigidTelescopic
from sim_core.systems.telescopic.schema import params_from_scene
from sim_core.systems.telescopic.schema import validate_telescopic as validate

__all__ = ["validate", "build", "run", "describe", "figures"]


def build(scene: dict):
    """The model of a validated telescopic scene: a TelescopicSystem (flexible booms) or a
    RigidTelescopic (the kinematic limit)."""
    params = params_from_scene(scene)
    return build_telescopic(params) if params.flexible else RigidTelescopic(params)


def run(scene: dict, progress=None) -> Result:
    """The scene's fidelity: the modal ROM, the rigid limit or the flexible booms."""
    sol = scene["solver"]
    params = params_from_scene(scene)
    if scene.get("model", {}).get("reduction") == "modal":
        return simulate_modal(params, scene["model"]["n_modes"], sol["t_end"], sol["n_output"],
                              scene=scene)
    return simulate_telescopic(params, progress=progress, solver=sol, scene=scene)


def describe(scene: dict) -> list[str]:
    """What the scene assembles (the rigid limit: its coordinates and ropes)."""
    system = build(scene)
    if isinstance(system, RigidTelescopic):
        return ["assembled contributions: rigid booms (kinematic limit)"
                + (", elastic ropes" if system.elastic else
                   ", inextensible rope" if system.ropes else ""),
                f"coordinates: {system.n_dof}, DOF: {system.n_dof}"]
    lines = []
    if system.contact is not None and not system.params.friction:
        lines.append("note: slider-spring distribution evaluated for the outputs only (friction off)")
    return lines + system.model.describe()


def figures(result: Result, out: Path) -> list[Path]:
    """Tip motion, the rigid-limit comparison, contact-point forces and slider loads."""
    return plot_result(result, out) + plot_telescopic(result, out)
