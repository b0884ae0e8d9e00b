"""Hard cases 2 and 3: contact points passing each other, the overlap transition, and driving to
the end stops of the valid stroke range (0 < L_s < boom length).

Geometry (sim_core.systems.telescopic.build): boom 2 is two spline elements split at its outer contact node
s_3,2 = L - L_s; its inner contact point s_2,2 = L_s (boom 3's left end) is interpolated.  At
L_s = L/2 = 5 m the two contact points pass each other (s_2,2 moves from one element into the
other) and boom 3's left end passes boom 1's right end (overlap transition).  Near full
extension (L_s -> L) the element [0, s_3] of booms 2 and 3 shrinks towards zero length; near full
retraction (L_s -> 0) the element [s_3, L] does.

tests/telescopic/test_telescopic_system.py already drives the nearly rigid booms (E = 2.1e12,
1 t) through 5 m against the rigid model; here the soft, heavily loaded, steep case (E = 2.1e10
Pa, 25 t, 80 deg) crosses it with the energy balance, and the end stops are approached.
Frictionless, stress filter on (the paper's h = 0.01 s; it bounds the highest frequencies and
so the explicit step, and it only dissipates: from rest E(t) - E(0) <= W_cylinder(t))."""

import numpy as np
import pytest

from sim_core.systems.telescopic.params import TelescopicParams

from .conftest import assert_no_energy_created, assert_stable, build_at_equilibrium, run_window
from .thresholds import MIN_ELEMENT_LENGTH, MIN_STEP_FRICTIONLESS, constraint_tol

L = 10.0
SOFT_CROSSING = dict(n_nodes=3, E=2.1e10, payload=25000.0, luffing_angle_deg=80.0, stroke0=4.95,
                     v_max=0.5, t_ramp=0.1, t_hold_end=0.2)            # 4.95 -> 5.05 m
STIFF_EXTENSION = dict(n_nodes=3, E=2.1e12, payload=0.0, luffing_angle_deg=0.0, stroke0=9.6,
                       v_max=0.5, t_ramp=0.1, t_hold_end=0.6)          # 9.6 -> 9.9 m
PAPER_RETRACTION = dict(n_nodes=3, E=2.1e11, payload=25000.0, luffing_angle_deg=60.0,
                        stroke0=0.5, direction=-1, v_max=0.5, t_ramp=0.1, t_hold_end=0.8)  # -> 0.1


def energy_balanced(ts, res):
    """No energy is created: E(t) - E(0) - W_cyl(t) <= tolerance (the stress filter's rate terms
    add a non-negative 'kinetic' part (h^2/6) eps_dot' D eps_dot / 2 and dissipate (h/2) eps_dot'
    D eps_dot: starting at rest, the mechanical energy can only fall behind the work)."""
    assert_no_energy_created(ts, res)


def run_case(kw, t_end, n_out):
    # slider width 0.3 m does not fit the overlap L - L_s near full extension: resultants only
    p = TelescopicParams(**kw, contact_distribution=False)
    ts, y0 = build_at_equilibrium(p)
    res = run_window(ts, y0, t_end, n_out, energy=True)
    tol = constraint_tol(float(np.max(np.linalg.norm(res["tip_position"], axis=1))))
    assert_stable(res, MIN_STEP_FRICTIONLESS, tol)
    energy_balanced(ts, res)
    return p, res, tol


def _reach_end_stop(kw, t_end, n_out, stroke_end, s3_abs):
    """Drive to stroke_end (m) near an end stop: the piston gets there (to the driver row's
    violation), boom 2's outer contact node s_3,2 = L - L_s follows it to within s3_abs (m; it is
    tied to the piston, boom 3 follows on its elastic ropes and may surge about that), and every
    element keeps a positive length."""
    p, res, tol = run_case(kw, t_end, n_out)
    stroke = p.stroke0 + res["piston_stroke"]
    assert stroke[-1] == pytest.approx(stroke_end, abs=tol)
    s3 = res["outer_contact_s"][:, 0]
    extreme = np.min(s3) if stroke_end > p.stroke0 else np.max(s3)
    assert extreme == pytest.approx(L - stroke_end, abs=s3_abs)
    _element_lengths_positive(res)


def _element_lengths_positive(res):
    s3 = res["outer_contact_s"]                           # s_3,2 and s_3,3 (m)
    assert np.min(s3) >= MIN_ELEMENT_LENGTH and np.max(s3) <= L - MIN_ELEMENT_LENGTH
    s2 = res["inner_contact_s"]
    assert np.min(s2) > 0.0 and np.max(s2) < L


@pytest.mark.slow
def test_contact_points_pass_each_other_soft_heavy_steep():
    """4.95 -> 5.25 m at 0.5 m/s: s_2,2 - s_3,2 changes sign, no blow-up, energy balanced.
    (With E = 2.1e10 the ropes' EA scales to 1e7 N: boom 3 lags the piston by centimetres, so a
    0.1 m stroke did not carry s_2,2 past s_3,2 - measured -0.04 m at 5.05 m; 0.3 m does by the
    geometry, not yet re-measured.)"""
    p, res, tol = run_case(SOFT_CROSSING, 0.75, 31)
    stroke = p.stroke0 + res["piston_stroke"]
    assert stroke[0] < 5.0 < stroke[-1]
    gap = res["inner_contact_s"][:, 1] - res["outer_contact_s"][:, 0]   # s_2,2 - s_3,2
    assert gap[0] < 0.0 < gap[-1]
    _element_lengths_positive(res)


@pytest.mark.slow
def test_full_extension_to_the_end_stop_stiff_unloaded_horizontal():
    """9.6 -> 9.9 m (0.1 m short of the geometric limit): element [0, s_3] shrinks to 0.1 m."""
    _reach_end_stop(STIFF_EXTENSION, 0.7, 36, 9.9, s3_abs=1e-3)


@pytest.mark.slow
def test_full_retraction_to_the_end_stop():
    """0.5 -> 0.1 m on the paper's scene: element [s_3, L] of boom 2 shrinks to 0.1 m.

    Boom 3 hangs on its elastic extraction rope (k ~ EA / 18 m = 5.5e6 N/m) with the 25 t
    payload: the 0.1 s ramps (5 m/s^2) excite the rope-payload surge (~2.3 Hz), so boom 3's
    relative stroke swings by up to ~0.1 m about boom 2's (measured: it ends at 5 mm, its
    element [s_3, L] at 5.4 mm, s_3,3 = 9.9946 m).  The model has no mechanical end stop for
    boom 3 (a real crane would hit one); the check here is that the shrinking elements stay
    positive and the run stays stable and energy-consistent."""
    # s_3,2 is where boom 1's tip meets boom 2: L - L_s up to the shift from the booms' bending
    # and the radial offsets (25 t at 60 deg: measured +2.8 mm at the start, +3.9 mm at the end)
    _reach_end_stop(PAPER_RETRACTION, 1.0, 51, 0.1, s3_abs=1e-2)


@pytest.mark.slow
def test_crossing_at_paper_speed_paper_scene():
    """The paper's scene (E = 2.1e11, 25 t, 60 deg) through 5 m: 4.9 -> 5.1 m."""
    kw = dict(n_nodes=3, E=2.1e11, payload=25000.0, luffing_angle_deg=60.0, stroke0=4.9,
              v_max=0.5, t_ramp=0.2, t_hold_end=0.4)
    p, res, tol = run_case(kw, 0.7, 36)
    gap = res["inner_contact_s"][:, 1] - res["outer_contact_s"][:, 0]
    assert gap[0] < 0.0 < gap[-1]
    _element_lengths_positive(res)
