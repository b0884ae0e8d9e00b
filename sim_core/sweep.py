"""Parameter sweeps: the Cartesian product of scene overrides, one simulation per Ray task.

    from sim_core.sweep import run_sweep
    rows = run_sweep("telescopic_extraction_rl",
                     {"payload.mass": [20000, 25000, 30000],
                      "booms.luffing_angle_deg": [45, 60, 75]}, "sweep_out", workers=2)

Every case is validated before anything is launched (a misspelt key or an out-of-range value
raises :class:`sim_core.errors.SceneError` naming the case and the field).  Each case runs as a
Ray task with ``num_cpus=1``: a local Ray started with one CPU per core (``workers`` limits it)
whose services listen on 127.0.0.1 only, or an existing cluster (``address``, Ray's own address
format, e.g. ``"auto"`` or ``"ray://head:10001"``; the cluster's Python needs ``sim_core``
installed).  The task returns the
:class:`sim_core.result.Result` to the driver, which writes the case folder, so a cluster needs no
shared file system.

Output folder ``out``:

* one folder per case, named from its overrides (:func:`case_name`), holding ``result.npz``
  and ``summary.json`` (as ``boom-sim run`` writes them, plus the sweep fields ``status``,
  ``overrides``, ``outcomes``, ``scene_sha256``); the folder is written under a temporary name
  and renamed into place, so a case folder that exists is complete;
* ``summary.csv`` (and ``summary.parquet`` if pyarrow is importable): one row per case with
  the overrides, status (``ok``, ``failed``, ``skipped``; ``interrupted`` for cases not finished
  when the sweep was interrupted), error type and message, wall time, solver steps and the
  scalar outcomes (:func:`scalar_outcomes`);
* ``summary.png``: each scalar outcome against the first grid key.

Resuming: a case whose folder holds a successful run of the same resolved scene (same SHA-256
of the validated scene) is skipped and its row is read back from the folder; failed and
missing cases run again.  A failing case (any exception in the simulation, e.g. a
:class:`sim_core.errors.SimulationError`) is recorded with its error type and does not stop the
sweep.  On Ctrl-C the running tasks are cancelled, the finished case folders stay, and the
summary is written before the KeyboardInterrupt propagates.

Faults of the workers: a case whose worker process dies (SIGKILL, the kernel's or Ray's
out-of-memory killer, a lost node) is retried up to ``retries`` times (Ray's ``max_retries``,
system failures only: an exception of the simulation is a result, not retried), then recorded
as failed with Ray's error type (``WorkerCrashedError``, ``OutOfMemoryError``,
``NodeDiedError``, ...) and the reason; the sweep goes on, and a re-run runs only the failed
and missing cases.  Every case runs with checkpoints (:mod:`sim_core.checkpoint`, every
``checkpoint_every`` wall seconds, 30 by default: a case shorter than that writes none) in
``out/.checkpoints/<case>.pkl``, and a retried or re-run case resumes from its checkpoint
(``resumed_from_s`` in its summary.json; its result is bit-identical to an uninterrupted
run's).  The checkpoint path is an absolute path on the driver's machine: the retrying worker
finds it where it can read that path (always on a local Ray; on a cluster, where the folder
is on a file system shared by the nodes); elsewhere the retry starts from t = 0.  A case's
checkpoint is removed once its folder is written (a case whose worker died keeps it for the
re-run), and the ``.checkpoints`` folder once it is empty.

Ray is imported inside :func:`run_sweep` only: ``import sim_core.sweep`` needs no Ray.
"""

from __future__ import annotations

import csv
import hashlib
import io
import itertools
import json
import math
import os
import re
import shutil
import sys
import time
import uuid
from pathlib import Path
from typing import Any, Callable

import numpy as np

from sim_core.api import load_scene, simulate
from sim_core.checkpoint import DEFAULT_EVERY_S, CheckpointPolicy, scene_fingerprint
from sim_core.errors import SceneError
from sim_core.registry import system_kind
from sim_core.result import Result, atomic_write_bytes, json_default

