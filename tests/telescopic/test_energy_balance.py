"""Energy balance over a flexible, frictional telescopic run (issue 3):

    change of kinetic + elastic + gravity (+ rope) energy
        = drive work - friction dissipation - stress-filter dissipation,

to the solver tolerance.  The works are integrated as extra states of the same RK45 run
(sim_core.systems.telescopic.energy_audit), so the balance residual is an integration error only.

Setup: the paper's scene 9.2 (E = 2.1e11 Pa, 25 t, 60 deg, friction 0.1/0.15, v_eps 0.01 m/s,
filter h = 0.01) at 2 sub-elements per spline element, from its static equilibrium, with the
cubic ramp shortened to 0.5 s so that the 0.15 s window goes from stick (s_dot = 0) into
sliding (s_dot ~ 0.1 m/s > 2 v_eps).  ~1 min on the 2-core machine per combination.

Every combination of the slider-moment model (contact.moment_model: rigid, seat, couple) and
the friction's normal load (contact.friction_load: resultant, springs) closes the same balance;
the defaults (rigid, resultant) run in the default suite, the other five in the slow one.
"""

import numpy as np
import pytest

from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.energy_audit import run_energy_audit

RTOL = 1e-6


COMBINATIONS = [pytest.param(("rigid", "resultant"), id="rigid-resultant")] + [
    pytest.param((mm, fl), id=f"{mm}-{fl}", marks=pytest.mark.slow)
    for mm in ("rigid", "seat", "couple") for fl in ("resultant", "springs")
    if (mm, fl) != ("rigid", "resultant")]


@pytest.fixture(scope="module", params=COMBINATIONS)
def audit(request):
    moment_model, friction_load = request.param
    p = TelescopicParams(n_nodes=3, E=2.1e11, payload=25000.0, luffing_angle_deg=60.0,
                         stroke0=2.0, t_ramp=0.5, t_hold_end=0.6, friction=True,
                         moment_model=moment_model, friction_load=friction_load)
    ts = build_telescopic(p)
    z, _ = initial_equilibrium(ts)
    return run_energy_audit(ts, np.concatenate([z, 0 * z]), 0.15, rtol=RTOL, atol=RTOL / 10,
                            n_output=16)


def _scale(a):
    """Energy exchanged in the run (J): the sum of the magnitudes of every term."""
    return (np.max(np.abs(a["energy"] - a["energy"][0])) + np.max(np.abs(a["drive_work"]))
            + np.max(np.abs(a["friction_work"])) + np.max(np.abs(a["filter_work"])))


def test_energy_balance_to_solver_tolerance(audit):
    """|E(t) - E(0) - W_constraints + D_friction + D_filter| <= rtol * (energy exchanged): the
    works are RK45 states under the same relative error control as the motion (measured:
    ~1e-8 of the exchanged energy at rtol 1e-6, ~1e-9 at 1e-7)."""
    tol = RTOL * _scale(audit)
    assert np.max(np.abs(audit["residual"])) <= tol, (audit["residual"], tol)


def test_every_term_matters(audit):
    """The check can fail: leaving out the friction or the filter work, or taking the drive
    work with the wrong sign, breaks the balance by far more than the tolerance (the filter's
    work is the smallest term: with friction from the contact resultant ~100 x the tolerance)."""
    tol = RTOL * _scale(audit)
    r = audit["residual"]
    assert np.max(np.abs(r + audit["friction_work"])) > 100 * tol
    assert np.max(np.abs(r + audit["filter_work"])) > 20 * tol
    assert np.max(np.abs(r + 2 * audit["constraint_work"])) > 100 * tol


def test_only_the_drive_does_constraint_work(audit):
    """On the constraint manifold only the rheonomic telescopic cylinder works (lambda_cyl
    times its prescribed rate); the other rows (contact constraints I/II, luffing cylinder of
    fixed length) add only the Baumgarte correction of the velocity drift, at solver level."""
    tol = RTOL * _scale(audit)
    assert np.max(np.abs(audit["constraint_work"] - audit["drive_work"])) <= tol
    assert audit["drive_work"][-1] > 0.0          # the cylinder pushes the booms out (work in)


def test_friction_and_filter_dissipate(audit):
    """Friction (Section 8.3: -mu(s_dot) N s_dot, mu odd in s_dot) only removes energy; so does
    the filter over the run (it starts from rest, so its stored rate energy ends >= 0)."""
    tol = RTOL * _scale(audit)
    d = np.diff(audit["friction_work"])
    assert np.all(d <= tol)
    assert audit["friction_work"][-1] < -1e3 * tol        # sliding set in: friction is active
    assert audit["filter_work"][-1] < 0.0
