"""Frictional sliding-block contact between adjacent booms (Zhao-Qi-Wang 2024, Section 8).

For every contact region (pair k, k+1; region I at boom k's inner contact section s_2,k and
region II at boom k+1's outer contact section s_3,k+1) the constraint reaction of Constraint I or
II (force and moment, section frame) is distributed on the sliders' radial springs by the
micro-motion solver (Eqs. 59-71, :mod:`sim_core.physics.contact.sliding_block_contact`); the friction
force mu(s_dot) * sum(f_ij) (Eq. 65, regularised law of docs/model.md#input-friction) acts along e_s.  Its
virtual power under a relative slide is  -mu(s_dot) N delta s_dot  (Section 7: the contact
multiplier eta), so it enters the equations as the generalized force -mu(s_dot) N on the contact
coordinate s_2,k or s_3,k+1.  Because N depends on the multipliers, the model solves for the
friction values and the multipliers together (Model.multiplier_forces): by Newton in the four
values -mu N, with the analytic sensitivity of the micro-motion solve (FrictionAtState).

Where the normal load N comes from is the scene's ``contact.friction_load``:

* ``"springs"``: N = sum of the region's slider-spring forces (Eqs. 65-72 literally).  With the
  rigid moment model a slider of width 2w carries the contact moment M as a force couple of
  about M / (2w) at its ends, so N grows as 1/w: in the limit w/L -> 0 in which Section 6 derives
  the rigid orientation constraint, the friction load of this reading diverges.
* ``"resultant"``: N = |(f_t, f_b)|, the transverse resultant of the contact force, which global
  equilibrium fixes whatever the slider's width and pressure distribution.  It is the reading of
  Section 9.2 (4), where the axial component of the constraint force follows its vertical
  component by "the Coulomb friction ratio", and the one that keeps the telescopic-cylinder
  force of Fig. 27 near its static value (docs/validation.md).

How much moment a contact region carries is ``contact.moment_model`` (sim_core.systems.telescopic.build):
``rigid`` (Section 6: the two bending Cardan angles coincide, multipliers), ``seat`` (they are
tied by an elastic seat, point_effects.SliderSeat) or ``couple`` (they are free: the overlap
carries its bending moment as a force couple between its two contact regions).  The twist and
the two translations are constraints in every model.  :func:`region_multipliers` gives each
region's three angle multipliers whatever the model, so the section maps below apply to all.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.physics.beam.cardan import cardan_frame
from sim_core.physics.constraints import dependencies
from sim_core.physics.contact import FrictionLaw, SliderGeometry, SpringLaw, solve_micro_motion
from sim_core.physics.contact.sliding_block_contact import newton_matrices, normal_load


def section_reaction_maps(point, Q, basis, n_angles: int = 3):
    """The linear maps from a coincidence constraint's multipliers to the force and moment it
    exerts on its *second* body b (g = r_a - r_b), section components (s, t, b):
    f_sec = Lf lam_point (f = -lambda in global components) and m_sec = Lm lam_angles (the
    moment from the Cardan-angle multipliers, m = -T^-T lambda_psi, Eq. 31).  ``n_angles`` = 2
    without the twist row (effects.torsion = false).  Returns (Lf (3, 3), Lm (3, n_angles)).

    T maps the angle rates to the angular velocity (omega_s, omega_t, omega_b) (Eq. 31):
    T = [[sin b, 0, 1], [cos b cos g, sin g, 0], [-cos b sin g, cos g, 0]], det T = cos b, so
    T^-T = [[0, 0, 1], [cos g / cos b, sin g, -tan b cos g], [-sin g / cos b, cos g,
    tan b sin g]] in closed form (``_section_reaction_maps_inv`` is the same by inversion)."""
    _, _, psi, _ = point(Q)
    if np.iscomplexobj(psi):
        return _section_reaction_maps_inv(psi, basis, n_angles)
    a, b, g = float(psi[0]), float(psi[1]), float(psi[2])
    ca, sa, cb, sb, cg, sg = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(g), \
        math.sin(g)
    # rows e_s, e_t, e_b of the Cardan frame (Eq. 24, cardan_frame) in the reference basis
    R = np.array([[sb, -sa * cb, ca * cb],
                  [cb * cg, ca * sg + sa * sb * cg, sa * sg - ca * sb * cg],
                  [-cb * sg, ca * cg - sa * sb * sg, sa * cg + ca * sb * sg]])
    tb = sb / cb
    Lm = np.array([[0.0, 0.0, -1.0],
                   [-cg / cb, -sg, tb * cg],
                   [sg / cb, -cg, -tb * sg]])
    return -(R @ basis.T), Lm[:, :n_angles]


def _section_reaction_maps_inv(psi, basis, n_angles: int):
    """section_reaction_maps from the angles by the frame of cardan_frame and the inverse of T
    (the reference of the closed form; complex-step safe)."""
    frame = cardan_frame(*psi) @ basis.T                 # rows e_t, e_b, e_s (global)
    sb, cb = np.sin(psi[1]), np.cos(psi[1])
    sg, cg = np.sin(psi[2]), np.cos(psi[2])
    T = np.array([[sb, 0.0, 1.0], [cb * cg, sg, 0.0], [-cb * sg, cg, 0.0]])
    Lm = -np.linalg.inv(T.T)[:, :n_angles]
    return -frame[[2, 0, 1]], Lm


def region_multipliers(ts, name: str, Q, lam):
    """(lambda_point (3,), lambda_angles (3,)) of contact region ``name`` (e.g. "II_23"): the
    point rows' multipliers and the three Cardan-angle multipliers (alpha, beta, gamma) whatever
    the moment model: the constrained rows from ``lam``, a seat's bending rows as its equivalent
    multipliers -k g (point_effects.SliderSeat), free rows zero (the couple model)."""
    lam_angles = np.zeros(3)
    kept = ts.angle_rows[name]
    if kept:
        lam_angles[list(kept)] = lam[ts.rows[name + "_angles"]]
    seat = ts.seats.get(name)
    if seat is not None:
        lam_angles[:2] = seat.multipliers(Q)
    return lam[ts.rows[name + "_point"]], lam_angles


def section_reaction(point, Q, lam_point, lam_angles, basis):
    """Force and moment (section components (s, t, b)) that a coincidence constraint with
    multipliers (lam_point, lam_angles) exerts on its *second* body (see
    :func:`section_reaction_maps`)."""
    lam_angles = np.asarray(lam_angles)
    Lf, Lm = section_reaction_maps(point, Q, basis, lam_angles.shape[0])
    return Lf @ np.asarray(lam_point), Lm @ lam_angles


class ContactFriction:
    """Multiplier-dependent friction forces on the contact coordinates of all regions.

    ``distribution=True`` (effects.contact_distribution): each region's slider springs are
    solved by the micro-motion analysis (Eqs. 59-71) for the outputs.  ``friction_load``:
    ``"springs"`` (needs the distribution) takes the friction's normal load from their sum,
    ``"resultant"`` from the transverse contact resultant N = |(f_t, f_b)| (a lower bound of the
    spring sum: the force couples that carry the contact moment are not in it), which needs no
    slider geometry.  ``geometries``: the (inner, outer) SliderGeometry of every overlap, outermost
    first (sim_core.systems.telescopic.sliders); None: the paper's three-boom regions
    (SliderGeometry.paper_region)."""

    name = "friction"

    def __init__(self, ts, mu_static: float, mu_dynamic: float, v_eps: float,
                 k0: float = 1e9, eps: float = 1e-6, distribution: bool = True,
                 slider_half_width: float = 0.15, springs_per_quarter: int = 20,
                 radial_gap: float | None = None, friction_load: str | None = None,
                 geometries=None):
        if friction_load is None:
            friction_load = "springs" if distribution else "resultant"
        if friction_load not in ("springs", "resultant"):
            raise ValueError(f"friction_load = {friction_load!r} (allowed: 'springs', "
                             "'resultant')")
        if friction_load == "springs" and not distribution:
            raise ValueError("friction_load = 'springs' needs the slider-spring distribution "
                             "(distribution = True)")
        self.ts = ts
        self.distribution = distribution
        self.friction_load = friction_load
        self.law = FrictionLaw(mu_static, mu_dynamic, v_eps)
        self.spring = SpringLaw(k0, eps)
        self.basis = ts.model.beams[0].reference_basis
        from sim_core.physics.constraints import material_point
        m = ts.model
        self.regions = []
        for k in range(ts.params.n_booms - 1):
            inner = material_point(m, k, s_index=ts.s2_index[k])
            outer = material_point(m, k + 1, s_index=ts.s3_index[k + 1])
            if not distribution:
                geo = (None, None)
            elif geometries is not None:            # (inner, outer) SliderGeometry of pair k
                geo = tuple(geometries[k])
            else:
                geo = tuple(SliderGeometry.paper_region(k + 1, kind, springs_per_quarter,
                                                        slider_half_width, radial_gap)
                            for kind in ("inner", "outer"))
            self.regions.append((f"I_{k + 1}{k + 2}", inner, ts.s2_index[k], geo[0]))
            self.regions.append((f"II_{k + 1}{k + 2}", outer, ts.s3_index[k + 1], geo[1]))
        self._x0 = {}

    def coords(self, Q):
        """Coordinates the friction forces depend on besides the multipliers: the contact
        points' elements and contact coordinates (their velocities enter the law)."""
        return dependencies([point for _, point, _, _ in self.regions], Q)

    def velocity_coords(self, Q):
        """Rates in the friction law: the contact coordinates' (s_dot of Eq. 65)."""
        return np.array([s_idx for _, _, s_idx, _ in self.regions], dtype=int)

    def in_slope_band(self, Qd) -> bool:
        """Whether a contact coordinate's rate s_dot (Eq. 65) lies in the friction law's slope
        band |s_dot| < 2 v_eps (FrictionLaw.in_slope_band): a contact sticking, breaking away
        or coming to stick."""
        return self.law.in_slope_band(Qd[self.velocity_coords(None)])

    def at_state(self, t, Q, Qd, only=None) -> "FrictionAtState":
        """The friction as a function of the multipliers alone, at the state (Q, Qd): the
        section maps and mu(s_dot) are formed once here, not in every multiplier iteration.
        ``only``: indices of the regions to include (default all)."""
        ts = self.ts
        rows = ts.rows
        regions = []
        chosen = self.regions if only is None else [self.regions[k] for k in only]
        for name, point, s_idx, geom in chosen:
            kept = list(ts.angle_rows[name])
            rp = rows[name + "_point"]
            ra = rows[name + "_angles"] if kept else slice(0, 0)
            Lf, Lm3 = section_reaction_maps(point, Q, self.basis, 3)
            seat = ts.seats.get(name)
            # the seat's moment does not depend on the multipliers: a constant of the state
            m0 = np.zeros(3) if seat is None else Lm3[:, :2] @ seat.multipliers(Q)
            regions.append((name, s_idx, rp, ra, Lf, Lm3[:, kept],
                            self.law.mu(float(Qd[s_idx])), geom, m0))
        return FrictionAtState(self, regions, t, batch=only is None)

    def _resultant_rows(self, regions):
        """The regions' point multiplier rows stacked (k, p) for
        micro_motion_compiled.resultant_newton, formed once per set of regions; None where it
        does not apply (no numba, regions with unequal row counts)."""
        cache = self.__dict__.setdefault("_resultant_row_stacks", {})
        key = tuple(r[0] for r in regions)
        if key not in cache:
            from sim_core.physics.contact import _sliding_block_contact_numba as mmc
            sizes = {r[2].stop - r[2].start for r in regions}
            cache[key] = (np.stack([np.arange(r[2].start, r[2].stop) for r in regions])
                          if mmc.AVAILABLE and len(sizes) == 1 else None)
        return cache[key]

    def _compiled_regions(self, regions):
        """values(lam, x0, gradient) -> (g, dg or None) of all ``regions`` in one compiled call
        (micro_motion_compiled.regions_values), or None where it does not apply (regions
        without slider geometry, another spring law, no numba, unequal spring counts).  The
        call returns None where a region needs the reference path (a cold start, a failed
        solve: FrictionAtState.values then re-solves region by region and raises the typed
        error)."""
        from sim_core.physics.contact import _sliding_block_contact_numba as mmc
        from sim_core.physics.contact.sliding_block_contact import KAPPA, MAX_ITER, RTOL
        if (not mmc.AVAILABLE or type(self.spring) is not SpringLaw or not regions
                or self.friction_load != "springs" or self.ts.params.moment_model != "rigid"):
            return None          # the kernels take the rigid model's angle rows
        # what depends on the regions alone (geometry, multiplier rows) is stacked once
        key = tuple(r[0] for r in regions)
        cache = self.__dict__.setdefault("_region_stacks", {})
        if key not in cache:
            geoms = [r[7] for r in regions]
            if any(gm is None for gm in geoms) or len({gm.n_springs for gm in geoms}) != 1:
                cache[key] = None
            else:
                arrays = tuple(np.ascontiguousarray(np.stack([getattr(gm, a) for gm in geoms]),
                                                    dtype=float)
                               for a in ("A", "AT", "BfT", "AtA", "BftA"))
                Lr = np.array([1.0 / gm.length_scale for gm in geoms])
                rp = np.stack([np.arange(r[2].start, r[2].stop) for r in regions])
                ra = np.stack([np.arange(r[3].start, r[3].stop) for r in regions])
                cache[key] = (arrays, Lr, rp, ra)
        if cache[key] is None:
            return None
        (A, AT, BfT, AtA, BftA), Lr, rp, ra = cache[key]
        names = list(key)
        Lf = np.ascontiguousarray(np.stack([r[4] for r in regions]), dtype=float)
        Lm = np.ascontiguousarray(np.stack([r[5] for r in regions]), dtype=float)
        mu = np.array([r[6] for r in regions], dtype=float)
        k0, eps, kappa = self.spring.k0, self.spring.eps, KAPPA * self.spring.k0
        nan5 = np.full(5, np.nan)
        maps = (Lf, Lm, rp, ra, mu, A, AT, BfT, AtA, BftA, Lr)   # the kernels' shared arguments
        law = (k0, eps, kappa, RTOL, MAX_ITER)

        def warm(x0):                    # the regions' last micro-motions (NaN: none yet)
            return np.stack([x0.get(nm, nan5) for nm in names]).astype(float)

        def values(lam, x0, gradient):
            g, dg, X, status = mmc.regions_values(lam, *maps, warm(x0), *law, gradient)
            if status.any():
                return None
            x0.update(zip(names, X))
            return g, (dg if gradient else None)

        def newton(lam0, L, x0, tol, max_iter, g0):
            # the whole multiplier Newton (Model._multiplier_newton) in one compiled call, from
            # g0; None where a region needs the reference path (the caller runs the Python loop)
            g, X, ok = mmc.multiplier_newton(
                np.ascontiguousarray(lam0, dtype=float), np.ascontiguousarray(L, dtype=float),
                *maps, warm(x0), *law, float(tol), int(max_iter),
                np.ascontiguousarray(g0, dtype=float))
            if not ok:
                return None
            x0.update(zip(names, X))
            return g
        values.newton = newton
        return values

    def solve_regions(self, Q, Qd, lam):
        """Per region: (name, s_index, mu, ContactSolution) (distribution on) or
        (name, s_index, mu, N) with the transverse resultant N in N (distribution off)."""
        return self.at_state(0.0, Q, Qd).solve_regions(lam)

    def forces(self, t, Q, Qd, lam, only=None):
        """Generalized friction forces (N, on the contact coordinates), length of Q; ``only``:
        the regions to include (default all)."""
        at = self.at_state(t, Q, Qd, only)
        dF = np.zeros(len(Q))
        np.add.at(dF, at.coords, at.values(lam)[0])
        return dF

    def pieces(self) -> list["FrictionRegion"]:
        """The friction split by region for the structured Jacobian, each with the interface of
        the whole (coords, velocity_coords, forces), so that a column re-solves only the regions
        whose contact point depends on it."""
        return [FrictionRegion(self, k) for k in range(len(self.regions))]


