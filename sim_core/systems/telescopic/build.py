"""Telescopic boom system of Zhao-Qi-Wang 2024 (Sections 2, 5-7, 9): nested flexible booms with
moving contact constraints, luffing cylinder, telescopic cylinder, ropes and payload.

Contact regions carry their moment by the scene's ``contact.moment_model``: ``rigid`` (Section 6
as printed: the sections' Cardan angles coincide), ``seat`` (the bending angles tied by an
elastic seat, point_effects.SliderSeat) or ``couple`` (the bending angles free, so an overlap
carries its moment as a force couple between its two regions).  The friction of Section 8.3
takes its normal load from ``contact.friction_load`` (sim_core.physics.contact.friction).

Booms are numbered from the outermost (1).  Each boom is two moving-node spline elements split
at its outer contact point (boom 1: at the luffing point s = L_h, a material point, Eq. 50);
the end nodes are material points (s_1,k = 0, s_4,k = L_k, Eq. 50).  The inner contact point of
boom k < N is not a node: its arc-length coordinate s_2,k is an extra generalized coordinate
(Section 5) and the point is interpolated with Eq. 6.

Constraint I (Eq. 47): centroid and Cardan angles of boom k+1's section at its inner slider
(the left end, or d_in from it: ``[[overlap]] inner_slider_distance``) = those of boom k at
s_2,k.  Constraint II (Eq. 48): boom k's section at its outer slider (the right end, or d_out
inside it) = boom k+1's outer-contact node s_3,k+1.  Their multipliers are the contact
force/moment resultants; the generalized forces they exert on s_2,k and s_3,k+1 are the
contact multipliers eta of Section 7 (zero without friction).  Each boom has its own length
L_k and section (params.BoomSpec, docs/model.md#own-crane).

Mounting and drives (docs/model.md#input-luffing and #input-ropes, proposed defaults): revolute
pivot D1 about Y (a rigid offset from boom 1's left section), luffing cylinder = massless rigid
rod D2-D3 of constant length (its multiplier is the cylinder force; the mounting points of the
scene's [luffing] table, docs/model.md#own-crane-luffing), telescopic cylinder = massless
actuator imposing the distance L_s(t) between the left-section centres of booms 1 and 2,
elastic tension-only extraction and retraction ropes over point pulleys, payload point mass at
boom N's tip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sim_core import run_control
from sim_core.model.boundary import (
    LinearConstraint,
    boundary_condition,
    fix_material_coordinate,
    no_torsion,
    reference_basis,
)
from sim_core.model.model import Model
from sim_core.physics.beam.moving_node_beam import Beam
from sim_core.physics.constraints import (
    NonlinearConstraint,
    angle_coincidence,
    distance_driver,
    fixed_point,
    material_point,
    point_coincidence,
    rope_length,
)
from sim_core.physics.drive_profiles import CubicSmoothstepSchedule, HoldProfile
from sim_core.physics.hoist import HangingMass, HoistRope, free_point
from sim_core.physics.effects import Effect, Elasticity, Gravity, Inertia, StressFilter
from sim_core.physics.hydraulic_cylinder import OilColumn
from sim_core.physics.point_effects import PointMass, RopeDrive, SliderSeat
from sim_core.physics.rigid_body import beam_frame, revolute_axis, turntable_frame
from sim_core.systems.telescopic.luffing import cylinder_drive, luffing_geometry
from sim_core.systems.telescopic.params import STAGEWISE, TelescopicParams, boom_section
from sim_core.systems.telescopic.sliders import overlap_pads, slider_geometries
from sim_core.systems.telescopic.telescoping import cylinder_stage


@dataclass
class TelescopicSystem:
    model: Model
    Q0: np.ndarray
    schedule: CubicSmoothstepSchedule
    s2_index: list[int]                     # coordinates of the inner contact points s_2,k
    s3_index: list[int]                     # coordinates of the outer contact points s_3,k
    rows: dict[str, slice]                  # nonlinear-constraint rows by name
    tip: callable                           # point function of the tip (boom N, s = L)
    params: TelescopicParams
    contact: object = None                  # contact_friction.ContactFriction, if built
    # per contact region ("I_12", "II_12", ...): the Cardan-angle rows kept as constraints
    # (0, 1 bending, 2 twist) and, for the seat model, its point_effects.SliderSeat
    angle_rows: dict = field(default_factory=dict)
    seats: dict = field(default_factory=dict)
    drives: list = field(default_factory=list)  # names of the prescribed-distance rows
    ropes: list = field(default_factory=list)   # (extraction, retraction) RopeDrive per unit
    stages: list = field(default_factory=list)  # schedule of each stage k (boom k -> k+1)
    hoist: object = None                        # physics.hoist.HoistRope (payload_swing)
    ground: object = None                       # physics.ground_contact.GroundContact

    def section_outline(self, k: int) -> np.ndarray:
        """Boom k's outer contour in section coordinates, m (for loads on its surface)."""
        return _section_outline(self, k)

    def exposed_elements(self) -> list:
        """The spline elements outside the neighbouring booms: boom 1 whole, boom k > 1 beyond
        its outer contact point (its second element)."""
        beams = self.model.beams
        return list(beams[0].elements) + [b.elements[-1] for b in beams[1:]]
    slew_angle: object = None                   # t -> slew angle (rad) where the crane slews
    i_phi: int | None = None                    # the turntable's slew-angle coordinate
    plugin_effects: list = field(default_factory=list)  # (EffectPlugin, its Effect)
    # the cylinders driven through their oil column (effects.oil_column): drive name ->
    # physics.hydraulic_cylinder.OilColumn, in place of the drive's constraint row
    oil_columns: dict = field(default_factory=dict)


def _section_outline(ts: "TelescopicSystem", k: int) -> np.ndarray:
    """Boom k's outer contour (n, 2) in section coordinates (e_t, e_b), m: its section's, or
    for the shorthand the U family's Table 1 contour (outer radii)."""
    return boom_cross_section(ts.params, k).outer


