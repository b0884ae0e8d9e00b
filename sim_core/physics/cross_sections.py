"""Cross-section constants of hollow boom sections: area, centroid, second moments, St. Venant
torsion constant, shear centre, wall boundaries and the bearing patches of the outer face.

Units: SI (m, m^2, m^4; mass per length kg/m).  Section frame: y lateral (along e_t), z up
(along e_b); the origin is the beam's reference line, shared by nested booms.  Second moments
are centroidal: I_t = int (z - z_c)^2 dA (bending in the luffing plane, about e_t),
I_b = int (y - y_c)^2 dA (lateral bending, about e_b), I_tb = int (y - y_c)(z - z_c) dA.

Shapes (``spec["shape"]``):
  "u"           the paper's U family (Zhao, Qi, Wang 2024, Table 1 / Figure 8), exactly as
                :class:`sim_core.physics.sections.USection`; origin = centre of the lower half
                circle.  y_a = z_a = 0 and r = R is a circular tube.
  "box"         rectangular tube, optionally with rounded corners (outer corner radius r_c,
                inner corner radius max(r_c - t, 0)); origin = box centre.
  "polygon"     closed polygonal tube: a regular n-gon (origin = its centre) or an explicit
                counter-clockwise outer contour whose inner boundary is the outer one offset
                inwards by the wall thickness (mitre joins: faces stay parallel).
  "properties"  constants given directly, no geometry.

Methods:
  "sectionproperties"  finite-element cross-section analysis of the wall polygon with the
                       ``sectionproperties`` package (R. van der Walt), which implements
                       Pilkey, "Analysis and Design of Elastic Beams: Computational Methods"
                       (Wiley 2002): area and second moments by Gauss quadrature over the
                       straight-sided 6-node triangles (exact for the polygon), the warping
                       function omega from the Saint-Venant torsion problem and
                       J = I_x + I_y - omega^T K omega (Pilkey 2002), shear centre by the
                       elasticity approach (Pilkey 2002).
  "closed form"        area, first and second moments of the exact region (arcs as arcs) by
                       Green's theorem, evaluated as a fan of signed triangles from the origin
                       over the straight faces (polygon moment formulas, Steger 1996, "On the
                       calculation of arbitrary moments of polygons", TU Munich report
                       FGBV-96-05) and of signed circular sectors over the arcs (exact sector
                       integrals of :func:`sim_core.physics.sections.annular_sector_moments`);
                       torsion by Bredt-Batho for a closed single-cell thin-walled tube,
                       J = 4 A_m^2 t / P_m (Bredt 1896; Timoshenko & Goodier, "Theory of
                       Elasticity", torsion of thin tubular members), A_m and P_m the area
                       enclosed by and the length of the wall mid-line (the outer boundary
                       offset inwards by t/2); shear centre on the symmetry axes (box, regular
                       polygon, circular tube: the centre; u: y_s = 0, z_s = nan; explicit
                       contour: nan).  For "u" the values equal
                       :func:`sim_core.physics.sections.section_properties` (method "exact").
  "given"              (result only) the "properties" shape.

Arc discretisation.  ``outer`` / ``inner`` (and :func:`clearance`) use inscribed polygons with
a segment angle of 0.25 deg: the boundary lies at most r dtheta^2/8 = 1.2e-6 r inside the true
arc (0.5 um for the paper booms), A and I of that polygon are low by dtheta^2/6 and dtheta^2/3
(6e-6; series expansion of the chord against the arc).  The finite-element mesh uses a coarser
moment-preserving polygon: each arc of angle dtheta is replaced by the chords through its end
points and the mid-angle points at radius r (1 + dtheta^2/12), which cancels the dtheta^2 terms
of the area, first and second moments of the fan triangles against the circular sectors
(series expansion).  Its segment length along the outer arcs starts at 2 t and is halved until
the polygon's A, I_t, I_b differ from the exact closed-form values by at most 2e-5 relative
(I_tb by 2e-5 sqrt(I_t I_b), the centroid by 2e-5 times the polar radius of gyration); the
check runs for every section, so A and I of the "sectionproperties" result are within 2e-5 of
exact (measured: circular tube R = 0.39 m, t = 15 mm, 2.9e-6; paper U booms 1-3, 4e-6 to
1.6e-5; box with 30 mm corners, 3e-6).

Mesh rule: the largest triangle area is (t/2)^2 (t = wall thickness, ``MESH_SIZE_PER_WALL``),
i.e. about two quadratic triangles across the wall.  A and I do not depend on the mesh.  J
converges from above (displacement-type finite elements are too stiff).  J at this rule
against a mesh 16 times finer in area, (t/8)^2, measured: box 0.4 x 0.6 m, t = 12 mm, sharp
corners +0.050 % (+0.06 % against the Richardson extrapolation; the re-entrant inner corners
converge slowest); regular hexagon, 0.5 m across flats, t = 10 mm, +0.038 % (+0.04 %); box
with 30 mm corner radius < 0.001 %; circular tube R = 0.39 m, t = 15 mm, +0.003 % (J against
the exact I_t + I_b: +0.0003 %); paper U booms 1 and 3 +0.005 % and +0.001 %.  All are below
the 0.2 % target; the rule (t/1)^2 gives +0.15 % for the sharp box, too close to it.  Time per
section (mesh, geometric and warping analysis; cached afterwards) on this 2-core machine:
0.2-0.45 s (paper U boom about 0.3 s); the first call in a process also imports
sectionproperties and shapely (about 0.5 s), and the very first call after installing
sectionproperties compiles and caches its numba kernels once (about 9 s).  The results are
cached in the process and on disk (``$BOOM_SIM_CACHE_DIR``, default
``~/.cache/telescopic-boom-sim/sections``; an empty value switches the disk cache off), keyed
on the wall polygons, the mesh rule and the sectionproperties version, so a scene's sections
are analysed once per machine.

Why the torsion constant matters: paper Table 2 uses the polar moment I_t + I_b as the torsion
constant (GJ/G = 2 EI/E), which is exact only for a circular tube.  The St. Venant constant of a
real section is smaller: for a thin square tube of side b and wall t, J = b^3 t (Bredt) against
I_t + I_b = (4/3) b^3 t (second moments of the four thin walls), i.e. about 25 % lower; for
the paper's U sections about 10 % lower; for an open (slit) section it is orders of magnitude lower (J = P t^3 / 3, Saint-Venant thin
strip).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sim_core.errors import SceneError
from sim_core.physics.sections import annular_sector_moments

__all__ = ["METHODS", "SHAPES", "CrossSection", "analysed_section", "clearance", "cross_section"]

#: Section shapes accepted by :func:`cross_section`.
SHAPES = ("u", "box", "polygon", "properties")
#: Methods accepted by :func:`cross_section`.
METHODS = ("sectionproperties", "closed form")

#: Largest triangle area of the finite-element mesh is (MESH_SIZE_PER_WALL * t)^2 (module doc).
MESH_SIZE_PER_WALL = 0.5
#: Largest relative error of A, I_t, I_b of the polygonal wall handed to the mesh.
ARC_RTOL = 2e-5
#: Arc segment angle of the ``outer`` / ``inner`` output polygons, rad (0.25 deg).
OUTPUT_ARC_ANGLE = math.pi / 720
#: Mitre limit of the inward offset of an explicit contour (large: faces stay parallel).
_MITRE_LIMIT = 1e6
#: Tolerance of the tangency condition R = y_a + r of the "u" shape, m (as sections.USection).
_TANGENCY_TOL = 1e-9

_UNITS = {"A": "m^2", "I_t": "m^4", "I_b": "m^4", "I_tb": "m^4", "J": "m^4",
          "mass_per_length": "kg/m", "rotation_deg": "deg", "n_sides": ""}
_REQUIRED = {
    "u": ("top_arc_centre_y", "top_arc_centre_z", "top_arc_radius", "wall"),
    "box": ("width", "height", "wall"),
    "polygon": ("wall",),
    "properties": ("A", "I_t", "I_b", "J", "mass_per_length"),
}
_OPTIONAL = {
    "u": ("bottom_arc_radius",),
    "box": ("corner_radius",),
    "polygon": ("n_sides", "width_across_flats", "circumradius", "rotation_deg", "contour"),
    "properties": ("y_c", "z_c", "I_tb"),
}


@dataclass(frozen=True, eq=False)
class CrossSection:
    """Constants of one boom cross-section (SI units, section frame y = e_t, z = e_b).

    shape : "u", "box", "polygon" or "properties".
    A : area, m^2.
    I_t, I_b, I_tb : centroidal second moments int (z-z_c)^2, int (y-y_c)^2, int (y-y_c)(z-z_c)
        dA, m^4 (I_t: bending in the luffing plane).
    J : St. Venant torsion constant, m^4.
    y_c, z_c : centroid, m.   y_s, z_s : shear centre, m (nan where unknown).
    outer, inner : (n, 2) outer / inner wall boundary polygons (y, z), counter-clockwise, first
        point not repeated, arcs discretised (read-only); None for "properties".
    patches : bearing patches of the outer face in counter-clockwise order,
        ("arc", name, yc, zc, radius, theta0, theta1) (azimuth from +y towards +z, rad,
        theta1 > theta0) or ("face", name, y0, z0, y1, z1) (outward normal (dz, -dy)/|d|);
        () for "properties".
    mass_per_length : kg/m, only for "properties" (else None: rho A is the caller's).
    method : "sectionproperties", "closed form" or "given".
    """

    shape: str
    A: float
    I_t: float
    I_b: float
    I_tb: float
    J: float
    y_c: float
    z_c: float
    y_s: float
    z_s: float
    outer: np.ndarray | None
    inner: np.ndarray | None
    patches: tuple
    mass_per_length: float | None
    method: str
    #: the normalised spec (shape, items) the section was made from (None: built directly);
    #: :mod:`sim_core.physics.section_stress` meshes the same walls from it
    key: tuple | None = None


# ----------------------------------------------------------------------------- input checks

def _fmt(x: float) -> str:
    return f"{x:.6g}"


def _number(where: str, key: str, value, unit: str) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(
            value, (int, float, np.integer, np.floating)):
        raise SceneError(f"{where}.{key} = {value!r}: must be a number"
                         + (f" in {unit}" if unit else ""))
    v = float(value)
    if not math.isfinite(v):
        raise SceneError(f"{where}.{key} = {value!r} {unit}: must be finite".replace("  ", " "))
    return v


def _check_range(where: str, key: str, v: float, lo: float, hi: float, unit: str,
                 lo_closed: bool = False, hi_closed: bool = False, why: str = "") -> float:
    ok = (v >= lo if lo_closed else v > lo) and (v <= hi if hi_closed else v < hi)
    if not ok:
        rng = f"{'[' if lo_closed else '('}{_fmt(lo)}, {_fmt(hi)}{']' if hi_closed else ')'}"
        u = f" {unit}" if unit else ""
        raise SceneError(f"{where}.{key} = {v!r}{u}: allowed range {rng}{u}"
                         + (f" ({why})" if why else ""))
    return v


def _check_keys(where: str, shape: str, spec: Mapping) -> None:
    allowed = ("shape", "_where") + _REQUIRED[shape] + _OPTIONAL[shape]
    for key in spec:
        if key not in allowed:
            raise SceneError(
                f"{where}.{key}: unknown key for shape {shape!r}; allowed keys: "
                + ", ".join(k for k in allowed if k != "_where"))
    for key in _REQUIRED[shape]:
        if key not in spec:
            raise SceneError(
                f"{where}.{key} missing: shape {shape!r} needs " + ", ".join(_REQUIRED[shape])
                + " (optional: " + ", ".join(_OPTIONAL[shape]) + ")")


def _normalise(spec: Mapping) -> tuple:
    """Check ``spec`` and return a hashable key (shape, ((name, value), ...))."""
    if not isinstance(spec, Mapping):
        raise SceneError(f"section spec = {spec!r}: must be a dict with key 'shape'")
    where = str(spec.get("_where", "section"))
    if "shape" not in spec:
        raise SceneError(f"{where}.shape missing: allowed values " + ", ".join(map(repr, SHAPES)))
    shape = spec["shape"]
    if shape not in SHAPES:
        raise SceneError(f"{where}.shape = {shape!r}: allowed values "
                         + ", ".join(map(repr, SHAPES)))
    _check_keys(where, shape, spec)
    return {"u": _norm_u, "box": _norm_box, "polygon": _norm_polygon,
            "properties": _norm_properties}[shape](where, spec)


def _norm_u(where: str, spec: Mapping) -> tuple:
    ya = _number(where, "top_arc_centre_y", spec["top_arc_centre_y"], "m")
    za = _number(where, "top_arc_centre_z", spec["top_arc_centre_z"], "m")
    r = _number(where, "top_arc_radius", spec["top_arc_radius"], "m")
    t = _number(where, "wall", spec["wall"], "m")
    _check_range(where, "top_arc_centre_y", ya, 0.0, math.inf, "m", lo_closed=True,
                 why="negative values make the top arcs P1, P2 overlap")
    _check_range(where, "top_arc_centre_z", za, 0.0, math.inf, "m", lo_closed=True,
                 why="negative values make the top arcs overlap the lower half circle")
    _check_range(where, "top_arc_radius", r, 0.0, math.inf, "m")
    expected = ya + r
    if "bottom_arc_radius" in spec:
        big_r = _number(where, "bottom_arc_radius", spec["bottom_arc_radius"], "m")
        if abs(big_r - expected) > _TANGENCY_TOL:
            raise SceneError(
                f"{where}.bottom_arc_radius = {big_r!r} m: must equal top_arc_centre_y + "
                f"top_arc_radius = {_fmt(expected)} m (+-{_TANGENCY_TOL} m) for vertical side "
                "walls tangent to both arcs (or leave it out)")
    _check_range(where, "wall", t, 0.0, r, "m",
                 why="below the top arc radius top_arc_radius: inner radius r - t > 0")
    return ("u", (("top_arc_centre_y", ya), ("top_arc_centre_z", za), ("top_arc_radius", r),
                  ("wall", t)))


def _norm_box(where: str, spec: Mapping) -> tuple:
    w = _check_range(where, "width", _number(where, "width", spec["width"], "m"),
                     0.0, math.inf, "m")
    h = _check_range(where, "height", _number(where, "height", spec["height"], "m"),
                     0.0, math.inf, "m")
    half = min(w, h) / 2
    rc = _number(where, "corner_radius", spec.get("corner_radius", 0.0), "m")
    _check_range(where, "corner_radius", rc, 0.0, half, "m", lo_closed=True,
                 why="outer corner radius, below min(width, height)/2")
    t = _number(where, "wall", spec["wall"], "m")
    _check_range(where, "wall", t, 0.0, half, "m", why="below min(width, height)/2")
    return ("box", (("width", w), ("height", h), ("wall", t), ("corner_radius", rc)))


def _norm_polygon(where: str, spec: Mapping) -> tuple:
    t = _number(where, "wall", spec["wall"], "m")
    regular_keys = [k for k in ("n_sides", "width_across_flats", "circumradius", "rotation_deg")
                    if k in spec]
    if "contour" in spec:
        if regular_keys:
            raise SceneError(
                f"{where}.{regular_keys[0]}: not allowed together with contour (give either "
                "contour and wall, or n_sides, width_across_flats or circumradius, wall and "
                "optional rotation_deg)")
        return _norm_contour(where, spec["contour"], t)
    if "n_sides" not in spec:
        raise SceneError(f"{where}.n_sides missing: shape 'polygon' needs either n_sides "
                         "(with width_across_flats or circumradius) or contour")
    n_raw = spec["n_sides"]
    n = _number(where, "n_sides", n_raw, "")
    if n != int(n) or not 3 <= n <= 24:
        raise SceneError(f"{where}.n_sides = {n_raw!r}: allowed values 3, 4, ..., 24")
    n = int(n)
    given = [k for k in ("width_across_flats", "circumradius") if k in spec]
    if len(given) != 1:
        raise SceneError(
            f"{where}.width_across_flats / {where}.circumradius: give exactly one "
            f"(got {len(given)})")
    key = given[0]
    size = _check_range(where, key, _number(where, key, spec[key], "m"), 0.0, math.inf, "m")
    if key == "width_across_flats":
        if n % 2:
            raise SceneError(
                f"{where}.width_across_flats = {size!r} m: an odd polygon (n_sides = {n}) has "
                "no opposite faces; give circumradius instead")
        apothem = size / 2
    else:
        apothem = size * math.cos(math.pi / n)
    rot = _number(where, "rotation_deg", spec.get("rotation_deg", 0.0), "deg")
    _check_range(where, "wall", t, 0.0, apothem, "m",
                 why="below the apothem (half the width across flats)")
    return ("polygon", (("n_sides", n), ("apothem", apothem), ("rotation_deg", rot),
                        ("wall", t)))


def _norm_contour(where: str, contour, t: float) -> tuple:
    import shapely
    from shapely.geometry import Polygon
    from shapely.validation import explain_validity

    _check_range(where, "wall", t, 0.0, math.inf, "m")
    key = "contour"
    try:
        pts = np.asarray(contour, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(f"{where}.{key}: must be a list of [y, z] points in m") from None
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
        raise SceneError(f"{where}.{key}: must be a list of at least 3 [y, z] points in m "
                         f"(got shape {pts.shape})")
    if not np.all(np.isfinite(pts)):
        raise SceneError(f"{where}.{key}: all coordinates must be finite")
    if np.array_equal(pts[0], pts[-1]):
        pts = pts[:-1]          # a closing repeat of the first point
    scale = float(np.ptp(pts, axis=0).max())
    seg = np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1)
    if len(pts) < 3 or scale <= 0 or np.any(seg <= 1e-12 * scale):
        i = int(np.argmin(seg)) if len(seg) else 0
        raise SceneError(f"{where}.{key}: point {(i + 1) % max(len(pts), 1)} repeats point {i}; "
                         "give at least 3 distinct points")
    poly = Polygon(pts)
    if not poly.is_valid:
        raise SceneError(f"{where}.{key}: the contour self-intersects or is degenerate "
                         f"({explain_validity(poly)}); give a simple polygon")
    signed = _fan_moments_polygon(pts)[0]
    if signed <= 0:
        raise SceneError(f"{where}.{key}: the contour is clockwise (signed area "
                         f"{_fmt(signed)} m^2); give the vertices counter-clockwise")
    inner = poly.buffer(-t, join_style="mitre", mitre_limit=_MITRE_LIMIT)
    if inner.is_empty:
        r_in = float(shapely.maximum_inscribed_circle(poly, scale * 1e-6).length)
        raise SceneError(f"{where}.wall = {t!r} m: allowed range (0, {_fmt(r_in)}) m (below "
                         "the contour's inscribed radius): the inner boundary is empty")
    if inner.geom_type != "Polygon":
        raise SceneError(f"{where}.wall = {t!r} m: the inner boundary splits into "
                         f"{len(inner.geoms)} cells where the contour is narrower than twice "
                         "the wall; only single-cell tubes are handled (use a thinner wall)")
    return ("polygon", (("contour", tuple(map(tuple, pts.tolist()))), ("wall", t)))


def _norm_properties(where: str, spec: Mapping) -> tuple:
    vals = {}
    for key in ("A", "I_t", "I_b", "J", "mass_per_length"):
        vals[key] = _check_range(where, key, _number(where, key, spec[key], _UNITS[key]),
                                 0.0, math.inf, _UNITS[key])
    for key in ("y_c", "z_c", "I_tb"):
        vals[key] = _number(where, key, spec.get(key, 0.0), _UNITS.get(key, "m"))
    bound = math.sqrt(vals["I_t"] * vals["I_b"])
    _check_range(where, "I_tb", vals["I_tb"], -bound, bound, "m^4",
                 why="|I_tb| < sqrt(I_t I_b): the second-moment tensor is positive definite")
    return ("properties", tuple(vals.items()))


# ------------------------------------------------------------------------ boundary geometry

def _boundary(shape: str, p: dict, d: float) -> list[tuple]:
    """Patches of the outer boundary offset inwards by d (d = 0 outer, t/2 mid-line, t inner).

    Zero-length faces and zero-radius arcs are left out.
    """
    if shape == "u":
        ya, za, r = p["top_arc_centre_y"], p["top_arc_centre_z"], p["top_arc_radius"]
        rr, big = r - d, ya + r - d
        out = [("arc", "P1", ya, za, rr, 0.0, math.pi / 2)]
        if ya > 0:
            out.append(("face", "flange", ya, za + rr, -ya, za + rr))
        out.append(("arc", "P2", -ya, za, rr, math.pi / 2, math.pi))
        if za > 0:
            out.append(("face", "side_left", -big, za, -big, 0.0))
        out.append(("arc", "P3", 0.0, 0.0, big, math.pi, 2 * math.pi))
        if za > 0:
            out.append(("face", "side_right", big, 0.0, big, za))
        return out
    if shape == "box":
        hw, hh = p["width"] / 2 - d, p["height"] / 2 - d
        rd = max(p["corner_radius"] - d, 0.0)
        cy, cz = hw - rd, hh - rd
        faces = [("face", "bottom", -cy, -hh, cy, -hh), ("face", "right", hw, -cz, hw, cz),
                 ("face", "top", cy, hh, -cy, hh), ("face", "left", -hw, cz, -hw, -cz)]
        if rd <= 0:
            return faces
        arcs = [("arc", "corner_br", cy, -cz, rd, 1.5 * math.pi, 2 * math.pi),
                ("arc", "corner_tr", cy, cz, rd, 0.0, 0.5 * math.pi),
                ("arc", "corner_tl", -cy, cz, rd, 0.5 * math.pi, math.pi),
                ("arc", "corner_bl", -cy, -cz, rd, math.pi, 1.5 * math.pi)]
        return [x for pair in zip(faces, arcs) for x in pair]
    if shape == "polygon" and "contour" in p:
        pts = np.asarray(p["contour"], dtype=float)
        if d > 0:
            pts = _offset_contour(pts, d)
        return _polygon_faces(pts)
    if shape == "polygon":
        n, a = p["n_sides"], p["apothem"] - d
        rc = a / math.cos(math.pi / n)
        phi = -math.pi / 2 + math.radians(p["rotation_deg"]) - math.pi / n \
            + 2 * math.pi * np.arange(n) / n
        return _polygon_faces(np.column_stack([rc * np.cos(phi), rc * np.sin(phi)]))
    raise AssertionError(shape)


def _offset_contour(pts: np.ndarray, d: float) -> np.ndarray:
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    inner = orient(Polygon(pts).buffer(-d, join_style="mitre", mitre_limit=_MITRE_LIMIT), 1.0)
    return np.asarray(inner.exterior.coords, dtype=float)[:-1]


def _polygon_faces(pts: np.ndarray) -> list[tuple]:
    """Faces "face_1".."face_n" of a CCW polygon, face_1 the one whose outward normal is closest
    to -z (ties, i.e. a vertex at the bottom: the face on the +y side of it)."""
    nxt = np.roll(pts, -1, axis=0)
    d = nxt - pts
    normal_angle = np.arctan2(-d[:, 0], d[:, 1])        # outward normal (dz, -dy)
    delta = (normal_angle + math.pi / 2 + math.pi) % (2 * math.pi) - math.pi
    key = np.round(np.abs(delta), 9) - 1e-12 * np.sign(delta)
    first = int(np.argmin(key))
    order = np.roll(np.arange(len(pts)), -first)
    return [("face", f"face_{k + 1}", float(pts[i, 0]), float(pts[i, 1]),
             float(nxt[i, 0]), float(nxt[i, 1])) for k, i in enumerate(order)]


def _discretise(patches: list[tuple], n_arc: Sequence[int], moment: bool) -> np.ndarray:
    """Polygon (m, 2) through the patches; arc j split into n_arc[j] equal angles dtheta.

    moment=False: inscribed chords (vertices on the arc).  moment=True: the arc's end points
    plus one vertex at the middle of each angle, at radius r (1 + dtheta^2/12); this radius
    cancels the dtheta^2 terms of the area, first and second moments of each fan triangle
    against its circular sector (series expansion), leaving O(dtheta^3) from the half segments
    at the arc ends."""
    pts, j = [], 0
    for pa in patches:
        if pa[0] == "face":
            pts.append((pa[2], pa[3]))
            continue
        yc, zc, rad, th0, th1 = pa[2:]
        n = n_arc[j]
        j += 1
        dth = (th1 - th0) / n
        if moment:
            th = th0 + dth * (np.arange(n) + 0.5)
            rv = rad * (1.0 + dth * dth / 12.0)
            pts.append((yc + rad * math.cos(th0), zc + rad * math.sin(th0)))
        else:
            th = th0 + dth * np.arange(n)
            rv = rad
        pts.extend(zip(yc + rv * np.cos(th), zc + rv * np.sin(th)))
    return np.asarray(pts, dtype=float)


# -------------------------------------------------------------------- exact (Green) moments

def _fan_triangles(p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """Signed moments (A, Sy, Sz, Syy, Szz, Syz) of the triangles (origin, p0, p1), summed.

    Green's theorem for a closed boundary = sum of these over its straight pieces (standard
    polygon moment formulas, e.g. Steger 1996)."""
    y0, z0, y1, z1 = p0[..., 0], p0[..., 1], p1[..., 0], p1[..., 1]
    c = y0 * z1 - y1 * z0
    return np.array([
        np.sum(c) / 2,
        np.sum(c * (y0 + y1)) / 6,
        np.sum(c * (z0 + z1)) / 6,
        np.sum(c * (y0 * y0 + y0 * y1 + y1 * y1)) / 12,
        np.sum(c * (z0 * z0 + z0 * z1 + z1 * z1)) / 12,
        np.sum(c * (2 * y0 * z0 + y0 * z1 + y1 * z0 + 2 * y1 * z1)) / 24,
    ])


def _fan_moments_polygon(pts: np.ndarray) -> np.ndarray:
    return _fan_triangles(pts, np.roll(pts, -1, axis=0))


def _exact_moments(patches: list[tuple]) -> np.ndarray:
    """Exact moments of the region enclosed by CCW patches (arcs as arcs).

    An arc's fan contribution = its circular sector (exact sector integrals) minus the fans of
    the two radii (centre -> start, end -> centre), since the sector's boundary is radius, arc,
    radius."""
    total = np.zeros(6)
    for pa in patches:
        if pa[0] == "face":
            total += _fan_triangles(np.array(pa[2:4]), np.array(pa[4:6]))
        else:
            yc, zc, rad, th0, th1 = pa[2:]
            c = np.array([yc, zc])
            s = c + rad * np.array([math.cos(th0), math.sin(th0)])
            e = c + rad * np.array([math.cos(th1), math.sin(th1)])
            total += annular_sector_moments(yc, zc, 0.0, rad, th0, th1)
            total -= _fan_triangles(c, s) + _fan_triangles(e, c)
    return total


def _centroidal(m: np.ndarray) -> tuple[float, float, float, float, float, float]:
    """(A, y_c, z_c, I_t, I_b, I_tb) from origin moments (A, Sy, Sz, Syy, Szz, Syz)."""
    a, sy, sz, syy, szz, syz = (float(x) for x in m)
    y_c, z_c = sy / a, sz / a
    return a, y_c, z_c, szz - a * z_c**2, syy - a * y_c**2, syz - a * y_c * z_c


def _perimeter(patches: list[tuple]) -> float:
    return sum(math.hypot(pa[4] - pa[2], pa[5] - pa[3]) if pa[0] == "face"
               else pa[4] * (pa[6] - pa[5]) for pa in patches)


# ------------------------------------------------------------------------------ computation

def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=float)
    a.flags.writeable = False
    return a


def _walls(shape: str, p: dict) -> tuple[np.ndarray, np.ndarray]:
    """Outer and inner boundaries for output and clearance: inscribed chords of OUTPUT_ARC_ANGLE
    (module docstring)."""
    out = []
    for d in (0.0, p["wall"]):
        patches = _boundary(shape, p, d)
        n = [max(1, math.ceil((pa[6] - pa[5]) / OUTPUT_ARC_ANGLE - 1e-9))
             for pa in patches if pa[0] == "arc"]
        out.append(_discretise(patches, n, moment=False))
    return out[0], out[1]


def _mesh_walls(shape: str, p: dict, exact: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Outer and inner boundaries for the finite-element mesh: moment-preserving polygons
    (see _discretise), segment length along the outer arcs starting at 2 t and halved until A,
    I_t and I_b are within ARC_RTOL of the exact values (module docstring)."""
    t = p["wall"]
    out_p, in_p = _boundary(shape, p, 0.0), _boundary(shape, p, t)
    arcs_o = {pa[1]: pa for pa in out_p if pa[0] == "arc"}
    a_ex, yc_ex, zc_ex, it_ex, ib_ex, itb_ex = exact
    gyration = math.sqrt((it_ex + ib_ex) / a_ex)
    seg = 2.0 * t
    for _ in range(20):
        # same subdivision for an outer arc and its inner offset (same name)
        n = {name: max(1, math.ceil(pa[4] * (pa[6] - pa[5]) / seg)) for name, pa in arcs_o.items()}
        outer = _discretise(out_p, [n[pa[1]] for pa in out_p if pa[0] == "arc"], moment=True)
        inner = _discretise(in_p, [n[pa[1]] for pa in in_p if pa[0] == "arc"], moment=True)
        a, yc, zc, it, ib, itb = _centroidal(_fan_moments_polygon(outer)
                                             - _fan_moments_polygon(inner))
        err = max(abs(a / a_ex - 1), abs(it / it_ex - 1), abs(ib / ib_ex - 1),
                  abs(itb - itb_ex) / math.sqrt(it_ex * ib_ex),
                  math.hypot(yc - yc_ex, zc - zc_ex) / gyration)
        if not arcs_o or err <= ARC_RTOL:
            return outer, inner
        seg /= 2
    raise AssertionError("arc discretisation did not converge")  # pragma: no cover


