"""Scene validation: every bad value is refused with a SceneError whose message names the dotted
field, the value and the allowed range; unknown keys and names get a "did you mean" hint.

Validation only (no model is built), so these tests are fast.
"""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path

import pytest

from sim_core import load_scene
from sim_core.errors import SceneError
from sim_core.scene.io import apply_overrides, parse_value, shipped_scenes
from sim_core.systems.beam.schema import BEAMS, GRAVITY, POINT_LOADS, SECTION, SOLVER, validate

SCENE = "beam_through_sleeve"


def err(overrides: dict, scene: str = SCENE) -> str:
    with pytest.raises(SceneError) as ei:
        load_scene(scene, overrides=overrides)
    msg = str(ei.value)
    assert "\n" not in msg
    return msg


def assert_names(msg: str, *parts: str) -> None:
    for p in parts:
        assert p in msg, f"{p!r} not in message {msg!r}"


# -- the shipped scene ----------------------------------------------------------------------

def test_shipped_scene_is_valid_and_resolved():
    assert "beam_through_sleeve" in shipped_scenes()
    sc = load_scene(SCENE)
    assert sc["name"] == "beam_through_sleeve"
    assert sc["solver"]["t_end"] == 8.0
    assert sc["effects"] == {"gravity": True, "torsion": True, "filtering": True}
    b = sc["beams"][0]
    assert b["breakpoints"] == [8.0, 12.0] and b["n_nodes"] == 9 and b["n_gauss"] == 5
    assert b["section"]["I_p"] == pytest.approx(b["section"]["I_t"] + b["section"]["I_b"])
    assert sc["boundary"][0]["speed"] == -0.5 and sc["boundary"][0]["kind"] == "sleeve"
    assert sc["point_loads"][0] == {"beam": 0, "s": 12.0, "speed": 0.0,
                                    "force": [0.0, 0.0, -500.0], "start": 0.0}


def test_overrides_do_not_modify_the_raw_scene():
    raw = {"solver": {"t_end": 1.0}}
    out = apply_overrides(raw, {"solver.t_end": 2.0})
    assert raw == {"solver": {"t_end": 1.0}} and out == {"solver": {"t_end": 2.0}}


# -- material and geometry values outside their physical ranges ------------------------------

@pytest.mark.parametrize("key", ["E", "G", "rho", "A", "I_t", "I_b", "J", "I_p"])
@pytest.mark.parametrize("value", [0.0, -1.0, 1e30])
def test_section_value_outside_its_range(key, value):
    """Non-positive and absurdly large section constants are refused with the declared range
    and its unit (E in [1e8, 1e15] Pa, A in [1e-8, 10] m^2, ...)."""
    msg = err({f"beams.0.section.{key}": value})
    assert_names(msg, f"beams[0].section.{key}", f"= {value!r}", SECTION[key].range_text())


@pytest.mark.parametrize("value", [0.0, -12.0, 1e4])
def test_length_outside_its_range(value):
    assert_names(err({"beams.0.length": value}), "beams[0].length", f"= {value!r}",
                 "[0.001, 1000] m")


def test_missing_required_value_names_the_range():
    sec = load_scene(SCENE)["beams"][0]["section"]
    msg = err({"beams.0.section": {k: sec[k] for k in ("E", "G", "rho", "A", "I_t", "I_b")}})
    assert_names(msg, "beams[0].section.J", "missing", SECTION["J"].range_text())


# -- NaN and inf anywhere -------------------------------------------------------------------

NUMBER_FIELDS = [
    ("solver.t_end", "solver.t_end", "[1e-06, 3600] s"),
    ("solver.rtol", "solver.rtol", "[1e-12, 0.1]"),
    ("solver.atol", "solver.atol", "[1e-14, 0.01] m"),
    ("solver.max_step", "solver.max_step", "[1e-07, 8] s"),       # at most solver.t_end
    ("solver.n_output", "solver.n_output", "[2, 200001]"),
    ("filtering.h", "filtering.h", "[0.0001, 1] s"),
    ("beams.0.length", "beams[0].length", "[0.001, 1000] m"),
    ("beams.0.n_nodes", "beams[0].n_nodes", "[3, 65]"),
    ("beams.0.n_gauss", "beams[0].n_gauss", "[1, 10]"),
    ("beams.0.section.E", "beams[0].section.E", "[1e+08, 1e+15] Pa"),
    ("beams.0.section.J", "beams[0].section.J", "[1e-16, 100] m^4"),
    ("boundary.0.speed", "boundary[0].speed", "[-10, 10] m/s"),
    ("point_loads.0.s", "point_loads[0].s", "[0, 12] m"),          # on the 12 m beam
    ("point_loads.0.speed", "point_loads[0].speed", "[-10, 10] m/s"),
    ("point_loads.0.start", "point_loads[0].start", "[0, 3600] s"),
]


@pytest.mark.parametrize("text", ["nan", "inf", "-inf"])
@pytest.mark.parametrize("key, field, rng", NUMBER_FIELDS)
def test_non_finite_number(key, field, rng, text):
    msg = err({key: text})             # a string value is parsed as TOML: nan, inf, -inf
    assert_names(msg, field, f"= {parse_value(text)!r}", "finite", rng)


VECTOR_FIELDS = [
    ("gravity.g", "gravity.g", GRAVITY["g"]),
    ("beams.0.origin", "beams[0].origin", BEAMS["origin"]),
    ("beams.0.direction", "beams[0].direction", BEAMS["direction"]),
    ("boundary.0.position", "boundary[0].position", None),
    ("boundary.0.direction", "boundary[0].direction", None),
    ("point_loads.0.force", "point_loads[0].force", POINT_LOADS["force"]),
]


