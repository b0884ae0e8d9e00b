"""Validation against Section 9 of Zhao-Qi-Wang 2024: every statement, every contact model.

    python benchmarks/paper_comparison.py                 # all cases (~15 runs), the report
    python benchmarks/paper_comparison.py --quick --out /tmp/pc --report /tmp/pc/validation.md

Runs the three paper scenes (``telescopic_extraction`` = Section 9.2, ``telescopic_retraction``
= its retraction, ``telescopic_extraction_rigid`` = Section 9.1) under every slider-moment model
(contact.moment_model: rigid, seat, couple) and, for the frictional scenes, every friction normal
load (contact.friction_load: resultant, springs), and writes

* ``docs/validation.md``: one row per quantitative or qualitative statement of Section 9 (figure,
  statement, our value, holds or not) for every model, the luffing-cylinder reading and the
  reasons where a statement does not hold;
* figures ``docs/img/validation_*.png``: the models side by side;
* ``benchmarks/results/paper_comparison/summary.csv``: wall time, steps and the headline values
  of every case (the result folders themselves are not committed).

A case whose result file exists is loaded, not re-run (``--rerun`` forces it).  ``--quick`` runs
every case at 2 sub-elements per spline element (n_nodes = 3) instead of the paper's 8, for the
slow test suite.  Result files and the report are written atomically.
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sim_core import Result, load_scene, simulate  # noqa: E402
from sim_core.result import atomic_write_bytes  # noqa: E402
from sim_core.validation.closed_form import luffing_geometry, static_luffing_forces  # noqa: E402

MODELS = ("rigid", "seat", "couple")
LOADS = ("resultant", "springs")
DEFAULT = ("rigid", "resultant")
THETA = math.radians(60.0)
MU_D = 0.1
# slider springs per region, in sim_core.physics.contact order: arc by arc (P1, P2, P3), within an arc
# the front end (k_s = +1, towards the payload: the paper's rounding I-x) then the back end
# (k_s = -1, towards the platform: II-x), 20 springs per quarter arc and end
NQ = 20
ARCS = {"I-1": (0, NQ), "II-1": (NQ, 2 * NQ), "I-2": (2 * NQ, 3 * NQ), "II-2": (3 * NQ, 4 * NQ),
        "I-3": (4 * NQ, 6 * NQ), "II-3": (6 * NQ, 8 * NQ)}


@dataclass(frozen=True)
class Case:
    scene: str
    moment_model: str
    friction_load: str | None          # None: frictionless scene

    @property
    def key(self) -> str:
        return f"{self.scene}__{self.moment_model}" + (
            f"_{self.friction_load}" if self.friction_load else "")

    @property
    def label(self) -> str:
        return self.moment_model + (f" / {self.friction_load}" if self.friction_load else "")

    @property
    def is_default(self) -> bool:
        return self.moment_model == DEFAULT[0] and self.friction_load in (None, DEFAULT[1])


def _cell(text: str) -> str:
    """A markdown table cell's text with its "|" escaped."""
    return str(text).replace("|", "\\|")


def cases() -> list[Case]:
    out = []
    for scene in ("telescopic_extraction", "telescopic_retraction"):
        out += [Case(scene, mm, fl) for mm in MODELS for fl in LOADS]
    out += [Case("telescopic_extraction_rigid", mm, None) for mm in MODELS]
    return out


def run_case(case: Case, out: Path, quick: bool, rerun: bool) -> Result:
    path = out / case.key / "result.npz"
    if path.exists() and not rerun:
        return Result.load(path)
    overrides = {"contact.moment_model": case.moment_model}
    if case.friction_load:
        overrides["contact.friction_load"] = case.friction_load
    if quick:
        overrides["booms.n_nodes"] = 3
    sc = load_scene(case.scene, overrides)
    t0 = time.perf_counter()
    res = simulate(sc)
    res.stats.setdefault("wall_s", time.perf_counter() - t0)
    res.save(path)
    return res


# ----------------------------------------------------------------------------- measurements

def window(res: Result, a: float, b: float) -> np.ndarray:
    return (res.t >= a - 1e-9) & (res.t <= b + 1e-9)