def _closed_form(shape: str, p: dict) -> dict:
    t = p["wall"]
    out_p, in_p, mid_p = (_boundary(shape, p, d) for d in (0.0, t, t / 2))
    exact = _centroidal(_exact_moments(out_p) - _exact_moments(in_p))
    a_m = float(_exact_moments(mid_p)[0])
    p_m = _perimeter(mid_p)
    j_bredt = 4.0 * a_m**2 * t / p_m
    if shape == "u":
        circle = p["top_arc_centre_y"] == 0.0 and p["top_arc_centre_z"] == 0.0
        y_s, z_s = 0.0, (0.0 if circle else math.nan)
    elif shape == "polygon" and "contour" in p:
        y_s = z_s = math.nan
    else:
        y_s = z_s = 0.0
    return {"exact": exact, "J": j_bredt, "y_s": y_s, "z_s": z_s, "patches": out_p}


def _cache_dir():
    """Folder of the on-disk cache of finite-element results: ``$BOOM_SIM_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/telescopic-boom-sim/sections`` (default ``~/.cache``); None where the
    variable is set to an empty string (no disk cache)."""
    import os
    from pathlib import Path
    env = os.environ.get("BOOM_SIM_CACHE_DIR")
    if env is not None:
        return Path(env) if env else None
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "telescopic-boom-sim" / "sections"