def _component_range(f) -> str:
    return f"[{f.lo:g}, {f.hi:g}]" + (f" {f.unit}" if f.unit else "")


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("key, field, decl", VECTOR_FIELDS)
@pytest.mark.parametrize("j", [0, 2])
def test_non_finite_vector_component(key, field, decl, j, bad):
    vec = [1.0, 0.0, 0.0]
    vec[j] = bad
    msg = err({key: vec})
    assert_names(msg, f"{field}[{j}]", f"= {bad!r}", "finite")
    if decl is not None:
        assert_names(msg, _component_range(decl))


@pytest.mark.parametrize("key, field, decl", [v for v in VECTOR_FIELDS if v[2] is not None])
def test_vector_component_outside_its_range(key, field, decl):
    msg = err({key: [0.0, 1.0, decl.hi * 10 + 1.0]})
    assert_names(msg, f"{field}[2]", "out of range", _component_range(decl))


def test_non_finite_vector_component_through_an_indexed_override():
    msg = err({"gravity.g.2": "nan"})
    assert_names(msg, "gravity.g[2]", "= nan", "finite")


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_non_finite_breakpoint(bad):
    msg = err({"beams.0.breakpoints": [8.0, bad]})
    assert_names(msg, "beams[0].breakpoints", repr(bad), "finite", "[0, 12]")


@pytest.mark.parametrize("key, field", [("gravity.g", "gravity.g"),
                                        ("point_loads.0.force", "point_loads[0].force")])
@pytest.mark.parametrize("value", [[0.0, 1.0], [0.0, 1.0, 2.0, 3.0], 5.0, "down"])
def test_vector_of_wrong_shape(key, field, value):
    assert_names(err({key: value}), field, repr(value), "list of 3")


# -- directions -----------------------------------------------------------------------------

@pytest.mark.parametrize("key, field", [("beams.0.direction", "beams[0].direction"),
                                        ("boundary.0.direction", "boundary[0].direction")])
def test_zero_direction_vector(key, field):
    msg = err({key: [0.0, 0.0, 0.0]})
    assert_names(msg, field, "[0.0, 0.0, 0.0]", "zero vector", "nonzero")


# -- breakpoints ----------------------------------------------------------------------------

@pytest.mark.parametrize("bps", [[12.0, 8.0], [8.0, 8.0], [0.0, 6.0, 5.0, 12.0]])
def test_breakpoints_not_increasing(bps):
    msg = err({"beams.0.breakpoints": bps})
    assert_names(msg, "beams[0].breakpoints", repr(bps), "increase strictly", "[0, 12]")


@pytest.mark.parametrize("bps, j", [([-1.0, 12.0], 0), ([8.0, 12.5], 1), ([-0.5, 13.0], 0)])
def test_breakpoints_outside_the_beam(bps, j):
    msg = err({"beams.0.breakpoints": bps})
    assert_names(msg, f"beams[0].breakpoints[{j}] = {bps[j]!r}", "out of range", "[0, 12] m")


@pytest.mark.parametrize("bps", [[8.0], [], 8.0, list(range(40))])
def test_breakpoints_not_a_list_of_2_to_33(bps):
    msg = err({"beams.0.breakpoints": bps})
    assert_names(msg, "beams[0].breakpoints", "must be a list of 2 to 33 numbers")


@pytest.mark.parametrize("bps", [["a", 12.0], [True, 12.0]])
def test_breakpoints_that_are_not_numbers(bps):
    msg = err({"beams.0.breakpoints": bps})
    assert_names(msg, "beams[0].breakpoints[0]", repr(bps[0]), "number", "[0, 12] m")


def test_breakpoints_range_follows_the_length():
    msg = err({"beams.0.length": 10.0})            # shipped breakpoints end at 12
    assert_names(msg, "beams[0].breakpoints[1] = 12.0", "out of range", "[0, 10] m")


# -- integers -------------------------------------------------------------------------------

@pytest.mark.parametrize("value", [2, 0, -3])
def test_n_nodes_below_three(value):
    assert_names(err({"beams.0.n_nodes": value}), "beams[0].n_nodes", f"= {value}", "[3, 65]")


@pytest.mark.parametrize("value", [5.5, "5.5", "five", True])
def test_n_nodes_not_an_integer(value):
    shown = repr(parse_value(value) if isinstance(value, str) else value)
    msg = err({"beams.0.n_nodes": value})
    assert_names(msg, "beams[0].n_nodes", f"= {shown}", "integer", "[3, 65]")


def test_integral_float_n_nodes_is_accepted_as_int():
    sc = load_scene(SCENE, {"beams.0.n_nodes": 5.0})
    assert sc["beams"][0]["n_nodes"] == 5 and isinstance(sc["beams"][0]["n_nodes"], int)


@pytest.mark.parametrize("value", [0, 11, -1, 2.5])
def test_n_gauss_out_of_range(value):
    assert_names(err({"beams.0.n_gauss": value}), "beams[0].n_gauss", f"= {value!r}", "[1, 10]")


@pytest.mark.parametrize("value", [1, 10])
def test_n_gauss_limits_accepted(value):
    assert load_scene(SCENE, {"beams.0.n_gauss": value})["beams"][0]["n_gauss"] == value


# -- solver ---------------------------------------------------------------------------------

