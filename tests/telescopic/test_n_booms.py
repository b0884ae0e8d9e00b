"""Telescopic booms of two to six sections: the section family, the two drive mechanisms
(synchronized cylinder-and-rope units, sequential single cylinder with locked stages), their
statics against a hand calculation and their rigid limit against their own kinematics.

The hand calculation (frictionless, rigid booms, weights W_i = m_i g sin(theta) along the axis,
the payload's added to the tip boom) is the axial balance of every boom solved from the tip
inwards, written here independently of the production formula:

* synchronized: a cylinder on stage (k, k+1) pushes boom k+1 out, the rope unit of boom j pulls
  it out with T_j, pulls its pulley boom j-1 in with 2 T_j and its anchor boom j-2 out with T_j;
* sequential: the stage (k, k+1) carries everything outside boom k.

The flexible model tends to these values as E -> infinity: its deviation is the change of the
geometry by the elastic sag, first order in 1/E, so a ten times stiffer boom must cut it by about
ten (asserted: by at least five) and leave it below 1e-4 of the force at E = 2.1e13 Pa.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from sim_core.systems.telescopic.build import (
    active_stage,
    build_telescopic,
    drive_layout,
    initial_equilibrium,
    simulate_telescopic,
    stage_schedules,
)
from sim_core.systems.telescopic.luffing import luffing_geometry
from sim_core.systems.telescopic.params import (
    TABLE2,
    TelescopicParams,
    crane_sections,
    family_radius,
    family_section,
)
from sim_core.systems.telescopic.schema import params_from_scene

TH = math.radians(60.0)


def _params(n, mechanism="synchronized", **kw):
    base = dict(n_booms=n, mechanism=mechanism, n_nodes=3, payload=1000.0,
                contact_distribution=False)
    base.update(kw)
    return TelescopicParams(**base)


# -- the section family --------------------------------------------------------------------------

def test_family_reproduces_table2_on_the_papers_radii():
    """The family's construction on Table 1's radii gives Table 2: m' to 0.01 kg/m (the wall
    mid-line reading), EI within the 2 % the section module documents (-1.0..+1.8 %), GJ = EI /
    1.3 as Table 2 (within the same 2 %)."""
    for k, (EI, GJ, m) in enumerate(TABLE2):
        (EI_f, GJ_f, m_f), _ = family_section(family_radius(k, 3))
        assert m_f == pytest.approx(m, abs=0.01)
        assert EI_f == pytest.approx(EI, rel=0.02)
        assert GJ_f == pytest.approx(GJ, rel=0.02)


@pytest.mark.parametrize("n", [4, 5, 6])
def test_larger_cranes_put_the_papers_booms_inside(n):
    rows, zc = crane_sections(n)
    assert rows[-3:] == TABLE2 and len(rows) == len(zc) == n
    # stiffer and heavier outwards; adjacent walls (15 mm, mid-line radii 20 mm apart) keep
    # Table 1's 5 mm radial gap
    assert all(a[0] > b[0] and a[2] > b[2] for a, b in zip(rows, rows[1:]))
    gaps = [(family_radius(k, n) - 0.0075) - (family_radius(k + 1, n) + 0.0075)
            for k in range(n - 1)]
    assert np.allclose(gaps, 0.005)


# -- the drive layouts and schedules -------------------------------------------------------------

def test_synchronized_layout_is_the_papers_unit_repeated():
    assert drive_layout(3, "synchronized") == ([0], [2])          # the paper: Section 2
    assert drive_layout(5, "synchronized") == ([0, 2], [2, 4])
    assert drive_layout(6, "synchronized") == ([0, 2, 4], [2, 4])
    assert drive_layout(5, "sequential") == ([0, 1, 2, 3], [])


@pytest.mark.parametrize("direction", [1, -1])
def test_sequential_schedule_moves_one_stage_at_a_time(direction):
    p = _params(5, "sequential", direction=direction, stroke0=2.0 if direction > 0 else 8.0)
    st = stage_schedules(p)
    t = np.linspace(0.0, 4 * (p.t_ramp + p.t_hold_end), 2001)
    rates = np.array([s.rate(t) for s in st])
    assert np.all(np.count_nonzero(np.abs(rates) > 1e-12, axis=0) <= 1)
    travel = np.array([s.stroke(t[-1]) - p.stroke0 for s in st])
    assert np.allclose(travel, direction * p.v_max * p.t_hold_end)
    # extraction: the innermost stage first; retraction: the reverse order
    first = [np.argmax(np.abs(r) > 1e-12) for r in rates]
    order = np.argsort(first)
    assert list(order) == (list(range(3, -1, -1)) if direction > 0 else list(range(4)))


# -- statics against the hand calculation --------------------------------------------------------

def _hand(p):
    """(drive forces in the order of ts.drives, extraction-rope tensions by rope unit), N."""
    n, s = p.n_booms, p.gravity * math.sin(math.radians(p.luffing_angle_deg))
    W = [p.boom_length * row[2] * s for row in p.sections]
    W[-1] += p.payload * s
    if p.mechanism == "sequential":
        return [sum(W[k + 1:]) for k in range(n - 1)], []
    cyl, rope_booms = drive_layout(n, "synchronized")
    T, F = {}, {}
    for i in range(n - 1, 0, -1):              # from the tip inwards
        if i - 1 in cyl:                       # boom i pushed by the cylinder of stage i-1
            F[i - 1] = W[i] + 2 * T.get(i + 1, 0.0)
        else:                                  # boom i held by its rope
            T[i] = W[i] + F.get(i, 0.0) - T.get(i + 2, 0.0)
    return [F[k] for k in cyl], [T[j] for j in rope_booms]


def _static_forces(p):
    ts = build_telescopic(p)
    z, lam = initial_equilibrium(ts)
    Q, _ = ts.model.full_state(0.0, z, np.zeros_like(z))
    forces = [lam[ts.rows[name]][0] for name in ts.drives]
    tensions = [ext.tension(float(ext.length(Q)[0])) for ext, _ in ts.ropes]
    return np.array(forces + tensions)


@pytest.mark.parametrize("n, mechanism", [(4, "synchronized"), (5, "synchronized"),
                                          (5, "sequential")])
def test_statics_tend_to_the_hand_calculation(n, mechanism):
    p = _params(n, mechanism)
    F, T = _hand(p)
    ref = np.array(F + T)
    errs = [np.max(np.abs(_static_forces(replace(p, E=E)) - ref) / ref) for E in (2.1e12, 2.1e13)]
    assert errs[1] < 1e-4
    assert errs[1] < 0.2 * errs[0]


# -- the rigid limit of each mechanism -----------------------------------------------------------

def _run(n, mechanism, t_end, E):
    """No gravity, no payload, inextensible ropes: the booms move as the drive's kinematics
    prescribes up to their elastic response to the drive's inertia loads (first order in 1/E)."""
    p = _params(n, mechanism, E=E, gravity=0.0, payload=0.0, rope_elasticity=False,
                v_max=0.5, t_ramp=0.2, t_hold_end=0.4)
    res = simulate_telescopic(p, t_end=t_end, n_output=41, solver={"method": "auto"})
    assert not res.suspect
    return p, res