STATUSES = ("ok", "failed", "skipped", "interrupted")
RESULT_FILE = "result.npz"
CASE_SUMMARY = "summary.json"
BASE_FIELDS = ("case", "status", "error_type", "error", "wall_s", "n_steps")
_TEMP_DIR = re.compile(r"^\..+\.(tmp|old)-[0-9a-f]{32}$")
_MAX_NAME = 120                       # characters of a case folder name (file systems allow 255)
CHECKPOINTS = ".checkpoints"          # the cases' checkpoint files, in the output folder
#: retries of a case whose worker process died (Ray's max_retries)
DEFAULT_RETRIES = 2


class SweepError(RuntimeError):
    """A sweep input other than the scene is unusable (Ray missing or unreachable, a bad
    output folder, a bad worker count); the message names the option."""


# -- the grid --------------------------------------------------------------------------------

def split_values(text: str) -> list[str]:
    """Split ``v1,v2,...`` at the commas outside brackets and quotes, so TOML arrays and
    quoted strings stay whole: ``"[0, 0, -1],[1, 0, 0]"`` -> two arrays."""
    parts, depth, quote, cur = [], 0, None, []
    for ch in text:
        if quote:
            quote = None if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append("".join(cur).strip())
            cur = []
            continue
        cur.append(ch)
    parts.append("".join(cur).strip())
    return parts


def parse_grid(items: list[str] | None) -> dict[str, list[str]]:
    """``["payload.mass=20000,25000", ...]`` (the ``--grid`` options) -> {key: [values]}.

    Values stay text; they are parsed as TOML values when the override is applied
    (:func:`sim_core.scene.io.apply_overrides`).  Raises SceneError naming the key for a missing
    ``=``, an empty key or value, a key given twice or a value repeated within a key."""
    grid: dict[str, list[str]] = {}
    for item in items or []:
        if "=" not in item:
            raise SceneError(f"--grid {item!r}: expected KEY=V1,V2,..., e.g. "
                             f"payload.mass=20000,25000")
        key, text = (s.strip() for s in item.split("=", 1))
        if not key:
            raise SceneError(f"--grid {item!r}: empty key (expected KEY=V1,V2,...)")
        if key in grid:
            raise SceneError(f"--grid {key}: key given twice (give all its values in one "
                             f"--grid {key}=V1,V2,...)")
        values = split_values(text)
        for i, v in enumerate(values):
            if not v:
                raise SceneError(f"--grid {key}={text}: value {i + 1} of {len(values)} is empty "
                                 f"(expected a comma-separated list of values)")
        seen = set()
        for v in values:
            if v in seen:
                raise SceneError(f"--grid {key}: value {v!r} given twice")
            seen.add(v)
        grid[key] = values
    return grid


def grid_cases(grid: dict[str, list]) -> list[dict[str, Any]]:
    """The Cartesian product of the grid as override dicts, the first key varying slowest
    (an empty grid is one case without overrides)."""
    for key, values in grid.items():
        if not isinstance(values, (list, tuple)) or not values:
            raise SceneError(f"grid {key}: needs a non-empty list of values, got {values!r}")
    keys = list(grid)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(grid[k] for k in keys))]


def _text(value: Any) -> str:
    return value if isinstance(value, str) else json.dumps(value, default=str)


def case_name(overrides: dict[str, Any]) -> str:
    """Folder name of a case: ``key=value`` pairs joined by ``__``, every character outside
    ``[A-Za-z0-9._=+-]`` replaced by ``_``.  Where a character was replaced or the name is
    longer than 120 characters, an 8-digit hash of the overrides is appended (truncating the
    name), so distinct cases get distinct names; the name depends on the overrides only, so a
    resumed sweep finds its folders again."""
    if not overrides:
        return "base"
    raw = "__".join(f"{k}={_text(v)}" for k, v in overrides.items())
    safe = re.sub(r"[^A-Za-z0-9._=+-]", "_", raw)
    if safe == raw and len(safe) <= _MAX_NAME and not safe.startswith("."):
        return safe
    digest = hashlib.sha1(json.dumps({k: _text(v) for k, v in overrides.items()},
                                     sort_keys=True).encode()).hexdigest()[:8]
    return f"{safe.lstrip('.')[:_MAX_NAME]}-{digest}"


