"""Linear boundary conditions of beam ends (clamped, pinned, roller, free, sleeve), material
points held at a coordinate, and the reference basis of a straight beam.  Each condition is a
set of rows a . Q = b(t) with b and its first two derivatives, eliminated by the model's
reduction to independent coordinates (:class:`sim_core.model.model.Model`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from sim_core.physics.beam.moving_node_beam import Beam


@dataclass
class LinearConstraint:
    """Rows a . Q = b(t) with the first two time derivatives of b (m, m/s, m/s^2 ...)."""

    name: str
    rows: np.ndarray | list                # (m, N) dense, or sparse [{index: coeff}] per row
    value: Callable[[float], np.ndarray]   # b(t)   (m,)
    rate: Callable[[float], np.ndarray]    # b'(t)
    accel: Callable[[float], np.ndarray]   # b''(t)
    # b does not change in time (b' = b'' = 0): where every constraint is constant, the model
    # forms A^+ b once (Model._particular) instead of at every state lift
    constant: bool = False


def constant_signal(v):
    """(b, b', b'') of a constant value v: the value and two zero derivatives."""
    v = np.atleast_1d(np.asarray(v, dtype=float))
    z = np.zeros_like(v)
    return (lambda t: v), (lambda t: z), (lambda t: z)


def reference_basis(direction) -> np.ndarray:
    """Cardan reference basis with g3 along the beam axis and g1 normal to it (horizontal if
    possible), so that the singular direction e_s = g1 is 90 degrees away (Section 5)."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 0.0, 1.0])
    g1 = np.cross(up, d) if abs(d @ up) < 0.99 else np.array([0.0, 1.0, 0.0])
    g1 = g1 / np.linalg.norm(g1)
    if g1 @ np.array([0.0, 1.0, 0.0]) < 0:
        g1 = -g1
    g2 = np.cross(d, g1)
    return np.column_stack([g1, g2, d])


def no_torsion(offsets, beams) -> LinearConstraint:
    """effects.torsion = false: all torsion angles and their derivatives are held at zero,
    so the torsional coordinates leave the integrated state."""
    rows = []
    for ib, b in enumerate(beams):
        for e, el in enumerate(b.elements):
            for k in range(el.n):
                for what in ("g", "gp"):
                    rows.append(int(offsets[ib] + b.index_map[e][el.index(what, k)]))
    rows = sorted(set(rows))
    z = np.zeros(len(rows))
    return LinearConstraint("no_torsion", [{i: 1.0} for i in rows],
                            lambda t: z, lambda t: z, lambda t: z, constant=True)


def dense_rows(N: int, entries: Sequence[dict[int, float]]) -> np.ndarray:
    A = np.zeros((len(entries), N))
    for i, ent in enumerate(entries):
        for j, v in ent.items():
            A[i, j] = v
    return A


def _perp(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = d / np.linalg.norm(d)
    a = np.eye(3)[np.argmin(np.abs(d))]
    n1 = np.cross(d, a)
    n1 /= np.linalg.norm(n1)
    return n1, np.cross(d, n1)


def end_index(beam: Beam, end: str):
    """(element, node, breakpoint) of the 'left' (s = 0) or 'right' (s = L) end."""
    if end == "left":
        return 0, 0, 0
    if end == "right":
        return len(beam.elements) - 1, beam.n_nodes - 1, len(beam.elements)
    raise ValueError(f"end = {end!r}: allowed 'left' or 'right'")


def boundary_condition(model_offsets, beams: list[Beam], ibeam: int, end: str, kind: str,
                       position=None, direction=None, s_of_t=None,
                       fix_torsion: bool = True) -> LinearConstraint:
    """Linear boundary condition at a beam end.

    kind:
      'clamped'  r = position, r' parallel to direction, gamma = 0, material end fixed;
      'pinned'   r = position, gamma = 0 (no torsional rigid mode), material end fixed;
      'roller'   r components normal to ``direction`` fixed, gamma = 0, material end fixed;
      'free'     only the material end is fixed (s = 0 or L);
      'sleeve'   the end node is the spatial point at the exit of a rigid sleeve: r = position,
                 r' parallel to direction, gamma = 0, and its material coordinate follows the
                 prescribed s_of_t = (s(t), s'(t), s''(t)) (material flows through the point).
    fix_torsion=False omits the gamma row (when torsion is switched off globally).
    """
    beam = beams[ibeam]
    off = int(model_offsets[ibeam])
    e, node, bp = end_index(beam, end)
    el = beam.elements[e]

    def gi(what, nd=0, comp=0):
        return off + int(beam.index_map[e][el.index(what, nd, comp)])

    rp_name = "rp1" if node == 0 else "rpn"
    entries: list[dict[int, float]] = []
    vals: list[float] = []
    pos = None if position is None else np.asarray(position, float)
    d = None if direction is None else np.asarray(direction, float)
    if kind in ("clamped", "pinned", "sleeve"):
        for c in range(3):
            entries.append({gi("r", node, c): 1.0})
            vals.append(pos[c])
    if kind == "roller":
        for n_ in _perp(d):
            entries.append({gi("r", node, c): n_[c] for c in range(3)})
            vals.append(float(n_ @ pos))
    if kind in ("clamped", "sleeve"):
        for n_ in _perp(d):
            entries.append({gi(rp_name, 0, c): n_[c] for c in range(3)})
            vals.append(0.0)
    if fix_torsion and kind in ("clamped", "pinned", "roller", "sleeve"):
        entries.append({gi("g", node): 1.0})
        vals.append(0.0)
    s_idx = off + beam.s_coord(bp)
    entries.append({s_idx: 1.0})
    n_geom = len(vals)
    if kind == "sleeve":
        if s_of_t is None:
            raise ValueError("sleeve boundary condition needs s_of_t = (s, s_dot, s_ddot)")
        fs, fv, fa = s_of_t
    else:
        s0 = 0.0 if end == "left" else beam.length
        fs, fv, fa = (lambda t: s0), (lambda t: 0.0), (lambda t: 0.0)
    constant = kind != "sleeve"
    geo = np.asarray(vals, float)
    zero = np.zeros(n_geom)

    def value(t):
        return np.append(geo, fs(t))

    def rate(t):
        return np.append(zero, fv(t))

    def accel(t):
        return np.append(zero, fa(t))

    return LinearConstraint(f"{kind}:{beam.name}:{end}", entries, value, rate, accel,
                            constant=constant)


def fix_material_coordinate(model_offsets, beams: list[Beam], ibeam: int, breakpoint: int,
                            value: float) -> LinearConstraint:
    """A breakpoint that is a material point (e.g. the luffing point s_3,1 = L_h, Eq. 50)."""
    idx = int(model_offsets[ibeam]) + beams[ibeam].s_coord(breakpoint)
    v, r, a = constant_signal([value])
    return LinearConstraint(f"material:{beams[ibeam].name}:{breakpoint}", [{idx: 1.0}], v, r, a,
                            constant=True)
