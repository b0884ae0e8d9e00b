"""Inputs of the telescopic boom system (Zhao-Qi-Wang 2024, Section 9; SCENARIOS A1-A6) and
the cross-section of each boom: Table 2 for the paper's three booms, and for cranes of four to
six sections the same U-section family continued outwards (:func:`crane_sections`).  SI units."""

from __future__ import annotations

from dataclasses import dataclass

from sim_core.physics.beam.moving_node_beam import BeamSection
from sim_core.physics.sections import USection, section_properties

# SCENARIOS A1 Table 2 (EI_t = EI_b, GJ, m'), EA = E m'/rho (proposed default)
TABLE2 = ((7.22e8, 5.55e8, 318.86), (6.30e8, 4.85e8, 304.07), (5.46e8, 4.20e8, 289.27))
Z_C_TABLE2 = (0.045, 0.044, 0.043)          # m, mass centre along e_b (Table 2)
MAX_BOOMS = 6                               # sections of the longest crane the scenes accept
MECHANISMS = ("synchronized", "sequential")  # telescoping drives (docs/model.md, "N-boom drives")

# Table 1 family: top arcs centred at y_a = z_a = 0.300 m, wall t = 15 mm, top-arc radius r of
# boom k (from the outermost) 20 mm above boom k+1's, so adjacent walls keep a 5 mm radial gap
_Y_A, _WALL, _R_STEP, _R_INNERMOST = 0.300, 0.015, 0.020, 0.050


def family_radius(k: int, n_booms: int) -> float:
    """Top-arc radius r (m, Table 1 contour) of boom k (0-based from the outermost) of an
    n_booms crane: the innermost is Table 1's boom 3 (50 mm), each outer one 20 mm larger."""
    return _R_INNERMOST + _R_STEP * (n_booms - 1 - k)


def family_section(r: float, E: float = 2.1e11, nu: float = 0.3, rho: float = 7850.0):
    """((EI, GJ, m'), z_c) of the family's section with top-arc radius r (m): the Table 1 contour
    (y_a = z_a = 0.3 m, R = y_a + r) as the wall mid-line of thickness 15 mm; EI_t = EI_b = the
    centroidal E I_t of that wall, GJ = G (I_t + I_b) with I_b = I_t, i.e. EI / (1 + nu)."""
    s = USection(_Y_A, _Y_A, r + _WALL / 2, _Y_A + r + _WALL / 2, _WALL)
    sp = section_properties(s, E, nu, rho)
    return (sp.EI_t, sp.EI_t / (1.0 + nu), sp.mass_per_length), sp.z_c


def crane_sections(n_booms: int):
    """Section rows ((EI, GJ, m'), z_c) of booms 1..n_booms, outermost first, at the reference
    E = 2.1e11 Pa, nu = 0.3, rho = 7850 kg/m^3 (boom_section scales the stiffnesses with E).

    The paper's three booms are the innermost three of every crane (Table 1 radii r = 90, 70,
    50 mm, Table 2 constants): a crane with more sections adds larger sections outside them, r
    = 110, 130, 150 mm (:func:`family_radius`), the same wall and the same 20 mm step that keeps
    Table 1's 5 mm gap (a smaller innermost section would need r < t at five sections).  Their
    constants (:func:`family_section`) follow the conventions that reproduce Table 2
    (sim_core.physics.sections, module docstring): the Table 1 contour as the wall mid-line (m'
    exact for booms 1-3), EI_t = EI_b = the centroidal E I_t of that wall (Table 2 within
    -1.0..+1.8 %), and GJ = G (I_t + I_b) = EI / (1 + nu) (Table 2's GJ = EI / 1.3).
    """
    if not 2 <= n_booms <= MAX_BOOMS:
        raise ValueError(f"n_booms = {n_booms}: allowed 2..{MAX_BOOMS}")
    if n_booms <= 3:
        return TABLE2[:n_booms], Z_C_TABLE2[:n_booms]
    added = [family_section(family_radius(k, n_booms)) for k in range(n_booms - 3)]
    return (tuple(row for row, _ in added) + TABLE2,
            tuple(zc for _, zc in added) + Z_C_TABLE2)


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
    mechanism: str = "synchronized"         # telescoping drive of MECHANISMS (N >= 3)
    flexible: bool = True                   # flexible booms; off = rigid kinematic limit
    mass_centre_offset: bool = False        # Table 2 z_c as rigid offset (SCENARIOS A1)
    z_c: tuple | None = None                # m, mass centre along e_b (None: crane_sections)
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
    sections: tuple | None = None           # (EI, GJ, m') per boom (None: crane_sections)

    def __post_init__(self):
        if self.mechanism not in MECHANISMS:
            raise ValueError(f"mechanism = {self.mechanism!r}: allowed {MECHANISMS}")
        rows, zc = crane_sections(self.n_booms)
        if self.sections is None:
            self.sections = rows
        if self.z_c is None:
            self.z_c = zc

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
