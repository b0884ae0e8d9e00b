"""Simulation results: time + named output arrays, atomic .npz/.json writing."""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder + rename.

    Readers see either the old file or the complete new one; on any failure the temporary file
    is removed and an existing ``path`` is left untouched.  The new file gets the usual
    permissions (those of the file it replaces, else 0666 less the umask), not mkstemp's 0600.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, _mode_for(path))
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    _fsync_dir(path.parent)


def _mode_for(path: Path) -> int:
    try:
        return path.stat().st_mode & 0o7777
    except OSError:
        return 0o666 & ~_umask()


def _umask() -> int:
    try:  # Linux: read it without changing it (os.umask would, briefly, for every thread)
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    umask = os.umask(0o022)
    os.umask(umask)
    return umask


def _fsync_dir(folder: Path) -> None:
    """Make the rename durable (best effort: not every OS/file system allows it)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def json_default(obj):
    """numpy scalars/arrays as plain numbers/lists in the metadata (anything else as text)."""
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    return str(obj)


@dataclass
class Result:
    """Output of :func:`sim_core.integrate.driver`.

    ``t`` (n,) in s; ``result[name]`` gives an output array whose first axis is time.
    ``stats`` holds solver statistics (wall time s, steps, RHS evaluations, ...), ``scene``
    the resolved scene (a plain dict) and ``error`` the failure message if the run stopped early.
    """

    t: np.ndarray
    outputs: dict[str, np.ndarray]
    stats: dict[str, Any] = field(default_factory=dict)
    scene: dict[str, Any] = field(default_factory=dict)
    error: str | None = None

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.outputs[name]
        except KeyError:
            raise KeyError(f"no output {name!r}; available: {sorted(self.outputs)}") from None

    def __contains__(self, name: str) -> bool:
        return name in self.outputs

    @property
    def suspect(self) -> bool:
        """The run finished but failed one of its own result checks (``stats["checks"]``,
        :func:`sim_core.integrate.driver.check_result`): its outputs may be wrong."""
        return bool(self.stats.get("suspect", False))

    def failed_checks(self) -> dict:
        """The failed result checks: name -> {value, limit, fail_limit, ok, gross, what}."""
        checks = self.stats.get("checks") or {}
        return {k: c for k, c in checks.items() if not c.get("ok", True)}

    def suspect_note(self) -> str:
        """One line naming the failed checks with their values and limits ("" if none), e.g.
        for the command line: ``suspect result: energy_balance = 0.35 > 0.1 (energy drift /
        exchanged energy ...)``."""
        failed = self.failed_checks()
        if not failed:
            return ""
        return "suspect result: " + "; ".join(
            f"{k} = {c['value']:.3g} > {c['limit']:.3g} ({c['what']})" for k, c in failed.items())

    def keys(self):
        return self.outputs.keys()

    def save(self, path: str | Path) -> Path:
        """Write an .npz (arrays + JSON metadata) atomically."""
        import io

        from sim_core._version import __version__
        meta = {"stats": self.stats, "scene": self.scene, "error": self.error,
                "versions": {"sim_core": __version__, "numpy": np.__version__}}
        try:
            import scipy
            meta["versions"]["scipy"] = scipy.__version__
        except ImportError:  # pragma: no cover
            pass
        buf = io.BytesIO()
        np.savez_compressed(buf, t=self.t, __meta__=np.array(json.dumps(meta, default=json_default)),
                            **{f"out__{k}": v for k, v in self.outputs.items()})
        atomic_write_bytes(path, buf.getvalue())
        return Path(path)

    @classmethod
    def load(cls, path: str | Path) -> "Result":
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["__meta__"]))
            outs = {k[5:]: z[k] for k in z.files if k.startswith("out__")}
            return cls(z["t"], outs, meta.get("stats", {}), meta.get("scene", {}), meta.get("error"))
