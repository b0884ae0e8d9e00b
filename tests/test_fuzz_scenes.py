"""Fuzzed scenes: random overrides of every declared key of every scene kind, applied to shipped
scenes through ``sim_core.load_scene(name, overrides=...)`` and, for the cheap scenes,
``sim_core.simulate``.

Every key comes from the declarations the validators check with (``SCHEMA`` of
``sim_core.systems.{beam,telescopic,folding}.schema`` and the effect plug-ins' tables), so a
key added to a kind is fuzzed without touching this file.  The values: inside the declared
range and on its ends, just outside it and far outside, wrong types (booleans, strings, TOML
text, nested tables), NaN and inf, empty and huge (1e5 items) arrays; one to three keys per
example.  Each example must end in exactly one of

* a :class:`sim_core.Result` whose outputs are finite, or that its own checks flag
  (``Result.suspect``);
* a :class:`sim_core.SceneError` of one line that names a field of the scene;
* a typed :class:`sim_core.SimulationError` (subclasses included) with a finite time.

Anything else (another exception, a NaN in an unflagged result, a run past its wall budget) is
a failure.

What is simulated and what is validate-only: every example is validated.  One in three of
the examples on the cheap scenes is also run (about one in six of all): the beam scenes
``beam_through_sleeve`` (5 nodes per element, no static equilibrium unless drawn) and
``cantilever_release``, the modal ROM ``telescopic_extraction_rl`` and the rigid limit of
``telescopic_extraction`` (``effects.flexible = false``); each with a short ``solver.t_end``
(at most 0.02 s for the beams, 0.5 s otherwise), at most 50 outputs (evaluated after the
integration, outside its budget) and the wall budget ``solver.max_wall_s = 1 s`` (all clamped
after the drawn overrides), whose use the test checks (the integration's wall time stays
within the budget plus 2 s).  Beam scenes of more than 33 nodes in all are validated only: the
budget is served between steps, and one step of a large beam on the numpy path (its tangent)
takes seconds.  The flexible telescopic scenes (``telescopic_extraction``,
``crane_hexagonal_4``, ``crane_lift_and_slew``) and the folding manipulator are validate-only:
a run of theirs takes seconds to minutes.  ``test_wall_budget_is_honoured_on_every_path`` runs
each integration path once with a run that would take minutes to hours and a 0.5 s budget.

Every shipped scene (``sim_core/scenes/*.toml``, the crane scenes included) is also drawn
with two or three keys at once (``test_shipped_scenes_with_two_or_three_keys_*``): mostly keys
of its arrays of tables (``boom.2.length``, ``overlap.1.radial_gap``: an index the scene has),
its ``[luffing]``, drive and effect plug-in tables (``[wind]``, ``[oil_column]``, switched on),
and drive tables replaced by rows inline or by a CSV file written next to a copy of the scene.
Each valid example runs (``solver.t_end`` at most ``RUN_T_END``, ``solver.max_wall_s =
RUN_BUDGET``) and must end -- a SceneError, a typed SimulationError or a result with finite
outputs -- within ``RUN_BUDGET + RUN_MARGIN`` of wall time in all.  The default run draws 30
examples, the slow one 300.

The default run draws 800 examples from a fixed seed (``FUZZ_SEED`` in the environment
replaces it, so a failure reproduces with the seed printed in the summary); the slow test draws
5000.  The summary line (seed and the count of each outcome) is written to the terminal at the
end of the module, with or without ``-s``.
"""

from __future__ import annotations

import collections
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

import sim_core
from sim_core.errors import SceneError, SimulationError
from sim_core.scene.fields import Field, Schema
from sim_core.scene.io import shipped_scenes
from sim_core.systems.beam.schema import SCHEMA as BEAM
from sim_core.systems.folding.schema import SCHEMA as FOLDING
from sim_core.systems.telescopic.schema import SCHEMA as TELESCOPIC

ROOT = Path(__file__).resolve().parents[1]
SEED = int(os.environ.get("FUZZ_SEED", "43044"))
BUDGET = 1.0                 # s: solver.max_wall_s of every run
STEP_SLACK = 2.0             # s: the budget is checked between steps (or compiled calls)