def prepare_cases(scene: str | Path, cases: list[dict], fixed: dict | None = None) -> list[dict]:
    """Validate every case before anything runs: -> [{name, overrides, scene, fingerprint}].

    ``fixed`` overrides apply to every case (a case's own overrides win).  A case whose scene
    is invalid raises SceneError naming the case and the field (the scene validator's message);
    the first invalid case is reported together with the number of invalid cases."""
    fixed = dict(fixed or {})
    prepared, errors, names = [], [], {}
    for ov in cases:
        name = case_name(ov)
        if name in names:
            raise SceneError(f"cases {names[name]} and {ov}: the same case folder {name!r} "
                             f"(give each case distinct overrides)")
        names[name] = ov
        try:
            sc = load_scene(scene, {**fixed, **ov})
        except SceneError as exc:
            errors.append(f"case {name}: {exc}")
            continue
        prepared.append({"name": name, "overrides": dict(ov), "scene": sc,
                         "fingerprint": scene_fingerprint(sc)})
    if errors:
        more = f" (and {len(errors) - 1} more invalid case(s))" if len(errors) > 1 else ""
        raise SceneError(errors[0] + more)
    return prepared


# -- outcomes ----------------------------------------------------------------------------------

def _peak_abs(a: np.ndarray) -> float:
    a = np.asarray(a, dtype=float)
    return float(np.nanmax(np.abs(a))) if a.size and not np.all(np.isnan(a)) else math.nan


def rigid_tip_deviation(result: Result, scene: dict) -> float | None:
    """Largest distance (m) in the luffing plane (X, Z) between the tip and its rigid-boom
    kinematics tip(0) + f s(t) (cos theta, sin theta), with s the piston stroke and f = 2 for
    three booms (the ropes move boom 3 twice the stroke, Zhao-Qi-Wang 2024 Eqs. 74-76) or
    f = 1 for two booms; None where the result or the boom count has no such limit."""
    if "tip_position" not in result or "piston_stroke" not in result:
        return None
    count = scene.get("booms", {}).get("count")
    theta = scene.get("booms", {}).get("luffing_angle_deg")
    if count not in (2, 3) or theta is None:
        return None
    f = 2.0 if count == 3 else 1.0
    e = np.array([math.cos(math.radians(theta)), math.sin(math.radians(theta))])
    tip = np.asarray(result["tip_position"], float)[:, [0, 2]]
    rigid = tip[0] + f * np.asarray(result["piston_stroke"], float)[:, None] * e
    return float(np.max(np.linalg.norm(tip - rigid, axis=1)))


def scalar_outcomes(result: Result, scene: dict) -> dict[str, float]:
    """Scalar outcomes of a run, SI units (the column names carry them).

    Telescopic scenes, where the result has the output: peak |telescopic cylinder force| N,
    peak |luffing cylinder force| N, the largest constraint violation (max over time of the
    largest |row|; m or rad by row), the final tip position m (x, y, z), the largest tip
    deviation from the rigid-boom limit m (:func:`rigid_tip_deviation`) and, for the modal ROM,
    the peak |tip deflection| m from the static tip.  Other scene kinds: the peak |value| of
    every output array (``max_abs_<output>``), leaving out ``state`` (the solver's reduced state
    vector, no physical quantity)."""
    out: dict[str, float] = {}
    if scene.get("kind") == "telescopic":
        for name, col in (("telescopic_cylinder_force", "peak_abs_telescopic_cylinder_force_N"),
                          ("luffing_cylinder_force", "peak_abs_luffing_cylinder_force_N"),
                          ("constraint_violation", "max_constraint_violation"),
                          ("tip_deflection", "peak_abs_tip_deflection_m")):
            if name in result:
                out[col] = _peak_abs(result[name])
        if "tip_position" in result and len(result["tip_position"]):
            for axis, v in zip("xyz", np.asarray(result["tip_position"], float)[-1]):
                out[f"final_tip_{axis}_m"] = float(v)
        dev = rigid_tip_deviation(result, scene)
        if dev is not None:
            out["max_tip_deviation_from_rigid_m"] = dev
        return out
    for name in result.keys():
        if name == "state":
            continue
        arr = np.asarray(result[name])
        if arr.size and np.issubdtype(arr.dtype, np.number):
            out[f"max_abs_{name}"] = _peak_abs(np.real(arr))
    return out


