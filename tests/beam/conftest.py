"""Shared builders for single-beam tests (a slender steel-like beam, SI units)."""

import numpy as np

from sim_core.model.boundary import boundary_condition, reference_basis
from sim_core.model.model import Model
from sim_core.physics.beam.moving_node_beam import Beam, BeamSection
from sim_core.physics.effects import Elasticity, Gravity, Inertia

E, G_MOD, RHO = 2.1e11, 8.0e10, 7850.0
L = 10.0
A, I_T, I_B = 1e-2, 1e-5, 1.3e-5


def section(rotary_bending: bool = False) -> BeamSection:
    J = I_T + I_B
    return BeamSection(EA=E * A, GJ=G_MOD * J, EI_t=E * I_T, EI_b=E * I_B, rhoA=RHO * A,
                       J_s=RHO * J, J_t=RHO * I_T if rotary_bending else 0.0,
                       J_b=RHO * I_B if rotary_bending else 0.0)


def cantilever(n_nodes=9, breakpoints=(0.0, L), effects=None, loads=(), gravity=None):
    """Beam along X, clamped at s = 0, free at s = L."""
    b = Beam("b", L, section(), tuple(breakpoints), n_nodes=n_nodes,
             reference_basis=reference_basis([1, 0, 0]))
    eff = [Inertia(), Elasticity()] if effects is None else list(effects)
    if gravity is not None:
        eff.append(Gravity(np.asarray(gravity, float)))
    cons = [boundary_condition([0], [b], 0, "left", "clamped", [0, 0, 0], [1, 0, 0]),
            boundary_condition([0], [b], 0, "right", "free")]
    m = Model([b], eff, list(loads), cons)
    Q0 = b.straight_coordinates([0, 0, 0], [1, 0, 0])
    return m, Q0