# scene -> (kind's schema, overrides that make a run cheap, largest t_end of a run); None:
# validate-only
SCENES = {
    "beam_through_sleeve": (BEAM, {"beams.0.n_nodes": 5, "initial.static_equilibrium": False,
                                   "solver.t_end": 0.01, "solver.n_output": 3}, 0.02),
    "cantilever_release": (BEAM, {"solver.t_end": 0.01, "solver.n_output": 3}, 0.02),
    "telescopic_extraction_rl": (TELESCOPIC, {"solver.t_end": 0.5, "solver.n_output": 6}, 0.5),
    "telescopic_extraction": (TELESCOPIC, None, None),
    "rigid": (TELESCOPIC, {"effects.flexible": False, "effects.friction": False,
                           "solver.t_end": 0.5, "solver.n_output": 6}, 0.5),
    "crane_hexagonal_4": (TELESCOPIC, None, None),
    "crane_lift_and_slew": (TELESCOPIC, None, None),
    "folding_boom": (FOLDING, None, None),
}
SHIPPED = {"rigid": "telescopic_extraction"}


def declared_keys(schema: Schema) -> list[tuple[str, Field]]:
    """(dotted override key, declaration) of every declared key; items of arrays of tables
    at index 0."""
    out = []
    for table in schema.tables:
        base = table.path.replace("[]", ".0")
        for f in table.fields:
            out.append((f"{base}.{f.key}" if base else f.key, f))
    return out


KEYS = {s.kind: declared_keys(s) for s in (BEAM, TELESCOPIC, FOLDING)}
TABLES = {s.kind: sorted({t.path.replace("[]", ".0") for t in s.tables if t.path} |
                         {t.path.split("[]")[0] for t in s.tables if "[]" in t.path})
          for s in (BEAM, TELESCOPIC, FOLDING)}
FIELD_NAMES = {s.kind: {t.path.split(".")[0].removesuffix("[]") for t in s.tables if t.path}
               | {f.key for t in s.tables for f in t.fields} | {"scene", "override"}
               for s in (BEAM, TELESCOPIC, FOLDING)}

HUGE = [1.0] * 100_000
GARBAGE = st.sampled_from([
    math.nan, math.inf, -math.inf, "nan", "inf", "abc", "", True, False, [], HUGE, [[]],
    [math.nan, 1.0], {"x": {"y": 1}}, {}, "[1, 2", "[[0, 1], [1]]", "1e400", -0.0, 0, -1,
    10**30, 1e-300, "solver", ["a", "b"], [[0.0, 1.0], [1.0, math.inf]]])


def _numbers(lo: float, hi: float, integer: bool):
    inside = (st.integers(int(math.ceil(lo)), int(math.floor(hi))) if integer else
              st.floats(lo, hi, allow_nan=False, allow_infinity=False))
    span = max(hi - lo, abs(hi), 1.0)
    edges = st.sampled_from([lo, hi, lo - 1e-9 * span - 1e-300, hi + 1e-9 * span, lo - span,
                             hi * 10 + 1, 0, 0.0, -hi, hi * 1e6])
    return st.one_of(inside, inside, edges)


def values(f: Field):
    """Values for one declared key: inside and on the ends of its range, outside, and garbage
    (the same for every type)."""
    t = f.type
    if t in ("number", "integer"):
        good = _numbers(f.lo, f.hi, t == "integer")
    elif t == "boolean":
        good = st.booleans()
    elif t == "choice":
        good = st.one_of(st.sampled_from(f.choices or ("x",)), st.text(max_size=4))
    elif t == "string":
        good = st.text(max_size=8)
    elif t == "vector":
        good = st.lists(_numbers(f.lo, f.hi, False), min_size=f.n - 1, max_size=f.n + 1)
    elif t == "numbers":
        lo, hi = f.items
        good = st.lists(_numbers(f.lo, f.hi, False), min_size=max(lo - 1, 0),
                        max_size=min(hi + 1, 8)).map(sorted)
    elif t == "rows":
        cols = [_numbers(a, b, False) for a, b, _ in f.columns]
        good = st.lists(st.tuples(*cols).map(list), min_size=f.items[0] - 1, max_size=6) \
            .map(lambda rows: sorted(rows))
    else:                                               # strings
        good = st.lists(st.text(max_size=6), max_size=4)
    return st.one_of(good, good, good, GARBAGE)