# -- one case (runs in a Ray worker) --------------------------------------------------------------

def _one_line(msg: object) -> str:
    return " ".join(str(msg).split())


def _partial(exc: BaseException) -> Result | None:
    for name in ("result", "partial_result"):
        res = getattr(exc, name, None)
        if isinstance(res, Result):
            return res
    return None


def run_case(scene: dict, checkpoint: str | None = None,
             checkpoint_every: float = DEFAULT_EVERY_S) -> dict:
    """Simulate one validated scene; never raises for a failed simulation.

    ``checkpoint``: the case's checkpoint file (None: none): written every
    ``checkpoint_every`` wall seconds, and resumed from where it holds a checkpoint of this
    scene (``resume="auto"``: a retry of a case whose worker died).

    Returns {status "ok"/"failed", error_type, error (one line), wall_s (wall time of
    :func:`sim_core.integrate.driver` incl. model build, s), n_steps, outcomes, stats, result (the
    Result, or the partial result a failed solver attached, or None), t_fail_s}."""
    t0 = time.perf_counter()
    rec: dict[str, Any] = {"status": "ok", "error_type": None, "error": None, "t_fail_s": None}
    policy = None if checkpoint is None else \
        CheckpointPolicy(checkpoint, checkpoint_every, required=False)
    try:
        res = simulate(scene, checkpoint=policy, resume="auto" if policy else False)
    except Exception as exc:  # noqa: BLE001 - any failure is recorded with its type
        res = _partial(exc)
        rec.update(status="failed", error_type=type(exc).__name__, error=_one_line(exc),
                   t_fail_s=getattr(exc, "t", None))
        if res is not None:
            if res.error is None:
                res.error = rec["error"]
            if not res.scene:
                res.scene = scene
    rec["wall_s"] = time.perf_counter() - t0
    stats = dict(res.stats) if res is not None else {}
    rec["stats"] = stats
    rec["n_steps"] = stats.get("n_steps")
    rec["outcomes"] = scalar_outcomes(res, scene) if res is not None and rec["status"] == "ok" else {}
    rec["result"] = res
    return rec


# -- case folders ------------------------------------------------------------------------------

def _json_bytes(obj) -> bytes:
    return json.dumps(obj, indent=2, default=json_default).encode()


def _write_case(out: Path, case: dict, rec: dict, plots: bool) -> None:
    """Write the case folder under a temporary name, then rename it into place (a previous
    folder of the case is moved aside first and removed after)."""
    final = out / case["name"]
    tmp = out / f".{case['name']}.tmp-{uuid.uuid4().hex}"
    tmp.mkdir(parents=True)
    try:
        res = rec.get("result")
        if res is not None:
            res.save(tmp / RESULT_FILE)
        summary = {"scene": case["scene"]["name"], "case": case["name"],
                   "status": rec["status"], "overrides": case["overrides"],
                   "scene_sha256": case["fingerprint"], "error_type": rec["error_type"],
                   "error": rec["error"], "t_fail_s": rec.get("t_fail_s"),
                   "wall_s": rec["wall_s"], "n_steps": rec.get("n_steps"),
                   "result_file": RESULT_FILE if res is not None else None,
                   "outcomes": rec["outcomes"], **rec.get("stats", {})}
        atomic_write_bytes(tmp / CASE_SUMMARY, _json_bytes(summary))
        if plots and res is not None and rec["status"] == "ok":
            system_kind(res.scene).figures(res, tmp)
        old = None
        if final.exists():
            old = out / f".{case['name']}.old-{uuid.uuid4().hex}"
            os.replace(final, old)
        os.replace(tmp, final)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def completed_case(folder: Path, fingerprint: str) -> dict | None:
    """The stored summary of a successful run of the same resolved scene in ``folder``, else
    None (missing, unreadable, failed or another scene: the case runs)."""
    try:
        summary = json.loads((folder / CASE_SUMMARY).read_text())
    except (OSError, ValueError):
        return None
    if (not isinstance(summary, dict) or summary.get("status") != "ok"
            or summary.get("scene_sha256") != fingerprint or not (folder / RESULT_FILE).is_file()):
        return None
    return summary


