"""Closed-form reference solutions (SI units) for the checks of docs/model.md#checks.

Sources
-------
* cantilever statics (docs/model.md#check-cantilever-statics), cantilever/bar frequencies
  (docs/model.md#check-cantilever-frequencies): Euler-Bernoulli beam theory (e.g. Timoshenko &
  Gere; Blevins, "Formulas for natural frequency and mode shape").
* moving force on a simply supported beam (docs/model.md#check-moving-load): Fryba, "Vibration
  of Solids and Structures under Moving Loads" (1972), Ch. 1, series exactly as written on
  that page.
* rod through a frictionless sleeve (docs/model.md#check-sleeve): Bigoni, Dal Corso, Bosi,
  Misseroni, "Eshelby-like forces acting on elastic structures", J. Mech. Phys. Solids 2015
  (configurational force M^2/(2EI)).
* rigid-limit tip kinematics (docs/model.md#input-rigid-limit, docs/model.md#check-rigid-limit):
  Zhao-Qi-Wang 2024, Section 9.1, Eqs. 74-76.
* luffing geometry (docs/model.md#input-luffing) and static forces
  (docs/model.md#check-static-luffing): Zhao-Qi-Wang 2024, Section 9 (Fig. 13a, the L_h
  equation and rotation R) with the proposed-default signs of docs/model.md#input-luffing.

Frames (docs/model.md#input-luffing): global X forward, Z up, Y = Z x X.  Boom-1 left-section
components are (axial e_s, lateral e_t, e_b); at theta = 0 they coincide with (X, Y, Z).  PD
rotation R(theta) = [[cos, 0, -sin], [0, 1, 0], [sin, 0, cos]] maps them to global; theta > 0
lifts the tip.

"Top centre of boom 3" (docs/model.md#input-outputs): the paper calls the right-end section the
*top* section (B1, B3 are given "relative to the top cross-sections").  Its *centre* is the
section-frame origin, i.e. the centre of the lower half circle = the beam reference line
(docs/model.md#input-sections), at material coordinate s = boom_length of boom 3, whose left
section lies 2 L_s along boom 1's axis (docs/model.md#input-ropes).  This reproduces the quoted
start points (7.404, 13.024) m (L_s = 2 m) and (13.404, 23.417) m (8 m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.optimize import brentq

from sim_core.errors import SceneError
from sim_core.physics.drive_profiles import ArrayLike, DriveProfile
from sim_core.systems.telescopic.luffing import (  # noqa: F401  (re-exported: the reference
    R1_DEFAULT,  # geometry of docs/model.md#input-luffing)
    R2_DEFAULT,
    RBAR1_DEFAULT,
    RBAR3_DEFAULT,
    LuffingGeometry,
    luffing_geometry,
    luffing_rotation,
)

# --- Table 2 (docs/model.md#input-sections): mass per length (kg/m) and mass-centre offset z_c
# along e_b (m), booms 1..3.
M_PER_LENGTH_DEFAULT = (318.86, 304.07, 289.27)
Z_C_DEFAULT = (0.045, 0.044, 0.043)


def _pos(name: str, value: float) -> float:
    """Return float(value); raise SceneError unless finite and > 0."""
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise SceneError(f"{name} = {value!r} is invalid; allowed range: > 0 (finite)")
    return v


# ---------------------------- cantilever statics (docs/model.md#check-cantilever-statics)
@dataclass(frozen=True)
class TipResponse:
    """Cantilever tip deflection (m, along the load) and tip slope (rad)."""

    deflection: float
    slope: float


def cantilever_tip_load(P: float, L: float, EI: float) -> TipResponse:
    """Cantilever, tip force P (N), length L (m), EI (N m^2): w = PL^3/(3EI), w' = PL^2/(2EI)."""
    L, EI = _pos("L", L), _pos("EI", EI)
    return TipResponse(P * L**3 / (3 * EI), P * L**2 / (2 * EI))


def cantilever_uniform_load(q: float, L: float, EI: float) -> TipResponse:
    """Cantilever under uniform load q (N/m, e.g. m' g): w = qL^4/(8EI), w' = qL^3/(6EI)."""
    L, EI = _pos("L", L), _pos("EI", EI)
    return TipResponse(q * L**4 / (8 * EI), q * L**3 / (6 * EI))