@st.composite
def examples(draw, scenes=tuple(SCENES)):
    """(scene, overrides, run): one to three drawn keys (mostly declared ones, sometimes a
    whole table or an unknown key) and whether the example runs."""
    name = draw(st.sampled_from(scenes))
    schema, base, _ = SCENES[name]
    keys = KEYS[schema.kind]
    overrides = {}
    for _ in range(draw(st.integers(1, 3))):
        pick = draw(st.integers(0, 19))
        if pick < 17:
            key, f = draw(st.sampled_from(keys))
            overrides[key] = draw(values(f))
        elif pick < 19:
            key = draw(st.sampled_from(TABLES[schema.kind]))
            overrides[key] = draw(st.one_of(GARBAGE, st.dictionaries(
                st.sampled_from([f.key for _, f in keys][:40]), GARBAGE, max_size=2)))
        else:
            overrides[draw(st.sampled_from(["solver.tend", "booms.lenght", "zzz", "effects.x"]))] \
                = draw(GARBAGE)
    run = base is not None and draw(st.integers(0, 2)) == 0
    return name, overrides, run


# -- the outcome of one example ----------------------------------------------------------------

OUTCOMES = collections.Counter()


@pytest.fixture(scope="module", autouse=True)
def summary(request):
    """The seed and the count of each outcome, written to the terminal after the module."""
    OUTCOMES.clear()
    yield OUTCOMES
    line = (f"fuzzed scenes: seed {SEED} (FUZZ_SEED), "
            + ", ".join(f"{k} {v}" for k, v in sorted(OUTCOMES.items())))
    plugins = request.config.pluginmanager
    reporter, capture = plugins.get_plugin("terminalreporter"), plugins.get_plugin("capturemanager")
    if reporter is not None and capture is not None:
        with capture.global_and_fixture_disabled():
            reporter.write_line("")
            reporter.write_line(line)
    else:                                                # pragma: no cover
        sys.__stdout__.write(line + "\n")


@pytest.fixture(scope="module")
def warm():
    """Each simulated scene run once on each of its integration paths, so the first use's
    loading of the compiled kernels is not charged to a fuzzed run's wall budget."""
    for name, (_, base, _) in SCENES.items():
        if base is None:
            continue
        methods = [{}]
        if SCENES[name][0] is BEAM:
            methods += [{"solver.method": m} for m in ("RK45", "BDF", "auto")]
            methods += [{"solver.h": 1e-3, "solver.t_end": 0.004}]
        for extra in methods:
            try:
                sim_core.simulate(sim_core.load_scene(SHIPPED.get(name, name), {**base, **extra}))
            except (SceneError, SimulationError):     # a method the scene does not take
                pass


def _names_a_field(msg: str, kind) -> bool:
    """The message starts with a field of the scene: ``booms.length = ...``, ``boom[2].section:
    ...``, ``[[overlap]]: ...``, ``drive: ...``, ``scene.x: unknown key``, ``override 'k': ...``."""
    head = msg.lstrip("[").split(" ")[0].split(":")[0]
    first = head.split(".")[0].split("[")[0].rstrip("]")
    return first in FIELD_NAMES[kind]


def _finite_outputs(res) -> bool:
    for k in res.keys():
        a = np.asarray(res[k])
        if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
            return False
    return bool(np.all(np.isfinite(res.t)))


def _cap(over: dict, caps, base: dict) -> None:
    """Each (key, cap): a drawn number in (0, cap] stays, else the base's value (at most the
    cap) replaces it."""
    for key, cap in caps:
        v = over.get(key)
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and 0 < v <= cap):
            over[key] = min(base.get(key, cap), cap)


def check_example(name: str, overrides: dict, run: bool) -> str:
    """Validate (and run) one example; returns its outcome, fails on any other."""
    schema, base, t_cap = SCENES[name]
    scene = SHIPPED.get(name, name)
    over = {**(base or {}), **overrides} if run else dict(overrides)
    if run:
        # the run stays short and budgeted whatever was drawn: t_end, the budget and the
        # outputs (evaluated after the integration, outside its budget) at most their caps,
        # else the cheap base's (or the cap)
        _cap(over, (("solver.t_end", t_cap), ("solver.max_wall_s", BUDGET),
                    ("solver.n_output", 50)), base)
    try:
        sc = sim_core.load_scene(scene, overrides=over)
    except SceneError as exc:
        msg = str(exc)
        assert msg and "\n" not in msg, (scene, over, msg)
        assert _names_a_field(msg, schema.kind), (scene, over, msg)
        return "SceneError"
    if not run:
        return "valid (not run)"
    # beams of at most 33 nodes in all are run: the budget is served between steps, and one
    # step of a larger beam on the numpy path (its tangent) takes seconds
    if schema is BEAM and sum((b["n_nodes"] - 1) * (len(b["breakpoints"]) - 1) + 1
                              for b in sc["beams"]) > 33:
        return "valid (not run: over 33 nodes)"
    t0 = time.perf_counter()
    try:
        res = sim_core.simulate(sc)
    except SimulationError as exc:
        assert math.isfinite(exc.t) and exc.t >= 0.0, (scene, over, exc)
        part = getattr(exc, "result", None)
        if part is not None and "wall_time_s" in part.stats:
            assert part.stats["wall_time_s"] <= BUDGET + STEP_SLACK, (scene, over, exc)
        return f"SimulationError ({type(exc).__name__})" if type(exc) is not SimulationError \
            else "SimulationError"
    wall = time.perf_counter() - t0
    assert res.t[-1] == pytest.approx(sc["solver"]["t_end"]), (scene, over)
    assert _finite_outputs(res) or res.suspect, (scene, over, res.stats)
    if "wall_time_s" in res.stats:
        assert res.stats["wall_time_s"] <= BUDGET + STEP_SLACK, (scene, over, res.stats)
    assert wall < 120.0, (scene, over, wall)
    return "Result (suspect)" if res.suspect else "Result"


