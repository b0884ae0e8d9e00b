"""The hoisting load case: the dynamic factor phi2 of a lift-off over a grid of crane states.

    from sim_core.dynamic_factor import dynamic_factor
    rows = dynamic_factor("crane_lift_off", {"booms.luffing_angle_deg": [30, 45, 60],
                                             "hoist_drive.v_max": [0.25, 0.5]}, "phi2_out")

Every grid cell is the scene (a telescopic scene with ``effects.ground``: the payload on the
ground, the hoist winding in) with the cell's overrides and two of its own, so that every cell
starts the same way whatever its boom length or luffing angle:

* ``hoist.length`` = the distance from the boom tip (straight booms at t = 0) down to the
  ground plus ``slack`` (m): the payload stands on the ground on a slack rope;
* ``solver.t_end`` = the time the hoist has wound in that slack (from the hoist profile) plus
  ``after`` (s): the rope tightens, takes the load, lifts the payload off and the rope force
  passes its first peak.

The cells run as a sweep (:func:`sim_core.sweep.run_sweep`: Ray tasks, one case folder each)
or one after the other in this process (``serial``, or where Ray is not installed).  Per cell:

* ``phi2`` = the peak hoist-rope force over the static rope force (m_payload + m_hook) g: the
  dynamic factor of hoisting an unrestrained grounded load (EN 13001-2:2014, 4.2.2.2;
  ISO 8686-1:2012, 6.1.2.1.2).  The peak between output samples is the vertex of the parabola
  through the largest sample and its neighbours (the force is smooth there);
* ``phi2_rope_only`` = 1 + (v_h / g) sqrt(k / m), k = EA / L0 at lift-off: the undamped
  lift-off of a rigid crane (docs/model.md#the-hoisting-load-case), beside the simulated one;
* ``tip_deflection_m``: the largest distance of the boom tip from its position at t = 0;
* ``utilisation_boom_<k>``: the peak utilisation of boom k where the result has a
  ``section_utilisation`` output (time, boom, ...); left out otherwise;
* ``phi2_HC1`` ... ``phi2_HC4``: EN 13001-2's phi2 = phi2_min + beta2 v_h of the hoisting
  classes (:data:`HOISTING_CLASSES`) at the cell's steady hoisting speed v_h.

Output folder: the case folders of the sweep, ``dynamic_factor.csv``, ``dynamic_factor.md``
and ``dynamic_factor.png`` (phi2 and the tip deflection against the working radius: the
payload's horizontal distance from the slewing axis, the global Z axis).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sim_core.api import load_scene
from sim_core.errors import SceneError
from sim_core.result import Result, atomic_write_bytes
from sim_core.sweep import (
    RESULT_FILE,
    _write_case,
    csv_bytes,
    out_folder,
    grid_cases,
    prepare_cases,
    run_case,
    run_sweep,
)

#: EN 13001-2:2014 Table 2B (ISO 8686-1:2012 Table 3): hoisting class -> (beta2 s/m, phi2_min);
#: phi2 = phi2_min + beta2 v_h with the characteristic hoisting speed v_h (m/s) of Table 2C,
#: for hoist drive class HD1 (no creep speed) the steady hoisting speed
HOISTING_CLASSES = {"HC1": (0.17, 1.05), "HC2": (0.34, 1.10), "HC3": (0.51, 1.15),
                    "HC4": (0.68, 1.20)}
#: the columns of the table after the grid keys
COLUMNS = ("status", "working_radius_m", "v_h_m_s", "static_rope_force_N", "peak_rope_force_N",
           "phi2", "phi2_rope_only", "t_lift_off_s", "tip_deflection_m")


def en13001_phi2(v_h: float, hoisting_class: str) -> float:
    """phi2 = phi2_min + beta2 v_h (EN 13001-2:2014, Eq. (5) with Table 2B), v_h in m/s."""
    if hoisting_class not in HOISTING_CLASSES:
        raise ValueError(f"hoisting class {hoisting_class!r}: allowed "
                         f"{', '.join(HOISTING_CLASSES)}")
    beta2, phi2_min = HOISTING_CLASSES[hoisting_class]
    return phi2_min + beta2 * v_h


def peak(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(time, value) of the largest value of samples y(t): the vertex of the parabola through
    the largest sample and its two neighbours (the sample itself at an end or where the three
    do not bend down)."""
    y = np.asarray(y, float)
    i = int(np.argmax(y))
    if i == 0 or i == len(y) - 1:
        return float(t[i]), float(y[i])
    t0, t1, t2 = t[i - 1:i + 2]
    y0, y1, y2 = y[i - 1:i + 2]
    A = np.array([[t0 * t0, t0, 1.0], [t1 * t1, t1, 1.0], [t2 * t2, t2, 1.0]])
    a, b, c = np.linalg.solve(A, [y0, y1, y2])
    if a >= 0.0:
        return float(t1), float(y1)
    tv = -b / (2.0 * a)
    return float(tv), float(c - b * b / (4.0 * a))