@pytest.mark.parametrize("value", [0.0, 1e-15, 0.5, 1.0, -1e-3])
def test_rtol_outside_its_range(value):
    assert_names(err({"solver.rtol": value}), "solver.rtol", f"= {value!r}",
                 SOLVER["rtol"].range_text())


@pytest.mark.parametrize("value", [0.0, -1.0, 1e5])
def test_t_end_outside_its_range(value):
    assert_names(err({"solver.t_end": value}), "solver.t_end", f"= {value!r}",
                 "[1e-06, 3600] s")


def test_t_end_missing():
    raw_solver = {"rtol": 1e-6}
    assert_names(err({"solver": raw_solver}), "solver.t_end", "missing", "[1e-06, 3600] s")


def test_t_end_not_a_number():
    assert_names(err({"solver.t_end": "soon"}), "solver.t_end", "'soon'", "number",
                 "[1e-06, 3600] s")


def test_max_step_at_most_t_end():
    assert_names(err({"solver.max_step": 9.0}), "solver.max_step", "= 9.0", "[1e-07, 8] s")
    assert load_scene(SCENE, {"solver.max_step": 8.0})["solver"]["max_step"] == 8.0


def test_unknown_method_suggests():
    assert_names(err({"solver.method": "rk45"}), "solver.method", "'rk45'", "RK45",
                 "did you mean 'RK45'")


@pytest.mark.parametrize("scene", ["beam_through_sleeve", "telescopic_extraction", "folding_boom"])
def test_one_solver_table_for_every_scene_kind(scene):
    """The [solver] table is validated by one function (sim_core.scene.fields.solver_table) for all
    scene kinds: the same methods are accepted, the same errors name the field and range."""
    for method in ("RK45", "BDF", "auto"):
        assert load_scene(scene, overrides={"solver.method": method})["solver"]["method"] == method
    t_end = load_scene(scene)["solver"]["t_end"]
    assert_names(err({"solver.method": "Radau"}, scene), "solver.method", "'Radau'",
                 "RK45", "BDF", "auto")
    assert_names(err({"solver.max_step": 0}, scene), "solver.max_step",
                 f"[1e-07, {t_end:g}] s")
    assert_names(err({"solver.max_wall_s": -1}, scene), "solver.max_wall_s", "(0, 86400] s")
    assert_names(err({"solver.rtol": 1.0}, scene), "solver.rtol", "[1e-12, 0.1]")


def test_ros2_keys_of_the_telescopic_kind():
    """solver.method = "ROS2" (the telescopic kind only) reads its fixed step h (default 0.05 s,
    at most t_end) and jacobian_interval (default 0.5 s, >= 0); the two keys are refused with
    another method, and by kinds without the method; the generalized-alpha keys stay refused."""
    tel = "telescopic_extraction"
    s = load_scene(tel, overrides={"solver.method": "ROS2"})["solver"]
    assert (s["h"], s["jacobian_interval"]) == (0.05, 0.5)
    s = load_scene(tel, overrides={"solver.method": "ROS2", "solver.h": 0.02,
                                   "solver.jacobian_interval": 0.0})["solver"]
    assert (s["h"], s["jacobian_interval"]) == (0.02, 0.0)
    t_end = load_scene(tel)["solver"]["t_end"]
    assert_names(err({"solver.method": "ROS2", "solver.h": 2 * t_end}, tel), "solver.h",
                 f"{t_end:g}")
    assert_names(err({"solver.method": "ROS2", "solver.h": 1e-6}, tel), "solver.h", "[0.0001, ")
    assert_names(err({"solver.method": "ROS2", "solver.jacobian_interval": -1.0}, tel),
                 "solver.jacobian_interval", "-1")
    assert_names(err({"solver.jacobian_interval": 0.5}, tel), "solver.jacobian_interval",
                 "only method = 'ROS2'", "'auto'")
    assert_names(err({"solver.h": 0.05}, tel), "solver.h", "'ROS2'", "'auto'")
    assert_names(err({"solver.method": "ROS2", "solver.rho_inf": 0.5}, tel), "solver.rho_inf",
                 "generalized_alpha")
    for other in ("beam_through_sleeve", "folding_boom"):
        assert_names(err({"solver.method": "ROS2"}, other), "solver.method", "'ROS2'")
        assert_names(err({"solver.jacobian_interval": 0.5}, other), "solver.jacobian_interval",
                     "only method = 'ROS2'")


@pytest.mark.parametrize("key, field", [("effects.gravity", "effects.gravity"),
                                        ("initial.static_equilibrium", "initial.static_equilibrium")])
def test_boolean_field(key, field):
    assert_names(err({key: 1}), field, "= 1", "true or false")


# -- unknown keys at every level --------------------------------------------------------------

@pytest.mark.parametrize("key, field, hint", [
    ("solverr.t_end", "scene.solverr", "solver"),
    ("solver.tend", "solver.tend", "t_end"),
    ("effects.gravty", "effects.gravty", "gravity"),
    ("filtering.hh", "filtering.hh", "h"),
    ("gravity.gg", "gravity.gg", "g"),
    ("beams.0.lenght", "beams[0].lenght", "length"),
    ("beams.0.section.rh", "beams[0].section.rh", "rho"),
    ("beams.0.section.I_P", "beams[0].section.I_P", "I_p"),
    ("boundary.0.kin", "boundary[0].kin", "kind"),
    ("point_loads.0.forc", "point_loads[0].forc", "force"),
    ("initial.static_equilibrum", "initial.static_equilibrum", "static_equilibrium"),
])
def test_unknown_key_suggests(key, field, hint):
    msg = err({key: 1.0})
    assert_names(msg, field, "unknown key", f"did you mean {hint!r}?", "allowed:")


