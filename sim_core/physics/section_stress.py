"""Stresses at the outline of a boom section from its stress resultants, and the utilisation.

The stresses are those of the finite-element section analysis of ``sectionproperties``
(R. van der Walt; Pilkey, "Analysis and Design of Elastic Beams: Computational Methods", Wiley
2002): the normal stress sigma_zz of the axial force and the two bending moments
(unsymmetric bending about the centroid) and the shear stresses (tau_zx, tau_zy) of the
torque (the Saint-Venant warping function) and of the two shear forces (the shear functions
of Pilkey's elasticity approach), at the mesh nodes.

Every stress is linear in the six resultants, so the section is analysed once: one call of
``Section.calculate_stress`` with unit values of all six actions returns each action's stress
field separately, and the unit responses at the chosen outline points form a table (K, 6) for
sigma_zz and (K, 6, 2) for (tau_zx, tau_zy).  The stresses of any resultants F (..., 6) are then
sigma = table @ F; the table is cached in the process and on disk (next to the section
constants, :mod:`sim_core.physics.cross_sections`).

Axes: sectionproperties' x, y are the section frame's y (along e_t) and z (along e_b), its z is
e_s, so (N, Q_t, Q_b, T, M_t, M_b) (:mod:`sim_core.physics.beam.section_forces`) map to its
(n, vx, vy, mzz, mxx, myy) with the same signs: sigma_zz = N/A + M_t z/I_t - M_b y/I_b for a
symmetric section (its mxx stretches +y, its myy compresses +x, as the right-hand rule about
e_t and e_b).  The bending and axial stresses are taken about the section's centroid and the
shear forces act through its shear centre (sectionproperties' convention): the element's
constitutive law (Eq. 36 of Zhao, Qi, Wang 2024, a diagonal D) treats the reference line as the
elastic centre line.

Outline points: mesh nodes on the outer boundary: its corners, the nodes farthest along the
eight directions (+-y, +-z, +-(y +- z)), then, one at a time, the node farthest by arc length
from those taken, OUTLINE_POINTS in all.  Utilisation: the largest von Mises stress
sqrt(sigma^2 + 3 tau^2) over the points divided by the yield strength f_y (the elastic von
Mises check of a proof of static strength as in EN 13001-3-1, without its partial factors,
which the user applies).
"""

from __future__ import annotations

import functools
import hashlib
import math
from dataclasses import dataclass

import numpy as np

#: outline points per section at which the stresses are given
OUTLINE_POINTS = 32
#: a boundary vertex turning by more than this angle (rad) is a corner
_CORNER_ANGLE = math.radians(20.0)
#: sectionproperties' actions in the order of the section-force components (N, Q_t, Q_b, T,
#: M_t, M_b)
_ACTIONS = ("n", "vx", "vy", "mzz", "mxx", "myy")
_CACHE_FORMAT = 1


