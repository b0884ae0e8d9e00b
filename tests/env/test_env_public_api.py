"""boom_env on sim_core's public API: v0 reproduces its pinned trajectories, and the full-physics
plant (boom_env.full_physics) gives the deflection and the payload's sway of the full model.

The reference trajectories (tests/env/data/v0_reference.json, written by
tests/env/make_v0_reference.py) record v0 under fixed action sequences: the ROM from the
default start and through velocity saturation and an end stop (three and five booms), and the
full model frictionless, with friction and with five booms.  The env must reproduce them to
round-off: the ROM's steps are closed-form arithmetic (relative 1e-12); the full model is
integrated by an error-controlled method, where a round-off difference (another BLAS) can change
the accepted steps and so the result by up to the solver's tolerance (rtol 1e-6, atol 1e-7 m),
which bounds the deflection there.  The stroke kinematics are the env's own arithmetic and match
exactly.
"""

from __future__ import annotations

import json
import math
import pickle
from pathlib import Path

import numpy as np
import pytest

from boom_env.full_physics import FullPhysicsPlant
from tests.env.make_v0_reference import EPISODES, run

REFERENCE = json.loads((Path(__file__).parent / "data" / "v0_reference.json").read_text())
RL = [k for k in EPISODES if k.startswith("rl")]
FULL = [k for k in EPISODES if k.startswith("paper")]


def _ref(name: str) -> dict:
    pre = f"{name}/"
    return {k[len(pre):]: np.asarray(v) for k, v in REFERENCE.items() if k.startswith(pre)}


def _compare(name: str, rtol: float, atol: float) -> None:
    kw, opt, _, _ = EPISODES[name]
    ref = _ref(name)
    rec = run(kw, opt, ref["actions"].astype(np.float32))
    assert len(rec["obs"]) == len(ref["obs"])
    for k in ("terminated", "truncated", "velocity_saturated", "end_stop", "diverged"):
        np.testing.assert_array_equal(rec[k], ref[k], err_msg=k)
    for k in ("stroke", "stroke_rate"):                    # the env's own kinematics
        np.testing.assert_array_equal(rec[k], ref[k], err_msg=k)
    np.testing.assert_array_equal(rec["obs"][:, :5], ref["obs"][:, :5])
    np.testing.assert_allclose(rec["tip_deflection"], ref["tip_deflection"], rtol=rtol, atol=atol)
    # float32 observations: the deflection and its rate, and the parameters where observed
    np.testing.assert_allclose(rec["obs"][:, 5:], ref["obs"][:, 5:], rtol=max(rtol, 6e-8),
                               atol=atol)
    # the reward differs through its deflection terms only: with |d| the deflection and dd <=
    # rtol |d| + sqrt(2) atol its difference (likewise the rate), |dr| <= scale dt (w_d
    # (2 |d| dd + dd^2) / d_ref^2 + w_r (2 |d'| dd' + dd'^2) / dv_ref^2), plus the rounding of
    # the sum
    from boom_env import TelescopicBoomEnv
    env = TelescopicBoomEnv(**kw)
    o = ref["obs"].astype(float)
    d, dv = np.hypot(o[:, 5], o[:, 6]), np.hypot(o[:, 7], o[:, 8])
    dd, ddv = rtol * d + math.sqrt(2) * atol, rtol * dv + math.sqrt(2) * atol
    bound = env.reward_scale * env.dt * (
        env.w["deflection"] * (2 * d * dd + dd * dd) / env.d_ref ** 2
        + env.w["rate"] * (2 * dv * ddv + ddv * ddv) / env.dv_ref ** 2)
    r, r0 = rec["reward"], ref["reward"]
    assert np.all(np.abs(r - r0) <= bound + 1e-12 * (1 + np.abs(r0))), np.max(np.abs(r - r0))


@pytest.mark.parametrize("name", RL)
def test_rom_fidelity_reproduces_the_v0_reference(name):
    _compare(name, rtol=1e-12, atol=1e-15)


@pytest.mark.slow
@pytest.mark.parametrize("name", FULL)
def test_paper_fidelity_reproduces_the_v0_reference(name):
    _compare(name, rtol=1e-6, atol=1e-7)


def test_reference_episodes_exercise_saturation_and_end_stops():
    """The pinned episodes reach the velocity limit and an end stop (the rate jump of the
    stroke command), on both fidelities."""
    for name in ("rl3_stops", "rl5_stops", "paper3_stops"):
        ref = _ref(name)
        assert ref["velocity_saturated"].any() and ref["end_stop"].any(), name


def _plant(**kw):
    return FullPhysicsPlant(**{"fidelity": "paper", "friction": False, **kw})


