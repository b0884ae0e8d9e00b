"""The telescopic figures of the CLI (paper Section 9: Figs. 14-17, 22-26)."""

import numpy as np

from sim_core.cli import main
from sim_core.result import Result


def _result(n=41, t_end=20.0):
    """A result with the telescopic outputs: a rigid extraction at 60 deg (tip = tip_0 + 2 s e)
    plus a known 5 mm vertical offset, contact forces and slider springs."""
    t = np.linspace(0.0, t_end, n)
    s = 6.0 * (t / t_end) ** 2 * (3.0 - 2.0 * t / t_end)
    e = np.array([np.cos(np.radians(60.0)), 0.0, np.sin(np.radians(60.0))])
    tip = np.array([7.5, 0.0, 13.0]) + 2.0 * s[:, None] * e
    tip[1:, 2] -= 0.005
    out = {"tip_position": tip, "tip_velocity": np.gradient(tip, t, axis=0),
           "tip_acceleration": np.zeros_like(tip), "piston_stroke": s,
           "luffing_cylinder_force": np.full(n, 3.3e6),
           "telescopic_cylinder_force": np.full(n, 5e5),
           "contact_point_forces": np.ones((n, 2, 2, 6)) * 1e5,
           "slider_contact_forces": np.abs(np.sin(np.arange(160)))[None, None] * np.ones((n, 4, 1))}
    scene = {"kind": "telescopic", "name": "telescopic_extraction",
             "booms": {"luffing_angle_deg": 60.0}}
    return Result(t, out, {}, scene)


def test_plot_writes_the_telescopic_figures(tmp_path, capsys):
    path = _result().save(tmp_path / "result.npz")
    assert main(["plot", str(path)]) == 0
    assert "wrote 5 figures" in capsys.readouterr().out
    for png in ("tip.png", "cylinder_forces.png", "tip_rigid_limit.png",
                "contact_point_forces.png", "slider_contact_forces.png"):
        data = (tmp_path / png).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


def test_rigid_limit_panel_shows_the_deflection(tmp_path, monkeypatch):
    """The difference panel is tip - (tip_0 + 2 s e): for the synthetic result, -5 mm in Z."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sim_core.systems.telescopic import plots

    figs = []
    orig = plots.save_figure
    monkeypatch.setattr(plots, "save_figure", lambda fig, path: (figs.append(fig), orig(fig, path))[1])
    monkeypatch.setattr(plt, "close", lambda fig=None: None)      # keep the figures to read
    plots.plot_telescopic(_result(), tmp_path)
    diff_ax = figs[0].axes[2]
    z_line = [ln for ln in diff_ax.get_lines() if ln.get_label() == "Z - rigid"][0]
    np.testing.assert_allclose(z_line.get_ydata()[1:], -5.0, atol=1e-9)
    monkeypatch.undo()
    for fig in figs:
        plt.close(fig)