def test_unknown_key_without_close_match_lists_the_allowed_keys():
    msg = err({"solver.zzzzzz": 1.0})
    assert_names(msg, "solver.zzzzzz", "unknown key", "t_end", "rtol")
    assert "did you mean" not in msg


def test_unknown_key_in_a_scene_file(tmp_path):
    text = (tmp_path / "s.toml")
    src = shipped_scenes()[SCENE].read_text().replace("t_end = 8.0", "tend = 8.0")
    text.write_text(src)
    assert_names(err({}, scene=str(text)), "solver.tend", "did you mean 't_end'?")


# -- names ----------------------------------------------------------------------------------

def test_unknown_scene_name_suggests():
    msg = err({}, scene="beam_thru_sleeve")
    assert_names(msg, "'beam_thru_sleeve'", "not a shipped scene", "beam_through_sleeve",
                 "did you mean 'beam_through_sleeve'?")


def test_unknown_scene_path():
    msg = err({}, scene="/nonexistent/scene.toml")
    assert_names(msg, "/nonexistent/scene.toml", "nor an existing file")


def test_scene_path_that_is_a_folder(tmp_path):
    assert_names(err({}, scene=str(tmp_path)), str(tmp_path), "nor an existing file")


@pytest.mark.parametrize("content", [b"solver = [", "t_end = 1\n".encode() + b"\xff\xfe = 2"])
def test_invalid_toml_file(tmp_path, content):
    p = tmp_path / "bad.toml"
    p.write_bytes(content)
    assert_names(err({}, scene=str(p)), str(p), "invalid TOML")


def test_scene_from_a_file_path(tmp_path):
    p = tmp_path / "mine.toml"
    p.write_text(shipped_scenes()[SCENE].read_text().replace('name = "beam_through_sleeve"\n', ""))
    sc = load_scene(p, {"solver.t_end": 1.0})
    assert sc["name"] == "mine" and sc["source"] == str(p) and sc["solver"]["t_end"] == 1.0


@pytest.mark.parametrize("key, field", [("boundary.0.beam", "boundary[0].beam"),
                                        ("point_loads.0.beam", "point_loads[0].beam")])
def test_unknown_beam_name_suggests(key, field):
    msg = err({key: "rood"})
    assert_names(msg, field, "'rood'", "no such beam (rod)", "did you mean 'rod'?")


@pytest.mark.parametrize("key, value, shown", [
    ("boundary.0.position", [1.0, 0.0, 0.0], "[0, 0, 0] m"),
    ("boundary.0.direction", [0.0, 1.0, 0.0], "[1, 0, 0]"),
    ("boundary.0.end", "right", "[4, 0, 0] m"),
])
def test_boundary_held_where_the_straight_beam_has_its_end(key, value, shown):
    """The model starts straight and at rest: a boundary's position and direction are the
    straight beam's end and axis (the rod's left end s = 8 m sits at the origin, its right end
    s = 12 m at x = 4 m), else the first state would break the condition."""
    msg = err({key: value})
    field = key.replace("boundary.0", "boundary[0]")
    if key.endswith("end"):
        field = "boundary[0].position"
    assert_names(msg, field, "straight beam 'rod'", shown, "allowed")


def test_duplicate_beam_names():
    sc = load_scene(SCENE)
    raw_beam = {"name": "rod", "length": 12.0, "breakpoints": [8.0, 12.0],
                "section": {k: sc["beams"][0]["section"][k]
                            for k in ("E", "G", "rho", "A", "I_t", "I_b", "J")}}
    msg = err({"beams": [raw_beam, dict(raw_beam)]})
    assert_names(msg, "beams[1].name", "'rod'", "already used by beams[0]", "unique")


@pytest.mark.parametrize("key, field, hint", [("boundary.0.kind", "boundary[0].kind", "sleeve"),
                                              ("boundary.0.end", "boundary[0].end", "left")])
def test_bad_choice_suggests(key, field, hint):
    msg = err({key: hint[:-1]})
    assert_names(msg, field, repr(hint[:-1]), "allowed", f"did you mean {hint!r}?")


# -- boundary conditions --------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["clamped", "pinned", "roller", "free"])
def test_speed_on_a_non_sleeve_boundary(kind):
    msg = err({"boundary.0.kind": kind})       # the shipped boundary has speed = -0.5
    assert_names(msg, "boundary[0].speed", "= -0.5", "only a 'sleeve'", repr(kind))


def test_non_sleeve_boundary_without_speed_is_accepted():
    bc = {"beam": "rod", "end": "left", "kind": "clamped"}
    sc = load_scene(SCENE, {"boundary": [bc]})
    assert sc["boundary"][0]["kind"] == "clamped" and sc["boundary"][0]["speed"] == 0.0


def test_two_conditions_on_the_same_end():
    a = {"beam": "rod", "end": "left", "kind": "clamped"}
    b = {"beam": "rod", "end": "right", "kind": "pinned"}
    c = {"beam": "rod", "end": "left", "kind": "pinned"}
    msg = err({"boundary": [a, b, c]})
    assert_names(msg, "boundary[2].end", "'left'", "boundary[0]", "'rod'", "one condition per")


