"""Bad input on the scene API: ``load_scene(name, overrides)`` and the command line's ``--set``.

Whatever the caller passes -- overrides that are not a mapping, keys that are not strings,
values of any Python type (None, lists, tables, bytes, complex numbers, booleans where
numbers go, integers beyond a float's range or past Python's digit limit for printing, NaN
and inf written as text), scene names that are neither a name nor a path -- ``load_scene``
ends in a :class:`sim_core.SceneError` of one line that names the offending field or key,
never in another exception.  A number beyond a float's range names its field and the field's
allowed range.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

from sim_core import SceneError, load_scene
from sim_core import cli
from sim_core.scene.io import shipped_scenes

HUGE = 10 ** 400                      # beyond a float (1.8e308): float(HUGE) overflows
PAST_DIGITS = 10 ** 5000              # past Python's 4300-digit limit for str(int)


def _one_line(exc: pytest.ExceptionInfo) -> str:
    msg = str(exc.value)
    assert msg and "\n" not in msg
    return msg


@pytest.mark.parametrize("overrides", [["solver.t_end=1"], "solver.t_end=1",
                                       (("solver.t_end", 1),), 5, {"solver.t_end"}])
def test_overrides_that_are_not_a_mapping(overrides):
    with pytest.raises(SceneError) as info:
        load_scene("cantilever_release", overrides)
    msg = _one_line(info)
    assert msg.startswith("overrides = ") and "mapping of dotted keys to values" in msg


@pytest.mark.parametrize("overrides", [[], ""])
def test_empty_overrides_of_the_wrong_type_are_refused_too(overrides):
    """An empty list or string is not an empty mapping: refused, not silently ignored."""
    with pytest.raises(SceneError, match="mapping of dotted keys"):
        load_scene("cantilever_release", overrides)


@pytest.mark.parametrize("key", [None, 5, 1.5, b"solver.t_end", ("solver", "t_end")])
def test_override_keys_must_be_strings(key):
    with pytest.raises(SceneError) as info:
        load_scene("cantilever_release", {key: 1.0})
    msg = _one_line(info)
    assert msg.startswith("override ") and "must be a dotted string" in msg


@pytest.mark.parametrize("scene, key, range_text", [
    ("cantilever_release", "solver.t_end", "allowed [1e-06, 3600] s"),
    ("cantilever_release", "beams.0.section.E", "allowed [1e+08, 1e+15] Pa"),
    ("cantilever_release", "beams.0.n_nodes", "allowed [3, 65]"),
    ("telescopic_extraction", "payload.mass", "allowed ["),
    ("crane_hexagonal_4", "boom.1.length", "allowed ["),
    ("folding_boom", "solver.t_end", "allowed ["),
])
@pytest.mark.parametrize("value", [HUGE, -HUGE, str(HUGE)], ids=["int", "negative", "text"])
def test_a_number_beyond_a_float_names_its_field_and_range(scene, key, range_text, value):
    """10**400 (or its numeral as text, as ``--set`` passes it): float() would overflow; the
    error names the field and its allowed range."""
    with pytest.raises(SceneError) as info:
        load_scene(scene, {key: value})
    msg = _one_line(info)
    assert key.replace(".0.", ".").split(".")[-1] in msg, msg
    assert "out of range" in msg and range_text in msg, msg
    assert len(msg) < 400, msg                      # the 401-digit value is cut


@pytest.mark.parametrize("value", [PAST_DIGITS, [1.0, PAST_DIGITS, 0.0], {"x": PAST_DIGITS},
                                   "1" * 5000], ids=["int", "in-list", "in-table", "text"])
@pytest.mark.parametrize("key", ["solver.t_end", "gravity.g", "kind", "name"])
def test_integers_past_the_digit_limit(key, value):
    """Integers too long to print (str() raises ValueError past 4300 digits): the override is
    refused naming its key (or, as text no TOML reader takes, refused as a string where a
    number goes, or taken as the name it may be)."""
    try:
        sc = load_scene("cantilever_release", {key: value})
    except SceneError as exc:
        msg = str(exc)
        assert msg and "\n" not in msg, msg
        assert isinstance(value, str) or len(msg) < 600, msg
        assert key in msg or key.split(".")[0] in msg, msg
    else:
        assert key == "name" and sc["name"] == value


ODD = [None, [], {}, b"1", bytearray(b"1"), 1 + 2j, object(), True, False, [1.0, None],
       {"a": 1}, "nan", "inf", "-inf", "1e400", math.nan, math.inf, [HUGE], [[HUGE, 1.0]],
       "[1e400]", "x" * 100]
ODD_KEYS = {
    "cantilever_release": ["solver.t_end", "solver.n_output", "solver.h", "beams.0.n_nodes",
                           "beams.0.section.E", "gravity.g", "beams.0.breakpoints",
                           "solver.method", "boundary.0.kind", "effects.gravity"],
    "crane_lift_and_slew": ["boom.0.length", "overlap.0.radial_gap", "luffing.pivot",
                            "hoist_drive.table", "slew_drive.travel", "booms.n_nodes"],
    "folding_boom": ["solver.t_end"],
}


@pytest.mark.parametrize("scene, key", [(s, k) for s, ks in ODD_KEYS.items() for k in ks])
def test_odd_types_end_in_a_scene_error_or_a_valid_scene(scene, key):
    """Every odd value on a declared key: a one-line SceneError naming the key's table, or a
    valid scene (a boolean where a boolean goes, a name that is any string)."""
    for value in ODD:
        try:
            load_scene(scene, {key: value})
        except SceneError as exc:
            msg = str(exc)
            assert msg and "\n" not in msg, (key, value, msg)
            assert key.split(".")[0] in msg, (key, value, msg)


@pytest.mark.parametrize("name", [None, 5, b"cantilever_release", ["cantilever_release"]])
def test_scene_names_that_are_neither_a_name_nor_a_path(name):
    with pytest.raises(SceneError) as info:
        load_scene(name)
    assert _one_line(info).startswith("scene = ")


def test_a_scene_file_with_an_integer_past_the_digit_limit(tmp_path):
    path = tmp_path / "huge.toml"
    path.write_text(Path(shipped_scenes()["cantilever_release"]).read_text()
                    .replace("t_end = 2.0", "t_end = " + "1" * 5000, 1))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(path) in _one_line(info)


@pytest.mark.parametrize("setting", ["solver.t_end=" + str(HUGE), "solver.t_end=" + "1" * 5000,
                                     "solver.t_end=nan", "gravity.g=[0, 0, 1e400]"],
                         ids=["huge", "past-digits", "nan", "inf-in-vector"])
def test_cli_set_of_odd_values_exits_2_with_one_line(setting, tmp_path, capsys):
    """``boom-sim describe SCENE --set KEY=VALUE``: status 2 and one line naming the key."""
    assert cli.main(["describe", "cantilever_release", "--set", setting]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert setting.split("=")[0] in err[0] or "solver" in err[0], err


def test_the_digit_limit_is_pythons():
    """The tests above rely on str(int) refusing 5000 digits (Python >= 3.11 default)."""
    if not hasattr(sys, "get_int_max_str_digits") or sys.get_int_max_str_digits() == 0:
        pytest.skip("no digit limit for str(int) here")
    with pytest.raises(ValueError):
        str(PAST_DIGITS)