def _checkpoint_file(out: Path, case: dict) -> Path:
    """A case's checkpoint: an absolute path, for workers whose working folder differs."""
    return out.resolve() / CHECKPOINTS / f"{case['name']}.pkl"


def _remove_checkpoint(out: Path, case: dict) -> None:
    try:
        os.unlink(_checkpoint_file(out, case))
    except OSError:
        pass


def _remove_checkpoint_folder(out: Path) -> None:
    """The checkpoint folder, once no case keeps a checkpoint there."""
    try:
        (out / CHECKPOINTS).rmdir()
    except OSError:                   # missing, or a case whose worker died keeps its own
        pass


def _remove_stale_temporaries(out: Path) -> None:
    """Folders a killed sweep left under their temporary names (never a finished case)."""
    if not out.is_dir():
        return
    for p in out.iterdir():
        if p.is_dir() and _TEMP_DIR.match(p.name):
            shutil.rmtree(p, ignore_errors=True)


# -- summary table and figure ---------------------------------------------------------------------

def _row(case: dict, status: str, rec: dict | None) -> dict:
    rec = rec or {}
    return {"case": case["name"], **{k: _text(v) for k, v in case["overrides"].items()},
            "status": status, "error_type": rec.get("error_type"), "error": rec.get("error"),
            "wall_s": rec.get("wall_s"), "n_steps": rec.get("n_steps"),
            **(rec.get("outcomes") or {})}


def summary_fields(rows: list[dict], keys: list[str]) -> list[str]:
    """Column order: case, grid keys, status, error type/message, wall_s, n_steps, then the
    outcomes in order of first appearance."""
    fields = ["case", *keys, *BASE_FIELDS[1:]]
    for r in rows:
        for k in r:
            if k not in fields:
                fields.append(k)
    return fields


def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if math.isnan(v) else repr(v)
    return str(v)


