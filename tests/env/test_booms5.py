"""boom_env and the modal ROM with five sections (``booms=5``; the env checkers run in
test_env.py for both boom counts): the shipped five-section tables against the full model and
against kinematics, the scene route, and the errors for boom counts without tables."""

import numpy as np
import pytest

import boom_env  # noqa: F401
from boom_env import TelescopicBoomEnv
from sim_core.systems.telescopic.modal import (TABLE_BOOMS, allowed_ranges, data_path, load_raw,
                                                tables_for)

from .first_mode import first_mode_table_and_jacobian


@pytest.mark.parametrize("bad", [4, 2, 6, 0, True, "5", 5.5, None])
def test_bad_boom_count_names_the_field_and_the_allowed_values(bad):
    with pytest.raises(ValueError, match=r"booms = .*allowed 3, 5"):
        TelescopicBoomEnv(booms=bad)


def test_five_booms_env_uses_its_own_tables_and_ranges():
    """The payload range and the default payload follow the five-section tables; a payload of
    the three-boom range outside them is refused naming the field and the range."""
    (p_lo, p_hi), (a_lo, a_hi), _ = allowed_ranges(n_booms=5)
    env = TelescopicBoomEnv(booms=5, payload_range=(p_lo, p_hi), angle_range=(a_lo, a_hi),
                            observe_parameters=True)
    obs, info = env.reset(seed=1)
    assert info["booms"] == 5 and p_lo <= info["payload"] <= p_hi
    assert env.observation_space.contains(obs) and obs.shape == (11,)
    assert TelescopicBoomEnv(booms=5).payload0 == 10000.0            # the five-section scenes'
    with pytest.raises(ValueError, match=r"payload = 25000.0 outside .*booms = 5"):
        TelescopicBoomEnv(booms=5, payload=25000.0)
    for _ in range(40):
        obs, r, term, trunc, info = env.step(np.ones(1, np.float32))
        assert env.observation_space.contains(obs) and np.isfinite(r)
    assert not info["diverged"] and np.max(np.abs(obs[5:7])) > 1e-5  # the booms respond


def test_five_booms_deflect_more_than_three_under_the_same_stroke():
    """Same actions (full acceleration for 1 s, then braking for 1 s): the five-section crane
    (42 m, first mode 0.6 Hz at 10 t) deflects more than the paper's (26 m, 0.7 Hz at 25 t):
    the tip is four times as far from the hinge per metre of stroke and its effective mass
    per unit stroke acceleration is spread over the longer boom."""
    peaks = {}
    for n in (3, 5):
        env = TelescopicBoomEnv(booms=n)
        env.reset(seed=0)
        d = []
        for k in range(60):
            obs = env.step(np.array([1.0 if k < 20 else -1.0 if k < 40 else 0.0], np.float32))[0]
            d.append(np.hypot(obs[5], obs[6]))
        peaks[n] = max(d)
    assert peaks[5] > peaks[3] > 0


def test_rgb_array_render_five_booms():
    env = TelescopicBoomEnv(booms=5, render_mode="rgb_array")
    env.reset(seed=0, options={"stroke_start": 8.0})
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.std() > 0
    env.close()


