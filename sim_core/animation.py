"""Animations of a telescopic run's replay geometry (GIF or MP4, matplotlib, Agg backend).

:func:`animate` replays a result of the telescopic full model from the geometry it records
(``geometry_*`` outputs, SI units, global frame X forward, Y lateral, Z up):

* each boom as a tube in its own colour: its outer section contour (decimated to a few dozen
  points) swept along the centre line with the section frames, a point ``(y, z)`` of the
  contour drawn at ``r + y e_t + z e_b``; the tubes are translucent, so the overlaps, the inner
  booms and the sliders inside the outer booms stay visible;
* the sliders (each overlap's inner and outer contact point) as markers, the luffing cylinder
  as a thick line from its base D2 to its head D3, the hoist rope from the boom tip to the
  payload where the payload swings (``payload_position``), else the payload at the tip, and the
  slew axis / turntable origin as a small marker;
* a text block with the time (``t = 1.25 s``) and the current values of the chosen outputs in
  display units (m, kN, deg); outputs missing from the result are skipped.

``view="3d"`` draws one 3D view (mplot3d, equal aspect); ``view="two"`` a side view (the
horizontal distance along the boom's vertical plane, i.e. X turned by the slew angle where the
result has one, against Z) and a top view (X-Y), side by side, both at equal aspect.  The axes
limits are fixed over the whole replay window, so the picture does not jump.

Time: frames are spaced ``speed / fps`` seconds of simulated time apart (``speed = 1`` plays in
real time, 2 twice as fast) from ``t_start`` to ``t_end``; every drawn quantity is interpolated
linearly in time between the output samples.

Deflection scale: the elastic deflection of the booms is a few centimetres on a boom of many
metres, invisible at true scale.  ``scale`` exaggerates it about one straight reference line
per frame, the chord through the first centre-line point of boom 1 (the root) along that
section's axis e_s (the frame at point 0): a point ``r`` is drawn at
``r0 + a (a.(r - r0)) + scale (I - a a^T)(r - r0)``, i.e. the offset perpendicular to the chord
is multiplied by ``scale`` and the position along it kept (``scale = 1`` draws the true
shape).  One line for all booms (rather than one chord per boom) keeps the telescope together:
the map is the same for every boom, so an inner boom's root stays inside the outer boom at the
overlap however large the scale, and the root rotations that one boom passes on to the next are
exaggerated too.  The section contours are drawn at true size around the mapped centre line;
the sliders and the tip move with the booms, the luffing cylinder's head with boom 1, and the
hoist rope keeps its true length and direction (the payload is shifted with the tip).

Why matplotlib: it is already a dependency; it writes a GIF through Pillow without any further
binary, and an MP4 through the ffmpeg binary that the optional ``imageio-ffmpeg`` package
bundles (``pip install "telescopic-boom-sim[media]"``), so nothing has to be installed on the
system.  matplotlib is imported only when :func:`animate` runs, and the output file is written
atomically (rendered to a temporary file in the same folder, then renamed).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sim_core.result import atomic_path

__all__ = ["ALLOWED_SUFFIXES", "animate", "frame_times"]

ALLOWED_SUFFIXES = (".gif", ".mp4")

_FIGSIZE = (8.0, 6.0)        # inches: 800 x 600 px at _DPI
_DPI = 100
_BOOM_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                 "#17becf")
_TUBE_ALPHA = 0.6
PAYLOAD_COLOUR = "#ffcc00"   # safety yellow, black edge: the payload stands out of the booms
_OUTLINE_POINTS = 24         # the contour is decimated to about this many points

# overlay name -> (label, unit, factor from SI); any other output is shown as it is, no unit
_OVERLAY_UNITS = {
    "piston_stroke": ("piston stroke", "m", 1.0),
    "telescopic_cylinder_force": ("telescopic cylinder", "kN", 1e-3),
    "luffing_cylinder_force": ("luffing cylinder", "kN", 1e-3),
    "hoist_rope_force": ("hoist rope", "kN", 1e-3),
    "slew_angle": ("slew", "deg", 180.0 / math.pi),
    "luffing_angle": ("luffing", "deg", 180.0 / math.pi),
    "sway_angle": ("sway", "deg", 180.0 / math.pi),
    "tip_position": ("tip", "m", 1.0),
    "payload_position": ("payload", "m", 1.0),
    "stage_stroke": ("stage stroke", "m", 1.0),
}


def animate(result, out, *, scale=1.0, speed=1.0, fps=20, t_start=None, t_end=None,
            overlays=("piston_stroke", "telescopic_cylinder_force"), view="3d") -> Path:
    """Render ``result``'s replay geometry as an animation; returns the written path.

    result: a :class:`sim_core.Result` of the telescopic full model (it records the
    ``geometry_*`` outputs; other results raise ValueError).  out: the file, ``.gif``
    (Pillow) or ``.mp4`` (ffmpeg from imageio-ffmpeg), written atomically.  scale: deflection
    exaggeration about boom 1's root chord (1 = true shape, see the module docstring).
    speed: simulated seconds per second of playback.  fps: frames per second of playback.
    t_start, t_end: the replayed window in s (defaults: the whole run).  overlays: outputs whose
    current values are printed next to the time.  view: ``"3d"`` or ``"two"`` (side and top
    view).
    """
    out = Path(out)
    suffix = out.suffix.lower()
    if suffix not in ALLOWED_SUFFIXES:
        raise ValueError(f"animation file {out.name!r}: unknown suffix {out.suffix!r} "
                         f"(allowed: {', '.join(ALLOWED_SUFFIXES)})")
    if view not in ("3d", "two"):
        raise ValueError(f"view {view!r} (allowed: '3d', 'two')")
    geometry = _Geometry(result, float(scale))
    times = frame_times(result.t, speed=speed, fps=fps, t_start=t_start, t_end=t_end)

    if suffix == ".mp4":
        try:
            import imageio_ffmpeg
        except ImportError as exc:
            raise ImportError('MP4 animations need imageio-ffmpeg: pip install '
                              '"telescopic-boom-sim[media]" (or write a .gif)') from exc
        ffmpeg = imageio_ffmpeg.get_ffmpeg_exe()

    import matplotlib
    matplotlib.use("Agg")
    from matplotlib import animation as mpl_animation

    renderer = _Renderer(geometry, times, overlays=overlays, view=view)
    if suffix == ".gif":
        writer = _pillow_writer(fps)
    else:
        matplotlib.rcParams["animation.ffmpeg_path"] = ffmpeg
        writer = mpl_animation.FFMpegWriter(fps=fps, codec="h264")

    try:
        with atomic_path(out, suffix=suffix) as tmp:    # written atomically (sim_core.result)
            with writer.saving(renderer.fig, tmp, dpi=_DPI):
                for tq in times:
                    renderer.update(tq)
                    writer.grab_frame()
    finally:
        renderer.close()
    return out


def frame_times(t, *, speed=1.0, fps=20, t_start=None, t_end=None) -> np.ndarray:
    """The simulated times of the frames: ``t_start + k speed / fps`` up to ``t_end``."""
    t = np.asarray(t, dtype=float)
    if t.size == 0:
        raise ValueError("the result has no output samples")
    if not (np.isfinite(speed) and speed > 0):
        raise ValueError(f"speed = {speed!r}: must be > 0")
    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"fps = {fps!r}: must be > 0")
    t0 = float(t[0]) if t_start is None else float(t_start)
    t1 = float(t[-1]) if t_end is None else float(t_end)
    tol = 1e-9 * max(1.0, abs(float(t[-1])))
    if t0 < t[0] - tol or t1 > t[-1] + tol or t1 < t0:
        raise ValueError(f"time window [{t0:g}, {t1:g}] s is not inside the run "
                         f"[{t[0]:g}, {t[-1]:g}] s")
    dt = float(speed) / float(fps)
    n = math.floor((t1 - t0) / dt + 1e-9) + 1
    return t0 + dt * np.arange(n)


def _interp(t, values, tq):
    """values (n, ...) sampled at t (n,), linearly interpolated at the scalar time tq."""
    values = np.asarray(values, dtype=float)
    if len(t) == 1:
        return values[0]
    i = int(np.clip(np.searchsorted(t, tq, side="right") - 1, 0, len(t) - 2))
    span = t[i + 1] - t[i]
    w = 0.0 if span <= 0 else float(np.clip((tq - t[i]) / span, 0.0, 1.0))
    return (1.0 - w) * values[i] + w * values[i + 1]


def _decimate_outline(outline, n=_OUTLINE_POINTS):
    """The closed contour (k, 2) without NaN padding, simplified to about n points.

    Ramer-Douglas-Peucker with a tolerance raised until at most n points remain keeps the
    corners of polygonal sections; a contour that already has few points is kept as it is.
    """
    pts = np.asarray(outline, dtype=float)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if len(pts) >= 2 and np.allclose(pts[0], pts[-1]):
        pts = pts[:-1]
    if len(pts) < 3:
        raise ValueError("a boom's section outline has fewer than 3 points")
    if len(pts) <= n:
        return pts
    size = float(np.ptp(pts, axis=0).max())
    tol = 1e-3 * size
    while True:
        keep = _rdp_closed(pts, tol)
        if keep.sum() <= n:
            return pts[keep]
        tol *= 1.5


def _rdp_closed(pts, tol):
    """Ramer-Douglas-Peucker on a closed polygon: mask of the kept points."""
    far = int(np.argmax(np.linalg.norm(pts - pts[0], axis=1)))
    keep = np.zeros(len(pts), dtype=bool)
    keep[0] = keep[far] = True
    stack = [(0, far), (far, len(pts))]
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        pa, pb = pts[a], pts[b % len(pts)]
        seg = pb - pa
        mid = pts[a + 1:b]
        length = float(np.hypot(*seg))
        if length > 0:
            d = np.abs(seg[0] * (mid[:, 1] - pa[1]) - seg[1] * (mid[:, 0] - pa[0])) / length
        else:
            d = np.linalg.norm(mid - pa, axis=1)
        j = int(np.argmax(d))
        if d[j] > tol:
            keep[a + 1 + j] = True
            stack += [(a, a + 1 + j), (a + 1 + j, b)]
    return keep


class _Geometry:
    """The drawn geometry of ``result`` at any time (interpolated, deflection exaggerated)."""

    def __init__(self, result, scale):
        missing = [k for k in ("geometry_centre_lines", "geometry_section_frames",
                               "geometry_section_outlines") if k not in result]
        if missing:
            name = (getattr(result, "scene", None) or {}).get("name", "")
            what = f" ({name})" if name else ""
            raise ValueError(f"the result{what} has no replay geometry ({', '.join(missing)} "
                             "missing): only the telescopic full model writes it")
        if not np.isfinite(scale):
            raise ValueError(f"scale = {scale!r}: must be finite")
        self.result = result
        self.scale = scale
        self.t = np.asarray(result.t, dtype=float)
        self.lines = np.asarray(result["geometry_centre_lines"], dtype=float)
        self.frames = np.asarray(result["geometry_section_frames"], dtype=float)
        self.n_booms = self.lines.shape[1]
        self.outlines = [_decimate_outline(o) for o in
                         np.asarray(result["geometry_section_outlines"], dtype=float)]
        self.cylinder = (np.asarray(result["geometry_luffing_cylinder"], dtype=float)
                         if "geometry_luffing_cylinder" in result else None)
        self.contacts = (np.asarray(result["geometry_contacts"], dtype=float)
                         if "geometry_contacts" in result else None)
        self.payload = (np.asarray(result["payload_position"], dtype=float)
                        if "payload_position" in result else None)
        self.tip = (np.asarray(result["tip_position"], dtype=float)
                    if "tip_position" in result else self.lines[:, -1, -1])
        self.slew = (np.asarray(result["slew_angle"], dtype=float)
                     if "slew_angle" in result else None)
        self.name = (getattr(result, "scene", None) or {}).get("name", "")

    def at(self, tq):
        """Drawn geometry at time tq: a dict of arrays (global frame, m)."""
        lines = _interp(self.t, self.lines, tq)                   # (N, P, 3)
        frames = _interp(self.t, self.frames, tq)                 # (N, P, 3, 3)
        r0 = lines[0, 0]
        axis = frames[0, 0, 2]
        axis = axis / np.linalg.norm(axis)
        s = self.scale

        def deform(p):
            d = p - r0
            along = d @ axis
            return r0 + along[..., None] * axis + s * (d - along[..., None] * axis)

        drawn = deform(lines)
        tubes = []
        for b in range(self.n_booms):
            yz = self.outlines[b]
            e_t, e_b = frames[b, :, 0], frames[b, :, 1]            # (P, 3)
            rings = (drawn[b][:, None, :] + yz[None, :, 0, None] * e_t[:, None, :]
                     + yz[None, :, 1, None] * e_b[:, None, :])     # (P, m, 3)
            tubes.append(rings)
        geo = {"tubes": tubes, "centre": drawn, "axis_plane": self._plane(tq)}
        tip_true = _interp(self.t, self.tip, tq)
        tip = deform(tip_true)
        geo["tip"] = tip
        if self.contacts is not None:
            geo["contacts"] = deform(_interp(self.t, self.contacts, tq))
        if self.cylinder is not None:
            d2, d3 = _interp(self.t, self.cylinder, tq)
            # the head moves with boom 1: the exaggeration's shift at its position along boom 1
            s_b1 = (lines[0] - r0) @ axis
            shift = drawn[0] - lines[0]
            s3 = (d3 - r0) @ axis
            d3 = d3 + np.array([np.interp(s3, s_b1, shift[:, k]) for k in range(3)])
            geo["cylinder"] = np.array([d2, d3])
        if self.payload is not None:
            geo["payload"] = tip + (_interp(self.t, self.payload, tq) - tip_true)
            geo["rope"] = np.array([tip, geo["payload"]])
        else:
            geo["payload"] = tip
        return geo

    def _plane(self, tq):
        """Horizontal unit vector of the boom's vertical plane (turned by the slew angle)."""
        if self.slew is None:
            return np.array([1.0, 0.0, 0.0])
        psi = float(_interp(self.t, self.slew, tq))
        return np.array([math.cos(psi), math.sin(psi), 0.0])

    def points(self, geo):
        """All drawn points of one frame, (k, 3), for the axes limits."""
        pts = [tube.reshape(-1, 3) for tube in geo["tubes"]]
        pts.append(np.zeros((1, 3)))
        pts.append(geo["payload"][None])
        for key in ("cylinder", "contacts"):
            if key in geo:
                pts.append(geo[key].reshape(-1, 3))
        return np.concatenate(pts)