def out_folder(out) -> Path:
    """The sweep's output folder, created where missing; SweepError naming ``--out`` for a file
    or a folder that cannot be created."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise SweepError(f"--out {str(out)!r}: is a file, not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SweepError(f"--out {str(out)!r}: cannot create the folder: {exc.strerror}") from None
    return out


def csv_bytes(rows: list[dict], fields: list[str], cell) -> bytes:
    """The rows as CSV text (a header of ``fields``, then each row's ``cell(value)`` of every
    field), encoded UTF-8."""
    buf = io.StringIO(newline="")
    w = csv.DictWriter(buf, fields)
    w.writeheader()
    for r in rows:
        w.writerow({k: cell(r.get(k)) for k in fields})
    return buf.getvalue().encode()


def write_summary(out: Path, rows: list[dict], keys: list[str], title: str) -> list[Path]:
    """summary.csv, summary.parquet (if pyarrow is importable) and summary.png, each written
    atomically.  Returns the paths written."""
    fields = summary_fields(rows, keys)
    paths = [out / "summary.csv"]
    atomic_write_bytes(paths[0], csv_bytes(rows, fields, _cell))
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        pass
    else:
        table = pa.Table.from_pylist([{k: r.get(k) for k in fields} for r in rows])
        pbuf = io.BytesIO()
        pq.write_table(table, pbuf)
        atomic_write_bytes(out / "summary.parquet", pbuf.getvalue())
        paths.append(out / "summary.parquet")
    try:
        paths.append(summary_figure(out / "summary.png", rows, keys, title))
    except ImportError:
        print("boom-sim: warning: matplotlib is not installed, summary.png skipped",
              file=sys.stderr)
    return paths


def _numbers(values: list[str]) -> list[float] | None:
    try:
        return [float(v) for v in values]
    except (TypeError, ValueError):
        return None


def summary_figure(path: Path, rows: list[dict], keys: list[str], title: str) -> Path:
    """Each scalar outcome of the successful cases against the first grid key (numeric axis
    if all its values are numbers, else one tick per value), one line per combination of the
    other grid keys."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sim_core.figures import save_figure

    good = [r for r in rows if r["status"] in ("ok", "skipped")]
    outcome_keys = [k for k in summary_fields(rows, keys)
                    if k not in keys and k not in BASE_FIELDS]
    n = max(1, len(outcome_keys))
    ncols = min(3, n)
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.6 * ncols, 3.4 * nrows), squeeze=False)
    x_key = keys[0] if keys else "case"
    x_values = list(dict.fromkeys(str(r.get(x_key)) for r in rows))
    nums = _numbers(x_values)
    pos = dict(zip(x_values, nums if nums is not None else range(len(x_values))))
    groups: dict[str, list[dict]] = {}
    for r in good:
        label = ", ".join(f"{k}={r.get(k)}" for k in keys[1:])
        groups.setdefault(label, []).append(r)
    for ax, key in zip(axes.flat, outcome_keys):
        for label, rs in groups.items():
            pts = sorted((pos[str(r.get(x_key))], r[key]) for r in rs
                         if isinstance(r.get(key), (int, float)) and math.isfinite(r[key]))
            if pts:
                ax.plot(*zip(*pts), "o-", ms=4, label=label or None)
        ax.set_title(key, fontsize=9)
        ax.set_xlabel(x_key, fontsize=8)
        if nums is None:
            ax.set_xticks(range(len(x_values)))
            ax.set_xticklabels(x_values, rotation=30, fontsize=7)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(outcome_keys):]:
        ax.axis("off")
    if not outcome_keys:
        axes.flat[0].text(0.5, 0.5, "no successful case: no outcomes", ha="center",
                          va="center", transform=axes.flat[0].transAxes)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    if labels and len(labels) <= 12:
        fig.legend(handles, labels, loc="lower center", ncol=min(4, len(labels)), fontsize=7)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout(rect=(0, 0.08 if labels and len(labels) <= 12 else 0, 1, 0.95))
    save_figure(fig, path)
    plt.close(fig)
    return path


# -- Ray -----------------------------------------------------------------------------------------

def _check_reachable(address: str, timeout: float = 5.0) -> None:
    """A ``host:port`` or ``ray://host:port`` address must accept a TCP connection within
    ``timeout`` s (Ray itself retries an unreachable address for minutes).  Other forms
    (``auto``, ``local``) are left to Ray."""
    import socket
    hostport = address[len("ray://"):] if address.startswith("ray://") else address
    host, sep, port = hostport.rpartition(":")
    if not sep or not host or not port.isdigit():
        return
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout).close()
    except OSError as exc:
        raise SweepError(f"--address {address!r}: no Ray cluster answers there "
                         f"({exc.strerror or exc}); start one with 'ray start --head' or "
                         f"leave --address out for a local Ray") from None


def _start_ray(address: str | None, workers: int | None):
    """-> (ray module, whether this call started Ray).  An already initialised Ray is used as
    it is.  Without ``address`` a new local Ray with one CPU per core, or ``workers`` CPUs,
    listening on 127.0.0.1 only (:func:`_init_loopback_ray`; never a cluster found on this
    machine: ``address="auto"`` joins that); ``address``: join that cluster.  Ray's own
    logging is kept to errors and worker output is not forwarded."""
    import logging
    try:
        import ray
    except ImportError:
        raise SweepError("sweep needs Ray: pip install 'telescopic-boom-sim[cluster]' "
                         "(or pip install 'ray>=2.9')") from None
    if ray.is_initialized():
        return ray, False
    kw = dict(include_dashboard=False, log_to_driver=False, logging_level=logging.ERROR)
    if address:
        _check_reachable(address)
    try:
        if address:
            ray.init(address=address, **kw)
        else:       # "local": a new Ray here, even where a cluster runs or RAY_ADDRESS is set
            _init_loopback_ray(ray, num_cpus=workers, **kw)
    except (ConnectionError, ValueError, RuntimeError) as exc:
        where = f"--address {address!r}" if address else "local Ray"
        raise SweepError(f"{where}: cannot start or join Ray: {_one_line(exc)}") from None
    return ray, True


