"""The sliders of every overlap as spring layouts of Section 8.2 (Zhao-Qi-Wang 2024, Fig. 8 and
Eq. 59), for any crane: the paper's U family or a section described boom by boom.

A slider of width 2w bears on patches of the inner boom's outer face: the rounding arcs of a U
section (the paper: P1, P2, P3), the faces and corners of a box, the faces of a polygonal tube.
Its compression-only springs sit on the contact surface, the middle of the sliding block of
thickness ``radial_gap``: the patch offset outwards by half the gap (the paper's convention,
docs/model.md#input-springs: the contact circle at mid-gap).  An arc of opening dtheta carries
``springs_per_quarter`` * dtheta / (pi/2) springs per slider end (the paper's 20 per quarter arc,
40 on the half circle), a face carries ``springs_per_quarter``.  The inner region (boom k's inner
contact section, the slider on boom k+1) and the outer region (boom k+1's outer contact section,
the slider on boom k) share the surface and differ in k_t (Eq. 61).

A slider is one pad: :func:`overlap_pads` sums its springs (both ends, every patch) into the
force and couple it puts on the overlap's inner boom, the outputs ``pad_forces``,
``pad_couples`` and ``pad_face_forces``.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.physics.contact import SliderGeometry

__all__ = ["bearing_patches", "patches_hold", "slider_geometries", "family_region", "pad_loads",
           "PAD_NAMES", "overlap_pads"]

_U_DEFAULT = ("P1", "P2", "P3")          # the paper's bearing arcs (Section 8.2, Fig. 8)


def bearing_patches(section, chosen=None) -> list[tuple]:
    """The patches of ``section`` (a CrossSection) the sliders bear on: those named in
    ``chosen``, or the shape's default (the arcs P1-P3 of a U section, every patch of a box or
    polygon)."""
    if chosen is None:
        chosen = _U_DEFAULT if section.shape == "u" else [p[1] for p in section.patches]
    by_name = {p[1]: p for p in section.patches}
    return [by_name[name] for name in chosen if name in by_name]


def _normals(patches) -> np.ndarray:
    """Azimuths (rad) of the outward normals a set of patches offers (arcs sampled)."""
    out = []
    for p in patches:
        if p[0] == "arc":
            out.extend(np.linspace(p[5], p[6], 9))
        else:
            _, _, y0, z0, y1, z1 = p
            out.append(math.atan2(-(y1 - y0), z1 - z0))
    return np.mod(np.asarray(out, float), 2 * math.pi)


def patches_hold(patches) -> bool:
    """Whether compression-only springs on these patches resist a transverse load in every
    direction: their outward normals leave no angular gap of pi or more (a gap of pi leaves a
    half-plane of directions unsupported: the section lifts off)."""
    if not patches:
        return False
    th = np.sort(_normals(patches))
    gaps = np.diff(np.concatenate([th, [th[0] + 2 * math.pi]]))
    return bool(np.max(gaps) < math.pi - 1e-9)


def _layout(patches, offset: float, per_quarter: int):
    """(arcs (n, 6), faces (m, 5)) rows of SliderGeometry for patches offset outwards."""
    arcs, faces = [], []
    for p in patches:
        if p[0] == "arc":
            _, _, yc, zc, r, t0, t1 = p
            n = max(1, int(round(per_quarter * (t1 - t0) / (0.5 * math.pi))))
            arcs.append([yc, zc, r + offset, t0, t1, n])
        else:
            _, _, y0, z0, y1, z1 = p
            ln = math.hypot(y1 - y0, z1 - z0)
            ny, nz = (z1 - z0) / ln, -(y1 - y0) / ln
            faces.append([y0 + offset * ny, z0 + offset * nz, y1 + offset * ny,
                          z1 + offset * nz, per_quarter])
    return np.array(arcs, float).reshape(-1, 6), np.array(faces, float).reshape(-1, 5)


def family_region(k: int, n_booms: int, kind: str, per_quarter: int, half_width: float,
                  radial_gap: float) -> SliderGeometry:
    """A region of the shorthand crane's U family (sim_core.systems.telescopic.params): the
    paper's regions for two and three booms (SliderGeometry.paper_region: the shorthand's two
    booms are the paper's booms 1 and 2, params.crane_sections), and for four to six sections
    the same construction on the family's radii: the contact circle half the gap inside the
    outer boom k's inner face (top arcs r_k - t - gap/2, half circle y_a + r_k - t - gap/2)."""
    if n_booms <= 3:
        return SliderGeometry.paper_region(k + 1, kind, per_quarter, half_width, radial_gap)
    from sim_core.systems.telescopic.params import _WALL, _Y_A, family_radius
    r_o = family_radius(k, n_booms)
    r_top = (r_o - _WALL) - 0.5 * radial_gap
    r_half = (_Y_A + r_o - _WALL) - 0.5 * radial_gap
    nq = int(per_quarter)
    arcs = np.array([[_Y_A, _Y_A, r_top, 0.0, 0.5 * math.pi, nq],
                     [-_Y_A, _Y_A, r_top, 0.5 * math.pi, math.pi, nq],
                     [0.0, 0.0, r_half, math.pi, 2.0 * math.pi, 2 * nq]])
    return SliderGeometry(half_width, arcs, -1 if kind == "inner" else 1,
                          name=f"pair {k + 1}-{k + 2} {kind}")


