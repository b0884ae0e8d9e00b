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

from sim_core.physics.beam.cardan import SectionState, section_state
from sim_core.physics.beam.spline import SplineBasis, spline_basis, xi_powers


@dataclass(frozen=True)
class BeamSection:
    """Cross-section constants of a beam (reference line = centroid line).

    EA : axial stiffness, N.  GJ : torsional stiffness, N m^2.  EI_t, EI_b : bending stiffness
    about e_t and e_b, N m^2.  rhoA : mass per length, kg/m.  J_s, J_t, J_b : rotary inertia
    per length about e_s, e_t, e_b, kg m (= rho I).
    Constitutive diagonal D = diag(EA, GJ, EI_t, EI_b) (Eq. 36).
    y_c, z_c : mass-centre offset from the reference line along e_t and e_b, m (paper Table 2:
    z_c = 0.045 / 0.044 / 0.043 m).  A rigid offset in inertia and gravity (PD,
    docs/model.md#input-sections): the stiffness stays on the reference line; the rotary
    inertia J is taken about the mass centre.  0 (default): mass on the reference line.
    """

    EA: float
    GJ: float
    EI_t: float
    EI_b: float
    rhoA: float
    J_s: float
    J_t: float = 0.0
    J_b: float = 0.0
    y_c: float = 0.0
    z_c: float = 0.0

    @property
    def has_offset(self) -> bool:
        return self.y_c != 0.0 or self.z_c != 0.0

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


class _LazyState:
    """What evaluate() keeps to form the remaining PointKinematics fields on demand."""

    __slots__ = ("el", "X", "Y", "RR", "TT", "ds_dchi", "strains", "material", "dt", "coef",
                 "S6")

    def __init__(self, el, X, Y, RR, TT, ds_dchi, strains, material, dt):
        self.el, self.X, self.Y, self.RR, self.TT = el, X, Y, RR, TT
        self.ds_dchi, self.strains, self.material, self.dt = ds_dchi, strains, material, dt
        self.coef = self.S6 = None


class _LazyKinematics(PointKinematics):
    """The PointKinematics returned by SplineElement.evaluate.

    A PointKinematics (same fields, same values) whose ``sec``, ``J_r``, ``J_w``, ``B_xi``,
    ``B_s`` and ``J_psi`` are formed on first access and then kept: a point load reads J_r only,
    the complex-step pass of the model J_r, J_w, B_s only, and none of them needs the Cardan-angle
    Jacobian J_psi.  Assigning a field replaces it as for the plain dataclass.
    """

    def _form(self, name):
        st = self.__dict__["_lazy"]
        el = st.el
        if name == "sec":
            value = el._kin_sec(st)
        elif (name == "B_xi" and not st.strains) or (name == "B_s" and not st.material):
            value = None
        elif name == "B_s" and "_f_B_xi" in self.__dict__:
            value = el._kin_B(st, self.sec, B_xi=self.__dict__["_f_B_xi"])
        else:
            value = el._kin_J_r(st) if name == "J_r" else getattr(el, "_kin_" + name)(st, self.sec)
        if value is not None and name != "sec" and value.dtype != st.dt:
            value = value.astype(st.dt)   # complex s with real qe: Jacobians are real
        self.__dict__["_f_" + name] = value
        return value


def _lazy_field(name):
    key = "_f_" + name

    def get(self):
        try:
            return self.__dict__[key]
        except KeyError:
            return self._form(name)

    def set(self, value):
        self.__dict__[key] = value

    return property(get, set, doc=f"{name} (formed on first access)")


for _name in ("sec", "J_r", "J_w", "B_xi", "B_s", "J_psi"):
    setattr(_LazyKinematics, _name, _lazy_field(_name))