def test_conditions_on_both_ends_are_accepted():
    a = {"beam": "rod", "end": "left", "kind": "clamped"}
    b = {"beam": "rod", "end": "right", "kind": "pinned"}
    sc = load_scene(SCENE, {"boundary": [a, b]})
    assert [x["end"] for x in sc["boundary"]] == ["left", "right"]


# -- sleeve travel: the end may not run out of material nor collapse its element ------------

@pytest.mark.parametrize("speed", [-1.5, -1.0, 0.5, 0.6])
def test_left_sleeve_pushed_through_the_beam(speed):
    # s_1 = 8, t_end = 8, breakpoints[1] = 12: s_1 + v t_end in (0, 12) <=> v in (-1, 0.5)
    msg = err({"boundary.0.speed": speed})
    assert_names(msg, "boundary[0].speed", f"= {speed!r}", "(0, 12)", "allowed (-1, 0.5)")


@pytest.mark.parametrize("speed", [-0.99, 0.0, 0.49])
def test_left_sleeve_within_the_beam_is_accepted(speed):
    assert load_scene(SCENE, {"boundary.0.speed": speed})["boundary"][0]["speed"] == speed


def test_sleeve_range_depends_on_t_end():
    msg = err({"boundary.0.speed": -1.5, "solver.t_end": 16.0})
    assert_names(msg, "boundary[0].speed", "allowed (-0.5, 0.25)")
    assert load_scene(SCENE, {"boundary.0.speed": -1.5, "solver.t_end": 5.0})


def test_left_sleeve_with_inner_breakpoint():
    # breakpoints [8, 10, 12]: the sleeve end may move in (0, 10): v in (-1, 0.25) for t_end 8
    over = {"beams.0.breakpoints": [8.0, 10.0, 12.0], "boundary.0.speed": 0.3}
    assert_names(err(over), "boundary[0].speed", "(0, 10)", "allowed (-1, 0.25)")


RIGHT = {"beams.0.breakpoints": [0.0, 8.0], "beams.0.origin": [0.0, 0.0, 0.0],
         "boundary.0.end": "right", "boundary.0.position": [8.0, 0.0, 0.0],
         "point_loads.0.s": 4.0}


@pytest.mark.parametrize("speed", [0.5, 1.0, -1.0, -2.0])
def test_right_sleeve_pushed_through_the_beam(speed):
    # s_n = 8, t_end = 8, breakpoints[-2] = 0, L = 12: v in (-1, 0.5)
    msg = err({**RIGHT, "boundary.0.speed": speed})
    assert_names(msg, "boundary[0].speed", f"= {speed!r}", "(0, 12)", "allowed (-1, 0.5)")


def test_right_sleeve_within_the_beam_is_accepted():
    sc = load_scene(SCENE, {**RIGHT, "boundary.0.speed": 0.25})
    assert sc["boundary"][0]["end"] == "right"


def test_two_sleeves_on_one_element_must_not_collapse_it():
    left = {"beam": "rod", "end": "left", "kind": "sleeve", "speed": 0.5}
    right = {"beam": "rod", "end": "right", "kind": "sleeve", "speed": -0.4}
    over = {"beams.0.breakpoints": [2.0, 10.0], "beams.0.origin": [-2.0, 0.0, 0.0],
            "point_loads": [], "boundary": [left, right]}
    # s_1(8) = 6, s_n(8) = 6.8 -> fine; faster left sleeve collapses the element
    assert load_scene(SCENE, over)
    left["speed"] = 0.6                      # s_1(8) = 6.8 = s_n(8)
    assert_names(err(over), "boundary[0].speed", "= 0.6", "allowed (-0.25, 0.6)")


# -- point loads ----------------------------------------------------------------------------

@pytest.mark.parametrize("s", [-0.1, 12.5])
def test_point_load_outside_the_beam(s):
    assert_names(err({"point_loads.0.s": s}), "point_loads[0].s", f"= {s!r}", "[0, 12]")


def test_point_load_behind_the_sleeve_is_refused():
    # material s < 8 is inside the sleeve at t = 0 and not modelled
    msg = err({"point_loads.0.s": 5.0})
    assert_names(msg, "point_loads[0].s", "= 5.0", "modelled part", "[8, 12]")


def test_moving_point_load_leaving_the_beam():
    # s = 10, t_end = 8: s + v t_end in [0, 12] <=> v in [-1.25, 0.25]
    msg = err({"point_loads.0.s": 10.0, "point_loads.0.speed": 0.5})
    assert_names(msg, "point_loads[0].speed", "= 0.5", "[0, 12]", "allowed [-1.25, 0.25]")


def test_moving_point_load_entering_the_sleeve():
    # modelled part at t_end = 8 is [4, 12]: v in [-0.75, 0.25]
    msg = err({"point_loads.0.s": 10.0, "point_loads.0.speed": -1.0})
    assert_names(msg, "point_loads[0].speed", "= -1.0", "[4, 12]", "allowed [-0.75, 0.25]")


@pytest.mark.parametrize("speed", [-0.75, 0.0, 0.25])
def test_moving_point_load_on_the_beam_is_accepted(speed):
    sc = load_scene(SCENE, {"point_loads.0.s": 10.0, "point_loads.0.speed": speed})
    assert sc["point_loads"][0]["speed"] == speed


def test_point_load_start_negative():
    assert_names(err({"point_loads.0.start": -1.0}), "point_loads[0].start", "[0, 3600] s")


# -- tables of the wrong type ---------------------------------------------------------------

