"""Scene schema of the folding long-boom manipulator (kind = "folding"), SI units.

Every key is declared once in :data:`SCHEMA` (type, unit, default, allowed range, note) and read
through the declarations (:mod:`sim_core.scene.fields`); the scene reference of the
documentation is rendered from them.  PD: the SIMULTECH 2020 paper's parameter set.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sim_core.errors import SceneError
from sim_core.scene.fields import (
    ERROR_CONTROLLED,
    T_MAX,
    Field,
    Schema,
    Table,
    read_text,
    short_repr,
    solver_fields,
    solver_table,
    table_of,
    text_fields,
    time_field,
)
from sim_core.systems.folding.build import FoldingParams, cylinder_lengths

# -- the declarations ---------------------------------------------------------------------------

TOP = Table("", (Field("kind", "choice", choices=("folding",)), *text_fields("folding")),
            tables=("solver", "booms", "cylinders", "drive", "rest", "effects", "filtering",
                    "gravity"))
SOLVER = solver_fields(t_end=45.0, n_output=451, methods=ERROR_CONTROLLED)
BOOMS = Table("booms", (
    Field("length", "number", "m", 12.0, lo=1.0, hi=100.0, lo_open=True,
          note="each of the two booms"),
    Field("radius", "number", "m", 0.15, lo=1e-3, hi=2.0,
          note="outer radius of the booms' circular tube"),
    Field("mass_per_length", "number", "kg/m", 544.6, lo=0.1, hi=1e5),
    Field("E", "number", "Pa", 2.11e11, lo=1e8, hi=1e15, note="Young's modulus"),
    Field("nu", "number", "", 0.3, lo=-1.0, hi=0.5, lo_open=True, hi_open=True,
          note="Poisson's ratio"),
    Field("n_nodes", "integer", "", 9, lo=3, hi=33,
          note="nodes of the one spline element per boom; PD 9 = 8 sub-elements"),
    Field("n_gauss", "integer", "", 3, lo=1, hi=10, note="Gauss points per sub-element; PD 3"),
), note="the two flexible booms")
CYLINDERS = Table("cylinders", (
    Field("k", "number", "N/m", 5e7, lo=1e3, hi=1e12, note="axial stiffness"),
    Field("c", "number", "N s/m", 4e5, lo=0.0, hi=1e10, note="axial damping"),
    Field("barrel_mass", "number", "kg", 10.0, lo=0.01, hi=1e4),
    Field("rod_mass", "number", "kg", 10.0, lo=0.01, hi=1e4),
), note="the two hydraulic cylinders")
DRIVE = Table("drive", (
    time_field("t1", 3.0, lo=1e-3, note="rise of each stage (Eq. 52)"),
    time_field("t2", 6.0, note="hold of each stage (Eq. 52)"),
    time_field("t3", 3.0, lo=1e-3, note="decay of each stage (Eq. 52)"),
    Field("stage_starts", "numbers", "s", [0.0, 15.0, 30.0], lo=0.0, hi=T_MAX, items=(3, 3),
          note="start of the luff, slew and unfold stages; a stage starts after the previous "
               "one ends (start + t1 + t2 + t3)"),
    Field("cyl1_stroke", "number", "m", 1.328, lo=1e-3, hi=10.0,
          allowed="[0.001, 10] m, and boom 1 stays below 85 deg",
          note="stroke of cylinder 1 (luffing boom 1)"),
    Field("slew_angle_deg", "number", "deg", -90.0, lo=-180.0, hi=180.0,
          allowed="[-180, 180] deg, not 0", note="slew stage; PD -90 = clockwise seen from above"),
    Field("cyl2_stroke", "number", "m", 1.242, lo=1e-3, hi=10.0,
          allowed="[0.001, 10] m, and the links stay assemblable",
          note="stroke of cylinder 2 (unfolding boom 2)"),
), note="the three drive stages (Eq. 52)")
REST = Table("rest", (
    Field("k", "number", "N/m", 1e7, lo=0.0, hi=1e12, note="0 = no boom rest"),
    Field("c", "number", "N s/m", 1e4, lo=0.0, hi=1e10),
), note="the rest boom 2 lies on at the start")
EFFECTS = Table("effects", (
    Field("gravity", "boolean", default=True),
    Field("filtering", "boolean", default=True, note="stress averaging over [filtering] h"),
))
FILTERING = Table("filtering", (
    Field("h", "number", "s", 0.005, lo=1e-4, hi=1.0,
          note="stress-averaging window (SIMULTECH 2020 Eq. 53)"),
))
GRAVITY = Table("gravity", (
    Field("g", "number", "m/s^2", 9.81, lo=0.0, hi=100.0, lo_open=True, note="along -X"),
))

SCHEMA = Schema(
    "folding", 'Folding scenes (`kind = "folding"`)',
    "sim_core.systems.folding.schema.validate_folding",
    (TOP, SOLVER, BOOMS, CYLINDERS, DRIVE, REST, EFFECTS, FILTERING, GRAVITY),
    rules=(
        "The drive stages do not overlap: each of drive.stage_starts is at least the previous "
        "one plus t1 + t2 + t3.",
        "Closed-form linkage (booms rigid): drive.cyl1_stroke keeps boom 1's elevation in "
        "[0, 85] deg; drive.cyl2_stroke keeps the links assemblable with boom 2's relative "
        "angle in (0, 180] deg (the errors give the largest strokes).",
    ))


def validate_folding(raw: dict, source: str) -> dict[str, Any]:
    TOP.check_keys(raw, "scene")
    TOP.read(raw, "kind", "scene")
    sc: dict[str, Any] = {"kind": "folding"}
    read_text(raw, TOP, sc, "folding")
    sc["source"] = source
    sc["solver"] = solver_table(table_of(raw, "solver", ""), t_end=45.0, n_output=451,
                                methods=ERROR_CONTROLLED)
    b = table_of(raw, "booms", "")
    BOOMS.check_keys(b, "booms")
    sc["booms"] = {k: BOOMS.read(b, k, "booms") for k in
                   ("length", "radius", "mass_per_length", "E", "nu", "n_nodes", "n_gauss")}
    c = table_of(raw, "cylinders", "")
    CYLINDERS.check_keys(c, "cylinders")
    sc["cylinders"] = {k: CYLINDERS.read(c, k, "cylinders")
                       for k in ("k", "c", "barrel_mass", "rod_mass")}
    d = table_of(raw, "drive", "")
    DRIVE.check_keys(d, "drive")
    t1, t2, t3 = (DRIVE.read(d, k, "drive") for k in ("t1", "t2", "t3"))
    starts = DRIVE.read(d, "stage_starts", "drive")
    dur = t1 + t2 + t3
    for k in (1, 2):
        if starts[k] < starts[k - 1] + dur:
            raise SceneError(f"drive.stage_starts = {short_repr(d.get('stage_starts'))}: stage "
                             f"{k + 1} starts at {starts[k]:g} s before stage {k} ends at "
                             f"{starts[k - 1] + dur:g} s (start + t1 + t2 + t3); allowed "
                             f">= {starts[k - 1] + dur:g} s")
    slew = DRIVE.read(d, "slew_angle_deg", "drive")
    if slew == 0.0:
        raise SceneError("drive.slew_angle_deg = 0: must be non-zero, allowed [-180, 180] deg "
                         "(set the slew stage's angle; PD -90)")
    sc["drive"] = {"t1": t1, "t2": t2, "t3": t3, "stage_starts": [float(x) for x in starts],
                   "cyl1_stroke": DRIVE.read(d, "cyl1_stroke", "drive"),
                   "slew_angle_deg": slew,
                   "cyl2_stroke": DRIVE.read(d, "cyl2_stroke", "drive")}
    r = table_of(raw, "rest", "")
    REST.check_keys(r, "rest")
    sc["rest"] = {"k": REST.read(r, "k", "rest"), "c": REST.read(r, "c", "rest")}
    e = table_of(raw, "effects", "")
    EFFECTS.check_keys(e, "effects")
    sc["effects"] = {"gravity": EFFECTS.read(e, "gravity", "effects"),
                     "filtering": EFFECTS.read(e, "filtering", "effects")}
    sc["filtering"] = FILTERING.resolve(raw, "filtering", ("h",))
    sc["gravity"] = GRAVITY.resolve(raw, "gravity", ("g",))
    _check_geometry(sc)
    return sc


def _check_geometry(sc: dict) -> None:
    """Closed-form linkage (rigid booms): strokes must stay within the mechanism's range."""
    p = params_from_scene(sc)
    s1_0, s2_0 = cylinder_lengths(p, 0.0, np.pi)
    s1_max = cylinder_lengths(p, np.radians(85.0), np.pi)[0]
    if s1_0 + sc["drive"]["cyl1_stroke"] > s1_max:
        raise SceneError(f"drive.cyl1_stroke = {sc['drive']['cyl1_stroke']!r}: boom 1 would pass "
                         f"85 deg elevation; allowed (0, {s1_max - s1_0:.4g}] m")
    rels = np.radians(np.linspace(180.0, 1.0, 180))
    lens = []
    for rel in rels:
        try:
            lens.append(cylinder_lengths(p, 0.0, rel)[1])
        except ValueError:
            break
    s2_max = max(lens)
    if s2_0 + sc["drive"]["cyl2_stroke"] > s2_max:
        raise SceneError(f"drive.cyl2_stroke = {sc['drive']['cyl2_stroke']!r}: the links cannot "
                         f"be assembled (boom 2 relative angle would leave (0, 180] deg); "
                         f"allowed (0, {s2_max - s2_0:.4g}] m")


def params_from_scene(sc: dict):
    """FoldingParams of a validated folding scene."""
    b, c, d = sc["booms"], sc["cylinders"], sc["drive"]
    return FoldingParams(
        boom_length=b["length"], boom_radius=b["radius"], boom_mass_per_length=b["mass_per_length"],
        E=b["E"], nu=b["nu"], n_nodes=b["n_nodes"], n_gauss=b["n_gauss"], k=c["k"], c=c["c"],
        barrel_mass=c["barrel_mass"], rod_mass=c["rod_mass"], t1=d["t1"], t2=d["t2"], t3=d["t3"],
        stage_starts=tuple(d["stage_starts"]), cyl1_stroke=d["cyl1_stroke"],
        slew_angle_deg=d["slew_angle_deg"], cyl2_stroke=d["cyl2_stroke"],
        rest_k=sc["rest"]["k"], rest_c=sc["rest"]["c"],
        gravity=sc["gravity"]["g"] if sc["effects"]["gravity"] else 0.0,
        filter_h=sc["filtering"]["h"] if sc["effects"]["filtering"] else 0.0)