def _fe(outer: np.ndarray, inner: np.ndarray, t: float) -> dict:
    """The finite-element constants of the wall between ``outer`` and ``inner``, from the disk
    cache where an analysis of the same polygons, mesh rule and sectionproperties version is
    there (a deterministic computation: the same inputs give the same numbers), else computed
    and stored (:func:`disk_cached`)."""
    import hashlib
    from importlib.metadata import version

    h = hashlib.sha256()
    for a in (outer, inner):
        h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    h.update(repr((float(t), MESH_SIZE_PER_WALL, _CACHE_FORMAT,
                   version("sectionproperties"))).encode())
    vals = disk_cached(h.hexdigest(), _FE_KEYS, lambda: _fe_compute(outer, inner, t))
    return {k: float(v) for k, v in vals.items()}


def disk_cached(name: str, keys: set, compute) -> dict:
    """The JSON object ``name`` of the disk cache (:func:`_cache_dir`) where it is there and has
    exactly the ``keys``, else ``compute()`` (a JSON-serialisable dict), stored atomically
    (temporary file and rename; an unwritable cache is skipped)."""
    import json
    import os
    import tempfile

    folder = _cache_dir()
    path = None if folder is None else folder / f"{name}.json"
    if path is not None and path.is_file():
        try:
            vals = json.loads(path.read_text())
            if set(vals) == set(keys):
                return vals
        except (OSError, ValueError):
            pass
    vals = compute()
    if path is not None:
        try:
            folder.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
            with os.fdopen(fd, "w") as f:
                json.dump(vals, f)
            os.replace(tmp, path)
        except OSError:
            pass
    return vals


