"""Discrete sliding-block contact between adjacent booms, with friction.

Source: Zhao, Qi, Wang (2024), "Dynamic Contact Analysis of Flexible Telescopic Boom Systems
with Moving Boundary", Section 8.2 (discrete model: compression-only radial springs on the
rounding arcs at the two slider ends) and Section 8.3 (Eqs. 59-72); the inputs the paper leaves
open are those of docs/model.md#input-sections (section geometry, Table 1) and
docs/model.md#input-springs (spring counts, azimuths, contact radius, k_t signs, k0, eps,
friction law).  Sections other than the paper's bear on straight faces as well as arcs
(:class:`SliderGeometry` ``faces``): a spring on a face has the face's outward normal, and
Eq. 61's compression map holds for any position and normal in the section plane.

Frame and components
--------------------
Everything is expressed in the section frame of the contact (middle) cross-section, with
components ordered (s, t, b) = (axial e_s, lateral e_t, vertical e_b).  (e_t, e_b, e_s) is
right-handed, hence so is (e_s, e_t, e_b) and ``np.cross`` applies to (s, t, b) triples.
The origin is the section centroid on the reference line (centre of the lower half circle).

Model (paper Section 8.3)
-------------------------
Spring i on rounding arc j at slider end k_s = +-1 (front/back, at +-w along e_s) sits at
    rbar_ij = k_s w e_s + y_j e_t + z_j e_b + r (cos th_ij e_t + sin th_ij e_b)     (Eq. 59)
The contact section makes a small rigid motion x = (u_t, u_b, alpha, beta, gamma) relative to
the slider (Eq. 60); spring compression (Eq. 61), with n_ij = cos th e_t + sin th e_b,
    delta_ij = (r_ij - rbar_ij) . k_t n_ij = A_ij . x,
    A_ij = k_t [cos th, sin th, (rbar x n)_s, (rbar x n)_t, (rbar x n)_b]
         = k_t [cos th, sin th, y_j sin th - z_j cos th, -k_s w sin th, k_s w cos th].
Smoothed compression-only spring (Eqs. 62-63): f = k(delta) delta.

Sign conventions (the paper's signs were lost in extraction; resolved here)
--------------------------------------------------------------------------
* k_t (docs/model.md#input-springs): -1 for an inner region (contact section = inner contact section of the
  outer boom k, slider on the outer face of boom k+1 inside it), +1 for an outer region
  (contact section = outer contact section of the inner boom k+1, slider on the inner face of
  boom k outside it).  Then delta > 0 exactly when the wall moves towards the slider.
* Eq. 64, f^n = f k_t n, is the normal force the section exerts ON THE SLIDER (an inner-region
  slider is pushed inwards, -n, an outer-region slider outwards, +n).  The force on the section
  is -f k_t n: it opposes the compression, i.e. the springs push.
* Eq. 65, f^s = mu sign(s_dot) f e_s, is the friction ON THE SECTION: the slider moves along the
  section at the contact point's arc-coordinate rate s_dot and drags the wall with it (the
  paper's text: inner contact point during extraction, s_dot > 0, friction along +e_s; outer
  contact point, s_dot < 0, along -e_s).  Its dissipation is non-positive.  Here mu_value is the
  signed regularised mu(s_dot) of docs/model.md#input-friction (FrictionLaw.mu), replacing mu sign(s_dot).
* fbar_c, mbar_c (Eq. 66) are the resultants about the section centroid of the forces the section
  exerts ON THE SLIDER: f_ij (k_t n_ij - mu e_s).  With f_c, m_c the constraint reaction acting on
  the contact section (paper Section 7: f_2,k on boom k; the inner boom gets -f_2,k) the
  equivalence is action = -reaction, f_c + fbar_c = 0 and m_c + mbar_c = 0, exactly the printed
  form of Eqs. 67-72.  Consequently the axial auxiliary residual (Eq. 72) is
      f_c,s + fbar_c,s = f_c,s - mu_value * sum_ij f_ij.

Solvability
-----------
Without friction the five equations (Eqs. 67-71) are the stationarity conditions of the convex
energy  sum phi(A_ij x) + c . x  (phi' = f, f monotone), so a solution exists for every load
(the arcs face every radial direction and P1/P2 carry torsion) and the resultant-level forces
are unique; x itself is not unique when some rigid motion compresses no active spring (e.g. the
torsion alpha under a pure vertical load carried by the half circle P3, whose springs are all
radial through the origin).  The solver therefore
  * returns x = 0 for zero load (every x with all delta <= 0 solves it; 0 is the natural one),
  * cold-starts from the linear all-springs-active solution scaled along its ray to the energy
    minimum on that ray (this handles both the linear and the cubic, delta < eps, regime),
  * uses Newton with a tiny spring-stiffness floor kappa = 1e-10 k0 on every spring in the
    Newton matrix only (not in the residual), so singular directions get a finite but large
    step, which is capped in compression space and back-tracked on the merit ||S R||^2.
Friction (|mu| small) makes the Jacobian non-symmetric; it enters only the moment equations about
e_t and e_b through rbar x f^s, and the coupled system is solved by the same Newton iteration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg.lapack import dgesv as _dgesv

from sim_core.errors import SimulationError
from sim_core.physics.contact import _sliding_block_contact_numba as _compiled

__all__ = [
    "ContactSolution",
    "ContactSolveError",
    "FrictionLaw",
    "SliderGeometry",
    "SpringLaw",
    "axial_residual",
    "contact_residual",
    "solve_micro_motion",
]

# Table 1 (paper Section 9; docs/model.md#input-sections): outer radii (top arcs P1/P2, half circle P3), m.
_TABLE1_OUTER_RADII = {1: (0.090, 0.390), 2: (0.070, 0.370), 3: (0.050, 0.350)}
_WALL = 0.015            # wall thickness, m (Section 9)
_TOP_CENTRE = 0.300      # |y|, z of the P1/P2 centres, m (Table 1)
_HALF_WIDTH = 0.150      # slider width 2w = 0.3 m (Section 9)

_EPS = np.finfo(float).eps


class ContactSolveError(SimulationError):
    """The micro-motion Newton solve of one contact region failed.

    Attributes (besides SimulationError's t, reason, last_state = last iterate x):
    iterations : int, Newton iterations done; residual : numpy.ndarray (5,), last residual.
    """

    def __init__(self, reason: str, t: float = float("nan"), iterations: int | None = None,
                 residual: np.ndarray | None = None, last_x: np.ndarray | None = None):
        super().__init__(t, f"contact micro-motion solve: {reason}", last_state=last_x)
        self.iterations = iterations
        self.residual = residual


# --------------------------------------------------------------------------- constitutive laws

@dataclass(frozen=True)
class SpringLaw:
    """Smoothed compression-only radial spring (paper Section 8.3, Eqs. 62-63; docs/model.md#input-springs).

    k(delta) = 0 (delta < 0); k0 (3 x^2 - 2 x^3), x = delta/eps (0 <= delta < eps);
    k0 (delta >= eps); force f = k(delta) delta.  k is C1 (k = k' = 0 at 0, k = k0, k' = 0 at
    eps), f is C1 and monotone non-decreasing (f' = k0 (9 x^2 - 8 x^3) >= 0 on the transition).
    k0 in N/m per spring, eps in m.
    """

    k0: float = 1e9
    eps: float = 1e-6

    def __post_init__(self):
        for name in ("k0", "eps"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"SpringLaw.{name} = {v!r}: must be finite and > 0")

    def stiffness(self, delta):
        """k(delta), N/m (Eq. 63)."""
        x = np.clip(np.asarray(delta, dtype=float) / self.eps, 0.0, 1.0)
        return self.k0 * x * x * (3.0 - 2.0 * x)

    def stiffness_derivative(self, delta):
        """dk/d delta, N/m^2 (derivative of Eq. 63; zero outside the transition [0, eps))."""
        x = np.clip(np.asarray(delta, dtype=float) / self.eps, 0.0, 1.0)
        return self.k0 * 6.0 * x * (1.0 - x) / self.eps

    def force(self, delta):
        """Spring force f = k(delta) delta >= 0, N (Section 8.3, item (3))."""
        return self.force_and_tangent(delta)[0]

    def tangent_stiffness(self, delta):
        """df/d delta = k + delta dk/d delta, N/m: the quantity entering the Newton Jacobian."""
        return self.force_and_tangent(delta)[1]

    def force_and_tangent(self, delta):
        """(f, df/d delta) in one vectorized pass (hot path).

        With x clipped to [0, 1]: f = k0 x^2 (3 - 2 x) delta and df/d delta = k0 x^2 (9 - 8 x)
        (= k + delta dk/d delta on the transition; 0 below it, k0 above it).
        """
        d = np.asarray(delta, dtype=float)
        x = np.minimum(np.maximum(d * (1.0 / self.eps), 0.0), 1.0)
        kx2 = self.k0 * (x * x)
        return kx2 * (3.0 - 2.0 * x) * d, kx2 * (9.0 - 8.0 * x)


@dataclass(frozen=True)
class FrictionLaw:
    """Regularised Coulomb friction coefficient mu(v), v = contact point's arc-coordinate rate.

    docs/model.md#input-friction (PD for the paper's mu sign(s_dot), Eq. 65):
    mu = mu_s v / v_eps (|v| <= v_eps); sign(v) [mu_s + (mu_d - mu_s)(3 tau^2 - 2 tau^3)],
    tau = |v|/v_eps - 1 (v_eps < |v| <= 2 v_eps); mu_d sign(v) (|v| > 2 v_eps).
    Continuous and odd in v (C0 at |v| = v_eps, C1 at 2 v_eps).
    """

    mu_static: float
    mu_dynamic: float
    v_eps: float

    def __post_init__(self):
        if not (math.isfinite(self.mu_static) and self.mu_static >= 0.0):
            raise ValueError(f"FrictionLaw.mu_static = {self.mu_static!r}: must be >= 0")
        if not (math.isfinite(self.mu_dynamic) and self.mu_dynamic >= 0.0):
            raise ValueError(f"FrictionLaw.mu_dynamic = {self.mu_dynamic!r}: must be >= 0")
        if not (math.isfinite(self.v_eps) and self.v_eps > 0.0):
            raise ValueError(f"FrictionLaw.v_eps = {self.v_eps!r}: must be > 0")

    def mu(self, v):
        """Signed friction coefficient mu(v) (scalar in, float out; array in, array out)."""
        if isinstance(v, (float, int)):             # the same formula for one float
            a = abs(v)
            if a <= self.v_eps:
                return self.mu_static * float(v) / self.v_eps
            tau = min(a / self.v_eps - 1.0, 1.0)
            return math.copysign(self.mu_static + (self.mu_dynamic - self.mu_static)
                                 * tau * tau * (3.0 - 2.0 * tau), v)
        va = np.asarray(v, dtype=float)
        a = np.abs(va)
        tau = np.clip(a / self.v_eps - 1.0, 0.0, 1.0)
        outer = np.sign(va) * (self.mu_static
                               + (self.mu_dynamic - self.mu_static) * tau * tau * (3.0 - 2.0 * tau))
        out = np.where(a <= self.v_eps, self.mu_static * va / self.v_eps, outer)
        return float(out) if out.ndim == 0 else out

    def in_slope_band(self, v) -> bool:
        """Whether any rate v (m/s) lies where mu(v) varies, |v| < 2 v_eps: there the law
        acts as a damper (mu_s N / v_eps near stick, the falling branch above v_eps) and makes
        the dynamics stiff; outside it mu = mu_d sign(v) is constant."""
        return bool(np.any(np.abs(np.asarray(v, dtype=float)) < 2.0 * self.v_eps))

    def dmu_dv(self, v):
        """d mu / dv, 1/(m/s) (one-sided from above at |v| = v_eps, where mu is only C0)."""
        va = np.asarray(v, dtype=float)
        a = np.abs(va)
        tau = np.clip(a / self.v_eps - 1.0, 0.0, 1.0)
        outer = (self.mu_dynamic - self.mu_static) * 6.0 * tau * (1.0 - tau) / self.v_eps
        out = np.where(a < self.v_eps, self.mu_static / self.v_eps, outer)
        return float(out) if out.ndim == 0 else out


# --------------------------------------------------------------------------- geometry

def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class SliderGeometry:
    """Spring layout of one contact region (section-frame components (s, t, b), m, rad).

    half_width : w, springs at k_s w e_s, k_s = +1 (front) and -1 (back).
    arcs : (n_arcs, 6) rows (y_j, z_j, radius, theta_start, theta_end, n_springs); azimuth from
        e_t towards e_b; spring azimuths th_i = theta_start + (i - 1/2) dth, i = 1..n
        (docs/model.md#input-springs).  May be empty where ``faces`` are given.
    k_t : compression indicator (Eq. 61), -1 inner region, +1 outer region
        (docs/model.md#input-springs).
    faces : (n_faces, 5) rows (y_0, z_0, y_1, z_1, n_springs) of straight bearing faces,
        traversed counter-clockwise about the section (outward normal (dz, -dy) / |d|); spring
        i at the fraction (i - 1/2) / n along the face.  None: arcs only (the paper's sections).

    Per-spring arrays (length N = 2 sum n_springs), ordered patch by patch (the arcs, then the
    faces), within a patch front end (k_s = +1) then back end (k_s = -1), within an end by
    increasing azimuth or position along the face: arc_index (the patch index: arcs 0..n_arcs-1,
    faces after them), k_s, theta (azimuth of the spring's normal), positions (N, 3) = rbar_ij
    (Eq. 59), normals (N, 3) = n_ij, A (N, 5) compression map delta = A x (Eq. 61), Bf (N, 5)
    friction moment map (see module doc).
    """

    half_width: float
    arcs: np.ndarray
    k_t: int
    name: str = ""
    faces: np.ndarray | None = None
    arc_index: np.ndarray = field(init=False, repr=False)
    k_s: np.ndarray = field(init=False, repr=False)
    theta: np.ndarray = field(init=False, repr=False)
    positions: np.ndarray = field(init=False, repr=False)
    normals: np.ndarray = field(init=False, repr=False)
    A: np.ndarray = field(init=False, repr=False)
    Bf: np.ndarray = field(init=False, repr=False)
    AT: np.ndarray = field(init=False, repr=False)
    BfT: np.ndarray = field(init=False, repr=False)
    AtA: np.ndarray = field(init=False, repr=False)
    BftA: np.ndarray = field(init=False, repr=False)
    length_scale: float = field(init=False, repr=False)

    def __post_init__(self):
        w = float(self.half_width)
        if not (math.isfinite(w) and w > 0.0):
            raise ValueError(f"SliderGeometry.half_width = {self.half_width!r}: must be > 0")
        if self.k_t not in (1, -1):
            raise ValueError(f"SliderGeometry.k_t = {self.k_t!r}: must be +1 or -1")
        arcs = np.array(self.arcs, dtype=float).reshape(-1, 6) if np.size(self.arcs) else \
            np.zeros((0, 6))
        faces = (np.zeros((0, 5)) if self.faces is None or np.size(self.faces) == 0
                 else np.array(self.faces, dtype=float))
        if arcs.ndim != 2 or arcs.shape[1] != 6:
            raise ValueError(f"SliderGeometry.arcs: shape {arcs.shape}, expected (n_arcs, 6)")
        if faces.ndim != 2 or faces.shape[1] != 5:
            raise ValueError(f"SliderGeometry.faces: shape {faces.shape}, expected (n_faces, 5)")
        if arcs.shape[0] + faces.shape[0] == 0:
            raise ValueError("SliderGeometry: no arcs and no faces (a slider needs a bearing "
                             "patch)")
        if not (np.all(np.isfinite(arcs)) and np.all(np.isfinite(faces))):
            raise ValueError("SliderGeometry.arcs/faces: non-finite entry")
        n = np.concatenate([arcs[:, 5], faces[:, 4]])
        if np.any(n < 1) or np.any(n != np.round(n)):
            raise ValueError(f"SliderGeometry: n_springs {n} must be positive integers")
        if np.any(arcs[:, 2] <= 0.0) or np.any(arcs[:, 4] <= arcs[:, 3]):
            raise ValueError("SliderGeometry.arcs: need radius > 0 and theta_end > theta_start")
        if np.any(np.hypot(faces[:, 2] - faces[:, 0], faces[:, 3] - faces[:, 1]) <= 0.0):
            raise ValueError("SliderGeometry.faces: a face of zero length")

        idx, ks, th, Ys, Zs, nt, nb, arm = [], [], [], [], [], [], [], []
        for j, (y, z, r, t0, t1, nj) in enumerate(arcs):
            nj = int(nj)
            tj = t0 + (np.arange(nj) + 0.5) * (t1 - t0) / nj    # docs/model.md#input-springs
            c, s_ = np.cos(tj), np.sin(tj)
            for k in (1.0, -1.0):
                idx.append(np.full(nj, j))
                ks.append(np.full(nj, k))
                th.append(tj)
                Ys.append(y + r * c)
                Zs.append(z + r * s_)
                nt.append(c)
                nb.append(s_)
                arm.append(y * s_ - z * c)             # (rbar x n)_s on an arc
        for f, (y0, z0, y1, z1, nj) in enumerate(faces):
            nj = int(nj)
            u = (np.arange(nj) + 0.5) / nj
            ln = math.hypot(y1 - y0, z1 - z0)
            c, s_ = (z1 - z0) / ln, -(y1 - y0) / ln             # outward normal (dz, -dy)/|d|
            for k in (1.0, -1.0):
                idx.append(np.full(nj, arcs.shape[0] + f))
                ks.append(np.full(nj, k))
                th.append(np.full(nj, math.atan2(s_, c)))
                Ys.append(y0 + u * (y1 - y0))
                Zs.append(z0 + u * (z1 - z0))
                nt.append(np.full(nj, c))
                nb.append(np.full(nj, s_))
                arm.append(Ys[-1] * s_ - Zs[-1] * c)  # (rbar x n)_s on a face
        idx, ks, th = np.concatenate(idx), np.concatenate(ks), np.concatenate(th)
        Y, Z = np.concatenate(Ys), np.concatenate(Zs)
        c, s, arm = np.concatenate(nt), np.concatenate(nb), np.concatenate(arm)
        pos = np.stack([ks * w, Y, Z], axis=1)                        # Eq. 59
        nrm = np.stack([np.zeros_like(c), c, s], axis=1)
        kt = float(self.k_t)
        # Eq. 61: delta = k_t n . (u_t e_t + u_b e_b + omega x rbar) = k_t [n_t, n_b, rbar x n] . x
        # with (rbar x n)_s = Y n_b - Z n_t (= y_j sin th - z_j cos th on an arc)
        A = kt * np.stack([c, s, arm, -ks * w * s, ks * w * c], axis=1)
        # rbar x (-mu f e_s) = mu f (0, -Z, Y): friction moment on the slider per unit mu f (Eq. 66)
        zero = np.zeros_like(c)
        Bf = np.stack([zero, zero, zero, -Z, Y], axis=1)
        set_ = object.__setattr__
        set_(self, "half_width", w)
        set_(self, "arcs", _readonly(arcs))
        set_(self, "faces", _readonly(faces))
        set_(self, "arc_index", _readonly(idx).astype(int))
        set_(self, "k_s", _readonly(ks))
        set_(self, "theta", _readonly(th))
        set_(self, "positions", _readonly(pos))
        set_(self, "normals", _readonly(nrm))
        set_(self, "A", _readonly(A))
        set_(self, "Bf", _readonly(Bf))
        set_(self, "AT", _readonly(A.T))
        set_(self, "BfT", _readonly(Bf.T))
        set_(self, "AtA", _readonly(A.T @ A))
        set_(self, "BftA", _readonly(Bf.T @ A))
        set_(self, "length_scale", float(np.max(np.hypot(Y, Z))))

    @property
    def n_springs(self) -> int:
        return int(self.theta.size)

    def mask(self, arc: int | None = None, k_s: int | None = None) -> np.ndarray:
        """Boolean mask of the springs on arc index `arc` (0 = P1, ...) and/or end `k_s`."""
        m = np.ones(self.n_springs, dtype=bool)
        if arc is not None:
            m &= self.arc_index == arc
        if k_s is not None:
            m &= self.k_s == k_s
        return m

    @classmethod
    def paper_region(cls, pair, kind: str, springs_per_quarter: int = 20,
                     half_width: float | None = None,
                     radial_gap: float | None = None) -> "SliderGeometry":
        """A contact region of the paper's three-boom example (Section 9, docs/model.md#input-sections and #input-springs).

        pair : outer boom index k of the pair (k, k+1): 1, 2, or (1, 2), (2, 3), "1-2", "2-3".
        kind : "inner" (inner contact section of boom k, left-end slider of boom k+1, k_t = -1) or
            "outer" (outer contact section of boom k+1, right-end slider of boom k, k_t = +1).
        Arcs P1 centre (0.3, 0.3), 0-90 deg; P2 (-0.3, 0.3), 90-180 deg; P3 (0, 0), 180-360 deg;
        contact radius = mid-gap between boom k's inner face (outer radius - 15 mm) and boom
        k+1's outer face: 72.5/372.5 mm (pair 1-2), 52.5/352.5 mm (pair 2-3); w = 0.15 m unless
        ``half_width`` (m) is given.  ``radial_gap`` (m; Table 1: 5 mm) places the contact circle
        at the middle of a gap of that width below boom k's inner face (the sliding block fills
        the gap); the boom sections themselves (Table 2) are not changed by it.
        """
        if isinstance(pair, str):
            pair = tuple(int(p) for p in pair.replace("–", "-").split("-"))
        if isinstance(pair, (tuple, list)):
            if len(pair) != 2 or pair[1] != pair[0] + 1:
                raise ValueError(f"paper_region: pair {pair!r} must be adjacent booms (k, k+1)")
            pair = pair[0]
        k = int(pair)
        if k not in (1, 2):
            raise ValueError(f"paper_region: pair {pair!r}: the paper's pairs are 1-2 and 2-3")
        if kind not in ("inner", "outer"):
            raise ValueError(f"paper_region: kind {kind!r} must be 'inner' or 'outer'")
        (r_o, big_o), (r_i, big_i) = _TABLE1_OUTER_RADII[k], _TABLE1_OUTER_RADII[k + 1]
        r_top = 0.5 * ((r_o - _WALL) + r_i)         # mid-gap, docs/model.md#input-springs
        r_half = 0.5 * ((big_o - _WALL) + big_i)
        if radial_gap is not None:                   # a block of thickness radial_gap
            r_top = (r_o - _WALL) - 0.5 * radial_gap
            r_half = (big_o - _WALL) - 0.5 * radial_gap
        nq = int(springs_per_quarter)
        arcs = np.array([
            [_TOP_CENTRE, _TOP_CENTRE, r_top, 0.0, 0.5 * math.pi, nq],          # P1 top right
            [-_TOP_CENTRE, _TOP_CENTRE, r_top, 0.5 * math.pi, math.pi, nq],     # P2 top left
            [0.0, 0.0, r_half, math.pi, 2.0 * math.pi, 2 * nq],                 # P3 lower half
        ])
        return cls(_HALF_WIDTH if half_width is None else half_width, arcs,
                   -1 if kind == "inner" else 1,
                   name=f"pair {k}-{k + 1} {kind}")


# --------------------------------------------------------------------------- solution

@dataclass(frozen=True, eq=False)
class ContactSolution:
    """Result of one micro-motion solve (section-frame components (s, t, b), SI).

    x : (5,) micro-motions (u_t, u_b, alpha, beta, gamma), m and rad (Eq. 60).
    delta : (N,) spring compressions, m (Eq. 61); normal_force : (N,) f_ij >= 0, N (Eq. 63).
    friction_force : (N,) axial friction ON THE SECTION per spring, mu f_ij, N (Eq. 65).
    f_bar, m_bar : (3,) resultants on the slider about the section centroid (Eq. 66).
    residual : (5,) Eqs. 67-71 in the order (e_t force, e_b force, e_s, e_t, e_b moment).
    axial_residual : f_c,s + fbar_c,s (Eq. 72), N.
    """

    geometry: SliderGeometry
    mu: float
    x: np.ndarray
    delta: np.ndarray
    normal_force: np.ndarray
    friction_force: np.ndarray
    f_bar: np.ndarray
    m_bar: np.ndarray
    residual: np.ndarray
    axial_residual: float
    iterations: int
    tangent: np.ndarray = field(repr=False)
    newton_floor: np.ndarray | None = field(default=None, repr=False)   # kappa (A^T A + mu Bf^T A)
    load_sensitivity: np.ndarray | None = field(default=None, repr=False)  # z, if already formed

    @property
    def jacobian(self) -> np.ndarray:
        """(5, 5) dR/dx of Eqs. 67-71 at the solution, G^T diag(f') A, G = A + mu Bf."""
        g = self.geometry
        return (g.AT + self.mu * g.BfT) @ (self.tangent[:, None] * g.A)

    u_t = property(lambda self: float(self.x[0]))
    u_b = property(lambda self: float(self.x[1]))
    alpha = property(lambda self: float(self.x[2]))
    beta = property(lambda self: float(self.x[3]))
    gamma = property(lambda self: float(self.x[4]))

    @property
    def total_normal_force(self) -> float:
        """sum f_ij, N."""
        return float(self.normal_force.sum())

    @property
    def force_on_section(self) -> np.ndarray:
        """Resultant contact force on the section, -fbar_c (= f_c at equilibrium), N."""
        return -self.f_bar

    @property
    def moment_on_section(self) -> np.ndarray:
        """Resultant contact moment on the section, -mbar_c (= m_c at equilibrium), N m."""
        return -self.m_bar

    def slider_force_vectors(self) -> np.ndarray:
        """(N, 3) per-spring force on the slider, f (k_t n - mu e_s) (Eqs. 64-65)."""
        g = self.geometry
        out = self.normal_force[:, None] * (g.k_t * g.normals)
        out[:, 0] -= self.friction_force
        return out

    def normal_load_gradient(self) -> np.ndarray:
        """d(sum f_ij)/dc, c = (f_c,t, f_c,b, m_c,s, m_c,t, m_c,b): how the region's normal load
        (the friction load of Eq. 65) follows the section load at fixed mu; f_c,s does not
        enter.  Implicit function theorem on Eqs. 67-71: dx/dc = -J^-1, so
        dN/dc = -(J^-T A^T f')^T.  Rigid-motion directions that compress no active spring do
        not change any force; the solve keeps them regular (see _load_sensitivity).  (5,), 1
        and 1/m."""
        return -self._load_sensitivity()

    def _load_sensitivity(self) -> np.ndarray:
        """z = J^-T A^T f': d sum f / dc = -z.  Solved with the Newton matrix's stiffness floor
        kappa (it changes z by a relative ~1e-10 and keeps directions that compress no active
        spring regular); by least squares where the solution carries no floor."""
        if self.load_sensitivity is not None:
            return self.load_sensitivity
        g = self.geometry
        rhs = g.AT @ self.tangent
        if not rhs.any():
            return np.zeros(5)              # no spring on its stiff branch: N does not move
        if self.newton_floor is not None:
            return np.linalg.solve((self.jacobian + self.newton_floor).T, rhs)
        return np.linalg.lstsq(self.jacobian.T, rhs, rcond=1e-12)[0]

    def aux_gradient(self):
        """Sensitivities of the axial residual (Eq. 72) at this solution.

        Returns (d_aux/d_f_c (3,), d_aux/d_m_c (3,), d_aux/d_mu), by the implicit function
        theorem on Eqs. 67-71 (the micro-motions follow the load).  Use with FrictionLaw.dmu_dv
        for the s_dot dependence.
        """
        g = self.geometry
        # d fbar_s / dx = -mu f'^T A ; dx/dc = -J^-1  =>  d aux/dc = y^T, J^T y = mu A^T f'
        y = self.mu * self._load_sensitivity()
        d_fc = np.array([1.0, y[0], y[1]])
        d_mc = y[2:5].copy()
        # dR/dmu = Bf^T f ; d aux/dmu = -sum f - mu f'^T A dx/dmu = -sum f + y . Bf^T f
        d_mu = -self.total_normal_force + float(y @ (g.BfT @ self.normal_force))
        return d_fc, d_mc, d_mu


def axial_residual(f_c, solution: ContactSolution) -> float:
    """Auxiliary equation of paper Eq. 72, f_c . e_s + fbar_c . e_s (zero closes the multiplier)."""
    return float(np.asarray(f_c, dtype=float)[0] + solution.f_bar[0])


def contact_residual(geom: SliderGeometry, spring: SpringLaw, f_c, m_c, mu_value: float, x):
    """Residual of Eqs. 67-71 and its analytic Jacobian at micro-motion x.

    Returns (R, J): R (5,) = (f_c,t + fbar_t, f_c,b + fbar_b, m_c,s + mbar_s, m_c,t + mbar_t,
    m_c,b + mbar_b), J (5, 5) = dR/dx = G^T diag(f'(A x)) A with G = A + mu Bf.
    """
    f_c = np.asarray(f_c, dtype=float)
    m_c = np.asarray(m_c, dtype=float)
    c5 = np.array([f_c[1], f_c[2], m_c[0], m_c[1], m_c[2]])
    GT = geom.AT + float(mu_value) * geom.BfT
    f, fp = spring.force_and_tangent(geom.A @ np.asarray(x, dtype=float))   # Eqs. 61-63
    return c5 + GT @ f, GT @ (fp[:, None] * geom.A)


# --------------------------------------------------------------------------- solver

KAPPA = 1e-10      # stiffness floor (x k0) in the Newton matrix only
RTOL = 1e-11       # default convergence of the micro-motion Newton (relative to the load)
MAX_ITER = 50      # default Newton iteration limit
_ARMIJO = 1e-4


def _cold_start(geom: SliderGeometry, spring: SpringLaw, c5: np.ndarray) -> np.ndarray:
    """Linear all-springs-active solution, scaled to the energy minimum along its ray."""
    x_lin = -np.linalg.solve(geom.AtA, c5) / spring.k0
    d = geom.A @ x_lin
    if not np.any(d > 0.0):
        return x_lin
    target = spring.k0 * float(d @ d)          # = -c . x_lin (frictionless energy balance)
    lam, lo, hi = 1.0, 0.0, math.inf
    for _ in range(200):
        f, fp = spring.force_and_tangent(lam * d)
        h = float(d @ f) - target
        if abs(h) <= 1e-6 * target:
            break
        if h < 0.0:
            lo = lam
        else:
            hi = lam
        hp = float((d * d) @ fp)
        nxt = lam - h / hp if hp > 0.0 else math.nan
        if not (lo < nxt < hi):
            nxt = 2.0 * lam if hi == math.inf else (math.sqrt(lo * hi) if lo > 0 else 0.5 * hi)
        lam = nxt
    return lam * x_lin


def newton_matrices(geom: SliderGeometry, spring: SpringLaw, mu: float):
    """(G^T, kappa (A^T A + mu Bf^T A)) of the micro-motion Newton at friction coefficient mu:
    R = c + G^T f(A x) with G = A + mu Bf (Eqs. 67-71), and the Newton matrix's stiffness
    floor.  They depend on the region and mu only (FrictionAtState forms them once per state)."""
    GT = geom.AT + mu * geom.BfT if mu != 0.0 else geom.AT
    return GT, (KAPPA * spring.k0) * (geom.AtA + mu * geom.BftA)


def _load_vector(geom: SliderGeometry, f_c, m_c, mu: float, t: float):
    """(c (5,), row scales S (5,), load scale) of Eqs. 67-71, ordered like x:
    (f_t, f_b, m_s, m_t, m_b) equations; moments scaled by 1/length_scale."""
    fs, ft, fb = float(f_c[0]), float(f_c[1]), float(f_c[2])
    ms, mt, mb = float(m_c[0]), float(m_c[1]), float(m_c[2])
    if not all(map(math.isfinite, (fs, ft, fb, ms, mt, mb, mu))):
        raise ContactSolveError("non-finite load or friction coefficient", t=t)
    Lr = 1.0 / geom.length_scale
    return (np.array([ft, fb, ms, mt, mb]), np.array([1.0, 1.0, Lr, Lr, Lr]),
            max(abs(ft), abs(fb), Lr * abs(ms), Lr * abs(mt), Lr * abs(mb)))


def _start(geom: SliderGeometry, spring: SpringLaw, c5, x0) -> np.ndarray:
    """The Newton start: x0 where it compresses a spring, else the cold start."""
    if x0 is not None:
        x = np.array(x0, dtype=float).reshape(5)
        if (geom.A @ x).max() > 0.0:    # also catches NaN; no spring compressed: cold start
            return x
    return _cold_start(geom, spring, c5)


def _compiled_newton(geom, spring, GT, kappa_GA, c5, S, x, tol, load_scale, max_iter, t):
    """micro_motion_compiled.newton; (x, iterations, delta, f, f', R, load sensitivity z) or
    ContactSolveError with the reason."""
    x, status, it, err, delta, f, fp, R, z = _compiled.newton(
        geom.A, GT, kappa_GA, c5, S, x, spring.k0, spring.eps, tol, load_scale, max_iter)
    if status == 0:
        return x, it, delta, f, fp, R, z
    reason = {1: "singular Newton matrix",
              2: f"line search failed (|S R| = {err:.3e}, tol {tol:.3e})",
              3: f"no convergence in {max_iter} Newton iterations "
                 f"(|S R| = {err:.3e}, tol {tol:.3e})"}[status]
    raise ContactSolveError(reason, t=t, iterations=it, residual=R, last_x=x)


def normal_load(geom: SliderGeometry, spring: SpringLaw, f_c, m_c, mu: float, GT, kappa_GA,
                x0=None, *, rtol: float = RTOL, max_iter: int = MAX_ITER, t: float = float("nan")):
    """(N = sum f_ij, dN/dc (5,), x) of the micro-motion solve: what the friction Newton needs
    (Eq. 65's normal load and its sensitivity, ContactSolution.normal_load_gradient), without
    building the ContactSolution; GT, kappa_GA from :func:`newton_matrices` at this mu.  The
    same solve as :func:`solve_micro_motion` (compiled Newton; the Python loop where numba or
    the plain SpringLaw is missing)."""
    c5, S, load_scale = _load_vector(geom, f_c, m_c, mu, t)
    if load_scale == 0.0:
        return 0.0, np.zeros(5), np.zeros(5)
    if not (_compiled.AVAILABLE and type(spring) is SpringLaw):
        sol = solve_micro_motion(geom, spring, f_c, m_c, mu, x0, rtol=rtol, max_iter=max_iter,
                                 t=t)
        return sol.total_normal_force, sol.normal_load_gradient(), sol.x
    x = _start(geom, spring, c5, x0)
    x, _, _, f, _, _, z = _compiled_newton(geom, spring, GT, kappa_GA, c5, S, x,
                                           rtol * load_scale, load_scale, max_iter, t)
    return float(f.sum()), -z, x


def solve_micro_motion(geom: SliderGeometry, spring: SpringLaw, f_c, m_c, mu_value: float = 0.0,
                       x0=None, *, rtol: float = RTOL, max_iter: int = MAX_ITER,
                       t: float = float("nan")) -> ContactSolution:
    """Solve Eqs. 67-71 for the five micro-motions of one contact region.

    f_c, m_c : (3,) constraint-reaction force (N) and moment (N m) acting on the contact section,
        section components (s, t, b), moment about the section centroid.
    mu_value : signed friction coefficient mu(s_dot) (FrictionLaw.mu of the contact point's
        arc-coordinate rate); friction on the section is +mu f e_s per spring.
    x0 : warm start (5,), e.g. the previous time step's solution.x.
    rtol : convergence on max |S R| <= rtol max |S c| (S scales moments by 1/length_scale),
        or the round-off floor of the sums.
    t : simulated time, only for the error message.
    Raises ContactSolveError if not converged in max_iter Newton iterations.
    """
    f_c = np.asarray(f_c, dtype=float)
    m_c = np.asarray(m_c, dtype=float)
    mu = float(mu_value)
    if f_c.shape != (3,) or m_c.shape != (3,):
        raise ValueError(f"solve_micro_motion: f_c, m_c must have shape (3,), got "
                         f"{f_c.shape}, {m_c.shape}")
    fs = float(f_c[0])
    c5, S, load_scale = _load_vector(geom, f_c, m_c, mu, t)
    A = geom.A
    n = geom.n_springs
    GT, kappa_GA = newton_matrices(geom, spring, mu)
    fat = spring.force_and_tangent

    def finish(x, delta, f, fp, R, it, floor=None, sensitivity=None):
        fr = mu * f
        gf = GT @ f                     # (fbar_t, fbar_b, mbar_s, mbar_t, mbar_b), Eq. 66
        f_bar = np.array([-float(fr.sum()), gf[0], gf[1]])
        return ContactSolution(geom, mu, x, delta, f, fr, f_bar, gf[2:5].copy(), R,
                               fs + float(f_bar[0]), it, fp, floor, sensitivity)  # aux: Eq. 72

    if load_scale == 0.0:
        # zero load: every x with all delta <= 0 solves Eqs. 67-71; return the rest position
        z = np.zeros(n)
        return finish(np.zeros(5), z, z, z.copy(), np.zeros(5), 0)

    x = _start(geom, spring, c5, x0)
    delta = A @ x
    tol = rtol * load_scale
    if _compiled.AVAILABLE and type(spring) is SpringLaw:
        # the same Newton as the loop below, compiled (micro_motion_compiled)
        x, it, delta, f, fp, R, z = _compiled_newton(geom, spring, GT, kappa_GA, c5, S, x, tol,
                                                     load_scale, max_iter, t)
        return finish(x, delta, f, fp, R, it, kappa_GA, z)
    f, fp = fat(delta)
    R = c5 + GT @ f
    SR = S * R
    phi = float(SR @ SR)
    err = float(np.abs(SR).max())
    row_scale = None
    for it in range(max_iter + 1):
        if err <= tol:
            return finish(x, delta, f, fp, R, it, kappa_GA)
        if row_scale is None:
            row_scale = float(np.max(np.abs(S[:, None] * GT)))
        floor = 64.0 * _EPS * (row_scale * float(f.sum()) + load_scale)   # round-off of the sums
        if err <= floor:
            return finish(x, delta, f, fp, R, it, kappa_GA)
        if it == max_iter:
            break
        # Newton step on Eqs. 67-71: J = G^T diag(f') A, stiffness floor kappa in the matrix only
        _, _, d, info = _dgesv(GT @ (fp[:, None] * A) + kappa_GA, -R)
        if info != 0 or not math.isfinite(float(d @ d)):
            raise ContactSolveError(f"singular Newton matrix (info {info})", t=t,
                                    iterations=it, residual=R, last_x=x)
        dd = A @ d
        step_max = float(np.abs(dd).max())
        cap = 4.0 * max(float(delta.max()), spring.eps)
        s = 1.0 if step_max <= cap else cap / step_max        # cap the compression change
        for _ in range(60):                                   # back-tracking on ||S R||^2
            x_n = x + s * d
            delta_n = A @ x_n
            f_n, fp_n = fat(delta_n)
            R_n = c5 + GT @ f_n
            SR_n = S * R_n
            phi_n = float(SR_n @ SR_n)
            if phi_n <= (1.0 - 2.0 * _ARMIJO * s) * phi:
                break
            s *= 0.5
        else:
            if err <= 1e3 * floor:
                return finish(x, delta, f, fp, R, it, kappa_GA)
            raise ContactSolveError(f"line search failed (|S R| = {err:.3e}, tol {tol:.3e})",
                                    t=t, iterations=it, residual=R, last_x=x)
        x, delta, f, fp, R, SR, phi = x_n, delta_n, f_n, fp_n, R_n, SR_n, phi_n
        err = float(np.abs(SR).max())
    raise ContactSolveError(f"no convergence in {max_iter} Newton iterations "
                            f"(|S R| = {err:.3e}, tol {tol:.3e})",
                            t=t, iterations=max_iter, residual=R, last_x=x)
