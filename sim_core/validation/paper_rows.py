"""The statements of Section 9 of Zhao-Qi-Wang 2024 as rows computed from a result.

T. Zhao, Z. Qi, T. Wang, "Dynamic Contact Analysis of Flexible Telescopic Boom Systems with
Moving Boundary", Mathematics 12 (2024) 2496, Section 9: the paper's text on its Figs. 16-27
(signs, which components vanish, trends, the rounding pattern of the sliders) and the rigid-limit
kinematics of Eqs. 75-76.  One function per paper scene (:data:`ROWS`) turns a result of that
scene into :class:`Row` objects (figure, statement, our value, whether it holds).
``benchmarks/paper_comparison.py`` runs the scenes under every contact model and writes
docs/validation.md from these rows; :mod:`sim_core.report` shows them for a single run.

The rows read the paper's whole run (windows up to :data:`T_END` = 20 s) and the outputs in
:data:`NEEDS`; :func:`not_applicable` says why a result has no rows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_core.result import Result
from sim_core.validation.closed_form import luffing_geometry, static_luffing_forces

THETA = math.radians(60.0)
MU_D = 0.1
# slider springs per region, in sim_core.physics.contact order: arc by arc (P1, P2, P3), within an arc
# the front end (k_s = +1, towards the payload: the paper's rounding I-x) then the back end
# (k_s = -1, towards the platform: II-x), 20 springs per quarter arc and end
NQ = 20
ARCS = {"I-1": (0, NQ), "II-1": (NQ, 2 * NQ), "I-2": (2 * NQ, 3 * NQ), "II-2": (3 * NQ, 4 * NQ),
        "I-3": (4 * NQ, 6 * NQ), "II-3": (6 * NQ, 8 * NQ)}


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


ROWS = {"telescopic_extraction": extraction_rows, "telescopic_retraction": retraction_rows,
        "telescopic_extraction_rigid": rigid_rows}
TITLES = {"telescopic_extraction_rigid": "Section 9.1: nearly rigid booms, 1 t, no friction",
          "telescopic_extraction": "Section 9.2: extraction, 25 t, friction 0.1 / 0.15",
          "telescopic_retraction": "Retraction, 25 t, friction 0.1 / 0.15"}
#: The paper's runs last 20 s (Section 9); the rows read windows up to that time.
T_END = 20.0
#: The outputs each scene's rows read (``slider_contact_forces`` adds Fig. 26's rows where
#: present).
NEEDS = {
    "telescopic_extraction": ("telescopic_cylinder_force", "luffing_cylinder_force",
                              "tip_position", "tip_acceleration", "piston_stroke",
                              "contact_point_forces"),
    "telescopic_retraction": ("telescopic_cylinder_force", "contact_point_forces"),
    "telescopic_extraction_rigid": ("tip_position", "tip_velocity", "piston_stroke",
                                    "telescopic_cylinder_force", "luffing_cylinder_force"),
}


def scene_rows(res: Result) -> list[Row]:
    """The rows of the paper scene that ``res`` ran (``res.scene["name"]``); ValueError naming
    why where it has none (:func:`not_applicable`)."""
    why = not_applicable(res)
    if why:
        raise ValueError(why)
    return ROWS[res.scene["name"]](res)


def not_applicable(res: Result) -> str:
    """Why ``res`` has no comparison rows ("" if it has them): not a paper scene, a run that
    stops before :data:`T_END`, or an output the rows read missing."""
    name = res.scene.get("name")
    if name not in ROWS:
        return f"scene {name!r} is not one of the paper scenes ({', '.join(sorted(ROWS))})"
    t_last = float(res.t[-1]) if len(res.t) else 0.0
    if len(res.t) < 3 or res.t[0] > 1e-9 or t_last < T_END - 1e-9:
        return (f"the paper's statements cover 0 to {T_END:g} s; this run covers "
                f"{float(res.t[0]) if len(res.t) else 0.0:g} to {t_last:g} s")
    missing = [k for k in NEEDS[name] if k not in res]
    if missing:
        return f"the result has no {', '.join(missing)} (the rows of {name} read them)"
    return ""