#: Version of the cache entries' content (bump when _fe_compute changes what it returns).
_CACHE_FORMAT = 1
_FE_KEYS = {"A", "y_c", "z_c", "I_t", "I_b", "I_tb", "J", "y_s", "z_s"}


def _sp_section(outer: np.ndarray, inner: np.ndarray, t: float):
    """The sectionproperties Section of the wall between ``outer`` and ``inner`` (mesh rule of
    the module docstring), its geometric and warping analyses done."""
    try:
        from sectionproperties.analysis.section import Section
        from sectionproperties.pre.geometry import Geometry
    except ImportError as exc:  # pragma: no cover - dependency of the package
        raise ImportError("cross_section(method='sectionproperties') needs the "
                          "sectionproperties package (pip install sectionproperties); "
                          "method='closed form' works without it") from exc
    from shapely.geometry import Polygon

    geom = Geometry(Polygon(outer, holes=[inner[::-1]]))
    geom.create_mesh(mesh_sizes=[(MESH_SIZE_PER_WALL * t) ** 2])
    sec = Section(geom)
    sec.calculate_geometric_properties()
    sec.calculate_warping_properties()
    return sec


def analysed_section(cs: CrossSection):
    """The finite-element section (sectionproperties ``Section``, geometric and warping
    analyses done) of ``cs``: the walls and mesh of the "sectionproperties" method, whatever
    method gave ``cs`` (for the stress recovery of :mod:`sim_core.physics.section_stress`).
    Raises SceneError for a section without geometry ("properties")."""
    if cs.key is None or cs.key[0] == "properties":
        raise SceneError(f"section of shape {cs.shape!r}: a stress analysis needs the wall "
                         "geometry (allowed shapes: 'u', 'box', 'polygon')")
    shape, items = cs.key
    p = dict(items)
    return _sp_section(*_mesh_walls(shape, p, _closed_form(shape, p)["exact"]), p["wall"])