@pytest.mark.parametrize("key, value, field", [
    ("solver", 5, "solver"), ("effects", [1], "effects"), ("beams.0.section", 1.0, "beams[0].section"),
    ("boundary", {"beam": "rod"}, "boundary"), ("point_loads", [1, 2], "point_loads"),
    ("beams", [], "beams"), ("beams", "rod", "beams"), ("beams", [3], "beams"),
])
def test_table_of_the_wrong_type(key, value, field):
    assert_names(err({key: value}), field, repr(value))


def test_validate_rejects_a_non_table():
    with pytest.raises(SceneError, match="must be a table"):
        validate([1, 2])


# -- overrides ------------------------------------------------------------------------------

@pytest.mark.parametrize("key, part, rng", [
    ("beams.3.n_nodes", "'3'", "(0..0)"),
    ("beams.x.n_nodes", "'x'", "(0..0)"),
    ("beams.-1.n_nodes", "'-1'", "(0..0)"),
    ("beams.1", "'1'", "(0..0)"),
    ("beams.name", "'name'", "(0..0)"),
    ("gravity.g.3", "'3'", "(0..2)"),
    ("boundary.1.speed", "'1'", "(0..0)"),
])
def test_bad_override_index(key, part, rng):
    msg = err({key: 1.0})
    assert_names(msg, f"override {key!r}", part, "not a valid index", rng)


@pytest.mark.parametrize("key", ["solver.t_end.x", "name.x", "gravity.g.0.x"])
def test_override_inside_a_value(key):
    msg = err({key: 1.0})
    assert_names(msg, f"override {key!r}", "not a table or list")


@pytest.mark.parametrize("key", ["", "solver.", ".t_end", "solver..t_end"])
def test_override_with_an_empty_key_part(key):
    assert_names(err({key: 1.0}), f"override {key!r}", "empty key part")


def test_override_of_a_misspelt_key_reaches_validation():
    assert_names(err({"solver.tend": "0.5"}), "solver.tend", "did you mean 't_end'?")


def test_override_values_are_parsed_as_toml():
    sc = load_scene(SCENE, {"solver.t_end": "0.5", "effects.gravity": "false",
                            "gravity.g": "[0, 0, -1.62]", "beams.0.n_nodes": "5",
                            "effects.torsion": "true", "description": "a test run",
                            "point_loads.0.force.2": "-1e3", "beams.0.section.E": "2.0e11"})
    assert sc["solver"]["t_end"] == 0.5
    assert sc["effects"]["gravity"] is False and sc["effects"]["torsion"] is True
    assert sc["gravity"]["g"] == [0.0, 0.0, -1.62]
    assert sc["beams"][0]["n_nodes"] == 5
    assert sc["description"] == "a test run"
    assert sc["point_loads"][0]["force"] == [0.0, 0.0, -1000.0]
    assert sc["beams"][0]["section"]["E"] == 2.0e11


def test_parse_value():
    assert parse_value("0.5") == 0.5
    assert parse_value("4") == 4 and isinstance(parse_value("4"), int)
    assert parse_value("false") is False
    assert parse_value('"false"') == "false"
    assert parse_value("[1, 2.5]") == [1, 2.5]
    assert math.isnan(parse_value("nan")) and parse_value("-inf") == -math.inf
    assert parse_value("hello world") == "hello world"


def test_override_value_of_the_wrong_type_names_the_field():
    assert_names(err({"effects.gravity": "no"}), "effects.gravity", "'no'", "true or false")


# -- fuzz: any value anywhere gives a resolved scene or a SceneError, never another error -----

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

FUZZ_KEYS = [k for k, _, _ in NUMBER_FIELDS] + [k for k, _, _ in VECTOR_FIELDS] + [
    "name", "description", "solver", "solver.method", "effects.torsion", "effects", "filtering",
    "gravity", "beams", "beams.0", "beams.0.name", "beams.0.breakpoints", "beams.0.section",
    "beams.0.section.rotary_bending", "boundary", "boundary.0", "boundary.0.beam",
    "boundary.0.end", "boundary.0.kind", "point_loads", "point_loads.0", "initial",
    "initial.static_equilibrium", "gravity.g.1", "beams.0.breakpoints.0", "notes"]

VALUES = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6), st.floats(),
              st.text(max_size=6), st.sampled_from(["nan", "inf", "rod", "left", "sleeve", "[]"])),
    lambda inner: st.one_of(st.lists(inner, max_size=4),
                            st.dictionaries(st.sampled_from(["beam", "end", "kind", "speed", "s",
                                                             "force", "E", "x"]), inner, max_size=3)),
    max_leaves=6)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.dictionaries(st.sampled_from(FUZZ_KEYS), VALUES, min_size=1, max_size=3))
def test_fuzzed_overrides_give_a_scene_or_a_scene_error(overrides):
    overrides = {k: v for k, v in overrides.items() if v is not None}
    try:
        sc = load_scene(SCENE, overrides)
    except SceneError as exc:
        assert str(exc) and "\n" not in str(exc)
        return
    # a resolved scene holds only finite numbers
    def walk(x):
        if isinstance(x, dict):
            for v in x.values():
                walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)
        elif isinstance(x, float):
            assert math.isfinite(x)
    walk(sc)


@pytest.mark.parametrize("key", ["name", "description"])
def test_name_and_description_are_strings(key):
    assert_names(err({key: 5}), f"scene.{key}", "= 5", "string")


# -- the declared fields: complete, checked by the validators, rendered cleanly ---------------

