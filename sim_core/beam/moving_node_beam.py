"""The geometrically exact spline beam element with moving nodes.

Source: Zhao, Qi, Wang (2024), Sections 3-5.

Spatial vs material points (Section 3, Eqs. 1-4).  The element's nodes are *spatial* points:
their material (arc-length) coordinates s_1, s_n are generalized coordinates, the inner node
coordinates follow by linear interpolation (Eq. 5), and a point of the element is labelled by
its sub-element and the normalized parameter xi (Eq. 10), which is held fixed while s and l
vary with time (Eq. 11).  For any field f(s, t):

    material rate   df/dt|_s = df/dt|_xi - f' ds/dt|_xi          (Eq. 3)

so the material Jacobian of a field w.r.t. the coordinates Q is

    df/dQ|_s = df/dQ|_xi - f' ds/dQ|_xi.

Virtual power (Eq. 34) is written with material velocities and accelerations: for every
quadrature point (a material point at the current instant)
    v = J_r Q_dot,  a = J_r Q_ddot + (J_r)^. Q_dot,  omega = J_w Q_dot,
with J_r = dr/dQ|_s and J_w the material angular-velocity Jacobian (Eqs. 30-31).  The
convective terms (J)^. Q_dot = D_Q[J(Q) Q_dot][Q_dot] at fixed s are evaluated by complex-step
differentiation of the analytic Jacobians (exact to round-off; checked against finite
differences in tests/beam).

Internal forces.  We assemble the generalized elastic force as the gradient of the strain
energy U = sum over sub-elements of int_0^1 W(eps) l dxi, W = eps^T D eps / 2 (Eq. 36).
Inside a boom this equals the material virtual power int (d eps/dt|_s)^T sigma ds of Eq. 34:
the two differ only by boundary fluxes W ds/dQ at element ends, which cancel at shared nodes
(the strain is continuous there) and vanish at fixed material ends.  At a truncated domain
(a beam drawn through a sleeve, whose material behind the sleeve is not modelled and is
unstrained) the flux is the configurational force of Bigoni et al. (2015); the energy form gives
it correctly, which tests/beam/test_sleeve.py checks.  Design decision recorded in README.

Coordinate layout of one element with n nodes (5 n + 14 coordinates):
    [r_1 .. r_n (3 n), r'_1, r'_n, r''_1, r''_n (12), gamma_1..gamma_n, gamma'_1..gamma'_n
     (2 n), s_1, s_n]                                              (Section 4, q_c, gamma_c, chi_c)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .cardan import SectionState, section_state
from .spline import SplineBasis, spline_basis, xi_powers


@dataclass(frozen=True)
class BeamSection:
    """Cross-section constants of a beam (reference line = centroid line).

    EA : axial stiffness, N.  GJ : torsional stiffness, N m^2.  EI_t, EI_b : bending stiffness
    about e_t and e_b, N m^2.  rhoA : mass per length, kg/m.  J_s, J_t, J_b : rotary inertia
    per length about e_s, e_t, e_b, kg m (= rho I).
    Constitutive diagonal D = diag(EA, GJ, EI_t, EI_b) (Eq. 36).
    """

    EA: float
    GJ: float
    EI_t: float
    EI_b: float
    rhoA: float
    J_s: float
    J_t: float = 0.0
    J_b: float = 0.0

    @property
    def D(self) -> np.ndarray:
        return np.array([self.EA, self.GJ, self.EI_t, self.EI_b])

    @property
    def J(self) -> np.ndarray:
        """Rotary inertia per length in section-frame order (s, t, b), kg m."""
        return np.array([self.J_s, self.J_t, self.J_b])


@dataclass
class PointKinematics:
    """Kinematics of an element at a set of points (leading axis G), Jacobians at fixed s."""

    s: np.ndarray            # (G,) material coordinates, m
    sub: np.ndarray          # (G,) sub-element index
    ell: complex | float     # sub-element length, m
    r: np.ndarray            # (G, 3) position, m
    rp: np.ndarray           # (G, 3) r'
    sec: SectionState
    J_r: np.ndarray          # (G, 3, nq) material velocity Jacobian
    J_w: np.ndarray          # (G, 3, nq) angular velocity Jacobian (section-frame components)
    B_xi: np.ndarray | None  # (G, 4, nq) strain Jacobian at fixed xi
    B_s: np.ndarray | None   # (G, 4, nq) strain Jacobian at fixed s (material)
    J_psi: np.ndarray | None = None   # (G, 3, nq) Cardan angles (alpha, beta, gamma) at fixed s


class SplineElement:
    """One moving-node spline element (Section 4) with ``n_nodes`` nodes.

    Parameters
    ----------
    n_nodes : int
        Nodes of the element (n - 1 equal sub-elements; paper: 9 nodes = 8 sub-elements).
    n_gauss : int
        Gauss-Legendre points per sub-element.
    section : BeamSection
    reference_basis : (3, 3) array
        Columns g1, g2, g3 of the Cardan reference basis (global components).
    """

    def __init__(self, n_nodes: int, n_gauss: int, section: BeamSection,
                 reference_basis: np.ndarray):
        self.n = int(n_nodes)
        self.basis: SplineBasis = spline_basis(self.n)
        self.section = section
        self.G = np.asarray(reference_basis, dtype=float)
        n = self.n
        self.n_pos = n + 4
        self.n_coords = 5 * n + 14
        self.tor_slice = slice(3 * (n + 4), 3 * (n + 4) + 2 * n)
        self.i_s1 = 3 * (n + 4) + 2 * n
        self.i_sn = self.i_s1 + 1
        xg, wg = np.polynomial.legendre.leggauss(int(n_gauss))
        xg = 0.5 * (xg + 1.0)
        wg = 0.5 * wg
        self.q_sub = np.repeat(np.arange(n - 1), len(xg))
        self.q_xi = np.tile(xg, n - 1)
        self.q_w = np.tile(wg, n - 1)

    # -- coordinate helpers -------------------------------------------------------------
    def index(self, what: str, node: int = 0, comp: int = 0) -> int:
        """Local index of a coordinate: what in {'r','rp1','rpn','rpp1','rppn','g','gp','s1','sn'}."""
        n = self.n
        if what == "r":
            return 3 * node + comp
        offs = {"rp1": n, "rpn": n + 1, "rpp1": n + 2, "rppn": n + 3}
        if what in offs:
            return 3 * offs[what] + comp
        if what == "g":
            return 3 * (n + 4) + node
        if what == "gp":
            return 3 * (n + 4) + n + node
        if what == "s1":
            return self.i_s1
        if what == "sn":
            return self.i_sn
        raise KeyError(what)

    def straight_coordinates(self, r0: np.ndarray, direction: np.ndarray, s1: float,
                             sn: float, s_origin: float = 0.0) -> np.ndarray:
        """Coordinates of the undeformed straight element: r(s) = r0 + (s - s_origin) d."""
        d = np.asarray(direction, float) / np.linalg.norm(direction)
        q = np.zeros(self.n_coords)
        s_nodes = np.linspace(s1, sn, self.n)
        for k, s in enumerate(s_nodes):
            q[3 * k:3 * k + 3] = np.asarray(r0, float) + (s - s_origin) * d
        q[self.index("rp1"):self.index("rp1") + 3] = d
        q[self.index("rpn"):self.index("rpn") + 3] = d
        q[self.i_s1], q[self.i_sn] = s1, sn
        return q

    def locate(self, qe: np.ndarray, s: np.ndarray) -> np.ndarray:
        """Sub-element index holding material coordinate(s) s (clipped to the element)."""
        s1, sn = qe[self.i_s1].real, qe[self.i_sn].real
        ell = (sn - s1) / (self.n - 1)
        return np.clip(np.floor((np.asarray(s) - s1) / ell).astype(int), 0, self.n - 2)

    # -- kinematics --------------------------------------------------------------------
    def evaluate(self, qe: np.ndarray, s: np.ndarray | None = None,
                 sub: np.ndarray | None = None, strains: bool = True,
                 material_strain: bool = False) -> PointKinematics:
        """Kinematics at the quadrature points (s is None) or at material coordinates s.

        Complex ``qe`` is allowed (complex-step); then pass the real ``s`` and ``sub`` of the
        real evaluation so that the same material points are followed.
        """
        n, b = self.n, self.basis
        P = qe[:3 * (n + 4)].reshape(n + 4, 3)
        gv = qe[self.tor_slice]
        s1, sn = qe[self.i_s1], qe[self.i_sn]
        ell = (sn - s1) / (n - 1)                                     # Eq. 5
        if s is None:
            sub = self.q_sub
            xi = self.q_xi.astype(np.result_type(ell, float))
            s = (s1 + (sub + self.q_xi) * ell).real
        else:
            s = np.atleast_1d(np.asarray(s))          # complex allowed (complex-step in s)
            sub = self.locate(qe, s.real) if sub is None else np.atleast_1d(sub)
            xi = (s - s1) / ell - sub                                  # Eq. 10
        Gn = len(s)
        dt = np.result_type(qe, float)

        C = b.pos_coeffs[sub]                                          # (G, 6, n+4)
        lp = ell ** b.pos_powers
        dlp = b.pos_powers * ell ** np.maximum(b.pos_powers - 1, 0)
        phi = [np.einsum("gm,gma->ga", xi_powers(xi, k, 5), C) for k in range(4)]
        Phi = [p * lp for p in phi]
        R = [Ph @ P for Ph in Phi]
        dR = [(p * dlp) @ P for p in phi[:3]]
        r = R[0]
        rp = R[1] / ell
        rpp = R[2] / ell ** 2
        rppp = R[3] / ell ** 3
        dr_dl = dR[0]
        drp_dl = dR[1] / ell - R[1] / ell ** 2
        drpp_dl = dR[2] / ell ** 2 - 2.0 * R[2] / ell ** 3

        Ct = b.tor_coeffs[sub]                                         # (G, 4, 2n)
        lt = ell ** b.tor_powers
        dlt = b.tor_powers * ell ** np.maximum(b.tor_powers - 1, 0)
        psi = [np.einsum("gm,gma->ga", xi_powers(xi, k, 3), Ct) for k in range(3)]
        Psi = [p * lt for p in psi]
        gam = Psi[0] @ gv
        gamp = Psi[1] @ gv / ell
        gampp = Psi[2] @ gv / ell ** 2
        dgam_dl = (psi[0] * dlt) @ gv
        dgamp_dl = (psi[1] * dlt) @ gv / ell - gamp / ell

        inv = 1.0 / (n - 1)
        dl_dchi = np.array([-inv, inv])                                # dl/d(s_1, s_n)
        frac = (sub + xi) * inv
        ds_dchi = np.stack([1.0 - frac, frac], axis=1)                 # ds/d(s_1, s_n) at fixed xi

        nq = self.n_coords
        npos = 3 * (n + 4)
        eye3 = np.eye(3)
        chi = slice(self.i_s1, self.i_sn + 1)

        def pos_block(Ph):
            return (Ph[:, None, :, None] * eye3[None, :, None, :]).reshape(Gn, 3, npos)

        J_r = np.zeros((Gn, 3, nq), dtype=dt)
        J_r[:, :, :npos] = pos_block(Phi[0])
        J_r[:, :, chi] = dr_dl[:, :, None] * dl_dchi - rp[:, :, None] * ds_dchi[:, None, :]

        J_rp = np.zeros((Gn, 3, nq), dtype=dt)
        J_rp[:, :, :npos] = pos_block(Phi[1] / ell)
        J_rp[:, :, chi] = drp_dl[:, :, None] * dl_dchi - rpp[:, :, None] * ds_dchi[:, None, :]
        J_g = np.zeros((Gn, nq), dtype=dt)
        J_g[:, self.tor_slice] = Psi[0]
        J_g[:, chi] = dgam_dl[:, None] * dl_dchi - gamp[:, None] * ds_dchi

        sec = section_state(rp, rpp, gam, gamp, self.G)

        # material angular velocity Jacobian (Eqs. 30-31): omega = T (alpha, beta, gamma)^.
        dpsi = np.empty((Gn, 3, nq), dtype=dt)
        dpsi[:, 0:2] = np.einsum("gki,gin->gkn", sec.dpsi_drp, J_rp)
        dpsi[:, 2] = J_g
        J_w = np.einsum("gij,gjn->gin", sec.tmat, dpsi)

        B_xi = B_s = None
        if strains:
            J_x = np.zeros((Gn, 8, nq), dtype=dt)                      # x = (r', r'', g, g')
            J_x[:, 0:3, :npos] = pos_block(Phi[1] / ell)
            J_x[:, 0:3, chi] = drp_dl[:, :, None] * dl_dchi
            J_x[:, 3:6, :npos] = pos_block(Phi[2] / ell ** 2)
            J_x[:, 3:6, chi] = drpp_dl[:, :, None] * dl_dchi
            J_x[:, 6, self.tor_slice] = Psi[0]
            J_x[:, 6, chi] = dgam_dl[:, None] * dl_dchi
            J_x[:, 7, self.tor_slice] = Psi[1] / ell
            J_x[:, 7, chi] = dgamp_dl[:, None] * dl_dchi
            B_xi = np.einsum("gij,gjn->gin", sec.deps_dx, J_x)
            if material_strain:
                xprime = np.concatenate([rpp, rppp, gamp[:, None], gampp[:, None]], axis=1)
                eps_prime = np.einsum("gij,gj->gi", sec.deps_dx, xprime)
                B_s = B_xi.copy()
                B_s[:, :, chi] -= eps_prime[:, :, None] * ds_dchi[:, None, :]
        return PointKinematics(s, np.asarray(sub), ell, r, rp, sec, J_r, J_w, B_xi, B_s, dpsi)

    def strain_energy_density(self, kin: PointKinematics) -> np.ndarray:
        """W = eps^T D eps / 2 at the points (J/m)."""
        return 0.5 * np.einsum("gi,i,gi->g", kin.sec.eps, self.section.D, kin.sec.eps)


@dataclass
class Beam:
    """A flexible beam as a chain of spline elements sharing their junction nodes.

    The material domain is [0, length]; ``breakpoints`` are the initial material coordinates of
    the element ends (e.g. [0, L_h, L] for the outermost boom split at the luffing point,
    Section 5).  Junction nodes share r, r', r'', gamma, gamma' and s (C2 continuity of the
    centroid line, C1 of torsion).  ``index_map[e]`` maps local element coordinates to beam
    coordinates.
    """

    name: str
    length: float
    section: BeamSection
    breakpoints: tuple[float, ...]
    n_nodes: int = 9
    n_gauss: int = 5
    reference_basis: np.ndarray = field(default_factory=lambda: np.eye(3)[:, [1, 2, 0]])
    elements: list[SplineElement] = field(init=False)
    index_map: list[np.ndarray] = field(init=False)
    n_coords: int = field(init=False)

    def __post_init__(self):
        bps = tuple(float(b) for b in self.breakpoints)
        if len(bps) < 2 or any(b1 <= b0 for b0, b1 in zip(bps[:-1], bps[1:])):
            raise ValueError(f"breakpoints {bps}: need an increasing sequence of >= 2 values")
        self.breakpoints = bps
        self.elements = [SplineElement(self.n_nodes, self.n_gauss, self.section,
                                       self.reference_basis) for _ in range(len(bps) - 1)]
        self.index_map = []
        total = 0
        prev = None
        for el in self.elements:
            idx = np.full(el.n_coords, -1, dtype=int)
            if prev is not None:
                pel, pidx = prev
                shared = [(el.index("r", 0, c), pidx[pel.index("r", pel.n - 1, c)]) for c in range(3)]
                shared += [(el.index("rp1", 0, c), pidx[pel.index("rpn", 0, c)]) for c in range(3)]
                shared += [(el.index("rpp1", 0, c), pidx[pel.index("rppn", 0, c)]) for c in range(3)]
                shared += [(el.index("g", 0), pidx[pel.index("g", pel.n - 1)]),
                           (el.index("gp", 0), pidx[pel.index("gp", pel.n - 1)]),
                           (el.i_s1, pidx[pel.i_sn])]
                for li, gi in shared:
                    idx[li] = gi
            free = np.flatnonzero(idx < 0)
            idx[free] = total + np.arange(len(free))
            total += len(free)
            self.index_map.append(idx)
            prev = (el, idx)
        self.n_coords = total

    # -- named coordinates ---------------------------------------------------------------
    def coord(self, element: int, what: str, node: int = 0, comp: int = 0) -> int:
        el = self.elements[element]
        return int(self.index_map[element][el.index(what, node, comp)])

    def s_coord(self, breakpoint: int) -> int:
        """Beam-coordinate index of the material coordinate of breakpoint k."""
        if breakpoint < len(self.elements):
            return self.coord(breakpoint, "s1")
        return self.coord(len(self.elements) - 1, "sn")

    def straight_coordinates(self, r0, direction) -> np.ndarray:
        """Undeformed straight beam r(s) = r0 + s d at its initial breakpoints."""
        q = np.zeros(self.n_coords)
        for e, el in enumerate(self.elements):
            q[self.index_map[e]] = el.straight_coordinates(
                r0, direction, self.breakpoints[e], self.breakpoints[e + 1])
        return q

    def element_of(self, q: np.ndarray, s: float) -> int:
        """Element whose current material span contains s."""
        for e in range(len(self.elements) - 1):
            if s < q[self.s_coord(e + 1)].real:
                return e
        return len(self.elements) - 1