def smooth(t: np.ndarray, y: np.ndarray, width: float = 1.0) -> np.ndarray:
    """Moving average over ``width`` s (removes the booms' oscillation from a trend)."""
    dt = float(np.median(np.diff(t)))
    n = max(1, int(round(width / dt)))
    k = np.ones(n) / n
    pad = np.pad(y, (n // 2, n - 1 - n // 2), mode="edge")
    return np.convolve(pad, k, mode="valid")


def at(res: Result, y: np.ndarray, time_s: float) -> float:
    return float(np.interp(time_s, res.t, y))


def contact(res: Result, region: str) -> np.ndarray:
    """(n_t, 6) force and moment (section components s, t, b) of a region (I_12, II_12, I_23,
    II_23) on the body the paper reports: boom k at its inner contact point (I), boom k+1 at
    its outer contact point (II)."""
    kind, pair = region.split("_")
    return res["contact_point_forces"][:, int(pair[0]) - 1, 0 if kind == "I" else 1, :]


def frac(mask: np.ndarray) -> float:
    return float(np.mean(mask)) if mask.size else float("nan")


def rigid_tip(res: Result, sign: int) -> np.ndarray:
    """Eq. 75: r0 + 2 s0(t) (cos theta, sin theta) in (X, Z), r0 the initial tip."""
    s0 = sign * res["piston_stroke"] if sign > 0 else res["piston_stroke"]
    e = np.array([math.cos(THETA), math.sin(THETA)])
    return res["tip_position"][0, [0, 2]] + 2.0 * s0[:, None] * e


@dataclass
class Row:
    figure: str
    statement: str
    value: str
    holds: bool | None                 # None: reported, nothing to hold
    note: str = ""


def ok(b) -> bool:
    return bool(b)


def moment_row(figure: str, where: str, c: np.ndarray, sign: int) -> Row:
    """'Only the moment about e_t, of this sign': m_t of the sign at >= 95 % of the times,
    the other two components below 5 % of max |m_t|; ``c`` (n_t, 6) a region's contact()."""
    mt = np.max(np.abs(c[:, 4]))
    other = max(np.max(np.abs(c[:, 3])), np.max(np.abs(c[:, 5])))
    share = frac(sign * c[:, 4] > 0)
    word, rel = ("positive", ">") if sign > 0 else ("negative", "<")
    return Row(figure, f"{where}: only the moment about e_t, {word}",
               f"max |m_t| = {mt / 1e3:.0f} kN m, m_t {rel} 0 at {100 * share:.0f} %, other "
               f"components <= {other / max(mt, 1e-30):.1e} of it",
               ok(mt > 1e3 and other < 0.05 * mt and share >= 0.95))


def extraction_rows(res: Result) -> list[Row]:
    t = res.t
    Ft = res["telescopic_cylinder_force"]
    Fl = res["luffing_cylinder_force"]
    sc = res.scene.get("params", {})
    mp = sc.get("payload", 25000.0)
    stat = static_luffing_forces(THETA, 2.0, mp)
    rows = []
    F0 = Ft[0]
    rows.append(Row("27", "Telescopic-cylinder force starts at the static value m2 g sin(theta) "
                    "+ 2 T of the frictionless rigid boom "
                    "([check: static luffing](model.md#check-static-luffing))",
                    f"{F0 / 1e6:.4f} MN vs {stat.telescopic_force / 1e6:.4f} MN",
                    ok(abs(F0 / stat.telescopic_force - 1) < 0.02)))
    sm = smooth(t, Ft)
    dev = np.max(np.abs(sm / F0 - 1.0))
    rows.append(Row("27", "Telescopic-cylinder force stays within a few percent of its initial "
                    "value through the extraction (its 1 s average within 10 %; the booms' "
                    "oscillation rides on it)",
                    f"1 s average within {100 * dev:.1f} % (equilibrium's lower bound while "
                    f"sliding: +{100 * friction_floor(mp) / F0:.1f} %); raw peak "
                    f"{np.max(Ft) / 1e6:.3f} MN (+{100 * (np.max(Ft) / F0 - 1):.0f} %)",
                    ok(dev < 0.10)))
    w = window(res, 0.5, 15.5)
    t_peak = float(t[w][np.argmax(sm[w])])
    rows.append(Row("27", "The telescopic force has its maximum near 8 s (1 s moving average)",
                    f"maximum at {t_peak:.1f} s", ok(6.0 <= t_peak <= 10.0)))
    late = window(res, 18.0, 20.0)
    mean_late = float(np.mean(Ft[late]))
    rows.append(Row("27", "After 16 s the telescopic force settles a little below its initial "
                    "value (within 10 % below)",
                    f"mean 18-20 s = {mean_late / F0:.3f} F(0)",
                    ok(0.9 * F0 <= mean_late < F0)))
    g = luffing_geometry(THETA)
    stat16 = static_luffing_forces(THETA, 8.0, mp)
    rows.append(Row("27", "Luffing-cylinder force at t = 0 from the printed geometry (lever "
                    f"{g.lever:.3f} m about D1 at 60 deg; "
                    "[inputs: luffing](model.md#input-luffing), "
                    "[check: static luffing](model.md#check-static-luffing))",
                    f"{Fl[0] / 1e6:.3f} MN vs {stat.luffing_force / 1e6:.3f} MN (rigid statics)",
                    ok(abs(Fl[0] / stat.luffing_force - 1) < 0.02)))
    sl = smooth(t, Fl)
    rows.append(Row("27", "The luffing-cylinder force increases gradually during the extraction "
                    "(1 s average at 0, 4, 8, 12, 16 s) and then stabilises (std 18-20 s < 1 %)",
                    f"{sl[0] / 1e6:.2f} -> {at(res, sl, 16.0) / 1e6:.2f} MN (static at L_s = 8 m: "
                    f"{stat16.luffing_force / 1e6:.2f} MN); std 18-20 s = "
                    f"{100 * np.std(Fl[late]) / np.mean(Fl[late]):.2f} %",
                    ok(all(at(res, sl, b) > at(res, sl, a)
                           for a, b in ((0.0, 4.0), (4.0, 8.0), (8.0, 12.0), (12.0, 16.0)))
                       and np.std(Fl[late]) < 0.01 * np.mean(Fl[late]))))
    dev_tip = np.linalg.norm(res["tip_position"][:, [0, 2]] - rigid_tip(res, +1), axis=1)
    ds = [at(res, smooth(t, dev_tip), x) for x in (4.0, 8.0, 12.0, 16.0)]
    rows.append(Row("19", "The tip deviates gradually from the rigid-limit solution (Eq. 75) as "
                    "the booms extend", "deviation at 4/8/12/16 s = "
                    + "/".join(f"{1e3 * d:.0f}" for d in ds) + " mm",
                    ok(all(b > a for a, b in zip(ds, ds[1:])))))
    a_rigid = 2.0 * np.gradient(np.gradient(res["piston_stroke"], t), t)
    acc = res["tip_acceleration"][:, [0, 2]] @ np.array([math.cos(THETA), math.sin(THETA)])
    u = window(res, 4.5, 11.5)
    rms = float(np.sqrt(np.mean((acc[u] - a_rigid[u]) ** 2)))
    rows.append(Row("21", "The tip acceleration fluctuates during the uniform motion (4-12 s)",
                    f"rms of a - a_rigid along the boom = {rms:.3f} m/s^2 (drive peak "
                    "0.375 m/s^2)", ok(rms > 0.01)))
    I23, II23 = contact(res, "I_23"), contact(res, "II_23")
    slide = window(res, 1.0, 15.5)
    rows.append(Row("24a", "Boom 2, inner contact point: axial force positive (friction along "
                    "the extraction)", f"f_s > 0 at {100 * frac(I23[slide, 0] > 0):.0f} % of "
                    "1-15.5 s", ok(frac(I23[slide, 0] > 0) >= 0.95)))
    allt = window(res, 0.0, 20.0)
    pos = np.flatnonzero(I23[:, 2] >= 0)
    last_pos = float(t[pos[-1]]) if pos.size else float("nan")
    rows.append(Row("24a", "Boom 2, inner contact point: vertical force negative",
                    f"f_b < 0 at {100 * frac(I23[allt, 2] < 0):.0f} % of 0-20 s "
                    f"(f_b(0) = {I23[0, 2] / 1e3:.0f} kN, >= 0 until {last_pos:.1f} s; "
                    f"f_b(16 s) = {at(res, I23[:, 2], 16.0) / 1e3:.0f} kN)",
                    ok(frac(I23[allt, 2] < 0) >= 0.95)))
    rows.append(moment_row("25a", "Boom 2, inner contact point", I23[allt], +1))
    rows.append(Row("24b", "Boom 3, outer contact point: axial force negative",
                    f"f_s < 0 at {100 * frac(II23[slide, 0] < 0):.0f} % of 1-15.5 s",
                    ok(frac(II23[slide, 0] < 0) >= 0.95)))
    rows.append(Row("24b", "Boom 3, outer contact point: vertical force positive",
                    f"f_b > 0 at {100 * frac(II23[allt, 2] > 0):.0f} % of 0-20 s",
                    ok(frac(II23[allt, 2] > 0) >= 0.95)))
    rows.append(moment_row("25b", "Boom 3, outer contact point", II23[allt], -1))

    def trend(y):
        s = smooth(t, np.abs(y))
        return at(res, s, 1.0), at(res, s, 8.0)
    fI, mI = trend(I23[:, 2]), trend(I23[:, 4])
    fII, mII = trend(II23[:, 2]), trend(II23[:, 4])
    rows.append(Row("24a/25a", "Section 9.2 (3): up to 8 s the force and moment at boom 2's inner "
                    "contact point grow", f"|f_b| {fI[0] / 1e3:.0f} -> {fI[1] / 1e3:.0f} kN, "
                    f"|m_t| {mI[0] / 1e3:.0f} -> {mI[1] / 1e3:.0f} kN m",
                    ok(fI[1] > fI[0] and mI[1] > mI[0])))
    rows.append(Row("24b/25b", "Section 9.2 (3): up to 8 s the force at boom 3's outer contact "
                    "point falls and its moment grows", f"|f_b| {fII[0] / 1e3:.0f} -> "
                    f"{fII[1] / 1e3:.0f} kN, |m_t| {mII[0] / 1e3:.0f} -> {mII[1] / 1e3:.0f} kN m",
                    ok(fII[1] < fII[0] and mII[1] > mII[0])))
    sliding = window(res, 4.0, 12.0)
    ratio = np.median(np.abs(I23[sliding, 0]) / np.maximum(np.abs(I23[sliding, 2]), 1.0))
    rows.append(Row("24", "Section 9.2 (4): the axial and vertical components fluctuate together, "
                    "by the Coulomb ratio (mu_d = 0.1 while sliding)",
                    f"median |f_s| / |f_b| at boom 2's inner contact point, 4-12 s = {ratio:.3f}",
                    ok(abs(ratio / MU_D - 1) < 0.2)))
    if "slider_contact_forces" in res:
        sf = res["slider_contact_forces"]
        i16 = int(np.argmin(np.abs(t - 16.0)))
        loaded, sym = [], []
        for reg in (2, 3):                   # I_23 (left end of boom 3), II_23 (right end of 2)
            f = sf[i16, reg]
            tot = float(np.sum(f))
            part = sum(float(np.sum(f[a:b])) for nm, (a, b) in ARCS.items()
                       if nm in ("II-1", "II-2", "I-3"))
            loaded.append(part / tot if tot > 0 else float("nan"))
            p1 = float(np.sum(f[0:2 * NQ]))
            p2 = float(np.sum(f[2 * NQ:4 * NQ]))
            sym.append(abs(p1 - p2) / tot if tot > 0 else float("nan"))
        rows.append(Row("26", "At 16 s only roundings II-1, II-2 and I-3 carry force (left-end "
                        "slider of boom 3, right-end slider of boom 2)",
                        f"share on II-1, II-2, I-3: {100 * loaded[0]:.1f} % / "
                        f"{100 * loaded[1]:.1f} %", ok(min(loaded) > 0.99)))
        rows.append(Row("26", "The slider forces are symmetric about the vertical plane",
                        f"|P1 - P2| / total = {max(sym):.1e}", ok(max(sym) < 0.01)))
        tot_t = np.sum(sf[:, 2], axis=1) + np.sum(sf[:, 3], axis=1)
        s_tot = smooth(t, tot_t)
        rows.append(Row("26", "Figs. A1-A2: the slider forces grow with the extraction and level "
                        "off after 16 s", f"sum on both sliders {at(res, s_tot, 1.0) / 1e3:.0f} "
                        f"-> {at(res, s_tot, 8.0) / 1e3:.0f} -> {at(res, s_tot, 16.0) / 1e3:.0f} kN;"
                        f" std 18-20 s {100 * np.std(tot_t[late]) / np.mean(tot_t[late]):.1f} %",
                        ok(at(res, s_tot, 8.0) > at(res, s_tot, 1.0)
                           and np.std(tot_t[late]) < 0.05 * np.mean(tot_t[late]))))
    return rows


def friction_floor(payload: float, mu: float = MU_D, g: float = 9.81) -> float:
    """Lower bound (N) of the friction in the telescopic-cylinder force while every region
    slides, whatever the contact model: a pair's two regions carry at least the transverse
    weight outboard of it (|F_I| + |F_II| >= |F_I + F_II|), pair 2-3 boom 3 and the payload,
    pair 1-2 booms 2, 3 and the payload; the rope doubles pair 2-3's friction at the cylinder
    (F_cyl = m2 g sin(theta) + 2 T + friction_12, T = (m3 + m_p) g sin(theta) + friction_23)."""
    m2, m3 = 10.0 * 304.07, 10.0 * 289.27                  # Table 2, 10 m booms
    w23 = (m3 + payload) * g * math.cos(THETA)
    w12 = (m2 + m3 + payload) * g * math.cos(THETA)
    return mu * (2.0 * w23 + w12)


def retraction_rows(res: Result) -> list[Row]:
    t = res.t
    Ft = res["telescopic_cylinder_force"]
    I23, II23 = contact(res, "I_23"), contact(res, "II_23")
    slide = window(res, 1.0, 15.5)
    rows = [
        Row("8.3 (2)", "Retraction: friction on boom 2's inner contact point points against e_s",
            f"f_s < 0 at {100 * frac(I23[slide, 0] < 0):.0f} % of 1-15.5 s",
            ok(frac(I23[slide, 0] < 0) >= 0.95)),
        Row("8.3 (2)", "Retraction: friction on boom 3's outer contact point points along e_s",
            f"f_s > 0 at {100 * frac(II23[slide, 0] > 0):.0f} % of 1-15.5 s",
            ok(frac(II23[slide, 0] > 0) >= 0.95)),
        Row("-", "Telescopic-cylinder force (no statement in the paper: reported)",
            f"{Ft[0] / 1e6:.3f} MN at 0 s, extremes {np.min(Ft) / 1e6:.3f} / "
            f"{np.max(Ft) / 1e6:.3f} MN, {at(res, Ft, 20.0) / 1e6:.3f} MN at 20 s", None),
    ]
    del t
    return rows


def rigid_rows(res: Result) -> list[Row]:
    t = res.t
    tip = res["tip_position"][:, [0, 2]]
    dev = np.linalg.norm(tip - rigid_tip(res, +1), axis=1)
    vel = res["tip_velocity"][:, [0, 2]]
    v_rigid = 2.0 * np.gradient(res["piston_stroke"], t)[:, None] * np.array(
        [math.cos(THETA), math.sin(THETA)])
    dv = np.max(np.linalg.norm(vel - v_rigid, axis=1))
    Ft, Fl = res["telescopic_cylinder_force"], res["luffing_cylinder_force"]
    a = np.gradient(np.gradient(res["piston_stroke"], t), t)
    sm = smooth(t, Ft - Ft[0], 0.5)
    corr = float(np.corrcoef(sm, a)[0, 1])
    stat = static_luffing_forces(THETA, 2.0, 1000.0)
    return [
        Row("16-17", "Tip position follows the rigid kinematics (Eq. 75) to a small error",
            f"max |r - r_rigid| = {1e3 * np.max(dev):.1f} mm over a 12 m travel",
            ok(np.max(dev) < 0.01)),
        Row("16-17", "Tip velocity follows Eq. 76", f"max |v - v_rigid| = {dv:.3f} m/s "
            "(peak 1.0 m/s)", ok(dv < 0.1)),
        Row("18", "Luffing-cylinder force increases gradually",
            f"{Fl[0] / 1e6:.3f} -> {at(res, Fl, 16.0) / 1e6:.3f} MN",
            ok(at(res, smooth(t, Fl), 16.0) > Fl[0])),
        Row("18", "Telescopic-cylinder force starts at the static value and follows the drive's "
            "acceleration", f"F(0) = {Ft[0] / 1e3:.1f} kN vs {stat.telescopic_force / 1e3:.1f} kN;"
            f" correlation of F - F(0) (0.5 s average) with a(t) = {corr:.2f}",
            ok(abs(Ft[0] / stat.telescopic_force - 1) < 0.02 and corr > 0.8)),
    ]


# ----------------------------------------------------------------------------- report

def figure(results: dict, scene: str, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    chosen = [(c, r) for c, r in results.items() if c.scene == scene]
    fig, ax = plt.subplots(2, 3, figsize=(15, 7.5), constrained_layout=True)
    for c, r in chosen:
        style = dict(lw=2.0 if c.is_default else 0.9, label=c.label)
        ax[0, 0].plot(r.t, r["telescopic_cylinder_force"] / 1e6, **style)
        ax[0, 1].plot(r.t, r["luffing_cylinder_force"] / 1e6, **style)
        I23, II23 = contact(r, "I_23"), contact(r, "II_23")
        ax[0, 2].plot(r.t, I23[:, 2] / 1e3, **style)
        ax[1, 0].plot(r.t, II23[:, 2] / 1e3, **style)
        ax[1, 1].plot(r.t, I23[:, 4] / 1e3, **style)
        ax[1, 2].plot(r.t, II23[:, 4] / 1e3, **style)
    titles = ["telescopic cylinder (MN)", "luffing cylinder (MN)",
              "boom 2 inner contact f_b (kN)", "boom 3 outer contact f_b (kN)",
              "boom 2 inner contact m_t (kN m)", "boom 3 outer contact m_t (kN m)"]
    for a_, ti in zip(ax.flat, titles):
        a_.set_title(ti)
        a_.set_xlabel("t (s)")
        a_.grid(alpha=0.3)
    ax[0, 0].legend(fontsize=8)
    fig.suptitle(f"{scene}: contact models side by side (thick: default)")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())


def slider_figure(res: Result, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    i16 = int(np.argmin(np.abs(res.t - 16.0)))
    fig, ax = plt.subplots(1, 2, figsize=(12, 3.5), constrained_layout=True)
    for a_, reg, ti in zip(ax, (2, 3), ("left-end slider of boom 3 (I_23)",
                                        "right-end slider of boom 2 (II_23)")):
        f = res["slider_contact_forces"][i16, reg]
        for nm, (a0, b0) in ARCS.items():
            a_.plot(np.arange(a0, b0), f[a0:b0] / 1e3, ".-", label=nm)
        a_.set_title(f"{ti}, t = 16 s")
        a_.set_xlabel("spring (arc by arc)")
        a_.set_ylabel("normal force (kN)")
        a_.grid(alpha=0.3)
    ax[0].legend(fontsize=8, ncol=3)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())


REASONS = {
    "within a few percent":
        "Equilibrium bounds the friction from below whatever the contact model (the lower bound "
        "in the row, benchmarks/paper_comparison.friction_floor): while every region slides at "
        "mu_d = 0.1, each pair's two regions carry at least the transverse weight outboard of "
        "it, and the rope doubles pair 2-3's friction at the cylinder. The rigid sections carry "
        "part of the overlap's moment as opposed shear forces at the two regions of a pair "
        "(Fig. 24a/24b rows), which adds to that floor. A force within a few percent of its "
        "static value, as the paper's figure shows, needs a friction coefficient of a few "
        "hundredths; the scenes keep the paper's stated mu_d = 0.1. Friction from the slider "
        "springs (`springs`) or the crane-design couple (`couple`) raises the force much "
        "further (other columns).",
    "maximum near 8 s":
        "The 1 s average forms a broad plateau from ~2 s to ~11 s (friction fully developed, "
        "the stroke rate constant from 4 to 12 s) on which the booms' slow oscillation decides "
        "where the highest point falls; the value at 8 s is within a few percent of it "
        "(figure). The paper's peak at 8 s is where boom 3's left end passes boom 1's right end "
        "(L_s = 5 m).",
    "vertical force negative":
        "At the start (L_s = 2 m, an 8 m overlap of booms 2 and 3) the left end of boom 3 "
        "presses boom 2 upwards, as the inner support of a beam on two supports does; as the "
        "overlap shortens, the moment that the rigid sections transmit turns this shear "
        "downwards for the rest of the run. Under the rigid model the regions' forces converge "
        "only at first order in the sub-element length "
        "(tests/telescopic/test_moment_models.py), so the time of the sign change depends on "
        "the mesh; the paper's 'always negative' is not reproduced before the time in the row.",
}

ROWS = {"telescopic_extraction": extraction_rows, "telescopic_retraction": retraction_rows,
        "telescopic_extraction_rigid": rigid_rows}
TITLES = {"telescopic_extraction_rigid": "Section 9.1: nearly rigid booms, 1 t, no friction",
          "telescopic_extraction": "Section 9.2: extraction, 25 t, friction 0.1 / 0.15",
          "telescopic_retraction": "Retraction, 25 t, friction 0.1 / 0.15"}


def mark(h) -> str:
    return "-" if h is None else ("holds" if h else "**does not hold**")


def report(results: dict, img: Path, report_path: Path, quick: bool,
           machine: str = "machine state not recorded") -> str:
    lines = [
        "# Validation against the paper (Section 9)",
        "",
        "Generated by `python benchmarks/paper_comparison.py` from the three paper scenes run "
        "under every slider-moment model (`contact.moment_model`) and friction normal load "
        "(`contact.friction_load`); do not edit by hand."
        + (" **Quick mode: 2 sub-elements per spline element, not the paper's 8.**"
           if quick else " The paper's discretisation: 8 sub-elements per spline element."),
        "",
        "The paper's result values are withheld from `shared/seeds`; the statements below are "
        "its text on its figures (signs, which components vanish, trends, the rounding "
        "pattern). Fig. 27 is the 25 t extraction's cylinder-force figure (the issue that "
        "asked for this report calls it Fig. 18, the figure of the 1 t case of Section 9.1).",
        "",
        "## Defaults and why",
        "",
        "The paper scenes run with `moment_model = \"rigid\"` and `friction_load = "
        "\"resultant\"`:",
        "",
        "* **rigid** is Section 6 as printed, and the only model that reproduces what "
        "Section 9.2 says of Figs. 25-26: moments at the contact points about e_t only, and "
        "the rounding pattern II-1, II-2, I-3 (a force couple across each slider). `couple` "
        "has no contact moments at all; `seat` with a real pad's compliance leaves only small "
        "ones.",
        "* **resultant**: the friction's normal load is the transverse contact resultant "
        "|(f_t, f_b)|. With the rigid model a slider of width 2w = 0.3 m carries the overlap's "
        "moment M as a couple of about M/(2w), so the spring sum of Eq. 72 grows as 1/w: in "
        "the limit of a narrow slider, in which Section 6 derives the rigid constraint, that "
        "friction load diverges, while the resultant is fixed by equilibrium whatever the "
        "slider width. It is also what Section 9.2 (4) describes (the axial component follows "
        "the vertical one by the Coulomb ratio) and what keeps the telescopic-cylinder force of "
        "Fig. 27 within ~20 % of its static value, near the floor that equilibrium sets for "
        "friction 0.1; Eq. 72 literally (`springs`) gives ten times that force.",
        "",
        "`couple` is the usual assumption of crane design (the overlap carries its moment as "
        "the pair P L_s / a, P L / a); `seat` puts a stated pad compliance between the two "
        "(`contact.seat_stiffness`, default 1e8 N m/rad for a 20 mm polyamide pad). Both are "
        "one override away: `--set contact.moment_model=couple`.",
        "",
    ]
    for scene in ("telescopic_extraction_rigid", "telescopic_extraction", "telescopic_retraction"):
        chosen = [(c, r) for c, r in results.items() if c.scene == scene]
        if not chosen:
            continue
        lines += [f"## {TITLES[scene]} (`{scene}`)", ""]
        table = {c: ROWS[scene](r) for c, r in chosen}
        base = table[chosen[0][0]]
        header = "| Fig. | statement | " + " | ".join(
            f"{c.label}{' (default)' if c.is_default else ''}" for c, _ in chosen) + " |"
        lines += [header, "|" + "---|" * (2 + len(chosen))]
        for i, row in enumerate(base):
            # a "|" inside a cell (|r - r_rigid|) is escaped, or it would split the cell
            cells = [_cell(f"{table[c][i].value}: {mark(table[c][i].holds)}")
                     for c, _ in chosen]
            lines.append(f"| {row.figure} | {_cell(row.statement)} | " + " | ".join(cells)
                         + " |")
        lines += ["", f"Wall times as the runs recorded them ({machine}); speed figures are on "
                  "the [performance](performance.md) page.", "",
                  "| model | wall time (s) | steps | status |", "|---|---|---|---|"]
        for c, r in chosen:
            st = r.stats
            lines.append(f"| {c.label} | {st.get('wall_s', float('nan')):.0f} | "
                         f"{st.get('n_steps', st.get('steps', '-'))} | "
                         f"{'stopped: ' + r.error if r.error else 'complete'} |")
        lines += ["", f"![{scene}](img/validation_{scene}.png)", ""]
    lines += ["## Statements that do not hold under the defaults, and why", ""]
    failing = [(c, row) for c, r in results.items() if c.is_default
               for row in ROWS[c.scene](r) if row.holds is False]
    for c, row in failing:
        why = next((text for key, text in REASONS.items() if key in row.statement),
                   "no explanation recorded")
        lines += [f"* **{c.scene}, Fig. {row.figure}: {row.statement}** ({row.value}). {why}",
                  ""]
    if not failing:
        lines += ["Every statement holds under the defaults.", ""]
    lines += [
        "The contact models themselves are described in "
        "[the model's decisions](model.md#contact-models).",
        "",
        "## The luffing-cylinder force",
        "",
        "The printed coordinates of D1, D2, D3 ([inputs: luffing](model.md#input-luffing)) put "
        "the luffing cylinder's line "
        f"{luffing_geometry(THETA).lever:.3f} m from the pivot D1 at 60 deg. With that lever the "
        "moment of the booms and the 25 t payload about D1 needs "
        f"{static_luffing_forces(THETA, 2.0, 25000.0).luffing_force / 1e6:.2f} MN at L_s = 2 m "
        f"and {static_luffing_forces(THETA, 8.0, 25000.0).luffing_force / 1e6:.2f} MN at "
        "L_s = 8 m (rigid statics, [check: static luffing](model.md#check-static-luffing)), and "
        "the dynamic runs agree with it at t = 0 "
        "(rows above). A lever below 0.72 m (|D1 D2|) is short for a crane of this size, and "
        "the rotation matrix of the printed equation lost its signs, so this reading is "
        "uncertain: it follows the printed numbers, and the force scales with 1/lever if the "
        "figure's geometry differs. The shape (growing with the extraction, level after 16 s) "
        "does not depend on the lever.",
        "",
        "## Slider forces at 16 s (default model)",
        "",
        "![slider forces](img/validation_sliders.png)",
        "",
    ]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "paper_comparison"))
    ap.add_argument("--report", default=str(ROOT / "docs" / "validation.md"))
    ap.add_argument("--quick", action="store_true", help="2 sub-elements per spline element")
    ap.add_argument("--rerun", action="store_true", help="run cases whose result exists")
    ap.add_argument("--only", choices=("all", "default"), default="all",
                    help="'default': only the default models")
    ap.add_argument("--machine", default="machine state not recorded",
                    help="the machine state the runs had, for the report's wall times")
    args = ap.parse_args(argv)
    out, report_path = Path(args.out), Path(args.report)
    img = report_path.parent / "img"
    results = {}
    rows = []
    for case in cases():
        if args.only == "default" and not case.is_default:
            continue
        t0 = time.perf_counter()
        res = run_case(case, out, args.quick, args.rerun)
        results[case] = res
        Ft = res["telescopic_cylinder_force"]
        rows.append({"case": case.key, "wall_s": res.stats.get("wall_s", ""),
                     "steps": res.stats.get("n_steps", res.stats.get("steps", "")),
                     "error": res.error or "", "F_tel_0_N": Ft[0], "F_tel_max_N": np.max(Ft),
                     "F_tel_20s_N": Ft[-1], "F_luff_0_N": res["luffing_cylinder_force"][0]})
        print(f"{case.key}: {time.perf_counter() - t0:.0f} s, F_tel {Ft[0] / 1e6:.3f} -> max "
              f"{np.max(Ft) / 1e6:.3f} MN", flush=True)
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
    atomic_write_bytes(out / "summary.csv", buf.getvalue().encode())
    for scene in ROWS:
        if any(c.scene == scene for c in results):
            figure(results, scene, img / f"validation_{scene}.png")
    default = next((r for c, r in results.items()
                    if c.scene == "telescopic_extraction" and c.is_default), None)
    if default is not None and "slider_contact_forces" in default:
        slider_figure(default, img / "validation_sliders.png")
    atomic_write_bytes(report_path, report(results, img, report_path, args.quick,
                                           args.machine).encode())
    print(f"report: {report_path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
