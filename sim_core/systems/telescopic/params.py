"""Inputs of the telescopic boom system (Zhao-Qi-Wang 2024, Section 9; SCENARIOS A1-A6) and
the cross-section of each boom from Table 2.  SI units."""

from __future__ import annotations

from dataclasses import dataclass, field

from sim_core.physics.beam.moving_node_beam import BeamSection

# SCENARIOS A1 Table 2 (EI_t = EI_b, GJ, m'), EA = E m'/rho (proposed default)
TABLE2 = ((7.22e8, 5.55e8, 318.86), (6.30e8, 4.85e8, 304.07), (5.46e8, 4.20e8, 289.27))


@dataclass
class TelescopicParams:
    """Inputs of the paper's telescopic scenes (SI units; defaults = paper Section 9.2)."""

    n_booms: int = 3
    boom_length: float = 10.0               # m
    luffing_angle_deg: float = 60.0         # deg
    stroke0: float = 2.0                    # m, initial piston-rod length L_s
    direction: int = +1                     # +1 extraction, -1 retraction
    L_h: float = 7.25                       # m, luffing point on boom 1
    E: float = 2.1e11                       # Pa (2.1e12: the nearly rigid case 9.1)
    rho: float = 7850.0                     # kg/m^3
    payload: float = 25000.0                # kg
    rope_EA: float = 1e8                    # N
    gravity: float = 9.81                   # m/s^2 along -Z
    n_nodes: int = 9                        # nodes per spline element (8 sub-elements)
    n_gauss: int = 5
    filter_h: float = 0.01                  # s, 0 = off
    v_max: float = 0.5                      # m/s, schedule of A4
    t_ramp: float = 4.0
    t_hold_end: float = 12.0
    baumgarte: tuple[float, float] = (20.0, 20.0)
    friction: bool = False                  # Coulomb friction on the contact coordinates (Sec. 8)
    contact_distribution: bool | None = None  # slider springs (Sec. 8); off = resultants only;
                                              # None = on for the paper's 3 booms
    torsion: bool = True                    # torsion angles as coordinates; off = held at zero
    rope_elasticity: bool = True            # elastic tension-only ropes; off = one inextensible rope
    flexible: bool = True                   # flexible booms; off = rigid kinematic limit
    mass_centre_offset: bool = False        # Table 2 z_c as rigid offset (SCENARIOS A1)
    z_c: tuple = (0.045, 0.044, 0.043)      # m, mass centre along e_b (Table 2)
    mu_static: float = 0.15
    mu_dynamic: float = 0.1
    v_eps: float = 0.01                     # m/s, switching speed
    moment_model: str = "rigid"             # slider moment: "rigid" (Sec. 6), "seat", "couple"
    seat_stiffness: float = 1e8             # N m/rad, rocking stiffness of a slider seat
    friction_load: str = "resultant"        # friction normal load: "resultant" or "springs"
    spring_k0: float = 1e9                  # N/m per radial spring (SCENARIOS A6)
    spring_eps: float = 1e-6                # m, smoothing interval
    slider_width: float = 0.3               # m, 2w: slider length along the boom (SCENARIOS A1)
    springs_per_quarter: int = 20           # radial springs per quarter arc and slider end (A6)
    radial_gap: float = 0.005               # m, gap between adjacent booms' walls (A1, Table 1)
    sections: tuple = field(default=TABLE2)

    def summary(self, name: str = "telescopic") -> dict:
        """What a Result records as its scene where it was run from parameters, not a scene."""
        return {"kind": "telescopic", "name": name,
                "params": {k: v for k, v in self.__dict__.items() if k != "sections"}}


def boom_section(k: int, p: TelescopicParams) -> BeamSection:
    EI, GJ, m = p.sections[min(k, len(p.sections) - 1)]
    scale = p.E / 2.1e11                   # case 9.1: stiffnesses x10, masses unchanged
    I = EI / 2.1e11                         # second moment from Table 2
    # mass-centre offset along e_b (Table 2), a rigid offset in inertia and gravity (A1)
    zc = p.z_c[min(k, len(p.z_c) - 1)] if p.mass_centre_offset else 0.0
    return BeamSection(EA=p.E * m / p.rho, GJ=GJ * scale, EI_t=EI * scale, EI_b=EI * scale,
                       rhoA=m, J_s=2 * p.rho * I, J_t=p.rho * I, J_b=p.rho * I, z_c=zc)
