"""``solver.method = "auto"`` on the paper scene: BDF only while a contact's friction law is
in its slope band |s_dot| < 2 v_eps (sticking, breaking away, coming to stick), RK45 while
every contact slides.

Where RK45's step is held by the stress filter's eigenvalue pair (the sliding), BDF at the same
tolerance takes longer steps whose global error on the oscillating payload and booms is far
larger.  On this case (3 s from the static equilibrium, 2 sub-elements, rtol 1e-5, atol 1e-6,
against RK45 at rtol 1e-8) the cylinder force errs by 13 N with RK45, 335 N with BDF and 20 N
with "auto" (BDF through the breakaway only): the bounds below, auto within 3 times RK45's
error and BDF beyond 10 times, separate the two with margin."""

import numpy as np
import pytest

from sim_core import load_scene, simulate
from sim_core.physics.contact.sliding_block_contact import FrictionLaw
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.schema import params_from_scene

BASE = {"booms.n_nodes": 3, "solver.t_end": 3.0, "solver.n_output": 31}
LOOSE = {"solver.rtol": 1e-5, "solver.atol": 1e-6}


def test_slope_band_is_where_the_friction_coefficient_varies():
    """in_slope_band(v) is True exactly where d mu / dv != 0 (the law of
    docs/model.md#input-friction)."""
    law = FrictionLaw(0.15, 0.1, 0.01)
    for v in np.concatenate([np.linspace(-0.05, 0.05, 201), [0.0199, 0.0201, -0.0201]]):
        assert law.in_slope_band(v) == (law.dmu_dv(v) != 0.0), v


def _force(over):
    r = simulate(load_scene("telescopic_extraction", overrides={**BASE, **over}))
    return r, np.reshape(r["telescopic_cylinder_force"], (len(r.t), -1))[:, 0]


@pytest.fixture(scope="module")
def runs():
    ref, f_ref = _force({"solver.rtol": 1e-8, "solver.atol": 1e-9, "solver.method": "RK45"})
    auto, f_auto = _force({**LOOSE, "solver.method": "auto"})
    rk45, f_rk45 = _force({**LOOSE, "solver.method": "RK45"})
    _, f_bdf = _force({**LOOSE, "solver.method": "BDF"})
    return ref, f_ref, auto, f_auto, rk45, f_rk45, f_bdf


def test_auto_runs_bdf_only_through_the_breakaway(runs):
    """One BDF stretch, from the breakaway (the contacts stuck at t = 0) to the first BDF step
    after every contact rate has left the band (the outputs bracket that exit; a BDF step is
    shorter than one output interval here)."""
    _, _, auto, _, _, _, _ = runs
    ts = build_telescopic(params_from_scene(load_scene("telescopic_extraction",
                                                       overrides={**BASE, **LOOSE})))
    initial_equilibrium(ts)
    m = ts.model
    n = m.n_dof
    band = [m.friction_in_slope_band(t, y[:n], y[n:2 * n])
            for t, y in zip(auto.t, np.asarray(auto["state"]))]
    assert band[0] and not band[-1]
    exit_ = float(auto.t[int(np.flatnonzero(band)[-1]) + 1])    # first output out of the band
    assert all(not b for b in band[int(np.flatnonzero(band)[-1]) + 1:])
    st = auto.stats
    assert st["n_method_switches"] == 2                 # to BDF and back to RK45
    assert 0.0 < st["first_switch_to_bdf_s"] < exit_
    assert st["last_switch_s"] <= exit_ + (auto.t[1] - auto.t[0])


def test_auto_is_as_accurate_as_rk45_at_the_same_tolerance(runs):
    """The cylinder force against RK45 at rtol 1e-8: auto within 3 times RK45's error at the
    same tolerance, while BDF throughout is beyond 10 times (module doc)."""
    _, f_ref, _, f_auto, _, f_rk45, f_bdf = runs
    e_auto, e_rk45, e_bdf = (float(np.max(np.abs(f - f_ref))) for f in (f_auto, f_rk45, f_bdf))
    assert e_auto <= 3.0 * e_rk45, (e_auto, e_rk45)
    assert e_bdf > 10.0 * e_rk45, (e_bdf, e_rk45)
