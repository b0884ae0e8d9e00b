"""Inputs of the telescopic boom system (Zhao-Qi-Wang 2024, Section 9; docs/model.md#inputs-and-decisions) and
the cross-section of each boom: Table 2 for the paper's three booms, and for cranes of four to
six sections the same U-section family continued outwards (:func:`crane_sections`).  SI units."""

from __future__ import annotations

from dataclasses import dataclass, field

from sim_core.physics.beam.moving_node_beam import BeamSection
from sim_core.physics.sections import USection, section_properties

# docs/model.md#input-sections: Table 2 (EI_t = EI_b, GJ, m'), EA = E m'/rho (proposed default)
TABLE2 = ((7.22e8, 5.55e8, 318.86), (6.30e8, 4.85e8, 304.07), (5.46e8, 4.20e8, 289.27))
Z_C_TABLE2 = (0.045, 0.044, 0.043)          # m, mass centre along e_b (Table 2)
MAX_BOOMS = 6                               # sections of the longest crane the scenes accept
MECHANISMS = ("synchronized", "sequential", "independent",
              "single_cylinder")          # telescoping drives (docs/model.md, "N-boom drives")
#: the drives whose every stage is a prescribed length of its own (no rope units):
#: sim_core.systems.telescopic.telescoping
STAGEWISE = ("sequential", "independent", "single_cylinder")

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


@dataclass(frozen=True)
class BoomSpec:
    """One boom of a crane described boom by boom (scene ``[[boom]]``), SI units.

    length m; E, G Pa; rho kg/m^3; A m^2; I_t, I_b m^4 (centroidal, bending in and across the
    luffing plane); J m^4 (torsion constant: the St. Venant constant of the section, or a given
    value); mass_per_length kg/m (rho A, or a given value that may include fittings); y_c, z_c m
    (mass centre in the section frame); section: the
    :class:`~sim_core.physics.cross_sections.CrossSection` (None for given properties)."""

    length: float
    E: float
    G: float
    rho: float
    A: float
    I_t: float
    I_b: float
    J: float
    mass_per_length: float
    y_c: float = 0.0
    z_c: float = 0.0
    section: object = None


@dataclass(frozen=True)
class OverlapSpec:
    """The sliders of one overlap (booms k and k+1, 0-based k), SI units.

    slider_width m (2w, both sliders of the overlap); inner_distance m: the inner-region slider
    (on boom k+1, bearing inside boom k) sits this far from boom k+1's left end; outer_distance
    m: the outer-region slider (on boom k, bearing on boom k+1) sits this far from boom k's right
    end; radial_gap m: sliding-block thickness between the walls; bears_on: names of the inner
    boom's outer-face patches the sliders bear on (arcs and faces of
    :func:`sim_core.physics.cross_sections.cross_section`); None: every patch of the shape's
    default bearing set."""

    slider_width: float = 0.3
    inner_distance: float = 0.0
    outer_distance: float = 0.0
    radial_gap: float = 0.005
    bears_on: tuple | None = None


