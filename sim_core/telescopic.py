"""Telescopic boom system of Zhao-Qi-Wang 2024 (Sections 2, 5-7, 9): nested flexible booms with
moving contact constraints, luffing cylinder, telescopic cylinder, ropes and payload.

Contact regions carry their moment by the scene's ``contact.moment_model``: ``rigid`` (Section 6
as printed: the sections' Cardan angles coincide), ``seat`` (the bending angles tied by an
elastic seat, point_effects.SliderSeat) or ``couple`` (the bending angles free, so an overlap
carries its moment as a force couple between its two regions).  The friction of Section 8.3
takes its normal load from ``contact.friction_load`` (sim_core.contact_friction).

Booms are numbered from the outermost (1).  Each boom is two moving-node spline elements split
at its outer contact point (boom 1: at the luffing point s = L_h, a material point, Eq. 50);
the end nodes are material points (s_1,k = 0, s_4,k = L_k, Eq. 50).  The inner contact point of
boom k < N is not a node: its arc-length coordinate s_2,k is an extra generalized coordinate
(Section 5) and the point is interpolated with Eq. 6.

Constraint I (Eq. 47): centroid and Cardan angles of boom k+1's left end = those of boom k at
s_2,k.  Constraint II (Eq. 48): boom k's right end = boom k+1's outer-contact node s_3,k+1.
Their multipliers are the contact force/moment resultants; the generalized forces they exert
on s_2,k and s_3,k+1 are the contact multipliers eta of Section 7 (zero without friction).

Mounting and drives (SCENARIOS A2-A4, proposed defaults): revolute pivot D1 about Y (rigid
offset from boom 1's left section), luffing cylinder = massless rigid rod D2-D3 of constant
length (its multiplier is the cylinder force), telescopic cylinder = massless actuator imposing
the distance L_s(t) between the left-section centres of booms 1 and 2, elastic tension-only
extraction and retraction ropes over point pulleys, payload point mass at boom N's tip.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .assemble import reference_basis
from .beam.moving_node_beam import Beam, BeamSection
from .constraints import (NonlinearConstraint, angle_coincidence, distance_driver, fixed_point,
                          material_point, point_coincidence, rope_length)
from .drive_profiles import CubicSmoothstepSchedule
from .effects import Effect, Elasticity, Gravity, Inertia, StressFilter
from .model import Model, boundary_condition, fix_material_coordinate
from .point_effects import PointMass, RopeDrive, SliderSeat
from .validation.closed_form import luffing_geometry, static_luffing_forces

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


def boom_section(k: int, p: TelescopicParams) -> BeamSection:
    EI, GJ, m = p.sections[min(k, len(p.sections) - 1)]
    scale = p.E / 2.1e11                   # case 9.1: stiffnesses x10, masses unchanged
    I = EI / 2.1e11                         # second moment from Table 2
    # mass-centre offset along e_b (Table 2), a rigid offset in inertia and gravity (A1)
    zc = p.z_c[min(k, len(p.z_c) - 1)] if p.mass_centre_offset else 0.0
    return BeamSection(EA=p.E * m / p.rho, GJ=GJ * scale, EI_t=EI * scale, EI_b=EI * scale,
                       rhoA=m, J_s=2 * p.rho * I, J_t=p.rho * I, J_b=p.rho * I, z_c=zc)


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


def build_telescopic(p: TelescopicParams) -> TelescopicSystem:
    theta = np.radians(p.luffing_angle_deg)
    geo = luffing_geometry(theta)
    e = np.asarray(geo.e_s, float)
    O1 = np.asarray(geo.origin, float)
    L, N, Ls = p.boom_length, p.n_booms, p.stroke0
    G = reference_basis(e)
    beams = []
    for k in range(N):
        split = p.L_h if k == 0 else L - Ls
        beams.append(Beam(f"boom{k + 1}", L, boom_section(k, p), (0.0, split, L),
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
        from .assemble import _no_torsion
        lin.append(_no_torsion(offsets, beams))
    model = Model(beams, effects, [], lin, n_extra=N - 1, baumgarte=p.baumgarte)

    # initial straight configuration: boom k's left section a_k = k L_s along boom 1 (A3)
    Q0 = np.zeros(model.n_coords)
    for k, b in enumerate(beams):
        Q0[offsets[k]:offsets[k] + b.n_coords] = b.straight_coordinates(O1 + k * Ls * e, e)
    n_beam = int(sum(b.n_coords for b in beams))
    s2_index = [n_beam + k for k in range(N - 1)]
    Q0[s2_index] = Ls
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
    D1 = mp(0, s_fixed=0.0, offset=(-0.956, 0.0, 0.556))
    add(point_coincidence("pivot", D1, fixed=geo.d1))
    root = mp(0, s_fixed=0.0)
    add(angles("pivot_axis", root, fixed=[0.0, 0.0, 0.0], keep=(1, 2)))
    # luffing cylinder: rigid massless rod D2-D3 held at its initial length (A2)
    D3 = mp(0, s_fixed=p.L_h, offset=(0.0, 0.0, -0.556))
    Lc = float(geo.cylinder_length)
    add(distance_driver("luffing_cylinder", D3, fixed_point(geo.d2), lambda t: (Lc, 0.0, 0.0)))
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
        contact_region(f"I_{k + 1}{k + 2}", mp(k + 1, s_fixed=0.0), mp(k, s_index=s2_index[k]))
        contact_region(f"II_{k + 1}{k + 2}", mp(k, s_fixed=L), mp(k + 1, s_index=s3_index[k + 1]))
    # telescopic cylinder between the left sections of booms 1 and 2 (A3, A4)
    sched = CubicSmoothstepSchedule(v_max=p.v_max, t_ramp=p.t_ramp, t_hold_end=p.t_hold_end,
                                    sign=p.direction, s0=Ls)
    def cylinder_length(t):                        # one sample of the schedule: (L, L', L'')
        smp = sched.sample(t)
        return smp.s, smp.v, smp.a

    add(distance_driver("telescopic_cylinder", mp(1, s_fixed=0.0), mp(0, s_fixed=0.0),
                        cylinder_length))
    model.nonlinear = cons
    rows, i = {}, 0
    for nm, m in names:
        rows[nm] = slice(i, i + m)
        i += m

    tip = mp(N - 1, s_fixed=L)
    pe = []
    if p.payload > 0:
        pe.append(PointMass(tip, p.payload, g_vec if p.gravity > 0 else None))
    if N >= 3:
        ext = [mp(0, s_fixed=0.0, offset=(0.05, 0, 0)), mp(1, s_fixed=9.0),
               mp(2, s_fixed=0.0, offset=(-0.04, 0, 0))]
        ret = [mp(0, s_fixed=L, offset=(0.68, 0, 0)), mp(1, s_fixed=0.66),
               mp(2, s_fixed=0.0, offset=(0.64, 0, 0))]
        if p.rope_elasticity:
            EA = p.rope_EA * p.E / 2.1e11
            rope = RopeDrive(ext, EA, 1.0, name="extraction_rope")
            ell_e = float(rope.length(Q0)[0])
            # unstretched length from the static rope tension T = (m3 + m_p) g sin(theta) (C7)
            T0 = static_luffing_forces(theta, Ls, p.payload, g=p.gravity).rope_tension
            rope.L0 = ell_e / (1.0 + T0 / EA)
            retr = RopeDrive(ret, EA, 1.0, name="retraction_rope")
            retr.L0 = float(retr.length(Q0)[0])         # just taut
            pe += [rope, retr]
        else:
            # effects.rope_elasticity = false: one inextensible bilateral rope (its multiplier's
            # sign tells which of the two ropes is taut); nothing of the rope springs is computed
            ell_e = float(np.real(rope_length("rope", ext, 0.0).evaluate(Q0)[0][0]))
            c = rope_length("rope", ext, ell_e)
            cons.append(c)
            rows["rope"] = slice(i, i + 1)
            model.nonlinear = cons
    model.point_effects = pe + list(seats.values())
    ts = TelescopicSystem(model, Q0, sched, s2_index, s3_index, rows, tip, p,
                          angle_rows=angle_rows, seats=seats)
    # Section 8 contact analysis: the slider-spring distribution needs the paper's three-boom
    # slider geometry; with friction off it is only evaluated for the outputs (it does not act
    # on the motion), with contact_distribution off it is not built at all
    if p.contact_distribution is None:
        p.contact_distribution = N == 3
    if p.contact_distribution and N != 3:
        raise ValueError(f"contact_distribution with n_booms = {N}: the slider geometry is the "
                         "paper's three-boom section (allowed: 3)")
    if p.friction and p.friction_load == "springs" and not p.contact_distribution:
        raise ValueError("friction_load = 'springs' needs contact_distribution (the slider "
                         "springs); allowed: friction_load = 'resultant'")
    if p.friction or p.contact_distribution:
        from .contact_friction import ContactFriction
        ts.contact = ContactFriction(ts, p.mu_static, p.mu_dynamic, p.v_eps, p.spring_k0,
                                     p.spring_eps, distribution=p.contact_distribution,
                                     slider_half_width=0.5 * p.slider_width,
                                     springs_per_quarter=p.springs_per_quarter,
                                     radial_gap=p.radial_gap, friction_load=p.friction_load)
    if p.friction:
        model.multiplier_forces = [ts.contact]
    return ts


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
    """Static equilibrium at t = 0 with the rope lengths of SCENARIOS A3: the retraction rope is
    'just taut' *at the equilibrium*: it is slack while the equilibrium is solved, then its
    unstretched length is set to its length there (zero tension, no change of the equilibrium).
    Returns (z, lambda).

    Two-rope statics (our reading): when the static extraction-rope tension T0 =
    (m3 + m_p) g sin(theta) (C7) is not clearly in the rope's stiff branch (T0 <= (EA/L0) *
    slack_width, e.g. payload 0 at 0 deg), both tension-only ropes would sit at their kink with
    zero axial stiffness and boom 3's axial position is undetermined (Newton stalled at |r| ~
    0.3 N).  Then the equilibrium is solved with the extraction rope *bilateral* (a linear spring
    of either sign: the pair of opposing ropes acts as one rope), and afterwards the rope that
    carries the load is given that tension and the other one is made just taut at the start of
    its stiff branch (tension (EA/L0) slack_width / 2, ~5 N at the paper's EA); a final
    tension-only Newton from there leaves both ropes taut and the equilibrium well posed.

    Where Newton does not converge, the statics trace the equilibrium under the weight by load
    continuation (:func:`sim_core.statics.load_continuation`).  At low luffing angles the
    paper's luffing geometry has a short cylinder lever (0.23 m at 0 deg), and soft booms
    (E = 2.1e10 Pa) at 0 deg reach a limit point at 0.29 x their own weight: then
    :class:`~sim_core.errors.NoStaticEquilibrium` is raised, naming the angle and the lever."""
    from .errors import NoStaticEquilibrium
    try:
        return _initial_equilibrium(ts, t)
    except NoStaticEquilibrium as exc:
        # the statics' load continuation found a limit point below the full weight: say why
        import math
        from .validation.closed_form import luffing_geometry
        p = ts.params
        lever = luffing_geometry(math.radians(p.luffing_angle_deg)).lever
        raise NoStaticEquilibrium(exc.t, exc.load_factor_max, exc.path, reason=(
            f"no static equilibrium at luffing angle {p.luffing_angle_deg:g} deg (E = {p.E:.3g} "
            f"Pa, payload {p.payload:g} kg): the equilibrium path under the weight turns back at "
            f"a limit point at {exc.load_factor_max:.3g} x the full weight.  The luffing "
            f"cylinder's lever about the pivot D1 is {lever:.3f} m at this angle (0.714 m at "
            "60 deg) and the booms' deflection shortens it further; the limit load scales with "
            "E (docs/model.md, 'Initial state and statics')")) from exc


def _initial_equilibrium(ts: TelescopicSystem, t: float):
    from .statics import constrained_static_equilibrium
    m = ts.model
    z0, _ = m.reduced_state(t, ts.Q0, np.zeros_like(ts.Q0))
    ropes = {pe.name: pe for pe in m.point_effects if isinstance(pe, RopeDrive)}
    ext, retr = ropes.get("extraction_rope"), ropes.get("retraction_rope")
    if retr is not None:
        retr.L0 = np.inf
    if ext is None or retr is None:
        return constrained_static_equilibrium(m, z0, t)

    def length(rope, z):
        Q, _ = m.full_state(t, z, np.zeros_like(z))
        return float(rope.length(Q)[0])

    def taut_L0(rope, ell, T):
        """Unstretched length with tension-only tension T >= (EA/L0) s / 2 at length ell:
        (EA/L0)(ell - L0 - s/2) = T."""
        return rope.EA * (ell - 0.5 * rope.slack_width) / (rope.EA + T)

    k_e = ext.EA / ext.L0
    if ext.tension(length(ext, z0)) > k_e * ext.slack_width:       # stiff branch: as A3 says
        z, lam = constrained_static_equilibrium(m, z0, t)
        retr.L0 = length(retr, z)
        return z, lam
    ext.bilateral = True
    try:
        z, lam = constrained_static_equilibrium(m, z0, t)
        ell_e = length(ext, z)
        T = ext.tension(ell_e)
    finally:
        ext.bilateral = False
    s = ext.slack_width
    ell_r = length(retr, z)
    if T >= k_e * s:
        # the extraction rope carries T in its stiff branch: same forces, nothing to re-solve
        ext.L0 = taut_L0(ext, ell_e, T)
        retr.L0 = ell_r
        return z, lam
    # near zero or compressive: both ropes taut (the net pull T shared as T_min + max(+-T, 0))
    T_min = 0.5 * k_e * s
    ext.L0 = taut_L0(ext, ell_e, T_min + max(T, 0.0))
    retr.L0 = taut_L0(retr, ell_r, T_min + max(-T, 0.0))
    return constrained_static_equilibrium(m, z, t)


def simulate_telescopic(p: TelescopicParams, t_end: float = 20.0, n_output: int = 201,
                        rtol: float = 1e-6, atol: float = 1e-7, progress=None,
                        solver: dict | None = None):
    """Run the telescopic scene from its static equilibrium and return a Result with the
    public outputs of the telescopic contract (tip kinematics, piston stroke, cylinder forces,
    contact-point resultants, contact coordinates, constraint violation; with friction also the
    normal force of every slider spring per region (I_12, II_12, I_23, II_23; springs ordered arc
    by arc P1, P2, P3 as in sim_core.contact) and the signed friction coefficient per region).
    ``solver``: a validated [solver] table (:func:`sim_core.scene.solver_table`); its entries
    (method, max_step, max_wall_s, ...) take precedence over the keyword arguments."""
    from .simulate import integrate, run_with_partial
    sol = {"t_end": t_end, "rtol": rtol, "atol": atol, "n_output": n_output, **(solver or {})}
    if not p.flexible:
        from .rigid_telescopic import RigidTelescopic
        return RigidTelescopic(p).simulate(sol["t_end"], sol["n_output"], sol["rtol"], sol["atol"])
    ts = build_telescopic(p)
    m = ts.model
    z0, _ = initial_equilibrium(ts)
    y0 = np.concatenate([z0, 0 * z0])
    from .simulate import telescopic_energy_check
    return run_with_partial(
        lambda: integrate(m, y0, sol["t_end"], sol, progress),
        lambda t, ys, stats, err: _telescopic_result(ts, t, ys, stats, err),
        check=lambda res: telescopic_energy_check(ts, res))


def _telescopic_result(ts: TelescopicSystem, t, ys, stats, error):
    from .result import Result
    m, p = ts.model, ts.params
    n = m.n_dof
    N = p.n_booms
    out = {k: [] for k in ("tip_position", "tip_velocity", "tip_acceleration", "piston_stroke",
                           "luffing_cylinder_force", "telescopic_cylinder_force",
                           "contact_point_forces", "inner_contact_s", "outer_contact_s",
                           "constraint_violation")}
    from .contact_friction import region_multipliers, section_reaction
    basis = m.beams[0].reference_basis
    left1 = material_point(m, 0, s_fixed=0.0)
    left2 = material_point(m, 1, s_fixed=0.0)
    for tk, y in zip(t, ys):
        z, zd = y[:n], y[n:]
        zdd, lam = m.accelerations_and_multipliers(tk, z, zd)
        Q, Qd = m.full_state(tk, z, zd)
        Qdd = m._lift(tk, zdd, 2)
        r, J, _, _ = ts.tip(Q)
        _, Jc, _, _ = ts.tip(Q + 1e-20j * Qd)
        out["tip_position"].append(r)
        out["tip_velocity"].append(J @ Qd)
        out["tip_acceleration"].append(J @ Qdd + (Jc @ Qd).imag / 1e-20)
        out["piston_stroke"].append(np.linalg.norm(left2(Q)[0] - left1(Q)[0]) - p.stroke0)
        out["luffing_cylinder_force"].append(lam[ts.rows["luffing_cylinder"]][0])
        out["telescopic_cylinder_force"].append(lam[ts.rows["telescopic_cylinder"]][0])
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
                out.setdefault("slider_contact_forces", []).append(
                    [sol.normal_force for _, _, _, sol in sols])
            if p.friction:
                out.setdefault("friction_coefficient", []).append([mu for _, _, mu, _ in sols])
        if "rope" in ts.rows:
            out.setdefault("rope_tension", []).append(-lam[ts.rows["rope"]][0])
        out["inner_contact_s"].append(Q[ts.s2_index])
        out["outer_contact_s"].append(Q[ts.s3_index[1:]])
        out["constraint_violation"].append(np.max(np.abs(m.constraint_violation(tk, z, zd))))
    outputs = {k: np.array(v, dtype=float) for k, v in out.items()}
    # the integrated states at the output times (the energy check of the result re-evaluates
    # the energies from them, simulate.telescopic_energy_check)
    outputs["state"] = np.asarray(ys, dtype=float)
    stats["n_dof"] = int(n)
    scene = {"name": "telescopic", "params": {k: v for k, v in p.__dict__.items() if k != "sections"}}
    return Result(t, outputs, stats, scene, error)