def boom_cross_section(p: TelescopicParams, k: int):
    """Boom k's :class:`~sim_core.physics.cross_sections.CrossSection` (0-based k): the
    [[boom]] table's (None for given properties), or for the shorthand the U family's Table 1
    section (outer radii)."""
    from sim_core.physics.cross_sections import cross_section
    if p.booms is not None:
        return p.booms[k].section
    from sim_core.systems.telescopic.params import _Y_A, _WALL, family_radius
    # two shorthand booms are the paper's booms 1 and 2 (params.crane_sections)
    r = family_radius(k, max(p.n_booms, 3))
    return cross_section({"shape": "u", "top_arc_centre_y": _Y_A, "top_arc_centre_z": _Y_A,
                          "top_arc_radius": r, "wall": _WALL}, method="closed form")


def drive_layout(n_booms: int, mechanism: str) -> tuple[list[int], list[int]]:
    """(stages with a prescribed length, booms moved by a rope unit), 0-based.

    ``synchronized``: the paper's unit (Section 2: a cylinder pushes boom k+1 out of boom k, a
    rope pair over a pulley on boom k+1 moves boom k+2 by the same stroke) repeated along the
    boom: cylinders on stages 0, 2, 4, ..., rope units on booms 2, 4, ...  ``sequential``: one
    cylinder moves one stage at a time while locking pins hold the others; every stage is a
    prescribed length (the active one on its schedule, the locked ones constant) and there are
    no ropes; so are ``independent`` and ``single_cylinder`` (sim_core.systems.telescopic.
    telescoping)."""
    if mechanism in STAGEWISE:
        return list(range(n_booms - 1)), []
    return list(range(0, n_booms - 1, 2)), list(range(2, n_booms, 2))


def drive_name(stage: int, mechanism: str) -> str:
    """Constraint name of the prescribed length of stage ``stage`` (boom stage+1 -> stage+2)."""
    pair = f"{stage + 1}{stage + 2}"
    if mechanism in STAGEWISE:
        return f"stage_{pair}"
    return "telescopic_cylinder" if stage == 0 else f"telescopic_cylinder_{pair}"


def rope_names(j: int) -> tuple[str, str, str]:
    """(extraction, retraction, inextensible) rope names of the unit moving boom j (0-based):
    the paper's names for boom 3, suffixed by the boom number beyond."""
    if j == 2:
        return "extraction_rope", "retraction_rope", "rope"
    return f"extraction_rope_{j + 1}", f"retraction_rope_{j + 1}", f"rope_{j + 1}"


def rope_static_tension(p: TelescopicParams, j: int) -> float:
    """Static tension (N) of boom j's extraction rope (0-based j) on the rigid, frictionless
    boom of the synchronized drive: T_j = (m_j + ... + m_(N-1) + m_p) g sin(theta).

    Axial balance of boom i with weights W_i = m_i g sin(theta) (W_p added to the tip boom):
    rope j pulls its boom out with T_j, its pulley pulls boom j-1 in with 2 T_j, its anchor pulls
    boom j-2 out with T_j; a cylinder on stage (i, i+1) pushes boom i+1 out and boom i in with
    F.  Boom i+1 of a cylinder stage: F = W_(i+1) + 2 T_(i+2); boom i = j of a rope unit:
    T_j = W_j + F - T_(j+2) = W_j + W_(j+1) + T_(j+2), which sums from the tip to the formula
    (docs/model.md, "N-boom drives")."""
    masses = [p.lengths[i] * boom_section(i, p).rhoA for i in range(p.n_booms)]
    hanging = p.payload + (p.hook_mass if p.payload_swing else 0.0)
    return (sum(masses[j:]) + hanging) * p.gravity * math.sin(math.radians(p.luffing_angle_deg))


def stroke_mass_of(p: TelescopicParams) -> float:
    """The stages' and payload's rigid-body mass on the stroke M_s (kg) of the synchronized
    drive (:func:`sim_core.systems.telescopic.friction_table.stroke_mass`; the hook hangs with
    a swinging payload)."""
    from sim_core.systems.telescopic.friction_table import boom_masses, stroke_mass
    return stroke_mass(boom_masses(p), p.payload + (p.hook_mass if p.payload_swing else 0.0))


def stage_schedules(p: TelescopicParams) -> list[CubicSmoothstepSchedule]:
    """The length L_s,k(t) of every stage k (distance of the left sections of booms k and k+1,
    0-based), m.  ``synchronized``: every stage on the drive's cubic schedule (docs/model.md#input-drive).
    ``sequential``: one stage at a time on that schedule, shifted by the duration t_ramp +
    t_hold_end of one stroke; extraction moves the innermost stage first (the tip section out
    of its neighbour, then inwards), retraction the reverse order; a stage outside its window
    holds its length (a locked pin)."""
    n = p.n_booms - 1
    if p.stage_profiles is not None:              # each stage its own (telescoping.py)
        return list(p.stage_profiles)
    if p.drive_profile is not None:               # a [drive] profile (actuators): every stage
        return [p.drive_profile] * n
    if p.mechanism != "sequential":
        one = CubicSmoothstepSchedule(v_max=p.v_max, t_ramp=p.t_ramp, t_hold_end=p.t_hold_end,
                                      sign=p.direction, s0=p.stroke0)
        return [one] * n
    order = list(range(n - 1, -1, -1)) if p.direction > 0 else list(range(n))
    T = p.t_ramp + p.t_hold_end
    out = [None] * n
    for pos, k in enumerate(order):
        out[k] = CubicSmoothstepSchedule(v_max=p.v_max, t_ramp=p.t_ramp, t_hold_end=p.t_hold_end,
                                         sign=p.direction, s0=p.stroke0, t_start=pos * T)
    return out


def active_stage(ts: TelescopicSystem, t: float) -> int:
    """The stage (0-based) the single cylinder of the sequential drive moves at time t: the one
    whose window [t_start, t_end) holds t; before the first window the first stage of the
    order, after the last the last one."""
    order = sorted(range(len(ts.stages)), key=lambda k: ts.stages[k].t_start)
    for k in order:
        if t < ts.stages[k].t_end:
            return k
    return order[-1]


def _length_of(schedule):
    def length(t):                                 # one sample of the schedule: (L, L', L'')
        smp = schedule.sample(t)
        return smp.s, smp.v, smp.a
    return length


