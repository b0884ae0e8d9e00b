"""Energy audit of a telescopic run: where the energy goes, integrated with the motion.

The audit checks "change of kinetic + elastic + gravity energy = drive work - friction
dissipation, to the solver tolerance".  With the equations of motion of the telescopic model
(Zhao-Qi-Wang 2024, Eq. 34 virtual power; constraint reactions M z_ddot = F + C^T lambda)

    d/dt (T + U + V + U_rope)  =  P_constraints + P_friction + P_filter                     (*)

holds *exactly* at every state, because every other force is either the gradient of one of
the energies (elastic U, gravity V, rope strain U_rope, payload weight) or the convective part
of the inertia forces, which does no work on the material kinetic energy T
(Q_dot . F_inertia = -1/2 Q_dot^T M_dot Q_dot, tests/beam/test_mass_offset.py).  The terms:

* ``P_constraints = lambda . (g_Q Q_dot)`` over all nonlinear constraint rows.  On the
  constraint manifold only the rheonomic row does work: the telescopic cylinder's
  ``P_drive = lambda_cyl * b_dot(t)`` (its prescribed stroke rate); the rest (Baumgarte
  correction of the velocity drift of the other rows) is reported separately and must be at
  the level of the integrator's error.
* ``P_friction = Q_dot . F_friction <= 0`` (Section 8.3: -mu(s_dot) N s_dot on each contact
  coordinate; mu is odd in s_dot), the friction dissipation.
* ``P_friction`` also holds the ground's damper under a payload on the ground
  (effect ``ground``, :mod:`sim_core.physics.ground_contact`): -P_diss <= 0, while its spring's
  strain energy is part of E.
* ``P_filter = Q_dot . (F_filter - M_filter Q_ddot)``: the stress filter (SIMULTECH 2020 Eq. 53,
  docs/model.md#input-filter) adds a mass-like term and rate forces; treated here as an applied
  force, so T stays the material kinetic energy of the booms.  Its integral is the energy the
  filter takes out (h/2 eps_dot' D eps_dot) or stores in its mass-like term.

``run_energy_audit`` integrates the works W = int P dt as extra states of the same RK45 run, so
the balance E(t) - E(0) - W_constraints - W_friction - W_filter is a pure integration error
(it shrinks with rtol: tests/telescopic/test_energy_balance.py).
"""

from __future__ import annotations

import math

import numpy as np

from sim_core import run_control
from sim_core.integrate.checks import ENERGY_FAIL, ENERGY_SUSPECT, verdict
from sim_core.physics.constraints import constraint_terms
from sim_core.physics.ground_contact import GroundContact
from sim_core.physics.hoist import HangingMass, HoistRope
from sim_core.physics.point_effects import RopeDrive, SliderSeat, ramp_energy
from sim_core.result import Result

WORK_NAMES = ("constraint_work", "drive_work", "friction_work", "filter_work")


def rope_energy(rope: RopeDrive, ell: float) -> float:
    """Strain energy (J) of a tension-only RopeDrive at length ell (m): the integral of its
    C1-ramp tension law (point_effects.RopeDrive.tension)."""
    return float(ramp_energy(rope.EA / rope.L0, ell - rope.L0, rope.slack_width))


def mechanical_energy(ts, t: float, z: np.ndarray, zd: np.ndarray) -> float:
    """Material kinetic + strain + gravity energy of the booms, payload point mass (kinetic and
    gravity), rope strain energy, the slider seats' and the ground's strain energy, J.  The
    stress filter's mass-like term is not included (it is accounted as the filter's work, see
    the module docstring)."""
    m, p = ts.model, ts.params
    Q, Qd = m.full_state(t, z, zd)
    g = np.array([0.0, 0.0, -p.gravity])
    en = m.energies(t, Q, Qd, g)
    E = en["T"] + en["U"] + en["V"]
    if p.payload > 0 and ts.hoist is None:
        r, J, _, _ = ts.tip(Q)
        v = J @ Qd
        E += 0.5 * p.payload * float(v @ v) - p.payload * float(r @ g)
    for pe in m.point_effects:
        if isinstance(pe, RopeDrive):
            E += rope_energy(pe, float(np.real(pe.length(Q)[0])))
        elif isinstance(pe, SliderSeat):
            E += pe.energy(Q)
        elif isinstance(pe, HangingMass):          # the swinging payload and its hook
            E += pe.energy(Q, Qd)
        elif isinstance(pe, HoistRope):
            E += pe.energy(Q, t)
        elif isinstance(pe, GroundContact):        # the ground spring under the payload
            E += pe.energy(Q)
    return float(np.real(E))