def _run(name, overrides, run, check=check_example, label=""):
    """check(name, overrides, run) and count its outcome; any untyped exception fails,
    naming the example."""
    try:
        outcome = check(name, overrides, run)
    except (SceneError, SimulationError, AssertionError):
        raise
    except Exception as exc:       # noqa: BLE001 - the point of the test: name what escaped
        raise AssertionError(f"untyped {type(exc).__name__} from {name} with {overrides!r} "
                             f"(run / csv rows: {run}): {exc}") from exc
    OUTCOMES[label + outcome] += 1


FAST = settings(max_examples=800, deadline=None, database=None, derandomize=False,
                suppress_health_check=list(HealthCheck))
SLOW = settings(FAST, max_examples=5000)


@seed(SEED)
@FAST
@given(example=examples())
def test_fuzzed_scenes_end_in_a_result_a_scene_error_or_a_simulation_error(warm, example):
    _run(*example)


@pytest.mark.slow
@seed(SEED + 1)
@SLOW
@given(example=examples())
def test_fuzzed_scenes_many(warm, example):
    _run(*example)


# -- the wall budget on every integration path -------------------------------------------------

BUDGET_CASES = [
    # fixed-step generalized-alpha on the numpy path (a sleeve: a time-dependent boundary)
    ("beam_through_sleeve", {"solver.h": 1e-7, "solver.t_end": 0.5, "solver.n_output": 2}),
    # error-controlled generalized-alpha on the numpy path
    ("beam_through_sleeve", {"solver.rtol": 1e-12, "solver.atol": 1e-14, "solver.t_end": 8.0}),
    # fixed-step generalized-alpha in compiled calls (one output interval of 1e7 steps)
    ("cantilever_release", {"solver.h": 1e-7, "solver.t_end": 1.0, "solver.n_output": 2}),
    # error-controlled generalized-alpha in compiled calls (the scene's fixed step removed)
    ("cantilever_release", {"solver.h": None, "solver.rtol": 1e-8, "solver.atol": 1e-11,
                            "solver.newton_atol": 1e-12, "solver.t_end": 2.0}),
    # RK45 on a beam
    ("cantilever_release", {"solver.h": None, "solver.rho_inf": None, "solver.newton_atol": None,
                            "solver.method": "RK45", "solver.rtol": 1e-12, "solver.atol": 1e-14,
                            "solver.t_end": 2.0}),
    # the modal ROM: one hour at 1e5 outputs
    ("telescopic_extraction_rl", {"solver.t_end": 3600.0, "solver.n_output": 100001}),
    # the rigid limit with stiff elastic ropes
    ("telescopic_extraction", {"effects.flexible": False, "effects.friction": False,
                               "ropes.EA": 1e11, "solver.t_end": 3600.0}),
]


@pytest.mark.parametrize("scene, overrides", BUDGET_CASES)
def test_wall_budget_is_honoured_on_every_path(warm, scene, overrides):
    """A run that would take minutes to hours stops at solver.max_wall_s = 0.5 s with a typed
    SimulationError naming the budget (it ran out, or the pace showed it would); its
    integration ran at most the budget plus a step.  (An override of None removes the key.)"""
    from sim_core.registry import system_kind
    from sim_core.scene.io import apply_overrides, read_scene
    raw, source = read_scene(scene)
    for key in (k for k, v in overrides.items() if v is None):
        table, name = key.split(".")
        raw[table].pop(name, None)
    raw = apply_overrides(raw, {**{k: v for k, v in overrides.items() if v is not None},
                                "solver.max_wall_s": 0.5})
    sc = system_kind(raw).validate(raw, source)
    t0 = time.perf_counter()
    with pytest.raises(SimulationError, match=r"max_wall_s = 0\.5 s") as info:
        sim_core.simulate(sc)
    assert time.perf_counter() - t0 < 60.0
    assert 0.0 <= info.value.t < sc["solver"]["t_end"]
    part = getattr(info.value, "result", None)
    if part is not None and "wall_time_s" in part.stats:
        assert part.stats["wall_time_s"] <= 0.5 + STEP_SLACK


