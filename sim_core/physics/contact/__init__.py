"""Contact between adjacent telescopic booms.

Discrete sliding-block (slider) contact model of Zhao, Qi, Wang (2024), Section 8.2-8.3:
compression-only radial springs on the rounding arcs at both slider ends, five algebraic
micro-motions per contact region, friction, and the axial auxiliary equation (Eq. 72) that
closes the contact multiplier.  See :mod:`sim_core.physics.contact.sliding_block_contact`.
"""

from sim_core.physics.contact.sliding_block_contact import (
    ContactSolution,
    ContactSolveError,
    FrictionLaw,
    SliderGeometry,
    SpringLaw,
    axial_residual,
    contact_residual,
    solve_micro_motion,
)

__all__ = [
    "ContactSolution",
    "ContactSolveError",
    "FrictionLaw",
    "SliderGeometry",
    "SpringLaw",
    "axial_residual",
    "contact_residual",
    "solve_micro_motion",
]