LOOPBACK = "127.0.0.1"


def _init_loopback_ray(ray, **kw) -> None:
    """A new local Ray whose services (GCS, raylet, object manager, workers, agents) listen
    on 127.0.0.1 only.  Every Ray process binds its gRPC and HTTP servers to the node's IP
    address, and on Linux ``ray.init`` replaces a loopback ``_node_ip_address`` by the
    machine's routable address unless Ray's ``ENABLE_RAY_CLUSTER`` switch is off (the switch
    of its single-machine platforms): the switch is off while this node starts, so the node's
    address stays 127.0.0.1 and is handed to every process Ray starts.  A Ray that still
    comes up on another address is shut down (SweepError): a local sweep never listens on
    the network."""
    try:
        from ray._private import ray_constants
    except ImportError:               # another layout: the address check below decides
        ray_constants = None
    before = getattr(ray_constants, "ENABLE_RAY_CLUSTER", None)
    if before is not None:
        ray_constants.ENABLE_RAY_CLUSTER = False
    try:
        ray.init(address="local", _node_ip_address=LOOPBACK, dashboard_host=LOOPBACK, **kw)
    finally:
        if before is not None:
            ray_constants.ENABLE_RAY_CLUSTER = before
    ip = ray.util.get_node_ip_address()
    if ip != LOOPBACK:
        ray.shutdown()
        raise SweepError(f"local Ray: it started on {ip}, not on {LOOPBACK} only (this Ray "
                         "version ignores the loopback address); pass --address to use a "
                         "cluster deliberately")