from sim_core.scene.fields import COMPUTED, OPTIONAL, REQUIRED  # noqa: E402
from sim_core.systems.beam.schema import SCHEMA as BEAM_SCHEMA  # noqa: E402
from sim_core.systems.folding.schema import SCHEMA as FOLDING_SCHEMA  # noqa: E402
from sim_core.systems.telescopic.schema import SCHEMA as TELESCOPIC_SCHEMA  # noqa: E402

SCHEMAS = {"beam": BEAM_SCHEMA, "telescopic": TELESCOPIC_SCHEMA, "folding": FOLDING_SCHEMA}
UNITS = {"", "s", "m", "m/s", "m/s^2", "m/s^3", "deg", "deg/s", "deg/s^2", "deg/s^3", "Pa",
         "kg", "kg/m", "kg/m^3", "m^2", "m^4", "N", "N/m", "N s/m", "N m/rad"}
DECLARED = [(kind, table, f) for kind, s in SCHEMAS.items() for table in s.tables
            for f in table.fields]


def _ids(item):
    kind, table, f = item
    return f"{kind}:{table.path}.{f.key}" if table.path else f"{kind}:{f.key}"


@pytest.mark.parametrize("kind, table, f", DECLARED, ids=[_ids(d) for d in DECLARED])
def test_every_declared_key_has_a_type_unit_range_and_default(kind, table, f):
    """Every key: an SI unit from the list (or none), a bounded range for every number (a
    literal default inside it), a default that is a value, required, optional or computed
    (said in words)."""
    assert f.unit in UNITS, f.unit
    assert f.range_text() and "inf" not in f.range_text()
    if f.type in ("number", "integer", "vector", "numbers"):
        assert math.isfinite(f.lo) and math.isfinite(f.hi) and f.lo < f.hi
    if f.type == "rows":
        assert all(math.isfinite(lo) and math.isfinite(hi) and lo < hi for lo, hi, _ in f.columns)
    if f.default is COMPUTED:
        assert f.default_text
    elif f.default not in (REQUIRED, OPTIONAL):
        d = f.default
        if f.type in ("number", "integer"):
            assert f.bounds()[0] <= d <= f.bounds()[1]
        elif f.type in ("vector", "numbers"):
            assert all(f.lo <= x <= f.hi for x in d)
        elif f.type == "choice":
            assert d in f.choices
        elif f.type == "boolean":
            assert isinstance(d, bool)


# where each declared table is read: (scene, overrides)
U_SECTION = {"shape": "u", "top_arc_centre_y": 0.2, "top_arc_centre_z": 0.1,
             "top_arc_radius": 0.1, "wall": 0.01}
BOX_SECTION = {"shape": "box", "width": 0.8, "height": 0.8, "wall": 0.01, "corner_radius": 0.05}
PROPS_SECTION = {"shape": "properties", "A": 0.02, "I_t": 2e-3, "I_b": 2e-3, "J": 3e-3,
                 "mass_per_length": 170.0}
CONTEXTS = {
    "beam": [("beam_through_sleeve", {}),
             ("beam_through_sleeve", {"boundary.0.profile": "cubic", "boundary.0.speed": -0.1}),
             ("cantilever_release", {}),
             ("beam_through_sleeve", {"solver.method": "generalized_alpha"})],
    "telescopic": [
        ("telescopic_extraction", {}),
        ("telescopic_extraction", {"drive.profile": "trapezoid", "drive.travel": 3.0,
                                   "drive.a_max": 0.5}),
        ("telescopic_extraction", {"effects.wind": True}),
        ("crane_lift_and_slew", {}),
        ("crane_lift_and_slew", {"hoist_drive": {"profile": "trapezoid", "travel": -1.0,
                                                 "v_max": 0.5, "a_max": 0.5}}),
        ("crane_lift_and_slew", {"luffing_drive": {"profile": "trapezoid", "travel": 10.0,
                                                   "v_max": 2.0, "a_max": 1.0}}),
        ("crane_lift_and_slew", {"slew_drive": {"profile": "cubic", "travel": 10.0,
                                                "t_hold_end": 20.0}}),
        ("crane_lift_and_slew", {"hoist_drive": {"profile": "cubic", "travel": -1.0,
                                                 "t_hold_end": 20.0}}),
        ("crane_hexagonal_4", {}),
        ("crane_hexagonal_4", {"boom.0": {"length": 12.0, "section": {
            "shape": "polygon", "n_sides": 6, "width_across_flats": 0.8, "wall": 0.008}}}),
        ("crane_hexagonal_4", {"boom.0.section": U_SECTION}),
        ("crane_hexagonal_4", {"boom.0.section": BOX_SECTION}),
        ("crane_hexagonal_4", {"boom.0.section": {"shape": "polygon", "circumradius": 0.45,
                                                  "n_sides": 6, "wall": 0.008}}),
        ("crane_hexagonal_4", {"boom.0.section": {
            "shape": "polygon", "wall": 0.008,
            "contour": [[0.45, -0.45], [0.45, 0.45], [-0.45, 0.45], [-0.45, -0.45]]}}),
        ("crane_hexagonal_4", {"boom.0.section": PROPS_SECTION,
                               "effects.contact_distribution": False}),
        ("telescopic_extraction_rl", {}),
        ("telescopic_extraction", {"effects.oil_column": True}),
        ("telescopic_extraction", {"solver.method": "ROS2"}),
        ("crane_lift_off", {}),
        ("crane_telescoping_stages", {}),
        ("crane_telescoping_stages", {"stage_drive.0": {"profile": "cubic", "travel": 1.0,
                                                        "t_ramp": 2.0, "t_hold_end": 8.0,
                                                        "t_start": 0.0}}),
        ("crane_telescoping_stages", {"stage_drive.0": {"profile": "trapezoid", "travel": 1.0,
                                                        "v_max": 0.5, "a_max": 0.3,
                                                        "j_max": 1.0, "t_start": 0.0}}),
        ("crane_telescoping_sequence", {}),
        ("crane_telescoping_sequence", {"telescoping.profile": "trapezoid",
                                        "telescoping.a_max": 0.5, "telescoping.j_max": 2.0}),
    ],
    "folding": [("folding_boom", {})],
}