def slew_power(ts, t: float, Q, Qd, lam) -> float:
    """The slewing drive's power (W): the turntable's prescribed rate phi_dot times the torque
    the constraint rows exert on it, -lambda . g_phi phi_dot (on the manifold the rows' rates
    vanish, g_Q Q_dot = 0, so this equals their power on the booms' coordinates)."""
    _, J, _, _ = constraint_terms(ts.model.nonlinear, t, Q, Qd)
    return -float(np.real(lam @ J[:, ts.i_phi])) * float(np.real(Qd[ts.i_phi]))


def actuator_power(ts, t: float, Q, lam_luffing: float = 0.0) -> float:
    """The power (W) of the actuators other than the telescopic stages: the luffing cylinder's
    lambda b'(t) where it follows a profile (b = its length), and the hoist's dU/dL0 L0_dot
    (physics.hoist.HoistRope.hoist_power)."""
    P = 0.0
    if ts.params.luffing_profile is not None:
        c = next(c for c in ts.model.nonlinear if c.name == "luffing_cylinder")
        P += lam_luffing * float(np.atleast_1d(c.target(t)[1])[0])
    if ts.hoist is not None:
        P += ts.hoist.hoist_power(Q, t)
    return P


def plugin_power(ts, t: float, Q, Qd) -> float:
    """The power (W) the effect plug-ins feed into the system (their registered ``power``)."""
    return sum(plugin.power(effect, ts.model, t, Q, Qd)
               for plugin, effect in ts.plugin_effects if plugin.power is not None)


def _filter_power(m, filt, t, Q, Qd, Qdd) -> float:
    """Q_dot . (F_filter - M_filter Q_ddot), W, element by element."""
    P = 0.0
    for idx, ctx in m.element_contexts(t, Q, Qd):
        ne = len(idx)
        Me, Fe = np.zeros((ne, ne)), np.zeros(ne)
        filt.element_terms(ctx, Me, Fe)
        P += float(Qd[idx] @ (Fe - Me @ Qdd[idx]))
    return P