# -- the command line ------------------------------------------------------------------------

def test_cli_refuses_a_payload_outside_the_modal_tables_with_one_line(tmp_path):
    """``boom-sim run telescopic_extraction_rl --set payload.mass=7``: status 2 and one line
    naming the field, the value and the tables' range (nothing written)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    proc = subprocess.run([sys.executable, "-m", "sim_core.cli", "run", "telescopic_extraction_rl",
                           "--set", "payload.mass=7", "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, env=env, cwd=ROOT, timeout=300)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert "payload.mass = 7.0" in lines[0] and "[20000, 30000] kg" in lines[0], lines[0]
    assert not (tmp_path / "out").exists()


# -- every shipped scene, two or three keys at once, run under a wall budget -------------------

RUN_BUDGET = 5.0             # s: solver.max_wall_s of every run of a shipped scene
RUN_MARGIN = 5.0
"""s past RUN_BUDGET that loading, validating and running one example may take: the margin
docs/user_guide.md states for a run ("Budgets and interruption": the budget covers the static
equilibrium, the integration, the output collection and the self-checks, each checked between
units of work, and a unit in progress finishes), which also covers loading and validating the
scene (milliseconds)."""
RUN_T_END = 0.05             # s: the longest solver.t_end of a run (a few steps of each scene)
RUN_OUTPUTS = 5              # the most outputs of a run
ACTUATORS = ("drive", "luffing_drive", "slew_drive", "hoist_drive")
FOCUS = ("boom[]", "boom[].section", "overlap[]", "luffing", "stage_drive[]", "wind",
         "oil_column", "beams[]", "beams[].section", "boundary[]", *ACTUATORS)
SCHEMAS = {"beam": BEAM, "telescopic": TELESCOPIC, "folding": FOLDING}
_RAW: dict = {}


def shipped(name: str) -> tuple[dict, Schema]:
    """A shipped scene's raw table and its kind's schema (read once)."""
    if name not in _RAW:
        from sim_core.registry import kind_name
        from sim_core.scene.io import read_scene
        raw, _ = read_scene(name)
        _RAW[name] = (raw, SCHEMAS[kind_name(raw)])
    return _RAW[name]


def _rows(f: Field, first=None):
    """Rows [time, position] of a drive table, times increasing from 0 past RUN_T_END and
    positions in the column's range (the first one ``first`` where the scene fixes it)."""
    (t_lo, t_hi, _), (p_lo, p_hi, _) = f.columns
    pos = st.floats(p_lo, min(p_hi, p_lo + 1e3), allow_nan=False)
    times = st.lists(st.floats(1e-3, 2 * RUN_T_END), min_size=1, max_size=4, unique=True)
    return st.tuples(times, st.lists(pos, min_size=5, max_size=5)).map(
        lambda tp: [[0.0, first if first is not None else tp[1][0]]]
        + [[t, p] for t, p in zip(sorted(tp[0]), tp[1][1:])])


def _inside(f: Field):
    """A value of a declared key inside its range (or of its type), most examples of a
    shipped scene then run."""
    if f.type in ("number", "integer"):
        lo, hi = f.lo, f.hi
        return (st.integers(int(math.ceil(lo)), int(math.floor(hi))) if f.type == "integer"
                else st.floats(lo, hi, allow_nan=False, allow_infinity=False))
    return values(f)


