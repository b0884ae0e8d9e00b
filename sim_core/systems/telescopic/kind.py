"""The telescopic system kind (``kind = "telescopic"``): flexible booms with contact, their rigid
limit (``effects.flexible = false``) and the modal reduced-order model
(``model.reduction = "modal"``)."""

from __future__ import annotations

from pathlib import Path

from sim_core import run_control
from sim_core.figures import plot_result
from sim_core.result import Result
from sim_core.systems.telescopic.build import build_telescopic, simulate_telescopic
from sim_core.systems.telescopic.build import stage_schedules
from sim_core.systems.telescopic.modal import simulate_modal
from sim_core.systems.telescopic.plots import plot_telescopic
from sim_core.systems.telescopic.rigid import RigidTelescopic
from sim_core.systems.telescopic.schema import params_from_scene
from sim_core.systems.telescopic.schema import validate_telescopic as validate

__all__ = ["validate", "build", "run", "describe", "figures", "properties", "stepper"]


def build(scene: dict):
    """The model of a validated telescopic scene: a TelescopicSystem (flexible booms) or a
    RigidTelescopic (the kinematic limit)."""
    params = params_from_scene(scene)
    return build_telescopic(params) if params.flexible else RigidTelescopic(params)


@run_control.budgeted
def run(scene: dict, progress=None, checkpoint=None) -> Result:
    """The scene's fidelity: the modal ROM, the rigid limit or the flexible booms.
    ``checkpoint`` (:class:`sim_core.checkpoint.Checkpointer` or None): the flexible booms'
    integration writes to it and resumes from it; the modal ROM has no checkpoints (it runs in
    a fraction of a second)."""
    sol = scene["solver"]
    params = params_from_scene(scene)
    if scene.get("model", {}).get("reduction") == "modal":
        if checkpoint is not None:
            checkpoint.unsupported("model.reduction = 'modal' (the modal reduced-order model)")
        return simulate_modal(params, scene["model"]["n_modes"], sol["t_end"], sol["n_output"],
                              scene=scene, max_wall_s=sol.get("max_wall_s"))
    return simulate_telescopic(params, progress=progress, solver=sol, scene=scene,
                               checkpoint=checkpoint)


def describe(scene: dict) -> list[str]:
    """What the scene assembles (the rigid limit: its coordinates and ropes)."""
    system = build(scene)
    if isinstance(system, RigidTelescopic):
        return ["assembled contributions: rigid booms (kinematic limit)"
                + (", elastic ropes" if system.elastic else
                   ", inextensible rope" if system.ropes else ""),
                f"coordinates: {system.n_dof}, DOF: {system.n_dof}"]
    lines = []
    props = properties(scene)
    for k, b in enumerate(props["booms"]):
        lines.append(f"boom {k + 1}: length {b['length']:g} m, {b['shape']} section, A "
                     f"{b['A']:.4g} m^2, I_t {b['I_t']:.4g} m^4, I_b {b['I_b']:.4g} m^4, J "
                     f"{b['J']:.4g} m^4, {b['mass_per_length']:.4g} kg/m, z_c {b['z_c']:.4g} m "
                     f"({b['constants_from']})")
    lines.append(f"luffing cylinder: {props['luffing_cylinder_length']:.4g} m, lever "
                 f"{props['luffing_lever']:.4g} m about the pivot D1 at "
                 f"{props['luffing_angle_deg']:g} deg")
    for table, a in props["actuators"].items():
        lines.append(f"{a['actuator']} ({table}, {a['profile']}): largest rate "
                     f"{a['max_rate']:.4g} {a['unit']}/s at t = {a['t_max_rate']:.4g} s, "
                     f"largest acceleration {a['max_accel']:.4g} {a['unit']}/s^2 at t = "
                     f"{a['t_max_accel']:.4g} s")
    if system.contact is not None and not system.params.friction:
        lines.append("note: slider-spring distribution evaluated for the outputs only (friction off)")
    return lines + system.model.describe()


def build_schedule(p):
    """The telescopic stages' schedule (the first stage's; every stage of the synchronized
    drive has it)."""
    return stage_schedules(p)[0]