def test_five_section_tables_are_physical():
    """The shipped five-section tables: their boom count is recorded; the static tip moves
    4 m per m of piston length (four stages on the same L_s, the synchronized drive) plus the
    sag change, and the stroke tangent of the implicit-function theorem agrees with the chords
    of neighbouring equilibria without a lateral part; the first in-plane frequency falls with the extension (at
    every grid point: at 1.75 m, 10 t, 60 deg it lies 0.2 % from a lateral one and must not be
    lost, modal._separate_planes) and with the payload; damping ratios lie in (0, 1)."""
    r = load_raw(n_booms=5)
    assert int(r["n_booms"]) == 5 and data_path(5).name == "modal_telescopic_5.npz"
    assert set(TABLE_BOOMS) == {3, 5}
    # chord of neighbouring equilibria: 4 plus the growth of the sag with the reach (up to
    # 9 cm of tip drop per m of stroke at 8 m, 45 deg, 15 t)
    chord = np.diff(r["tip_static"], axis=2)[..., [0, 2]] / np.diff(r["L_grid"])[:, None]
    c = np.linalg.norm(chord, axis=-1)
    assert np.all(c > 4.0 - 1e-3) and np.all(c < 4.1)
    # the stroke tangent of the implicit-function theorem against the chord: the mean of the
    # tangents at an interval's ends equals the chord to O(h^2) (third derivative of r_s,
    # h = 0.65 m; < 0.6 % where the equilibrium path is smooth).  Tension-only ropes make it
    # piecewise smooth: a retraction rope set just taut at stroke_ref = 2 m stays near its
    # slack point at low payloads and the tangent there is that of one branch (75 deg, 5 t,
    # L_s = 2.4 m: 1.0 %, both intervals next to it) -> median 1e-3, every interval 2 %
    tangent = r["tip_dL"][..., [0, 2]]
    mean = 0.5 * (tangent[..., 1:, :] + tangent[..., :-1, :])
    dev = np.linalg.norm(mean - chord, axis=-1) / 4.0
    assert np.median(dev) < 1e-3 and dev.max() < 2e-2, dev.max()
    assert np.max(np.abs(r["tip_dL"][..., 1])) < 1e-6           # no lateral part (symmetry)
    assert np.all(r["zeta"] > 0) and np.all(r["zeta"] < 1)
    f1 = r["omega"][..., 0]
    assert np.all(np.diff(f1, axis=-1) < 0)                           # with the extension
    if f1.shape[1] > 1:
        assert np.all(np.diff(f1, axis=1) < 0)                        # with the payload
    # the 10 t, 60 deg scenes are inside
    (p_lo, p_hi), (a_lo, a_hi), (L_lo, L_hi) = allowed_ranges(n_booms=5)
    assert p_lo <= 10000.0 <= p_hi and a_lo <= 60.0 <= a_hi and L_lo < 2.0 and L_hi > 8.0


def test_five_section_first_mode_matches_the_full_models_state_jacobian():
    """The tables' first in-plane mode (frozen-multiplier stiffness K projected on the null
    space of the constraints, undamped frequency and modal damping) against the eigenvalue of
    the full model's state Jacobian (sim_core.model.state_jacobian: implicit differentiation of
    the constrained equations of motion, Baumgarte terms included) at the same static
    equilibrium: 10 t, 60 deg, L_s = 5 m (a grid point), n_nodes = 3.

    Theory: on the constraint manifold (C dz = 0, invariant under the Baumgarte terms) the
    linearised motion is N^T M N y'' + N^T D N y' + N^T K N y = 0, so the physical eigenvalues
    are lambda = -zeta omega +- i omega sqrt(1 - zeta^2) to second order in the off-diagonal
    modal damping (the tables' zeta is the diagonal): |lambda| = omega and -Re(lambda) / |lambda|
    = zeta.  Both sides are central differences (the tables' K: step 1e-8 max|z|; the state
    Jacobian: 1.5e-8 per coordinate), error O(h^2) ~ 1e-8 relative (forward differences are
    not good enough here: the state Jacobian's are 0.15 % off in omega_1 at 10 t, 60 deg,
    6.3 m, the old tables' 1.9 %).  The second-order damping coupling
    (2 zeta_j omega_1 / omega_j)^2 <= 1e-4 with zeta_j <= 0.16 of the higher modes at
    omega_j >= 5 omega_1 -> omega within 1e-4; zeta within 1 % (a 1 % quantity: its coupling
    share, zeta_j / zeta_1 times that, 1e-2)."""
    payload, angle, L_s = 10000.0, 60.0, 5.0
    w_tab, z_tab, w, zeta = first_mode_table_and_jacobian(5, payload, angle, L_s)
    assert abs(w - w_tab) <= 1e-4 * w_tab
    assert abs(zeta - z_tab) <= 0.01 * z_tab