# ------------------------------- frequencies (docs/model.md#check-cantilever-frequencies)
def cantilever_beta_L(n_modes: int = 3) -> np.ndarray:
    """Roots beta_n L of the clamped-free frequency equation 1 + cos x cosh x = 0 (brentq).

    Solved as cos x + 1/cosh x = 0 (same roots, no overflow); root n lies in ((n-1)pi, n pi).
    Returns (n_modes,) array: 1.8751, 4.6941, 7.8548, ...
    """
    if int(n_modes) < 1:
        raise SceneError(f"n_modes = {n_modes!r} is invalid; allowed range: >= 1")
    f = lambda x: math.cos(x) + 1.0 / math.cosh(x)  # noqa: E731
    lo = 1e-9
    return np.array([brentq(f, max((n - 1) * math.pi, lo), n * math.pi, xtol=1e-14)
                     for n in range(1, int(n_modes) + 1)])


def cantilever_release_tip(t: ArrayLike, EI: float, m: float, L: float, g: float = 9.81,
                           n_modes: int = 50) -> np.ndarray:
    """Tip deflection w(L, t) (m, positive along g) of a cantilever released straight and at
    rest under its own weight q = m g (N/m): EI N m^2, m kg/m, L m, t s.

    Exact superposition of the clamped-free Euler-Bernoulli modes (Rao, Vibration of Continuous
    Systems, 2nd ed. 2019, Sect. 11.5): phi_n = cosh b x - cos b x - s_n (sinh b x - sin b x),
    s_n = (cosh b L + cos b L) / (sinh b L + sin b L), int phi_n^2 = L, int phi_n = 2 s_n / b;
    each modal coordinate obeys eta'' + w_n^2 eta = 2 s_n g / (b_n L) from rest, so
    w(L, t) = sum_n A_n (1 - cos w_n t), A_n = phi_n(L) 2 s_n g / (b_n L w_n^2).  phi_n(L) and
    s_n are written with tanh and 1/cosh (no overflow for high modes).  The static limit
    sum A_n is q L^4 / (8 EI); the truncation error of n_modes is ~(b_N L)^-4 of it."""
    bl = cantilever_beta_L(n_modes)
    th, sech = np.tanh(bl), 1.0 / np.cosh(bl)
    s, c = np.sin(bl), np.cos(bl)
    sigma = (1.0 + c * sech) / (th + s * sech)
    phi_L = 2.0 * (s - c * th) / (th + s * sech)
    omega = bl ** 2 * math.sqrt(_pos("EI", EI) / (_pos("m", m) * _pos("L", L) ** 4))
    A = phi_L * 2.0 * sigma * g / (bl * omega ** 2)
    return (1.0 - np.cos(np.multiply.outer(np.asarray(t, dtype=float), omega))) @ A


def cantilever_bending_omegas(EI: float, m: float, L: float, n_modes: int = 3) -> np.ndarray:
    """Clamped-free bending circular frequencies omega_n = (beta_n L)^2 sqrt(EI/(m L^4)), rad/s.

    EI (N m^2), m mass per length (kg/m), L (m).
    """
    EI, m, L = _pos("EI", EI), _pos("m", m), _pos("L", L)
    return cantilever_beta_L(n_modes) ** 2 * math.sqrt(EI / (m * L**4))


def fixed_free_axial_f1(EA: float, m: float, L: float) -> float:
    """First axial frequency of a fixed-free bar f1 = sqrt(EA/m)/(4L), Hz (EA N, m kg/m, L m)."""
    return math.sqrt(_pos("EA", EA) / _pos("m", m)) / (4 * _pos("L", L))


def fixed_free_torsion_f1(GJ: float, J_s: float, L: float) -> float:
    """First torsional frequency f1 = sqrt(GJ/J_s)/(4L), Hz (GJ N m^2, J_s kg m, L m)."""
    return math.sqrt(_pos("GJ", GJ) / _pos("J_s", J_s)) / (4 * _pos("L", L))