@dataclass(frozen=True)
class StressTable:
    """Unit stress responses of one section at its outline points.

    points : (K, 2) outline points (y, z) in the section frame, m.
    sigma : (K, 6) normal stress per unit resultant (N, Q_t, Q_b, T, M_t, M_b), Pa/N, Pa/(N m).
    tau : (K, 6, 2) shear stress components (tau_zx along e_t, tau_zy along e_b) per unit
        resultant.
    """

    points: np.ndarray
    sigma: np.ndarray
    tau: np.ndarray

    def stresses(self, forces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(sigma, tau) (..., K), Pa, of section forces (..., 6): the normal stress and the
        magnitude of the shear stress at every outline point."""
        f = np.asarray(forces, dtype=float)
        sigma = f @ self.sigma.T
        tau = np.einsum("...j,kjc->...kc", f, self.tau)
        return sigma, np.hypot(tau[..., 0], tau[..., 1])


def von_mises(sigma: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress of a beam fibre (one normal, one shear stress), Pa."""
    return np.sqrt(sigma * sigma + 3.0 * tau * tau)


def utilisation(sigma: np.ndarray, tau: np.ndarray, f_y: float) -> np.ndarray:
    """Largest von Mises stress over the outline points (last axis) divided by f_y (Pa)."""
    return von_mises(sigma, tau).max(axis=-1) / float(f_y)


def _outline_nodes(sec, n_points: int) -> np.ndarray:
    """Indices of the mesh nodes chosen as outline points (module docstring)."""
    import shapely

    ring = sec.geometry.geom.exterior
    v = np.asarray(sec.mesh["vertices"], dtype=float)
    size = float(np.ptp(v, axis=0).max())
    on = np.flatnonzero(shapely.distance(ring, shapely.points(v)) < 1e-9 * size)
    pos = shapely.line_locate_point(ring, shapely.points(v[on]))
    # corners of the outer polygon
    c = np.asarray(ring.coords)[:-1]
    d_in, d_out = c - np.roll(c, 1, axis=0), np.roll(c, -1, axis=0) - c
    turn = np.abs(np.arctan2(d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0],
                             np.einsum("ij,ij->i", d_in, d_out)))
    corners = c[turn > _CORNER_ANGLE]
    chosen = [int(on[np.argmin(np.hypot(*(v[on] - p).T))]) for p in corners]
    for a in np.arange(8) * (math.pi / 4):
        chosen.append(int(on[np.argmax(v[on] @ [math.cos(a), math.sin(a)])]))
    chosen = list(dict.fromkeys(chosen))
    # fill greedily with the boundary node farthest (by arc length along the closed outline)
    # from those already taken
    on_pos = dict(zip(on.tolist(), pos))
    taken = np.array([on_pos[i] for i in chosen])
    while len(chosen) < min(n_points, len(on)):
        gap = np.abs(pos[:, None] - taken[None, :])
        far = np.argmax(np.minimum(gap, ring.length - gap).min(axis=1))
        chosen.append(int(on[far]))
        taken = np.append(taken, pos[far])
    idx = np.array(chosen[:n_points])
    return idx[np.argsort([on_pos[i] for i in idx])]


def _compute_table(cs, n_points: int) -> dict:
    from sim_core.physics.cross_sections import analysed_section

    sec = analysed_section(cs)
    idx = _outline_nodes(sec, n_points)
    st = sec.calculate_stress(**dict.fromkeys(_ACTIONS, 1.0)).get_stress()[0]
    sigma = np.zeros((len(idx), 6))
    tau = np.zeros((len(idx), 6, 2))
    for j, a in enumerate(_ACTIONS):
        if a in ("n", "mxx", "myy"):
            sigma[:, j] = st[f"sig_zz_{a}"][idx]
        else:
            tau[:, j, 0] = st[f"sig_zx_{a}"][idx]
            tau[:, j, 1] = st[f"sig_zy_{a}"][idx]
    points = np.asarray(sec.mesh["vertices"], dtype=float)[idx]
    return {"points": points.tolist(), "sigma": sigma.tolist(), "tau": tau.tolist()}


@functools.lru_cache(maxsize=64)
def stress_table(cs, n_points: int = OUTLINE_POINTS) -> StressTable:
    """The :class:`StressTable` of the section ``cs``
    (:class:`~sim_core.physics.cross_sections.CrossSection` with geometry), from the disk cache
    where the same section, point count and sectionproperties version were analysed, else
    computed (about 1-4 s) and stored atomically (an unwritable cache is skipped).  Raises
    SceneError for a section without geometry."""
    from importlib.metadata import version

    from sim_core.physics.cross_sections import MESH_SIZE_PER_WALL, analysed_section, disk_cached

    if cs.key is None or cs.key[0] == "properties":
        analysed_section(cs)                         # raises the SceneError
    h = hashlib.sha256(repr((cs.key, int(n_points), MESH_SIZE_PER_WALL, _CACHE_FORMAT,
                             version("sectionproperties"))).encode())
    vals = disk_cached(f"stress-{h.hexdigest()}", {"points", "sigma", "tau"},
                       lambda: _compute_table(cs, int(n_points)))
    arrays = {k: np.asarray(v, dtype=float) for k, v in vals.items()}
    for a in arrays.values():
        a.flags.writeable = False
    return StressTable(**arrays)