class AuditedSystem:
    """The telescopic model's first-order system extended by works (J) of WORK_NAMES:
    y = (z, z_dot, W_1, ..., W_k) for the chosen ``terms`` (default: all four).  Has ``rhs`` so
    that sim_core.integrate.driver.integrate integrates it like a model.  ``terms=("drive_work",)``
    costs nothing beyond the model's own right-hand side (lambda is computed there anyway)."""

    def __init__(self, ts, terms=WORK_NAMES):
        unknown = set(terms) - set(WORK_NAMES)
        if unknown:
            raise ValueError(f"terms = {sorted(unknown)}: allowed {WORK_NAMES}")
        self.ts, self.terms = ts, tuple(terms)
        m = ts.model
        self.n = m.n_dof
        self.filter = next((e for e in m.effects if e.name == "filtering"), None)
        # every prescribed stage length (cylinders, and the locked stages of the sequential drive)
        self.drives = [(c, ts.rows[c.name]) for c in m.nonlinear if c.name in ts.drives]

    def powers(self, t: float, z: np.ndarray, zd: np.ndarray):
        """(z_ddot, powers in W of self.terms, in that order)."""
        m = self.ts.model
        zdd, lam = m.accelerations_and_multipliers(t, z, zd)
        Q, Qd = m.full_state(t, z, zd)
        P = {}
        if "constraint_work" in self.terms:
            _, J, _, _ = constraint_terms(m.nonlinear, t, Q, Qd)
            P["constraint_work"] = float(lam @ (J @ Qd))
            if self.ts.i_phi is not None:       # on the booms, not on the turntable's phi
                P["constraint_work"] -= float(lam @ J[:, self.ts.i_phi]) * float(Qd[self.ts.i_phi])
            if self.ts.hoist is not None:       # the hoist: a rope of prescribed length
                P["constraint_work"] += self.ts.hoist.hoist_power(Q, t)
            P["constraint_work"] += plugin_power(self.ts, t, Q, Qd)   # external loads
            P["constraint_work"] += column_power(self.ts, t, Q, Qd)   # oil columns
        if "drive_work" in self.terms:
            P["drive_work"] = float(sum(np.sum(lam[row] * np.atleast_1d(c.target(t)[1]))
                                        for c, row in self.drives))
            P["drive_work"] += actuator_power(self.ts, t, Q,
                                              lam[self.ts.rows["luffing_cylinder"]][0])
            if self.ts.i_phi is not None:
                P["drive_work"] += slew_power(self.ts, t, Q, Qd, lam)
            P["drive_work"] += plugin_power(self.ts, t, Q, Qd)
            P["drive_work"] += column_power(self.ts, t, Q, Qd)
        if "friction_work" in self.terms:
            P["friction_work"] = (float(Qd @ sum(mf.forces(t, Q, Qd, lam)
                                                 for mf in m.multiplier_forces))
                                  if m.multiplier_forces else 0.0)
            if self.ts.ground is not None:      # the ground's damper (ground_contact)
                P["friction_work"] -= self.ts.ground.dissipation(Q, Qd)
        if "filter_work" in self.terms:
            P["filter_work"] = 0.0
            if self.filter is not None:
                Qdd = m.lift(t, zdd, 2)
                P["filter_work"] = _filter_power(m, self.filter, t, Q, Qd, Qdd)
        return zdd, [P[k] for k in self.terms]

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        n = self.n
        zdd, P = self.powers(t, y[:n], y[n:2 * n])
        return np.concatenate([y[n:2 * n], zdd, P])

    def integrate(self, y0: np.ndarray, t_end: float, sol: dict, progress=None):
        """integrate on the extended system from the model state y0 = (z, z_dot) with zero
        works: returns (t, Y, stats), Y = (z, z_dot, works...)."""
        from sim_core.integrate.driver import integrate
        Y0 = np.concatenate([y0, np.zeros(len(self.terms))])
        return integrate(self, Y0, t_end, sol, progress)


def run_energy_audit(ts, y0: np.ndarray, t_end: float, rtol: float = 1e-6, atol: float = 1e-7,
                     n_output: int = 21, terms=WORK_NAMES):
    """Integrate ts from y0 = (z, z_dot) with the works as extra states; returns a dict of
    arrays at the output times: ``t`` (s), ``energy`` (J, mechanical_energy), the works of
    ``terms`` (J, from 0), with all four terms ``residual`` = E - E(0) - W_constraints -
    W_friction - W_filter (J), and the RK45 ``stats``."""
    sysa = AuditedSystem(ts, terms)
    n = sysa.n
    t, Y, stats = sysa.integrate(y0, t_end, {"rtol": rtol, "atol": atol, "n_output": n_output})
    E = np.array([mechanical_energy(ts, tk, y[:n], y[n:2 * n]) for tk, y in zip(t, Y)])
    out = {"t": t, "energy": E, "stats": stats}
    for k, name in enumerate(sysa.terms):
        out[name] = Y[:, 2 * n + k]
    if set(sysa.terms) == set(WORK_NAMES):
        out["residual"] = (E - E[0] - out["constraint_work"] - out["friction_work"]
                           - out["filter_work"])
    return out


def column_power(ts, t: float, Q, Qd) -> float:
    """F l' (W) of every cylinder driven through its oil column (effects.oil_column,
    :class:`sim_core.physics.hydraulic_cylinder.OilColumn`): an applied force on the booms in
    place of the drive's constraint, whose work it is."""
    return float(sum(col.power(t, Q, Qd) for col in ts.oil_columns.values()))


