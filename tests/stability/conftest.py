"""Shared machinery of the numerical-stability suite (hard cases that must stay numerically
stable).

* Static equilibria cost ~25 s each at n_nodes = 3 (finite-difference tangent in the constrained
  Newton solve), so they are cached per session and keyed by the parameters that change the
  statics (friction, slider springs, gap, smoothing interval and the stress filter do not act at
  rest: friction law mu(0) = 0, the filter forces are rate terms).
* ``run_window`` integrates the full model with sim_core's own RK45 driver
  (``sim_core.integrate.driver.integrate``: the integrator statistics, including the minimum
  accepted step ``min_step_s``) and returns the public Result plus the total mechanical energy
  and the telescopic-cylinder work at the output times.
"""

from __future__ import annotations

import numpy as np
import pytest

from sim_core.integrate.driver import integrate, run_with_partial
from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import _telescopic_result, build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.energy_audit import AuditedSystem
from sim_core.systems.telescopic.energy_audit import mechanical_energy as _mechanical_energy

_EQ_KEYS = ("n_booms", "boom_length", "luffing_angle_deg", "stroke0", "L_h", "E", "rho",
            "payload", "rope_EA", "gravity", "n_nodes", "n_gauss", "torsion", "rope_elasticity",
            "flexible", "baumgarte")
_EQ_CACHE: dict = {}


def equilibrium(p: TelescopicParams):
    """(z, rope L0 by name) of the static equilibrium of the frictionless model with p's
    statics-relevant parameters, cached for the session."""
    key = tuple(getattr(p, k) for k in _EQ_KEYS)
    if key not in _EQ_CACHE:
        from dataclasses import replace
        q = replace(p, friction=False, contact_distribution=False, filter_h=0.0)
        ts = build_telescopic(q)
        z, _ = initial_equilibrium(ts)
        ropes = {pe.name: pe.L0 for pe in ts.model.point_effects if hasattr(pe, "L0")}
        _EQ_CACHE[key] = (z, ropes)
    return _EQ_CACHE[key]


def build_at_equilibrium(p: TelescopicParams, target=None):
    """Build the system of p, set the equilibrium rope lengths, optionally replace the
    telescopic cylinder's target (t -> (L, L_dot, L_ddot)) as boom_env does; returns (ts, y0)."""
    ts = build_telescopic(p)
    z, ropes = equilibrium(p)
    for pe in ts.model.point_effects:
        if pe.name in ropes:
            pe.L0 = ropes[pe.name]
    if target is not None:
        cyl = next(c for c in ts.model.nonlinear if c.name == "telescopic_cylinder")
        cyl.target = target
    return ts, np.concatenate([z, np.zeros_like(z)])


def build_undeformed(p: TelescopicParams, target=None):
    """Build the system of p and start from its straight, unloaded configuration at rest (a
    "drop" under gravity and payload: consistent with every constraint, not in equilibrium)."""
    ts = build_telescopic(p)
    m = ts.model
    if target is not None:
        cyl = next(c for c in m.nonlinear if c.name == "telescopic_cylinder")
        cyl.target = target
    z0, _ = m.reduced_state(0.0, ts.Q0, np.zeros_like(ts.Q0))
    return ts, np.concatenate([z0, np.zeros_like(z0)])


def mechanical_energy(ts, t: float, y: np.ndarray) -> float:
    """Kinetic + strain + gravity energy of the booms, payload point mass and rope strain (J)
    (sim_core.systems.telescopic.energy_audit.mechanical_energy).  The stress filter's rate terms are not included:
    with the filter on, a run from rest has E(t) - E(0) <= W (the filter's inertia-like term is
    >= 0 and its damping term dissipates)."""
    n = ts.model.n_dof
    return _mechanical_energy(ts, t, y[:n], y[n:])


class StepCollapse(AssertionError):
    """An accepted RK45 step below the stated floor: the run is stopped there (a stalled
    integrator would otherwise take hours to reach the end of the window)."""