class _Renderer:
    """One matplotlib figure, updated in place for each frame."""

    def __init__(self, geometry, times, *, overlays, view):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        self.g = geometry
        self.view = view
        self.overlays = [k for k in (overlays or ()) if k in geometry.result]
        self.t_dec = _decimals(times)
        self.fig = Figure(figsize=_FIGSIZE, dpi=_DPI)
        FigureCanvasAgg(self.fig)
        self.colours = [_BOOM_COLOURS[b % len(_BOOM_COLOURS)] for b in range(geometry.n_booms)]

        # the axes limits: every drawn point over the window (a few samples in between too)
        sample = np.unique(np.concatenate([
            times, geometry.t[(geometry.t >= times[0]) & (geometry.t <= times[-1])]]))
        geos = [geometry.at(tq) for tq in sample]
        pts = np.concatenate([geometry.points(g) for g in geos])
        if view == "3d":
            self._setup_3d(pts)
        else:
            side = np.concatenate([self._side(geometry.points(g), g["axis_plane"])
                                   for g in geos])
            self._setup_two(pts, side, slewing=geometry.slew is not None)
        title = geometry.name or "telescopic boom"
        if geometry.scale != 1.0:
            title += f"  (deflection x{geometry.scale:g})"
        self.fig.text(0.985, 0.975, title, va="top", ha="right", fontsize=10)
        self.text = self.fig.text(0.015, 0.975, "", va="top", ha="left", family="monospace",
                                  fontsize=9, bbox={"facecolor": "white", "alpha": 0.8,
                                                    "edgecolor": "0.7", "boxstyle": "round"})

    # ------------------------------------------------------------------ 3D
    def _setup_3d(self, pts):
        from matplotlib.ticker import MaxNLocator
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection

        self.fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=1.0)
        ax = self.fig.add_subplot(projection="3d", computed_zorder=False)
        lo, hi = _padded_box(pts, ground=True, least=0.4)
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_zlim(lo[2], hi[2])
        ax.set_box_aspect(hi - lo, zoom=0.9)
        ax.view_init(elev=20, azim=-55)
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_major_locator(MaxNLocator(5))
        ax.set_xlabel("X [m]")
        ax.set_ylabel("Y [m]")
        ax.set_zlabel("Z [m]")
        ax.tick_params(labelsize=8)
        self.ax = ax
        self.light = np.array([-0.4, -0.7, 0.6])
        self.light /= np.linalg.norm(self.light)
        self.tube_art = []
        n = len(self.colours)
        for b, colour in enumerate(self.colours):
            # the inner booms first: an outer boom is drawn over the booms it holds
            z = 1.0 + (n - b) / (n + 1)
            poly = Poly3DCollection([], facecolor=colour, edgecolor="none", alpha=_TUBE_ALPHA,
                                    zorder=z)
            ax.add_collection3d(poly)
            ends = [ax.plot([], [], [], color=colour, lw=1.0, zorder=z)[0] for _ in range(2)]
            self.tube_art.append((poly, ends))
        self.cyl_art = ax.plot([], [], [], color="0.25", lw=6, solid_capstyle="round",
                               zorder=3)[0]
        self.rope_art = ax.plot([], [], [], color="0.1", lw=1.0, zorder=3)[0]
        self.inner_art = ax.plot([], [], [], ls="none", marker="o", ms=5, color="k",
                                 zorder=5)[0]
        self.outer_art = ax.plot([], [], [], ls="none", marker="s", ms=5, mfc="white",
                                 mec="k", zorder=5)[0]
        self.payload_art = ax.plot([], [], [], ls="none", marker="s", ms=12, mfc=PAYLOAD_COLOUR,
                                   mec="k", zorder=6)[0]
        ax.plot([0], [0], [0], ls="none", marker="^", ms=9, color="k", zorder=4)

    def _update_3d(self, geo):
        from matplotlib.colors import to_rgba

        for (poly, ends), rings, colour in zip(self.tube_art, geo["tubes"], self.colours):
            quads = np.stack([rings[:-1], np.roll(rings[:-1], -1, axis=1),
                              np.roll(rings[1:], -1, axis=1), rings[1:]], axis=2)
            quads = quads.reshape(-1, 4, 3)
            normal = np.cross(quads[:, 2] - quads[:, 0], quads[:, 3] - quads[:, 1])
            normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
            shade = 0.55 + 0.45 * np.abs(normal @ self.light)
            rgba = np.array(to_rgba(colour, _TUBE_ALPHA))
            face = np.tile(rgba, (len(quads), 1))
            face[:, :3] *= shade[:, None]
            poly.set_verts(list(quads))
            poly.set_facecolor(face)
            for line, ring in zip(ends, (rings[0], rings[-1])):
                closed = np.vstack([ring, ring[:1]])
                line.set_data_3d(closed[:, 0], closed[:, 1], closed[:, 2])
        _set3(self.cyl_art, geo.get("cylinder"))
        _set3(self.rope_art, geo.get("rope"))
        contacts = geo.get("contacts")
        _set3(self.inner_art, None if contacts is None else contacts[:, 0])
        _set3(self.outer_art, None if contacts is None else contacts[:, 1])
        _set3(self.payload_art, geo["payload"][None])

    # ------------------------------------------------------------------ side + top
    @staticmethod
    def _side(pts, plane):
        return np.column_stack([pts @ plane, pts[:, 2]])

    def _setup_two(self, pts, side, slewing):
        from matplotlib.collections import LineCollection, PolyCollection

        # room above the panels for the text block (one line per overlay, about 15 px each)
        top = min(0.86, 0.93 - 0.025 * (1 + len(self.overlays)))
        self.fig.subplots_adjust(left=0.08, right=0.98, bottom=0.09, top=top, wspace=0.25)
        ax_side = self.fig.add_subplot(1, 2, 1)
        ax_top = self.fig.add_subplot(1, 2, 2)
        lo, hi = _padded_box(np.column_stack([side, np.zeros(len(side))]), ground=False)
        _fit_equal(ax_side, lo[:2], hi[:2])
        lo, hi = _padded_box(pts, ground=False)
        _fit_equal(ax_top, lo[:2], hi[:2])
        ax_side.set_xlabel("horizontal distance in the boom plane [m]" if slewing else "X [m]")
        ax_side.set_ylabel("Z [m]")
        ax_side.set_title("side view", fontsize=10)
        ax_top.set_xlabel("X [m]")
        ax_top.set_ylabel("Y [m]")
        ax_top.set_title("top view", fontsize=10)
        self.axes2 = {}
        for name, ax in (("side", ax_side), ("top", ax_top)):
            ax.grid(alpha=0.3)
            ax.tick_params(labelsize=8)
            if name == "side":
                ax.axhline(0.0, color="0.6", lw=0.8, zorder=0)      # the ground
            ax.plot([0], [0], ls="none", marker="^" if name == "side" else "o", ms=8,
                    color="k", zorder=4)
            # the inner booms first: an outer boom is drawn over the booms it holds
            colours = self.colours[::-1]
            polys = PolyCollection([], facecolors=[(*_rgb(c), _TUBE_ALPHA) for c in colours],
                                   edgecolors=colours, linewidths=0.8, zorder=1)
            ax.add_collection(polys)
            rings = LineCollection([], colors=[c for c in colours for _ in range(2)],
                                   linewidths=0.8, zorder=2)
            ax.add_collection(rings)
            art = {
                "polys": polys, "rings": rings,
                "cyl": ax.plot([], [], color="0.25", lw=5, solid_capstyle="round",
                               zorder=3)[0],
                "rope": ax.plot([], [], color="0.1", lw=1.0, zorder=3)[0],
                "inner": ax.plot([], [], ls="none", marker="o", ms=4, color="k", zorder=5)[0],
                "outer": ax.plot([], [], ls="none", marker="s", ms=4, mfc="white", mec="k",
                                 zorder=5)[0],
                "payload": ax.plot([], [], ls="none", marker="s", ms=10, mfc=PAYLOAD_COLOUR,
                                   mec="k", zorder=6)[0],
            }
            self.axes2[name] = (ax, art)

    def _update_two(self, geo):
        plane = geo["axis_plane"]
        projections = {"side": lambda p: np.stack([p @ plane, p[..., 2]], axis=-1),
                       "top": lambda p: p[..., :2]}
        for name, (ax, art) in self.axes2.items():
            proj = projections[name]
            polys, ends = [], []
            for rings, centre in zip(geo["tubes"][::-1], geo["centre"][::-1]):
                r2 = proj(rings)                                    # (P, m, 2)
                c2 = proj(centre)                                   # (P, 2)
                polys.append(_silhouette(r2, c2))
                ends += [np.vstack([r2[0], r2[0][:1]]), np.vstack([r2[-1], r2[-1][:1]])]
            art["polys"].set_verts(polys)
            art["rings"].set_segments(ends)
            _set2(art["cyl"], geo.get("cylinder"), proj)
            _set2(art["rope"], geo.get("rope"), proj)
            contacts = geo.get("contacts")
            _set2(art["inner"], None if contacts is None else contacts[:, 0], proj)
            _set2(art["outer"], None if contacts is None else contacts[:, 1], proj)
            _set2(art["payload"], geo["payload"][None], proj)

    # ------------------------------------------------------------------ common
    def update(self, tq):
        geo = self.g.at(tq)
        if self.view == "3d":
            self._update_3d(geo)
        else:
            self._update_two(geo)
        self.text.set_text(self._overlay_text(tq))

    def _overlay_text(self, tq):
        lines = [f"t = {tq:.{self.t_dec}f} s"]
        for key in self.overlays:
            value = np.asarray(_interp(self.g.t, self.g.result[key], tq), dtype=float)
            label, unit, factor = _OVERLAY_UNITS.get(key, (key.replace("_", " "), "", 1.0))
            value = value * factor
            if value.ndim == 0:
                text = _fmt(float(value))
            elif value.size <= 4:
                text = "(" + ", ".join(_fmt(float(v)) for v in value.ravel()) + ")"
            else:
                continue
            lines.append(f"{label} = {text}{' ' + unit if unit else ''}")
        return "\n".join(lines)

    def close(self):
        self.fig.clear()


