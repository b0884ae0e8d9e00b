"""Hard case 1: tiny radial gaps (down to 0.1 mm) and very stiff slider springs (up to 1e12 N/m)
with a small smoothing interval eps, frictional contact on (the spring sum is the friction
normal load, so the micro-motion solve of Section 8 acts on the motion in every RHS call).

The drive is the paper's schedule (smoothstep start from rest): within the window the contacts
are on the static (stick) branch of the friction law, where the normal load - the spring sum -
sets the stiff viscous-like friction force.  (A fast sliding start is hard case 4; see
test_velocity_reversal.py for its failure.)"""

import numpy as np
import pytest

from sim_core.systems.telescopic.params import TelescopicParams

from .conftest import assert_no_energy_created, assert_stable, build_at_equilibrium, run_window
from .thresholds import CONSTRAINT_TOL, MIN_STEP_FRICTION

START = dict(friction=True)


def _check_contact(res, k0, eps):
    f = res["slider_contact_forces"]                      # (n_out, 4 regions, springs)
    assert np.all(np.isfinite(f))
    # springs push only (force-law f = k(delta) delta >= 0 for delta >= 0, zero in the gap)
    assert np.min(f) >= 0.0
    # triangle inequality: the spring forces (in the section plane) add up to the transverse
    # contact resultant, so their magnitudes' sum is at least the resultant's magnitude
    cpf = res["contact_point_forces"]                     # (n_out, pair, I/II, 6)
    for i in range(f.shape[0]):
        for r, (k, j) in enumerate(((0, 0), (0, 1), (1, 0), (1, 1))):
            fs = cpf[i, k, j]
            assert f[i, r].sum() >= np.hypot(fs[1], fs[2]) * (1 - 1e-6), (i, r)
    # stiff springs: compressions f / k0 stay of the order of eps or below (no penetration blow-up)
    assert np.max(f) / k0 < 1e-3


def _run(paper_params, gap, k0, eps, t_end, n_out):
    p = TelescopicParams(**paper_params, radial_gap=gap, spring_k0=k0, spring_eps=eps, **START)
    ts, y0 = build_at_equilibrium(p)
    return ts, run_window(ts, y0, t_end, n_out, energy=True, step_floor=MIN_STEP_FRICTION)


def test_tiny_gap_stiffest_springs_small_eps(paper_params):
    """0.1 mm gap, k0 = 1e12 N/m, eps = 1e-8 m, first 0.05 s of the drive."""
    ts, res = _run(paper_params, 1e-4, 1e12, 1e-8, 0.05, 6)
    assert_stable(res, MIN_STEP_FRICTION, CONSTRAINT_TOL)
    _check_contact(res, 1e12, 1e-8)
    assert_no_energy_created(ts, res)
    assert res["piston_stroke"][-1] > 0.0                  # it did move


@pytest.mark.slow
@pytest.mark.parametrize("gap", [1e-4, 1e-3, 5e-3])
@pytest.mark.parametrize("k0", [1e9, 1e12])
def test_gap_and_spring_grid(paper_params, gap, k0):
    """The grid of gaps 0.1-5 mm and springs 1e9-1e12 N/m (eps = 1e-8 m), 0.15 s windows."""
    ts, res = _run(paper_params, gap, k0, 1e-8, 0.15, 16)
    assert_stable(res, MIN_STEP_FRICTION, CONSTRAINT_TOL)
    _check_contact(res, k0, 1e-8)
    assert_no_energy_created(ts, res)