def test_five_section_rom_scene_runs_and_moves_the_tip_four_times_the_stroke():
    """The five-section scene on the ROM (model.reduction = 'modal', frictionless): piston
    2 -> 8 m, the tip travels 4 x 6 = 24 m along the boom (the static tip of the tables plus mm
    of deflection)."""
    import sim_core
    sc = sim_core.load_scene("telescopic_extraction_5",
                             overrides={"model.reduction": "modal", "effects.friction": False,
                                        "model.n_modes": 4})
    res = sim_core.simulate(sc)
    assert abs(res["piston_stroke"][-1] - 6.0) < 1e-9
    travel = np.linalg.norm(res["tip_position"][-1] - res["tip_position"][0])
    assert abs(travel - 24.0) < 0.05                                # sag change: cm
    assert np.all(np.isfinite(res["tip_deflection"]))
    assert np.max(np.abs(res["tip_deflection"])) < 0.1


@pytest.mark.parametrize("overrides, match", [
    ({"booms.count": 4}, "booms.count = 4: modal tables exist for booms.count 3 or 5"),
    ({"drive.mechanism": "sequential"}, "drive.mechanism = 'sequential'"),
])
def test_modal_scene_with_a_boom_count_or_drive_without_tables_is_refused(overrides, match):
    import sim_core
    from sim_core.errors import SceneError
    with pytest.raises(SceneError, match=match):
        sim_core.load_scene("telescopic_extraction_5",
                            overrides={"model.reduction": "modal", "effects.friction": False,
                                       **overrides})


def test_tables_for_a_count_without_tables_raises():
    with pytest.raises(ValueError, match="n_booms = 4: modal tables exist for booms 3, 5"):
        tables_for(10000.0, 60.0, n_booms=4)
    with pytest.raises(ValueError, match="payload = 25000.0 kg outside"):
        tables_for(25000.0, 60.0, n_booms=5)


@pytest.mark.slow
def test_paper_fidelity_five_booms_steps_the_full_model():
    """fidelity='paper' with five sections: both cylinders follow the env's stroke (the full
    model's stage strokes equal the env's L_s to the constraint tolerance) and the tip
    deflection from the static tip stays the small dynamic response."""
    env = TelescopicBoomEnv(booms=5, fidelity="paper")
    o, _ = env.reset(seed=0)
    assert np.max(np.abs(o[5:])) < 1e-9
    for _ in range(3):
        o, r, term, trunc, info = env.step(np.ones(1, np.float32))
        assert not info["diverged"], info["reason"]
    m = env._ts.model
    n = m.n_dof
    assert np.max(np.abs(m.constraint_violation(env.dt, env._y[:n], env._y[n:]))) < 1e-6
    assert np.all(np.isfinite(o)) and np.max(np.abs(o[5:7])) < 1e-2
    # every stage at the env's stroke: the cylinder stages (1-2, 3-4) to the constraint
    # tolerance, the rope stages (2-3, 4-5) within the rope stretch change (EA = 1e8 N, tension
    # change << 1e5 N over 10 m: < 1 cm)
    from sim_core.physics.constraints import material_point
    Q, _ = m.full_state(0.0, env._y[:n], env._y[n:])
    left = [np.real(material_point(m, k, s_fixed=0.0)(Q)[0]) for k in range(5)]
    stage = np.array([np.linalg.norm(left[k + 1] - left[k]) for k in range(4)])
    assert np.allclose(stage[[0, 2]], info["stroke"], atol=1e-6)
    assert np.allclose(stage[[1, 3]], info["stroke"], atol=1e-2)