def _pillow_writer(fps):
    """matplotlib's PillowWriter, each frame kept as a paletted image (a third of RGB's memory;
    the GIF is paletted anyway), so that long replays fit in memory."""
    from matplotlib.animation import PillowWriter
    from PIL import Image

    class PalettePillowWriter(PillowWriter):
        def grab_frame(self, **savefig_kwargs):
            super().grab_frame(**savefig_kwargs)
            frame = self._frames[-1]
            if frame.mode == "RGB":
                self._frames[-1] = frame.quantize(256, method=Image.Quantize.FASTOCTREE,
                                                  dither=Image.Dither.NONE)

    return PalettePillowWriter(fps=fps)


def _fmt(x):
    """About four significant digits at a steady width (the numbers do not jitter)."""
    a = abs(x)
    if a < 1e-9:
        return "0"
    if 1e-2 <= a < 1e5:
        return f"{x:.{max(0, 3 - math.floor(math.log10(a)))}f}"
    return f"{x:.3e}"


def _decimals(times):
    """Decimals of the time display: enough to tell consecutive frames apart."""
    if len(times) < 2:
        return 2
    step = float(times[1] - times[0])
    return int(min(3, max(1, math.ceil(-math.log10(step) - 1e-9))))


def _padded_box(pts, ground, least=0.25):
    """Axes limits around pts (k, 3): 5 % padding, each range at least ``least`` times the
    largest (a flat crane does not squash the view), the ground Z = 0 inside when ground."""
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    if ground:
        lo[2] = min(lo[2], 0.0)
    span = hi - lo
    big = max(float(span.max()), 1.0)
    pad = 0.05 * big
    lo, hi = lo - pad, hi + pad
    need = np.maximum(least * big - (hi - lo), 0.0)
    lo, hi = lo - need / 2, hi + need / 2
    if ground and lo[2] < 0 <= pts[:, 2].min():
        hi[2] -= lo[2]          # keep the ground at the bottom of the box
        lo[2] = 0.0
    return lo, hi


