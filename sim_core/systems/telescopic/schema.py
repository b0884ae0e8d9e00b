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
               t_hold_end s (>= t_ramp)  -- the cubic schedule of Section 9 (SCENARIOS A4);
               mechanism ("synchronized" default: the paper's cylinder-and-rope unit repeated
               along the boom, every stage moves together; "sequential": one cylinder moves
               one stage at a time, the others pinned; docs/model.md, "N-boom drives")
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
               mass_centre_offset (bool, default false: mass on the reference line; true =
               the Table 2 offsets z_c = 0.045/0.044/0.043 m as a rigid offset in inertia and
               gravity, SCENARIOS A1; the modal ROM tables are built without it)
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
Geometry rules: the stroke history must keep each boom inside its neighbour: with L_s(t) the
piston length, 0 < L_s(t) < length for all t in [0, t_end] (error names drive/booms fields).
"""

from __future__ import annotations

from typing import Any

from sim_core.errors import SceneError
from sim_core.scene.fields import ERROR_CONTROLLED, boolean, check_keys, choice, number, solver_table
from sim_core.systems.telescopic.params import MAX_BOOMS, MECHANISMS, TelescopicParams

_TOP = {"kind", "name", "description", "solver", "booms", "drive", "payload", "ropes", "effects",
        "filtering", "gravity", "contact", "notes", "model"}


def validate_telescopic(raw: dict, source: str) -> dict[str, Any]:
    check_keys(raw, _TOP, "scene")
    sc: dict[str, Any] = {"kind": "telescopic", "name": str(raw.get("name", "telescopic")),
                          "description": str(raw.get("description", "")), "source": source}
    sc["solver"] = solver_table(raw.get("solver", {}), t_end=20.0, atol=1e-7,
                                methods=ERROR_CONTROLLED)
    b = raw.get("booms", {})
    check_keys(b, {"count", "length", "luffing_angle_deg", "stroke0", "L_h", "E", "rho",
                   "n_nodes", "n_gauss"}, "booms")
    L = number(b, "length", "booms", 10.0, lo=0.0, lo_open=True)
    sc["booms"] = {"count": number(b, "count", "booms", 3, lo=2, hi=MAX_BOOMS, integer=True),
                   "length": L,
                   "luffing_angle_deg": number(b, "luffing_angle_deg", "booms", 60.0, lo=0.0, hi=85.0),
                   "stroke0": number(b, "stroke0", "booms", 2.0, lo=0.0, hi=L, lo_open=True, hi_open=True),
                   "L_h": number(b, "L_h", "booms", 7.25, lo=0.0, hi=L, lo_open=True, hi_open=True),
                   "E": number(b, "E", "booms", 2.1e11, lo=0.0, lo_open=True),
                   "rho": number(b, "rho", "booms", 7850.0, lo=0.0, lo_open=True),
                   "n_nodes": number(b, "n_nodes", "booms", 9, lo=3, hi=33, integer=True),
                   "n_gauss": number(b, "n_gauss", "booms", 5, lo=1, hi=10, integer=True)}
    d = raw.get("drive", {})
    check_keys(d, {"direction", "v_max", "t_ramp", "t_hold_end", "mechanism"}, "drive")
    t_ramp = number(d, "t_ramp", "drive", 4.0, lo=0.0, lo_open=True)
    sc["drive"] = {"direction": choice(d, "direction", "drive", ("extraction", "retraction"), "extraction"),
                   "v_max": number(d, "v_max", "drive", 0.5, lo=0.0, lo_open=True),
                   "t_ramp": t_ramp,
                   "t_hold_end": number(d, "t_hold_end", "drive", 12.0, lo=t_ramp),
                   "mechanism": choice(d, "mechanism", "drive", MECHANISMS, "synchronized")}
    travel = sc["drive"]["v_max"] * sc["drive"]["t_hold_end"]
    sign = 1 if sc["drive"]["direction"] == "extraction" else -1
    end = sc["booms"]["stroke0"] + sign * travel
    if not 0.0 < end < L:
        raise SceneError(f"drive: the stroke history moves L_s from {sc['booms']['stroke0']:g} m to "
                         f"{end:g} m, outside the allowed (0, {L:g}) m (booms.length): a boom would "
                         f"leave its neighbour; reduce drive.v_max or drive.t_hold_end "
                         f"(v_max * t_hold_end <= {(L - sc['booms']['stroke0']) if sign > 0 else sc['booms']['stroke0']:g} m)")
    pl = raw.get("payload", {})
    check_keys(pl, {"mass"}, "payload")
    sc["payload"] = {"mass": number(pl, "mass", "payload", 25000.0, lo=0.0)}
    r = raw.get("ropes", {})
    check_keys(r, {"EA"}, "ropes")
    sc["ropes"] = {"EA": number(r, "EA", "ropes", 1e8, lo=0.0, lo_open=True)}
    e = raw.get("effects", {})
    check_keys(e, {"gravity", "filtering", "friction", "contact_distribution", "torsion",
                   "rope_elasticity", "flexible", "mass_centre_offset"}, "effects")
    three = sc["booms"]["count"] == 3
    sc["effects"] = {"flexible": boolean(e, "flexible", "effects", True),
                     "torsion": boolean(e, "torsion", "effects", True),
                     "gravity": boolean(e, "gravity", "effects", True),
                     "filtering": boolean(e, "filtering", "effects", True),
                     "friction": boolean(e, "friction", "effects", False),
                     "contact_distribution": boolean(e, "contact_distribution", "effects", three),
                     "rope_elasticity": boolean(e, "rope_elasticity", "effects", True),
                     "mass_centre_offset": boolean(e, "mass_centre_offset", "effects", False)}
    eff = sc["effects"]
    if eff["contact_distribution"] and not three:
        raise SceneError(f"effects.contact_distribution = true with booms.count = "
                         f"{sc['booms']['count']}: the slider geometry is the paper's three-boom "
                         "section (allowed: booms.count = 3, or contact_distribution = false)")
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
    ls_max = max(sc["booms"]["stroke0"], end)
    overlap = L - ls_max
    if sc["contact"]["slider_width"] >= overlap:
        raise SceneError(f"contact.slider_width = {sc['contact']['slider_width']:g} m does not fit "
                         f"the shortest overlap of adjacent booms, booms.length - max L_s = "
                         f"{overlap:g} m (allowed: 0 < slider_width < {overlap:g} m)")
    f = raw.get("filtering", {})
    check_keys(f, {"h"}, "filtering")
    sc["filtering"] = {"h": number(f, "h", "filtering", 0.01, lo=0.0, lo_open=True)}
    g = raw.get("gravity", {})
    check_keys(g, {"g"}, "gravity")
    sc["gravity"] = {"g": number(g, "g", "gravity", 9.81, lo=0.0, lo_open=True)}
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
    if sc["model"]["reduction"] == "modal" and sc["effects"]["friction"]:
        raise SceneError("model.reduction = 'modal' with effects.friction = true: the modal tables "
                         "are frictionless; set effects.friction = false")
    return sc


def params_from_scene(sc: dict):
    """TelescopicParams of a validated telescopic scene."""
    b, d = sc["booms"], sc["drive"]
    return TelescopicParams(
        n_booms=b["count"], boom_length=b["length"], luffing_angle_deg=b["luffing_angle_deg"],
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