def _fe_compute(outer: np.ndarray, inner: np.ndarray, t: float) -> dict:
    sec = _sp_section(outer, inner, t)
    ixx_c, iyy_c, ixy_c = sec.get_ic()   # sectionproperties x = our y, its y = our z
    y_c, z_c = sec.get_c()
    y_s, z_s = sec.get_sc()
    return {"A": float(sec.get_area()), "y_c": float(y_c), "z_c": float(z_c),
            "I_t": float(ixx_c), "I_b": float(iyy_c), "I_tb": float(ixy_c),
            "J": float(sec.get_j()), "y_s": float(y_s), "z_s": float(z_s)}


@functools.lru_cache(maxsize=512)
def _cached(key: tuple, method: str) -> CrossSection:
    shape, items = key
    p = dict(items)
    if shape == "properties":
        return CrossSection(shape=shape, A=p["A"], I_t=p["I_t"], I_b=p["I_b"], I_tb=p["I_tb"],
                            J=p["J"], y_c=p["y_c"], z_c=p["z_c"], y_s=math.nan, z_s=math.nan,
                            outer=None, inner=None, patches=(),
                            mass_per_length=p["mass_per_length"], method="given", key=key)
    cf = _closed_form(shape, p)
    outer, inner = _walls(shape, p)
    patches = tuple(tuple(float(x) if i >= 2 else x for i, x in enumerate(pa))
                    for pa in cf["patches"])
    if method == "closed form":
        a, y_c, z_c, i_t, i_b, i_tb = cf["exact"]
        vals = {"A": a, "y_c": y_c, "z_c": z_c, "I_t": i_t, "I_b": i_b, "I_tb": i_tb,
                "J": cf["J"], "y_s": cf["y_s"], "z_s": cf["z_s"]}
    else:
        vals = _fe(*_mesh_walls(shape, p, cf["exact"]), p["wall"])
    return CrossSection(shape=shape, outer=_readonly(outer), inner=_readonly(inner),
                        patches=patches, mass_per_length=None, method=method, key=key, **vals)