del _name


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
        self.basis_tables()

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
    #
    # Implementation (performance: docs/performance.md).  For every point the element needs
    # the basis rows
    #     position  X = [phi_k l^(p-k), k = 0..3]   (r and its first three s-derivatives)
    #               and the l-derivatives (p - k) phi_k l^(p-k-1), k = 0..2, at fixed xi
    #     torsion   Y = [psi_k l^(t-k), k = 0..2] and the l-derivatives of the first two
    # (phi_k, psi_k = d^k/dxi^k of the scaled bases, p, t the powers of l of the coefficients),
    # so one matrix product with the coefficients gives all centre-line and torsion quantities.
    # At the default quadrature points phi_k, psi_k are constant and cached; elsewhere they are
    # sum_p xi^p D[sub, p] with a cached table D.  The Jacobians are formed on first access of
    # the returned PointKinematics (_LazyKinematics, _kin_* below).

    def basis_tables(self) -> None:
        """Constant tables of the element (they depend only on n and the Gauss rule)."""
        b = self.basis
        n = self.n
        self.tables_key = (self.q_xi, self.q_sub)
        # exponents/factors of l for the 7 position rows and the 5 torsion rows
        kp = np.array([0, 1, 2, 3, 0, 1, 2])
        dp = np.array([0, 0, 0, 0, 1, 1, 1])
        self._exp_p = b.pos_powers[None, :] - kp[:, None] - dp[:, None]
        self._fac_p = np.where(dp[:, None] == 1, b.pos_powers[None, :] - kp[:, None], 1.0)
        kt = np.array([0, 1, 2, 0, 1])
        dtt = np.array([0, 0, 0, 1, 1])
        self._exp_t = b.tor_powers[None, :] - kt[:, None] - dtt[:, None]
        self._fac_t = np.where(dtt[:, None] == 1, b.tor_powers[None, :] - kt[:, None], 1.0)
        # l**e for the integer exponents e in [-4, 2] come from a 7-entry table
        self.pow_p = (self._exp_p + 4).astype(int)
        self.pow_t = (self._exp_t + 4).astype(int)
        # at the default quadrature points
        xi, sub = self.q_xi, self.q_sub
        C, Ct = b.pos_coeffs[sub], b.tor_coeffs[sub]
        phi = np.stack([np.einsum("gm,gma->ga", xi_powers(xi, k, 5), C) for k in range(4)], 1)
        psi = np.stack([np.einsum("gm,gma->ga", xi_powers(xi, k, 3), Ct) for k in range(3)], 1)
        self.q_phi = phi[:, kp] * self._fac_p                   # (G, 7, n+4), factors folded in
        self.q_psi = psi[:, kt] * self._fac_t                   # (G, 5, 2n)
        self.q_pos = sub + xi
        frac = self.q_pos * (1.0 / (n - 1))
        self.q_ds_dchi = np.stack([1.0 - frac, frac], axis=1)
        # arbitrary points: all basis rows of a point are sum_p xi^p D[sub, p, :]
        fac = np.zeros((6, 4, 6))                  # d^k/dxi^k xi^m = fac[p, k, m] xi^p
        for k in range(4):
            for m in range(k, 6):
                fac[m - k, k, m] = np.prod(np.arange(m - k + 1, m + 1, dtype=float))
        Dp = np.einsum("pkm,ima->ipka", fac, b.pos_coeffs)[:, :, kp] * self._fac_p
        Dt = np.einsum("pkm,ima->ipka", fac[:4, :3, :4], b.tor_coeffs)[:, :, kt] * self._fac_t
        Dt = np.concatenate([Dt, np.zeros((n - 1, 2) + Dt.shape[2:])], axis=1)
        self.D_all = np.concatenate([Dp.reshape(n - 1, 6, -1), Dt.reshape(n - 1, 6, -1)], 2)
        # at the quadrature points: the xi-derivatives sum_p p xi^(p-1) D[sub, p, :] of the
        # rows (the rows themselves are q_phi, q_psi; the complex-step convective terms of
        # element_compiled._complex_kinematics need Im(rows) = Im(xi) d rows/d xi)
        dpw = np.zeros((len(xi), 6))
        dpw[:, 1:] = xi[:, None] ** np.arange(5)[None, :] * np.arange(1, 6)[None, :]
        self.q_drows = np.ascontiguousarray(np.einsum("gp,gpk->gk", dpw, self.D_all[sub]))
        inv = 1.0 / (n - 1)
        self._dl_dchi = np.array([-inv, inv])

    def _basis_at(self, xi: np.ndarray, sub: np.ndarray):
        """Position rows (G, 7, n+4) and torsion rows (G, 5, 2n) at arbitrary (complex) xi
        (with the factors _fac_p, _fac_t applied, as the cached q_phi, q_psi)."""
        n, G = self.n, len(xi)
        pw = np.empty((G, 6), dtype=np.result_type(xi, float))
        pw[:, 0] = 1.0
        pw[:, 1] = xi
        for p in range(2, 6):
            pw[:, p] = pw[:, p - 1] * xi
        cplx = np.iscomplexobj(pw)
        if G == 1:
            D = self.D_all[sub[0]]
            rows = (pw.real @ D + 1j * (pw.imag @ D)) if cplx else pw @ D
        elif G == len(self.q_sub) and (sub is self.q_sub or np.array_equal(sub, self.q_sub)):
            # the quadrature layout: points grouped by sub-element, one batched product
            ng = G // (n - 1)
            pw3 = pw.reshape(n - 1, ng, 6)
            if cplx:
                rows = np.empty((n - 1, ng, self.D_all.shape[2]), dtype=pw.dtype)
                rows.real = pw3.real @ self.D_all
                rows.imag = pw3.imag @ self.D_all
            else:
                rows = pw3 @ self.D_all
            rows = rows.reshape(G, -1)
        else:
            rows = np.einsum("gp,gpx->gx", pw, self.D_all[sub])
        npb = 7 * (n + 4)
        return rows[:, :npb].reshape(G, 7, n + 4), rows[:, npb:].reshape(G, 5, 2 * n)

    def evaluate(self, qe: np.ndarray, s: np.ndarray | None = None,
                 sub: np.ndarray | None = None, strains: bool = True,
                 material_strain: bool = False) -> PointKinematics:
        """Kinematics at the quadrature points (s is None) or at material coordinates s.

        Complex ``qe`` is allowed (complex-step); then pass the real ``s`` and ``sub`` of the
        real evaluation so that the same material points are followed.

        s, sub, ell, r, rp are computed here; the section state and the Jacobians (sec, J_r,
        J_w, B_xi, B_s, J_psi) on first access of the returned object (same values, nothing is
        formed that the caller does not read; they do not depend on ``qe`` being kept unchanged).
        """
        n = self.n
        if self.tables_key[0] is not self.q_xi or self.tables_key[1] is not self.q_sub:
            self.basis_tables()
        na = n + 4
        npos = 3 * na
        P = qe[:npos].reshape(na, 3)
        gv = qe[self.tor_slice]
        s1, sn = qe[self.i_s1], qe[self.i_sn]
        ell = (sn - s1) / (n - 1)                                     # Eq. 5
        if s is None:
            sub = self.q_sub
            s = (s1 + self.q_pos * ell).real
            phi, psi = self.q_phi, self.q_psi
            ds_dchi = self.q_ds_dchi
        else:
            s = np.atleast_1d(np.asarray(s))          # complex allowed (complex-step in s)
            sub = self.locate(qe, s.real) if sub is None else np.atleast_1d(sub)
            xi = (s - s1) / ell - sub                                  # Eq. 10
            phi, psi = self._basis_at(xi, sub)
            frac = (sub + xi) * (1.0 / (n - 1))
            ds_dchi = np.empty((len(s), 2), dtype=frac.dtype)          # ds/d(s_1, s_n) at fixed xi
            ds_dchi[:, 1] = frac
            ds_dchi[:, 0] = 1.0 - frac
        Gn = len(s)

        # basis rows with the powers of l, and all centre-line / torsion quantities at once
        il = 1.0 / ell
        il2 = il * il
        lpow = np.array([il2 * il2, il2 * il, il2, il, 1.0, ell, ell * ell])  # l**(-4..2)
        X = phi * lpow[self.pow_p]                                    # (G, 7, n+4)
        Y = psi * lpow[self.pow_t]                                    # (G, 5, 2n)
        # RR: r and its s-derivatives of order 1..3, then d/dl (at fixed xi) of orders 0..2;
        # TT: gamma and its s-derivatives of order 1, 2, then d/dl of orders 0, 1
        RR = (X.reshape(7 * Gn, na) @ P).reshape(Gn, 7, 3).transpose(1, 0, 2).copy()
        TT = (Y.reshape(5 * Gn, 2 * n) @ gv).reshape(Gn, 5).T.copy()
        kin = _LazyKinematics.__new__(_LazyKinematics)
        kin.__dict__.update(s=s, sub=np.asarray(sub), ell=ell, r=RR[0], rp=RR[1], _lazy=_LazyState(
            self, X, Y, RR, TT, ds_dchi, bool(strains), bool(strains and material_strain),
            np.result_type(qe, float)))
        return kin

    # -- the lazily formed parts of evaluate() (see _LazyKinematics) ----------------------
    #
    # Every Jacobian has the column blocks [positions 3(n+4) | torsion 2n | s_1, s_n].  Its
    # position block is a Kronecker product: row i, column 3a + j is sum_k c_k[g, i, j] X_k[g, a]
    # (c_k = derivative of the quantity w.r.t. r' or r'' for k = 1, 2; the identity for r, k = 0),
    # formed as [c_1 c_2] @ S6 with the interleaved rows S6 = [X_1 (x) I3; X_2 (x) I3] shared by
    # all Jacobians of a point set; no dense Jacobians of r', r'' are formed and contracted.  The
    # material-coordinate block is c_l dl/dchi + c_s ds/dchi with two coefficients per row.

    def _kin_sec(self, st: "_LazyState") -> SectionState:
        return section_state(st.RR[1], st.RR[2], st.TT[0], st.TT[1], self.G)

    def _kron_rows(self, st: "_LazyState") -> np.ndarray:
        """S6 (G, 6, 3(n+4)): rows X_1 (x) e_j and X_2 (x) e_j (j = 0..2) of the position block.

        A position block with rows c1[:, i, :] . dr'/dQ + c2[:, i, :] . dr''/dQ is then the batched
        product [c1 c2] @ S6 (one BLAS call per point instead of dense (G, 3, nq) Jacobians of r'
        and r'' and their contraction)."""
        if st.S6 is None:
            X = st.X
            npos = 3 * (self.n + 4)
            S6 = np.zeros((X.shape[0], 6, npos), dtype=X.dtype)
            for j in range(3):
                S6[:, j, j::3] = X[:, 1]
                S6[:, 3 + j, j::3] = X[:, 2]
            st.S6 = S6
        return st.S6

    def _kin_J_r(self, st: "_LazyState") -> np.ndarray:
        """J_r = dr/dQ|_s: position block X_0 (x) I3, material block dr/dl dl/dchi - r' ds/dchi."""
        npos = 3 * (self.n + 4)
        X, RR = st.X, st.RR
        J_r = np.zeros((X.shape[0], 3, self.n_coords), dtype=np.result_type(X, RR))
        for j in range(3):
            J_r[:, j, j:npos:3] = X[:, 0]
        J_r[:, :, self.i_s1:] = (RR[4][:, :, None] * self._dl_dchi
                                 - RR[1][:, :, None] * st.ds_dchi[:, None, :])
        return J_r

    def _psi_coef(self, st, sec):
        """Material-coordinate columns (G, 3, 2) of the Cardan-angle Jacobian at fixed s."""
        if st.coef is None:
            RR, TT = st.RR, st.TT
            # d(alpha, beta)/dl at fixed xi and (alpha, beta)' from dr'/dl and r''
            cab = sec.dpsi_drp @ RR[[5, 2]].transpose(1, 2, 0)         # (G, 2, 2)
            chi = np.empty((cab.shape[0], 3, 2), dtype=np.result_type(cab, st.ds_dchi))
            chi[:, 0:2] = (cab[:, :, 0:1] * self._dl_dchi
                           - cab[:, :, 1:2] * st.ds_dchi[:, None, :])
            chi[:, 2] = TT[3][:, None] * self._dl_dchi - TT[1][:, None] * st.ds_dchi
            st.coef = chi
        return st.coef

    def _kin_J_psi(self, st: "_LazyState", sec: SectionState) -> np.ndarray:
        """Cardan angles at fixed s: (alpha, beta) from r', gamma."""
        npos = 3 * (self.n + 4)
        chi = self._psi_coef(st, sec)
        J = np.zeros((st.X.shape[0], 3, self.n_coords), dtype=chi.dtype)
        np.matmul(sec.dpsi_drp, self._kron_rows(st)[:, 0:3], out=J[:, 0:2, :npos])
        J[:, 2, npos:self.i_s1] = st.Y[:, 0]
        J[:, :, self.i_s1:] = chi
        return J

    def _kin_J_w(self, st: "_LazyState", sec: SectionState) -> np.ndarray:
        """Material angular velocity Jacobian (Eqs. 30-31): omega = T (alpha, beta, gamma)^."""
        npos = 3 * (self.n + 4)
        chi = self._psi_coef(st, sec)
        tmat = sec.tmat
        A = tmat[:, :, 0:2] @ sec.dpsi_drp                             # d omega / d r'
        J = np.empty((st.X.shape[0], 3, self.n_coords), dtype=np.result_type(chi, st.X))
        np.matmul(A, self._kron_rows(st)[:, 0:3], out=J[:, :, :npos])
        np.multiply(tmat[:, :, 2, None], st.Y[:, None, 0], out=J[:, :, npos:self.i_s1])
        J[:, :, self.i_s1:] = tmat @ chi
        return J

    def _kin_B_xi(self, st: "_LazyState", sec: SectionState) -> np.ndarray:
        return self._kin_B(st, sec, material=False)

    def _kin_B_s(self, st: "_LazyState", sec: SectionState) -> np.ndarray:
        return self._kin_B(st, sec, material=True)

    def _kin_B(self, st, sec, material=True, B_xi=None):
        """Strain Jacobian at fixed xi (B_xi) or at fixed s (B_s = B_xi - eps' ds/dchi)."""
        npos = 3 * (self.n + 4)
        d = sec.deps_dx                                                # (G, 4, 8)
        RR, TT = st.RR, st.TT
        # c_l = d eps/dl at fixed xi = d . x_l with x_l = l-derivatives of (r', r'', gamma,
        # gamma'); for B_s also eps' = d . x' with x' = s-derivatives of the same
        x_l = np.concatenate([RR[5], RR[6], TT[3][:, None], TT[4][:, None]], axis=1)
        chi = (d @ x_l[:, :, None]) * self._dl_dchi
        if material:
            x_p = np.concatenate([RR[2], RR[3], TT[1][:, None], TT[2][:, None]], axis=1)
            chi -= (d @ x_p[:, :, None]) * st.ds_dchi[:, None, :]
        if B_xi is not None:
            B = B_xi.copy()
        else:
            B = np.empty((st.X.shape[0], 4, self.n_coords), dtype=np.result_type(d, st.X))
            np.matmul(d[:, :, 0:6], self._kron_rows(st), out=B[:, :, :npos])
            np.matmul(d[:, :, 6:8], st.Y[:, 0:2], out=B[:, :, npos:self.i_s1])
        B[:, :, self.i_s1:] = chi
        return B

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
