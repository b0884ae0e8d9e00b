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
    """Write ``data`` to ``path`` through a temporary file in the same folder + rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


@dataclass
class Result:
    """Output of :func:`sim_core.simulate`.

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

    def keys(self):
        return self.outputs.keys()

    def save(self, path: str | Path) -> Path:
        """Write an .npz (arrays + JSON metadata) atomically."""
        import io

        from . import __version__
        meta = {"stats": self.stats, "scene": self.scene, "error": self.error,
                "versions": {"sim_core": __version__, "numpy": np.__version__}}
        try:
            import scipy
            meta["versions"]["scipy"] = scipy.__version__
        except ImportError:  # pragma: no cover
            pass
        buf = io.BytesIO()
        np.savez_compressed(buf, t=self.t, __meta__=np.array(json.dumps(meta, default=str)),
                            **{f"out__{k}": v for k, v in self.outputs.items()})
        atomic_write_bytes(path, buf.getvalue())
        return Path(path)

    @classmethod
    def load(cls, path: str | Path) -> "Result":
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["__meta__"]))
            outs = {k[5:]: z[k] for k in z.files if k.startswith("out__")}
            return cls(z["t"], outs, meta.get("stats", {}), meta.get("scene", {}), meta.get("error"))