def run_window(ts, y0, t_end: float, n_output: int = 21, rtol: float = 1e-6, atol: float = 1e-7,
               energy: bool = False, step_floor: float | None = None):
    """Integrate ts from y0 over [0, t_end] (RK45 of sim_core) and return the Result (outputs of
    the telescopic contract).  With ``energy``: also outputs ``energy`` (J, mechanical energy
    incl. payload and ropes) and ``cylinder_work`` (J, the work of the telescopic cylinder, its
    multiplier times the prescribed rate, integrated as an extra state of the same RK45 run:
    sim_core.systems.telescopic.energy_audit; with this model's sign convention the multiplier is the pushing
    force, positive in an extraction against gravity).  A SimulationError propagates with its
    partial result attached.  With ``step_floor``: raises StepCollapse at the first accepted
    step shorter than the floor (the final step, cut to land on t_end, excepted)."""
    m = ts.model
    n = m.n_dof
    sol = {"rtol": rtol, "atol": atol, "n_output": n_output}
    audited = AuditedSystem(ts, ("drive_work",)) if energy else None

    def collect(t, ys, stats, err):
        res = _telescopic_result(ts, t, ys[:, :2 * n], stats, err)
        if energy:
            res.outputs["energy"] = np.array([mechanical_energy(ts, tk, y[:2 * n])
                                              for tk, y in zip(t, ys)])
            res.outputs["cylinder_work"] = ys[:, 2 * n]
        return res

    last = [0.0]

    def watch(t, wall):
        h = t - last[0]
        last[0] = t
        if step_floor is not None and h < step_floor and t < t_end - step_floor:
            raise StepCollapse(f"accepted RK45 step {h:.3g} s < floor {step_floor:g} s at "
                               f"t = {t:.6g} s (wall {wall:.1f} s)")

    if energy:
        return run_with_partial(lambda: audited.integrate(y0, t_end, sol, watch), collect)
    return run_with_partial(lambda: integrate(m, y0, t_end, sol, watch), collect)


def energy_tol(ts, res) -> float:
    """Energy tolerance of a run (J): ENERGY_REL_TOL of the exchanged energy plus the total
    weight times ENERGY_POSITION_ERROR (see thresholds.py)."""
    from .thresholds import ENERGY_POSITION_ERROR, ENERGY_REL_TOL
    p = ts.params
    weight = p.gravity * (sum(b.section.rhoA * b.length for b in ts.model.beams) + p.payload)
    scale = np.ptp(res["energy"]) + np.max(np.abs(res["cylinder_work"]))
    return ENERGY_REL_TOL * scale + weight * ENERGY_POSITION_ERROR


def assert_no_energy_created(ts, res):
    """E(t) - E(0) - W_cyl(t) <= tolerance (friction and the stress filter only dissipate)."""
    excess = res["energy"] - res["energy"][0] - res["cylinder_work"]
    assert np.max(excess) <= energy_tol(ts, res), (np.max(excess), energy_tol(ts, res))


def assert_stable(res, min_step_floor: float, violation_tol: float):
    """The common checks of every hard case: completed, finite outputs, minimum accepted step
    above the floor, constraint violation below the tolerance."""
    assert res.error is None, res.error
    for name, val in res.outputs.items():
        assert np.all(np.isfinite(np.asarray(val, dtype=float))), f"non-finite output {name}"
    st = res.stats
    assert st["n_steps"] > 0
    assert st["min_step_s"] >= min_step_floor, (st["min_step_s"], min_step_floor, st)
    assert np.max(res["constraint_violation"]) <= violation_tol, np.max(res["constraint_violation"])


@pytest.fixture(scope="session")
def paper_params():
    """The paper's scene 9.2 (E = 2.1e11 Pa, 25 t, 60 deg, L_s = 2 m) at 2 sub-elements per
    spline element (n_nodes = 3) for speed."""
    return dict(n_nodes=3, E=2.1e11, payload=25000.0, luffing_angle_deg=60.0, stroke0=2.0)
