"""Folding long-boom manipulator (SIMULTECH 2020, "folding long-boom manipulator";
inputs in docs/model.md#input-folding): two flexible booms, turntable, two hydraulic cylinders
(barrel + rod), two links; luffing of boom 1, slewing by 90 deg, unfolding of boom 2.

Bodies (docs/model.md#input-folding-bodies, PD)
  * booms 1, 2: the geometrically exact beam :class:`sim_core.physics.beam.moving_node_beam.Beam` with
    fixed nodes (material ends s = 0, L held by linear rows), one spline element of 8
    sub-elements, 3 Gauss points, solid round section r = 0.15 m, m' = 544.6 kg/m,
    E = 2.11e11 Pa, nu = 0.3 (EA = 1.49e10 N, EI = 8.39e7 N m^2, GJ = 6.45e7 N m^2),
    rotary inertia rho I per length;
  * turntable: coordinate phi about the vertical slew axis X (prescribed, PD; free for the
    angular-momentum check), inertia ``turntable_inertia`` (not in the paper: PD of this module,
    irrelevant while the slew is prescribed);
  * barrel and rod of each cylinder (10 kg each, solid cylinders r = 0.05 / 0.035 m, length
    0.6 x retracted pin distance), links a, b (61.5 kg/m solid rods r = 0.05 m): rigid bodies
    (:mod:`sim_core.physics.rigid_body`).

Reduced parametrization (allowed simplification, stated): the rigid bodies have in-plane
coordinates (u, v, theta) in the luffing plane carried by the turntable (real 3-D rotation
S(phi) about X; the plane goes from XY to XZ for phi = -90 deg).  The booms stay full 3-D beams
and may deflect out of the plane.  Luffing-plane coordinates (u, v) -> global: e_u = -Y
(towards boom 1's tip at t = 0), e_v = X (up), normal n = Z; gravity -X (PD).

Joints (SIMULTECH 2020 Section 2.1, Eq. 7; Baumgarte Eq. 8 with xi1 = xi2 = 10 1/s in
:class:`sim_core.model.model.Model`)
  * hinge A (turntable - boom 1 foot) and hinge B (boom 1 tip - boom 2 foot): revolute =
    3 point rows + 2 axis rows (:func:`sim_core.physics.rigid_body.revolute_axis`);
  * rigid - rigid pins (cylinder 1 base on the turntable, the three bodies at E): 2 in-plane
    rows (:func:`planar_pin`; the out-of-plane row is identically zero);
  * rigid - boom pins (cylinder 1 rod on boom 1, cylinder 2 barrel at C, link a at F, link b at
    G): 3 point rows (the planar rigid chain holds the boom point in the plane; the section
    rotation at these pins is left to the beam - spherical on the boom side);
  * barrel - rod: prismatic = the rod's frame reads the barrel's angle coordinate (the rod has
    coordinates (u, v) only) + lateral row.
Cylinders are spring-dampers on the pin distance s (docs/model.md#input-folding-drive, PD):
    F = k (s - s_ref) + c (s_dot - v(t)),  s_ref = s_ref(0) + int v dt,
v(t) from Eq. 52 (:class:`sim_core.physics.drive_profiles.Eq52Profile`); s_ref(0) from the static
equilibrium at t = 0 (solved with the cylinders held at their retracted length).

Departures from the PDs
  * Cardan reference basis: the existing Beam has a constant reference basis; a basis "fixed to
    the turntable" would rotate with phi.  We use one global basis for both booms with
    g1 = (0, 1, 1)/sqrt 2, which is >= 45 deg away from the luffing plane for every slew angle
    in [-90, 0] deg (so e_s never approaches the singular direction g1), and g3 chosen so that
    no boom direction of the scenario comes near -g3 (the cut of the complex-safe atan2).
  * Stage 1 ends when cylinder 1 has travelled the PD stroke 1.328 m (reference length; the
    boom reaches ~60 deg up to the static spring compression).
  * Boom rest (not in the paper or the PDs): with the PD section (EI = 8.39e7 N m^2) the booms
    are soft -- boom 1's tip sags ~0.16 m under gravity -- and the folded boom 2, held only by
    the link chain at G (0.4 m from its hinge), loads the four-bar towards its toggle: the
    static solution under gravity passes a limit point near 90 % of g and snaps to a boom 2
    hanging ~7 m down (found with load continuation).  A real folding crane rests the folded
    boom on the other one, so :class:`BoomRest` (compression-only spring-damper, k = 1e7 N/m,
    c = 1e4 N s/m, C1 onset over 1 mm) carries boom 2 at its s = 11 m on boom 1's s = 1 m; it
    lifts off when cylinder 2 unfolds boom 2.  rest_k = 0 removes it.
  * Static equilibrium: :func:`scaled_static_equilibrium` (symmetrically scaled saddle-point
    Newton) instead of :func:`sim_core.model.statics.constrained_static_equilibrium`, whose
    unscaled matrix is numerically singular here (cond ~ 1e19).

Cost: with h = 0.005 s the filter bounds |lambda| <= ~2.45/h, so RK45 takes steps of
1.6e-3 ... 6e-3 s (stability-limited); the scene runs BDF, whose steps (~8 ms) follow rtol, with
the structured state Jacobian (:mod:`sim_core.model.state_jacobian`), which differences each
constraint and rigid-body term only in the coordinates of its frames (their ``coords``).  Each
linear row fixes one coordinate (a rod shares its barrel's angle coordinate instead of a row
theta_rod = theta_barrel), so the reduction is a signed selection and the model assembles block by
block and solves the saddle-point system by block elimination over the two booms.  The default
tests use 2 sub-elements per boom and compressed stages (run times: docs/performance.md,
benchmarks/results/folding_speed.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from sim_core import run_control
from sim_core.model.boundary import LinearConstraint, boundary_condition
from sim_core.model.model import Model
from sim_core.physics.beam.moving_node_beam import Beam, BeamSection
from sim_core.physics.constraints import (
    NonlinearConstraint,
    distance_driver,
    point_coincidence,
)
from sim_core.physics.drive_profiles import Eq52Profile
from sim_core.physics.effects import Effect, Elasticity, Gravity, Inertia, StressFilter
from sim_core.physics.rigid_body import (
    CoordinateInertia,
    RigidBody,
    SpringDamperActuator,
    beam_frame,
    cylinder_inertia,
    planar_body_frame,
    planar_pin,
    point_coords,
    prismatic_offset,
    revolute_axis,
    turntable_frame,
)

SLEW_AXIS = np.array([1.0, 0.0, 0.0])                       # vertical (PD gravity -X)
PLANE_BASIS = np.column_stack([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # e_u, e_v, n


def boom_reference_basis() -> np.ndarray:
    """Cardan reference basis (columns g1, g2, g3) shared by both booms (see module docstring)."""
    g1 = np.array([0.0, 1.0, 1.0]) / np.sqrt(2.0)
    m = np.array([0.0, 1.0, -1.0]) / np.sqrt(2.0)
    psi = np.radians(55.0)
    g3 = np.cos(psi) * m + np.sin(psi) * SLEW_AXIS
    g2 = np.cross(g3, g1)
    return np.column_stack([g1, g2, g3])


@dataclass
class FoldingParams:
    """Inputs of the folding-boom scene (SI units; defaults = docs/model.md#input-folding)."""

    boom_length: float = 12.0               # m
    boom_radius: float = 0.15               # m
    boom_mass_per_length: float = 544.6     # kg/m
    E: float = 2.11e11                      # Pa
    nu: float = 0.3
    n_nodes: int = 9                        # 8 sub-elements per boom
    n_gauss: int = 3
    hinge_A: tuple = (0.0, 2.0)             # (u, v) m
    cyl1_base: tuple = (0.5, 0.6)           # (u, v) m
    cyl1_pin: tuple = (3.0, -0.35)          # (along boom 1 from A, offset normal) m
    cyl2_base: tuple = (-5.5, 0.9)          # C in boom-1 axes at B (xi, eta) m
    link_a_base: tuple = (-1.1, 0.2)        # F in boom-1 axes at B (xi, eta) m
    link_b_end: tuple = (0.4, -0.45)        # G in boom-2 axes at B (x, y) m
    link_a_length: float = 0.9              # m
    link_b_length: float = 1.3              # m
    link_mass_per_length: float = 61.5      # kg/m
    link_radius: float = 0.05               # m
    barrel_mass: float = 10.0               # kg
    rod_mass: float = 10.0                  # kg
    barrel_radius: float = 0.05             # m
    rod_radius: float = 0.035               # m
    cylinder_length_factor: float = 0.6     # barrel, rod length / retracted pin distance
    k: float = 5e7                          # N/m
    c: float = 4e5                          # N s/m
    t1: float = 3.0                         # s (Eq. 52)
    t2: float = 6.0
    t3: float = 3.0
    stage_starts: tuple = (0.0, 15.0, 30.0)  # s: luff, slew, unfold
    cyl1_stroke: float = 1.328              # m
    slew_angle_deg: float = -90.0           # deg about +X (clockwise seen from above)
    cyl2_stroke: float = 1.242              # m
    gravity: float = 9.81                   # m/s^2 along -X
    filter_h: float = 0.005                 # s, 0 = raw model
    baumgarte: tuple = (10.0, 10.0)         # xi1, xi2 1/s
    turntable_inertia: float = 5000.0       # kg m^2 about X (PD of this module)
    slew_prescribed: bool = True            # False: phi free (zero drive torque)
    initial_slew_rate: float = 0.0          # rad/s (only with slew_prescribed = False)
    rigid_cylinders: bool = False           # True: pin distance = s_ref(t) exactly (massless)
    rest_k: float = 1e7                     # N/m, boom rest (0 = none), see BoomRest
    rest_c: float = 1e4                     # N s/m
    rest_s: tuple = (1.0, 11.0)             # rest point on boom 1, contact point on boom 2 (s, m)
    rest_width: float = 1e-3                # m, C1 smoothing of the contact onset

    def section(self) -> BeamSection:
        r, m = self.boom_radius, self.boom_mass_per_length
        A = np.pi * r ** 2
        rho = m / A
        I = np.pi * r ** 4 / 4.0
        G = self.E / (2.0 * (1.0 + self.nu))
        return BeamSection(EA=self.E * A, GJ=G * 2 * I, EI_t=self.E * I, EI_b=self.E * I,
                           rhoA=m, J_s=2 * rho * I, J_t=rho * I, J_b=rho * I)

    def v0(self, travel: float) -> float:
        """Eq. 52 hold rate for a travel: travel / (t1/2 + t2 + t3/2)."""
        return abs(travel) / (0.5 * self.t1 + self.t2 + 0.5 * self.t3)

    def profiles(self):
        """(cylinder 1, slew, cylinder 2) Eq. 52 profiles (offset 0)."""
        mk = lambda travel, t0: Eq52Profile(v0=self.v0(travel), t1=self.t1, t2=self.t2,
                                            t3=self.t3, t_start=t0,
                                            sign=1 if travel >= 0 else -1)
        s0, s1, s2 = self.stage_starts
        return (mk(self.cyl1_stroke, s0), mk(np.radians(self.slew_angle_deg), s1),
                mk(self.cyl2_stroke, s2))


def _sampler(profile):
    """t -> (s, v, a) of a profile with the last time cached (the RHS asks several times)."""
    last = [None, None]

    def f(t):
        if last[0] != t:
            smp = profile.sample(float(t))
            last[:] = [t, (smp.s, smp.v, smp.a)]
        return last[1]
    return f


# -- closed-form linkage geometry in the luffing plane -------------------------------------------

def _rot2(v, a):
    c, s = np.cos(a), np.sin(a)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def linkage_points(p: FoldingParams, theta1: float, rel: float) -> dict:
    """Plane points (u, v) of the mechanism for boom-1 angle theta1 (from horizontal) and
    boom-2 relative angle rel (180 deg folded), booms rigid
    (docs/model.md#input-folding-geometry)."""
    A = np.asarray(p.hinge_A, float)
    d1 = np.array([np.cos(theta1), np.sin(theta1)])
    n1 = _rot2(d1, np.pi / 2)
    L = p.boom_length
    B = A + L * d1
    P1 = A + p.cyl1_pin[0] * d1 + p.cyl1_pin[1] * n1
    C = B + p.cyl2_base[0] * d1 + p.cyl2_base[1] * n1
    F = B + p.link_a_base[0] * d1 + p.link_a_base[1] * n1
    d2 = _rot2(d1, rel)
    n2 = _rot2(d2, np.pi / 2)
    G = B + p.link_b_end[0] * d2 + p.link_b_end[1] * n2
    dd = G - F
    D = np.linalg.norm(dd)
    la, lb = p.link_a_length, p.link_b_length
    a = (la ** 2 - lb ** 2 + D ** 2) / (2 * D)
    h2 = la ** 2 - a ** 2
    if h2 < 0:
        raise ValueError(f"links cannot be assembled at rel = {np.degrees(rel):.1f} deg")
    mid = F + a * dd / D
    perp = _rot2(dd / D, np.pi / 2)
    E = max((mid + np.sqrt(h2) * perp, mid - np.sqrt(h2) * perp), key=lambda e: (e - B) @ n1)
    return {"A": A, "B": B, "P1": P1, "base1": np.asarray(p.cyl1_base, float), "C": C, "F": F,
            "G": G, "E": E, "d1": d1, "n1": n1, "d2": d2, "n2": n2,
            "tip": B + L * d2}


def cylinder_lengths(p: FoldingParams, theta1: float, rel: float) -> tuple[float, float]:
    pts = linkage_points(p, theta1, rel)
    return (float(np.linalg.norm(pts["P1"] - pts["base1"])),
            float(np.linalg.norm(pts["E"] - pts["C"])))


def plane_to_global(uv, phi: float = 0.0) -> np.ndarray:
    from sim_core.physics.rigid_body import rot_axis
    u, v = uv
    return rot_axis(SLEW_AXIS, phi) @ (PLANE_BASIS @ np.array([u, v, 0.0]))


@dataclass
class BoomRest:
    """Compression-only boom rest (departure from the PDs, see module docstring): the contact
    point b of boom 2 rests on the rest point a of boom 1.  Gap g = (r_b - r_a) . nu with nu the
    body-a normal (boom 1's in-plane normal, section components ``nu_a``); contact force
    f = k ramp(-g) + c max(-g_dot, 0) [ramp C1 over ``width``] pushes along +nu when g < 0.
    Generalized force F += f dg/dQ,  dg/dQ = nu . (J_b - J_a) + (nu x d) . W_a."""

    a: object
    b: object
    nu_a: np.ndarray
    k: float
    c: float
    width: float = 1e-3
    name: str = "boom_rest"

    def coords(self, Q):
        """Coordinates the contact force depends on (the two points' frames')."""
        return point_coords(self, (self.a, self.b), Q)

    def velocity_coords(self, Q):
        """Coordinates whose rates enter the force (the damper's gap rate)."""
        return self.coords(Q)

    def gap(self, Q):
        ra, Ja, Ra, Wa = self.a(Q)
        rb, Jb, _, _ = self.b(Q)
        nu = Ra @ self.nu_a
        d = rb - ra
        nxd = np.array([nu[1] * d[2] - nu[2] * d[1], nu[2] * d[0] - nu[0] * d[2],
                        nu[0] * d[1] - nu[1] * d[0]])          # nu x d
        return d @ nu, nu @ (Jb - Ja) + nxd @ Wa

    def force(self, Q, Qd):
        g, dg = self.gap(Q)
        pen, w = -float(np.real(g)), self.width
        if pen <= 0:
            return 0.0, dg
        f = self.k * (pen - 0.5 * w) if pen >= w else self.k * 0.5 * pen * pen / w
        gd = float(np.real(dg @ Qd))
        f += self.c * max(-gd, 0.0) * min(pen / w, 1.0)
        return f, dg

    def local(self, t, Q, Qd, mass=True):
        """(idx, None, Fe): the contact force f dg/dQ on the two points' coordinates."""
        f, dg = self.force(Q, Qd)
        idx = self.coords(Q)
        idx = np.arange(len(Q)) if idx is None else idx
        return idx, None, f * np.real(dg[idx])

    def add(self, t, Q, Qd, M, F):
        idx, _, Fe = self.local(t, Q, Qd)
        F[idx] += Fe


# -- assembly --------------------------------------------------------------------------------------

@dataclass
class FoldingSystem:
    model: Model
    Q0: np.ndarray
    params: FoldingParams
    i_phi: int
    bodies: dict                      # name -> index of u in Q
    frames: dict                      # named frame functions
    cylinders: list                   # SpringDamperActuator (or None when rigid)
    rows: dict = field(default_factory=dict)
    profiles: tuple = ()
    s_retracted: tuple = ()           # geometric pin distances at t = 0, m


def build_folding(p: FoldingParams) -> FoldingSystem:
    L = p.boom_length
    G = boom_reference_basis()
    sec = p.section()
    beams = [Beam(f"boom{k + 1}", L, sec, (0.0, L), n_nodes=p.n_nodes, n_gauss=p.n_gauss,
                  reference_basis=G) for k in range(2)]
    offsets = np.cumsum([0] + [b.n_coords for b in beams])[:-1]
    n_beam = int(sum(b.n_coords for b in beams))
    i_phi = n_beam
    # plane coordinates (u, v, theta) of each body; a rod has (u, v) and shares its barrel's
    # theta (the angle part of the prismatic joint), so every linear row fixes one coordinate
    names = ("barrel1", "rod1", "barrel2", "rod2", "link_a", "link_b")
    sizes = [2 if nm.startswith("rod") else 3 for nm in names]
    bodies = dict(zip(names, (n_beam + 1 + np.cumsum([0] + sizes[:-1])).tolist()))
    theta = {nm: bodies[nm.replace("rod", "barrel")] + 2 for nm in names}
    n_extra = 1 + sum(sizes)
    g_vec = np.array([-p.gravity, 0.0, 0.0])
    effects: list[Effect] = [Inertia(), Elasticity()]
    if p.filter_h > 0:
        effects.append(StressFilter(p.filter_h))           # SIMULTECH 2020 Eq. 53
    if p.gravity > 0:
        effects.append(Gravity(g_vec))

    # fixed nodes: material end coordinates s = 0, L of both booms (linear rows)
    lin = [boundary_condition(offsets, beams, ib, end, "free")
           for ib in range(2) for end in ("left", "right")]
    profs = p.profiles()
    if p.slew_prescribed:
        sp = _sampler(profs[1])
        lin.append(LinearConstraint("slew", [{i_phi: 1.0}], lambda t: np.array([sp(t)[0]]),
                                    lambda t: np.array([sp(t)[1]]),
                                    lambda t: np.array([sp(t)[2]])))
    model = Model(beams, effects, [], lin, n_extra=n_extra, baumgarte=tuple(p.baumgarte))
    N = model.n_coords

    # initial configuration: boom 1 horizontal along e_u, boom 2 folded back onto it
    pts = linkage_points(p, 0.0, np.pi)
    Q0 = np.zeros(N)
    A_g, B_g = plane_to_global(pts["A"]), plane_to_global(pts["B"])
    e_u = PLANE_BASIS[:, 0]
    Q0[offsets[0]:offsets[0] + beams[0].n_coords] = beams[0].straight_coordinates(A_g, e_u)
    Q0[offsets[1]:offsets[1] + beams[1].n_coords] = beams[1].straight_coordinates(B_g, -e_u)
    s1_0 = float(np.linalg.norm(pts["P1"] - pts["base1"]))
    s2_0 = float(np.linalg.norm(pts["E"] - pts["C"]))

    def place(name, origin, towards):
        d = towards - origin
        Q0[bodies[name]:bodies[name] + 2] = origin
        Q0[theta[name]] = np.arctan2(d[1], d[0])     # a rod's is its barrel's (same direction)
        return float(np.linalg.norm(d))

    place("barrel1", pts["base1"], pts["P1"])
    place("rod1", pts["P1"], pts["P1"] + (pts["P1"] - pts["base1"]))
    place("barrel2", pts["C"], pts["E"])
    place("rod2", pts["E"], pts["E"] + (pts["E"] - pts["C"]))
    place("link_a", pts["F"], pts["E"])
    place("link_b", pts["E"], pts["G"])

    def body(name, point=(0.0, 0.0, 0.0)):
        return planar_body_frame(N, i_phi, bodies[name], SLEW_AXIS, PLANE_BASIS, point,
                                 i_theta=theta[name])

    turn = lambda point=(0.0, 0.0, 0.0): turntable_frame(N, i_phi, SLEW_AXIS, PLANE_BASIS, point)

    def boom_point(ib, s, plane_offset=None):
        """Boom section frame at s with an in-plane rigid offset (plane components at t = 0)."""
        if plane_offset is None:
            return beam_frame(model, ib, s)
        R0 = beam_frame(model, ib, s)(Q0)[2]
        o = PLANE_BASIS[:, :2] @ np.asarray(plane_offset, float)
        return beam_frame(model, ib, s, o, R0)

    n1, n2 = pts["n1"], pts["n2"]
    frames = {
        "turntable": turn(),
        "A_turntable": turn((pts["A"][0], pts["A"][1], 0.0)),
        "boom1_foot": boom_point(0, 0.0),
        "boom1_tip": boom_point(0, L),
        "boom2_foot": boom_point(1, 0.0),
        "boom2_tip": boom_point(1, L),
        "P1_boom": boom_point(0, p.cyl1_pin[0], p.cyl1_pin[1] * n1),
        "C_boom": boom_point(0, L + p.cyl2_base[0], p.cyl2_base[1] * n1),
        "F_boom": boom_point(0, L + p.link_a_base[0], p.link_a_base[1] * n1),
        "G_boom": boom_point(1, p.link_b_end[0], p.link_b_end[1] * n2),
        "base1_turntable": turn((p.cyl1_base[0], p.cyl1_base[1], 0.0)),
        "barrel1": body("barrel1"), "rod1": body("rod1"),
        "barrel2": body("barrel2"), "rod2": body("rod2"),
        "link_a": body("link_a"), "E_link_a": body("link_a", (p.link_a_length, 0.0, 0.0)),
        "link_b": body("link_b"), "G_link_b": body("link_b", (p.link_b_length, 0.0, 0.0)),
    }
    cons: list[NonlinearConstraint] = []

    def hinge(name, fa, fb):
        """Revolute joint about the plane normal between frames a and b (3 + 2 rows)."""
        cons.append(point_coincidence(name, fb, fa))
        Ra0, Rb0 = fa(Q0)[2], fb(Q0)[2]
        n_g = PLANE_BASIS[:, 2]
        cons.append(revolute_axis(name + "_axis", fa, fb, Ra0.T @ n_g,
                                  Rb0.T @ PLANE_BASIS[:, 0], Rb0.T @ PLANE_BASIS[:, 1]))

    hinge("hinge_A", frames["A_turntable"], frames["boom1_foot"])
    hinge("hinge_B", frames["boom1_tip"], frames["boom2_foot"])
    cons.append(planar_pin("cyl1_base", frames["barrel1"], frames["base1_turntable"],
                           frames["turntable"]))
    cons.append(prismatic_offset("prismatic1", frames["barrel1"], frames["rod1"], (0, 1, 0)))
    cons.append(point_coincidence("cyl1_rod_pin", frames["P1_boom"], frames["rod1"]))
    cons.append(point_coincidence("cyl2_base", frames["C_boom"], frames["barrel2"]))
    cons.append(prismatic_offset("prismatic2", frames["barrel2"], frames["rod2"], (0, 1, 0)))
    cons.append(planar_pin("E_rod2_link_a", frames["rod2"], frames["E_link_a"], frames["turntable"]))
    cons.append(planar_pin("E_link_b_link_a", frames["link_b"], frames["E_link_a"],
                           frames["turntable"]))
    cons.append(point_coincidence("F", frames["F_boom"], frames["link_a"]))
    cons.append(point_coincidence("G", frames["G_boom"], frames["G_link_b"]))

    # rigid bodies (mass centres in body axes, axis 1 from the base pin towards the rod pin)
    g_or_none = g_vec if p.gravity > 0 else None
    pe = []
    for cyl, s0 in (("1", s1_0), ("2", s2_0)):
        lc = p.cylinder_length_factor * s0
        pe.append(RigidBody(body("barrel" + cyl, (0.5 * lc, 0, 0)), p.barrel_mass,
                            cylinder_inertia(p.barrel_mass, p.barrel_radius, lc), g_or_none,
                            "barrel" + cyl))
        pe.append(RigidBody(body("rod" + cyl, (-0.5 * lc, 0, 0)), p.rod_mass,
                            cylinder_inertia(p.rod_mass, p.rod_radius, lc), g_or_none,
                            "rod" + cyl))
    for nm, ln in (("link_a", p.link_a_length), ("link_b", p.link_b_length)):
        m = p.link_mass_per_length * ln
        pe.append(RigidBody(body(nm, (0.5 * ln, 0, 0)), m, cylinder_inertia(m, p.link_radius, ln),
                            g_or_none, nm))
    pe.append(CoordinateInertia(i_phi, p.turntable_inertia))
    Q0[i_phi] = 0.0
    cyls = []
    for cyl, s0, prof in (("1", s1_0, profs[0]), ("2", s2_0, profs[2])):
        a, b = frames["barrel" + cyl], frames["rod" + cyl]
        if p.rigid_cylinders:
            smp = _sampler(prof)
            cons.append(distance_driver(f"cylinder{cyl}", b, a,
                                        lambda t, s0=s0, f=smp: (s0 + f(t)[0], f(t)[1], f(t)[2])))
            cyls.append(None)
        else:
            act = SpringDamperActuator(a, b, p.k, p.c, s0, prof, name=f"cylinder{cyl}")
            pe.append(act)
            cyls.append(act)
    if p.rest_k > 0:
        R1 = boom_point(0, p.rest_s[0])
        nu = R1(Q0)[2].T @ PLANE_BASIS[:, :2] @ pts["n1"]
        pe.append(BoomRest(R1, boom_point(1, p.rest_s[1]), nu, p.rest_k, p.rest_c, p.rest_width))
    model.nonlinear = cons
    model.point_effects = pe
    rows, i = {}, 0
    for c in cons:
        rows[c.name] = slice(i, i + c.m)
        i += c.m
    return FoldingSystem(model, Q0, p, i_phi, bodies, frames, cyls, rows, profs, (s1_0, s2_0))


def initial_equilibrium(fs: FoldingSystem, load_steps=(1.0,)):
    """Static equilibrium at t = 0 with the cylinders held at their retracted pin distance;
    then s_ref(0) = s + lambda/k so that the spring force equals the holding force (PD:
    s_ref(0) from static equilibrium).  Returns z (reduced coordinates)."""
    m = fs.model
    z0, _ = m.reduced_state(0.0, fs.Q0, np.zeros_like(fs.Q0))
    if fs.params.gravity <= 0 or any(c is None for c in fs.cylinders):
        return z0
    keep_pe, keep_nl = m.point_effects, m.nonlinear
    holders = [distance_driver(f"hold{k}", c.b, c.a, lambda t, s=s: (s, 0.0, 0.0))
               for k, (c, s) in enumerate(zip(fs.cylinders, fs.s_retracted))]
    m.point_effects = [pe for pe in keep_pe if not isinstance(pe, SpringDamperActuator)]
    m.nonlinear = keep_nl + holders
    # gravity applied in increments (continuation): the booms deflect by decimetres under their
    # weight (boom-2 tip ~0.9 m linear estimate), too far for one Newton solve from straight
    grav = [e for e in m.effects if isinstance(e, Gravity)]
    g_full = [e.g.copy() for e in grav] + [pe.gravity for pe in m.point_effects
                                           if isinstance(pe, RigidBody)]
    rb = [pe for pe in m.point_effects if isinstance(pe, RigidBody)]
    z = z0
    try:
        for fac in load_steps:
            for e, g in zip(grav + rb, g_full):
                if isinstance(e, Gravity):
                    e.g = fac * g
                elif g is not None:
                    e.gravity = fac * g
            z, lam = scaled_static_equilibrium(m, z)
    finally:
        for e, g in zip(grav + rb, g_full):
            if isinstance(e, Gravity):
                e.g = g
            else:
                e.gravity = g
        m.point_effects, m.nonlinear = keep_pe, keep_nl
    for c, s, lk in zip(fs.cylinders, fs.s_retracted, lam[-2:]):
        c.s_ref0 = s + lk / c.k          # spring tension k (s - s_ref) = -lambda
    return z


def scaled_static_equilibrium(m: Model, z0: np.ndarray, t: float = 0.0, k_ref: float = 1e9,
                              tol: float = 1e-9, max_iter: int = 25):
    """Newton on P^T F(z) + C^T lambda = 0, Phi(z) = 0 with the saddle-point matrix scaled
    symmetrically (z by 1/sqrt(k_ref), lambda by sqrt(k_ref)): the stiff booms (EA ~ 1e10 N)
    and the stiffness-free rigid-body coordinates make the unscaled matrix of
    :func:`sim_core.model.statics.constrained_static_equilibrium` numerically singular (cond ~ 1e19).
    Forward-difference tangent.  Converged when |r| < tol * (total weight scale) and
    |Phi| < 1e-10.  Returns (z, lambda)."""
    from sim_core.errors import SimulationError
    from sim_core.model.statics import force_tangent, static_parts
    z = np.array(z0, float)
    n = len(z)
    parts = static_parts(m, t)

    Fr, phi, C = parts(z)
    mm = C.shape[0]
    lam = np.linalg.lstsq(C.T, -Fr, rcond=None)[0]
    scale = max(np.linalg.norm(Fr), 1.0)
    S = np.concatenate([np.full(n, 1.0 / np.sqrt(k_ref)), np.full(mm, np.sqrt(k_ref))])
    for _ in range(max_iter):
        r1 = Fr + C.T @ lam
        if np.linalg.norm(r1) <= tol * scale and np.max(np.abs(phi), initial=0.0) < 1e-10:
            return z, lam
        run_control.check("statics", t)             # the run's budget and Ctrl-C
        K = force_tangent(parts, z, lam, rel_step=1e-7, r0=r1)       # forward differences
        A = np.block([[K, C.T], [C, np.zeros((mm, mm))]])
        d = S * np.linalg.solve(S[:, None] * A * S[None, :], -S * np.concatenate([r1, phi]))
        z, lam = z + d[:n], lam + d[n:]
        Fr, phi, C = parts(z)
        if np.linalg.norm(d[:n]) <= 1e-12 * (1.0 + np.linalg.norm(z)) and \
                np.max(np.abs(phi), initial=0.0) < 1e-10:
            return z, lam                       # update at round-off: converged
        if not np.all(np.isfinite(Fr)):
            break
    raise SimulationError(t, "folding static equilibrium: Newton did not converge "
                             f"(|r| = {np.linalg.norm(Fr + C.T @ lam):.3g} N, "
                             f"|phi| = {np.max(np.abs(phi)):.3g})")


# -- outputs -------------------------------------------------------------------------------------

def angular_momentum(fs: FoldingSystem, Q: np.ndarray, Qd: np.ndarray) -> np.ndarray:
    """Total angular momentum about the origin (on the slew axis), kg m^2/s: booms (material
    velocities + rotary inertia), rigid bodies, turntable rotor."""
    m = fs.model
    H = np.zeros(3)
    for el, idx in m.element_indices():
        kin = el.evaluate(Q[idx], strains=False)
        wl = el.q_w * kin.ell
        v = np.einsum("gin,n->gi", kin.J_r, Qd[idx])
        w = np.einsum("gin,n->gi", kin.J_w, Qd[idx])      # (s, t, b) components
        fr = kin.sec.frame                                      # rows e_t, e_b, e_s
        Js = el.section.J
        hsec = (Js[0] * w[:, 0])[:, None] * fr[:, 2] + (Js[1] * w[:, 1])[:, None] * fr[:, 0] \
            + (Js[2] * w[:, 2])[:, None] * fr[:, 1]
        H += np.einsum("g,gi->i", wl, el.section.rhoA * np.cross(kin.r, v) + hsec)
    for pe in m.point_effects:
        if isinstance(pe, RigidBody):
            H += pe.momentum(Q, Qd)[1]
        elif isinstance(pe, CoordinateInertia):
            H += pe.inertia * Qd[pe.index] * SLEW_AXIS
    return H


def simulate_folding(p: FoldingParams, t_end: float = 45.0, n_output: int = 451,
                     rtol: float = 1e-6, atol: float = 1e-8, progress=None,
                     solver: dict | None = None, scene: dict | None = None,
                     checkpoint=None):
    """Run the folding scene from its static equilibrium; Result with tip_position,
    tip_velocity (boom-2 tip, m, m/s), cylinder_forces (N, pushing positive, one column per
    cylinder), cylinder_lengths (m), slew_angle (rad), boom_angles (boom-1 elevation and
    boom-2 relative angle from the rigid-body chain, rad) and constraint_violation (max |Phi|,
    m or rad).  ``solver``: a validated [solver] table (:func:`sim_core.scene.fields.solver_table`);
    its entries (method, max_step, max_wall_s, ...) take precedence over the keyword arguments.
    ``checkpoint``: a :class:`sim_core.checkpoint.Checkpointer` the integration writes to and
    resumes from."""
    from sim_core.integrate.driver import integrate, run_with_partial
    fs = build_folding(p)
    m = fs.model
    z0 = initial_equilibrium(fs)
    y0 = np.concatenate([z0, np.zeros_like(z0)])
    if not p.slew_prescribed and p.initial_slew_rate:
        Qd = np.zeros(m.n_coords)
        Qd[fs.i_phi] = p.initial_slew_rate
        Q, _ = m.full_state(0.0, z0, 0 * z0)
        y0[m.n_dof:] = m.reduced_state(0.0, Q, Qd)[1]
    sol = {"t_end": t_end, "rtol": rtol, "atol": atol, "n_output": n_output, **(solver or {})}
    return run_with_partial(lambda: integrate(m, y0, sol["t_end"], sol, progress, checkpoint),
                            lambda t, ys, st, err: folding_result(fs, t, ys, st, err, scene))


def folding_result(fs: FoldingSystem, t, ys, stats, error, scene=None):
    from sim_core.result import Result
    m, p = fs.model, fs.params
    n = m.n_dof
    out = {k: [] for k in ("tip_position", "tip_velocity", "cylinder_forces", "cylinder_lengths",
                           "slew_angle", "boom_angles", "constraint_violation",
                           "angular_momentum")}
    tip = fs.frames["boom2_tip"]
    stop = run_control.OutputGuard(partial=error is not None)    # the run's budget, Ctrl-C
    for tk, y in zip(t, ys):
        if stop(tk):
            break
        z, zd = y[:n], y[n:]
        Q, Qd = m.full_state(tk, z, zd)
        r, J, _, _ = tip(Q)
        out["tip_position"].append(r)
        out["tip_velocity"].append(J @ Qd)
        forces, lengths = [], []
        if any(c is None for c in fs.cylinders):
            lam = m.accelerations_and_multipliers(tk, z, zd)[1]
        for k, c in enumerate(fs.cylinders):
            if c is None:
                # distance row: C^T lambda along +grad s -> pushing force = lambda
                forces.append(lam[fs.rows[f"cylinder{k + 1}"]][0])
                a, b = fs.frames[f"barrel{k + 1}"], fs.frames[f"rod{k + 1}"]
                lengths.append(np.linalg.norm(b(Q)[0] - a(Q)[0]))
            else:
                f, s, _ = c.tension(tk, Q, Qd)
                forces.append(-f)
                lengths.append(s)
        out["cylinder_forces"].append(forces)
        out["cylinder_lengths"].append(lengths)
        out["slew_angle"].append(Q[fs.i_phi])
        ra, rb = fs.frames["boom1_foot"](Q)[0], fs.frames["boom1_tip"](Q)[0]
        rc = fs.frames["boom2_tip"](Q)[0]
        d1, d2 = rb - ra, rc - rb
        ang = np.arccos(np.clip(d1 @ d2 / np.linalg.norm(d1) / np.linalg.norm(d2), -1, 1))
        up = d1 @ SLEW_AXIS / np.linalg.norm(d1)
        out["boom_angles"].append([np.arcsin(up), np.pi - ang])
        out["constraint_violation"].append(np.max(np.abs(m.constraint_violation(tk, z, zd))))
        out["angular_momentum"].append(angular_momentum(fs, Q, Qd))
    outputs = {k: np.array(v, dtype=float) for k, v in out.items()}
    stats["n_dof"] = int(n)
    if scene is None:
        scene = {"kind": "folding", "name": "folding", "params": dict(p.__dict__)}
    k = len(out["tip_position"])
    return stop.finish(Result(np.asarray(t)[:k], outputs, stats, scene, error))