def properties(scene: dict) -> dict:
    """What ``boom-sim describe --json`` prints of a telescopic scene, SI units: every boom's
    length (m), A (m^2), I_t, I_b, J (m^4), mass_per_length (kg/m), mass centre (y_c, z_c) (m),
    E, G (Pa), rho (kg/m^3) and where the constants come from; the luffing cylinder's length and
    its lever about the pivot D1 at the scene's luffing angle (``luffing_lever``, m); the
    sliders of every overlap; every moving actuator's profile with its largest rate and
    acceleration and their times (in the scene's units: m or deg)."""
    import math

    from sim_core.systems.telescopic.luffing import luffing_geometry
    from sim_core.systems.telescopic.params import boom_section
    p = params_from_scene(scene)
    booms = []
    for k in range(p.n_booms):
        if p.booms is not None:
            b = p.booms[k]
            row = {"length": b.length, "A": b.A, "I_t": b.I_t, "I_b": b.I_b, "J": b.J,
                   "mass_per_length": b.mass_per_length, "y_c": b.y_c, "z_c": b.z_c,
                   "E": b.E, "G": b.G, "rho": b.rho,
                   "shape": scene["boom"][k]["section"]["shape"],
                   "constants_from": scene["boom"][k]["section"]["method"]}
        else:
            # the shorthand: the U family's constants (Table 2 for the paper's booms), the
            # torsion constant of the paper's convention GJ = G (I_t + I_b), G = E / 2.6
            bs = boom_section(k, p)
            G = p.E / 2.6
            row = {"length": p.lengths[k], "A": bs.EA / p.E, "I_t": bs.EI_t / p.E,
                   "I_b": bs.EI_b / p.E, "J": bs.GJ / G, "mass_per_length": bs.rhoA,
                   "y_c": 0.0, "z_c": float(p.z_c[k]), "E": p.E, "G": G, "rho": p.rho,
                   "shape": "u", "constants_from": "paper Table 2 (U family)"}
        booms.append({k2: (float(v) if isinstance(v, (int, float)) else v)
                      for k2, v in row.items()})
    geo = luffing_geometry(math.radians(p.luffing_angle_deg), *p.luffing.points())
    from sim_core.systems.telescopic import actuators as act
    moving = {}
    t_end = scene["solver"]["t_end"]
    for table, prof in (("drive", p.drive_profile or build_schedule(p)),
                        ("luffing_drive", p.luffing_profile), ("slew_drive", p.slew_profile),
                        ("hoist_drive", p.hoist_profile)):
        if prof is None:
            continue
        limits = act.check_limits(table, scene.get(table, {}), prof, t_end)
        moving[table] = {"actuator": act.ACTUATORS[table][0],
                         "profile": scene.get(table, {}).get("profile", "cubic"), **limits}
    return {"actuators": moving,
            "booms": booms,
            "luffing_angle_deg": p.luffing_angle_deg,
            "luffing_lever": geo.lever,
            "luffing_cylinder_length": geo.cylinder_length,
            "luffing": {"pivot": list(p.luffing.pivot), "pivot_on_boom": list(p.luffing.pivot_on_boom),
                        "base": list(p.luffing.base), "head_on_boom": list(p.luffing.head_on_boom)},
            "overlaps": [{"slider_width": o.slider_width,
                          "inner_slider_distance": o.inner_distance,
                          "outer_slider_distance": o.outer_distance,
                          "radial_gap": o.radial_gap,
                          "bears_on": None if o.bears_on is None else list(o.bears_on)}
                         for o in p.overlaps]}


def figures(result: Result, out: Path) -> list[Path]:
    """Tip motion, the rigid-limit comparison, contact-point forces and slider loads."""
    return plot_result(result, out) + plot_telescopic(result, out)


def stepper(scene: dict):
    """The scene's model advanced step by step (sim_core.Simulation): the full model, or the
    modal ROM where model.reduction = "modal"."""
    from sim_core.systems.telescopic.stepping import stepper_for
    return stepper_for(scene)
