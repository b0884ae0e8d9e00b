"""Scene -> Model: only the effects a scene switches on are built into the model."""

from __future__ import annotations

import numpy as np

from sim_core.model.boundary import LinearConstraint, boundary_condition, no_torsion, reference_basis
from sim_core.model.model import Model
from sim_core.physics.beam.moving_node_beam import Beam, BeamSection
from sim_core.physics.drive_profiles import sleeve_motion
from sim_core.physics.effects import Effect, Elasticity, Gravity, Inertia, PointLoad, StressFilter


def beam_section(sec: dict) -> BeamSection:
    """BeamSection from scene section data (E, G, rho, A, I_t, I_b, J, I_p)."""
    rho = sec["rho"]
    rot = sec.get("rotary_bending", True)
    return BeamSection(EA=sec["E"] * sec["A"], GJ=sec["G"] * sec["J"], EI_t=sec["E"] * sec["I_t"],
                       EI_b=sec["E"] * sec["I_b"], rhoA=rho * sec["A"], J_s=rho * sec["I_p"],
                       J_t=rho * sec["I_t"] if rot else 0.0, J_b=rho * sec["I_b"] if rot else 0.0)


def build_model(scene: dict) -> tuple[Model, np.ndarray, np.ndarray]:
    """Model and its initial full state (Q0, Q0_dot) from a validated scene."""
    beams = [Beam(b["name"], b["length"], beam_section(b["section"]), tuple(b["breakpoints"]),
                  n_nodes=b["n_nodes"], n_gauss=b["n_gauss"],
                  reference_basis=reference_basis(b["direction"]))
             for b in scene["beams"]]
    offsets = np.cumsum([0] + [b.n_coords for b in beams])[:-1]
    eff = scene["effects"]
    effects: list[Effect] = [Inertia(), Elasticity()]
    if eff["filtering"]:
        effects.append(StressFilter(scene["filtering"]["h"]))
    if eff["gravity"]:
        effects.append(Gravity(np.array(scene["gravity"]["g"])))

    Q0 = np.concatenate([b.straight_coordinates(sb["origin"], sb["direction"])
                         for b, sb in zip(beams, scene["beams"])])
    Qd0 = np.zeros_like(Q0)
    cons: list[LinearConstraint] = []
    constrained_ends = set()
    for bc in scene["boundary"]:
        ib, end = bc["beam"], bc["end"]
        b, sb = beams[ib], scene["beams"][ib]
        d = np.asarray(sb["direction"], float)
        d /= np.linalg.norm(d)
        s_end = b.breakpoints[0] if end == "left" else b.breakpoints[-1]
        pos = bc["position"] if bc["position"] is not None else np.asarray(sb["origin"]) + s_end * d
        direction = bc["direction"] if bc["direction"] is not None else d
        s_fun = None
        if bc["kind"] == "sleeve":
            motion = sleeve_motion(bc, s_end)
            s_fun = (lambda t, m=motion: m(t)[0], lambda t, m=motion: m(t)[1],
                     lambda t, m=motion: m(t)[2])
            Qd0[offsets[ib]:offsets[ib] + b.n_coords] += _axial_flow_velocity(b, end,
                                                                             motion(0.0)[1], d)
        cons.append(boundary_condition(offsets, beams, ib, end, bc["kind"], pos, direction, s_fun,
                                       fix_torsion=eff["torsion"]))
        constrained_ends.add((ib, end))
    # every beam end that is not a sleeve is a material point (s = 0 or L), Eq. 50
    for ib, b in enumerate(beams):
        for end in ("left", "right"):
            if (ib, end) not in constrained_ends:
                cons.append(boundary_condition(offsets, beams, ib, end, "free"))
    if not eff["torsion"]:
        cons.append(no_torsion(offsets, beams))

    loads = []
    for pl in scene["point_loads"]:
        f = np.asarray(pl["force"], float)
        t0 = pl["start"]
        loads.append(PointLoad(pl["beam"], lambda t, s=pl["s"], v=pl["speed"]: s + v * t,
                               lambda t, f=f, t0=t0: f if t >= t0 else 0.0 * f))
    model = Model(beams, effects, loads, cons)
    model.scene = scene
    return model, Q0, Qd0


def _axial_flow_velocity(b: Beam, end: str, v: float, d: np.ndarray) -> np.ndarray:
    """Initial coordinate rates of a straight beam whose material slides rigidly through a
    sleeve at the ``end`` node with ds/dt = v there (other breakpoints are material points):
    material velocity -v d everywhere, node rates r_dot_k = -v d + d s_dot_k (Eq. 1)."""
    qd = np.zeros(b.n_coords)
    nb = len(b.elements)
    s_rate = np.zeros(nb + 1)
    s_rate[0 if end == "left" else nb] = v
    for e, (el, imap) in enumerate(zip(b.elements, b.index_map)):
        for k in range(el.n):
            sk = s_rate[e] + (s_rate[e + 1] - s_rate[e]) * k / (el.n - 1)
            qd[imap[el.index("r", k, 0):el.index("r", k, 0) + 3]] = -v * d + d * sk
        qd[imap[el.i_s1]], qd[imap[el.i_sn]] = s_rate[e], s_rate[e + 1]
    return qd