# ------------------------------------------------ Fryba (docs/model.md#check-moving-load)
def fryba_deflection(x: ArrayLike, t: ArrayLike, P: float, c: float, L: float, EI: float,
                     m: float, n_terms: int = 50) -> np.ndarray:
    """Deflection w(x, t) (m, along P) of a simply supported beam under a force P (N) moving
    at speed c (m/s) from x = 0 at t = 0, zero initial state, valid for 0 <= t <= L/c
    (docs/model.md#check-moving-load; the sum runs over j = 1..n_terms):

        w = w0 sum_j [sin(j w t) - (alpha/j) sin(w_j t)] sin(j pi x/L) / (j^2 (j^2 - alpha^2)),
        w0 = 2 P L^3/(pi^4 EI),  w = pi c/L,  w_j = j^2 (pi/L)^2 sqrt(EI/m),  alpha = w/w_1.

    x (m) and t (s) broadcast against each other; EI (N m^2), m (kg/m).  Raises SceneError if
    alpha is an integer <= n_terms (resonant term) or t leaves [0, L/c].
    """
    c, L, EI, m = _pos("c", c), _pos("L", L), _pos("EI", EI), _pos("m", m)
    n = int(n_terms)
    if n < 1:
        raise SceneError(f"n_terms = {n_terms!r} is invalid; allowed range: >= 1")
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if np.any(t < 0) or np.any(t > (L / c) * (1 + 1e-12)):
        raise SceneError(f"t = [{t.min()!r}, {t.max()!r}] is invalid; allowed range: "
                         f"0 <= t <= L/c = {L / c!r} s (force on the beam)")
    w0 = 2 * P * L**3 / (math.pi**4 * EI)
    om = math.pi * c / L
    om1 = (math.pi / L) ** 2 * math.sqrt(EI / m)
    alpha = om / om1
    j = np.arange(1, n + 1, dtype=float)
    if np.any(np.abs(j - alpha) < 1e-9):
        raise SceneError(f"alpha = {alpha!r} is invalid; allowed range: not an integer <= {n}")
    tt, xx = np.broadcast_arrays(t, x)
    tt, xx = tt[..., None], xx[..., None]
    om_j = j**2 * om1
    terms = ((np.sin(j * om * tt) - (alpha / j) * np.sin(om_j * tt)) * np.sin(j * math.pi * xx / L)
             / (j**2 * (j**2 - alpha**2)))
    return w0 * terms.sum(axis=-1)


# ---------------------------------------------------- sleeve (docs/model.md#check-sleeve)
@dataclass(frozen=True)
class SleeveReference:
    """Bigoni et al. 2015: tip deflection (m), clamp moment M = P l (N m), and configurational
    (Eshelby-like) force M^2/(2EI) (N) pushing the rod out of the sleeve."""

    tip_deflection: float
    moment: float
    configurational_force: float


def bigoni_sleeve(P: float, ell: float, EI: float) -> SleeveReference:
    """Rod of free length ell (m) out of a frictionless sleeve, tip load P (N), EI (N m^2)."""
    ell, EI = _pos("ell", ell), _pos("EI", EI)
    M = P * ell
    return SleeveReference(P * ell**3 / (3 * EI), M, M**2 / (2 * EI))


def boom3_top_centre(theta: float, L_s: ArrayLike, boom_length: float = 10.0,
                     **geometry: Sequence[float]) -> np.ndarray:
    """Global (X, Z) of the top centre of boom 3 in the rigid state (m), shape (..., 2).

    Reference-line point of boom 3's right-end section: O + (2 L_s + boom_length) e_s
    (docs/model.md#input-sections, docs/model.md#input-ropes).
    ``geometry`` forwards r1, r2, rbar1, rbar3 to ``luffing_geometry``.
    """
    g = luffing_geometry(theta, **geometry)
    a = 2 * np.asarray(L_s, float)[..., None] + boom_length
    p = g.origin + a * g.e_s
    return p[..., [0, 2]]


# ------------------------------------------ rigid limit (docs/model.md#input-rigid-limit)
@dataclass(frozen=True)
class TipKinematics:
    """Rigid-limit top-centre position (m), velocity (m/s), acceleration (m/s^2), X and Z."""

    x: ArrayLike
    z: ArrayLike
    vx: ArrayLike
    vz: ArrayLike
    ax: ArrayLike
    az: ArrayLike


def rigid_tip_kinematics(t: ArrayLike, schedule: DriveProfile, theta: float,
                         r0: Sequence[float]) -> TipKinematics:
    """Zhao-Qi-Wang 2024 Eqs. 74-76 (docs/model.md#input-rigid-limit): boom 3 moves twice the
    piston stroke.

    r = r0 + 2 s0(t) (cos th, sin th), v = 2 v(t) (cos th, sin th), a = 2 a(t) (cos th, sin th),
    with s0(t) = schedule.stroke(t) - schedule.s0 (signed; a retraction schedule with sign = -1
    gives -s0).  r0 = (X0, Z0) initial top centre (see ``boom3_top_centre``), theta in rad.
    """
    ct, st = math.cos(theta), math.sin(theta)
    ds = np.asarray(schedule.stroke(t), float) - schedule.s0
    v = np.asarray(schedule.rate(t), float)
    a = np.asarray(schedule.accel(t), float)
    return TipKinematics(r0[0] + 2 * ds * ct, r0[1] + 2 * ds * st, 2 * v * ct, 2 * v * st,
                         2 * a * ct, 2 * a * st)