def _drive_power_of_outputs(ts, audit: AuditedSystem, res: Result):
    """P_drive (W) at the output times from the result's ``drive_forces`` (the drive rows'
    multipliers, in the order of ``ts.drives``) and the prescribed stage rates b'(t): the
    ``drive_work`` power of :meth:`AuditedSystem.powers` without a right-hand side per output.
    None where the result has no drive forces or a drive has more than one row."""
    if "drive_forces" not in res or any(c.m != 1 for c, _ in audit.drives):
        return None
    F = np.asarray(res["drive_forces"], dtype=float)
    column = {name: k for k, name in enumerate(ts.drives)}
    P = np.zeros(len(res.t))
    for c, _ in audit.drives:
        rate = np.array([float(np.atleast_1d(c.target(t)[1])[0]) for t in res.t])
        P += F[:, column[c.name]] * rate
    return P


def telescopic_energy_check(ts, res: Result) -> dict:
    """Energy balance of a telescopic run's result (``res["state"]``: the integrated states at
    the output times): E = booms' T + U + V, payload and rope strain energy
    (:func:`sim_core.systems.telescopic.energy_audit.mechanical_energy`) against the telescopic cylinder's work
    W = int lambda_cyl b'(t) dt (its prescribed stroke rate; trapezoidal rule over the outputs,
    the power from one right-hand side per output).  Friction and the stress filter only take
    energy out and the other constraint rows do no work on the constraint manifold
    (:mod:`sim_core.systems.telescopic.energy_audit`), so only growth is checked: max_t (E - E(0) - W) over the
    exchanged energy ptp(E) + ptp(W), against ENERGY_SUSPECT and ENERGY_FAIL plus the
    quadrature error of W.  Empty where the result has no states."""
    if not len(res.t) or "state" not in res:
        return {}
    ts_, Y = np.asarray(res.t, dtype=float), np.asarray(res["state"])
    audit = AuditedSystem(ts, ("drive_work",))
    n = audit.n
    # every loop over the outputs checks the run's wall budget and Ctrl-C (run_control)
    E = np.array([mechanical_energy(ts, t, y[:n], y[n:2 * n])
                  for t, y in run_control.checked(zip(ts_, Y))])
    P = None if ts.i_phi is not None or ts.plugin_effects or ts.oil_columns else \
        _drive_power_of_outputs(ts, audit, res)
    if P is None:
        P = np.array([audit.powers(t, y[:n], y[n:2 * n])[1][0]
                      for t, y in run_control.checked(zip(ts_, Y))])
    elif ts.params.luffing_profile is not None or ts.hoist is not None:
        lam_l = np.asarray(res["luffing_cylinder_force"], dtype=float)
        P = P + np.array([actuator_power(ts, t, ts.model.full_state(t, y[:n], y[n:2 * n])[0], lam)
                          for t, y, lam in run_control.checked(zip(ts_, Y, lam_l))])
    W = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(ts_))])
    quad = 0.0
    if len(ts_) >= 3:
        tc, Pc = ts_[::2], P[::2]
        Wc = np.concatenate([[0.0], np.cumsum(0.5 * (Pc[1:] + Pc[:-1]) * np.diff(tc))])
        quad = float(np.max(np.abs(Wc - W[::2])))
    # the states carry relative errors ~rtol, so E itself is known to ~rtol |E|: a run that
    # exchanges less energy than that (nothing moves yet) is judged against that floor
    rtol = float(res.stats.get("rtol", 1e-12)) if isinstance(res.stats, dict) else 1e-12
    scale = max(float(np.ptp(E) + np.ptp(W)), max(1e-12, 10.0 * rtol) * float(np.max(np.abs(E))),
                1e-300)
    value = float(np.max(E - E[0] - W)) / scale
    if not np.isfinite(value):
        value = math.inf
    q = quad / scale
    return {"energy_balance": verdict(
        value, ENERGY_SUSPECT + q, ENERGY_FAIL + q,
        f"energy growth / exchanged energy (E = T + U + V + payload + ropes, W: drives; E_x = "
        f"{scale:.3g} J, quadrature {q:.2g})")}
