"""Scene schema of the telescopic boom system (kind = "telescopic"), SI units.

Every key is declared once in :data:`SCHEMA` (type, unit, default, allowed range, note) and read
through the declarations (:mod:`sim_core.scene.fields`), so an error names the dotted field,
the value and the declared range; the scene reference of the documentation is rendered from
the same declarations.  The effect plug-ins (:mod:`sim_core.physics.plugins`) declare their
own tables.  Rules across keys (the stroke history keeps every boom inside its neighbour, the
sliders fit their overlaps, the sections fit inside each other, ...) are listed in
``SCHEMA.rules`` and checked below.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sim_core.errors import SceneError
from sim_core.physics.plugins import effect_plugins
from sim_core.scene.fields import (
    COMPUTED,
    ERROR_CONTROLLED,
    OPTIONAL,
    REQUIRED,
    T_MAX,
    Field,
    Schema,
    Table,
    check_keys,
    read_text,
    short_repr,
    solver_fields,
    solver_table,
    table_of,
    tables_of,
    text_fields,
    time_field,
)
from sim_core.systems.telescopic import actuators, telescoping
from sim_core.systems.telescopic.params import (
    MAX_BOOMS,
    MECHANISMS,
    BoomSpec,
    LuffingSpec,
    OverlapSpec,
    TelescopicParams,
)

# -- the declarations ---------------------------------------------------------------------------

#: the longest boom section, m; the farthest mounting point from the crane's base frame, m
L_MAX, X_MAX = 100.0, 50.0
#: the largest extent of a boom's cross-section, m
SEC_MAX = 10.0
#: the steel ropes' and hoist rope's axial stiffness EA, N (a thin wire to a 20-fall reeving)
EA_RANGE = dict(lo=1e4, hi=1e11)
#: Young's modulus, Pa: from soft polymers to ten times diamond (the nearly rigid booms of the
#: paper's Section 9.1 have 2.1e12); density, kg/m^3: from foams to osmium
E_RANGE, RHO_RANGE = dict(lo=1e8, hi=1e15), dict(lo=10.0, hi=1e5)

TOP = Table("", (Field("kind", "choice", choices=("telescopic",)), *text_fields("telescopic")),
            tables=("solver", "booms", "boom", "luffing", "drive", "payload", "ropes",
                    "effects", "contact", "overlap", "filtering", "gravity", "luffing_drive",
                    "slew_drive", "hoist_drive", "hoist", "oil_column", "model", "ground",
                    "stage_drive", "telescoping", "material"))
#: the error-controlled methods and the Rosenbrock-W training integrator (fixed step)
TELESCOPIC_METHODS = ERROR_CONTROLLED + ("ROS2",)
SOLVER = solver_fields(t_end=20.0, atol=1e-7, methods=TELESCOPIC_METHODS)
BOOMS = Table("booms", (
    Field("count", "integer", "", COMPUTED, lo=2, hi=MAX_BOOMS,
          default_text="3, or the number of [[boom]] tables",
          note="sections of the crane: the paper's three booms are the innermost three, larger "
               "sections of the same family outside them (params.crane_sections)"),
    Field("length", "number", "m", 10.0, lo=1.0, hi=L_MAX,
          applies="the shorthand (no [[boom]] tables)", note="every boom's length"),
    Field("luffing_angle_deg", "number", "deg", 60.0, lo=0.0, hi=85.0,
          note="luffing angle of the rigid crane at t = 0"),
    Field("stroke0", "number", "m", 2.0, lo=1e-3, hi=L_MAX, hi_open=True,
          allowed="[0.001, shortest boom length) m", note="piston-rod length L_s at t = 0"),
    Field("L_h", "number", "m", 7.25, lo=1e-3, hi=L_MAX, hi_open=True,
          allowed="[0.001, length of boom 1) m", note="luffing point on boom 1"),
    Field("E", "number", "Pa", 2.1e11, **E_RANGE, note="Young's modulus of every boom"),
    Field("rho", "number", "kg/m^3", 7850.0, **RHO_RANGE, note="density of every boom"),
    Field("n_nodes", "integer", "", 9, lo=3, hi=33,
          note="nodes per spline element (paper 9 = 8 sub-elements)"),
    Field("n_gauss", "integer", "", 5, lo=1, hi=10, note="Gauss points per sub-element"),
), note="the booms shorthand: the paper's U-section family")
BOOM = Table("boom[]", (
    Field("length", "number", "m", REQUIRED, lo=1.0, hi=L_MAX),
    Field("E", "number", "Pa", COMPUTED, **E_RANGE, default_text="booms.E"),
    Field("nu", "number", "", 0.3, lo=-1.0, hi=0.5, lo_open=True, hi_open=True,
          note="Poisson's ratio (or give G)"),
    Field("G", "number", "Pa", COMPUTED, lo=1e7, hi=1e15, default_text="E / (2 (1 + nu))",
          note="shear modulus (or give nu)"),
    Field("rho", "number", "kg/m^3", COMPUTED, **RHO_RANGE, default_text="booms.rho"),
), tables=("section",),
    note="a crane described boom by boom, outermost first (replaces booms.length and the "
         "shorthand sections; booms.count, when given, equals the number of tables)")

_U, _BOX, _POLY, _PROPS = ("u",), ("box",), ("polygon",), ("properties",)
_SHAPES = ("u", "box", "polygon")
_GIVEN = ("A", "I_t", "I_b", "J", "mass_per_length", "y_c", "z_c")   # constants a table may give
_GIVEN_NOTE = ("required with shape \"properties\"; beside another shape it replaces the value "
               "computed from the contour")
_CENTRE = 'from the contour; 0 with shape "properties"'
SECTION = Table("boom[].section", (
    Field("shape", "choice", choices=("u", "box", "polygon", "properties"),
          note="\"u\", \"box\" and \"polygon\": the constants come from a finite-element "
               "section analysis (sectionproperties); \"properties\": given"),
    Field("top_arc_centre_y", "number", "m", REQUIRED, lo=0.0, hi=SEC_MAX, when=_U,
          applies='shape = "u"'),
    Field("top_arc_centre_z", "number", "m", REQUIRED, lo=0.0, hi=SEC_MAX, when=_U,
          applies='shape = "u"'),
    Field("top_arc_radius", "number", "m", REQUIRED, lo=1e-3, hi=SEC_MAX, when=_U,
          applies='shape = "u"', note="outer radius r of the top arcs"),
    Field("bottom_arc_radius", "number", "m", COMPUTED, lo=1e-3, hi=SEC_MAX,
          when=_U, applies='shape = "u"', default_text="top_arc_centre_y + top_arc_radius",
          note="outer radius R of the bottom arc"),
    Field("width", "number", "m", REQUIRED, lo=1e-3, hi=SEC_MAX, when=_BOX,
          applies='shape = "box"'),
    Field("height", "number", "m", REQUIRED, lo=1e-3, hi=SEC_MAX, when=_BOX,
          applies='shape = "box"'),
    Field("corner_radius", "number", "m", 0.0, lo=0.0, hi=SEC_MAX / 2, when=_BOX,
          applies='shape = "box"', note="outer radius of the corners"),
    Field("n_sides", "integer", "", REQUIRED, lo=3, hi=24, when=_POLY,
          applies='shape = "polygon" without contour'),
    Field("width_across_flats", "number", "m", OPTIONAL, lo=1e-3, hi=SEC_MAX,
          when=_POLY, applies='shape = "polygon", even n_sides',
          note="give it or circumradius"),
    Field("circumradius", "number", "m", OPTIONAL, lo=1e-3, hi=SEC_MAX,
          when=_POLY, applies='shape = "polygon"', note="give it or width_across_flats"),
    Field("rotation_deg", "number", "deg", 0.0, lo=-180.0, hi=180.0, when=_POLY,
          applies='shape = "polygon"', note="rotation of the polygon about the section centre"),
    Field("contour", "rows", "m", OPTIONAL, items=(3, 1000),
          columns=((-SEC_MAX, SEC_MAX, "m"), (-SEC_MAX, SEC_MAX, "m")), when=_POLY,
          applies='shape = "polygon"',
          note="outer vertices [y, z], counter-clockwise (instead of n_sides)"),
    Field("wall", "number", "m", REQUIRED, lo=1e-4, hi=0.5, when=_SHAPES,
          applies='shape "u", "box", "polygon"', note="wall thickness"),
    Field("A", "number", "m^2", OPTIONAL, lo=1e-8, hi=10.0, note=_GIVEN_NOTE),
    Field("I_t", "number", "m^4", OPTIONAL, lo=1e-16, hi=100.0, note=_GIVEN_NOTE),
    Field("I_b", "number", "m^4", OPTIONAL, lo=1e-16, hi=100.0, note=_GIVEN_NOTE),
    Field("J", "number", "m^4", OPTIONAL, lo=1e-16, hi=100.0,
          note="St. Venant torsion constant; " + _GIVEN_NOTE),
    Field("mass_per_length", "number", "kg/m", OPTIONAL, lo=1e-3, hi=1e5,
          note="default rho A; " + _GIVEN_NOTE + " (a mass with fittings, say)"),
    Field("y_c", "number", "m", COMPUTED, lo=-SEC_MAX, hi=SEC_MAX, default_text=_CENTRE,
          note="mass centre across the luffing plane (the section's must be 0)"),
    Field("z_c", "number", "m", COMPUTED, lo=-SEC_MAX, hi=SEC_MAX, default_text=_CENTRE,
          note="mass centre, vertical"),
), note="each boom's cross-section")
LUFFING = Table("luffing", (
    Field("pivot", "vector", "m", [-0.556, 0.350], n=2, lo=-X_MAX, hi=X_MAX,
          note="D1 in global X and Z"),
    Field("pivot_on_boom", "vector", "m", [-0.956, 0.556], n=2, lo=-X_MAX, hi=X_MAX,
          note="D1 in boom 1's left-section frame (axial, vertical)"),
    Field("base", "vector", "m", [0.100, 0.050], n=2, lo=-X_MAX, hi=X_MAX,
          note="the cylinder base D2 in global X and Z"),
    Field("head_on_boom", "vector", "m", COMPUTED, n=2, lo=-X_MAX, hi=X_MAX,
          default_text="[booms.L_h, -0.556]",
          note="the cylinder head D3 in boom 1's left-section frame; its axial coordinate is "
               "the luffing point L_h, in (0, length of boom 1)"),
), note="the luffing cylinder's mounting points (docs/model.md#input-luffing)")


def actuator_table(name: str, unit: str, travel: tuple, rate: float, accel: float,
                   jerk: float, position: tuple, what: str) -> Table:
    """The declared table of an actuator's drive profile (sim_core.systems.telescopic.
    actuators): positions in ``unit`` (m or deg), travel in ``travel`` (lo, hi), rates up to
    ``rate`` per s, accelerations up to ``accel`` per s^2, jerks up to ``jerk`` per s^3, table
    positions in ``position`` (lo, hi)."""
    drive = name == "drive"
    prof = ("cubic", "trapezoid", "table") if drive else ("hold", "cubic", "trapezoid", "table")
    cubic, trap, tab = ("cubic",), ("trapezoid",), ("table",)
    fields = []
    if drive:
        fields += [
            Field("direction", "choice", default="extraction",
                  choices=("extraction", "retraction"), note="the sign of the stroke"),
            Field("v_max", "number", f"{unit}/s", 0.5, lo=1e-4, hi=rate,
                  note="peak stroke rate (cubic and trapezoid profiles)"),
            Field("t_ramp", "number", "s", 4.0, lo=1e-3, hi=T_MAX,
                  note="length of each ramp of the cubic schedule"),
            Field("t_hold_end", "number", "s", 12.0, lo=1e-3, hi=T_MAX,
                  allowed=f"[t_ramp, {T_MAX:g}] s", note="end of the constant-rate hold"),
            Field("mechanism", "choice", default="synchronized", choices=MECHANISMS,
                  note="\"synchronized\": the paper's cylinder-and-rope unit repeated along "
                       "the boom, every stage moves together; \"sequential\": one cylinder "
                       "moves one stage at a time, the others pinned (docs/model.md, \"N-boom "
                       "drives\"); \"independent\": a cylinder per stage on its own "
                       "[[stage_drive]] profile; \"single_cylinder\": one cylinder moves one "
                       "stage at a time between the pins of [telescoping] (docs/user_guide.md, "
                       "\"Telescoping sequences\")"),
        ]
    fields += [
        Field("profile", "choice", default="cubic" if drive else "hold", choices=prof,
              note=("\"cubic\": the paper's schedule (Section 9); " if drive else
                    "\"hold\": no motion; \"cubic\": the paper's schedule (Section 9); ")
              + "\"trapezoid\": acceleration-limited, jerk-limited with j_max; \"table\": "
                "time and position rows"),
        Field("travel", "number", unit, REQUIRED, lo=travel[0], hi=travel[1],
              when=trap if drive else cubic + trap,
              applies='profile "trapezoid"' if drive else 'profile "cubic" or "trapezoid"',
              allowed=(None if drive else
                       f"[{travel[0]:g}, {travel[1]:g}] {unit}, not 0") or "",
              note="stroke length, its sign from direction" if drive else "signed"),
    ]
    if not drive:
        fields += [
            Field("t_ramp", "number", "s", 4.0, lo=1e-3, hi=T_MAX, when=cubic,
                  applies='profile "cubic"'),
            Field("t_hold_end", "number", "s", REQUIRED, lo=1e-3, hi=T_MAX,
                  when=cubic, applies='profile "cubic"', allowed=f"[t_ramp, {T_MAX:g}] s"),
            Field("v_max", "number", f"{unit}/s", REQUIRED, lo=1e-4, hi=rate,
                  when=trap, applies='profile "trapezoid"'),
        ]
    fields += [
        Field("a_max", "number", f"{unit}/s^2", REQUIRED, lo=1e-4, hi=accel,
              when=trap, applies='profile "trapezoid"'),
        Field("j_max", "number", f"{unit}/s^3", OPTIONAL, lo=1e-4, hi=jerk,
              when=trap, applies='profile "trapezoid"', note="a jerk-limited S-curve"),
        time_field("t_start", 0.0, when=cubic + trap, applies='profile "cubic" or "trapezoid"',
                   note="when the motion starts"),
        Field("table", "rows", unit, OPTIONAL, items=(2, 100000),
              columns=((0.0, T_MAX, "s"), (position[0], position[1], unit)), when=tab,
              applies='profile "table"',
              note="rows [time, position], times increasing"
                   + ("; the first position is booms.stroke0" if drive else "")
                   + " (or table_file)"),
        Field("table_file", "string", default=OPTIONAL, when=tab, applies='profile "table"',
              note="a CSV file of time and position, relative to the scene file; it lies "
                   "inside the scene file's folder or a folder of BOOM_SIM_DATA_DIR, at most "
                   "1 MiB and 20000 rows (docs/security.md)"),
        Field("max_rate", "number", f"{unit}/s", OPTIONAL, lo=1e-4, hi=rate,
              note="the actuator's rate limit, checked against the profile"),
        Field("max_accel", "number", f"{unit}/s^2", OPTIONAL, lo=1e-4, hi=accel,
              note="the actuator's acceleration limit, checked against the profile"),
    ]
    return Table(name, tuple(fields), note=what)


DRIVE = actuator_table("drive", "m", (1e-3, L_MAX), 5.0, 10.0, 100.0, (0.0, L_MAX),
                       "the telescopic cylinders: the stage length L_s (m) from booms.stroke0")
LUFFING_DRIVE = actuator_table(
    "luffing_drive", "deg", (-85.0, 85.0), 30.0, 100.0, 1000.0, (0.0, 85.0),
    "the luffing cylinder: the luffing angle of the rigid crane (deg) from "
    "booms.luffing_angle_deg; it stays in [0, 85] deg")
SLEW_DRIVE = actuator_table(
    "slew_drive", "deg", (-3600.0, 3600.0), 60.0, 100.0, 1000.0, (-3600.0, 3600.0),
    "the slewing drive: the slew angle about the vertical (deg) from 0, a turntable under the "
    "pivot and the cylinder base")
HOIST_DRIVE = actuator_table(
    "hoist_drive", "m", (-1000.0, 1000.0), 10.0, 20.0, 200.0, (0.1, 1000.0),
    "the hoist: the unstretched hoist-rope length (m) from hoist.length; it stays at least "
    "0.1 m")
ACTUATOR_TABLES = {t.path: t for t in (DRIVE, LUFFING_DRIVE, SLEW_DRIVE, HOIST_DRIVE)}
_STAGE = actuator_table(
    "stage_drive[]", "m", (-L_MAX, L_MAX), 5.0, 10.0, 100.0, (0.0, L_MAX),
    'one stage\'s cylinder of drive.mechanism = "independent", one table per stage, stage 1 '
    "(boom 2 in boom 1) first: the stage length L_s,k (m), the distance of the two booms' left "
    "sections, from length0 (docs/user_guide.md, \"Telescoping sequences\")")
STAGE_DRIVE = Table(_STAGE.path, (
    Field("length0", "number", "m", COMPUTED, lo=1e-3, hi=L_MAX, default_text="booms.stroke0",
          allowed="(0, shortest boom length) m; a table profile's first length",
          note="the stage length at t = 0"), *_STAGE.fields), note=_STAGE.note)
# each stage's table is read as an actuator table of its own name (stage_drive[k])
ACTUATOR_TABLES.update({telescoping.stage_table(k): STAGE_DRIVE for k in range(MAX_BOOMS - 1)})

PAYLOAD = Table("payload", (
    # the heaviest lifts of mobile cranes are ~1200 t
    Field("mass", "number", "kg", 25000.0, lo=0.0, hi=2e6, note="the payload at the tip"),
))
MATERIAL = Table("material", (
    # from mild structural steel to the ultra-high-strength steels of crane booms (S1300)
    Field("f_y", "number", "Pa", 355e6, lo=100e6, hi=2000e6,
          note="yield strength of the booms (output section_utilisation = von Mises / f_y); "
               "default S355"),
))
ROPES = Table("ropes", (
    Field("EA", "number", "N", 1e8, **EA_RANGE, note="axial stiffness of the telescoping ropes"),
))


def _effects_table() -> Table:
    plugins = effect_plugins()
    return Table("effects", (
        Field("flexible", "boolean", default=True,
              note="false = rigid booms, the kinematic limit of sim_core.systems.telescopic."
                   "rigid: no beams, no contact constraints"),
        Field("torsion", "boolean", default=True,
              note="false = torsion angles held at zero, the twist rows of the angle "
                   "constraints dropped"),
        Field("gravity", "boolean", default=True),
        Field("filtering", "boolean", default=True, note="stress averaging over [filtering] h"),
        Field("friction", "boolean", default=False,
              note="Coulomb friction on the contact coordinates (Section 8.3)"),
        Field("contact_distribution", "boolean", default=COMPUTED,
              default_text="true for 3 booms or [[boom]] tables, else false",
              note="slider-spring analysis of Section 8, output slider_contact_forces; false = "
                   "only the constraint resultants"),
        Field("rope_elasticity", "boolean", default=True,
              note="elastic tension-only ropes with [ropes] EA; false = one inextensible rope "
                   "constraint, output rope_tension"),
        Field("mass_centre_offset", "boolean", default=False,
              note="true = the Table 2 offsets z_c = 0.045/0.044/0.043 m as a rigid offset in "
                   "inertia and gravity (docs/model.md#input-sections); the modal tables are "
                   "built without it"),
        Field("payload_swing", "boolean", default=False,
              note="the payload and hook hang on the elastic hoist rope of [hoist] and swing; "
                   "false = a point mass fixed at the tip"),
        Field("ground", "boolean", default=False,
              note="the swinging payload stands on the ground of [ground] (unilateral "
                   "spring-damper contact, output payload_ground_force): the lift-off load case"),
        Field("oil_column", "boolean", default=False,
              note="the telescopic cylinder drives its stage through the compressible oil of "
                   "[oil_column] (the stages can stick and slip on their sliders); false = the "
                   "stage length follows the drive exactly (a constraint)"),
        *(Field(name, "boolean", default=False,
                note=f"an effect plug-in ({p.validate.__module__}): {p.description}")
          for name, p in plugins.items()),
    ), note="what is off is not built (each a separate contribution to the model)")


EFFECTS = _effects_table()
CONTACT = Table("contact", (
    Field("mu_static", "number", "", 0.15, lo=0.0, hi=2.0,
          note="static friction coefficient of the sliders"),
    Field("mu_dynamic", "number", "", 0.1, lo=0.0, hi=2.0,
          note="dynamic friction coefficient of the sliders"),
    Field("v_eps", "number", "m/s", 0.01, lo=1e-6, hi=1.0,
          note="switching speed of the friction law"),
    Field("k0", "number", "N/m", 1e9, lo=1e4, hi=1e12, note="radial slider-spring stiffness"),
    Field("eps", "number", "m", 1e-6, lo=1e-9, hi=1e-2,
          note="smoothing interval of the spring stiffness"),
    Field("slider_width", "number", "m", 0.3, lo=1e-3, hi=5.0,
          allowed="[0.001, 5] m, and shorter than the smallest overlap",
          note="2w, the sliders' length along the boom"),
    Field("springs_per_quarter", "integer", "", 20, lo=1, hi=200,
          note="springs per quarter arc and slider end"),
    # a gap wider than 50 mm would put the contact circle of the 75 mm top arcs near their
    # centre (Table 1 radii)
    Field("radial_gap", "number", "m", 0.005, lo=1e-4, hi=0.05,
          note="sliding-block thickness between the walls; sets the contact-circle radius "
               "(Table 1: 5 mm)"),
    # the default: the model whose pad reactions and tip deflection are those of two-pad statics
    # for a crane described boom by boom (docs/model.md#contact-models,
    # tests/telescopic/test_pad_statics.py); the shorthand keeps Section 6 as printed
    Field("moment_model", "choice", default=COMPUTED, choices=("rigid", "seat", "couple"),
          default_text="\"couple\" for [[boom]] cranes, \"rigid\" for the [booms] shorthand",
          note="\"rigid\": Section 6, the contact sections' Cardan angles coincide; \"seat\": "
               "the two bending angles tied by an elastic seat of seat_stiffness; \"couple\": "
               "the bending angles free, the overlap carries its moment as a force couple "
               "between its two pads (two-pad statics, what a design calculation assumes)"),
    # a polyamide pad (E = 3 GPa) 20 mm thick on a 0.3 m x 0.3 m footprint rocking about its
    # centre: E/t * b (2w)^3 / 12 = 1.0e8 N m/rad
    Field("seat_stiffness", "number", "N m/rad", 1e8, lo=1e3, hi=1e12,
          applies='moment_model = "seat"',
          note="default: a 20 mm polyamide pad, E = 3 GPa, on a 0.3 m x 0.3 m footprint"),
    Field("friction_load", "choice", default="resultant", choices=("resultant", "springs"),
          note="\"resultant\": the friction's normal load is the transverse contact resultant; "
               "\"springs\": the sum of the slider springs (Eq. 72 literally, needs "
               "contact_distribution); docs/validation.md says why"),
), note="the sliders between the booms")
OVERLAP = Table("overlap[]", (
    Field("slider_width", "number", "m", COMPUTED, lo=1e-3, hi=5.0,
          default_text="contact.slider_width", allowed="[0.001, 5] m, and fits the overlap"),
    Field("inner_slider_distance", "number", "m", 0.0, lo=0.0, hi=L_MAX,
          note="the inner boom's slider centre from that boom's left end"),
    Field("outer_slider_distance", "number", "m", 0.0, lo=0.0, hi=L_MAX,
          note="the outer boom's slider centre from its right end"),
    Field("radial_gap", "number", "m", COMPUTED, lo=1e-4, hi=0.05,
          default_text="contact.radial_gap"),
    Field("bears_on", "strings", default=OPTIONAL, items=(1, 64),
          note="the inner boom's outer-face patches the sliders bear on: \"u\" P1, P2, P3, "
               "flange, side_right, side_left; \"box\" bottom, right, top, left, corner_br, "
               "corner_tr, corner_tl, corner_bl; \"polygon\" face_1..face_n from the bottom "
               "face counter-clockwise (default: P1-P3 for \"u\", every patch otherwise)"),
), note="the sliders of each overlap, outermost pair first (all or none)")
FILTERING = Table("filtering", (
    Field("h", "number", "s", 0.01, lo=1e-4, hi=1.0,
          note="stress-averaging window (SIMULTECH 2020 Eq. 53)"),
))
GRAVITY = Table("gravity", (
    Field("g", "number", "m/s^2", 9.81, lo=0.0, hi=100.0, lo_open=True, note="along -Z"),
))
HOIST = Table("hoist", (
    Field("length", "number", "m", 10.0, lo=0.1, hi=1000.0, note="unstretched, at t = 0"),
    Field("EA", "number", "N", 2e8, **EA_RANGE, note="axial stiffness of the hoist rope"),
    Field("hook_mass", "number", "kg", 500.0, lo=0.0, hi=1e5, note="hangs with the payload"),
), note="the hoist rope of effects.payload_swing")
GROUND = Table("ground", (
    Field("height", "number", "m", 0.0, lo=-1000.0, hi=1000.0,
          note="the ground plane Z = height in the crane's global frame (Z up)"),
    Field("stiffness", "number", "N/m", 1e8, lo=1e3, hi=1e12,
          note="penalty stiffness k of the contact (sim_core.physics.ground_contact)"),
    Field("damping", "number", "N s/m", 1e5, lo=0.0, hi=1e9,
          note="damper c of the contact, faded in over ramp_width; the force never pulls"),
    Field("ramp_width", "number", "m", 1e-4, lo=1e-7, hi=0.1,
          note="the spring's C1 ramp at first touch (as the ropes' slack_width)"),
), note="the ground under the payload of effects.ground (the payload starts on it)")
OIL_COLUMN = Table("oil_column", (
    Field("cylinder_area", "number", "m^2", 0.02, lo=1e-4, hi=1.0,
          note="piston area A"),
    Field("bulk_modulus", "number", "Pa", 1e9, lo=1e7, hi=1e11,
          note="effective bulk modulus beta of the oil with hoses"),
    Field("dead_length", "number", "m", 0.5, lo=0.01, hi=10.0,
          note="l_0: the oil in hoses and the cylinder's end as piston travel; k_h = beta A / "
               "(l + l_0)"),
    Field("damping_ratio", "number", "", 0.2, lo=0.0, hi=2.0,
          note="valve and leakage losses: c_h = 2 zeta sqrt(k_h M_s), M_s the stroke mass"),
), note="the telescopic cylinder's oil column of effects.oil_column (Merritt 1967, Sec. 5.2)")
MODEL = Table("model", (
    Field("reduction", "choice", default="none", choices=("none", "modal"),
          note="\"none\" = full model; \"modal\" = the stroke-parametric modal ROM of "
               "sim_core.systems.telescopic.modal (tables built from the full model for 3 and 5 "
               "booms, synchronized drive, frictionless)"),
    Field("n_modes", "integer", "", 3, lo=1, hi=4, note="in-plane modes kept by the ROM"),
))


def _plugin_tables() -> tuple[Table, ...]:
    return tuple(p.fields for p in effect_plugins().values() if p.fields is not None)


SCHEMA = Schema(
    "telescopic", 'Telescopic scenes (`kind = "telescopic"`)',
    "sim_core.systems.telescopic.schema.validate_telescopic",
    (TOP, SOLVER, BOOMS, BOOM, SECTION, LUFFING, DRIVE, STAGE_DRIVE, telescoping.TELESCOPING,
     PAYLOAD, MATERIAL, ROPES, EFFECTS, CONTACT,
     OVERLAP, FILTERING, GRAVITY, LUFFING_DRIVE, SLEW_DRIVE, HOIST_DRIVE, HOIST, GROUND,
     OIL_COLUMN, MODEL,
     *_plugin_tables()),
    rules=(
        "The stroke history keeps every boom inside its neighbour: 0 < L_s(t) < the shortest "
        "boom length for t in [0, solver.t_end] (the cubic drive: v_max t_hold_end bounded by "
        "the room left).",
        "booms.length and [[boom]] tables exclude each other; booms.count, when given, equals "
        "the number of [[boom]] tables; a [[boom]] table gives nu or G, not both.",
        "The two sliders of every overlap fit its shortest length, the inner boom reaches past "
        "the outer boom's slider, and every inner section fits inside its outer one with the "
        "stated radial gap; [[overlap]] has one table per pair of adjacent booms or none.",
        "A boom's section is symmetric about the luffing plane (its mass centre y_c = 0); its "
        "outer contour is at most 1000 walls long (width to wall about 250).",
        "luffing.head_on_boom[0] and booms.L_h agree where both are given; the luffing "
        "cylinder is at least 0.1 m long with a lever of at least 0.01 m about the pivot D1 at "
        "every angle of the luffing profile.",
        "drive.profile \"trapezoid\" or \"table\" needs drive.mechanism = \"synchronized\"; a "
        "drive table's first length equals booms.stroke0 where both are given.",
        "A profile's keys belong to its kind (travel, t_ramp, t_hold_end to \"cubic\"; travel, "
        "v_max, a_max, j_max to \"trapezoid\"; one of table or table_file to \"table\"); a "
        "travel is not 0; the profile's largest rate and acceleration stay within max_rate "
        "and max_accel.",
        "drive.mechanism \"independent\" takes one [[stage_drive]] table per stage, "
        "\"single_cylinder\" a [telescoping] table, and [drive] then holds only the mechanism; "
        "the pins increase, every stage starts at a pin, every move takes an existing stage to "
        "a pin other than its current one; every stage length stays in (0, the shortest boom "
        "length) m and the sliders fit every overlap at the longest and shortest stage length.",
        "The slew keeps the boom's axis more than 15 deg from the lateral axis of the initial "
        "luffing plane, where the booms' Cardan angles are singular.",
        "[oil_column] needs effects.oil_column = true, which needs flexible booms, the "
        "synchronized drive and model.reduction = \"none\".",
        "[hoist] and [hoist_drive] need effects.payload_swing = true; a swinging payload needs "
        "a positive payload.mass + hoist.hook_mass.",
        "[ground] needs effects.ground = true, which needs effects.payload_swing = true.",
        "effects.flexible = false (the rigid limit): booms.count 2 or 3, the synchronized "
        "drive, no friction, moment_model \"rigid\", no [[boom]] tables, no luffing, slewing or "
        "swinging payload.",
        "contact.friction_load = \"springs\" needs effects.contact_distribution = true, which "
        "needs sections with a contour (not \"properties\").",
        "model.reduction = \"modal\": booms.count 3 or 5, the synchronized drive on the cubic "
        "profile from t = 0, no friction, moment_model \"rigid\", payload.mass, "
        "booms.luffing_angle_deg and the stroke history within the modal tables' ranges (3 "
        "booms: 20-30 t, 45-75 deg, L_s in [1.75, 8.25] m), the crane the tables were built "
        "from (the defaults of booms.length, L_h, E, rho, ropes.EA, gravity, filtering, "
        "torsion, rope_elasticity, flexible), no [[boom]] tables, no mass-centre offset, effect "
        "plug-in, luffing, slewing or swinging payload.",
        "An effect plug-in's table ([wind]) needs its switch effects.<name> = true; the wind "
        "needs sections with a contour.",
    ))


# -- the validator --------------------------------------------------------------------------

def validate_telescopic(raw: dict, source: str) -> dict[str, Any]:
    plugins = effect_plugins()
    TOP.check_keys(raw, "scene", extra=plugins)
    TOP.read(raw, "kind", "scene")
    sc: dict[str, Any] = {"kind": "telescopic"}
    read_text(raw, TOP, sc, "telescopic")
    sc["source"] = source
    sc["solver"] = solver_table(table_of(raw, "solver", ""), t_end=20.0, atol=1e-7,
                                methods=TELESCOPIC_METHODS)
    b = table_of(raw, "booms", "")
    BOOMS.check_keys(b, "booms")
    boom_tables = tables_of(raw, "boom")
    if boom_tables and "length" in b:
        raise SceneError("booms.length with [[boom]] tables: every [[boom]] gives its own length "
                         "(allowed: booms.length or [[boom]] lengths, not both)")
    if boom_tables and b.get("count", len(boom_tables)) != len(boom_tables):
        raise SceneError(f"booms.count = {short_repr(b['count'])} with {len(boom_tables)} "
                         "[[boom]] tables: the count must equal the number of tables (or be "
                         "left out)")
    E = BOOMS.read(b, "E", "booms")
    rho = BOOMS.read(b, "rho", "booms")
    if boom_tables:
        sc["boom"] = _check_booms(boom_tables, E, rho)
        L1, Lmin = sc["boom"][0]["length"], min(x["length"] for x in sc["boom"])
    else:
        L1 = Lmin = BOOMS.read(b, "length", "booms")
    sc["booms"] = {"count": BOOMS.read(b, "count", "booms", default=len(boom_tables) or 3),
                   "luffing_angle_deg": BOOMS.read(b, "luffing_angle_deg", "booms"),
                   "stroke0": BOOMS.read(b, "stroke0", "booms", hi=Lmin, hi_open=True),
                   "L_h": BOOMS.read(b, "L_h", "booms", hi=L1, hi_open=True),
                   "E": E, "rho": rho,
                   "n_nodes": BOOMS.read(b, "n_nodes", "booms"),
                   "n_gauss": BOOMS.read(b, "n_gauss", "booms")}
    if not boom_tables:
        sc["booms"] = {"count": sc["booms"]["count"], "length": L1,
                       **{k: v for k, v in sc["booms"].items() if k != "count"}}
    lf = table_of(raw, "luffing", "")
    if lf:
        sc["luffing"] = _check_luffing(lf, b, sc["booms"]["L_h"], L1)
        sc["booms"]["L_h"] = sc["luffing"]["head_on_boom"][0]
    d = table_of(raw, "drive", "")
    check_keys(d, DRIVE.all_keys(), "drive")
    t_ramp = DRIVE.read(d, "t_ramp", "drive")
    sc["drive"] = {"direction": DRIVE.read(d, "direction", "drive"),
                   "v_max": DRIVE.read(d, "v_max", "drive"),
                   "t_ramp": t_ramp,
                   "t_hold_end": DRIVE.read(d, "t_hold_end", "drive", lo=t_ramp),
                   "mechanism": DRIVE.read(d, "mechanism", "drive")}
    sc["drive"].update(_check_actuator(d, "drive"))
    L = Lmin
    what = "booms.length" if not boom_tables else "the shortest [[boom]] length"
    telescoping.check_tables_belong(raw, sc["drive"]["mechanism"])
    if sc["drive"]["mechanism"] in ("independent", "single_cylinder"):
        # every stage on its own profile (telescoping.py)
        ls_lo, ls_hi = telescoping.validate_stages(raw, sc, d, L, what)
        end = ls_hi
    elif sc["drive"]["profile"] == "cubic":
        travel = sc["drive"]["v_max"] * sc["drive"]["t_hold_end"]
        sign = 1 if sc["drive"]["direction"] == "extraction" else -1
        end = sc["booms"]["stroke0"] + sign * travel
        if not 0.0 < end < L:
            room = (L - sc["booms"]["stroke0"]) if sign > 0 else sc["booms"]["stroke0"]
            raise SceneError(f"drive: the stroke history moves L_s from {sc['booms']['stroke0']:g} m to "
                             f"{end:g} m, outside the allowed (0, {L:g}) m ({what}): a boom would "
                             f"leave its neighbour; reduce drive.v_max or drive.t_hold_end "
                             f"(v_max * t_hold_end <= {room:g} m)")
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
    sc["payload"] = PAYLOAD.resolve(raw, "payload", ("mass",))
    sc["material"] = MATERIAL.resolve(raw, "material", ("f_y",))
    sc["ropes"] = ROPES.resolve(raw, "ropes", ("EA",))
    e = table_of(raw, "effects", "")
    EFFECTS.check_keys(e, "effects")
    three = sc["booms"]["count"] == 3 or bool(boom_tables)
    sc["effects"] = {k: EFFECTS.read(e, k, "effects", **({"default": three} if
                                                          k == "contact_distribution" else {}))
                     for k in ("flexible", "torsion", "gravity", "filtering", "friction",
                               "contact_distribution", "rope_elasticity", "mass_centre_offset",
                               "payload_swing", "oil_column", "ground")}
    for name in plugins:                # effect plug-ins (sim_core.physics.plugins): off unless on
        if name in e:
            sc["effects"][name] = EFFECTS.read(e, name, "effects")
    eff = sc["effects"]
    mo = table_of(raw, "model", "")
    MODEL.check_keys(mo, "model")
    reduction = MODEL.read(mo, "reduction", "model")
    if boom_tables and not (eff["flexible"] and reduction == "none"):
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
    c = table_of(raw, "contact", "")
    CONTACT.check_keys(c, "contact")
    sc["contact"] = {k: CONTACT.read(c, k, "contact", **(
                         {"default": "couple" if boom_tables else "rigid"}
                         if k == "moment_model" else {}))
                     for k in ("mu_static", "mu_dynamic", "v_eps", "k0", "eps", "slider_width",
                               "springs_per_quarter", "radial_gap", "moment_model",
                               "seat_stiffness", "friction_load")}
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
    sc["filtering"] = FILTERING.resolve(raw, "filtering", ("h",))
    sc["gravity"] = GRAVITY.resolve(raw, "gravity", ("g",))
    # the other actuators (sim_core.systems.telescopic.actuators) and the hoisted payload
    t_end = sc["solver"]["t_end"]
    theta0 = sc["booms"]["luffing_angle_deg"]
    for table in ("luffing_drive", "slew_drive", "hoist_drive"):
        tb = table_of(raw, table, "")
        T = ACTUATOR_TABLES[table]
        check_keys(tb, T.all_keys(), table)
        if tb:
            sc[table] = _check_actuator(tb, table)
    h = table_of(raw, "hoist", "")
    HOIST.check_keys(h, "hoist")
    if eff["payload_swing"] or h:
        sc["hoist"] = {k: HOIST.read(h, k, "hoist") for k in ("length", "EA", "hook_mass")}
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
    _effect_table(raw, GROUND, eff, "the ground")
    if eff["ground"]:
        if not eff["payload_swing"]:
            raise SceneError("effects.ground = true with effects.payload_swing = false: the ground "
                             "carries the payload that hangs on the hoist rope (allowed: "
                             "effects.payload_swing = true)")
        sc["ground"] = GROUND.resolve(raw, "ground")
    oc = _effect_table(raw, OIL_COLUMN, eff, "the oil column")
    if eff["oil_column"]:
        sc["oil_column"] = {k: OIL_COLUMN.read(oc, k, "oil_column") for k in
                            ("cylinder_area", "bulk_modulus", "dead_length", "damping_ratio")}
        why = ("effects.flexible = false" if not eff["flexible"] else
               "model.reduction = 'modal'" if reduction != "none" else
               f"drive.mechanism = {sc['drive']['mechanism']!r}"
               if sc["drive"]["mechanism"] != "synchronized" else None)
        if why:
            raise SceneError(f"effects.oil_column = true with {why}: the oil column drives the "
                             "full model's synchronized stages (allowed: effects.flexible = true, "
                             "model.reduction = 'none', drive.mechanism = 'synchronized')")
    moving = [k for k in ("luffing_drive", "slew_drive") if k in sc]
    if moving or eff["payload_swing"]:
        if not eff["flexible"] or reduction != "none":
            what = f"[{moving[0]}]" if moving else "effects.payload_swing = true"
            why = ("effects.flexible = false" if not eff["flexible"] else
                   "model.reduction = 'modal'")
            raise SceneError(f"{what} with {why}: the rigid limit and the modal tables have a "
                             "fixed luffing angle and a fixed payload (allowed: luffing, "
                             "slewing or a swinging payload on flexible booms with "
                             "model.reduction = 'none')")
    for name, plugin in plugins.items():
        tb = table_of(raw, name, "")
        if tb and not sc["effects"].get(name, False):
            raise SceneError(f"[{name}] with effects.{name} = false: the table configures the "
                             f"{name} effect (allowed: effects.{name} = true, or leave it out)")
        if sc["effects"].get(name, False):
            sc[name] = plugin.validate(tb, sc)
    sc["model"] = {"reduction": reduction, "n_modes": MODEL.read(mo, "n_modes", "model")}
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
        (p_lo, p_hi), (a_lo, a_hi), (L_lo, L_hi) = allowed_ranges(n_booms=sc["booms"]["count"])
        if not p_lo <= sc["payload"]["mass"] <= p_hi:
            raise SceneError(f"payload.mass = {sc['payload']['mass']!r}: out of range, allowed "
                             f"[{p_lo:g}, {p_hi:g}] kg (the modal tables' payloads; "
                             "model.reduction = 'none' takes any payload)")
        if not a_lo <= sc["booms"]["luffing_angle_deg"] <= a_hi:
            raise SceneError(f"booms.luffing_angle_deg = {sc['booms']['luffing_angle_deg']!r}: "
                             f"out of range, allowed [{a_lo:g}, {a_hi:g}] deg (the modal tables' "
                             "angles; model.reduction = 'none' takes 0..85)")
    if sc["model"]["reduction"] == "modal" and sc["effects"]["friction"]:
        raise SceneError("model.reduction = 'modal' with effects.friction = true: the modal tables "
                         "are frictionless; set effects.friction = false")
    if sc["model"]["reduction"] == "modal":
        _check_modal(sc, ls_lo, ls_hi, L_lo, L_hi)
    return sc


# the parameters the modal tables are built for (sim_core.systems.telescopic.modal.
# check_params) and the scene keys that set them
_MODAL_KEYS = (("boom_length", "booms.length"), ("L_h", "booms.L_h"), ("E", "booms.E"),
               ("rho", "booms.rho"), ("rope_EA", "ropes.EA"), ("gravity", "gravity.g"),
               ("filter_h", "filtering.h"),
               ("torsion", "effects.torsion"), ("rope_elasticity", "effects.rope_elasticity"),
               ("flexible", "effects.flexible"))


def _check_modal(sc: dict, ls_lo: float, ls_hi: float, L_lo: float, L_hi: float) -> None:
    """What the modal ROM (sim_core.systems.telescopic.modal.simulate_modal) needs beyond the
    tables' payloads and angles: the crane the tables were built from, the paper's cubic
    schedule from t = 0 within the tables' stage lengths, and no effect the tables lack."""
    from sim_core.systems.telescopic.modal import table_params
    d = sc["drive"]
    if d["profile"] != "cubic" or "t_start" in d:
        raise SceneError(f"model.reduction = 'modal' with drive.profile = {d['profile']!r}"
                         + (f" and drive.t_start = {d['t_start']:g} s" if "t_start" in d
                            else "") + ": the modal ROM runs the cubic schedule from t = 0 "
                         "(allowed: profile 'cubic' without t_start; other drives: "
                         "model.reduction = 'none')")
    if not L_lo - 1e-9 <= ls_lo <= ls_hi <= L_hi + 1e-9:
        raise SceneError(f"drive: the stroke history moves L_s between {ls_lo:g} and {ls_hi:g} m, "
                         f"outside the modal tables' stage lengths [{L_lo:g}, {L_hi:g}] m "
                         "(allowed: booms.stroke0 and drive.v_max * drive.t_hold_end within "
                         "them; other strokes: model.reduction = 'none')")
    for name in ("mass_centre_offset", *effect_plugins()):
        if sc["effects"].get(name):
            raise SceneError(f"model.reduction = 'modal' with effects.{name} = true: the modal "
                             "tables are built without it (allowed: false; with it: "
                             "model.reduction = 'none')")
    p, ref = params_from_scene(sc), table_params(sc["booms"]["count"])
    for attr, key in _MODAL_KEYS:
        if getattr(p, attr) != getattr(ref, attr):
            off = {"gravity": "gravity", "filter_h": "filtering"}.get(attr)
            shown = (f"effects.{off} = false" if off and not sc["effects"][off] else
                     f"{key} = {getattr(p, attr)!r}")
            raise SceneError(f"{shown}: the modal tables are built for {key} = "
                             f"{getattr(ref, attr)!r} (other values: model.reduction = 'none')")