# ------------------------------------------- statics (docs/model.md#check-static-luffing)
@dataclass(frozen=True)
class StaticLuffingForces:
    """Rigid static forces at t = 0 (docs/model.md#check-static-luffing), N and N m.

    luffing_force: cylinder force, > 0 = compression (pushes D3 away from D2);
    gravity_moment: moment of all weights about D1 (global Y component; > 0 lowers the tip);
    lever: distance from D1 to the line D2-D3 (m); rope_tension: extraction rope T;
    telescopic_force: cylinder force between booms 1 and 2 (> 0 pushes boom 2 out);
    retraction_rope_tension: 0 (slack).
    """

    luffing_force: float
    gravity_moment: float
    lever: float
    rope_tension: float
    telescopic_force: float
    retraction_rope_tension: float = 0.0


def static_luffing_forces(theta: float, L_s: float, payload_mass: float, *,
                          m_per_length: Sequence[float] = M_PER_LENGTH_DEFAULT,
                          z_c: Sequence[float] = Z_C_DEFAULT, boom_length: float = 10.0,
                          g: float = 9.81, **geometry: Sequence[float]) -> StaticLuffingForces:
    """Static luffing-cylinder, rope and telescopic forces of the rigid boom
    (docs/model.md#check-static-luffing).

    Moments about D1 (global Y): boom k of mass m_k = boom_length m'_k at axial a_k + boom_length/2
    (a_k = 0, L_s, 2 L_s, m, along boom 1 from its left section) offset z_c[k] along e_b; payload
    payload_mass (kg) on the axis at 2 L_s + boom_length; positions O + R (axial, 0, z_c).
    Balanced by the cylinder force along D2->D3 acting at D3.  Axially (frictionless):
    T = (m3 + m_p) g sin th, F_tel = m2 g sin th + 2 T.  theta rad, L_s m, g m/s^2.
    """
    geo = luffing_geometry(theta, **geometry)
    R = geo.rotation
    Lb, g = _pos("boom_length", boom_length), float(g)
    masses = [Lb * _pos(f"m_per_length[{k}]", mk) for k, mk in enumerate(m_per_length)]
    if len(masses) != 3 or len(z_c) != 3:
        raise SceneError(f"m_per_length/z_c lengths = ({len(masses)}, {len(z_c)}) are invalid; "
                         "allowed: 3 booms each")
    pts = [geo.origin + R @ np.array([k * L_s + 0.5 * Lb, 0.0, z_c[k]]) for k in range(3)]
    pts.append(geo.origin + R @ np.array([2 * L_s + Lb, 0.0, 0.0]))
    weights = [mk * g for mk in masses] + [payload_mass * g]
    M = sum(float(np.cross(p - geo.d1, np.array([0.0, 0.0, -W]))[1]) for p, W in zip(pts, weights))
    u = (geo.d3 - geo.d2) / geo.cylinder_length
    arm = float(np.cross(geo.d3 - geo.d1, u)[1])   # Y moment of a unit compression force at D3
    F_L = -M / arm
    T = (masses[2] + payload_mass) * g * math.sin(theta)
    return StaticLuffingForces(F_L, M, geo.lever, T, masses[1] * g * math.sin(theta) + 2 * T)


def rigid_luffing_force(p, theta: float, g: float) -> float:
    """Cylinder force (N, > 0 pushing) of the rigid crane of TelescopicParams ``p`` at the
    luffing angle theta (rad) by virtual work, for any lengths and mounting points: a virtual
    rotation d(theta) about the pivot D1 does work -sum W_i dz_i with the weights W_i (booms at
    their mid-length on the reference line, the payload at the tip), and the cylinder, whose length
    changes by d(L_cyl) = lever d(theta), does F lever d(theta); so F = M_D1 / lever with
    M_D1 = sum W_i (x_i - x_D1), the weights' moment about D1 (horizontal arms)."""
    from sim_core.systems.telescopic.params import boom_section
    geo = luffing_geometry(theta, *p.luffing.points())
    e = geo.e_s
    a = [k * p.stroke0 for k in range(p.n_booms)]          # left sections along boom 1
    arms = [(geo.origin + (a[k] + 0.5 * p.lengths[k]) * e)[0] - geo.d1[0]
            for k in range(p.n_booms)]
    weights = [p.lengths[k] * boom_section(k, p).rhoA * g for k in range(p.n_booms)]
    tip_arm = (geo.origin + (a[-1] + p.lengths[-1]) * e)[0] - geo.d1[0]
    M = sum(W * x for W, x in zip(weights, arms)) + p.payload * g * tip_arm
    # the sign: d(L_cyl)/d(theta) > 0 when lifting lengthens the cylinder (a pushing cylinder)
    d = 1e-6
    dL = (luffing_geometry(theta + d, *p.luffing.points()).cylinder_length
          - luffing_geometry(theta - d, *p.luffing.points()).cylinder_length) / (2 * d)
    return M / dL