def _fit_equal(ax, lo, hi):
    """Limits around [lo, hi] (2,) widened to the axes' shape, so that equal aspect fills the
    panel (matplotlib would otherwise shrink the panel or move fixed limits itself)."""
    fig_w, fig_h = ax.figure.get_size_inches()
    pos = ax.get_position()
    ratio = (pos.height * fig_h) / (pos.width * fig_w)
    span = np.asarray(hi, float) - np.asarray(lo, float)
    centre = (np.asarray(hi, float) + np.asarray(lo, float)) / 2
    if span[1] < ratio * span[0]:
        span[1] = ratio * span[0]
    else:
        span[0] = span[1] / ratio
    ax.set_xlim(centre[0] - span[0] / 2, centre[0] + span[0] / 2)
    ax.set_ylim(centre[1] - span[1] / 2, centre[1] + span[1] / 2)
    ax.set_aspect("equal", adjustable="box")


def _silhouette(r2, c2):
    """The outline of a projected tube: at each ring the projected points farthest to either
    side of the projected centre line, joined into one polygon (rings (P, m, 2))."""
    direction = c2[-1] - c2[0]
    length = float(np.hypot(*direction))
    direction = direction / length if length > 1e-9 else np.array([1.0, 0.0])
    normal = np.array([-direction[1], direction[0]])
    side = (r2 - c2[:, None, :]) @ normal                         # (P, m)
    rows = np.arange(len(r2))
    upper = r2[rows, np.argmax(side, axis=1)]
    lower = r2[rows, np.argmin(side, axis=1)]
    return np.vstack([upper, lower[::-1]])


def _rgb(colour):
    from matplotlib.colors import to_rgb
    return to_rgb(colour)


def _set3(line, pts):
    if pts is None:
        line.set_data_3d([], [], [])
    else:
        pts = np.atleast_2d(pts)
        line.set_data_3d(pts[:, 0], pts[:, 1], pts[:, 2])


def _set2(line, pts, proj):
    if pts is None:
        line.set_data([], [])
    else:
        p2 = proj(np.atleast_2d(pts))
        line.set_data(p2[:, 0], p2[:, 1])