def slider_geometries(p) -> list[tuple[SliderGeometry, SliderGeometry]]:
    """(inner, outer) SliderGeometry of every overlap of a crane, outermost first."""
    out = []
    for k, o in enumerate(p.overlaps):
        w = 0.5 * o.slider_width
        if p.booms is None:
            out.append(tuple(family_region(k, p.n_booms, kind, p.springs_per_quarter, w,
                                           o.radial_gap) for kind in ("inner", "outer")))
            continue
        section = p.booms[k + 1].section
        if section is None:
            raise ValueError(f"overlap {k}: boom {k + 2} has no section contour (given "
                             "properties); the slider springs need one")
        arcs, faces = _layout(bearing_patches(section, o.bears_on), 0.5 * o.radial_gap,
                              p.springs_per_quarter)
        out.append(tuple(SliderGeometry(w, arcs, kt, name=f"pair {k + 1}-{k + 2} {kind}",
                                        faces=faces)
                         for kind, kt in (("inner", -1), ("outer", 1))))
    return out


#: the two pads of an overlap in the order of the pad outputs: the outer boom's pad at its outer
#: (right) end, region II, and the inner boom's pad at its inner (left) end, region I
PAD_NAMES = ("outer pad", "inner pad")


def pad_loads(geom: SliderGeometry, normal_force) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The load one pad (one slider, all its springs at both ends x = +-w and on every patch)
    puts on the inner boom of its overlap, in the contact section's frame (e_t lateral, e_b
    vertical in the luffing plane; Section 8.3):

    * force (2,) (f_t, f_b), N: minus the sum of the spring forces along the patches' outward
      normals, -sum f_ij n_ij (Eq. 64: a spring pushes the inner boom's face inwards whichever
      boom the contact section belongs to, k_t n_ij f_ij on the slider of either region);
    * couple (2,) (m_t, m_b), N m: the moment about the pad's centre that the springs carry as
      a force pair across the pad's length, sum of k_s w e_s x (-f_ij n_ij);
    * per-patch normal force (n_patches,), N >= 0: the springs' sum on each patch (arc or
      face) in the order of ``geom.arc_index``.

    ``normal_force``: the springs' forces f_ij >= 0 (ContactSolution.normal_force), N."""
    f = np.asarray(normal_force, dtype=float)
    F = -(f[:, None] * geom.normals[:, 1:])             # (t, b) on the inner boom, per spring
    xs = geom.positions[:, 0]                            # k_s w, m
    couple = np.array([-xs @ F[:, 1], xs @ F[:, 0]])     # (e_s x F) k_s w: t and b components
    n_patch = int(geom.arc_index.max()) + 1
    return F.sum(axis=0), couple, np.bincount(geom.arc_index, weights=f, minlength=n_patch)


def overlap_pads(contact, sols) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pads of every overlap from the slider springs of every region (:func:`pad_loads`):
    forces (n_overlaps, 2, 2) N, couples (n_overlaps, 2, 2) N m and per-patch normal forces
    (n_overlaps, 2, n_patches) N (NaN-padded to the largest patch count), pads in the order
    of :data:`PAD_NAMES` (the outer pad, region II; the inner pad, region I).

    ``contact``: the system's ContactFriction with the distribution on; ``sols``: its
    ``solve_regions`` at one state (regions I_12, II_12, I_23, ...)."""
    loads = [pad_loads(geo, sol.normal_force)
             for (_, _, _, geo), (_, _, _, sol) in zip(contact.regions, sols)]
    n_ov = len(loads) // 2
    order = [(2 * k + 1, 2 * k) for k in range(n_ov)]           # (II, I) of overlap k
    n_patch = max(p.size for _, _, p in loads)
    faces = np.full((n_ov, 2, n_patch), np.nan)
    for k, pair in enumerate(order):
        for j, r in enumerate(pair):
            faces[k, j, :loads[r][2].size] = loads[r][2]
    return (np.array([[loads[r][0] for r in pair] for pair in order]).reshape(n_ov, 2, 2),
            np.array([[loads[r][1] for r in pair] for pair in order]).reshape(n_ov, 2, 2),
            faces)