def cross_section(spec: dict, method: str = "sectionproperties") -> CrossSection:
    """Constants of the section described by ``spec`` (a dict with key ``shape``, see the module
    docstring), by ``method`` "sectionproperties" (finite elements, default) or "closed form".

    A "properties" spec returns its values unchanged (method "given") for either method.
    Results are cached per (spec, method).  Bad input raises SceneError naming the key.
    """
    if method not in METHODS:
        where = spec.get("_where", "section") if isinstance(spec, Mapping) else "section"
        raise SceneError(f"{where}: method = {method!r}: allowed values "
                         + ", ".join(map(repr, METHODS)))
    key = _normalise(spec)
    if key[0] == "properties":
        method = "given"
    return _cached(key, method)


def clearance(outer_boom: CrossSection, inner_boom: CrossSection) -> float:
    """Smallest distance, m, between the inner wall boundary of ``outer_boom`` and the outer
    boundary of ``inner_boom`` (both in the shared section frame) when the latter lies inside
    the former; otherwise minus the largest depth by which a point of the inner boom's outer
    boundary lies outside the outer boom's inner boundary (a negative number).

    Curved walls use the discretised polygons (error <= r dtheta^2/8, module docstring).
    """
    import shapely
    from shapely.geometry import Polygon

    for name, cs in (("outer_boom", outer_boom), ("inner_boom", inner_boom)):
        if not isinstance(cs, CrossSection):
            raise SceneError(f"clearance: {name} = {cs!r}: must be a CrossSection")
        if cs.outer is None:
            raise SceneError(f"clearance: {name} has shape {cs.shape!r} without geometry")
    hole = Polygon(outer_boom.inner)
    body = Polygon(inner_boom.outer)
    if hole.covers(body):
        return float(hole.exterior.distance(body.exterior))
    size = float(np.ptp(np.asarray(inner_boom.outer), axis=0).max())
    pts = shapely.get_coordinates(shapely.segmentize(body.exterior, size * 1e-3))
    depth = float(np.max(shapely.distance(hole, shapely.points(pts))))
    return -depth