def build_telescopic(p: TelescopicParams) -> TelescopicSystem:
    theta = np.radians(p.luffing_angle_deg)
    geo = luffing_geometry(theta, *p.luffing.points())
    e = np.asarray(geo.e_s, float)
    O1 = np.asarray(geo.origin, float)
    Lk, N, Ls = p.lengths, p.n_booms, p.stroke0
    # the stage lengths at t = 0 and boom k's left section a_k along boom 1: k L_s, or the sum of
    # the stages' own initial lengths where each stage has a profile (telescoping.py)
    ls0, a0 = [Ls] * (N - 1), [k * Ls for k in range(N)]
    if p.stage_profiles is not None:
        ls0 = [float(pr.sample(0.0).s) for pr in p.stage_profiles]
        a0 = [0.0, *np.cumsum(ls0)]
    d_in = [o.inner_distance for o in p.overlaps]     # slider centres from the boom ends, m
    d_out = [o.outer_distance for o in p.overlaps]
    G = reference_basis(e)
    beams = []
    for k in range(N):
        # boom 1 splits at the luffing point, boom k+1 at the outer contact point s_3,k+1 =
        # L_k - d_out - L_s (Eq. 50; the paper's L - L_s)
        split = p.L_h if k == 0 else (Lk[k - 1] - d_out[k - 1]) - ls0[k - 1]
        beams.append(Beam(f"boom{k + 1}", Lk[k], boom_section(k, p), (0.0, split, Lk[k]),
                          n_nodes=p.n_nodes, n_gauss=p.n_gauss, reference_basis=G))
    offsets = np.cumsum([0] + [b.n_coords for b in beams])[:-1]
    g_vec = np.array([0.0, 0.0, -p.gravity])
    effects: list[Effect] = [Inertia(), Elasticity()]
    if p.filter_h > 0:
        effects.append(StressFilter(p.filter_h))
    if p.gravity > 0:
        effects.append(Gravity(g_vec))
    lin = []
    for ib in range(N):
        for end in ("left", "right"):
            lin.append(boundary_condition(offsets, beams, ib, end, "free"))
    lin.append(fix_material_coordinate(offsets, beams, 0, 1, p.L_h))
    if not p.torsion:
        lin.append(no_torsion(offsets, beams))
    # extra coordinates: the inner contact points s_2,k, then the swinging payload's position,
    # then the turntable's slew angle phi (prescribed: a linear constraint phi = phi(t))
    n_extra = N - 1 + (3 if p.payload_swing else 0) + (1 if p.slew_profile is not None else 0)
    i_phi = None
    if p.slew_profile is not None:
        i_phi = int(sum(b.n_coords for b in beams)) + n_extra - 1
        lin.append(_slew_signal(p.slew_profile, i_phi))
    model = Model(beams, effects, [], lin, n_extra=n_extra, baumgarte=p.baumgarte)

    # initial straight configuration: boom k's left section a_k = k L_s along boom 1
    # (docs/model.md#input-ropes)
    Q0 = np.zeros(model.n_coords)
    for k, b in enumerate(beams):
        Q0[offsets[k]:offsets[k] + b.n_coords] = b.straight_coordinates(O1 + a0[k] * e, e)
    n_beam = int(sum(b.n_coords for b in beams))
    s2_index = [n_beam + k for k in range(N - 1)]
    Q0[s2_index] = [x + d for x, d in zip(ls0, d_in)]
    s3_index = [int(offsets[k] + beams[k].s_coord(1)) for k in range(N)]

    def mp(k, **kw):
        return material_point(model, k, **kw)

    cons: list[NonlinearConstraint] = []
    names: list[tuple[str, int]] = []

    def add(c):
        cons.append(c)
        names.append((c.name, c.m))

    # effects.torsion = false: the torsion angles gamma are held at zero, so the gamma rows of the
    # angle coincidences would read 0 = 0 (a singular KKT matrix) and are left out
    bend = [0, 1] if not p.torsion else [0, 1, 2]

    def angles(name, fa, fb=None, fixed=None, keep=(0, 1, 2)):
        c = angle_coincidence(name, fa, fb, fixed=fixed)
        k = [i for i in keep if i in bend]
        return c if len(k) == 3 else _rows(c, k)

    # pivot D1: revolute about Y (point fixed, beta = gamma = 0 at boom 1's left section)
    _, _, rbar1, rbar3 = p.luffing.points()
    D1 = mp(0, s_fixed=0.0, offset=rbar1)
    base = fixed_point(geo.d2)
    if i_phi is None:
        add(point_coincidence("pivot", D1, fixed=geo.d1))
        root = mp(0, s_fixed=0.0)
        add(angles("pivot_axis", root, fixed=[0.0, 0.0, 0.0], keep=(1, 2)))
    else:
        # the pivot D1 and the cylinder base D2 ride on the turntable, which turns about the
        # vertical by phi; the pivot is a revolute joint about the turntable's plane normal
        # (3 point rows and 2 axis rows, sim_core.physics.rigid_body, as in the folding scene)
        def turn(point=(0.0, 0.0, 0.0)):
            return turntable_frame(model.n_coords, i_phi, SLEW_AXIS, PLANE_BASIS, point)
        add(point_coincidence("pivot", D1, turn((geo.d1[0], geo.d1[2], 0.0))))
        root_frame, table = beam_frame(model, 0, 0.0), turn()
        Ra0, Rb0 = table(Q0)[2], root_frame(Q0)[2]
        add(revolute_axis("pivot_axis", table, root_frame, Ra0.T @ PLANE_BASIS[:, 2],
                          Rb0.T @ PLANE_BASIS[:, 0], Rb0.T @ PLANE_BASIS[:, 1]))
        base = turn((geo.d2[0], geo.d2[2], 0.0))
    # luffing cylinder: rigid massless rod D2-D3 held at its initial length (docs/model.md#input-luffing)
    D3 = mp(0, s_fixed=p.L_h, offset=(0.0, 0.0, rbar3[2]))
    Lc = float(geo.cylinder_length)
    if p.luffing_profile is None:
        add(distance_driver("luffing_cylinder", D3, base, lambda t: (Lc, 0.0, 0.0)))
    else:          # the cylinder length that moves the rigid crane along the luffing profile
        add(distance_driver("luffing_cylinder", D3, base,
                            cylinder_drive(p.luffing_profile, p.luffing.points())))
    # contact constraints I and II between adjacent booms (Section 6).  The moment model decides
    # which Cardan-angle rows stay constraints: all three (rigid, Eqs. 47-48), or the twist only
    # (seat: the bending rows become an elastic seat; couple: they are free)
    if p.moment_model not in ("rigid", "seat", "couple"):
        raise ValueError(f"moment_model = {p.moment_model!r} (allowed: 'rigid', 'seat', "
                         "'couple')")
    kept = tuple(bend) if p.moment_model == "rigid" else tuple(i for i in bend if i == 2)
    angle_rows, seats = {}, {}

    def contact_region(name, fa, fb):
        add(point_coincidence(name + "_point", fa, fb))
        angle_rows[name] = kept
        if kept:
            add(angles(name + "_angles", fa, fb, keep=kept))
        if p.moment_model == "seat":
            seats[name] = SliderSeat(_rows(angle_coincidence(name + "_seat", fa, fb), [0, 1]),
                                     p.seat_stiffness, name=name + "_seat")

    for k in range(N - 1):
        contact_region(f"I_{k + 1}{k + 2}", mp(k + 1, s_fixed=d_in[k]),
                       mp(k, s_index=s2_index[k]))
        contact_region(f"II_{k + 1}{k + 2}", mp(k, s_fixed=Lk[k] - d_out[k]),
                       mp(k + 1, s_index=s3_index[k + 1]))
    # the drive: telescopic cylinders (prescribed distances of left sections, docs/model.md#input-drive) and rope
    # units (module docstring, "N-boom drives")
    sched = p.drive_profile or CubicSmoothstepSchedule(v_max=p.v_max, t_ramp=p.t_ramp,
                                                       t_hold_end=p.t_hold_end,
                                                       sign=p.direction, s0=Ls)
    stages = stage_schedules(p)
    cylinders, rope_booms = drive_layout(N, p.mechanism)
    drives, columns = [], {}
    for k in cylinders:
        name = drive_name(k, p.mechanism)
        ends = (mp(k + 1, s_fixed=0.0), mp(k, s_fixed=0.0))
        if p.oil_column is None:
            add(distance_driver(name, *ends, _length_of(stages[k])))
        else:
            # the cylinder through its oil column (physics.hydraulic_cylinder); its static
            # force F0 comes from the constrained equilibrium (initial_equilibrium)
            oc = p.oil_column
            columns[name] = OilColumn(ends, _length_of(stages[k]),
                                      kA=oc["bulk_modulus"] * oc["cylinder_area"],
                                      dead_length=oc["dead_length"], zeta=oc["damping_ratio"],
                                      stroke_mass=stroke_mass_of(p), name=name)
        drives.append(name)
    model.nonlinear = cons
    rows, i = {}, 0
    for nm, m in names:
        rows[nm] = slice(i, i + m)
        i += m

    tip = mp(N - 1, s_fixed=Lk[N - 1])
    pe = []
    hoist = ground = None
    if p.payload_swing:
        # the payload and hook on the hoist rope (sim_core.physics.hoist): their position is
        # three coordinates after the contact points, starting below the tip on the rope
        # stretched by their weight (the statics take it from there)
        ip = n_beam + N - 1
        m_hang = p.payload + p.hook_mass
        L0 = p.hoist_profile or HoldProfile(s0=p.hoist_length)
        L_static = L0.sample(0.0).s * (1.0 + m_hang * p.gravity / p.hoist_EA)
        Q0[ip:ip + 3] = np.real(tip(Q0)[0]) - np.array([0.0, 0.0, L_static])
        hoist = HoistRope(tip, free_point(ip, model.n_coords), p.hoist_EA, _length_of(L0))
        pe += [HangingMass(ip, m_hang, g_vec if p.gravity > 0 else None), hoist]
        if p.ground is not None:
            ground = _ground_under_payload(p, ip, m_hang, Q0, tip)
            pe.append(ground)
    elif p.payload > 0:
        pe.append(PointMass(tip, p.payload, g_vec if p.gravity > 0 else None))
    ropes = []
    for j in rope_booms:
        # rope unit of boom j (0-based): anchored on boom j-2, over a pulley on boom j-1, fixed
        # to boom j's left section (docs/model.md#input-ropes for j = 2, repeated along the boom)
        # (the pulley 1 m inside boom j-1's right end: s = 9 m on the paper's 10 m booms)
        ext = [mp(j - 2, s_fixed=0.0, offset=(0.05, 0, 0)), mp(j - 1, s_fixed=Lk[j - 1] - 1.0),
               mp(j, s_fixed=0.0, offset=(-0.04, 0, 0))]
        ret = [mp(j - 2, s_fixed=Lk[j - 2], offset=(0.68, 0, 0)), mp(j - 1, s_fixed=0.66),
               mp(j, s_fixed=0.0, offset=(0.64, 0, 0))]
        en, rn, bn = rope_names(j)
        if p.rope_elasticity:
            EA = p.rope_EA * p.E / 2.1e11
            rope = RopeDrive(ext, EA, 1.0, name=en)
            ell_e = float(rope.length(Q0)[0])
            # unstretched length from the static rope tension of the rigid, frictionless boom:
            # the rope of boom j carries booms j..N and the payload, T = (sum m_i + m_p) g
            # sin(theta) (docs/model.md#check-static-luffing for j = 2: (m3 + m_p) g sin(theta))
            T0 = rope_static_tension(p, j)
            rope.L0 = ell_e / (1.0 + T0 / EA)
            retr = RopeDrive(ret, EA, 1.0, name=rn)
            retr.L0 = float(retr.length(Q0)[0])         # just taut
            pe += [rope, retr]
            ropes.append((rope, retr))
        else:
            # effects.rope_elasticity = false: one inextensible bilateral rope (its multiplier's
            # sign tells which of the two ropes is taut); nothing of the rope springs is computed
            ell_e = float(np.real(rope_length(bn, ext, 0.0).evaluate(Q0)[0][0]))
            cons.append(rope_length(bn, ext, ell_e))
            rows[bn] = slice(i, i + 1)
            i += 1
            model.nonlinear = cons
    model.point_effects = pe + list(seats.values()) + list(columns.values())
    ts = TelescopicSystem(model, Q0, sched, s2_index, s3_index, rows, tip, p,
                          angle_rows=angle_rows, seats=seats, drives=drives, ropes=ropes,
                          oil_columns=columns,
                          stages=stages, hoist=hoist, ground=ground, i_phi=i_phi,
                          slew_angle=None if i_phi is None else
                          (lambda t, prof=p.slew_profile: float(prof.sample(t).s)))
    # Section 8 contact analysis: the slider springs on every overlap's bearing patches
    # (sim_core.systems.telescopic.sliders); with friction off it is only evaluated for the
    # outputs (it does not act on the motion), with contact_distribution off it is not built
    if p.contact_distribution is None:
        p.contact_distribution = N == 3 or p.booms is not None
    if p.friction and p.friction_load == "springs" and not p.contact_distribution:
        raise ValueError("friction_load = 'springs' needs contact_distribution (the slider "
                         "springs); allowed: friction_load = 'resultant'")
    if p.friction or p.contact_distribution:
        from sim_core.physics.contact.friction import ContactFriction
        ts.contact = ContactFriction(ts, p.mu_static, p.mu_dynamic, p.v_eps, p.spring_k0,
                                     p.spring_eps, distribution=p.contact_distribution,
                                     slider_half_width=0.5 * p.slider_width,
                                     springs_per_quarter=p.springs_per_quarter,
                                     radial_gap=p.radial_gap, friction_load=p.friction_load,
                                     geometries=slider_geometries(p) if p.contact_distribution
                                     else None)
    if p.friction:
        model.multiplier_forces = [ts.contact]
    # effect plug-ins switched on in the scene (sim_core.physics.plugins)
    if p.plugin_tables:
        from sim_core.physics.plugins import effect_plugins
        plugins = effect_plugins()
        for name, table in p.plugin_tables.items():
            effect = plugins[name].build(table, ts)
            model.effects.append(effect)
            ts.plugin_effects.append((plugins[name], effect))
        model.effects_changed()
    return ts


