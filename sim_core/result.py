"""Simulation results: time + named output arrays, atomic .npz/.json writing."""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sim_core.errors import ResultFormatError


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder + rename.

    Readers see either the old file or the complete new one; on any failure the temporary file
    is removed and an existing ``path`` is left untouched.  The new file gets the usual
    permissions (those of the file it replaces, else 0666 less the umask), not mkstemp's 0600.
    """
    with atomic_path(path) as tmp, os.fdopen(os.open(tmp, os.O_WRONLY | os.O_TRUNC), "wb") as f:
        f.write(data)


@contextlib.contextmanager
def atomic_path(path: str | Path, suffix: str = ".tmp"):
    """A temporary file path beside ``path`` for a writer that needs a path (an animation, an
    archive); when the block ends without an error the file is flushed to disk and renamed to
    ``path`` in one step (os.replace), with the folder's entry synced; on an error it is
    removed and ``path`` keeps what it held."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=suffix)
    os.close(fd)
    try:
        yield tmp
        with open(tmp, "rb+") as f:       # the content on disk before the rename
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
        """Write an .npz (arrays + JSON metadata) atomically, in result format
        :data:`RESULT_FORMAT` (see :meth:`load` for the layout)."""
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
        np.savez_compressed(buf, **{_FORMAT_MEMBER: np.array(RESULT_FORMAT, dtype=np.int64)},
                            t=self.t, __meta__=np.array(json.dumps(meta, default=json_default)),
                            **{f"out__{k}": v for k, v in self.outputs.items()})
        atomic_write_bytes(path, buf.getvalue())
        return Path(path)

    @classmethod
    def load(cls, path: str | Path) -> "Result":
        """Read a result file written by :meth:`save`.

        The file is an .npz (a zip of .npy arrays): ``__format__`` (the result format, an
        integer), ``t``, ``__meta__`` (JSON text: stats, scene, error, package versions) and one
        ``out__NAME`` per output.  Files written before the format was versioned have no
        ``__format__`` member and are otherwise laid out exactly as format 1: they are read as
        result format 0.

        Raises :class:`sim_core.errors.ResultFormatError` (a ``ValueError``), with a one-line
        message naming the file and what is wrong, for a file this version cannot read: one
        written in a newer or an unknown result format, a file that is not a result file
        (not a zip, a zip without our members), a truncated or corrupted file (a damaged
        member, a missing array, unreadable metadata).  A file that cannot be opened at all
        (missing, a directory, no permission) raises the usual ``OSError``.
        """
        with open(path, "rb") as f:                      # OSError: missing file, permissions
            return cls._read(f, path)

    @classmethod
    def _read(cls, f, path) -> "Result":
        def bad(problem: str) -> ResultFormatError:
            return ResultFormatError(path, problem)

        head = f.read(4)
        if not head:
            raise bad("empty file (not a result file)")
        if head != b"PK\x03\x04":
            raise bad("not a result file (not an .npz/zip archive)")
        f.seek(0)
        try:
            z = np.load(f, allow_pickle=False)
        except _DECODE_ERRORS as exc:
            raise bad(f"truncated or corrupted: not a readable zip archive ({_why(exc)})") from None
        if not isinstance(z, np.lib.npyio.NpzFile):  # pragma: no cover - head says zip
            raise bad("not a result file (not an .npz archive)")
        with z:
            names = set(z.files)
            if _FORMAT_MEMBER not in names and "__meta__" not in names:
                listed = ", ".join(sorted(names)[:5]) + (", ..." if len(names) > 5 else "")
                raise bad("not a telescopic-boom-sim result file (no result format version nor "
                          f"metadata; members: {listed or 'none'})")

            def member(name: str) -> np.ndarray:
                if name not in names:
                    raise bad(f"truncated or corrupted: missing array {name!r}")
                try:
                    return z[name]
                except _DECODE_ERRORS as exc:
                    raise bad(f"truncated or corrupted: cannot read array {name!r} "
                              f"({_why(exc)})") from None

            version = 0
            if _FORMAT_MEMBER in names:
                v = member(_FORMAT_MEMBER)
                if v.shape != () or v.dtype.kind not in "iu":
                    raise bad(f"corrupted: the result format version is not an integer "
                              f"({v.dtype}, shape {v.shape})")
                version = int(v)
            if version > RESULT_FORMAT:
                raise bad(f"written by result format {version}, this version of "
                          f"telescopic-boom-sim reads format {RESULT_FORMAT} (upgrade the package)")
            if version < OLDEST_RESULT_FORMAT:
                raise bad(f"unknown result format {version}, this version of telescopic-boom-sim "
                          f"reads formats {OLDEST_RESULT_FORMAT} to {RESULT_FORMAT}")

            raw = member("__meta__")
            if raw.shape != () or raw.dtype.kind != "U":
                raise bad(f"corrupted metadata: '__meta__' is not JSON text ({raw.dtype}, "
                          f"shape {raw.shape})")
            try:
                meta = json.loads(str(raw))
            except ValueError as exc:                    # json.JSONDecodeError
                raise bad(f"unreadable JSON metadata ({_why(exc)})") from None
            if not isinstance(meta, dict):
                raise bad(f"corrupted metadata: a JSON {type(meta).__name__}, not an object")
            stats, scene, error = meta.get("stats", {}), meta.get("scene", {}), meta.get("error")
            for key, value, kind in (("stats", stats, dict), ("scene", scene, dict),
                                     ("error", error, (str, type(None)))):
                if not isinstance(value, kind):
                    raise bad(f"corrupted metadata: {key!r} is a JSON {type(value).__name__}")

            t = member("t")
            if t.ndim != 1 or t.dtype.kind not in "fiu":
                raise bad(f"corrupted: the time array 't' is not a 1-D numeric array "
                          f"({t.dtype}, shape {t.shape})")
            outs = {k[5:]: member(k) for k in z.files if k.startswith("out__")}
        return cls(t, outs, stats, scene, error)


#: The result format :meth:`Result.save` writes.  Bump it when the layout of ``result.npz``
#: changes in a way an older reader would misread, and teach :meth:`Result.load` the old one.
#: 1: a ``__format__`` member added to the unversioned layout (format 0), nothing else changed.
RESULT_FORMAT = 1
#: The oldest result format :meth:`Result.load` reads (0: files written before versioning).
OLDEST_RESULT_FORMAT = 0
_FORMAT_MEMBER = "__format__"
# A damaged archive or member fails in zipfile, zlib or numpy's .npy reader with whatever it
# meets first (BadZipFile for a bad CRC or header, zlib.error, ValueError, EOFError, struct.error,
# tokenize.TokenError for a garbled .npy header, ...): every failure to decode the bytes is
# caught (only there) and reported as a damaged file.
_DECODE_ERRORS = (Exception,)


def _why(exc: BaseException) -> str:
    """The low-level reason in one line (its type when it has no text)."""
    text = " ".join(str(exc).split())
    return text or type(exc).__name__