def test_separate_planes_splits_a_mixed_near_degenerate_pair():
    """Two eigenpairs 0.2 % apart whose vectors mix an in-plane shape a (no lateral end
    displacement) and a lateral one b at 45 deg (as the noise of a differenced K mixes them):
    the separation returns a and b, still M-orthonormal (M = I here), each with its Rayleigh
    quotient inside the cluster (here the mean, 1.001: the split of a cluster is known to its
    width); a pair of one kind is returned as it is."""
    from sim_core.systems.telescopic.modal import _separate_planes
    n = 6
    a = np.zeros(n)
    a[[0, 2]] = (0.6, 0.8)                                     # in-plane: X, Z entries
    b = np.zeros(n)
    b[1] = 1.0                                                 # lateral: the Y entry
    D = np.zeros((3, 2, n))
    D[0, :, 0] = D[1, :, 1] = D[2, :, 2] = 1.0                 # coordinates 0, 1, 2 -> X, Y, Z
    c = np.sqrt(0.5)
    phi = np.column_stack([c * (a + b), c * (b - a)])          # the mixed eigenvectors
    w2 = np.array([1.0, 1.002])
    w2_out, phi_out = _separate_planes(w2, phi, D)
    assert np.allclose(phi_out.T @ phi_out, np.eye(2), atol=1e-12)
    lateral = np.abs(D[1] @ phi_out).max(axis=0)
    k_in = int(np.argmin(lateral))
    assert lateral[k_in] < 1e-12
    assert abs(phi_out[:, k_in] @ a) == pytest.approx(1.0, abs=1e-12)
    assert abs(phi_out[:, 1 - k_in] @ b) == pytest.approx(1.0, abs=1e-12)
    assert np.allclose(w2_out, 1.001, rtol=1e-12)
    same = np.column_stack([a, np.eye(n)[3]])                  # both without lateral motion
    w2s, phis = _separate_planes(w2, same, D)
    assert np.array_equal(phis, same) and np.array_equal(w2s, w2)


def _cubic_schedule_return(booms, task):
    """Unscaled return of the paper's cubic schedule (docs/model.md#input-drive) fed as mean
    accelerations."""
    from sim_core.physics.drive_profiles import CubicSmoothstepSchedule
    env = TelescopicBoomEnv(booms=booms, task=task)
    env.reset(seed=0)
    sign, s0 = (1, 2.0) if task == "extraction" else (-1, 8.0)
    sched = CubicSmoothstepSchedule(v_max=0.5, t_ramp=4.0, t_hold_end=12.0, sign=sign, s0=s0)
    total, success = 0.0, False
    for k in range(600):
        a = (sched.rate((k + 1) * env.dt) - sched.rate(k * env.dt)) / env.dt
        _, _, term, trunc, info = env.step(np.array([a / env.a_max], np.float32))
        total += info["reward_unscaled"]
        success |= info["success"]
        if term or trunc:
            break
    return total, success


@pytest.mark.parametrize("booms", [3, 5])
def test_paper_schedule_scores_better_than_standing_still(booms):
    """The reward ranks the paper's schedule above doing nothing for both boom counts (the
    five-section deflection scales are 10 times the three-boom ones: with the three-boom
    scales its 30 mm of deflection made it score -3549, ten times worse than standing still);
    standing still scores -(w_time + w_progress) x 30 s = -330 unscaled, and the retraction
    schedule meets the success test."""
    ext, _ = _cubic_schedule_return(booms, "extraction")
    ret, ret_success = _cubic_schedule_return(booms, "retraction")
    env = TelescopicBoomEnv(booms=booms)
    env.reset(seed=0)
    still = sum(env.step(np.zeros(1, np.float32))[4]["reward_unscaled"] for _ in range(600))
    assert still == pytest.approx(-330.0, rel=1e-9)
    assert -330.0 / 2 < ext < 0 and -330.0 / 2 < ret < 0 and ret_success
    assert TelescopicBoomEnv(booms=booms).d_ref == (1e-3 if booms == 3 else 1e-2)


@pytest.mark.parametrize("kw, match", [({"d_ref": 0.0}, "d_ref = 0.0: must be finite and > 0"),
                                       ({"dv_ref": np.nan}, "dv_ref = nan"),
                                       ({"tol_deflection": -1e-3}, "tol_deflection = -0.001")])
def test_bad_deflection_scales_are_refused(kw, match):
    with pytest.raises(ValueError, match=match):
        TelescopicBoomEnv(booms=5, **kw)
    assert TelescopicBoomEnv(booms=5, tol_deflection=0.0).tol["deflection"] == 0.0   # never met