# the turntable: slew axis vertical (global Z); the luffing plane's basis at phi = 0 has the
# columns e_u = X (forward), e_v = Z (up), n = e_u x e_v = -Y (sim_core.physics.rigid_body)
SLEW_AXIS = np.array([0.0, 0.0, 1.0])
PLANE_BASIS = np.column_stack([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


def _slew_signal(profile, i_phi: int):
    """The prescribed slew angle phi(t) (rad) as a linear constraint on its coordinate."""
    def part(k):
        return lambda t: np.array([float(profile.sample(t)[k])])
    return LinearConstraint("slew", [{i_phi: 1.0}], part(0), part(1), part(2))


#: points per boom of the replay geometry (the booms' centre lines at the output times)
REPLAY_POINTS = 11


def _replay_geometry(ts: TelescopicSystem, t, ys) -> dict:
    """What a picture of the run needs, at every output time (global coordinates, m):

    * ``geometry_centre_lines`` (n, N, REPLAY_POINTS, 3): each boom's reference line at equally
      spaced material points from s = 0 to its length;
    * ``geometry_section_frames`` (n, N, REPLAY_POINTS, 3, 3): the section frames there, rows
      (e_t, e_b, e_s);
    * ``geometry_luffing_cylinder`` (n, 2, 3): the cylinder's base D2 and head D3;
    * ``geometry_contacts`` (n, N-1, 2, 3): each overlap's inner and outer contact points;
    * ``geometry_section_outlines`` (N, k, 2): each boom's outer contour in section
      coordinates (e_t, e_b), for drawing the booms as tubes."""
    from sim_core.physics.beam.cardan import cardan_frame
    m, p = ts.model, ts.params
    n = m.n_dof
    basis = m.beams[0].reference_basis
    pts = [[material_point(m, k, s_fixed=float(s))
            for s in np.linspace(0.0, p.lengths[k], REPLAY_POINTS)] for k in range(p.n_booms)]
    cyl = next(c for c in m.nonlinear if c.name == "luffing_cylinder")
    contacts = [(material_point(m, k, s_index=ts.s2_index[k]),
                 material_point(m, k + 1, s_index=ts.s3_index[k + 1]))
                for k in range(p.n_booms - 1)]
    lines, frames, cylinder, cps = [], [], [], []
    for tk, y in zip(t, ys):
        Q, _ = m.full_state(tk, y[:n], y[n:])
        rr, ff = [], []
        for boom in pts:
            ev = [pt(Q) for pt in boom]
            rr.append([np.real(e[0]) for e in ev])
            ff.append([np.real(cardan_frame(*e[2]) @ basis.T) for e in ev])
        lines.append(rr)
        frames.append(ff)
        cylinder.append([np.real(pt(Q)[0]) for pt in reversed(cyl.points)])
        cps.append([[np.real(a(Q)[0]), np.real(b(Q)[0])] for a, b in contacts])
    outlines = []
    for k in range(p.n_booms):                   # at most ~100 contour points a boom
        o = np.asarray(ts.section_outline(k))
        outlines.append(o[::max(1, int(math.ceil(len(o) / 96)))])
    k_max = max(len(o) for o in outlines)
    padded = np.full((p.n_booms, k_max, 2), np.nan)
    for k, o in enumerate(outlines):
        padded[k, :len(o)] = o
    return {"geometry_centre_lines": np.array(lines), "geometry_section_frames": np.array(frames),
            "geometry_luffing_cylinder": np.array(cylinder),
            "geometry_contacts": np.array(cps).reshape(len(t), p.n_booms - 1, 2, 3),
            "geometry_section_outlines": np.broadcast_to(padded, padded.shape).copy()}


def _ground_under_payload(p: TelescopicParams, ip: int, m_hang: float, Q0, tip):
    """The ground of effects.ground (physics.ground_contact) under the payload on the
    coordinates ip..ip+2, which starts on it, below the tip, pressed in by its weight."""
    from sim_core.physics.ground_contact import GroundContact, resting_penetration
    gr = p.ground
    ground = GroundContact(ip, gr["height"], gr["stiffness"], gr["damping"], gr["ramp_width"])
    r_tip = np.real(tip(Q0)[0])
    Q0[ip:ip + 3] = [r_tip[0], r_tip[1],
                     gr["height"] - resting_penetration(ground, m_hang * p.gravity)]
    return ground


#: section-force stations per boom (equally spaced material points, both ends included)
SECTION_STATIONS = 21


def _section_outputs(ts: TelescopicSystem, t, ys) -> dict:
    """The booms' internal forces and stresses at every output time
    (docs/user_guide.md#section-forces-and-stresses):

    * ``section_stations`` (N, S): the stations' material coordinates, m (S =
      SECTION_STATIONS equally spaced points of each boom, ends included);
    * ``section_forces`` (n, N, S, 6): (N, Q_t, Q_b, T, M_t, M_b) in the section frame, N and
      N m (:mod:`sim_core.physics.beam.section_forces`);
    * ``section_stress`` (n, N, S, K, 2): normal stress and shear-stress magnitude at the K
      outline points of each boom's section, Pa; ``section_stress_points`` (N, K, 2): those
      points (e_t, e_b), m (:mod:`sim_core.physics.section_stress`);
    * ``section_utilisation`` (n, N, S): the largest von Mises stress of the section over the
      yield strength ``material.f_y``.
    A boom given by its constants (no geometry) has NaN stresses."""
    from sim_core.physics.beam.section_forces import model_section_forces
    from sim_core.physics.section_stress import OUTLINE_POINTS, stress_table, utilisation
    m, p = ts.model, ts.params
    n = m.n_dof
    stations = np.array([np.linspace(0.0, L, SECTION_STATIONS) for L in p.lengths])
    forces = np.array([model_section_forces(m, m.full_state(tk, y[:n], y[n:])[0], stations)
                       for tk, y in zip(t, ys)]).reshape(len(t), p.n_booms, SECTION_STATIONS, 6)
    stress = np.full(forces.shape[:3] + (OUTLINE_POINTS, 2), np.nan)
    points = np.full((p.n_booms, OUTLINE_POINTS, 2), np.nan)
    for k in range(p.n_booms):
        cs = boom_cross_section(p, k)
        if cs is None:
            continue
        table = stress_table(cs)
        stress[:, k, :, :, 0], stress[:, k, :, :, 1] = table.stresses(forces[:, k])
        points[k] = table.points
    return {"section_stations": stations, "section_forces": forces, "section_stress": stress,
            "section_stress_points": points,
            "section_utilisation": utilisation(stress[..., 0], stress[..., 1], p.f_y)}


def _payload_outputs(ts: TelescopicSystem, t: float, Q, r_tip, out: dict) -> None:
    """payload_position (m), sway_angle (rad: from the vertical in the luffing plane and across
    it, the plane turned by the slew angle) and hoist_rope_force (N) at one output time."""
    r_p = np.real(ts.hoist.bottom(Q)[0])
    d = r_p - np.real(r_tip)
    phi = ts.slew_angle(t) if ts.slew_angle is not None else 0.0
    u = np.array([math.cos(phi), math.sin(phi), 0.0])
    w = np.array([-math.sin(phi), math.cos(phi), 0.0])
    out.setdefault("payload_position", []).append(r_p)
    out.setdefault("sway_angle", []).append([math.atan2(d @ u, -d[2]), math.atan2(d @ w, -d[2])])
    out.setdefault("hoist_rope_force", []).append(ts.hoist.tension(float(np.linalg.norm(d)), t))


def _rows(c: NonlinearConstraint, keep: list[int]) -> NonlinearConstraint:
    """A constraint restricted to some of its rows."""
    ev = c.evaluate
    tgt = c.target

    def evaluate(Q):
        g, J = ev(Q)
        return g[keep], J[keep]

    def target(t):
        b, bd, bdd = tgt(t)
        return b[keep], bd[keep], bdd[keep]
    prog = None if c.program is None else (c.program[0], tuple(c.program[1][i] for i in keep),
                                           c.program[2])
    return NonlinearConstraint(c.name, len(keep), evaluate, None if tgt is None else target,
                               points=c.points, program=prog)


def initial_equilibrium(ts: TelescopicSystem, t: float = 0.0):
    """Static equilibrium at t = 0 with the rope lengths of docs/model.md#input-ropes: the
    retraction rope is 'just taut' *at the equilibrium*: it is slack while the equilibrium is
    solved, then its unstretched length is set to its length there (zero tension, no change of
    the equilibrium).
    Returns (z, lambda).

    Two-rope statics (our reading): when the static extraction-rope tension T0 =
    (m3 + m_p) g sin(theta) (docs/model.md#check-static-luffing) is not clearly in the rope's stiff branch (T0 <= (EA/L0) *
    slack_width, e.g. payload 0 at 0 deg), both tension-only ropes would sit at their kink with
    zero axial stiffness and boom 3's axial position is undetermined (Newton stalled at |r| ~
    0.3 N).  Then the equilibrium is solved with the extraction rope *bilateral* (a linear spring
    of either sign: the pair of opposing ropes acts as one rope), and afterwards the rope that
    carries the load is given that tension and the other one is made just taut at the start of
    its stiff branch (tension (EA/L0) slack_width / 2, ~5 N at the paper's EA); a final
    tension-only Newton from there leaves both ropes taut and the equilibrium well posed.

    Where Newton does not converge, the statics trace the equilibrium under the weight by load
    continuation (:func:`sim_core.model.statics.load_continuation`).  At low luffing angles the
    paper's luffing geometry has a short cylinder lever (0.23 m at 0 deg), and soft booms
    (E = 2.1e10 Pa) at 0 deg reach a limit point at 0.29 x their own weight: then
    :class:`~sim_core.errors.NoStaticEquilibrium` is raised, naming the angle and the lever."""
    from sim_core.errors import NoStaticEquilibrium
    try:
        if ts.oil_columns:
            return _oil_column_equilibrium(ts, t)
        return _initial_equilibrium(ts, t)
    except NoStaticEquilibrium as exc:
        # the statics' load continuation found a limit point below the full weight: say why
        p = ts.params
        lever = luffing_geometry(math.radians(p.luffing_angle_deg), *p.luffing.points()).lever
        raise NoStaticEquilibrium(exc.t, exc.load_factor_max, exc.path, reason=(
            f"no static equilibrium at luffing angle {p.luffing_angle_deg:g} deg (E = {p.E:.3g} "
            f"Pa, payload {p.payload:g} kg): the equilibrium path under the weight turns back at "
            f"a limit point at {exc.load_factor_max:.3g} x the full weight.  The luffing "
            f"cylinder's lever about the pivot D1 is {lever:.3f} m at this angle (0.714 m at "
            "60 deg) and the booms' deflection shortens it further; the limit load scales with "
            "E (docs/model.md, 'Initial state and statics')")) from exc


def _oil_column_equilibrium(ts: TelescopicSystem, t: float):
    """The static equilibrium of a system whose cylinders act through their oil column: that of
    the same crane with the cylinders as constraints (the twin built without the oil column;
    the coordinates are the same, the drive rows come on top), each column's static force F0
    the constraint's multiplier there, so the column starts uncompressed at the commanded
    length and the state is in equilibrium as it is.  The retraction ropes' lengths set by the
    twin's statics are copied.  Returns (z, lambda of this system)."""
    from dataclasses import replace
    twin = build_telescopic(replace(ts.params, oil_column=None))
    m = ts.model
    if m.n_dof != twin.model.n_dof:
        raise RuntimeError("the oil column's constrained twin has other coordinates")
    z, lam = _initial_equilibrium(twin, t)
    for name, col in ts.oil_columns.items():
        col.F0 = float(lam[twin.rows[name]][0])
    for (e, r), (te, tr) in zip(ts.ropes, twin.ropes):
        e.L0, r.L0 = te.L0, tr.L0
    _, lam_own = m.accelerations_and_multipliers(t, z, np.zeros_like(z))
    return z, lam_own


def _initial_equilibrium(ts: TelescopicSystem, t: float):
    if ts.ground is not None:            # the payload on the ground (physics.ground_contact)
        from sim_core.physics.ground_contact import resting_equilibrium
        return resting_equilibrium(ts, t, _rope_equilibrium)
    return _rope_equilibrium(ts, t)


def _rope_equilibrium(ts: TelescopicSystem, t: float):
    from sim_core.model.statics import constrained_static_equilibrium
    m = ts.model
    z0, _ = m.reduced_state(t, ts.Q0, np.zeros_like(ts.Q0))
    if not ts.ropes:
        return constrained_static_equilibrium(m, z0, t)
    for _, retr in ts.ropes:
        retr.L0 = np.inf

    def length(rope, z):
        Q, _ = m.full_state(t, z, np.zeros_like(z))
        return float(rope.length(Q)[0])

    def taut_L0(rope, ell, T):
        """Unstretched length with tension-only tension T >= (EA/L0) s / 2 at length ell:
        (EA/L0)(ell - L0 - s/2) = T."""
        return rope.EA * (ell - 0.5 * rope.slack_width) / (rope.EA + T)

    def stiff(ext, z):
        return ext.tension(length(ext, z)) > ext.EA / ext.L0 * ext.slack_width

    soft = [(ext, retr) for ext, retr in ts.ropes if not stiff(ext, z0)]
    soft_ids = {id(ext) for ext, _ in soft}
    if not soft:                                   # every rope in its stiff branch: as #input-ropes says
        z, lam = constrained_static_equilibrium(m, z0, t)
        for _, retr in ts.ropes:
            retr.L0 = length(retr, z)
        return z, lam
    for ext, _ in soft:
        ext.bilateral = True
    try:
        z, lam = constrained_static_equilibrium(m, z0, t)
        tensions = [ext.tension(length(ext, z)) for ext, _ in soft]
    finally:
        for ext, _ in soft:
            ext.bilateral = False
    resolve = False
    for ext, retr in ts.ropes:
        if id(ext) not in soft_ids:
            retr.L0 = length(retr, z)
    for (ext, retr), T in zip(soft, tensions):
        k_e, s = ext.EA / ext.L0, ext.slack_width
        ell_e, ell_r = length(ext, z), length(retr, z)
        if T >= k_e * s:
            # the extraction rope carries T in its stiff branch: same forces, nothing to re-solve
            ext.L0 = taut_L0(ext, ell_e, T)
            retr.L0 = ell_r
            continue
        # near zero or compressive: both ropes taut (the net pull T shared as T_min + max(+-T, 0))
        T_min = 0.5 * k_e * s
        ext.L0 = taut_L0(ext, ell_e, T_min + max(T, 0.0))
        retr.L0 = taut_L0(retr, ell_r, T_min + max(-T, 0.0))
        resolve = True
    return constrained_static_equilibrium(m, z, t) if resolve else (z, lam)


def simulate_telescopic(p: TelescopicParams, t_end: float = 20.0, n_output: int = 201,
                        rtol: float = 1e-6, atol: float = 1e-7, progress=None,
                        solver: dict | None = None, scene: dict | None = None,
                        checkpoint=None):
    """Run the telescopic scene from its static equilibrium and return a Result with the
    public outputs of the telescopic contract (tip kinematics, piston stroke, cylinder forces,
    contact-point resultants, contact coordinates, constraint violation; with friction also the
    normal force of every slider spring per region (I_12, II_12, I_23, II_23; springs ordered arc
    by arc P1, P2, P3 as in sim_core.physics.contact) and the signed friction coefficient per region).
    ``solver``: a validated [solver] table (:func:`sim_core.scene.fields.solver_table`); its entries
    (method, max_step, max_wall_s, ...) take precedence over the keyword arguments.  ``scene``:
    the validated scene the result records (a summary of ``p`` where None).  ``checkpoint``: a
    :class:`sim_core.checkpoint.Checkpointer` the integration writes to and resumes from (the
    rigid-boom limit has none)."""
    from sim_core.integrate.driver import integrate, run_with_partial
    sol = {"t_end": t_end, "rtol": rtol, "atol": atol, "n_output": n_output, **(solver or {})}
    if not p.flexible:
        if checkpoint is not None:
            checkpoint.unsupported("effects.flexible = false (the rigid-boom limit)")
        from sim_core.systems.telescopic.rigid import RigidTelescopic
        return RigidTelescopic(p).simulate(sol["t_end"], sol["n_output"], sol["rtol"], sol["atol"],
                                          scene=scene, max_wall_s=sol.get("max_wall_s"))
    ts = build_telescopic(p)
    m = ts.model
    z0, _ = initial_equilibrium(ts)
    y0 = np.concatenate([z0, 0 * z0])
    from sim_core.systems.telescopic.energy_audit import telescopic_energy_check
    return run_with_partial(
        lambda: integrate(m, y0, sol["t_end"], sol, progress, checkpoint),
        lambda t, ys, stats, err: _telescopic_result(ts, t, ys, stats, err, scene),
        check=lambda res: telescopic_energy_check(ts, res))


def _telescopic_result(ts: TelescopicSystem, t, ys, stats, error, scene=None):
    from sim_core.result import Result
    m, p = ts.model, ts.params
    n = m.n_dof
    N = p.n_booms
    out = {k: [] for k in ("tip_position", "tip_velocity", "tip_acceleration", "piston_stroke",
                           "luffing_cylinder_force", "telescopic_cylinder_force",
                           "contact_point_forces", "inner_contact_s", "outer_contact_s",
                           "constraint_violation", "stage_stroke", "drive_forces")}
    from sim_core.physics.contact.friction import region_multipliers, section_reaction
    from sim_core.physics.beam.cardan import cardan_frame
    basis = m.beams[0].reference_basis
    lefts = [material_point(m, k, s_fixed=0.0) for k in range(N)]
    out["luffing_angle"] = []
    stop = run_control.OutputGuard(partial=error is not None)    # the run's budget, Ctrl-C
    for tk, y in zip(t, ys):
        if stop(tk):
            break
        z, zd = y[:n], y[n:]
        zdd, lam = m.accelerations_and_multipliers(tk, z, zd)
        Q, Qd = m.full_state(tk, z, zd)
        Qdd = m.lift(tk, zdd, 2)
        r, J, _, _ = ts.tip(Q)
        _, Jc, _, _ = ts.tip(Q + 1e-20j * Qd)
        out["tip_position"].append(r)
        out["tip_velocity"].append(J @ Qd)
        out["tip_acceleration"].append(J @ Qdd + (Jc @ Qd).imag / 1e-20)
        a = [lp(Q)[0] for lp in lefts]
        stroke = [np.linalg.norm(a[k + 1] - a[k]) - p.stroke0 for k in range(N - 1)]
        forces = [ts.oil_columns[name].force(tk, Q, Qd) if name in ts.oil_columns
                  else lam[ts.rows[name]][0] for name in ts.drives]
        cyl = (active_stage(ts, tk) if p.mechanism == "sequential" else
               cylinder_stage(p.cylinder_moves, tk) if p.cylinder_moves else 0)
        out["stage_stroke"].append(stroke)
        out["drive_forces"].append(forces)
        out["piston_stroke"].append(stroke[cyl])
        out["luffing_cylinder_force"].append(lam[ts.rows["luffing_cylinder"]][0])
        out["telescopic_cylinder_force"].append(forces[cyl])
        cpf = []
        for k in range(N - 1):
            inner = material_point(m, k, s_index=ts.s2_index[k])
            outer = material_point(m, k + 1, s_index=ts.s3_index[k + 1])
            pair = []
            for name, point in ((f"I_{k + 1}{k + 2}", inner), (f"II_{k + 1}{k + 2}", outer)):
                f_sec, m_sec = section_reaction(point, Q, *region_multipliers(ts, name, Q, lam),
                                                basis)
                pair.append(np.concatenate([f_sec, m_sec]))
            cpf.append(pair)
        out["contact_point_forces"].append(cpf)
        if ts.contact is not None:
            sols = ts.contact.solve_regions(Q, Qd, lam)
            if ts.contact.distribution:
                # regions of different layouts: padded with NaN to the largest spring count
                forces = [sol.normal_force for _, _, _, sol in sols]
                n_max = max(f.size for f in forces)
                out.setdefault("slider_contact_forces", []).append(
                    [np.pad(f, (0, n_max - f.size), constant_values=np.nan) for f in forces])
                # the springs summed pad by pad (sliders.overlap_pads): the force and couple
                # each pad puts on its overlap's inner boom, and its springs' sum per patch
                pads = overlap_pads(ts.contact, sols)
                for key, v in zip(("pad_forces", "pad_couples", "pad_face_forces"), pads):
                    out.setdefault(key, []).append(v)
            if p.friction:
                out.setdefault("friction_coefficient", []).append([mu for _, _, mu, _ in sols])
        if "rope" in ts.rows:
            out.setdefault("rope_tension", []).append(-lam[ts.rows["rope"]][0])
        if ts.ropes:
            out.setdefault("rope_tensions", []).append(
                [r.tension(float(np.real(r.length(Q)[0]))) for unit in ts.ropes for r in unit])
        # the luffing angle: elevation of boom 1's axis e_s at its root section, rad
        es = np.real(cardan_frame(*lefts[0](Q)[2]) @ basis.T)[2]
        out["luffing_angle"].append(math.atan2(es[2], math.hypot(es[0], es[1])))
        if ts.i_phi is not None:
            out.setdefault("slew_angle", []).append(float(np.real(Q[ts.i_phi])))
        if ts.hoist is not None:
            _payload_outputs(ts, tk, Q, r, out)
        if ts.ground is not None:
            out.setdefault("payload_ground_force", []).append(ts.ground.force(Q, Qd))
        out["inner_contact_s"].append(Q[ts.s2_index])
        out["outer_contact_s"].append(Q[ts.s3_index[1:]])
        out["constraint_violation"].append(np.max(np.abs(m.constraint_violation(tk, z, zd))))
    if stop.error is not None:        # cut by the budget or Ctrl-C: the output times reached
        t, ys = np.asarray(t)[:len(out["tip_position"])], np.asarray(ys)[:len(out["tip_position"])]
    outputs = {k: np.array(v, dtype=float) for k, v in out.items()}
    # the integrated states at the output times (the energy check of the result re-evaluates
    # the energies from them, simulate.telescopic_energy_check); no replay geometry and no
    # section forces for outputs cut short by the budget (its time is spent)
    if stop.error is None:
        outputs.update(_replay_geometry(ts, t, ys))
        outputs.update(_section_outputs(ts, t, ys))
    outputs["state"] = np.asarray(ys, dtype=float)
    stats["n_dof"] = int(n)
    if m.uncompiled_effects:
        stats["uncompiled_effects"] = m.uncompiled_effects
    return stop.finish(Result(t, outputs, stats, scene if scene is not None else p.summary(),
                              error))
