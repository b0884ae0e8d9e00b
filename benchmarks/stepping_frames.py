"""The figure of the stepping API's frames and angles (docs/stepping.md): the global frame, the
luffing angle, the slew angle and the two sway angles of the payload with their positive
directions, drawn in a side view of the luffing plane and a top view.

    python benchmarks/stepping_frames.py          # writes docs/img/stepping_frames.png

The angles follow sim_core's outputs: ``luffing_angle`` theta is the boom's elevation above the
horizontal; ``slew_angle`` phi turns the luffing plane about the vertical +Z from +X towards
+Y; with d = payload - tip, u = (cos phi, sin phi, 0) (along the boom, away from the crane) and
w = (-sin phi, cos phi, 0) (the direction the tip moves as phi grows), ``sway_angle`` =
(atan2(d.u, -d_z), atan2(d.w, -d_z)).
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Arc, FancyArrowPatch  # noqa: E402

OUT = Path(__file__).resolve().parent.parent / "docs" / "img" / "stepping_frames.png"


def _arrow(ax, p, q, color="k", lw=1.4, style="-|>"):
    ax.add_patch(FancyArrowPatch(p, q, arrowstyle=style, mutation_scale=12, color=color,
                                 lw=lw, shrinkA=0, shrinkB=0))


def _angle(ax, centre, r, a0, a1, label, color, offset=1.25, at=None):
    """An arc from angle a0 to a1 (deg, anticlockwise in the drawing) with an arrow head at a1
    (the positive sense) and its label (at ``at``, else ``offset`` radii out on the arc's
    bisector)."""
    ax.add_patch(Arc(centre, 2 * r, 2 * r, theta1=min(a0, a1), theta2=max(a0, a1), color=color,
                     lw=1.4))
    t1, t0 = math.radians(a1), math.radians(a1 - math.copysign(4.0, a1 - a0))
    p0 = (centre[0] + r * math.cos(t0), centre[1] + r * math.sin(t0))
    p1 = (centre[0] + r * math.cos(t1), centre[1] + r * math.sin(t1))
    _arrow(ax, p0, p1, color)
    tm = math.radians(0.5 * (a0 + a1))
    if at is None:
        at = (centre[0] + offset * r * math.cos(tm), centre[1] + offset * r * math.sin(tm))
    ax.text(*at, label, color=color, ha="center", va="center", fontsize=11)


def side_view(ax):
    """The luffing plane seen from -w (u to the right, Z up): theta and the in-plane sway."""
    th = math.radians(35.0)
    L = 6.0
    tip = (L * math.cos(th), 0.8 + L * math.sin(th))
    ax.plot([-0.6, 0.6], [0.0, 0.0], color="0.3", lw=3)                   # turntable
    ax.plot([0.0, 0.0], [0.0, 0.8], color="0.3", lw=3)
    ax.plot([0.0, tip[0]], [0.8, tip[1]], color="tab:blue", lw=5, solid_capstyle="round")
    ax.plot([0.0, 2.5], [0.8, 0.8], color="0.5", lw=0.8, ls="--")
    _angle(ax, (0.0, 0.8), 1.8, 0.0, 35.0, r"$\theta$ luffing_angle", "tab:blue", 1.9)
    a1 = math.radians(18.0)
    rope = 3.0
    pay = (tip[0] + rope * math.sin(a1), tip[1] - rope * math.cos(a1))
    ax.plot([tip[0], tip[0]], [tip[1], tip[1] - rope - 0.3], color="0.5", lw=0.8, ls="--")
    ax.plot([tip[0], pay[0]], [tip[1], pay[1]], color="k", lw=1.2)
    ax.add_patch(plt.Rectangle((pay[0] - 0.25, pay[1] - 0.4), 0.5, 0.4, color="tab:orange"))
    _angle(ax, tip, 1.6, -90.0, -72.0, "sway_angle[0] > 0:\npayload away\nfrom the crane",
           "tab:red", at=(tip[0] + 2.3, tip[1] - 1.6))
    _arrow(ax, (-1.2, -0.6), (0.3, -0.6))
    ax.text(0.45, -0.6, "u (XY, along the boom)", va="center", fontsize=9)
    _arrow(ax, (-1.2, -0.6), (-1.2, 0.9))
    ax.text(-1.2, 1.05, "Z (up)", ha="center", fontsize=9)
    ax.set_title("side view of the luffing plane")


def top_view(ax):
    """Seen from above (X right, Y up): phi, u, w and the out-of-plane sway."""
    ph = math.radians(30.0)
    R = 5.0
    u = (math.cos(ph), math.sin(ph))
    w = (-math.sin(ph), math.cos(ph))
    tip = (R * u[0], R * u[1])
    ax.add_patch(plt.Circle((0, 0), 0.6, color="0.8"))
    _arrow(ax, (0, 0), (6.3, 0), "0.3", 1.0)
    ax.text(6.4, 0.0, "X", va="center")
    _arrow(ax, (0, 0), (0, 4.5), "0.3", 1.0)
    ax.text(0.0, 4.65, "Y", ha="center")
    ax.text(-0.35, -0.55, "Z out of\nthe page", fontsize=8, ha="center", va="top")
    ax.plot([0, tip[0]], [0, tip[1]], color="tab:blue", lw=5, solid_capstyle="round")
    _angle(ax, (0, 0), 2.2, 0.0, 30.0, r"$\phi$ slew_angle", "tab:green", 1.55)
    _arrow(ax, tip, (tip[0] + 1.3 * u[0], tip[1] + 1.3 * u[1]), "k", 1.2)
    ax.text(tip[0] + 1.5 * u[0], tip[1] + 1.5 * u[1], "u", fontsize=10, va="center")
    pay = (tip[0] + 0.9 * w[0], tip[1] + 0.9 * w[1])
    ax.add_patch(plt.Rectangle((pay[0] - 0.2, pay[1] - 0.2), 0.4, 0.4, color="tab:orange",
                               zorder=1))
    _arrow(ax, tip, (tip[0] + 2.0 * w[0], tip[1] + 2.0 * w[1]), "k", 1.2)
    ax.text(tip[0] + 2.2 * w[0], tip[1] + 2.2 * w[1], "w", fontsize=10, ha="right")
    ax.text(pay[0] + 0.35, pay[1] + 0.2, "payload along +w:\nsway_angle[1] > 0",
            color="tab:red", fontsize=9, ha="left", va="bottom")
    ax.set_title("top view")


def main() -> None:
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.8))
    side_view(axes[0])
    top_view(axes[1])
    for ax in axes:
        ax.set_aspect("equal")
        ax.axis("off")
    axes[0].set_xlim(-1.6, 7.8)
    axes[0].set_ylim(-1.0, 5.2)
    axes[1].set_xlim(-1.5, 7.0)
    axes[1].set_ylim(-1.3, 5.8)
    fig.suptitle("Stepping API: frames and positive angles (right-handed X, Y, Z; Z up)")
    fig.tight_layout()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    tmp = OUT.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=110)
    tmp.replace(OUT)
    print(OUT)


if __name__ == "__main__":
    main()