def _check_scene(sc: dict, where: str) -> None:
    if sc.get("kind") != "telescopic" or not sc.get("effects", {}).get("ground"):
        raise SceneError(f"{where}: the hoisting load case needs a telescopic scene with "
                         "effects.ground = true and effects.payload_swing = true (e.g. the "
                         "shipped crane_lift_off)")
    if "hoist_drive" not in sc:
        raise SceneError(f"{where}: the hoisting load case needs a [hoist_drive] that winds the "
                         "rope in (e.g. profile 'trapezoid' with a negative travel)")


def _tip_at_start(sc: dict) -> np.ndarray:
    """The boom tip (m) of the validated scene at t = 0, the booms straight."""
    from sim_core.systems.telescopic.build import build_telescopic
    from sim_core.systems.telescopic.schema import params_from_scene
    ts = build_telescopic(params_from_scene(sc))
    return np.real(ts.tip(ts.Q0)[0])


def _wound_in(profile, L0: float, slack: float, horizon: float = 600.0) -> float:
    """The first time (s) the hoist profile has shortened the rope by ``slack`` from L0."""
    t = np.linspace(0.0, horizon, 600001)
    s = np.asarray(profile.sample(t).s, float)
    hit = np.flatnonzero(L0 - s >= slack)
    if not hit.size:
        raise SceneError(f"hoist_drive: the hoist does not wind in the slack of {slack:g} m "
                         f"within {horizon:g} s (allowed: a profile that shortens the rope)")
    return float(t[hit[0]])


def lift_off_cases(scene, grid: dict, slack: float = 0.05, after: float = 1.0,
                   fixed: dict | None = None) -> list[dict]:
    """The grid's override dicts with each cell's ``hoist.length`` and ``solver.t_end`` (module
    docstring), validated with the ``fixed`` overrides of every cell (not in the dicts);
    raises SceneError naming the cell and the field."""
    fixed = dict(fixed or {})
    if not 0.0 < slack <= 10.0:
        raise SceneError(f"--slack {slack:g}: the slack hoist rope at the start, allowed "
                         "(0, 10] m")
    if not 0.0 < after <= 600.0:
        raise SceneError(f"--after {after:g}: simulated time after the rope is taut, allowed "
                         "(0, 600] s")
    cases = []
    for ov in grid_cases(grid):
        where = "case " + (", ".join(f"{k}={v}" for k, v in ov.items()) or "base")
        try:
            sc = load_scene(scene, {**fixed, **ov})
        except SceneError as exc:
            raise SceneError(f"{where}: {exc}") from None
        _check_scene(sc, where)
        tip = _tip_at_start(sc)
        L0 = float(tip[2] - sc["ground"]["height"]) + slack
        if L0 <= slack:
            raise SceneError(f"{where}: the boom tip is {tip[2]:.4g} m high, not above "
                             f"ground.height = {sc['ground']['height']:g} m")
        sc0 = load_scene(scene, {**fixed, **ov, "hoist.length": L0})
        t_taut = _wound_in(_profile_of(sc0), L0, slack)
        cases.append({**ov, "hoist.length": round(L0, 6),
                      "solver.t_end": round(t_taut + after, 6)})
    return cases