class FrictionRegion:
    """The friction of one contact region of a :class:`ContactFriction`."""

    def __init__(self, owner: ContactFriction, k: int):
        self.owner, self.k = owner, k
        _, self.point, self.s_index, _ = owner.regions[k]

    def coords(self, Q):
        return dependencies([self.point], Q)

    def velocity_coords(self, Q):
        return np.array([self.s_index], dtype=int)

    def forces(self, t, Q, Qd, lam):
        return self.owner.forces(t, Q, Qd, lam, only=(self.k,))


class FrictionAtState:
    """Friction forces at a fixed state as a function of the multipliers lambda.

    They act on k = 2 (n_booms - 1) coordinates only (the contact coordinates), so they are the
    low-rank term  F_mu(lambda) = E g(lambda),  g_r = -mu_r N_r(lambda)  (Eq. 65 with the
    regularised law), that :meth:`sim_core.model.model.Model.accelerations_and_multipliers` solves
    by Newton in the k values g."""

    def __init__(self, owner: ContactFriction, regions: list, t: float = float("nan"),
                 batch: bool = True):
        self.owner = owner
        self.regions = regions
        self.t = t
        self.coords = np.array([r[1] for r in regions], dtype=int)
        self._mats = None
        # all regions in one compiled call (the friction Newton's several evaluations at one
        # state); a single region (a Jacobian column) takes the per-region path
        self._batch = owner._compiled_regions(regions) if batch else None
        # the resultant normal load: the multiplier Newton in one compiled call
        # (micro_motion_compiled.resultant_newton) where the regions' multiplier rows are equal
        # in number
        self._resultant = None
        if batch and owner.friction_load == "resultant" and regions:
            rows = owner._resultant_rows(regions)
            if rows is not None:
                self._resultant = (
                    np.ascontiguousarray(np.stack([r[4] for r in regions]), dtype=float), rows,
                    np.array([float(r[6]) for r in regions]))

    @property
    def _matrices(self):
        """The micro-motion Newton's matrices per region: they depend on the region and
        mu(s_dot) only, so they are formed once per state, not in every friction iteration."""
        if self._mats is None:
            self._mats = [None if geom is None else newton_matrices(geom, self.owner.spring, mu)
                          for (_, _, _, _, _, _, mu, geom, _) in self.regions]
        return self._mats

    def newton(self, lam0, L, tol: float, max_iter: int, g0):
        """g solving g = g(lam0 + L g) by the multiplier Newton of Model._multiplier_newton
        in one compiled call (micro_motion_compiled.multiplier_newton) from g0, or None where
        it does not apply (no compiled batch, a region that needs the reference path).  With
        the resultant normal load: micro_motion_compiled.resultant_newton, the same iteration."""
        if self._resultant is not None:
            from sim_core.physics.contact import _sliding_block_contact_numba as mmc
            return mmc.resultant_newton(np.ascontiguousarray(lam0, dtype=float),
                                        np.ascontiguousarray(L, dtype=float), *self._resultant,
                                        float(tol), int(max_iter),
                                        np.ascontiguousarray(g0, dtype=float))
        if self._batch is None:
            return None
        return self._batch.newton(lam0, L, self.owner._x0, tol, max_iter, g0)

    def solve_regions(self, lam):
        out = []
        x0 = self.owner._x0
        spring = self.owner.spring
        for name, s_idx, rp, ra, Lf, Lm, mu, geom, m0 in self.regions:
            f_c, m_c = Lf @ lam[rp], Lm @ lam[ra] + m0
            N_res = float(np.hypot(f_c[1], f_c[2]))
            if geom is None:
                out.append((name, s_idx, mu, N_res))
                continue
            sol = solve_micro_motion(geom, spring, f_c, m_c, mu, x0=x0.get(name))
            if self.owner.friction_load == "resultant" and mu != 0.0:
                # the friction force mu N_res acts on the springs in proportion to their normal
                # forces: coefficient mu N_res / sum f_ij in the moment balance (Eqs. 64-71),
                # a fixed point that settles in a few passes (the sum depends weakly on it)
                for _ in range(4):
                    total = sol.total_normal_force
                    mu_eff = mu * N_res / total if total > 0.0 else 0.0
                    sol = solve_micro_motion(geom, spring, f_c, m_c, mu_eff, x0=sol.x)
            x0[name] = sol.x
            out.append((name, s_idx, mu, sol))
        return out

    def values(self, lam, gradient: bool = False):
        """(g (k,), dg/dlambda (k, m) or None): g_r = -mu_r N_r, N the region's slider-spring
        sum (micro-motion solve, Eqs. 59-71; friction_load "springs") or its transverse
        resultant |(f_t, f_b)| ("resultant")."""
        x0 = self.owner._x0
        if self._batch is not None:            # all regions in one compiled call
            out = self._batch(np.ascontiguousarray(lam, dtype=float), x0, gradient)
            if out is not None:
                return out
        g = np.empty(len(self.regions))
        dg = np.zeros((len(self.regions), len(lam))) if gradient else None
        spring = self.owner.spring
        resultant = self.owner.friction_load == "resultant"
        matrices = [None] * len(self.regions) if resultant else self._matrices
        for r, ((name, _, rp, ra, Lf, Lm, mu, geom, m0), mats) in enumerate(
                zip(self.regions, matrices)):
            f_c = Lf @ lam[rp]
            if resultant:                              # the transverse resultant
                N = float(np.hypot(f_c[1], f_c[2]))
                g[r] = -mu * N
                if gradient and N > 0.0:
                    dg[r, rp] = -mu * (f_c[1:3] / N) @ Lf[1:3]
                continue
            # Eq. 65's normal load by the micro-motion solve (Eqs. 59-71) and its sensitivity
            # d N / d(f_t, f_b, m_s, m_t, m_b) (ContactSolution.normal_load_gradient)
            N, dN, x0[name] = normal_load(geom, spring, f_c, Lm @ lam[ra] + m0, mu, *mats,
                                          x0=x0.get(name), t=self.t)
            g[r] = -mu * N
            if gradient and mu != 0.0:
                dg[r, rp] = -mu * (dN[:2] @ Lf[1:3])
                dg[r, ra] = -mu * (dN[2:] @ Lm)
        return g, dg
