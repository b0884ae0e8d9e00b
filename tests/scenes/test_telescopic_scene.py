"""Telescopic scene files: every validation rule (one bad value each, the message checked), the
effect switches as the scene resolves them, and the CLI's exit status on a bad scene."""

import math
import subprocess
import sys

import numpy as np
import pytest

from sim_core import SceneError, load_scene
from sim_core.scene.io import shipped_scenes
from sim_core.systems.telescopic.schema import params_from_scene

SCENE = "telescopic_extraction"


def _err(overrides, scene=SCENE) -> str:
    with pytest.raises(SceneError) as info:
        load_scene(scene, overrides=overrides)
    return str(info.value)


@pytest.mark.parametrize("name", [n for n in shipped_scenes() if n.startswith("telescopic")])
def test_shipped_telescopic_scenes_are_valid(name):
    sc = load_scene(name)
    p = params_from_scene(sc)
    assert p.n_booms == sc["booms"]["count"] and p.boom_length > 0


@pytest.mark.parametrize("key, value, allowed", [
    ("booms.length", 0.0, "[1, 100] m"),
    ("booms.length", -10.0, "[1, 100] m"),
    ("booms.E", 0.0, "[1e+08, 1e+15]"),
    ("booms.E", 1e-300, "[1e+08, 1e+15]"),
    ("booms.rho", -7850.0, "[10, 100000]"),
    ("payload.mass", -1.0, "[0, 2e+06]"),
    ("payload.mass", 1e12, "[0, 2e+06]"),
    ("ropes.EA", 0.0, "[10000, 1e+11] N"),
    ("contact.k0", 0.0, "[10000, 1e+12] N/m"),
    ("contact.eps", 0.0, "[1e-09, 0.01] m"),
    ("contact.v_eps", 0.0, "[1e-06, 1] m/s"),
    ("contact.mu_static", -0.1, "[0, 2]"),
    ("contact.slider_width", 0.0, "[0.001, 5] m"),
    ("contact.springs_per_quarter", 0, "[1, 200]"),
    ("contact.radial_gap", 0.0, "[0.0001, 0.05] m"),
    ("contact.radial_gap", -0.001, "[0.0001, 0.05] m"),
    ("filtering.h", 0.0, "[0.0001, 1] s"),
    ("solver.t_end", 0.0, "[1e-06, 3600] s"),
    ("solver.rtol", 1.0, "[1e-12, 0.1]"),
    ("booms.luffing_angle_deg", 90.0, "[0, 85]"),
    ("booms.n_nodes", 2, "[3, 33]"),
])
def test_out_of_range_value_names_field_value_and_range(key, value, allowed):
    msg = _err({key: value})
    assert msg.startswith(f"{key} = {value!r}") and allowed in msg


@pytest.mark.parametrize("count", [1, 0])
def test_boom_count_below_two(count):
    msg = _err({"booms.count": count, "effects.friction": False,
                "effects.contact_distribution": False})
    assert "booms.count" in msg and "[2, 6]" in msg


def test_boom_count_beyond_the_section_family_is_rejected_before_the_run():
    """Seven sections would need a section family the scenes do not define (crane_sections):
    the validator names the range instead of failing at t = 0."""
    msg = _err({"booms.count": 7, "effects.contact_distribution": False})
    assert msg.startswith("booms.count = 7") and "[2, 6]" in msg


@pytest.mark.parametrize("overrides, words", [
    ({"drive.mechanism": "hydraulic"}, ["drive.mechanism", "synchronized", "sequential"]),
    ({"booms.count": 5, "effects.contact_distribution": False, "effects.friction": False,
      "effects.flexible": False}, ["effects.flexible = false", "booms.count 2 or 3"]),
    ({"drive.mechanism": "sequential", "effects.flexible": False, "effects.friction": False},
     ["effects.flexible = false", "mechanism 'synchronized'"]),
])
def test_drive_mechanism_rules(overrides, words):
    msg = _err(overrides)
    assert all(w in msg for w in words), msg


@pytest.mark.parametrize("key", ["booms.E", "payload.mass", "drive.v_max", "contact.k0"])
@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_nan_or_inf_anywhere(key, bad):
    msg = _err({key: bad})
    assert key in msg and "finite" in msg


def test_stroke_history_that_pulls_a_boom_out():
    msg = _err({"drive.v_max": 1.0})          # 2 + 1.0 * 12 = 14 m > 10 m boom
    assert "drive" in msg and "outside the allowed (0, 10) m" in msg


def test_retraction_that_pushes_through_the_end():
    msg = _err({"drive.v_max": 1.0}, scene="telescopic_retraction")   # 8 - 12 < 0
    assert "outside the allowed (0, 10) m" in msg


def test_stroke0_beyond_the_boom():
    msg = _err({"booms.stroke0": 10.0})
    assert msg.startswith("booms.stroke0 = 10.0") and "[0.001, 10) m" in msg


def test_slider_wider_than_the_overlap():
    # extraction to L_s = 8 m leaves a 2 m overlap; two 1.2 m sliders do not fit
    msg = _err({"contact.slider_width": 2.0})
    assert "contact.slider_width = 2" in msg and "0 < slider_width < 2 m" in msg


def test_unknown_key_suggests():
    msg = _err({"effects.fricton": False})
    assert "effects.fricton: unknown key" in msg and "did you mean 'friction'" in msg