def _utilisation(res: Result) -> dict:
    """peak utilisation per boom from a ``section_utilisation`` output (time, boom, ...)."""
    if "section_utilisation" not in res:
        return {}
    u = np.asarray(res["section_utilisation"], float)
    u = u.reshape(u.shape[0], u.shape[1], -1)
    return {f"utilisation_boom_{k + 1}": float(np.nanmax(u[:, k])) for k in range(u.shape[1])}


def lift_off_outcomes(res: Result, scene: dict) -> dict:
    """The table's values of one lift-off result (module docstring)."""
    t = np.asarray(res.t, float)
    m = scene["payload"]["mass"] + scene["hoist"]["hook_mass"]
    W = m * scene["gravity"]["g"]
    T = np.asarray(res["hoist_rope_force"], float)
    N = np.asarray(res["payload_ground_force"], float)
    tip = np.asarray(res["tip_position"], float)
    r_p = np.asarray(res["payload_position"], float)
    taut = np.flatnonzero(T > 0.0)
    off = np.flatnonzero((N <= 0.0) & (np.arange(len(t)) >= (taut[0] if taut.size else 0)))
    t_off = float(t[off[0]]) if taut.size and off.size else math.nan
    v_h = _hoist_speed(scene)
    L_off = _rope_length(scene, t_off)
    out = {"working_radius_m": float(math.hypot(r_p[0, 0], r_p[0, 1])), "v_h_m_s": v_h,
           "static_rope_force_N": W, "peak_rope_force_N": peak(t, T)[1]}
    out["phi2"] = out["peak_rope_force_N"] / W
    out["phi2_rope_only"] = (1.0 + v_h / scene["gravity"]["g"]
                             * math.sqrt(scene["hoist"]["EA"] / L_off / m))
    out["t_lift_off_s"] = t_off
    out["tip_deflection_m"] = float(np.max(np.linalg.norm(tip - tip[0], axis=1)))
    out.update(_utilisation(res))
    for hc in HOISTING_CLASSES:
        out[f"phi2_{hc}"] = en13001_phi2(v_h, hc)
    return out


def _profile_of(scene: dict):
    from sim_core.systems.telescopic import actuators
    return actuators.build_profile({**scene["hoist_drive"], "_table": "hoist_drive"},
                                   scene["hoist"]["length"], "hoist_drive", scene.get("source"))


def _hoist_speed(scene: dict) -> float:
    """The steady hoisting speed v_h (m/s): the largest winding-in rate of the hoist profile."""
    prof = _profile_of(scene)
    t = np.linspace(0.0, scene["solver"]["t_end"], 20001)
    return float(max(0.0, -np.min(np.asarray(prof.sample(t).v, float))))


def _rope_length(scene: dict, t: float) -> float:
    """The unstretched hoist rope L0(t) (m); L0(0) where t is not a number."""
    return float(_profile_of(scene).sample(0.0 if math.isnan(t) else t).s)


def _row(case: dict, status: str, res: Result | None, error: str | None = None) -> dict:
    row = {"case": case["name"], **case["overrides"], "status": status}
    if res is not None and status in ("ok", "skipped"):
        row.update(lift_off_outcomes(res, case["scene"]))
    if error:
        row["error"] = error
    return row