@dataclass(frozen=True)
class LuffingSpec:
    """Mounting points of the luffing cylinder (docs/model.md#input-luffing), m.

    pivot: D1 in global (X, Z); pivot_on_boom: D1 in boom 1's left-section frame (axial s,
    vertical b); base: the cylinder base D2 in global (X, Z); head_on_boom: the cylinder head D3
    in boom 1's left-section frame (axial s, vertical b): its axial coordinate is the luffing
    point L_h, where boom 1's two spline elements meet."""

    pivot: tuple = (-0.556, 0.350)
    pivot_on_boom: tuple = (-0.956, 0.556)
    base: tuple = (0.100, 0.050)
    head_on_boom: tuple = (7.250, -0.556)

    def points(self):
        """(r1, r2, rbar1, rbar3) as 3-vectors for
        :func:`sim_core.systems.telescopic.luffing.luffing_geometry`."""
        (x1, z1), (x2, z2) = self.pivot, self.base
        (s1, b1), (s3, b3) = self.pivot_on_boom, self.head_on_boom
        return (x1, 0.0, z1), (x2, 0.0, z2), (s1, 0.0, b1), (s3, 0.0, b3)


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
    mass_centre_offset: bool = False        # Table 2 z_c as rigid offset (docs/model.md#input-sections)
    f_y: float = 355e6                      # Pa, the booms' yield strength (section_utilisation)
    z_c: tuple | None = None                # m, mass centre along e_b (None: crane_sections)
    mu_static: float = 0.15
    mu_dynamic: float = 0.1
    v_eps: float = 0.01                     # m/s, switching speed
    moment_model: str = "rigid"             # slider moment: "rigid" (Sec. 6), "seat", "couple"
    seat_stiffness: float = 1e8             # N m/rad, rocking stiffness of a slider seat
    friction_load: str = "resultant"        # friction normal load: "resultant" or "springs"
    spring_k0: float = 1e9                  # N/m per radial spring (docs/model.md#input-springs)
    spring_eps: float = 1e-6                # m, smoothing interval
    slider_width: float = 0.3               # m, 2w: slider length along the boom (docs/model.md#input-sections)
    springs_per_quarter: int = 20           # radial springs per quarter arc and slider end (docs/model.md#input-springs)
    radial_gap: float = 0.005               # m, gap between adjacent booms' walls (Table 1)
    sections: tuple | None = None           # (EI, GJ, m') per boom (None: crane_sections)
    booms: tuple | None = None              # BoomSpec per boom ([[boom]]); None: the shorthand
    lengths: tuple | None = None            # m, per boom (None: boom_length for every boom)
    overlaps: tuple | None = None           # OverlapSpec per overlap (None: the [contact] values)
    luffing: LuffingSpec | None = None      # None: the paper's mounting points with L_h
    # actuator profiles (sim_core.systems.telescopic.actuators, SI: m or rad); None: the cubic
    # schedule of v_max, t_ramp, t_hold_end (telescopic), a held position (the others)
    drive_profile: object = None
    luffing_profile: object = None
    slew_profile: object = None
    hoist_profile: object = None
    payload_swing: bool = False             # the payload on the hoist rope (physics.hoist)
    hoist_length: float = 10.0              # m, unstretched hoist rope at t = 0
    hoist_EA: float = 2e8                   # N
    hook_mass: float = 500.0                # kg
    # the ground under the swinging payload (physics.ground_contact): None = no ground; else
    # {height m, stiffness N/m, damping N s/m, ramp_width m}
    ground: dict | None = None
    # the telescopic cylinder's oil column (physics.hydraulic_cylinder): None = the stage
    # length follows the drive exactly; else {cylinder_area m^2, bulk_modulus Pa, dead_length m,
    # damping_ratio}
    oil_column: dict | None = None
    # mechanisms "independent" and "single_cylinder" (sim_core.systems.telescopic.telescoping):
    # each stage's length L_s,k(t) (m, a profile of physics.drive_profiles, stage 0 = boom 2 in
    # boom 1) and the single cylinder's moves (t_start s, t_end s, stage)
    stage_profiles: tuple | None = None
    cylinder_moves: tuple | None = None
    plugin_tables: dict = field(default_factory=dict)  # effect plug-ins on: name -> table

    def __post_init__(self):
        if self.mechanism not in MECHANISMS:
            raise ValueError(f"mechanism = {self.mechanism!r}: allowed {MECHANISMS}")
        if self.booms is not None:
            if len(self.booms) != self.n_booms:
                raise ValueError(f"booms: {len(self.booms)} BoomSpec for n_booms = "
                                 f"{self.n_booms}")
            self.lengths = tuple(b.length for b in self.booms)
        if self.lengths is None:
            self.lengths = (self.boom_length,) * self.n_booms
        if self.overlaps is None:
            self.overlaps = (OverlapSpec(self.slider_width, 0.0, 0.0, self.radial_gap),) * \
                (self.n_booms - 1)
        if self.luffing is None:
            self.luffing = LuffingSpec(head_on_boom=(self.L_h, -0.556))
        self.L_h = float(self.luffing.head_on_boom[0])
        if self.booms is not None:
            self.z_c = tuple(b.z_c for b in self.booms)
            return
        rows, zc = crane_sections(self.n_booms)
        if self.sections is None:
            self.sections = rows
        if self.z_c is None:
            self.z_c = zc

    @property
    def uniform(self) -> bool:
        """The paper's kind of crane: the shorthand sections, one length, sliders at the ends."""
        return (self.booms is None and len(set(self.lengths)) == 1
                and all(o.inner_distance == 0.0 and o.outer_distance == 0.0
                        and o.bears_on is None for o in self.overlaps))

    def summary(self, name: str = "telescopic") -> dict:
        """What a Result records as its scene where it was run from parameters, not a scene."""
        skip = ("sections", "booms", "overlaps", "luffing", "drive_profile", "luffing_profile",
                "slew_profile", "hoist_profile", "plugin_tables", "stage_profiles",
                "cylinder_moves")
        return {"kind": "telescopic", "name": name,
                "params": {k: v for k, v in self.__dict__.items() if k not in skip}}


def boom_section(k: int, p: TelescopicParams) -> BeamSection:
    """The beam constants of boom k (0-based, from the outermost).

    Described boom by boom: EA = E A, GJ = G J, EI_t = E I_t, EI_b = E I_b (Eq. 36), rhoA = m',
    rotary inertia (m'/A) (I_t + I_b, I_t, I_b) about (e_s, e_t, e_b).  The shorthand: the rows
    of :func:`crane_sections` scaled with E (the paper's nearly rigid case 9.1 scales the
    stiffnesses, not the masses), rotary inertia rho EI/E (docs/model.md#input-sections)."""
    if p.booms is not None:
        b = p.booms[k]
        dens = b.mass_per_length / b.A                   # kg/m^3 of the smeared section
        off = p.mass_centre_offset
        return BeamSection(EA=b.E * b.A, GJ=b.G * b.J, EI_t=b.E * b.I_t, EI_b=b.E * b.I_b,
                           rhoA=b.mass_per_length, J_s=dens * (b.I_t + b.I_b),
                           J_t=dens * b.I_t, J_b=dens * b.I_b,
                           y_c=b.y_c if off else 0.0, z_c=b.z_c if off else 0.0)
    EI, GJ, m = p.sections[min(k, len(p.sections) - 1)]
    scale = p.E / 2.1e11                   # case 9.1: stiffnesses x10, masses unchanged
    I = EI / 2.1e11                         # second moment from Table 2
    # mass-centre offset along e_b (Table 2), a rigid offset in inertia and gravity (#input-sections)
    zc = p.z_c[min(k, len(p.z_c) - 1)] if p.mass_centre_offset else 0.0
    return BeamSection(EA=p.E * m / p.rho, GJ=GJ * scale, EI_t=EI * scale, EI_b=EI * scale,
                       rhoA=m, J_s=2 * p.rho * I, J_t=p.rho * I, J_b=p.rho * I, z_c=zc)
