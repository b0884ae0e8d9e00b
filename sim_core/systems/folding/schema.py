"""Scene schema of the folding long-boom manipulator (kind = "folding"), SI units.

  kind = "folding", name, description, notes
  [solver]     t_end s (> 0), rtol (0, 1), atol (> 0), n_output (>= 2), method ("RK45", "BDF",
               "auto"), max_step s and max_wall_s s (> 0, optional)
  [booms]      length m (> 1), radius m (> 0), mass_per_length kg/m (> 0), E Pa (> 0),
               nu (-1, 0.5), n_nodes (3..33, nodes of the one spline element per boom; PD 9 =
               8 sub-elements), n_gauss (1..10; PD 3)
  [cylinders]  k N/m (> 0), c N s/m (>= 0), barrel_mass, rod_mass kg (> 0)
  [drive]      t1 s (> 0), t2 s (>= 0), t3 s (> 0) (Eq. 52), stage_starts s (3 increasing
               values >= 0: luff, slew, unfold; a stage may not start before the previous one
               ends, start + t1 + t2 + t3), cyl1_stroke m (> 0), slew_angle_deg ([-180, 180],
               non-zero; PD -90 = clockwise seen from above), cyl2_stroke m (> 0)
  [rest]       k N/m (>= 0, 0 = no boom rest), c N s/m (>= 0)
  [effects]    gravity (bool), filtering (bool)
  [filtering]  h s (> 0): stress-averaging window (second seed Eq. 53)
  [gravity]    g m/s^2 (> 0, along -X)
Geometry rules (closed-form linkage, booms rigid): the cylinder-1 stroke must keep boom 1's
elevation in [0, 85] deg; the cylinder-2 stroke must keep the links assemblable with boom 2's
relative angle in (0, 180] deg (errors name drive.cyl1_stroke / drive.cyl2_stroke).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sim_core.errors import SceneError
from sim_core.scene.fields import ERROR_CONTROLLED, boolean, check_keys, number, solver_table
from sim_core.systems.folding.build import FoldingParams, cylinder_lengths

_TOP = {"kind", "name", "description", "notes", "solver", "booms", "cylinders", "drive", "rest",
        "effects", "filtering", "gravity"}


def validate_folding(raw: dict, source: str) -> dict[str, Any]:
    check_keys(raw, _TOP, "scene")
    sc: dict[str, Any] = {"kind": "folding", "name": str(raw.get("name", "folding")),
                          "description": str(raw.get("description", "")), "source": source}
    sc["solver"] = solver_table(raw.get("solver", {}), t_end=45.0, n_output=451,
                                methods=ERROR_CONTROLLED)
    b = raw.get("booms", {})
    check_keys(b, {"length", "radius", "mass_per_length", "E", "nu", "n_nodes", "n_gauss"}, "booms")
    sc["booms"] = {"length": number(b, "length", "booms", 12.0, lo=1.0, lo_open=True),
                   "radius": number(b, "radius", "booms", 0.15, lo=0.0, lo_open=True),
                   "mass_per_length": number(b, "mass_per_length", "booms", 544.6, lo=0.0,
                                             lo_open=True),
                   "E": number(b, "E", "booms", 2.11e11, lo=0.0, lo_open=True),
                   "nu": number(b, "nu", "booms", 0.3, lo=-1.0, hi=0.5, lo_open=True,
                                hi_open=True),
                   "n_nodes": number(b, "n_nodes", "booms", 9, lo=3, hi=33, integer=True),
                   "n_gauss": number(b, "n_gauss", "booms", 3, lo=1, hi=10, integer=True)}
    c = raw.get("cylinders", {})
    check_keys(c, {"k", "c", "barrel_mass", "rod_mass"}, "cylinders")
    sc["cylinders"] = {"k": number(c, "k", "cylinders", 5e7, lo=0.0, lo_open=True),
                       "c": number(c, "c", "cylinders", 4e5, lo=0.0),
                       "barrel_mass": number(c, "barrel_mass", "cylinders", 10.0, lo=0.0,
                                             lo_open=True),
                       "rod_mass": number(c, "rod_mass", "cylinders", 10.0, lo=0.0, lo_open=True)}
    d = raw.get("drive", {})
    check_keys(d, {"t1", "t2", "t3", "stage_starts", "cyl1_stroke", "slew_angle_deg",
                   "cyl2_stroke"}, "drive")
    t1 = number(d, "t1", "drive", 3.0, lo=0.0, lo_open=True)
    t2 = number(d, "t2", "drive", 6.0, lo=0.0)
    t3 = number(d, "t3", "drive", 3.0, lo=0.0, lo_open=True)
    starts = d.get("stage_starts", [0.0, 15.0, 30.0])
    if (not isinstance(starts, list) or len(starts) != 3
            or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                       and np.isfinite(x) for x in starts)):
        raise SceneError(f"drive.stage_starts = {starts!r}: must be a list of 3 finite numbers "
                         "(luff, slew, unfold start times, s)")
    dur = t1 + t2 + t3
    if starts[0] < 0:
        raise SceneError(f"drive.stage_starts = {starts!r}: the first stage starts at "
                         f"{starts[0]:g} s, allowed >= 0")
    for k in (1, 2):
        if starts[k] < starts[k - 1] + dur:
            raise SceneError(f"drive.stage_starts = {starts!r}: stage {k + 1} starts at "
                             f"{starts[k]:g} s before stage {k} ends at "
                             f"{starts[k - 1] + dur:g} s (start + t1 + t2 + t3); allowed "
                             f">= {starts[k - 1] + dur:g} s")
    slew = number(d, "slew_angle_deg", "drive", -90.0, lo=-180.0, hi=180.0)
    if slew == 0.0:
        raise SceneError("drive.slew_angle_deg = 0: must be non-zero, allowed [-180, 180] deg "
                         "(set the slew stage's angle; PD -90)")
    sc["drive"] = {"t1": t1, "t2": t2, "t3": t3, "stage_starts": [float(x) for x in starts],
                   "cyl1_stroke": number(d, "cyl1_stroke", "drive", 1.328, lo=0.0, lo_open=True),
                   "slew_angle_deg": slew,
                   "cyl2_stroke": number(d, "cyl2_stroke", "drive", 1.242, lo=0.0, lo_open=True)}
    r = raw.get("rest", {})
    check_keys(r, {"k", "c"}, "rest")
    sc["rest"] = {"k": number(r, "k", "rest", 1e7, lo=0.0), "c": number(r, "c", "rest", 1e4, lo=0.0)}
    e = raw.get("effects", {})
    check_keys(e, {"gravity", "filtering"}, "effects")
    sc["effects"] = {"gravity": boolean(e, "gravity", "effects", True),
                     "filtering": boolean(e, "filtering", "effects", True)}
    f = raw.get("filtering", {})
    check_keys(f, {"h"}, "filtering")
    sc["filtering"] = {"h": number(f, "h", "filtering", 0.005, lo=0.0, lo_open=True)}
    g = raw.get("gravity", {})
    check_keys(g, {"g"}, "gravity")
    sc["gravity"] = {"g": number(g, "g", "gravity", 9.81, lo=0.0, lo_open=True)}
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