def test_synchronized_tip_tends_to_n_minus_one_strokes():
    """Every stage moves with the piston: the rigid tip travels (N - 1) (L_s(t) - L_s(0)) along
    the luffed axis e_s at the rate (N - 1) L_s'(t) (Eqs. 74-76 for N = 3: twice the stroke).
    The flexible booms' deviation from it is their elastic response, first order in 1/E: ten
    times stiffer booms cut it by at least five, to below 2e-5 m and 5e-4 m/s (2.5e-4 of the
    2 m/s peak tip rate) at E = 2.1e13 Pa; the solver's own error (atol 1e-7) is far below."""
    n = 5
    e = np.asarray(luffing_geometry(TH).e_s, float)
    errs = []
    for E in (2.1e12, 2.1e13):
        p, res = _run(n, "synchronized", 0.8, E)
        sched = stage_schedules(p)[0]
        travel = (n - 1) * (sched.stroke(res.t) - p.stroke0)
        rate = (n - 1) * sched.rate(res.t)
        tip = res["tip_position"] - res["tip_position"][0]
        errs.append((np.max(np.abs(tip - travel[:, None] * e)),
                     np.max(np.abs(res["tip_velocity"] - rate[:, None] * e))))
    (x0, v0), (x1, v1) = errs
    assert x1 < 2e-5 and v1 < 5e-4
    assert x1 < 0.2 * x0 and v1 < 0.2 * v0


def test_sequential_stages_follow_their_windows():
    """The single cylinder moves one stage on the cubic schedule while the locked stages keep
    their length: every stage's stroke is its own schedule (all prescribed, so to the solver's
    tolerance), and the reported cylinder force is the active stage's."""
    n = 4
    p, res = _run(n, "sequential", 3 * 0.6, 2.1e11)
    ts = build_telescopic(p)
    want = np.array([s.stroke(res.t) - p.stroke0 for s in stage_schedules(p)]).T
    assert np.max(np.abs(res["stage_stroke"] - want)) < 1e-5
    for i, t in enumerate(res.t):
        assert res["telescopic_cylinder_force"][i] == res["drive_forces"][i, active_stage(ts, t)]


# -- two to six sections (slow suite) ------------------------------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize("mechanism", ["synchronized", "sequential"])
@pytest.mark.parametrize("n", [2, 3, 4, 5, 6])
def test_statics_of_two_to_six_sections(n, mechanism):
    """Every crane the scenes accept has its static equilibrium, tending to the hand
    calculation as 1/E (module docstring)."""
    p = _params(n, mechanism)
    F, T = _hand(p)
    ref = np.array(F + T)
    errs = [np.max(np.abs(_static_forces(replace(p, E=E)) - ref) / ref) for E in (2.1e12, 2.1e13)]
    assert errs[1] < 1e-4 and errs[1] < 0.2 * errs[0]


@pytest.mark.slow
@pytest.mark.parametrize("n", [2, 3, 4, 5, 6])
def test_two_seconds_of_extraction_with_two_to_six_sections(n):
    """The five-section scene with booms.count = n (friction, filter, elastic ropes, 8
    sub-elements) runs 2 s: its own checks pass (energy balance, constraints), the cylinder
    stages follow the schedule to the constraint tolerance, and the tip moves out along the
    axis by (N - 1) strokes within 5 % (the rope stretch, T / EA ~ 2e-3 of ~18 m ropes, and the
    change of the deflection stay well inside)."""
    from sim_core import load_scene, simulate
    sc = load_scene("telescopic_extraction_5", overrides={"booms.count": n, "solver.t_end": 2.0,
                                                          "solver.n_output": 21})
    res = simulate(sc)
    assert not res.suspect and np.all(np.isfinite(res["tip_position"]))
    p = params_from_scene(sc)
    sched = stage_schedules(p)[0]
    s = sched.stroke(res.t) - p.stroke0
    cyl, _ = drive_layout(n, "synchronized")
    assert np.max(np.abs(res["stage_stroke"][:, cyl] - s[:, None])) < 1e-6
    e = np.asarray(luffing_geometry(TH).e_s, float)
    travel = (res["tip_position"][-1] - res["tip_position"][0]) @ e
    assert travel == pytest.approx((n - 1) * s[-1], rel=0.05)