def run_sweep(scene: str | Path, grid: dict[str, list] | None, out: str | Path, *,
              cases: list[dict] | None = None, fixed: dict | None = None,
              address: str | None = None, workers: int | None = None, quiet: bool = False,
              plots: bool = False, retries: int = DEFAULT_RETRIES,
              checkpoint_every: float = DEFAULT_EVERY_S,
              on_case: Callable[[dict, dict | None], None] | None = None) -> list[dict]:
    """Run a sweep of ``scene`` (shipped name or TOML path) and return the summary rows.

    grid:    {dotted key: [values]} (values as TOML text or Python values); its Cartesian
             product is the case list (first key slowest).
    cases:   an explicit list of override dicts instead of (not together with) a grid, for
             case lists that are no product; their keys are the union of the cases' keys.
    fixed:   overrides applied to every case (e.g. {"solver.t_end": 2}).
    out:     output folder (created).
    address: Ray cluster to join (Ray's address format); default a local Ray.
    workers: at most this many cases at a time (local Ray: started with this many CPUs).
    quiet:   no progress bar.
    plots:   also write the figures of ``boom-sim run`` into every successful case folder.
    retries: times a case whose worker process died is run again (module docstring).
    checkpoint_every: wall seconds between a case's checkpoints (``math.inf``: none).
    on_case: called in the driver as on_case(row, record) after each case has finished
             (record: :func:`run_case`'s dict, None for a skipped case).

    Each row: case, the overrides, status, error_type, error, wall_s, n_steps and the scalar
    outcomes (:func:`scalar_outcomes`); a skipped row carries the values stored by the run
    that produced the folder.  Raises SceneError (an invalid case, before anything runs),
    SweepError (Ray, ``out`` or ``workers``) and KeyboardInterrupt (after writing the summary).
    """
    if grid and cases is not None:
        raise SweepError("give either a grid or an explicit case list, not both")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise SweepError(f"workers = {workers!r}: must be an integer >= 1")
    if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
        raise SweepError(f"retries = {retries!r}: must be an integer >= 0")
    if isinstance(checkpoint_every, bool) or not isinstance(checkpoint_every, (int, float)) \
            or not checkpoint_every > 0:
        raise SweepError(f"checkpoint_every = {checkpoint_every!r}: wall seconds between a "
                         "case's checkpoints, allowed (0, inf] (inf: none)")
    case_list = [dict(c) for c in cases] if cases is not None else grid_cases(grid or {})
    keys = list(grid) if cases is None else list(dict.fromkeys(k for c in case_list for k in c))
    prepared = prepare_cases(scene, case_list, fixed)          # fail fast: nothing runs yet
    out = out_folder(out)
    _remove_stale_temporaries(out)
    name = prepared[0]["scene"]["name"] if prepared else str(scene)

    rows: list[dict | None] = [None] * len(prepared)
    todo = []
    for i, case in enumerate(prepared):
        stored = completed_case(out / case["name"], case["fingerprint"])
        if stored is not None:
            rows[i] = _row(case, "skipped", stored)
        else:
            todo.append(i)

    counts = {"failed": 0, "skipped": len(prepared) - len(todo)}
    bar = None
    if not quiet:
        from tqdm import tqdm
        bar = tqdm(total=len(prepared), desc=f"sweep {name}", unit="case", file=sys.stderr)
        bar.update(counts["skipped"])
        bar.set_postfix(failed=0, skipped=counts["skipped"])

    def title() -> str:
        st = [r["status"] if r else "interrupted" for r in rows]
        parts = [f"{st.count(s)} {s}" for s in STATUSES if st.count(s)]
        return f"sweep of {name}: {len(rows)} cases, " + ", ".join(parts)

    def finish() -> None:
        for i, case in enumerate(prepared):
            if rows[i] is None:
                rows[i] = _row(case, "interrupted", None)
        write_summary(out, rows, keys, title())
        _remove_checkpoint_folder(out)
        if bar is not None:
            bar.close()

    if on_case is not None:
        for i in range(len(prepared)):
            if rows[i] is not None:
                on_case(rows[i], None)

    ray = started = None
    if todo:
        try:
            ray, started = _start_ray(address, workers)
        except BaseException:
            if bar is not None:
                bar.close()
            raise
    pending: dict = {}
    try:
        if todo:
            # max_retries: system failures only (the worker process died); the simulation's
            # own exceptions come back as failed records
            task = ray.remote(num_cpus=1, max_retries=retries)(run_case)
            limit = workers or len(todo)
            queue = list(todo)
            every = None if math.isinf(checkpoint_every) else float(checkpoint_every)
            while queue or pending:
                while queue and len(pending) < limit:
                    i = queue.pop(0)
                    path = None if every is None else str(_checkpoint_file(out, prepared[i]))
                    pending[task.remote(prepared[i]["scene"], path,
                                        every or DEFAULT_EVERY_S)] = i
                done, _ = ray.wait(list(pending), num_returns=1)
                for ref in done:
                    i = pending.pop(ref)
                    crashed = False
                    try:
                        rec = ray.get(ref)
                    except ray.exceptions.RayError as exc:    # worker crash, lost node, ...
                        crashed = True
                        rec = {"status": "failed", "error_type": type(exc).__name__,
                               "error": f"the case's worker process died ({retries} "
                                        f"retr{'y' if retries == 1 else 'ies'} allowed, "
                                        f"--retries): {_one_line(exc)}",
                               "wall_s": None, "n_steps": None,
                               "outcomes": {}, "stats": {}, "result": None}
                    _write_case(out, prepared[i], rec, plots)
                    if not crashed:           # a re-run resumes a crashed case's checkpoint
                        _remove_checkpoint(out, prepared[i])
                    rows[i] = _row(prepared[i], rec["status"], rec)
                    if rec["status"] == "failed":
                        counts["failed"] += 1
                    if bar is not None:
                        bar.update(1)
                        bar.set_postfix(failed=counts["failed"], skipped=counts["skipped"])
                    if on_case is not None:
                        on_case(rows[i], rec)
    except BaseException:
        if ray is not None:
            for ref in pending:
                try:
                    ray.cancel(ref, force=True)
                except Exception:  # noqa: BLE001 - best effort; the summary comes first
                    pass
        finish()
        raise
    finally:
        if started:
            ray.shutdown()
    finish()
    return rows


__all__ = ["run_sweep", "parse_grid", "grid_cases", "case_name", "prepare_cases", "run_case",
           "scalar_outcomes", "rigid_tip_deviation", "write_summary", "completed_case",
           "scene_fingerprint", "SweepError", "STATUSES", "DEFAULT_RETRIES"]
