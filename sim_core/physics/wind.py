"""Wind load on the booms (effect ``wind``, the worked example of an effect plug-in), SI units.

Quasi-steady drag by the cross-flow principle (Hoerner, "Fluid-Dynamic Drag", 1965, ch. 3; the
drag of a slender member depends on the flow component normal to its axis): at a point of a
boom with velocity r_dot and axis e_s, the relative flow w = U(z) - r_dot has the normal part
w_n = w - (w . e_s) e_s, and the force per length is

    f = 1/2 rho_air C_d b(w_n) |w_n| w_n                                          (N/m)

with b the section's projected width seen by the flow: the extent of the section's outer
contour across the flow direction in the section plane (a box seen side-on shows its height,
seen from below its width).  Using the relative velocity makes the wind also damp the booms'
motion (aerodynamic damping); at rest it is the static drag 1/2 rho C_d b U^2 of the design
codes (EN 13000: C_d 1.2 for box-section booms).

The wind speed has an optional power-law height profile, U(z) = U_ref (max(z, 1 m) / z_ref)^a
(a = 0: uniform; a = 0.14 for open terrain), heights z above the crane's base frame (Z = 0),
and blows horizontally towards the azimuth ``direction_deg`` (0 = +X, the luffing plane at slew
0; 90 = +Y, across it).  A boom inside its outer neighbour is shielded: the load acts on boom 1
along its whole length and on boom k > 1 beyond its outer contact point s_3,k (the spline
element outside boom k-1, where the boom is exposed).  The load is not conservative; the
energy audit books its power F_wind . Q_dot as the wind's work.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.errors import SceneError
from sim_core.physics.effects import Effect, _jt_v
from sim_core.physics.plugins import EffectPlugin
from sim_core.scene.fields import Field, Table

__all__ = ["WindLoad", "PLUGIN", "WIND"]


class WindLoad(Effect):
    """Drag of the wind on the exposed elements (module docstring).

    ``outlines``: per beam, the section's outer contour (n, 2) in section coordinates (e_t,
    e_b), m; ``exposed``: the ids of the elements the wind reaches."""

    needs = frozenset()
    name = "wind"

    def __init__(self, speed, direction_deg, reference_height, exponent, air_density,
                 drag_coefficient, outlines, exposed):
        self.speed, self.exponent = float(speed), float(exponent)
        self.z_ref = float(reference_height)
        a = math.radians(direction_deg)
        self.direction = np.array([math.cos(a), math.sin(a), 0.0])
        self.k = 0.5 * float(air_density) * float(drag_coefficient)
        self.outlines = {id(el): np.asarray(o, float) for el, o in outlines}
        self.exposed = set(exposed)

    def velocity(self, z):
        """U(z) (G, 3), m/s, at heights z (G,), m."""
        zz = np.maximum(np.real(z), 1.0)
        scale = (zz / self.z_ref) ** self.exponent if self.exponent else np.ones_like(zz)
        return (self.speed * scale)[:, None] * self.direction[None, :]

    def element_terms(self, ctx, M, F):
        if id(ctx.el) not in self.exposed:
            return
        kin = ctx.kin
        w = self.velocity(kin.r[:, 2]) - np.einsum("gin,n->gi", kin.J_r, ctx.qde)
        frame = kin.sec.frame                              # (G, 3, 3): rows e_t, e_b, e_s
        e_s = frame[:, 2, :]
        w_n = w - np.einsum("gi,gi->g", w, e_s)[:, None] * e_s
        speed = np.sqrt(np.einsum("gi,gi->g", w_n, w_n) + 1e-12)
        # the flow's direction in the section plane (e_t, e_b) and the contour's extent across it
        ct = np.real(np.einsum("gi,gi->g", w_n, frame[:, 0, :]))
        cb = np.real(np.einsum("gi,gi->g", w_n, frame[:, 1, :]))
        norm = np.hypot(ct, cb) + 1e-300
        across = np.stack([-cb / norm, ct / norm], axis=1)  # (G, 2) unit, normal to the flow
        proj = self.outlines[id(ctx.el)] @ across.T          # (n, G)
        b = proj.max(axis=0) - proj.min(axis=0)
        f = (self.k * b * speed)[:, None] * w_n               # N/m
        F += _jt_v(kin.J_r, ctx.wl[:, None] * f)


WIND = Table("wind", (
    # the storm limit of crane operation is ~20 m/s; 70 m/s is a category-5 hurricane
    Field("speed", "number", "m/s", 10.0, lo=0.0, hi=70.0, note="at the reference height"),
    Field("direction_deg", "number", "deg", 90.0, lo=-360.0, hi=360.0,
          note="the azimuth the wind blows towards: 0 = +X, 90 = +Y across the luffing plane"),
    Field("reference_height", "number", "m", 10.0, lo=1.0, hi=500.0,
          note="height of the reference speed above the crane's base frame"),
    Field("exponent", "number", "", 0.0, lo=0.0, hi=1.0,
          note="power-law height profile: 0 = uniform, 0.14 = open terrain"),
    Field("air_density", "number", "kg/m^3", 1.225, lo=0.1, hi=2.0),
    Field("drag_coefficient", "number", "", 1.2, lo=0.01, hi=3.0,
          note="EN 13000: 1.2 for box-section booms"),
), note="with effects.wind: the drag of the wind on the exposed booms (sim_core.physics.wind)")


def validate(t: dict, scene: dict) -> dict:
    """The [wind] table, read through its declaration :data:`WIND`."""
    WIND.check_keys(t, "wind")
    for i, b in enumerate(scene.get("boom") or []):
        if b["section"]["shape"] == "properties":
            raise SceneError(f"effects.wind = true with boom[{i}].section.shape = 'properties': "
                             "the wind's projected width needs the section's contour (allowed: "
                             "shape 'u', 'box' or 'polygon', or wind = false)")
    return {k: WIND.read(t, k, "wind") for k in ("speed", "direction_deg", "reference_height",
                                                 "exponent", "air_density", "drag_coefficient")}


def build(table: dict, system) -> WindLoad:
    """The wind load of an assembled system: each beam's outer contour
    (``system.section_outline(k)``, section coordinates, m) and the elements the wind reaches
    (``system.exposed_elements()``)."""
    outlines = [(el, system.section_outline(k)) for k, beam in enumerate(system.model.beams)
                for el in beam.elements]
    return WindLoad(outlines=outlines, exposed=[id(el) for el in system.exposed_elements()],
                    **table)


def power(effect: WindLoad, model, t: float, Q, Qd) -> float:
    """F_wind . Q_dot (W): the wind's power on the booms."""
    P = 0.0
    for idx, ctx in model.element_contexts(t, Q, Qd):
        Fe = np.zeros(len(idx))
        effect.element_terms(ctx, None, Fe)
        P += float(np.real(Qd[idx] @ Fe))
    return P


PLUGIN = EffectPlugin(name="wind", validate=validate, build=build, power=power,
                      description="drag of the wind on the exposed booms", fields=WIND)