def dynamic_factor(scene, grid: dict, out, *, fixed: dict | None = None, slack: float = 0.05,
                   after: float = 1.0, serial: bool | None = None, workers: int | None = None,
                   quiet: bool = True) -> list[dict]:
    """Run the lift-off of every grid cell and write the table and chart into ``out``
    (module docstring).  ``fixed``: overrides of every cell.  ``serial``: one cell after the
    other in this process (None: where Ray is not installed).  Returns the table's rows."""
    cases = lift_off_cases(scene, grid, slack, after, fixed)
    out = Path(out)
    if serial is None:
        import importlib.util
        serial = importlib.util.find_spec("ray") is None
    rows = []
    if serial:
        out_folder(out)
        for case in prepare_cases(scene, cases, fixed):
            rec = run_case(case["scene"])
            _write_case(out, case, rec, False)
            rows.append(_row(case, rec["status"], rec["result"], rec["error"]))
    else:
        prepared = {c["name"]: c for c in prepare_cases(scene, cases, fixed)}

        def on_case(row, rec):
            case = prepared[row["case"]]
            res = rec["result"] if rec is not None else \
                Result.load(out / case["name"] / RESULT_FILE)
            rows.append(_row(case, row["status"], res, row.get("error")))
        run_sweep(scene, None, out, cases=cases, fixed=fixed, workers=workers, quiet=quiet,
                  on_case=on_case)
        order = list(prepared)
        rows.sort(key=lambda r: order.index(r["case"]))
    keys = list(dict.fromkeys(k for c in cases for k in c))
    write_table(out, rows, keys)
    return rows


def _fields(rows: list[dict], keys: list[str]) -> list[str]:
    fields = ["case", *keys, *COLUMNS]
    for r in rows:
        fields += [k for k in r if k not in fields]
    return fields


def _text(v) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.6g}"
    return str(v)


def write_table(out: Path, rows: list[dict], keys: list[str]) -> list[Path]:
    """dynamic_factor.csv, dynamic_factor.md and dynamic_factor.png in ``out`` (each written
    atomically); returns their paths."""
    fields = _fields(rows, keys)
    paths = [out / "dynamic_factor.csv", out / "dynamic_factor.md"]
    atomic_write_bytes(paths[0], csv_bytes(rows, fields, _text))
    md = ["# Dynamic factor phi2 of the lift-off", "",
          "phi2 = peak hoist-rope force / (m_payload + m_hook) g; phi2_HCi = phi2_min + beta2 "
          "v_h of EN 13001-2:2014 Table 2B (hoist drive class HD1).", "",
          "| " + " | ".join(fields) + " |", "|" + "---|" * len(fields)]
    md += ["| " + " | ".join(_text(r.get(k)) for k in fields) + " |" for r in rows]
    atomic_write_bytes(paths[1], ("\n".join(md) + "\n").encode())
    paths.append(chart(out / "dynamic_factor.png", rows))
    return paths


def chart(path: Path, rows: list[dict]) -> Path:
    """phi2 (simulated, and EN 13001-2's HC1-HC4 dashed) and the tip's peak deflection
    against the working radius, one colour per hoisting speed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from sim_core.result import atomic_path
    ok = [r for r in rows if "phi2" in r]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    speeds = sorted({r["v_h_m_s"] for r in ok})
    for i, v in enumerate(speeds):
        sel = sorted((r for r in ok if r["v_h_m_s"] == v), key=lambda r: r["working_radius_m"])
        R = [r["working_radius_m"] for r in sel]
        c = f"C{i}"
        a1.plot(R, [r["phi2"] for r in sel], "o-", color=c, label=f"simulated, v_h = {v:g} m/s")
        a2.plot(R, [r["tip_deflection_m"] for r in sel], "o-", color=c,
                label=f"v_h = {v:g} m/s")
        for hc in HOISTING_CLASSES:
            a1.axhline(en13001_phi2(v, hc), color=c, ls="--", lw=0.8)
            a1.annotate(hc, (1.0, en13001_phi2(v, hc)), xycoords=("axes fraction", "data"),
                        fontsize=7, color=c, ha="left", va="center")
    a1.set_xlabel("working radius (m)")
    a1.set_ylabel("phi2 (dashed: EN 13001-2 HC1-HC4)")
    a2.set_xlabel("working radius (m)")
    a2.set_ylabel("peak tip deflection (m)")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        if speeds:
            a.legend(fontsize=8)
    fig.suptitle("hoisting load case: lift-off of a grounded payload")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path


__all__ = ["dynamic_factor", "lift_off_cases", "lift_off_outcomes", "en13001_phi2", "peak",
           "write_table", "chart", "HOISTING_CLASSES"]
