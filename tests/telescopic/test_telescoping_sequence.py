"""Telescoping sequences (sim_core.systems.telescopic.telescoping): every stage on its own
profile (drive.mechanism "independent") and the single cylinder with locking pins
("single_cylinder").

Statics of a partial-extension state against the hand statics of the stack.  The crane is the
five-section shorthand at the telescoping mode 0/46/92/92 % of a 6 m stroke, frictionless (no
friction, so the pads carry no axial load), contact moment model "rigid" (Section 6; the checks
below are global balances, independent of how an overlap carries its moment).  Rigid booms,
weights W_i = m_i g on the reference line at mid-length, the payload at the tip:

* axial balance of the booms outside stage k (boom k+1 in boom k): the stage's cylinder or pin
  carries F_k = (m_(k+1) + ... + m_N + m_p) g sin(theta), whatever the extension;
* moment balance of the whole crane about the pivot D1 (the stages, contacts and pins are
  internal): the luffing cylinder pushes with F = M_D1 / (dL_cyl / dtheta), M_D1 = sum W_i x_i,
  x_i the horizontal arm of W_i from D1 with booms at a_k = L_s,1 + ... + L_s,k along boom 1;
  this one depends on the extension.

The flexible model tends to these values as E -> infinity: its deviation is the elastic sag's
change of the geometry, first order in 1/E, so ten times stiffer booms cut it by about ten
(asserted: by at least five) and leave it below 1e-4 of the force at E = 2.1e13 Pa (as
tests/telescopic/test_n_booms.py).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from sim_core import SceneError, load_scene, simulate
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.luffing import luffing_geometry
from sim_core.systems.telescopic.params import TelescopicParams, boom_section
from sim_core.systems.telescopic.schema import params_from_scene, validate_telescopic
from sim_core.systems.telescopic.telescoping import cylinder_stage, hold_profiles

THETA = 50.0
STROKE0, FULL = 1.0, 6.0
MODE = (0.0, 0.46, 0.92, 0.92)


def _mode_params(E: float) -> TelescopicParams:
    return TelescopicParams(n_booms=5, mechanism="independent", n_nodes=3, E=E, payload=3000.0,
                            luffing_angle_deg=THETA, stroke0=STROKE0, contact_distribution=False,
                            stage_profiles=hold_profiles(STROKE0 + f * FULL for f in MODE))


def _hand_statics(p: TelescopicParams) -> np.ndarray:
    """[F_stage_1 .. F_stage_(N-1), F_luffing] of the rigid, frictionless crane (module
    docstring), N."""
    th, g = math.radians(p.luffing_angle_deg), p.gravity
    m = [p.lengths[i] * boom_section(i, p).rhoA for i in range(p.n_booms)]
    stages = [(sum(m[k + 1:]) + p.payload) * g * math.sin(th) for k in range(p.n_booms - 1)]
    geo = luffing_geometry(th, *p.luffing.points())
    lengths = [float(pr.sample(0.0).s) for pr in p.stage_profiles]
    a = np.concatenate([[0.0], np.cumsum(lengths)])          # left sections along boom 1, m

    def arm(s):                                              # horizontal arm from D1, m
        return (geo.origin + s * np.asarray(geo.e_s))[0] - geo.d1[0]
    M = sum(m[i] * g * arm(a[i] + 0.5 * p.lengths[i]) for i in range(p.n_booms))
    M += p.payload * g * arm(a[-1] + p.lengths[-1])
    d = 1e-6                                                 # dL_cyl / dtheta, central
    dL = (luffing_geometry(th + d, *p.luffing.points()).cylinder_length
          - luffing_geometry(th - d, *p.luffing.points()).cylinder_length) / (2 * d)
    return np.array(stages + [M / dL])


def _model_statics(p: TelescopicParams) -> np.ndarray:
    ts = build_telescopic(p)
    _, lam = initial_equilibrium(ts)
    return np.array([lam[ts.rows[name]][0] for name in ts.drives]
                    + [lam[ts.rows["luffing_cylinder"]][0]])


def test_partial_extension_statics_tend_to_the_hand_statics():
    ref = _hand_statics(_mode_params(2.1e11))
    errs = [np.max(np.abs(_model_statics(_mode_params(E)) - ref) / np.abs(ref))
            for E in (2.1e12, 2.1e13)]
    assert errs[1] < 1e-4
    assert errs[1] < 0.2 * errs[0]
    # the mode matters: fully retracted, the luffing force is more than 5 % lower
    retracted = replace(_mode_params(2.1e11), stage_profiles=hold_profiles([STROKE0] * 4))
    assert _hand_statics(retracted)[-1] < 0.95 * ref[-1]


# -- scenes -------------------------------------------------------------------------------------

def _raw(drive: dict, **tables) -> dict:
    """A five-section shorthand crane with the given stagewise drive, coarse mesh."""
    raw = {"kind": "telescopic", "solver": {"t_end": 2.0, "n_output": 41},
           "booms": {"count": 5, "luffing_angle_deg": THETA, "stroke0": STROKE0, "n_nodes": 3},
           "payload": {"mass": 3000.0},
           "effects": {"friction": False, "contact_distribution": False},
           "drive": drive}
    raw.update(tables)
    return raw


def _single(**tel) -> dict:
    base = {"full_stroke": FULL, "pins": [0.0, 0.46, 0.92, 1.0],
            "sequence": [[4, 0.92], [3, 0.92], [2, 0.46]], "v_max": 0.5, "t_ramp": 2.0}
    base.update(tel)
    return _raw({"mechanism": "single_cylinder"}, telescoping=base)


def test_single_cylinder_sequence_reaches_the_mode_one_stage_at_a_time():
    """The build turns the sequence into stage profiles: at most one stage moves at a time,
    each move ends at its pin, and the last state is the mode 0/46/92/92 %."""
    p = params_from_scene(validate_telescopic(_single(), "<test>"))
    t = np.linspace(0.0, p.cylinder_moves[-1][1] + 1.0, 4001)
    rates = np.array([pr.rate(t) for pr in p.stage_profiles])
    assert np.all(np.count_nonzero(np.abs(rates) > 1e-12, axis=0) <= 1)
    final = np.array([pr.stroke(t[-1]) for pr in p.stage_profiles])
    assert np.allclose(final, [STROKE0 + f * FULL for f in MODE], rtol=0, atol=1e-12)
    assert [k for _, _, k in p.cylinder_moves] == [3, 2, 1]
    for t0, t1, k in p.cylinder_moves:          # the moving stage is the cylinder's
        mid = 0.5 * (t0 + t1)
        assert cylinder_stage(p.cylinder_moves, mid) == k
        assert abs(p.stage_profiles[k].rate(mid)) > 0.0


def test_stages_follow_their_profiles_and_the_pinned_ones_hold():
    """Two short single-cylinder moves on a four-section crane (stage 3 to 0.05, then stage 2
    to 0.05 of a 6 m stroke, 0.3 m each on 0.3 s cubic ramps, 0.1 s apart): every stage's
    length is its prescribed profile to the constraint tolerance (all stage lengths are
    constraints; 1e-5 m is the tolerance test_n_booms holds the sequential drive to), stage 1
    never moves and stage 3 holds its pin while stage 2 moves, to the same tolerance, and the
    reported cylinder force is that of the stage the cylinder is on."""
    raw = _single(pins=[0.0, 0.05], sequence=[[3, 0.05], [2, 0.05]], v_max=1.0, t_ramp=0.3,
                  dwell=0.1)
    raw["booms"]["count"] = 4
    raw["solver"] = {"t_end": 1.35, "n_output": 28}
    sc = validate_telescopic(raw, "<test>")
    res = simulate(sc)
    assert not res.suspect
    p = params_from_scene(sc)
    want = np.array([pr.stroke(res.t) for pr in p.stage_profiles]).T - STROKE0
    got = res["stage_stroke"]
    assert np.max(np.abs(got - want)) < 1e-5
    assert np.max(np.abs(got[:, 0])) < 1e-5                       # stage 1: pinned throughout
    (_, end3, _), (start2, _, _) = p.cylinder_moves
    after = res.t >= end3
    assert np.max(np.abs(got[after, 2] - 0.3)) < 1e-5             # stage 3 held at its pin
    assert np.ptp(got[res.t <= start2, 1]) < 1e-5                 # stage 2 before its move
    assert got[-1] == pytest.approx([0.0, 0.3, 0.3], abs=1e-5)    # both moves done
    for i, t in enumerate(res.t):
        k = cylinder_stage(p.cylinder_moves, t)
        assert res["telescopic_cylinder_force"][i] == res["drive_forces"][i, k]


def test_independent_stages_take_their_own_profiles():
    """Inline [[stage_drive]] tables: a hold, a cubic, a trapezoid and a table profile, each
    from its own length0, become the four stage profiles."""
    stages = [{"profile": "hold", "length0": 1.5},
              {"profile": "cubic", "travel": 2.76, "t_ramp": 1.0, "t_hold_end": 3.0},
              {"profile": "trapezoid", "travel": 5.52, "v_max": 1.0, "a_max": 0.5},
              {"profile": "table", "table": [[0.0, 2.0], [4.0, 6.52]]}]
    sc = validate_telescopic(_raw({"mechanism": "independent"}, stage_drive=stages), "<test>")
    p = params_from_scene(sc)
    assert [pr.stroke(0.0) for pr in p.stage_profiles] == [1.5, STROKE0, STROKE0, 2.0]
    end = [pr.stroke(100.0) for pr in p.stage_profiles]
    assert end == pytest.approx([1.5, STROKE0 + 2.76, STROKE0 + 5.52, 6.52], abs=1e-12)


@pytest.mark.parametrize("name, stroke0, full", [("crane_telescoping_sequence", 1.0, 8.0),
                                                  ("crane_telescoping_stages", 2.0, 6.0)])
def test_shipped_scenes_reach_the_mode(name, stroke0, full):
    """Both shipped telescoping scenes end in the mode 0/46/92/92 % (stage lengths stroke0 +
    fraction x full stroke) within their solver.t_end."""
    sc = load_scene(name)
    p = params_from_scene(sc)
    final = [pr.stroke(sc["solver"]["t_end"]) for pr in p.stage_profiles]
    assert final == pytest.approx([stroke0 + f * full for f in MODE], abs=1e-12)


# -- validation ---------------------------------------------------------------------------------

BAD = [
    (_single(pins=[0.0, 1.2]), ["telescoping.pins", "[0, 1]"]),
    (_single(pins=[0.0, 0.92, 0.46]), ["telescoping.pins", "increasing"]),
    (_single(sequence=[[5, 0.92]]), ["telescoping.sequence[0][0]", "[1, 4]"]),
    (_single(sequence=[[2.5, 0.92]]), ["telescoping.sequence[0][0]", "[1, 4]"]),
    (_single(sequence=[[4, 0.5]]), ["telescoping.sequence[0][1]", "0.5", "not a pin"]),
    (_single(sequence=[[4, 0.92], [4, 0.92]]), ["telescoping.sequence[1]", "already pinned"]),
    (_single(sequence=[[4, 0.0]]), ["telescoping.sequence[0]", "already pinned"]),
    (_single(start=[0.0, 0.0, 0.46]), ["telescoping.start", "4 numbers"]),
    (_single(start=[0.0, 0.0, 0.3, 0.0]), ["telescoping.start[2]", "not a pin"]),
    (_single(full_stroke=10.0), ["telescoping (stage", "outside the allowed (0, 10)"]),
    (_single(a_maxx=0.5), ["telescoping.a_maxx", "unknown key"]),
    (_raw({"mechanism": "single_cylinder"}), ["[telescoping]", "required"]),
    (_raw({"mechanism": "single_cylinder", "v_max": 0.5}, telescoping={}),
     ["drive.v_max", "mechanism only"]),
    (_raw({"mechanism": "synchronized"}, telescoping={"full_stroke": 6.0}),
     ["[telescoping]", "'single_cylinder'"]),
    (_raw({"mechanism": "independent"}, stage_drive=[{"profile": "hold"}] * 3),
     ["[[stage_drive]]", "3 tables for 4 stages"]),
    (_raw({"mechanism": "independent"},
          stage_drive=[{"profile": "hold"}] * 3 + [{"profile": "cubic", "travel": 9.5,
                                                    "t_hold_end": 4.0}]),
     ["stage_drive[3]", "outside the allowed (0, 10)"]),
    (_raw({"mechanism": "independent"}, stage_drive=[{"profile": "hold", "length0": -1.0}] * 4),
     ["stage_drive[0].length0", "out of range"]),
    (_raw({"mechanism": "independent"},
          stage_drive=[{"profile": "hold"}] * 3 + [{"profile": "trapezoid", "travel": 2.0,
                                                    "v_max": 1.0, "a_max": 0.5,
                                                    "max_rate": 0.5}]),
     ["stage_drive[3]", "stage cylinder", "max_rate = 0.5"]),
]


@pytest.mark.parametrize("raw, words", BAD)
def test_bad_telescoping_input_is_refused_naming_the_field(raw, words):
    with pytest.raises(SceneError) as exc:
        validate_telescopic(raw, "<test>")
    for w in words:
        assert w in str(exc.value), str(exc.value)