@st.composite
def shipped_examples(draw):
    """(scene, overrides, csv rows or None): two or three drawn keys of a shipped scene, mostly
    in its arrays of tables (at an index the scene has), its luffing, drive and effect tables;
    sometimes a drive table replaced by rows inline or by a CSV file (written next to a copy of
    the scene), or an effect plug-in switched on with a key of its table."""
    name = draw(st.sampled_from(sorted(shipped_scenes())))
    raw, schema = shipped(name)
    keys = declared_keys(schema)
    # the focus tables the scene has (an effect plug-in's table is switched on below)
    focus = [(f"{t.path.replace('[]', '.0')}.{f.key}", f) for t in schema.tables
             if t.path in FOCUS and (t.path.split("[]")[0].split(".")[0] in raw
                                     or t.path in ("wind", "oil_column"))
             for f in t.fields] or keys
    overrides, csv = {}, None
    for _ in range(draw(st.integers(2, 3))):
        pick = draw(st.integers(0, 9))
        if pick < 6 or schema is not TELESCOPIC:
            key, f = draw(st.sampled_from(focus if pick < 4 else keys))
            parts = key.split(".")
            if len(parts) > 2 and parts[1] == "0" and isinstance(raw.get(parts[0]), list):
                parts[1] = str(draw(st.integers(0, max(len(raw[parts[0]]) - 1, 0))))
            overrides[".".join(parts)] = draw(_inside(f) if draw(st.integers(0, 3)) else values(f))
            if parts[0] in ("wind", "oil_column"):
                overrides[f"effects.{parts[0]}"] = True
        elif pick < 8:
            table = draw(st.sampled_from(ACTUATORS))
            f = schema.table(table)["table"]
            first = raw.get("booms", {}).get("stroke0") if table == "drive" else None
            rows = draw(_rows(f, first))
            extra = {"direction": raw.get("drive", {}).get("direction", "extraction")} \
                if table == "drive" else {}
            if draw(st.booleans()):
                overrides[table] = {"profile": "table", "table": rows, **extra}
            else:
                overrides[table] = {"profile": "table", "table_file": "fuzz_drive.csv", **extra}
                csv = rows
        else:
            plugin = draw(st.sampled_from(("wind", "oil_column")))
            f = draw(st.sampled_from(schema.table(plugin).fields))
            overrides[f"effects.{plugin}"] = True
            overrides[f"{plugin}.{f.key}"] = draw(values(f))
    return name, overrides, csv


def check_shipped(name: str, overrides: dict, csv) -> str:
    """Validate and run one example of a shipped scene (copied into a temporary folder with
    the drive's CSV file where one was drawn) at most RUN_T_END long under RUN_BUDGET; returns
    its outcome, fails on any other: a run that returns must have finite outputs, and the
    whole example must end within RUN_BUDGET + RUN_MARGIN."""
    import shutil
    import tempfile
    over = dict(overrides)
    _cap(over, (("solver.t_end", RUN_T_END), ("solver.n_output", RUN_OUTPUTS)), {})
    over["solver.max_wall_s"] = RUN_BUDGET
    schema = shipped(name)[1]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"{name}.toml"
        shutil.copyfile(shipped_scenes()[name], path)
        if csv is not None:
            (Path(tmp) / "fuzz_drive.csv").write_text(
                "time_s,position\n" + "".join(f"{t!r},{p!r}\n" for t, p in csv))
        t0 = time.perf_counter()
        try:
            sc = sim_core.load_scene(path, overrides=over)
        except SceneError as exc:
            msg = str(exc)
            assert msg and "\n" not in msg, (name, over, msg)
            assert _names_a_field(msg, schema.kind) or tmp in msg, (name, over, msg)
            return "SceneError"
        try:
            res = sim_core.simulate(sc)
            outcome = "Result (suspect)" if res.suspect else "Result"
        except SimulationError as exc:
            assert math.isfinite(exc.t) and exc.t >= 0.0, (name, over, exc)
            outcome = f"SimulationError ({type(exc).__name__})"
            res = None
        wall = time.perf_counter() - t0
    assert wall <= RUN_BUDGET + RUN_MARGIN, (name, over, wall)
    if res is not None:
        assert _finite_outputs(res), (name, over, res.stats)
        assert res.t[-1] == pytest.approx(sc["solver"]["t_end"]), (name, over)
    return outcome


def _run_shipped(name, overrides, csv):
    _run(name, overrides, csv, check_shipped, "shipped: ")


SHIPPED_FAST = settings(FAST, max_examples=30)
SHIPPED_SLOW = settings(FAST, max_examples=300)


@seed(SEED + 2)
@SHIPPED_FAST
@given(example=shipped_examples())
def test_shipped_scenes_with_two_or_three_keys_end_within_their_budget(example):
    _run_shipped(*example)


@pytest.mark.slow
@seed(SEED + 3)
@SHIPPED_SLOW
@given(example=shipped_examples())
def test_shipped_scenes_with_two_or_three_keys_many(example):
    _run_shipped(*example)