def _effect_table(raw: dict, T: Table, eff: dict, what: str) -> dict:
    """The table ``T`` of the effect of the same name, its keys checked; a SceneError where it
    is given with the effect off."""
    name = T.path
    t = table_of(raw, name, "")
    T.check_keys(t, name)
    if t and not eff[name]:
        raise SceneError(f"[{name}] with effects.{name} = false: the table configures {what} "
                         f"(allowed: effects.{name} = true, or leave it out)")
    return t


def _check_actuator(d: dict, table: str) -> dict:
    """The drive profile of an actuator table (sim_core.systems.telescopic.actuators): its kind
    and the kind's keys, positions in the table's unit (m or deg), rates per s.  The telescopic
    [drive] keeps its cubic keys (direction, v_max, t_ramp, t_hold_end) beside these."""
    T = ACTUATOR_TABLES[table]
    out = {"profile": T.read(d, "profile", table)}
    kind = out["profile"]
    drive = table == "drive"
    if kind in ("cubic", "trapezoid") and "t_start" in d:
        out["t_start"] = T.read(d, "t_start", table)
    if kind == "cubic" and not drive:
        out["travel"] = T.read(d, "travel", table)
        out["t_ramp"] = T.read(d, "t_ramp", table)
        out["t_hold_end"] = T.read(d, "t_hold_end", table, lo=out["t_ramp"])
    if kind == "trapezoid":
        out["travel"] = T.read(d, "travel", table)
        if not drive:
            out["v_max"] = T.read(d, "v_max", table)
        out["a_max"] = T.read(d, "a_max", table)
        if "j_max" in d:
            out["j_max"] = T.read(d, "j_max", table)
    if kind in ("cubic", "trapezoid") and out.get("travel", 1.0) == 0.0:
        raise SceneError(f"{table}.travel = 0: allowed a nonzero travel (or profile = 'hold')")
    if kind == "table":
        if ("table" in d) == ("table_file" in d):
            raise SceneError(f"{table}: a table profile needs one of {table}.table (rows of "
                             f"[time s, position]) or {table}.table_file (a CSV file)")
        if "table" in d:
            out["table"] = T.read(d, "table", table)
        else:
            out["table_file"] = T.read(d, "table_file", table)
    for k in ("max_rate", "max_accel"):
        if k in d:
            out[k] = T.read(d, k, table)
    own = T.all_keys()
    if drive:
        own -= {"direction", "v_max", "t_ramp", "t_hold_end", "mechanism"}
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
        BOOM.check_keys(t, w)
        if "nu" in t and "G" in t:
            raise SceneError(f"{w}.nu and {w}.G: give one of the two (G = E / (2 (1 + nu)))")
        E = BOOM.read(t, "E", w, default=E0)
        nu = BOOM.read(t, "nu", w)
        G = BOOM.read(t, "G", w, default=E / (2.0 * (1.0 + nu)))
        Gf = BOOM["G"]
        if "G" not in t and not Gf.lo <= G <= Gf.hi:
            raise SceneError(f"{w}.nu = {nu!r}: gives G = E / (2 (1 + nu)) = {G:g} Pa, outside "
                             f"the allowed {Gf.range_text()} (give G, or another nu)")
        out.append({"length": BOOM.read(t, "length", w), "E": E, "G": G,
                    "rho": BOOM.read(t, "rho", w, default=rho0),
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
    shape = SECTION.read(t, "shape", w)
    given = {k: SECTION.read(t, k, w) for k in _GIVEN if k in t}
    if shape == "properties":
        for k in ("A", "I_t", "I_b", "J", "mass_per_length"):
            SECTION.read(t, k, w, required=True)
        SECTION.check_keys(t, w, tag=shape)
        given.setdefault("y_c", 0.0)
        given.setdefault("z_c", 0.0)
        spec = {"shape": "properties", **given}
    else:
        SECTION.check_keys(t, w, tag=shape)
        geo = {k: v for k, v in t.items() if k not in _GIVEN}
        # the ranges of the shape's keys (a table keeps its values as given: the geometry's
        # own checks, sim_core.physics.cross_sections, read them)
        keys = [f.key for f in SECTION.fields if f.when == (shape,)]
        if shape == "polygon":
            keys = (["contour"] if "contour" in t else
                    [k for k in keys if k != "contour"])
        for k in keys:
            if k in t or SECTION[k].default is REQUIRED:
                SECTION.read(t, k, w)
        wall = SECTION.read(t, "wall", w)
        perimeter = _outer_perimeter(shape, t)
        if perimeter is not None and perimeter > MAX_SLENDERNESS * wall:
            raise SceneError(f"{w}.wall = {wall!r} m: the outer contour is about "
                             f"{perimeter:.4g} m long, {perimeter / wall:.4g} walls (allowed: at "
                             f"most {MAX_SLENDERNESS:g}, a wall of at least "
                             f"{perimeter / MAX_SLENDERNESS:.3g} m; thinner walls buckle locally, "
                             "and the section analysis meshes ~4 triangles per wall length)")
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


#: the longest outer contour of a boom section in walls (contour length / wall thickness): a
#: width-to-wall ratio of about 250, beyond thin-walled crane booms (b/t up to ~150); the
#: section analysis (sim_core.physics.cross_sections) meshes about 4 triangles per wall length
#: of contour, ~10 s per section at this limit on 2 cores
MAX_SLENDERNESS = 1000.0


def _outer_perimeter(shape: str, t: dict) -> float | None:
    """About the length of a section's outer contour, m (None where the keys do not give it:
    the geometry's own checks refuse the section)."""
    if shape == "box":
        return 2.0 * (t["width"] + t["height"])
    if shape == "u":
        ya, za, r = t["top_arc_centre_y"], t["top_arc_centre_z"], t["top_arc_radius"]
        return math.pi * (ya + r) + 2.0 * za + 2.0 * math.pi * r + 2.0 * ya
    if "contour" in t:
        pts = t["contour"]
        return math.fsum(math.dist(pts[i - 1], pts[i]) for i in range(len(pts)))
    n = t.get("n_sides")
    if not isinstance(n, (int, float)) or n < 3:
        return None
    if "width_across_flats" in t:
        apothem = 0.5 * t["width_across_flats"]
    elif "circumradius" in t:
        apothem = t["circumradius"] * math.cos(math.pi / n)
    else:
        return None
    return 2.0 * n * apothem * math.tan(math.pi / n)


def cross_section_of(spec: dict):
    """The CrossSection of a section table (sim_core.physics.cross_sections; cached there)."""
    from sim_core.physics.cross_sections import cross_section
    spec = {k: v for k, v in spec.items() if k not in ("constants", "method")}
    return cross_section(spec)


def _check_luffing(t: dict, booms: dict, L_h: float, L1: float) -> dict:
    """The [luffing] table: the mounting points D1, D2, D3 (docs/model.md#input-luffing)."""
    LUFFING.check_keys(t, "luffing")
    out = {k: LUFFING.read(t, k, "luffing") for k in ("pivot", "pivot_on_boom", "base")}
    out["head_on_boom"] = LUFFING.read(t, "head_on_boom", "luffing", default=[L_h, -0.556])
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
        OVERLAP.check_keys(t, w)
        o = {"slider_width": OVERLAP.read(t, "slider_width", w, default=c["slider_width"]),
             "inner_slider_distance": OVERLAP.read(t, "inner_slider_distance", w),
             "outer_slider_distance": OVERLAP.read(t, "outer_slider_distance", w),
             "radial_gap": OVERLAP.read(t, "radial_gap", w, default=c["radial_gap"]),
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
            o["bears_on"] = OVERLAP.read(t, "bears_on", w)
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
        ground=sc.get("ground") if sc["effects"].get("ground") else None,
        oil_column=sc.get("oil_column"),
        booms=booms, overlaps=overlaps, luffing=luffing,
        n_booms=b["count"], boom_length=b.get("length", booms[0].length if booms else 10.0),
        luffing_angle_deg=b["luffing_angle_deg"],
        stroke0=b["stroke0"], direction=1 if d["direction"] == "extraction" else -1, L_h=b["L_h"],
        E=b["E"], rho=b["rho"], payload=sc["payload"]["mass"], rope_EA=sc["ropes"]["EA"],
        gravity=sc["gravity"]["g"] if sc["effects"]["gravity"] else 0.0, n_nodes=b["n_nodes"],
        n_gauss=b["n_gauss"], filter_h=sc["filtering"]["h"] if sc["effects"]["filtering"] else 0.0,
        v_max=d["v_max"], t_ramp=d["t_ramp"], t_hold_end=d["t_hold_end"],
        mechanism=d["mechanism"], **telescoping.stage_params(sc),
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
        mass_centre_offset=sc["effects"]["mass_centre_offset"],
        f_y=sc.get("material", {}).get("f_y", 355e6))
