"""Figures of the folding-boom scene (SIMULTECH 2020 Figs. 6-8 kinds): boom-2 tip displacement per
axis, tip velocity for several filter windows h, cylinder forces (PNG, written atomically)."""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np

from sim_core.figures import save_figure
from sim_core.result import Result


def plot_folding(result: Result, out: str | Path,
                 h_runs: Mapping[float, Result] | None = None) -> list[Path]:
    """tip_displacement.png (X, Y, Z displacement of the boom-2 tip from t = 0, m),
    tip_velocity_h.png (tip X and Y velocity, one line per h; ``h_runs`` maps h (s) to a Result,
    default just this result), folding_cylinders.png (cylinder forces, kN, pushing positive,
    and slew angle, deg)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    paths = []
    t = result.t
    tip = result["tip_position"]
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for c, (ax, lab) in enumerate(zip(axes, "XYZ")):
        ax.plot(t, tip[:, c] - tip[0, c])
        ax.set_ylabel(f"tip {lab} displ. [m]")
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("t [s]")
    fig.suptitle(f"{result.scene.get('name', 'folding')}: boom-2 tip displacement")
    fig.tight_layout()
    paths.append(save_figure(fig, out / "tip_displacement.png"))
    plt.close(fig)

    if h_runs is None:
        sc = result.scene
        h = sc.get("filtering", {}).get("h", sc.get("params", {}).get("filter_h", 0.0))
        if sc.get("effects", {}).get("filtering") is False:
            h = 0.0
        h_runs = {h: result}
    fig, axes = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
    for h, res in sorted(h_runs.items()):
        for ax, c, lab in ((axes[0], 1, "Y"), (axes[1], 0, "X")):
            ax.plot(res.t, res["tip_velocity"][:, c], label=f"h = {h:g} s")
            ax.set_ylabel(f"tip {lab} velocity [m/s]")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[-1].set_xlabel("t [s]")
    fig.tight_layout()
    paths.append(save_figure(fig, out / "tip_velocity_h.png"))
    plt.close(fig)

    if "cylinder_forces" in result:
        fig, axes = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
        f = result["cylinder_forces"]
        for k in range(f.shape[1]):
            axes[0].plot(t, f[:, k] / 1e3, label=f"cylinder {k + 1}")
        axes[0].set_ylabel("force [kN] (push +)")
        axes[0].legend(fontsize=8)
        axes[1].plot(t, np.degrees(result["slew_angle"]))
        axes[1].set_ylabel("slew angle [deg]")
        axes[1].set_xlabel("t [s]")
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.tight_layout()
        paths.append(save_figure(fig, out / "folding_cylinders.png"))
        plt.close(fig)
    return paths