def test_plant_starts_in_equilibrium_and_restores_its_state():
    """The plant starts at rest in its own static equilibrium (zero deflection and rate), and a
    snapshot (through pickle) repeats the following steps bit for bit."""
    plant = _plant()
    assert np.max(np.abs(plant.tip_deflection())) < 1e-9
    a, dt = 0.2, 0.05
    for _ in range(2):
        plant.advance([(a, dt, 0.0)])
    snap = pickle.loads(pickle.dumps(plant.save_state()))
    steps = [[(-0.1, 0.02, 0.0), (0.0, 0.03, 0.0)], [(0.1, dt, 0.0)]]
    for s in steps:
        plant.advance(s)
    first = plant.tip_deflection()
    plant.restore_state(snap)
    for s in steps:
        plant.advance(s)
    assert plant.tip_deflection() == first
    # the stroke follows the segments exactly: L0 + a T^2/2 (T = 0.1 s), then the two steps
    T = 2 * dt
    L, v = 2.0 + 0.5 * a * T * T, a * T
    L, v = L + v * 0.02 - 0.5 * 0.1 * 0.02 ** 2, v - 0.1 * 0.02
    L, v = L + v * 0.03, v
    L, v = L + v * dt + 0.5 * 0.1 * dt * dt, v + 0.1 * dt
    assert (plant.L, plant.v) == pytest.approx((L, v), abs=1e-12)


@pytest.mark.slow
def test_plant_sway_rate_is_the_derivative_of_the_sway_angle():
    """payload_swing: the payload hangs on a 6 m rope under the tip.  At rest in equilibrium the
    rope is vertical; while the stroke accelerates (the tip moves out and up along the 60 deg
    boom, 2 m per m of L_s) the payload lags: the in-plane angle turns negative (towards the
    crane) within its quasi-static bound 2 a_x / g (a pendulum released from rest under a
    constant support acceleration a_x swings between 0 and -2 a_x / g; the boom's own vibration
    adds to a_x), and the out-of-plane angle stays 0 (symmetry).  The sway rate equals the
    central difference of the angle over +-1 ms to O(h^2)."""
    plant = _plant(payload_swing=True, rope_length=6.0)
    ax, ay, rx, ry = plant.sway()
    assert max(abs(ax), abs(ay), abs(rx), abs(ry)) < 1e-6
    a = 0.25
    for _ in range(10):
        plant.advance([(a, 0.05, 0.0)])
    h = 1e-3
    angles = []
    for _ in range(2):
        angles.append(plant.sway())
        plant.advance([(a, h, 0.0)])
    angles.append(plant.sway())
    a_x = 2 * a * math.cos(math.radians(60.0))
    mid = angles[1]
    assert -2.5 * a_x / 9.81 < mid[0] < 0.0
    assert abs(mid[1]) < 1e-9 and abs(mid[3]) < 1e-9
    fd = (angles[2][0] - angles[0][0]) / (2 * h)
    assert mid[2] == pytest.approx(fd, rel=1e-3, abs=1e-6)


@pytest.mark.parametrize("kw, match", [
    ({"fidelity": "fast"}, "fidelity = 'fast'"),
    ({"booms": 4}, "booms = 4"),
    ({"payload": 1000.0}, "payload = 1000.0 outside"),
    ({"rope_length": 5.0}, "rope_length"),
    ({"hydraulics": {"bulk_modulus": 2e9}}, "hydraulics"),
    ({"oil_column": True, "hydraulics": {"bulk_modulus": -1.0}}, "bulk_modulus"),
])
def test_plant_bad_arguments_name_the_field(kw, match):
    with pytest.raises(ValueError, match=match):
        FullPhysicsPlant(**kw)


@pytest.mark.slow
def test_train_fidelity_steps_the_full_model_with_friction():
    """fidelity='converged': the full model with friction at the training settings follows the env's
    stroke (the full model's stroke output equals the env's L_s to the constraint tolerance) and
    its deflection stays within the env's success tolerance (0.2 mm, the bound the training
    fidelity was chosen for in benchmarks/results/training_fidelity.md) of the same model at the
    paper's tolerance (fidelity 'paper' with friction on the paper's mesh) over the first
    second at full acceleration."""
    from boom_env import TelescopicBoomEnv
    from boom_env.full_physics import FIDELITIES
    train = FIDELITIES["converged"]
    env = TelescopicBoomEnv(fidelity="converged")
    ref = TelescopicBoomEnv(fidelity="paper", paper_friction=True,
                            paper_n_nodes=train["n_nodes"])
    o, _ = env.reset(seed=0)
    o_ref, _ = ref.reset(seed=0)
    assert env.plant.scene["effects"]["friction"]
    assert env.plant.scene["booms"]["n_nodes"] == train["n_nodes"]
    assert env.plant.scene["solver"]["rtol"] == train["solver"]["rtol"]
    assert np.max(np.abs(o[5:])) < 1e-9
    for _ in range(20):
        o, r, term, trunc, info = env.step(np.ones(1, np.float32))
        o_ref, *_, info_ref = ref.step(np.ones(1, np.float32))
        assert not info["diverged"], info["reason"]
        assert np.array_equal(o[:5], o_ref[:5])
        assert np.hypot(*(info["tip_deflection"] - info_ref["tip_deflection"])) <= 2e-4
    out = env.plant.sim.outputs(("piston_stroke",))
    assert out["piston_stroke"] + 2.0 == pytest.approx(info["stroke"], abs=1e-6)
    assert np.hypot(*info_ref["tip_deflection"]) > 1e-3      # a response to compare: mm