def test_contact_distribution_of_two_shorthand_booms_is_the_papers_pair_1_2():
    """The shorthand's two booms are the paper's booms 1 and 2 (params.crane_sections): their
    slider springs are the paper's regions of pair 1-2."""
    from sim_core.physics.contact import SliderGeometry
    from sim_core.systems.telescopic.sliders import slider_geometries
    sc = load_scene(SCENE, overrides={"booms.count": 2, "effects.contact_distribution": True})
    (inner, outer), = slider_geometries(params_from_scene(sc))
    ref = SliderGeometry.paper_region(1, "inner", radial_gap=0.005)
    assert inner.arcs.tolist() == ref.arcs.tolist() and (inner.k_t, outer.k_t) == (-1, 1)


def test_rigid_limit_rejects_friction():
    msg = _err({"effects.flexible": False})      # the paper scene has friction on
    assert "effects.friction = true with effects.flexible = false" in msg


def test_contact_models_are_choices_with_their_allowed_values():
    msg = _err({"contact.moment_model": "hinge"})
    assert "contact.moment_model" in msg and "rigid" in msg and "couple" in msg
    msg = _err({"contact.friction_load": "sum"})
    assert "contact.friction_load" in msg and "resultant" in msg and "springs" in msg
    msg = _err({"contact.seat_stiffness": 0.0})
    assert "contact.seat_stiffness" in msg


def test_spring_friction_load_needs_the_slider_springs():
    msg = _err({"contact.friction_load": "springs", "effects.contact_distribution": False})
    assert "contact.friction_load = 'springs' with effects.contact_distribution = false" in msg


def test_modal_rom_and_rigid_limit_have_only_the_rigid_moment_model():
    msg = _err({"contact.moment_model": "couple"}, scene="telescopic_extraction_rl")
    assert "model.reduction = 'modal' with contact.moment_model = 'couple'" in msg
    msg = _err({"contact.moment_model": "seat", "effects.flexible": False,
                "effects.friction": False})
    assert "contact.moment_model = 'seat' with effects.flexible = false" in msg


def test_contact_models_reach_the_model_parameters():
    sc = load_scene(SCENE)
    p = params_from_scene(sc)
    assert (p.moment_model, p.friction_load) == ("rigid", "resultant")      # the defaults
    sc = load_scene(SCENE, overrides={"contact.moment_model": "seat",
                                      "contact.seat_stiffness": 3e7,
                                      "contact.friction_load": "springs"})
    p = params_from_scene(sc)
    assert (p.moment_model, p.seat_stiffness, p.friction_load) == ("seat", 3e7, "springs")


def test_effect_switches_reach_the_model_parameters():
    sc = load_scene(SCENE, overrides={"effects.friction": False, "effects.torsion": False,
                                      "effects.rope_elasticity": False,
                                      "effects.contact_distribution": False,
                                      "effects.filtering": False, "effects.gravity": False})
    p = params_from_scene(sc)
    assert (p.friction, p.torsion, p.rope_elasticity, p.contact_distribution) == (False,) * 4
    assert p.filter_h == 0.0 and p.gravity == 0.0 and p.flexible


def test_contact_distribution_defaults_off_for_other_boom_counts():
    sc = load_scene(SCENE, overrides={"booms.count": 2, "effects.friction": False})
    assert sc["effects"]["contact_distribution"] is False


def test_cli_exits_2_with_one_line_on_a_bad_telescopic_scene():
    proc = subprocess.run([sys.executable, "-m", "sim_core.cli", "describe", SCENE,
                           "--set", "booms.E=-1"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert "booms.E = -1" in proc.stderr and "Traceback" not in proc.stderr


@pytest.mark.parametrize("args", [
    ["telescopic_extraction_rl"],
    ["telescopic_extraction_rigid", "--set", "effects.flexible=false"],
])
def test_cli_runs_the_fast_fidelities(tmp_path, args):
    """The ROM and the rigid limit run through the same CLI and write the result contract."""
    from sim_core.result import Result
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "sim_core.cli", "run", *args, "--out", str(out),
                           "--quiet", "--set", "solver.t_end=6"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    res = Result.load(out / "result.npz")
    assert res.t[-1] == pytest.approx(6.0)
    for key in ("tip_position", "piston_stroke"):
        assert np.all(np.isfinite(res[key]))
    assert (out / "summary.json").exists()


@pytest.mark.parametrize("key, value, allowed", [
    ("payload.mass", 7.0, "[20000, 30000]"),
    ("booms.luffing_angle_deg", 30.0, "[45, 75]"),
])
def test_modal_scene_refuses_values_outside_its_tables(key, value, allowed):
    """The modal ROM's tables cover 20-30 t and 45-75 deg: the validator names the range
    before the run (a value outside failed at run time with a traceback)."""
    msg = _err({key: value}, scene="telescopic_extraction_rl")
    assert msg.startswith(f"{key} = {value!r}") and allowed in msg


def test_fixed_step_below_its_floor_is_refused():
    """A generalized-alpha step below 1e-7 s (or more than 1e7 steps) cannot finish in any
    budget: the validator refuses it naming the allowed range."""
    with pytest.raises(SceneError) as info:
        load_scene("beam_through_sleeve", overrides={"solver.h": 1e-9, "solver.t_end": 0.2})
    assert "solver.h = 1e-09" in str(info.value) and "[1e-07, 0.2]" in str(info.value)
