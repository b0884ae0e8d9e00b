"""Scene validation: every bad value is refused with a SceneError whose message names the dotted
field, the value and the allowed range; unknown keys and names get a "did you mean" hint.

Validation only (no model is built), so these tests are fast.
"""

from __future__ import annotations

import math

import pytest

from sim_core import load_scene
from sim_core.errors import SceneError
from sim_core.scene.io import apply_overrides, parse_value, shipped_scenes
from sim_core.systems.beam.schema import validate

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


# -- non-positive material and geometry values ----------------------------------------------

@pytest.mark.parametrize("key", ["E", "G", "rho", "A", "I_t", "I_b", "J", "I_p"])
@pytest.mark.parametrize("value", [0.0, -1.0])
def test_non_positive_section_value(key, value):
    msg = err({f"beams.0.section.{key}": value})
    assert_names(msg, f"beams[0].section.{key}", f"= {value!r}", "(0, inf)")


@pytest.mark.parametrize("value", [0.0, -12.0])
def test_non_positive_length(value):
    assert_names(err({"beams.0.length": value}), "beams[0].length", f"= {value!r}", "(0, inf)")


def test_missing_required_value_names_the_range():
    msg = err({"beams.0.section": {"E": 1.0, "G": 1.0, "rho": 1.0, "A": 1.0, "I_t": 1.0,
                                   "I_b": 1.0}})
    assert_names(msg, "beams[0].section.J", "missing", "(0, inf)")


# -- NaN and inf anywhere -------------------------------------------------------------------

NUMBER_FIELDS = [
    ("solver.t_end", "solver.t_end", "(0, inf)"),
    ("solver.rtol", "solver.rtol", "(0, 1)"),
    ("solver.atol", "solver.atol", "(0, inf)"),
    ("solver.max_step", "solver.max_step", "(0, inf)"),
    ("solver.n_output", "solver.n_output", "[2, inf)"),
    ("filtering.h", "filtering.h", "(0, inf)"),
    ("beams.0.length", "beams[0].length", "(0, inf)"),
    ("beams.0.n_nodes", "beams[0].n_nodes", "[3, 65]"),
    ("beams.0.n_gauss", "beams[0].n_gauss", "[1, 10]"),
    ("beams.0.section.E", "beams[0].section.E", "(0, inf)"),
    ("beams.0.section.J", "beams[0].section.J", "(0, inf)"),
    ("boundary.0.speed", "boundary[0].speed", "(-inf, inf)"),
    ("point_loads.0.s", "point_loads[0].s", "[0, 12]"),
    ("point_loads.0.speed", "point_loads[0].speed", "(-inf, inf)"),
    ("point_loads.0.start", "point_loads[0].start", "[0, inf)"),
]


@pytest.mark.parametrize("text", ["nan", "inf", "-inf"])
@pytest.mark.parametrize("key, field, rng", NUMBER_FIELDS)
def test_non_finite_number(key, field, rng, text):
    msg = err({key: text})             # a string value is parsed as TOML: nan, inf, -inf
    assert_names(msg, field, f"= {parse_value(text)!r}", "finite", rng)


VECTOR_FIELDS = [
    ("gravity.g", "gravity.g"),
    ("beams.0.origin", "beams[0].origin"),
    ("beams.0.direction", "beams[0].direction"),
    ("boundary.0.position", "boundary[0].position"),
    ("boundary.0.direction", "boundary[0].direction"),
    ("point_loads.0.force", "point_loads[0].force"),
]


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("key, field", VECTOR_FIELDS)
@pytest.mark.parametrize("j", [0, 2])
def test_non_finite_vector_component(key, field, j, bad):
    vec = [1.0, 0.0, 0.0]
    vec[j] = bad
    msg = err({key: vec})
    assert_names(msg, f"{field}[{j}]", f"= {bad!r}", "finite", "(-inf, inf)")


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


@pytest.mark.parametrize("bps", [[-1.0, 12.0], [8.0, 12.5], [-0.5, 13.0]])
def test_breakpoints_outside_the_beam(bps):
    msg = err({"beams.0.breakpoints": bps})
    assert_names(msg, "beams[0].breakpoints", repr(bps), "[0, 12]")


@pytest.mark.parametrize("bps", [[8.0], [], 8.0, ["a", 12.0], [True, 12.0]])
def test_breakpoints_malformed(bps):
    msg = err({"beams.0.breakpoints": bps})
    assert_names(msg, "beams[0].breakpoints", repr(bps), ">= 2 finite numbers", "[0, 12]")


def test_breakpoints_range_follows_the_length():
    msg = err({"beams.0.length": 10.0})            # shipped breakpoints end at 12
    assert_names(msg, "beams[0].breakpoints", "[8.0, 12.0]", "[0, 10]")


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

@pytest.mark.parametrize("value", [0.0, 1.0, 1.5, -1e-3])
def test_rtol_outside_open_unit_interval(value):
    assert_names(err({"solver.rtol": value}), "solver.rtol", f"= {value!r}", "(0, 1)")


@pytest.mark.parametrize("value", [0.0, -1.0])
def test_t_end_not_positive(value):
    assert_names(err({"solver.t_end": value}), "solver.t_end", f"= {value!r}", "(0, inf)")


def test_t_end_missing():
    raw_solver = {"rtol": 1e-6}
    assert_names(err({"solver": raw_solver}), "solver.t_end", "missing", "(0, inf)")


def test_t_end_not_a_number():
    assert_names(err({"solver.t_end": "soon"}), "solver.t_end", "'soon'", "number", "(0, inf)")


def test_unknown_method_suggests():
    assert_names(err({"solver.method": "rk45"}), "solver.method", "'rk45'", "RK45",
                 "did you mean 'RK45'")


@pytest.mark.parametrize("scene", ["beam_through_sleeve", "telescopic_extraction", "folding_boom"])
def test_one_solver_table_for_every_scene_kind(scene):
    """The [solver] table is validated by one function (sim_core.scene.fields.solver_table) for all
    scene kinds: the same methods are accepted, the same errors name the field and range."""
    for method in ("RK45", "BDF", "auto"):
        assert load_scene(scene, overrides={"solver.method": method})["solver"]["method"] == method
    assert_names(err({"solver.method": "Radau"}, scene), "solver.method", "'Radau'",
                 "RK45", "BDF", "auto")
    assert_names(err({"solver.max_step": 0}, scene), "solver.max_step", "(0, inf)")
    assert_names(err({"solver.max_wall_s": -1}, scene), "solver.max_wall_s", "(0, inf)")
    assert_names(err({"solver.rtol": 1.0}, scene), "solver.rtol", "(0, 1)")


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
         "boundary.0.end": "right", "point_loads.0.s": 4.0}


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
    assert_names(err({"point_loads.0.start": -1.0}), "point_loads[0].start", "[0, inf)")


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

FUZZ_KEYS = [k for k, _, _ in NUMBER_FIELDS] + [k for k, _ in VECTOR_FIELDS] + [
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
