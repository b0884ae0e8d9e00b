"""Cross-section properties of the thin-walled U-shaped boom sections.

Source: Zhao, Qi, Wang (2024), Section 9, Table 1 (geometry) and Table 2 (constitutive moduli,
linear mass density, mass centre); Section 8.2 / Figure 8 (contour = rounding arcs joined by
straight lines, equidistant inner and outer contours).  SI units: m, Pa, kg/m^3.

Geometry (section frame: origin at the centre of the lower half circle = beam reference line,
y along e_t (lateral), z along e_b (up), e_s axial):
  P1  quarter arc, centre (+y_a, z_a), azimuth   0..90 deg (from e_t towards e_b), outer radius r
  P2  quarter arc, centre (-y_a, z_a), azimuth  90..180 deg, outer radius r
  P3  half circle, centre (0, 0),      azimuth 180..360 deg, outer radius R
  top flange between P2 and P1 (z in [z_a + r - t, z_a + r], |y| <= y_a) and two vertical side
  walls (|y| in [R - t, R], z in [0, z_a]).  Tangent continuity of the side walls needs
  y_a + r = R.  Inner contour = outer contour offset inwards by the wall thickness t.
Table 1: y_a = z_a = 0.300 m, (r, R) = (90, 390), (70, 370), (50, 350) mm for booms 1, 2, 3;
t = 15 mm.

Method: the wall is the disjoint union of three annular sectors and three rectangles; area,
first and second moments are closed-form integrals over those pieces (no polygonisation), so
the results are exact for the stated geometry.  Torsion: Bredt-Batho for the closed single-cell
thin-walled section, J = 4 A_m^2 t / P_m (A_m, P_m area enclosed by and length of the wall
mid-line).  A thin-wall mid-line variant (`section_properties(..., method="midline")`) treats
the wall as a line of thickness t (error O(t^2/r^2) in I, exact in A).

Comparison with Table 2 (E = 2.1e11 Pa, nu = 0.3, rho = 7850 kg/m^3), exact wall, Table 1 radii
read as outer radii (default) / as mid-line radii (`USection.paper_boom(k, radii="midline")`):
  boom  EI_t [N m^2]     EI_b [N m^2]     GJ Bredt [N m^2]  m' [kg/m]       z_c [m]
  1     6.96e8 / 7.35e8  7.12e8 / 7.52e8  4.92e8 / 5.21e8   313.31 / 318.86  0.0444 / 0.0446
  2     5.97e8 / 6.33e8  6.13e8 / 6.49e8  4.18e8 / 4.45e8   298.52 / 304.07  0.0439 / 0.0441
  3     5.08e8 / 5.40e8  5.22e8 / 5.55e8  3.52e8 / 3.76e8   283.72 / 289.27  0.0434 / 0.0436
  Table 2: EI_t = EI_b = 7.22e8 / 6.30e8 / 5.46e8, GJ = 5.55e8 / 4.85e8 / 4.20e8,
           m' = 318.86 / 304.07 / 289.27, z_c = 0.045 / 0.044 / 0.043 (EA column lost).
Findings:
* m': Table 2 equals rho t (pi r + pi R + 2 y_a + 2 z_a) with the Table 1 radii, i.e. the authors
  took the Table 1 contour as the wall mid-line (wall t/2 either side).  That reproduces m' to
  0.01 kg/m for all three booms; with external radii (as Table 1 is headed) the area is smaller
  by exactly pi t^2 (m' lower by rho pi t^2 = 5.55 kg/m, 1.7-1.9 %).  No sliders or stiffeners
  are needed to explain the mass.  The PD EA = E m'/rho is the mid-line reading.
* EI: about the reference-line origin, int y^2 dA = int z^2 dA exactly when y_a = z_a (each upper
  quarter of the U maps onto itself under y <-> z: side wall <-> half flange), which is presumably
  why Table 2 lists EI_t = EI_b.  About the centroid, I_t = I_b - A z_c^2, so EI_t is 2.3-2.7 %
  below EI_b.  Table 2's EI falls off more slowly from boom 1 to 3 than any reading of Table 1
  (ratio 1.15 per step vs 1.16-1.17), so no single convention reproduces it: it is closest to
  the mid-line centroidal EI_t (-1.0..+1.8 %) and lies, for every boom, between the
  outer-radius EI_t (the lowest reading, -3.6..-6.9 %) and the mid-line EI_b (the highest,
  +1.7..+4.2 %).  The exact-wall default (outer radii) is therefore within 7 % of Table 2.
* GJ: Table 2 has GJ/G = 2 EI/E to 0.2 %, i.e. the paper used the polar moment I_t + I_b as
  the torsion constant (exact only for a circular tube).  For this closed non-circular section
  Bredt-Batho gives J = 0.89-0.91 (I_t + I_b), hence our GJ is 6-16 % below Table 2.  We keep
  Bredt (Saint-Venant J <= I_p; Bredt is accurate to thin-wall order for a closed single cell).
* z_c: computed values are within 0.7 mm of Table 2's (printed to 1 mm); neither reading
  reproduces all three printed digits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from sim_core.errors import SceneError

__all__ = [
    "USection",
    "SectionProperties",
    "section_properties",
    "annular_sector_moments",
    "rectangle_moments",
    "PAPER_TABLE2",
]

#: Paper Table 2 per boom k: (EI_t = EI_b [N m^2], GJ_s [N m^2], m' [kg/m], z_c [m]).
PAPER_TABLE2: dict[int, tuple[float, float, float, float]] = {
    1: (7.22e8, 5.55e8, 318.86, 0.045),
    2: (6.30e8, 4.85e8, 304.07, 0.044),
    3: (5.46e8, 4.20e8, 289.27, 0.043),
}

_TABLE1_OUTER_RADII = {1: (0.090, 0.390), 2: (0.070, 0.370), 3: (0.050, 0.350)}  # (r, R), m
_TABLE1_CENTRE = (0.300, 0.300)  # (y_a, z_a) of P1, m
_WALL = 0.015  # m
_TANGENCY_TOL = 1e-9  # m, tolerance of y_a + r = R


@dataclass(frozen=True)
class USection:
    """U-shaped thin-walled hollow section (paper Table 1 / Figure 8).

    Attributes
    ----------
    top_arc_centre_y : float
        y (e_t) of the centre of the top right arc P1, m (P2 mirrored at -y); >= 0.
    top_arc_centre_z : float
        z (e_b) of the centres of P1, P2 above the centre of the half circle P3 = length of the
        vertical side walls, m; >= 0.
    top_arc_outer_radius : float
        Outer radius r of the top arcs P1, P2, m; > wall_thickness.
    bottom_arc_outer_radius : float
        Outer radius R of the lower half circle P3, m; must equal top_arc_centre_y +
        top_arc_outer_radius (vertical side walls tangent to both arcs).
    wall_thickness : float
        Wall thickness t, m; 0 < t < top_arc_outer_radius (inner radii = outer - t).

    Degenerate case: y_a = z_a = 0 and r = R is a full circular tube.
    """

    top_arc_centre_y: float
    top_arc_centre_z: float
    top_arc_outer_radius: float
    bottom_arc_outer_radius: float
    wall_thickness: float

    def __post_init__(self) -> None:
        for name in ("top_arc_centre_y", "top_arc_centre_z", "top_arc_outer_radius",
                     "bottom_arc_outer_radius", "wall_thickness"):
            v = getattr(self, name)
            if not np.isfinite(v):
                raise SceneError(f"USection.{name} = {v!r} m: must be finite")
        if self.top_arc_centre_y < 0.0:
            raise SceneError(
                f"USection.top_arc_centre_y = {self.top_arc_centre_y!r} m: allowed range [0, inf) "
                "(negative values make the top arcs P1, P2 overlap)")
        if self.top_arc_centre_z < 0.0:
            raise SceneError(
                f"USection.top_arc_centre_z = {self.top_arc_centre_z!r} m: allowed range [0, inf) "
                "(negative values make the top arcs overlap the lower half circle)")
        for name in ("top_arc_outer_radius", "bottom_arc_outer_radius"):
            v = getattr(self, name)
            if v <= 0.0:
                raise SceneError(f"USection.{name} = {v!r} m: allowed range (0, inf)")
        t_max = min(self.top_arc_outer_radius, self.bottom_arc_outer_radius)
        if not 0.0 < self.wall_thickness < t_max:
            raise SceneError(
                f"USection.wall_thickness = {self.wall_thickness!r} m: allowed range "
                f"(0, {t_max!r}) m, i.e. positive and below the smallest outer radius "
                "(inner radius = outer - wall_thickness must stay positive)")
        expected = self.top_arc_centre_y + self.top_arc_outer_radius
        if abs(self.bottom_arc_outer_radius - expected) > _TANGENCY_TOL:
            raise SceneError(
                f"USection.bottom_arc_outer_radius = {self.bottom_arc_outer_radius!r} m: "
                f"must equal top_arc_centre_y + top_arc_outer_radius = {expected!r} m "
                f"(+-{_TANGENCY_TOL} m) for vertical side walls tangent to both arcs")

    @classmethod
    def paper_boom(cls, k: int, radii: Literal["outer", "midline"] = "outer") -> "USection":
        """Section of boom k = 1 (outermost), 2, 3 (innermost) from paper Table 1.

        radii="outer" (default) reads the Table 1 radii as external radii, as the table states.
        radii="midline" reads them as wall mid-line radii (outer radii + t/2); this is the
        convention that reproduces Table 2's m' and EA exactly (see the module docstring).
        """
        if k not in _TABLE1_OUTER_RADII:
            raise SceneError(f"boom index k = {k!r}: allowed values 1, 2, 3")
        if radii not in ("outer", "midline"):
            raise SceneError(f"radii = {radii!r}: allowed values 'outer', 'midline'")
        r, big_r = _TABLE1_OUTER_RADII[k]
        shift = _WALL / 2 if radii == "midline" else 0.0
        return cls(top_arc_centre_y=_TABLE1_CENTRE[0], top_arc_centre_z=_TABLE1_CENTRE[1],
                   top_arc_outer_radius=r + shift, bottom_arc_outer_radius=big_r + shift,
                   wall_thickness=_WALL)


@dataclass(frozen=True)
class SectionProperties:
    """Section constants (centroidal axes parallel to e_t, e_b).

    area : A, m^2.           mass_per_length : m' = rho A, kg/m.
    y_c, z_c : centroid (= mass centre) in the section frame, m.
    I_t : int (z - z_c)^2 dA, m^4 (bending about e_t, i.e. in the luffing plane).
    I_b : int (y - y_c)^2 dA, m^4 (lateral bending about e_b).
    I_tb : int (y - y_c)(z - z_c) dA, m^4 (0 by symmetry).
    J : Bredt-Batho torsion constant 4 A_m^2 t / P_m, m^4.
    A_m, P_m : area enclosed by / length of the wall mid-line, m^2, m.
    rho_I_t, rho_I_b : rotary inertia per length rho I_t, rho I_b, kg m.
    rho_I_polar : rho (I_t + I_b), kg m.
    E, G, rho : material, Pa, Pa, kg/m^3 (G = E / (2 (1 + nu))).
    EA : N.  GJ, EI_t, EI_b : N m^2.
    """

    area: float
    mass_per_length: float
    y_c: float
    z_c: float
    I_t: float
    I_b: float
    I_tb: float
    J: float
    A_m: float
    P_m: float
    rho_I_t: float
    rho_I_b: float
    rho_I_polar: float
    E: float
    G: float
    rho: float
    EA: float
    GJ: float
    EI_t: float
    EI_b: float


def annular_sector_moments(y0, z0, r_in, r_out, th0, th1) -> np.ndarray:
    """Exact area moments of annular sectors about the section origin (vectorized).

    Sector: centre (y0, z0), radii r_in <= rho <= r_out, azimuth th0 <= th <= th1 (rad, from
    e_t towards e_b).  Returns array (..., 6) of (A, int y, int z, int y^2, int z^2, int y z),
    units m^2, m^3, m^3, m^4, m^4, m^4.
    """
    y0, z0, a, b, t0, t1 = np.broadcast_arrays(*(np.asarray(x, dtype=float)
                                                 for x in (y0, z0, r_in, r_out, th0, th1)))
    d2, d3, d4 = (b**2 - a**2) / 2.0, (b**3 - a**3) / 3.0, (b**4 - a**4) / 4.0
    dth = t1 - t0
    ds2 = (np.sin(2 * t1) - np.sin(2 * t0)) / 4.0
    area = d2 * dth
    su = d3 * (np.sin(t1) - np.sin(t0))           # int u dA, u = y - y0
    sv = d3 * (np.cos(t0) - np.cos(t1))           # int v dA, v = z - z0
    suu = d4 * (dth / 2.0 + ds2)
    svv = d4 * (dth / 2.0 - ds2)
    suv = d4 * (np.sin(t1) ** 2 - np.sin(t0) ** 2) / 2.0
    return np.stack([
        area,
        su + y0 * area,
        sv + z0 * area,
        suu + 2 * y0 * su + y0**2 * area,
        svv + 2 * z0 * sv + z0**2 * area,
        suv + y0 * sv + z0 * su + y0 * z0 * area,
    ], axis=-1)


def rectangle_moments(y1, y2, z1, z2) -> np.ndarray:
    """Exact area moments of axis-parallel rectangles [y1, y2] x [z1, z2] about the origin.

    Returns array (..., 6) of (A, int y, int z, int y^2, int z^2, int y z) (vectorized).
    """
    y1, y2, z1, z2 = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (y1, y2, z1, z2)))
    wy1, wy2, wy3 = y2 - y1, (y2**2 - y1**2) / 2.0, (y2**3 - y1**3) / 3.0
    wz1, wz2, wz3 = z2 - z1, (z2**2 - z1**2) / 2.0, (z2**3 - z1**3) / 3.0
    return np.stack([wy1 * wz1, wy2 * wz1, wy1 * wz2, wy3 * wz1, wy1 * wz3, wy2 * wz2], axis=-1)


def _region_moments(s: USection, r_top_in: float, r_top_out: float,
                    r_bot_in: float, r_bot_out: float) -> np.ndarray:
    """Moments of the U band between two offset contours (inner radius 0 = solid region).

    The band consists of sectors P1, P2, P3 plus the flange and two side-wall strips; when the
    inner radii are 0 the flange/side "strips" become the solid rectangles of the enclosed region.
    """
    ya, za = s.top_arc_centre_y, s.top_arc_centre_z
    half_pi = np.pi / 2
    sectors = annular_sector_moments(
        y0=[ya, -ya, 0.0], z0=[za, za, 0.0],
        r_in=[r_top_in, r_top_in, r_bot_in], r_out=[r_top_out, r_top_out, r_bot_out],
        th0=[0.0, half_pi, np.pi], th1=[half_pi, np.pi, 2 * np.pi])
    # flange strip and the two side strips (for a solid region the side strips meet at y = 0)
    rects = rectangle_moments(
        y1=[-ya, r_bot_in, -r_bot_out], y2=[ya, r_bot_out, -r_bot_in],
        z1=[za + r_top_in, 0.0, 0.0], z2=[za + r_top_out, za, za])
    return sectors.sum(axis=0) + rects.sum(axis=0)


def _midline_moments(s: USection) -> np.ndarray:
    """Thin-wall moments: mid-line (radii r - t/2) as a curve carrying thickness t."""
    t = s.wall_thickness
    rt, rb = s.top_arc_outer_radius - t / 2, s.bottom_arc_outer_radius - t / 2
    ya, za = s.top_arc_centre_y, s.top_arc_centre_z
    # arcs: d/dr of the solid-sector moments at r = rho gives the line integral times d rho
    y0 = np.array([ya, -ya, 0.0])
    z0 = np.array([za, za, 0.0])
    rho = np.array([rt, rt, rb])
    t0 = np.array([0.0, np.pi / 2, np.pi])
    t1 = t0 + np.array([np.pi / 2, np.pi / 2, np.pi])
    dth, ds2 = t1 - t0, (np.sin(2 * t1) - np.sin(2 * t0)) / 4.0
    L = rho * dth
    su, sv = rho**2 * (np.sin(t1) - np.sin(t0)), rho**2 * (np.cos(t0) - np.cos(t1))
    suu, svv = rho**3 * (dth / 2 + ds2), rho**3 * (dth / 2 - ds2)
    suv = rho**3 * (np.sin(t1) ** 2 - np.sin(t0) ** 2) / 2
    arcs = np.stack([L, su + y0 * L, sv + z0 * L, suu + 2 * y0 * su + y0**2 * L,
                     svv + 2 * z0 * sv + z0**2 * L, suv + y0 * sv + z0 * su + y0 * z0 * L], -1)
    # straight lines: flange y in [-ya, ya] at z = za + rt; sides z in [0, za] at y = +-rb
    zf = za + rt
    flange = np.array([2 * ya, 0.0, 2 * ya * zf, 2 * ya**3 / 3, 2 * ya * zf**2, 0.0])
    sides = np.array([2 * za, 0.0, za**2, 2 * za * rb**2, 2 * za**3 / 3, 0.0])
    return t * (arcs.sum(axis=0) + flange + sides)


def section_properties(section: USection, E: float, nu: float, rho: float,
                       method: Literal["exact", "midline"] = "exact") -> SectionProperties:
    """Section constants of a U-section; E, Pa; nu, 1; rho, kg/m^3.

    method="exact" integrates over the true wall (default); "midline" is the thin-wall
    approximation.  The torsion constant is Bredt-Batho in both cases.
    """
    if not (np.isfinite(E) and E > 0):
        raise SceneError(f"E = {E!r} Pa: allowed range (0, inf)")
    if not (np.isfinite(nu) and -1.0 < nu < 0.5):
        raise SceneError(f"nu = {nu!r}: allowed range (-1, 0.5)")
    if not (np.isfinite(rho) and rho > 0):
        raise SceneError(f"rho = {rho!r} kg/m^3: allowed range (0, inf)")
    s, t = section, section.wall_thickness
    r, big_r = s.top_arc_outer_radius, s.bottom_arc_outer_radius
    if method == "exact":
        m = _region_moments(s, r - t, r, big_r - t, big_r)
    elif method == "midline":
        m = _midline_moments(s)
    else:
        raise SceneError(f"method = {method!r}: allowed values 'exact', 'midline'")
    area, sy, sz, syy, szz, syz = (float(x) for x in m)
    y_c, z_c = sy / area, sz / area
    i_t = szz - area * z_c**2
    i_b = syy - area * y_c**2
    i_tb = syz - area * y_c * z_c
    # Bredt-Batho: region enclosed by the mid-line = solid region with mid-line radii
    rm_t, rm_b = r - t / 2, big_r - t / 2
    a_m = float(_region_moments(s, 0.0, rm_t, 0.0, rm_b)[0])
    p_m = np.pi * rm_t + np.pi * rm_b + 2 * s.top_arc_centre_y + 2 * s.top_arc_centre_z
    j = 4.0 * a_m**2 * t / p_m
    g = E / (2.0 * (1.0 + nu))
    return SectionProperties(
        area=area, mass_per_length=rho * area, y_c=y_c, z_c=z_c,
        I_t=i_t, I_b=i_b, I_tb=i_tb, J=j, A_m=a_m, P_m=float(p_m),
        rho_I_t=rho * i_t, rho_I_b=rho * i_b, rho_I_polar=rho * (i_t + i_b),
        E=E, G=g, rho=rho, EA=E * area, GJ=g * j, EI_t=E * i_t, EI_b=E * i_b)
