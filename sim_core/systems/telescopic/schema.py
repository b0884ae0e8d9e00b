"""Scene schema of the telescopic boom system (kind = "telescopic"), SI units.

  kind = "telescopic", name, description
  [solver]     t_end s (> 0), rtol (0, 1), atol (> 0), n_output (>= 2), method ("RK45", "BDF",
               "auto"), max_step s and max_wall_s s (> 0, optional; max_wall_s: wall-clock budget,
               stops with a partial result)
  [booms]      count (2..6: the paper's three booms are the innermost three, larger sections
               of the same family outside them, params.crane_sections), length m (> 0),
               luffing_angle_deg (0..85),
               stroke0 m (piston-rod length L_s at t = 0, > 0), L_h m (luffing point on boom 1,
               within (0, length)), E Pa (> 0), rho kg/m^3 (> 0), n_nodes (3..33 per spline
               element; paper 9), n_gauss (1..10)
  [drive]      direction ("extraction"/"retraction"), v_max m/s (> 0), t_ramp s (> 0),
               t_hold_end s (>= t_ramp)  -- the cubic schedule of Section 9 (docs/model.md#input-drive);
               mechanism ("synchronized" default: the paper's cylinder-and-rope unit repeated
               along the boom, every stage moves together; "sequential": one cylinder moves
               one stage at a time, the others pinned; docs/model.md, "N-boom drives")
               profile ("cubic" default: the keys above; "trapezoid": travel m (> 0, with
               direction), v_max m/s, a_max m/s^2 (> 0), j_max m/s^3 (> 0, optional: a jerk-
               limited S-curve); "table": table (rows [time s, stage length m], the first row
               is booms.stroke0) or table_file (a CSV file of time s and stage length m,
               relative to the scene file)), t_start s (>= 0: when the cubic or trapezoid
               starts), max_rate m/s (> 0) and max_accel m/s^2 (> 0): the actuator's limits,
               checked against the profile (sim_core.systems.telescopic.actuators)
  [luffing_drive] the luffing cylinder's profile in the luffing angle of the rigid crane, from
               booms.luffing_angle_deg: profile ("hold" default, "cubic", "trapezoid",
               "table"), travel deg (signed), t_ramp s (> 0), t_hold_end s (>= t_ramp),
               t_start s (>= 0), v_max deg/s (> 0), a_max deg/s^2 (> 0), j_max deg/s^3 (> 0),
               table (rows [time s, angle deg]) or table_file, max_rate deg/s (> 0),
               max_accel deg/s^2 (> 0); the angle stays in [0, 85] deg
  [slew_drive] the slewing drive's profile in the slew angle about the vertical from 0 (a
               turntable under the pivot and the cylinder base): profile, travel deg,
               t_ramp s, t_hold_end s, t_start s, v_max deg/s, a_max deg/s^2, j_max deg/s^3,
               table or table_file (time s, angle deg), max_rate deg/s, max_accel deg/s^2,
               as in [luffing_drive]
  [hoist_drive] the hoist's profile in the unstretched hoist-rope length from hoist.length
               (at least 0.1 m): profile, travel m, t_ramp s, t_hold_end s, t_start s,
               v_max m/s, a_max m/s^2, j_max m/s^3, table or table_file (time s, length m),
               max_rate m/s, max_accel m/s^2, as in [luffing_drive]
  [hoist]      with effects.payload_swing: length m (> 0, unstretched at t = 0), EA N (> 0),
               hook_mass kg (>= 0, hangs with the payload)
  [payload]    mass kg (>= 0)
  [ropes]      EA N (> 0)
  [effects]    what is off is not built (each a separate contribution to the model):
               flexible (bool, default true; false = rigid booms, the kinematic limit of
               sim_core.systems.telescopic.rigid: no beams, no contact constraints),
               torsion (bool, default true; false = torsion angles held at zero, twist rows of
               the angle constraints dropped), gravity (bool), filtering (bool: stress
               averaging with [filtering] h), friction (bool, default false: Coulomb friction
               on the contact coordinates, Section 8.3), contact_distribution (bool, default
               true for 3 booms: slider-spring analysis of Section 8, output
               slider_contact_forces; false = only the constraint resultants),
               rope_elasticity (bool, default true: elastic tension-only ropes with [ropes] EA;
               false = one inextensible rope constraint, output rope_tension),
               payload_swing (bool, default false: the payload and hook hang on the elastic
               hoist rope of [hoist] and swing; false = a point mass fixed at the tip),
               wind (bool, default false: an effect plug-in, the drag of [wind] on the exposed
               booms, sim_core.physics.wind),
               mass_centre_offset (bool, default false: mass on the reference line; true =
               the Table 2 offsets z_c = 0.045/0.044/0.043 m as a rigid offset in inertia and
               gravity, docs/model.md#input-sections; the modal ROM tables are built without it)
  [contact]    mu_static (>= 0), mu_dynamic (>= 0), v_eps m/s (> 0, switching speed),
               k0 N/m (> 0, radial spring stiffness), eps m (> 0, stiffness smoothing interval),
               slider_width m (2w, > 0 and shorter than the smallest overlap L - max L_s),
               springs_per_quarter (1..200 springs per quarter arc and slider end),
               radial_gap m ((0, 0.05]: sliding-block thickness between the walls; sets the
               contact-circle radius, default 5 mm of Table 1),
               moment_model ("rigid" default: Section 6, the contact sections' Cardan angles
               coincide; "seat": the two bending angles tied by an elastic seat of
               seat_stiffness N m/rad (> 0, default 1e8: a 20 mm polyamide pad, E = 3 GPa, on a
               0.3 m x 0.3 m footprint); "couple": the bending angles free, the overlap carries
               its moment as a force couple between its two regions),
               friction_load ("resultant" default: the friction's normal load is the transverse
               contact resultant |(f_t, f_b)|; "springs": the sum of the slider springs, Eq. 72
               literally, needs contact_distribution) -- docs/validation.md says why
  [filtering]  h s (> 0)
  [gravity]    g m/s^2 (> 0, along -Z)
  [model]      reduction ("none" = full model, "modal" = stroke-parametric modal ROM of
               sim_core.systems.telescopic.modal, tables built from the full model for 3 and 5
               booms, synchronized drive, frictionless), n_modes (1..4, in-plane modes kept by
               the ROM; default 3)
  [[boom]]     a crane described boom by boom, outermost first (replaces booms.length and the
               shorthand sections; booms.count, when given, must equal the number of tables):
               length m (> 0), E Pa (> 0, default booms.E), nu (-1..0.5, default 0.3) or G Pa
               (> 0), rho kg/m^3 (> 0, default booms.rho), and its section table (below)
  [boom.section] shape ("u", "box", "polygon", "properties"):
               "u": top_arc_centre_y m, top_arc_centre_z m (>= 0), top_arc_radius m (> 0, outer
               radius r of the top arcs), bottom_arc_radius m (outer R = y_a + r, optional),
               wall m (> 0); "box": width m, height m (> 0), wall m (> 0), corner_radius m
               (>= 0, outer); "polygon": n_sides (3..24) with width_across_flats m (> 0, even
               n_sides) or circumradius m (> 0), rotation_deg deg, wall m, or contour (outer
               vertices [[y, z], ...] in m, counter-clockwise) and wall m; "properties": A m^2,
               I_t m^4, I_b m^4, J m^4, mass_per_length kg/m (> 0), y_c m, z_c m (mass centre,
               default 0).  For "u", "box" and
               "polygon" the constants come from sectionproperties (finite-element section
               analysis: A, I_t, I_b, the St. Venant constant J, centroid); any of A m^2, I_t
               m^4, I_b m^4, J m^4, mass_per_length kg/m, y_c m, z_c m given beside the shape
               replaces the computed value (a mass per length with fittings, say)
  [[overlap]]  the sliders of each overlap, outermost pair first (all or none):
               slider_width m (> 0, default contact.slider_width), inner_slider_distance m
               (>= 0: the inner boom's slider centre from that boom's left end; default 0),
               outer_slider_distance m (>= 0: the outer boom's slider centre from its right
               end; default 0), radial_gap m ((0, 0.05], default contact.radial_gap),
               bears_on (names of the inner boom's outer-face patches the sliders bear on: "u"
               P1, P2, P3, flange, side_right, side_left; "box" bottom, right, top, left,
               corner_br, corner_tr, corner_tl, corner_bl; "polygon" face_1..face_n from the
               bottom face counter-clockwise; default: P1-P3 for "u", every patch otherwise)
  [luffing]    the luffing cylinder's mounting points (docs/model.md#input-luffing), each [X, Z]
               or [s, b] in m: pivot m (D1 in global X and Z), pivot_on_boom m (D1 in boom 1's
               left-section frame: axial and vertical), base m (the cylinder base D2 in global X
               and Z), head_on_boom m (the cylinder head D3 in boom 1's left-section frame; its
               axial coordinate is the luffing point L_h; default booms.L_h and -0.556 m)
Geometry rules: the stroke history must keep each boom inside its neighbour: with L_s(t) the
piston length, 0 < L_s(t) < length for all t in [0, t_end] (error names drive/booms fields);
the two sliders of every overlap fit its shortest length, the inner boom reaches past the outer
boom's slider, and every inner section fits inside its outer one with the stated radial gap.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sim_core.errors import SceneError
from sim_core.scene.fields import (
    ERROR_CONTROLLED,
    boolean,
    check_keys,
    choice,
    number,
    solver_table,
    table_of,
    tables_of,
    vector,
)
from sim_core.physics.plugins import effect_plugins
from sim_core.systems.telescopic import actuators
from sim_core.systems.telescopic.params import (
    MAX_BOOMS,
    MECHANISMS,
    BoomSpec,
    LuffingSpec,
    OverlapSpec,
    TelescopicParams,
)

_TOP = {"kind", "name", "description", "solver", "booms", "drive", "payload", "ropes", "effects",
        "filtering", "gravity", "contact", "notes", "model", "boom", "overlap", "luffing",
        "luffing_drive", "slew_drive", "hoist_drive", "hoist", *effect_plugins()}
_GIVEN = ("A", "I_t", "I_b", "J", "mass_per_length", "y_c", "z_c")   # constants a table may give
_PROFILE_KEYS = ("profile", "travel", "a_max", "j_max", "t_start", "table", "table_file",
                 "max_rate", "max_accel")


def validate_telescopic(raw: dict, source: str) -> dict[str, Any]:
    check_keys(raw, _TOP, "scene")
    sc: dict[str, Any] = {"kind": "telescopic", "name": str(raw.get("name", "telescopic")),
                          "description": str(raw.get("description", "")), "source": source}
    sc["solver"] = solver_table(raw.get("solver", {}), t_end=20.0, atol=1e-7,
                                methods=ERROR_CONTROLLED)
    b = raw.get("booms", {})
    check_keys(b, {"count", "length", "luffing_angle_deg", "stroke0", "L_h", "E", "rho",
                   "n_nodes", "n_gauss"}, "booms")
    boom_tables = tables_of(raw, "boom")
    if boom_tables and "length" in b:
        raise SceneError("booms.length with [[boom]] tables: every [[boom]] gives its own length "
                         "(allowed: booms.length or [[boom]] lengths, not both)")
    if boom_tables and b.get("count", len(boom_tables)) != len(boom_tables):
        raise SceneError(f"booms.count = {b['count']!r} with {len(boom_tables)} [[boom]] tables: "
                         "the count must equal the number of tables (or be left out)")
    # physical ranges: from soft polymers to ten times diamond, from foams to osmium
    E = number(b, "E", "booms", 2.1e11, lo=1e8, hi=1e15)
    rho = number(b, "rho", "booms", 7850.0, lo=10.0, hi=1e5)
    if boom_tables:
        sc["boom"] = _check_booms(boom_tables, E, rho)
        L1, Lmin = sc["boom"][0]["length"], min(x["length"] for x in sc["boom"])
    else:
        L1 = Lmin = number(b, "length", "booms", 10.0, lo=0.0, lo_open=True)
    sc["booms"] = {"count": number(b, "count", "booms", len(boom_tables) or 3, lo=2,
                                   hi=MAX_BOOMS, integer=True),
                   "luffing_angle_deg": number(b, "luffing_angle_deg", "booms", 60.0, lo=0.0, hi=85.0),
                   "stroke0": number(b, "stroke0", "booms", 2.0, lo=0.0, hi=Lmin, lo_open=True,
                                     hi_open=True),
                   "L_h": number(b, "L_h", "booms", 7.25, lo=0.0, hi=L1, lo_open=True, hi_open=True),
                   "E": E, "rho": rho,
                   "n_nodes": number(b, "n_nodes", "booms", 9, lo=3, hi=33, integer=True),
                   "n_gauss": number(b, "n_gauss", "booms", 5, lo=1, hi=10, integer=True)}
    if not boom_tables:
        sc["booms"] = {"count": sc["booms"]["count"], "length": L1,
                       **{k: v for k, v in sc["booms"].items() if k != "count"}}
    lf = table_of(raw, "luffing", "")
    if lf:
        sc["luffing"] = _check_luffing(lf, b, sc["booms"]["L_h"], L1)
        sc["booms"]["L_h"] = sc["luffing"]["head_on_boom"][0]
    d = raw.get("drive", {})
    check_keys(d, {"direction", "v_max", "t_ramp", "t_hold_end", "mechanism", *_PROFILE_KEYS},
               "drive")
    t_ramp = number(d, "t_ramp", "drive", 4.0, lo=0.0, lo_open=True)
    sc["drive"] = {"direction": choice(d, "direction", "drive", ("extraction", "retraction"), "extraction"),
                   "v_max": number(d, "v_max", "drive", 0.5, lo=0.0, lo_open=True),
                   "t_ramp": t_ramp,
                   "t_hold_end": number(d, "t_hold_end", "drive", 12.0, lo=t_ramp),
                   "mechanism": choice(d, "mechanism", "drive", MECHANISMS, "synchronized")}
    sc["drive"].update(_check_actuator(d, "drive", "cubic"))
    L = Lmin
    what = "booms.length" if not boom_tables else "the shortest [[boom]] length"
    if sc["drive"]["profile"] == "cubic":
        travel = sc["drive"]["v_max"] * sc["drive"]["t_hold_end"]
        sign = 1 if sc["drive"]["direction"] == "extraction" else -1
        end = sc["booms"]["stroke0"] + sign * travel
        if not 0.0 < end < L:
            raise SceneError(f"drive: the stroke history moves L_s from {sc['booms']['stroke0']:g} m to "
                             f"{end:g} m, outside the allowed (0, {L:g}) m ({what}): a boom would "
                             f"leave its neighbour; reduce drive.v_max or drive.t_hold_end "
                             f"(v_max * t_hold_end <= {(L - sc['booms']['stroke0']) if sign > 0 else sc['booms']['stroke0']:g} m)")
        ls_lo, ls_hi = sorted((sc["booms"]["stroke0"], end))
    else:
        if sc["drive"]["profile"] == "table":
            _, s_tab = actuators.table_rows(sc["drive"], source)
            if "stroke0" in b and b["stroke0"] != s_tab[0]:
                raise SceneError(f"booms.stroke0 = {b['stroke0']:g} m and the drive table starts "
                                 f"at L_s = {s_tab[0]:g} m (allowed: equal, or leave stroke0 "
                                 "out: the table's first row sets it)")
            sc["booms"]["stroke0"] = float(s_tab[0])
        if sc["drive"]["mechanism"] != "synchronized":
            raise SceneError(f"drive.profile = {sc['drive']['profile']!r} with drive.mechanism = "
                             f"{sc['drive']['mechanism']!r}: the sequential drive runs the cubic "
                             "schedule stage by stage (allowed: profile 'cubic', or mechanism "
                             "'synchronized')")
        prof = actuators.build_profile(sc["drive"], sc["booms"]["stroke0"], "drive", source)
        ls_lo, ls_hi = actuators.extremes(prof, max(sc["solver"]["t_end"], prof.t_end))
        if not 0.0 < ls_lo <= ls_hi < L:
            raise SceneError(f"drive: the {sc['drive']['profile']} profile moves L_s between "
                             f"{ls_lo:g} and {ls_hi:g} m, outside the allowed (0, {L:g}) m "
                             f"({what}): a boom would leave its neighbour")
        actuators.check_limits("drive", sc["drive"], prof, sc["solver"]["t_end"])
        end = ls_hi if ls_hi != sc["booms"]["stroke0"] else ls_lo
    pl = raw.get("payload", {})
    check_keys(pl, {"mass"}, "payload")
    # the heaviest lifts of mobile cranes are ~1200 t
    sc["payload"] = {"mass": number(pl, "mass", "payload", 25000.0, lo=0.0, hi=2e6)}
    r = raw.get("ropes", {})
    check_keys(r, {"EA"}, "ropes")
    sc["ropes"] = {"EA": number(r, "EA", "ropes", 1e8, lo=0.0, lo_open=True)}
    e = raw.get("effects", {})
    plugins = effect_plugins()
    check_keys(e, {"gravity", "filtering", "friction", "contact_distribution", "torsion",
                   "rope_elasticity", "flexible", "mass_centre_offset", "payload_swing",
                   *plugins}, "effects")
    three = sc["booms"]["count"] == 3 or bool(boom_tables)
    sc["effects"] = {"flexible": boolean(e, "flexible", "effects", True),
                     "torsion": boolean(e, "torsion", "effects", True),
                     "gravity": boolean(e, "gravity", "effects", True),
                     "filtering": boolean(e, "filtering", "effects", True),
                     "friction": boolean(e, "friction", "effects", False),
                     "contact_distribution": boolean(e, "contact_distribution", "effects", three),
                     "rope_elasticity": boolean(e, "rope_elasticity", "effects", True),
                     "mass_centre_offset": boolean(e, "mass_centre_offset", "effects", False),
                     "payload_swing": boolean(e, "payload_swing", "effects", False)}
    for name in plugins:                # effect plug-ins (sim_core.physics.plugins): off unless on
        if name in e:
            sc["effects"][name] = boolean(e, name, "effects", False)
    eff = sc["effects"]
    if boom_tables and not (eff["flexible"]
                            and raw.get("model", {}).get("reduction", "none") == "none"):
        raise SceneError("[[boom]] tables with effects.flexible = false or model.reduction = "
                         "'modal': the rigid limit and the modal tables are built for the paper's "
                         "crane (allowed: the booms shorthand, or flexible booms with "
                         "model.reduction = 'none')")
    if not eff["flexible"]:
        if sc["booms"]["count"] not in (2, 3) or sc["drive"]["mechanism"] != "synchronized":
            raise SceneError(f"effects.flexible = false with booms.count = {sc['booms']['count']} "
                             f"and drive.mechanism = {sc['drive']['mechanism']!r}: the kinematic "
                             "rigid limit has the paper's drive (allowed: booms.count 2 or 3, "
                             "mechanism 'synchronized'; for more sections take a large booms.E)")
        if eff["friction"]:
            raise SceneError("effects.friction = true with effects.flexible = false: rigid contact "
                             "reactions are statically indeterminate (allowed: friction = false)")
    c = raw.get("contact", {})
    check_keys(c, {"mu_static", "mu_dynamic", "v_eps", "k0", "eps", "slider_width",
                   "springs_per_quarter", "radial_gap", "moment_model", "seat_stiffness",
                   "friction_load"}, "contact")
    sc["contact"] = {"mu_static": number(c, "mu_static", "contact", 0.15, lo=0.0),
                     "mu_dynamic": number(c, "mu_dynamic", "contact", 0.1, lo=0.0),
                     "v_eps": number(c, "v_eps", "contact", 0.01, lo=0.0, lo_open=True),
                     "k0": number(c, "k0", "contact", 1e9, lo=0.0, lo_open=True),
                     "eps": number(c, "eps", "contact", 1e-6, lo=0.0, lo_open=True),
                     "slider_width": number(c, "slider_width", "contact", 0.3, lo=0.0,
                                            lo_open=True),
                     "springs_per_quarter": number(c, "springs_per_quarter", "contact", 20,
                                                   lo=1, hi=200, integer=True),
                     # a gap wider than 50 mm would put the contact circle of the 75 mm top arcs
                     # near their centre (Table 1 radii)
                     "radial_gap": number(c, "radial_gap", "contact", 0.005, lo=0.0, hi=0.05,
                                          lo_open=True),
                     "moment_model": choice(c, "moment_model", "contact",
                                            ("rigid", "seat", "couple"), "rigid"),
                     # a polyamide pad (E = 3 GPa) 20 mm thick on a 0.3 m x 0.3 m footprint
                     # rocking about its centre: E/t * b (2w)^3 / 12 = 1.0e8 N m/rad
                     "seat_stiffness": number(c, "seat_stiffness", "contact", 1e8, lo=0.0,
                                              lo_open=True),
                     "friction_load": choice(c, "friction_load", "contact",
                                             ("resultant", "springs"), "resultant")}
    cc = sc["contact"]
    if cc["friction_load"] == "springs" and not eff["contact_distribution"]:
        raise SceneError("contact.friction_load = 'springs' with effects.contact_distribution = "
                         "false: the spring sum needs the slider springs (allowed: "
                         "friction_load = 'resultant', or contact_distribution = true)")
    if cc["moment_model"] != "rigid" and not eff["flexible"]:
        raise SceneError(f"contact.moment_model = {cc['moment_model']!r} with effects.flexible = "
                         "false: the rigid limit has no contact sections (allowed: 'rigid')")
    # the two sliders of a pair (boom k+1's left-end slider inside boom k, boom k's right-end
    # slider on boom k+1) must fit in the overlap L - L_s(t) at its shortest
    ls_max = max(sc["booms"]["stroke0"], end, ls_hi)
    ls_min = min(sc["booms"]["stroke0"], end, ls_lo)
    ov = tables_of(raw, "overlap")
    if ov or boom_tables:
        sc["overlap"] = _check_overlaps(ov, sc, ls_min, ls_max)
    else:
        overlap = L - ls_max
        if sc["contact"]["slider_width"] >= overlap:
            raise SceneError(f"contact.slider_width = {sc['contact']['slider_width']:g} m does not "
                             f"fit the shortest overlap of adjacent booms, booms.length - max L_s "
                             f"= {overlap:g} m (allowed: 0 < slider_width < {overlap:g} m)")
    f = raw.get("filtering", {})
    check_keys(f, {"h"}, "filtering")
    sc["filtering"] = {"h": number(f, "h", "filtering", 0.01, lo=0.0, lo_open=True)}
    g = raw.get("gravity", {})
    check_keys(g, {"g"}, "gravity")
    sc["gravity"] = {"g": number(g, "g", "gravity", 9.81, lo=0.0, lo_open=True)}
    # the other actuators (sim_core.systems.telescopic.actuators) and the hoisted payload
    t_end = sc["solver"]["t_end"]
    theta0 = sc["booms"]["luffing_angle_deg"]
    for table in ("luffing_drive", "slew_drive", "hoist_drive"):
        tb = table_of(raw, table, "")
        check_keys(tb, {*_PROFILE_KEYS, "v_max", "t_ramp", "t_hold_end"}, table)
        if tb:
            sc[table] = _check_actuator(tb, table, "hold")
    h = table_of(raw, "hoist", "")
    check_keys(h, {"length", "EA", "hook_mass"}, "hoist")
    if eff["payload_swing"] or h:
        sc["hoist"] = {"length": number(h, "length", "hoist", 10.0, lo=0.0, lo_open=True),
                       "EA": number(h, "EA", "hoist", 2e8, lo=0.0, lo_open=True),
                       "hook_mass": number(h, "hook_mass", "hoist", 500.0, lo=0.0)}
    if ("hoist_drive" in sc or "hoist" in sc) and not eff["payload_swing"]:
        raise SceneError("[hoist] or [hoist_drive] with effects.payload_swing = false: the hoist "
                         "rope exists only with the swinging payload (allowed: "
                         "effects.payload_swing = true, or leave the tables out)")
    if eff["payload_swing"] and sc["payload"]["mass"] + sc["hoist"]["hook_mass"] <= 0.0:
        raise SceneError("effects.payload_swing = true with payload.mass = 0 and hoist.hook_mass "
                         "= 0: nothing hangs on the hoist rope (allowed: a positive mass)")
    profiles = {}
    for table, s0 in (("luffing_drive", math.radians(theta0)), ("slew_drive", 0.0),
                      ("hoist_drive", sc.get("hoist", {}).get("length", 0.0))):
        if table in sc:
            prof = actuators.build_profile({**sc[table], "_table": table}, s0, table, source)
            actuators.check_limits(table, sc[table], prof, t_end)
            profiles[table] = prof
    if "luffing_drive" in profiles:
        lo, hi = (math.degrees(x) for x in actuators.extremes(profiles["luffing_drive"], t_end))
        if lo < 0.0 or hi > 85.0:
            raise SceneError(f"luffing_drive: the luffing angle moves between {lo:.4g} and "
                             f"{hi:.4g} deg, outside the allowed [0, 85] deg")
        _check_luffing_history(sc, profiles["luffing_drive"], t_end)
    if "slew_drive" in profiles:
        _check_slew_history(sc, profiles.get("luffing_drive"), profiles["slew_drive"], t_end)
    if "hoist_drive" in profiles:
        lo, _ = actuators.extremes(profiles["hoist_drive"], t_end)
        if lo < 0.1:
            raise SceneError(f"hoist_drive: the hoist rope's length drops to {lo:.4g} m (allowed: "
                             "at least 0.1 m)")
    if any(k in sc for k in ("luffing_drive", "slew_drive")) or eff["payload_swing"]:
        if not eff["flexible"] or raw.get("model", {}).get("reduction", "none") != "none":
            raise SceneError("luffing, slewing or a swinging payload with effects.flexible = "
                             "false or model.reduction = 'modal': the rigid limit and the modal "
                             "tables have a fixed luffing angle and a fixed payload (allowed: "
                             "flexible booms with model.reduction = 'none')")
    for name, plugin in plugins.items():
        tb = table_of(raw, name, "")
        if tb and not sc["effects"].get(name, False):
            raise SceneError(f"[{name}] with effects.{name} = false: the table configures the "
                             f"{name} effect (allowed: effects.{name} = true, or leave it out)")
        if sc["effects"].get(name, False):
            sc[name] = plugin.validate(tb, sc)
    mo = raw.get("model", {})
    check_keys(mo, {"reduction", "n_modes"}, "model")
    sc["model"] = {"reduction": choice(mo, "reduction", "model", ("none", "modal"), "none"),
                   "n_modes": number(mo, "n_modes", "model", 3, lo=1, hi=4, integer=True)}
    if sc["model"]["reduction"] == "modal" and sc["contact"]["moment_model"] != "rigid":
        raise SceneError(f"model.reduction = 'modal' with contact.moment_model = "
                         f"{sc['contact']['moment_model']!r}: the modal tables are built with the "
                         "rigid contact sections (allowed: 'rigid')")
    if sc["model"]["reduction"] == "modal" and sc["drive"]["mechanism"] != "synchronized":
        raise SceneError(f"model.reduction = 'modal' with drive.mechanism = "
                         f"{sc['drive']['mechanism']!r}: the modal tables follow one stroke "
                         "coordinate (allowed: 'synchronized')")
    if sc["model"]["reduction"] == "modal":
        from sim_core.systems.telescopic.modal import TABLE_BOOMS
        if sc["booms"]["count"] not in TABLE_BOOMS:
            raise SceneError(f"model.reduction = 'modal' with booms.count = "
                             f"{sc['booms']['count']}: modal tables exist for booms.count "
                             f"{' or '.join(map(str, TABLE_BOOMS))} (allowed values; other counts: "
                             "model.reduction = 'none')")
    if sc["model"]["reduction"] == "modal":
        from sim_core.systems.telescopic.modal import allowed_ranges
        (p_lo, p_hi), (a_lo, a_hi), _ = allowed_ranges(n_booms=sc["booms"]["count"])
        if not p_lo <= sc["payload"]["mass"] <= p_hi:
            raise SceneError(f"payload.mass = {sc['payload']['mass']!r}: out of range, allowed "
                             f"[{p_lo:g}, {p_hi:g}] kg (the modal tables' payloads; "
                             "model.reduction = 'none' takes any payload)")
        if not a_lo <= sc["booms"]["luffing_angle_deg"] <= a_hi:
            raise SceneError(f"booms.luffing_angle_deg = {sc['booms']['luffing_angle_deg']!r}: "
                             f"out of range, allowed [{a_lo:g}, {a_hi:g}] (the modal tables' "
                             "angles; model.reduction = 'none' takes 0..85)")
    if sc["model"]["reduction"] == "modal" and sc["effects"]["friction"]:
        raise SceneError("model.reduction = 'modal' with effects.friction = true: the modal tables "
                         "are frictionless; set effects.friction = false")
    return sc


def _check_actuator(d: dict, table: str, default: str) -> dict:
    """The drive profile of an actuator table (sim_core.systems.telescopic.actuators): its kind
    and the kind's keys, positions in the table's unit (m or deg), rates per s.  The telescopic
    [drive] keeps its cubic keys (direction, v_max, t_ramp, t_hold_end) beside these."""
    out = {"profile": choice(d, "profile", table, ("hold", "cubic", "trapezoid", "table"),
                             default)}
    if table == "drive" and out["profile"] == "hold":
        raise SceneError("drive.profile = 'hold': the telescopic stages hold with a table of "
                         "one length (allowed: 'cubic', 'trapezoid', 'table')")
    kind = out["profile"]
    lo_travel = 0.0 if table == "drive" else None        # [drive]: a length, with direction
    if kind in ("cubic", "trapezoid") and "t_start" in d:
        out["t_start"] = number(d, "t_start", table, lo=0.0)
    if kind == "cubic" and table != "drive":
        out["travel"] = number(d, "travel", table)
        out["t_ramp"] = number(d, "t_ramp", table, 4.0, lo=0.0, lo_open=True)
        out["t_hold_end"] = number(d, "t_hold_end", table, lo=out["t_ramp"])
    if kind == "trapezoid":
        out["travel"] = number(d, "travel", table, lo=lo_travel, lo_open=True)
        if table != "drive":
            out["v_max"] = number(d, "v_max", table, lo=0.0, lo_open=True)
        out["a_max"] = number(d, "a_max", table, lo=0.0, lo_open=True)
        if "j_max" in d:
            out["j_max"] = number(d, "j_max", table, lo=0.0, lo_open=True)
    if kind in ("cubic", "trapezoid") and out.get("travel", 1.0) == 0.0:
        raise SceneError(f"{table}.travel = 0: allowed a nonzero travel (or profile = 'hold')")
    if kind == "table":
        if ("table" in d) == ("table_file" in d):
            raise SceneError(f"{table}: a table profile needs one of {table}.table (rows of "
                             f"[time s, position]) or {table}.table_file (a CSV file)")
        if "table" in d:
            rows = d["table"]
            if not (isinstance(rows, list) and all(isinstance(r, list) and len(r) == 2
                                                   for r in rows)):
                raise SceneError(f"{table}.table = {rows!r}: must be rows [time s, position]")
            out["table"] = [[float(x) for x in r] for r in rows]
        else:
            if not isinstance(d["table_file"], str):
                raise SceneError(f"{table}.table_file = {d['table_file']!r}: must be a path")
            out["table_file"] = d["table_file"]
    for k in ("max_rate", "max_accel"):
        if k in d:
            out[k] = number(d, k, table, lo=0.0, lo_open=True)
    own = set(_PROFILE_KEYS) | ({"v_max", "t_ramp", "t_hold_end"} if table != "drive" else set())
    unused = sorted(set(d) & own - set(out) - {"profile"})
    if unused:
        raise SceneError(f"{table}.{unused[0]}: not a key of the {kind!r} profile")
    return out


def _luffing_spec(sc: dict) -> LuffingSpec:
    if sc.get("luffing"):
        return LuffingSpec(**{k: tuple(v) for k, v in sc["luffing"].items()})
    return LuffingSpec(head_on_boom=(sc["booms"]["L_h"], -0.556))


def _check_luffing_history(sc: dict, prof, t_end: float) -> None:
    """The luffing cylinder holds the crane at every angle of the profile: a lever of at least
    0.01 m about the pivot D1 (checked at 2001 times)."""
    from sim_core.systems.telescopic.luffing import luffing_geometry
    spec = _luffing_spec(sc)
    for t in np.linspace(0.0, t_end, 2001):
        th = float(prof.sample(t).s)
        geo = luffing_geometry(th, *spec.points())
        if geo.lever < 0.01:
            raise SceneError(f"luffing_drive: at t = {t:.4g} s ({math.degrees(th):.4g} deg) the "
                             f"luffing cylinder's lever about D1 is {geo.lever:.3g} m (allowed: "
                             "at least 0.01 m; change the profile or the [luffing] points)")


def _check_slew_history(sc: dict, luff, slew, t_end: float) -> None:
    """The boom's axis stays more than 15 deg away from the lateral axis g1 of its Cardan
    reference basis (the horizontal normal of the initial luffing plane, Section 5: the
    parametrisation is singular where e_s = g1), checked at 2001 times."""
    th0 = math.radians(sc["booms"]["luffing_angle_deg"])
    for t in np.linspace(0.0, t_end, 2001):
        th = th0 if luff is None else float(luff.sample(t).s)
        ph = float(slew.sample(t).s)
        c = abs(math.cos(th) * math.sin(ph))           # |e_s . Y|
        if c > math.cos(math.radians(15.0)):
            raise SceneError(f"slew_drive: at t = {t:.4g} s the boom (luffing {math.degrees(th):.4g}"
                             f" deg, slewed {math.degrees(ph):.4g} deg) points within "
                             f"{math.degrees(math.acos(min(c, 1.0))):.3g} deg of the initial "
                             "lateral axis, where the booms' Cardan angles are singular (allowed: "
                             "more than 15 deg; slew less or luff higher)")


def _check_booms(tables: list, E0: float, rho0: float) -> list[dict]:
    """The [[boom]] tables, outermost first: length, material and section (its constants
    computed here, so a bad section fails before the run and the resolved scene records them)."""
    if not 2 <= len(tables) <= MAX_BOOMS:
        raise SceneError(f"[[boom]]: {len(tables)} tables, allowed 2..{MAX_BOOMS} booms")
    out = []
    for i, t in enumerate(tables):
        w = f"boom[{i}]"
        check_keys(t, {"length", "E", "nu", "G", "rho", "section"}, w)
        if "nu" in t and "G" in t:
            raise SceneError(f"{w}.nu and {w}.G: give one of the two (G = E / (2 (1 + nu)))")
        E = number(t, "E", w, E0, lo=1e8, hi=1e15)
        nu = number(t, "nu", w, 0.3, lo=-1.0, hi=0.5, lo_open=True, hi_open=True)
        out.append({"length": number(t, "length", w, lo=0.0, lo_open=True), "E": E,
                    "G": number(t, "G", w, E / (2.0 * (1.0 + nu)), lo=0.0, lo_open=True),
                    "rho": number(t, "rho", w, rho0, lo=10.0, hi=1e5),
                    "section": _check_section(table_of(t, "section", w), i)})
        c = out[-1]["section"]["constants"]
        if "mass_per_length" not in c:
            c["mass_per_length"] = out[-1]["rho"] * c["A"]
    return out


def _check_section(t: dict, i: int) -> dict:
    """The [boom.section] table of boom i: the shape's keys (ranges checked here, the geometry by
    sim_core.physics.cross_sections) and the constants, computed or given."""
    w = f"boom[{i}].section"
    if not t:
        raise SceneError(f"{w}: missing (required: a table with shape = 'u', 'box', 'polygon' "
                         "or 'properties')")
    shape = choice(t, "shape", w, ("u", "box", "polygon", "properties"))
    given = {k: number(t, k, w, lo=0.0, lo_open=True) for k in ("A", "I_t", "I_b", "J",
                                                               "mass_per_length") if k in t}
    for k in ("y_c", "z_c"):
        if k in t:
            given[k] = number(t, k, w, lo=-10.0, hi=10.0)
    if shape == "properties":
        for k in ("A", "I_t", "I_b", "J", "mass_per_length"):
            number(t, k, w, lo=0.0, lo_open=True)          # required
        check_keys(t, {"shape", *_GIVEN}, w)
        given.setdefault("y_c", 0.0)
        given.setdefault("z_c", 0.0)
        spec = {"shape": "properties", **given}
    else:
        geo = {k: v for k, v in t.items() if k not in _GIVEN}
        if shape == "u":
            check_keys(geo, {"shape", "top_arc_centre_y", "top_arc_centre_z", "top_arc_radius",
                             "bottom_arc_radius", "wall"}, w)
            for k in ("top_arc_centre_y", "top_arc_centre_z"):
                number(t, k, w, lo=0.0)
            number(t, "top_arc_radius", w, lo=0.0, lo_open=True)
            if "bottom_arc_radius" in t:
                number(t, "bottom_arc_radius", w, lo=0.0, lo_open=True)
        elif shape == "box":
            check_keys(geo, {"shape", "width", "height", "wall", "corner_radius"}, w)
            for k in ("width", "height"):
                number(t, k, w, lo=0.0, lo_open=True)
            if "corner_radius" in t:
                number(t, "corner_radius", w, lo=0.0)
        else:
            check_keys(geo, {"shape", "n_sides", "width_across_flats", "circumradius",
                             "rotation_deg", "contour", "wall"}, w)
            if "contour" not in t:
                number(t, "n_sides", w, lo=3, hi=24, integer=True)
                for k in ("width_across_flats", "circumradius"):
                    if k in t:
                        number(t, k, w, lo=0.0, lo_open=True)
                if "rotation_deg" in t:
                    number(t, "rotation_deg", w, lo=-180.0, hi=180.0)
        number(t, "wall", w, lo=0.0, lo_open=True)
        spec = dict(geo)
    cs = cross_section_of({**spec, "_where": w})
    constants = {"A": cs.A, "I_t": cs.I_t, "I_b": cs.I_b, "J": cs.J, "y_c": cs.y_c,
                 "z_c": cs.z_c}
    if cs.mass_per_length is not None:
        constants["mass_per_length"] = cs.mass_per_length
    constants.update(given)
    for k in ("y_c", "z_c"):                            # round-off of a symmetric section
        if abs(constants[k]) < 1e-12:
            constants[k] = 0.0
    if constants["y_c"] != 0.0:
        raise SceneError(f"{w}: mass centre y_c = {constants['y_c']:g} m off the luffing plane; "
                         "the booms' sections must be symmetric about it (allowed: y_c = 0)")
    return {**spec, "constants": {k: float(v) for k, v in constants.items()},
            "method": cs.method}


def cross_section_of(spec: dict):
    """The CrossSection of a section table (sim_core.physics.cross_sections; cached there)."""
    from sim_core.physics.cross_sections import cross_section
    spec = {k: v for k, v in spec.items() if k not in ("constants", "method")}
    return cross_section(spec)


def _check_luffing(t: dict, booms: dict, L_h: float, L1: float) -> dict:
    """The [luffing] table: the mounting points D1, D2, D3 (docs/model.md#input-luffing)."""
    check_keys(t, {"pivot", "pivot_on_boom", "base", "head_on_boom"}, "luffing")
    out = {"pivot": vector(t, "pivot", "luffing", [-0.556, 0.350], n=2),
           "pivot_on_boom": vector(t, "pivot_on_boom", "luffing", [-0.956, 0.556], n=2),
           "base": vector(t, "base", "luffing", [0.100, 0.050], n=2),
           "head_on_boom": vector(t, "head_on_boom", "luffing", [L_h, -0.556], n=2)}
    s3 = out["head_on_boom"][0]
    if "L_h" in booms and "head_on_boom" in t and s3 != L_h:
        raise SceneError(f"luffing.head_on_boom[0] = {s3:g} m and booms.L_h = {L_h:g} m: both "
                         "place the cylinder head on boom 1 (allowed: equal, or give one)")
    if not 0.0 < s3 < L1:
        raise SceneError(f"luffing.head_on_boom[0] = {s3:g} m: out of range, allowed (0, {L1:g}) "
                         "m (on boom 1, whose length is the upper bound)")
    from sim_core.systems.telescopic.luffing import luffing_geometry
    spec = _luffing_spec({"luffing": out})
    theta = math.radians(booms.get("luffing_angle_deg", 60.0))
    geo = luffing_geometry(theta, *spec.points())
    if geo.cylinder_length < 0.1 or geo.lever < 0.01:
        raise SceneError(f"luffing: the cylinder D2-D3 is {geo.cylinder_length:.3g} m long with a "
                         f"lever of {geo.lever:.3g} m about the pivot D1 at "
                         f"{math.degrees(theta):g} deg: it cannot hold the boom (allowed: a "
                         "cylinder of at least 0.1 m with a lever of at least 0.01 m)")
    return out


def _check_overlaps(tables: list, sc: dict, ls_min: float, ls_max: float) -> list[dict]:
    """The [[overlap]] tables (or their defaults), one per pair of adjacent booms, outermost
    first, with the fit of the sliders over the stroke history and of the sections."""
    n = sc["booms"]["count"]
    c = sc["contact"]
    if tables and len(tables) != n - 1:
        raise SceneError(f"[[overlap]]: {len(tables)} tables for {n} booms, allowed {n - 1} (one "
                         "per pair of adjacent booms, outermost first) or none")
    booms = sc.get("boom")
    lengths = [x["length"] for x in booms] if booms else [sc["booms"]["length"]] * n
    out = []
    for k in range(n - 1):
        t = tables[k] if tables else {}
        w = f"overlap[{k}]"
        check_keys(t, {"slider_width", "inner_slider_distance", "outer_slider_distance",
                       "radial_gap", "bears_on"}, w)
        o = {"slider_width": number(t, "slider_width", w, c["slider_width"], lo=0.0,
                                    lo_open=True),
             "inner_slider_distance": number(t, "inner_slider_distance", w, 0.0, lo=0.0),
             "outer_slider_distance": number(t, "outer_slider_distance", w, 0.0, lo=0.0),
             "radial_gap": number(t, "radial_gap", w, c["radial_gap"], lo=0.0, hi=0.05,
                                  lo_open=True),
             "bears_on": None}
        Lo, Li = lengths[k], lengths[k + 1]
        sw, d_in, d_out = o["slider_width"], o["inner_slider_distance"], o["outer_slider_distance"]
        room = (Lo - d_out) - (ls_max + d_in)
        if sw >= room:
            raise SceneError(f"{w}.slider_width = {sw:g} m does not fit the shortest overlap of "
                             f"booms {k + 1} and {k + 2}: the slider centres are {room:g} m apart "
                             f"at L_s = {ls_max:g} m (allowed: 0 < slider_width < {max(room, 0):g} "
                             "m; shorten the slider, move it or reduce the stroke)")
        reach = Li - (Lo - d_out - ls_min)
        if reach <= 0.5 * sw:
            raise SceneError(f"boom[{k + 1}].length = {Li:g} m: at L_s = {ls_min:g} m boom {k + 2} "
                             f"ends {reach:g} m past the slider of boom {k + 1} (allowed: more "
                             f"than half the slider width, {0.5 * sw:g} m; lengthen boom {k + 2} "
                             f"or set {w}.outer_slider_distance)")
        if "bears_on" in t:
            v = t["bears_on"]
            if not (isinstance(v, list) and v and all(isinstance(x, str) for x in v)):
                raise SceneError(f"{w}.bears_on = {v!r}: must be a non-empty list of patch names")
            o["bears_on"] = list(v)
        if booms:
            _check_fit(booms[k], booms[k + 1], o, k, sc["effects"]["contact_distribution"])
        elif o["bears_on"] is not None:
            raise SceneError(f"{w}.bears_on with the booms shorthand: the paper's sliders bear on "
                             "the arcs P1-P3 (allowed: describe the booms with [[boom]] tables)")
        out.append(o)
    return out


def _check_fit(outer: dict, inner: dict, o: dict, k: int, distribution: bool) -> None:
    """The inner section fits inside the outer one with the stated gap, and the sliders' patches
    exist and hold the section in every transverse direction."""
    from sim_core.physics.cross_sections import clearance
    w = f"overlap[{k}]"
    if outer["section"]["shape"] == "properties" or inner["section"]["shape"] == "properties":
        if distribution:
            raise SceneError(f"effects.contact_distribution = true with boom[{k}] or boom[{k + 1}] "
                             "given by section properties: the slider springs need the section "
                             "contour (allowed: shape 'u', 'box' or 'polygon', or "
                             "contact_distribution = false)")
        return
    co, ci = cross_section_of(outer["section"]), cross_section_of(inner["section"])
    gap = clearance(co, ci)
    # 0.1 mm: the arcs of the contours are polygons in the clearance (a sagitta below 0.1 mm)
    if gap < o["radial_gap"] - 1e-4:
        where = (f"the walls are {gap:.4g} m apart at the closest" if gap >= 0 else
                 f"the walls overlap by {-gap:.4g} m")
        raise SceneError(f"boom[{k + 1}].section does not fit inside boom[{k}].section with "
                         f"{w}.radial_gap = {o['radial_gap']:g} m: {where} (allowed: radial_gap "
                         f"<= {max(gap, 0):.4g} m, or a smaller inner section)")
    names = [pt[1] for pt in ci.patches]
    chosen = o["bears_on"]
    if chosen is not None:
        bad = [x for x in chosen if x not in names]
        if bad:
            raise SceneError(f"{w}.bears_on: {bad[0]!r} is no patch of boom[{k + 1}]'s "
                             f"{inner['section']['shape']!r} section (allowed: "
                             f"{', '.join(names)})")
    from sim_core.systems.telescopic.sliders import patches_hold, bearing_patches
    if distribution and not patches_hold(bearing_patches(ci, chosen)):
        raise SceneError(f"{w}.bears_on = {chosen!r}: the sliders' faces leave a transverse "
                         "direction unsupported (allowed: patches whose normals surround the "
                         "section, e.g. all faces)")


def params_from_scene(sc: dict):
    """TelescopicParams of a validated telescopic scene."""
    b, d = sc["booms"], sc["drive"]
    booms = None
    if sc.get("boom"):
        booms = tuple(BoomSpec(length=x["length"], E=x["E"], G=x["G"], rho=x["rho"],
                               section=None if x["section"]["shape"] == "properties"
                               else cross_section_of(x["section"]), **x["section"]["constants"])
                      for x in sc["boom"])
    overlaps = None
    if sc.get("overlap"):
        overlaps = tuple(OverlapSpec(o["slider_width"], o["inner_slider_distance"],
                                     o["outer_slider_distance"], o["radial_gap"],
                                     None if o["bears_on"] is None else tuple(o["bears_on"]))
                         for o in sc["overlap"])
    luffing = _luffing_spec(sc) if sc.get("luffing") else None
    src = sc.get("source")
    legacy = d.get("profile", "cubic") == "cubic" and "t_start" not in d
    profiles = {"drive_profile": None if legacy else
                actuators.build_profile(d, b["stroke0"], "drive", src)}
    for table, key, s0 in (("luffing_drive", "luffing_profile",
                            math.radians(b["luffing_angle_deg"])),
                           ("slew_drive", "slew_profile", 0.0),
                           ("hoist_drive", "hoist_profile", sc.get("hoist", {}).get("length"))):
        profiles[key] = (actuators.build_profile({**sc[table], "_table": table}, s0, table, src)
                         if sc.get(table) else None)
    hoist = sc.get("hoist", {})
    plugin_tables = {name: sc[name] for name in effect_plugins() if sc["effects"].get(name)}
    return TelescopicParams(
        plugin_tables=plugin_tables,
        **profiles, payload_swing=sc["effects"].get("payload_swing", False),
        hoist_length=hoist.get("length", 10.0), hoist_EA=hoist.get("EA", 2e8),
        hook_mass=hoist.get("hook_mass", 500.0),
        booms=booms, overlaps=overlaps, luffing=luffing,
        n_booms=b["count"], boom_length=b.get("length", booms[0].length if booms else 10.0),
        luffing_angle_deg=b["luffing_angle_deg"],
        stroke0=b["stroke0"], direction=1 if d["direction"] == "extraction" else -1, L_h=b["L_h"],
        E=b["E"], rho=b["rho"], payload=sc["payload"]["mass"], rope_EA=sc["ropes"]["EA"],
        gravity=sc["gravity"]["g"] if sc["effects"]["gravity"] else 0.0, n_nodes=b["n_nodes"],
        n_gauss=b["n_gauss"], filter_h=sc["filtering"]["h"] if sc["effects"]["filtering"] else 0.0,
        v_max=d["v_max"], t_ramp=d["t_ramp"], t_hold_end=d["t_hold_end"],
        mechanism=d["mechanism"],
        friction=sc["effects"]["friction"], mu_static=sc["contact"]["mu_static"],
        mu_dynamic=sc["contact"]["mu_dynamic"], v_eps=sc["contact"]["v_eps"],
        spring_k0=sc["contact"]["k0"], spring_eps=sc["contact"]["eps"],
        contact_distribution=sc["effects"]["contact_distribution"],
        slider_width=sc["contact"]["slider_width"],
        springs_per_quarter=sc["contact"]["springs_per_quarter"],
        radial_gap=sc["contact"]["radial_gap"],
        moment_model=sc["contact"]["moment_model"],
        seat_stiffness=sc["contact"]["seat_stiffness"],
        friction_load=sc["contact"]["friction_load"],
        torsion=sc["effects"]["torsion"], rope_elasticity=sc["effects"]["rope_elasticity"],
        flexible=sc["effects"]["flexible"],
        mass_centre_offset=sc["effects"]["mass_centre_offset"])