def _display(path: str, key: str) -> str:
    base = path.replace("[]", "[0]")
    return f"{base}.{key}" if base else key


def _override_key(path: str, key: str) -> str:
    base = path.replace("[]", ".0")
    return f"{base}.{key}" if base else key


def _too_large(f):
    if f.type == "vector":
        return [f.hi * 10 + 1.0] * f.n
    if f.type == "numbers":
        return [f.hi * 10 + 1.0 + j for j in range(f.items[0])]
    return int(f.hi * 10 + 1) if f.type == "integer" else f.hi * 10 + 1.0


NUMERIC = [d for d in DECLARED if d[2].type in ("number", "integer", "vector", "numbers")]


@pytest.mark.parametrize("kind, table, f", NUMERIC, ids=[_ids(d) for d in NUMERIC])
def test_every_declared_range_is_what_the_validator_checks(kind, table, f):
    """A value ten times the declared upper bound is refused, in a scene that reads the key,
    with an error naming the field and "out of range" (the declared range, or one narrowed by
    other keys); the declaration and the check are one."""
    key, shown = _override_key(table.path, f.key), _display(table.path, f.key)
    messages = []
    for scene, over in CONTEXTS[kind]:
        try:
            load_scene(scene, {**copy.deepcopy(over), key: _too_large(f)})
        except SceneError as exc:
            msg = str(exc)
            messages.append(msg)
            if msg.startswith(shown) and "out of range" in msg:
                if f.allowed == "" and f.type in ("number", "integer"):
                    assert f.range_text() in msg, msg
                return
    pytest.fail(f"{shown}: no context refused {_too_large(f)!r} naming the field: {messages}")


def _unknown_key_list(scene: str, over: dict, key: str) -> set[str]:
    msg = err({**copy.deepcopy(over), key: 1.0}, scene)
    assert "unknown key (allowed: " in msg, msg
    return set(msg.split("(allowed: ")[1].split(")")[0].split(", "))


@pytest.mark.parametrize("kind", SCHEMAS)
def test_the_validators_accept_exactly_the_declared_keys(kind):
    """The keys an unknown-key error lists for every table are the declared ones (the
    section's per shape, the profiles' all together)."""
    schema = SCHEMAS[kind]
    from sim_core.physics.plugins import effect_plugins
    plugins = set(effect_plugins()) if kind == "telescopic" else set()
    for table in schema.tables:
        want = table.all_keys() | (plugins if table.path in ("", "effects") else set())
        tag = None
        if table.path == "boom[].section":
            tag = "polygon"
            want = table.keys("polygon")
        key = _override_key(table.path, "zz_unknown")
        for scene, over in CONTEXTS[kind]:
            try:
                got = _unknown_key_list(scene, over, key)
            except (AssertionError, pytest.fail.Exception):
                continue
            assert got == want, (table.path, tag, got ^ want)
            break
        else:
            pytest.fail(f"{table.path}: no context reads the table")


def _reference_page() -> str:
    import importlib.util
    path = Path(__file__).resolve().parents[2] / "docs" / "hooks" / "scene_reference.py"
    spec = importlib.util.spec_from_file_location("scene_reference_hook", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.scene_reference()


def test_the_scene_reference_is_rendered_from_the_declarations_without_debris():
    """The generated page lists every declared key of every kind in a six-column row with its
    type, no source code (``out.``, ``sc[``, ``len(``, conditional expressions, constant
    names), no empty cells where a type or range belongs, the generalized-alpha keys only for
    the beam scenes (the only kind that takes the method)."""
    page = _reference_page()
    sections = page.split("\n## ")
    assert len(sections) == 3
    for debris in (r"\bout\.", r"\bsc\[", r"\bsc\.", r"len\(", r" if .* else ", r"\bMAX_",
                   r"self\.", r"`three`", r"\| methods \|", "…", r"h_lo", r"\blo_open\b"):
        assert not re.search(debris, page), debris
    for section, (kind, schema) in zip(sections, SCHEMAS.items()):
        rows = [ln for ln in section.splitlines() if ln.startswith("| `")]
        keys = {ln.split("`")[1] for ln in rows}
        for table in schema.tables:
            for f in table.fields:
                assert _override_key(table.path, f.key) in keys, (kind, table.path, f.key)
        for ln in rows:
            cells = re.split(r"(?<!\\)\|", ln)[1:-1]
            if len(cells) == 6:
                key, typ, unit, default, allowed, note = (c.strip() for c in cells)
                assert typ != "–" and default and allowed and allowed != "–", ln
        alpha = {"solver.h", "solver.h_max", "solver.rho_inf", "solver.newton_atol"}
        assert (alpha <= keys) == (kind == "beam"), kind
        assert "### Rules across keys" in section and "### Shipped scenes of this kind" in section
