"""Figures of a result (matplotlib, Agg backend, PNG written atomically)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from sim_core import run_control
from sim_core.result import Result, atomic_write_bytes


def save_figure(fig, path: str | Path) -> Path:
    """fig rendered as PNG in memory and written atomically (sim_core.result.atomic_write_bytes).
    Within a run (``boom-sim run``) the run's wall budget and Ctrl-C are checked first
    (:func:`sim_core.run_control.check`, phase ``figures``): the figure is closed and the
    typed error raised."""
    exc = run_control.current().exceeded("figures")
    if exc is not None:
        import matplotlib.pyplot as plt
        plt.close(fig)
        raise exc
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    atomic_write_bytes(path, buf.getvalue())
    return path


def plot_result(result: Result, out: str | Path) -> list[Path]:
    """Tip position/velocity/acceleration components and energies vs time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    t = result.t
    paths = []
    names = [n for n in ("tip_position", "tip_velocity", "tip_acceleration") if n in result]
    if names:
        fig, axes = plt.subplots(len(names), 1, figsize=(8, 2.6 * len(names)), sharex=True)
        axes = np.atleast_1d(axes)
        units = {"tip_position": "m", "tip_velocity": "m/s", "tip_acceleration": "m/s²"}
        for ax, n in zip(axes, names):
            for c, lab in enumerate("XYZ"):
                ax.plot(t, result[n][:, c], label=lab)
            ax.set_ylabel(f"{n.replace('_', ' ')} [{units[n]}]")
            ax.grid(alpha=0.3)
            ax.legend(loc="best", fontsize=8)
        axes[-1].set_xlabel("t [s]")
        fig.suptitle(result.scene.get("name", ""))
        fig.tight_layout()
        paths.append(save_figure(fig, out / "tip.png"))
        plt.close(fig)
    if "luffing_cylinder_force" in result:
        fig, axes = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
        axes[0].plot(t, result["luffing_cylinder_force"] / 1e3)
        axes[0].set_ylabel("luffing cylinder [kN]")
        axes[1].plot(t, result["telescopic_cylinder_force"] / 1e3)
        axes[1].set_ylabel("telescopic cylinder [kN]")
        axes[1].set_xlabel("t [s]")
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.suptitle("cylinder forces (positive = pushing)")
        fig.tight_layout()
        paths.append(save_figure(fig, out / "cylinder_forces.png"))
        plt.close(fig)
    if "energy_kinetic" in result:
        fig, ax = plt.subplots(figsize=(8, 3))
        for n in ("energy_kinetic", "energy_strain", "energy_gravity"):
            if n in result:
                ax.plot(t, result[n], label=n.split("_")[1])
        ax.set_xlabel("t [s]")
        ax.set_ylabel("energy [J]")
        ax.grid(alpha=0.3)
        ax.legend()
        fig.tight_layout()
        paths.append(save_figure(fig, out / "energy.png"))
        plt.close(fig)
    return paths
