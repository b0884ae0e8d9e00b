"""Figures of a telescopic result: the rigid-limit tip comparison, contact-point forces and
slider loads of Zhao-Qi-Wang 2024 Section 9."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim_core.figures import save_figure
from sim_core.result import Result


def _luffing_angle(result: Result) -> float | None:
    sc = result.scene
    for table in ("booms", "params"):
        if isinstance(sc.get(table), dict) and "luffing_angle_deg" in sc[table]:
            return float(sc[table]["luffing_angle_deg"])
    return None


def _label_stack(axes, ylabels) -> None:
    """y labels, grid and legends of a column of panels over a shared time axis."""
    for ax, label in zip(axes, ylabels):
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best", fontsize=7)
    axes[-1].set_xlabel("t [s]")


def _times(t: np.ndarray, wanted) -> list[int]:
    """Output indices nearest to the wanted times inside the run (no duplicates)."""
    idx = []
    for w in wanted:
        if t[0] <= w <= t[-1]:
            i = int(np.argmin(np.abs(t - w)))
            if i not in idx:
                idx.append(i)
    return idx


def _drive(result: Result) -> tuple[int, str]:
    """(number of booms, drive mechanism) of the result's scene (the paper's 3, synchronized
    where the scene does not say)."""
    sc = result.scene
    n = 3
    for table in ("booms", "params"):
        if isinstance(sc.get(table), dict):
            n = int(sc[table].get("count", sc[table].get("n_booms", n)))
    mech = "synchronized"
    for table, key in (("drive", "mechanism"), ("params", "mechanism")):
        if isinstance(sc.get(table), dict) and key in sc[table]:
            mech = str(sc[table][key])
    return n, mech


def rigid_tip_travel(result: Result) -> np.ndarray:
    """Travel of the tip along the boom axis in the rigid limit of the scene's drive (m, per
    output): synchronized, every one of the N - 1 stages moves with the prescribed piston stroke
    s (Eqs. 74-76 for N = 3: boom 3 moves 2 s); sequential, the prescribed stage strokes add."""
    n, mech = _drive(result)
    if mech == "sequential" and "stage_stroke" in result:
        return np.sum(result["stage_stroke"], axis=1)
    if mech in ("independent", "single_cylinder") and "stage_stroke" in result:
        # every stage on its own profile, from its own length at t = 0
        s = np.asarray(result["stage_stroke"], float)
        return np.sum(s - s[0], axis=1)
    return (n - 1) * np.asarray(result["piston_stroke"], float)


def plot_telescopic(result: Result, out: str | Path, slider_times=None) -> list[Path]:
    """The telescopic figures of Zhao-Qi-Wang 2024 Section 9, for every overlap of N booms:

    * ``tip_rigid_limit.png`` (Figs. 14-17): tip X and Z and their rates against the rigid-boom
      kinematics tip_0 + travel(t) (cos theta, sin theta) (:func:`rigid_tip_travel`; Eqs. 74-76:
      boom 3 moves twice the piston stroke s), and the difference (the flexible deflection and
      the rope stretch);
    * ``contact_point_forces.png`` (Figs. 22-25): force and moment components (section frame:
      axial s, lateral t, vertical b) at the inner and outer contact points, one row per overlap;
    * ``drive_forces.png``: the force of every cylinder (or locked stage) and the tension of
      every rope;
    * ``slider_contact_forces.png`` (Fig. 26): normal force of every slider spring of every
      region at chosen times (default: t_end / 4, t_end / 2, 0.8 t_end = 16 s of the paper's
      20 s, t_end), springs numbered patch by patch (arcs, then faces) as in
      ``sim_core.physics.contact``; regions with fewer springs are padded with NaN (not for a
      crane described boom by boom: it has ``pad_forces.png`` instead);
    * ``pad_forces.png``: the force each pad puts on its overlap's inner boom (f_b in the
      luffing plane, f_t across it) and the couple it carries across its length, one row per
      overlap, labelled "overlap k outer pad" / "overlap k inner pad"
      (:func:`sim_core.systems.telescopic.sliders.overlap_pads`).
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    t = result.t
    paths = []
    theta = _luffing_angle(result)
    moving = "slew_angle" in result or bool(result.scene.get("luffing_drive"))
    if (theta is not None and "tip_position" in result and "piston_stroke" in result
            and not moving):             # the rigid limit of a fixed luffing angle and no slew
        e = np.array([np.cos(np.radians(theta)), np.sin(np.radians(theta))])
        tip = result["tip_position"][:, [0, 2]]
        vel = result["tip_velocity"][:, [0, 2]]
        s = rigid_tip_travel(result)
        rigid = tip[0] + s[:, None] * e
        rigid_rate = np.gradient(s, t)[:, None] * e
        fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
        for c, lab in enumerate("XZ"):
            axes[0].plot(t, tip[:, c], label=f"{lab} flexible")
            axes[0].plot(t, rigid[:, c], "--", label=f"{lab} rigid limit")
            axes[1].plot(t, vel[:, c], label=f"d{lab}/dt flexible")
            axes[1].plot(t, rigid_rate[:, c], "--", label=f"d{lab}/dt rigid limit")
            axes[2].plot(t, 1e3 * (tip[:, c] - rigid[:, c]), label=f"{lab} - rigid")
        _label_stack(axes, ("tip [m]", "tip rate [m/s]", "flexible - rigid [mm]"))
        fig.suptitle(f"tip (top centre of the innermost boom) vs rigid-boom kinematics, "
                     f"luffing {theta:g} deg")
        fig.tight_layout()
        paths.append(save_figure(fig, out / "tip_rigid_limit.png"))
        plt.close(fig)
    if "contact_point_forces" in result:
        cpf = result["contact_point_forces"]            # (n, pairs, 2, 6)
        n_pairs = cpf.shape[1]
        fig, axes = plt.subplots(n_pairs, 4, figsize=(14, 2.6 * n_pairs + 0.8), sharex=True,
                                 squeeze=False)
        comps = ("s", "t", "b")
        for k in range(n_pairs):
            for j, where in enumerate((f"I_{k + 1}{k + 2} (inner, boom {k + 1})",
                                       f"II_{k + 1}{k + 2} (outer, boom {k + 2})")):
                for c in range(3):
                    axes[k, 2 * j].plot(t, cpf[:, k, j, c] / 1e3, label=f"f_{comps[c]}")
                    axes[k, 2 * j + 1].plot(t, cpf[:, k, j, 3 + c] / 1e3, label=f"m_{comps[c]}")
                axes[k, 2 * j].set_title(f"{where}: force", fontsize=9)
                axes[k, 2 * j + 1].set_title(f"{where}: moment", fontsize=9)
                axes[k, 2 * j].set_ylabel("kN")
                axes[k, 2 * j + 1].set_ylabel("kN m")
        for ax in axes[-1]:
            ax.set_xlabel("t [s]")
        for ax in axes.ravel():
            ax.grid(alpha=0.3)
            ax.legend(loc="best", fontsize=6)
        fig.suptitle("constraint reactions at the contact points (section frame)")
        fig.tight_layout()
        paths.append(save_figure(fig, out / "contact_point_forces.png"))
        plt.close(fig)
    if "drive_forces" in result and "stage_stroke" in result:
        n, mech = _drive(result)
        from sim_core.systems.telescopic.build import drive_layout, drive_name
        names = [drive_name(k, mech) for k in drive_layout(n, mech)[0]]
        fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
        for name, f in zip(names, np.asarray(result["drive_forces"]).T):
            axes[0].plot(t, f / 1e3, label=name)
        for k, s in enumerate(np.asarray(result["stage_stroke"]).T):
            axes[1].plot(t, s, label=f"stage {k + 1}-{k + 2}")
        if "rope_tensions" in result:
            _, ropes = drive_layout(n, mech)
            for i, T in enumerate(np.asarray(result["rope_tensions"]).T):
                kind = ("extraction", "retraction")[i % 2]
                axes[2].plot(t, T / 1e3, label=f"{kind} rope, boom {ropes[i // 2] + 1}")
        _label_stack(axes, ("drive force [kN]", "stage stroke [m]", "rope tension [kN]"))
        fig.suptitle(f"{mech} drive of {n} booms (forces positive = pushing)")
        fig.tight_layout()
        paths.append(save_figure(fig, out / "drive_forces.png"))
        plt.close(fig)
    if "pad_forces" in result:
        paths.append(_pad_figure(result, out, plt))
    if "slider_contact_forces" in result and not (
            "pad_forces" in result and result.scene.get("boom")):
        # the paper's Fig. 26 (spring by spring); a crane described boom by boom has the
        # pad figure instead
        sf = result["slider_contact_forces"]            # (n, regions, springs)
        wanted = slider_times if slider_times is not None else \
            [t[-1] / 4, t[-1] / 2, 0.8 * t[-1], t[-1]]
        idx = _times(t, wanted)
        names = [f"{r}_{k + 1}{k + 2}" for k in range(sf.shape[1] // 2) for r in ("I", "II")]
        fig, axes = plt.subplots(len(names), 1, figsize=(9, 2.2 * len(names)), sharex=True)
        axes = np.atleast_1d(axes)
        for r, (ax, name) in enumerate(zip(axes, names)):
            for i in idx:
                ax.plot(np.arange(1, sf.shape[2] + 1), sf[i, r] / 1e3, label=f"t = {t[i]:.3g} s")
            ax.set_ylabel(f"{name} [kN]")
            ax.grid(alpha=0.3)
            ax.legend(loc="best", fontsize=7)
        axes[-1].set_xlabel("spring (patch by patch: arcs, then faces)")
        fig.suptitle("normal force of the slider springs")
        fig.tight_layout()
        paths.append(save_figure(fig, out / "slider_contact_forces.png"))
        plt.close(fig)
    paths += _operation_figures(result, out, plt)
    return paths


def _pad_figure(result: Result, out: Path, plt) -> Path:
    """``pad_forces.png`` (see :func:`plot_telescopic`): per overlap, the pads' forces on the
    inner boom (kN) and the couples they carry (kN m) over time."""
    from sim_core.systems.telescopic.sliders import PAD_NAMES
    t = result.t
    F = np.asarray(result["pad_forces"], float)         # (n, overlaps, 2 pads, (f_t, f_b))
    C = np.asarray(result["pad_couples"], float) if "pad_couples" in result else None
    n_ov = F.shape[1]
    fig, axes = plt.subplots(n_ov, 2, figsize=(12, 2.6 * n_ov + 0.8), sharex=True,
                             squeeze=False)
    for k in range(n_ov):
        for j, pad in enumerate(PAD_NAMES):
            label = f"overlap {k + 1} {pad}"
            line, = axes[k, 0].plot(t, F[:, k, j, 1] / 1e3, label=f"{label}, f_b")
            axes[k, 0].plot(t, F[:, k, j, 0] / 1e3, ":", color=line.get_color(),
                            label=f"{label}, f_t")
            if C is not None:
                axes[k, 1].plot(t, C[:, k, j, 0] / 1e3, color=line.get_color(),
                                label=f"{label}, m_t")
        axes[k, 0].set_ylabel("force [kN]")
        axes[k, 1].set_ylabel("couple [kN m]")
        axes[k, 0].set_title(f"overlap {k + 1} (booms {k + 1}-{k + 2}): pad forces on boom "
                             f"{k + 2}", fontsize=9)
        axes[k, 1].set_title(f"overlap {k + 1}: couples across the pads", fontsize=9)
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best", fontsize=6)
    fig.suptitle("slider pads: force on the inner boom (contact-section frame: e_b in the "
                 "luffing plane, e_t across) and couple about e_t")
    fig.tight_layout()
    path = save_figure(fig, out / "pad_forces.png")
    plt.close(fig)
    return path


def _operation_figures(result: Result, out: Path, plt) -> list[Path]:
    """The figures of an operation (luffing, slewing, a swinging payload):

    * ``crane_motion.png``: luffing angle and slew angle (deg), piston stroke (m), luffing and
      telescopic cylinder forces (kN);
    * ``payload_sway.png``: sway angles in the luffing plane and across it (deg) and the hoist
      rope's force (kN);
    * ``tip_path.png``: the paths of the boom tip and the payload seen from above (X, Y) and
      from the side (horizontal distance from the slew axis, Z)."""
    t, paths = result.t, []
    if "slew_angle" in result or "sway_angle" in result or result.scene.get("luffing_drive"):
        fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
        axes[0].plot(t, np.degrees(result["luffing_angle"]), label="luffing angle")
        if "slew_angle" in result:
            axes[0].plot(t, np.degrees(result["slew_angle"]), label="slew angle")
        axes[1].plot(t, result["piston_stroke"], label="piston stroke (stage 1-2)")
        axes[2].plot(t, result["luffing_cylinder_force"] / 1e3, label="luffing cylinder")
        axes[2].plot(t, result["telescopic_cylinder_force"] / 1e3, label="telescopic cylinder")
        _label_stack(axes, ("angle [deg]", "stroke [m]", "force [kN]"))
        fig.suptitle("the crane's motion and its cylinders")
        fig.tight_layout()
        paths.append(save_figure(fig, out / "crane_motion.png"))
        plt.close(fig)
    if "sway_angle" in result:
        sway = np.degrees(result["sway_angle"])
        fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
        axes[0].plot(t, sway[:, 0], label="in the luffing plane (outwards +)")
        axes[0].plot(t, sway[:, 1], label="across it")
        axes[1].plot(t, result["hoist_rope_force"] / 1e3, label="hoist rope")
        _label_stack(axes, ("sway from the vertical [deg]", "rope force [kN]"))
        fig.suptitle("the payload on the hoist rope")
        fig.tight_layout()
        paths.append(save_figure(fig, out / "payload_sway.png"))
        plt.close(fig)
        tip, pay = result["tip_position"], result["payload_position"]
        fig, axes = plt.subplots(1, 2, figsize=(11, 5))
        for r, lab in ((tip, "boom tip"), (pay, "payload")):
            axes[0].plot(r[:, 0], r[:, 1], label=lab)
            axes[1].plot(np.hypot(r[:, 0], r[:, 1]), r[:, 2], label=lab)
        axes[0].set_aspect("equal", adjustable="datalim")
        axes[0].set_xlabel("X [m]")
        axes[0].set_ylabel("Y [m]")
        axes[0].set_title("from above")
        axes[1].set_xlabel("distance from the slew axis [m]")
        axes[1].set_ylabel("Z [m]")
        axes[1].set_title("from the side")
        for ax in axes:
            ax.grid(alpha=0.3)
            ax.legend(loc="best", fontsize=8)
        fig.tight_layout()
        paths.append(save_figure(fig, out / "tip_path.png"))
        plt.close(fig)
    return paths
