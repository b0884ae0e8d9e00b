"""Checkpoints of a running simulation: the integrator's whole state written to one file at
most every ``every_s`` wall seconds, so that a run killed by a signal, an out-of-memory kill,
a lost machine or Ctrl-C continues from its last checkpoint instead of from t = 0.

    from sim_core import load_scene, simulate
    from sim_core.checkpoint import CheckpointPolicy
    scene = load_scene("telescopic_extraction")
    policy = CheckpointPolicy("run/checkpoint.pkl", every_s=30.0)
    result = simulate(scene, checkpoint=policy)                 # killed? then:
    result = simulate(scene, checkpoint=policy, resume=True)    # continues from the checkpoint

What a checkpoint holds (:class:`Checkpointer`): the scene's fingerprint
(:func:`scene_fingerprint`), the integration path that wrote it and that path's whole state
at the end of an accepted step -- time, state, the outputs computed so far, the method and
its history (scipy's RK45 / BDF solver state: step size, error history, BDF's difference
array, order, Jacobian and its factorisation; the RK45/BDF switch of ``"auto"`` with its
stiffness detector and cost memory; generalized-alpha's accelerations, auxiliary
accelerations, tangent, iteration matrix and step controller, compiled or numpy), the stall
monitor, the model's warm starts (the friction micro-motions and the multiplier Newton's last
solution) and the work counters.  The drives of a batch run are functions of time and carry
no state.  A resumed run takes exactly the steps the uninterrupted run takes from there, so
its result is bit-identical to it (tests/test_checkpoint.py) where both processes are set up
alike (the same library versions, which the checkpoint records and checks, and the same BLAS
thread count: ``import sim_core`` before numpy sets one thread).  Its statistics count the
work and the wall time of the whole run (the part after the last checkpoint of a killed
process is lost: computed again) and name the time it resumed from (``resumed_from_s``).

Which runs write checkpoints: every integrated model (the ``integrate`` driver's RK45, BDF
and ``"auto"``, generalized-alpha fixed-step and error-controlled, compiled or numpy).  The
modal reduced-order model and the rigid-boom limit (closed loops of a fraction of a second)
run without: a policy with ``required=True`` (the command line's explicit
``--checkpoint-every``) refuses them with a :class:`CheckpointError`; the default policy
(``required=False``) runs them without checkpoints.  The wall-clock budget
``solver.max_wall_s`` counts the whole run, the checkpointed part included.

When one is written: at the end of the first accepted step (compiled generalized-alpha: the
first return of a compiled call, every output interval or 1000 steps) after ``every_s`` wall
seconds since the run started or since the last checkpoint.  A run shorter than ``every_s``
writes none, so the default of the command line (:data:`DEFAULT_EVERY_S` = 30 s, on for every
run) costs nothing on short runs.  Size and cost, the paper's crane at 313 coordinates:
~0.5-1 MB while RK45 runs (it grows with the outputs), ~8 MB while BDF runs (its Jacobian and
factors), 0.02-0.2 s to write (synced to disk), well under 1 % of a 30 s interval.

The file: a header line with the format, the SHA-256 of the body, then the body (a pickle
of numbers, strings, tuples, lists, dicts and numpy arrays only, read back by a restricted
unpickler that refuses anything else: it resolves only the builtin containers and numbers
listed in ``_ALLOWED`` and numpy's array and dtype reconstructors, so no other class or
function is ever called).  The body's structure is then checked against what its integration
path writes (``_STATES``: the keys, types, array dtypes and shapes, one state length across
the arrays) and a restored solver attribute keeps the shape and kind of the fresh solver's,
so a body with a valid checksum but another structure is refused like a damaged file.  It is
written through
:func:`sim_core.result.atomic_path` (a temporary file, synced, renamed over the old one), so
a writer killed mid-write leaves the previous
checkpoint whole (and a stale temporary file beside it, removed by the next run with the same
path).  A file that is truncated, corrupt, of another format, of another scene (fingerprint),
of another integration path or written by another numpy/scipy/sim_core version raises
:class:`CheckpointError` with a one-line message when resumed strictly (``resume=True``);
with ``resume="auto"`` (the sweeps' retries) such a file is ignored and the run starts from
t = 0.

Fault injection for the tests: the environment variable ``SIM_CORE_CHECKPOINT_FAULT``
(``kill-after:MARKER`` or ``kill-during:MARKER``) makes the first process that creates the
file MARKER kill itself with SIGKILL right after writing a checkpoint, or half-way through
writing one while a previous checkpoint exists.
"""

from __future__ import annotations

import contextlib
import contextvars
import hashlib
import io
import json
import math
import os
import pickle
import signal
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sim_core._version import __version__
from sim_core.result import atomic_path

MAGIC = b"BOOM-SIM CHECKPOINT"
FORMAT = 1
#: wall seconds between checkpoints of the command line's default policy
DEFAULT_EVERY_S = 30.0
FAULT_ENV = "SIM_CORE_CHECKPOINT_FAULT"
RESUME_MODES = (False, True, "auto")


class CheckpointError(ValueError):
    """A checkpoint cannot be used: missing where a resume needs one, truncated or corrupt,
    of another scene, format, integration path or library version, or asked for on a run
    that has none.  One-line message ``PATH: what is wrong`` (command line: exit status 2).

    Attributes
    ----------
    path : str
        The checkpoint file.
    problem : str
        What is wrong with it.
    """

    def __init__(self, path, problem: str):
        self.path = str(path)
        self.problem = " ".join(str(problem).split())
        super().__init__(f"checkpoint {self.path}: {self.problem}")


def scene_fingerprint(scene: dict) -> str:
    """SHA-256 of the validated scene (its file path left out): equal fingerprints, equal
    runs.  The sweeps' ``scene_sha256`` and the checkpoints' scene check."""
    body = {k: v for k, v in scene.items() if k != "source"}
    return hashlib.sha256(json.dumps(body, sort_keys=True, default=str).encode()).hexdigest()


def _versions() -> dict:
    import scipy
    return {"sim_core": __version__, "numpy": np.__version__, "scipy": scipy.__version__}


@dataclass(frozen=True)
class CheckpointPolicy:
    """Where and how often a run writes its checkpoint.

    ``path``: the checkpoint file (its folder is created).  ``every_s``: wall seconds between
    checkpoints (> 0; ``math.inf``: never written, only read for a resume).  ``required``:
    a run that has no checkpoints (module docstring) raises :class:`CheckpointError` instead
    of running without."""

    path: str | Path
    every_s: float = DEFAULT_EVERY_S
    required: bool = True

    def __post_init__(self):
        every = self.every_s
        if isinstance(every, bool) or not isinstance(every, (int, float)) or \
                math.isnan(every) or every <= 0:
            raise ValueError(f"every_s = {every!r}: the wall seconds between checkpoints must "
                             "be > 0 (allowed: (0, inf])")

    def clear(self) -> None:
        """Remove the checkpoint file (a finished run's result makes it obsolete)."""
        try:
            os.unlink(self.path)
        except FileNotFoundError:
            pass


# -- the file ----------------------------------------------------------------------------------

_ALLOWED = {
    ("builtins", name) for name in ("complex", "float", "int", "bool", "str", "bytes", "tuple",
                                    "list", "dict", "set", "frozenset", "slice", "range")
} | {
    (mod, name) for mod in ("numpy", "numpy.core.multiarray", "numpy._core.multiarray",
                            "numpy.core.numeric", "numpy._core.numeric")
    for name in ("ndarray", "dtype", "_reconstruct", "scalar", "_frombuffer")
} | {("numpy", "dtypes." + n) for n in ("Float64DType", "Int64DType", "Int32DType", "BoolDType",
                                         "Complex128DType")} | {
    ("numpy.dtypes", n) for n in ("Float64DType", "Int64DType", "Int32DType", "BoolDType",
                                  "Complex128DType")}


class _Unpickler(pickle.Unpickler):
    """Numbers, strings, containers and numpy arrays only: a checkpoint holds nothing else,
    and a file that names another class is not a checkpoint of this module."""

    def find_class(self, module, name):
        if (module, name) in _ALLOWED:
            return super().find_class(module, name)
        raise pickle.UnpicklingError(f"unexpected object {module}.{name}")


def encode(payload: dict) -> bytes:
    """The checkpoint file's bytes: header line (magic, format, SHA-256 of the body), body."""
    body = pickle.dumps(payload, protocol=pickle.HIGHEST_PROTOCOL)
    head = MAGIC + f" {FORMAT} {hashlib.sha256(body).hexdigest()} {len(body)}\n".encode()
    return head + body


def decode(data: bytes, path) -> dict:
    """The payload of a checkpoint file's bytes; CheckpointError naming what is wrong."""
    head, sep, body = data.partition(b"\n")
    parts = head.split(b" ")
    if not data.startswith(MAGIC + b" ") or not sep or len(parts) != 5:
        raise CheckpointError(path, "not a boom-sim checkpoint (no checkpoint header); remove "
                                    "it and run without --resume")
    try:
        fmt, digest, size = int(parts[2]), parts[3].decode(), int(parts[4])
    except (ValueError, UnicodeDecodeError):
        raise CheckpointError(path, "corrupt checkpoint header; remove it and run without "
                                    "--resume") from None
    if fmt != FORMAT:
        raise CheckpointError(path, f"checkpoint format {fmt}, this version reads format "
                                    f"{FORMAT}; run without --resume")
    if len(body) != size or hashlib.sha256(body).hexdigest() != digest:
        raise CheckpointError(path, f"truncated or corrupt ({len(body)} of {size} body bytes, "
                                    "checksum mismatch); remove it and run without --resume")
    try:
        payload = _Unpickler(io.BytesIO(body)).load()
    except Exception as exc:  # noqa: BLE001 - any unpickling failure is a corrupt file
        raise CheckpointError(path, f"corrupt body ({type(exc).__name__}: {exc}); remove it "
                                    "and run without --resume") from None
    if not isinstance(payload, dict) or not {"fingerprint", "driver", "t", "state",
                                             "versions"} <= set(payload):
        raise CheckpointError(path, "corrupt body (fields missing); remove it and run without "
                                    "--resume")
    try:
        _check(payload, _BODY, "", {})
        _check(payload["state"], _STATES[payload["driver"]], "state", {})
    except _Malformed as exc:
        raise CheckpointError(path, f"corrupt body ({exc}); remove it and run without "
                                    "--resume") from None
    return payload


# -- the body's structure ------------------------------------------------------------------------
# What each integration path's :meth:`Checkpointer.save` writes and its resume reads
# (sim_core.integrate.driver, generalized_alpha, rosenbrock): the reader checks it before
# anything is restored.  A spec is a kind ("number", "integer", "string", "boolean", "object":
# a dict with string keys whose values are checked where they are restored, "numbers": a list
# or 1-D array of numbers, "any"), a dict of required keys (more keys are allowed), or a tuple:
# ("array", shape, dtype kinds) with each dimension an int, None (any) or a symbol that takes
# one length across the body, ("opt", spec) for None or spec, ("seq", spec) for a list, tuple
# or array of spec, ("tuple", n, spec) for n of them, ("choice", values).

class _Malformed(Exception):
    """A body that does not have the structure its integration path writes."""


def _vec(dim="n"):
    return ("array", (dim,), "f")


def _mat(rows="n", cols="n"):
    return ("array", (rows, cols), "f")


_STALL = {"times": _vec("window"), "walls": _vec("window"), "k": "integer", "slowest": "number"}
_GA = {"ga": {**{k: _vec() for k in ("q", "v", "a", "qdd", "qdd_prev", "atol_q", "atol_v")},
              "t": "number", "h_prev": "number", "step_index": "integer", "rtol": "number"},
       "ev": {"n_calls": "integer", "n_tangent": "integer"}, "stats": "object",
       "out": {"ts": "numbers", "ys": ("seq", ("tuple", 3, _vec())), "k": "integer"},
       "loop": "object"}
_ALPHA_COMMON = {"wall_s": "number", "warm": "object", "ga": _GA}
_STATES = {
    "scipy": {"solver_class": ("choice", ("RK45", "BDF")),
              "solver": {"t": "number", "y": _vec()}, "ys": ("seq", _vec()),
              "k_out": "integer", "steps": "numbers", "njev": "integer", "wall_s": "number",
              "jac": ("opt", "object"), "switch": ("opt", "object"), "stall": _STALL,
              "rhs": "object", "warm": "object"},
    "alpha_numpy_fixed": _ALPHA_COMMON,
    "alpha_numpy_adaptive": {**_ALPHA_COMMON, "shim": ("tuple", 2, "number"),
                             "shim_y": _vec("2n"), "stall": _STALL},
    # the compiled loops' arrays: carry and counts of driver._alpha_fixed / _alpha_adaptive
    "alpha_fixed": {**{k: _vec() for k in ("q", "v", "a", "qdd", "qdd_prev")},
                    "Sinv": _mat(), "carry": _vec(2), "counts": ("array", (6,), "iu"),
                    "h_used": "numbers", "k": "integer",
                    "out": ("tuple", 3, _mat(None, "n")), "ys": _mat(None, "2n"),
                    "wall_s": "number"},
    "alpha_adaptive": {**{k: _vec() for k in ("q", "v", "a", "qdd")},
                       **{k: _mat() for k in ("Cr", "Kr", "Mr", "Sinv")},
                       "Y": _mat(None, "2n"), "carry": _vec(3), "counts": ("array", (8,), "iu"),
                       "hs": _vec(7), "k_out": "integer",
                       "pace_marks": ("seq", ("tuple", 2, "number")),
                       "pace_slowest": "number", "wall_s": "number"},
    "ros2": {"k": "integer", "ys": ("seq", _vec("any")), "wall_s": "number", "warm": "object",
             "ros2": {"age": "number", "stats": "object", "band": "any", "Jzz": "any",
                      "Jzv": "any", "ft": "any"}},
}
_BODY = {"fingerprint": "string", "driver": ("choice", tuple(_STATES)), "t": "number",
         "versions": "object", "state": "object"}
_NUMBER = (int, float, np.integer, np.floating)


def _check(v, spec, where: str, dims: dict) -> None:
    """Raise _Malformed naming ``where`` (the dotted key) where ``v`` does not match ``spec``;
    ``dims`` holds the lengths the symbols took."""
    def bad(expected: str):
        got = (f"shape {v.shape} of {v.dtype}" if isinstance(v, np.ndarray)
               else type(v).__name__)
        raise _Malformed(f"{where or 'the body'}: {expected} expected, got {got}")

    if isinstance(spec, dict):
        if not isinstance(v, dict):
            bad("an object")
        for key, sub in spec.items():
            if key not in v:
                raise _Malformed(f"{where + '.' if where else ''}{key} is missing")
            _check(v[key], sub, f"{where}.{key}" if where else key, dims)
        return
    if isinstance(spec, str):
        ok = {"number": lambda: isinstance(v, _NUMBER) and not isinstance(v, bool),
              "integer": lambda: isinstance(v, (int, np.integer)) and not isinstance(v, bool),
              "string": lambda: isinstance(v, str),
              "boolean": lambda: isinstance(v, (bool, np.bool_)),
              "object": lambda: isinstance(v, dict) and all(isinstance(k, str) for k in v),
              "numbers": lambda: (isinstance(v, np.ndarray) and v.ndim == 1
                                  and v.dtype.kind in "fiu")
              or (isinstance(v, (list, tuple)) and all(isinstance(x, _NUMBER)
                                                       and not isinstance(x, bool) for x in v)),
              "any": lambda: True}[spec]()
        if not ok:
            bad({"integer": "an integer", "object": "an object", "any": ""}.get(spec, f"a {spec}"))
        if spec == "number" and where == "t" and not math.isfinite(v):
            raise _Malformed("t: a finite time expected")
        return
    kind = spec[0]
    if kind == "opt":
        if v is not None:
            _check(v, spec[1], where, dims)
    elif kind == "choice":
        if not isinstance(v, str) or v not in spec[1]:
            raise _Malformed(f"{where}: one of {', '.join(spec[1])} expected")
    elif kind in ("seq", "tuple"):
        items = list(v) if isinstance(v, (list, tuple, np.ndarray)) else None
        n = spec[1] if kind == "tuple" else None
        if items is None or (n is not None and len(items) != n):
            bad(f"a sequence of {n}" if n is not None else "a sequence")
        for i, x in enumerate(items):
            _check(x, spec[-1], f"{where}[{i}]", dims)
    else:                                   # ("array", shape, kinds)
        shape, kinds = spec[1], spec[2]
        if not isinstance(v, np.ndarray) or v.dtype.kind not in kinds or v.ndim != len(shape):
            bad(f"a {len(shape)}-D array of {'floats' if kinds == 'f' else 'integers'}")
        for size, dim in zip(v.shape, shape):
            if isinstance(dim, str) and dim != "any":
                dim = dims.setdefault(dim, size)
            if dim not in (None, "any") and size != dim:
                bad(f"a length of {dim}")


def _fault(kind: str) -> bool:
    """Whether this process takes the fault ``kind`` of SIM_CORE_CHECKPOINT_FAULT now (the
    first process to create its marker file does, once)."""
    spec = os.environ.get(FAULT_ENV, "")
    if not spec.startswith(kind + ":"):
        return False
    try:
        os.close(os.open(spec[len(kind) + 1:], os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except OSError:
        return False
    return True


def _kill_self() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


class Checkpointer:
    """A run's checkpoints under a :class:`CheckpointPolicy` (made by
    :func:`sim_core.api.simulate` for the scene's fingerprint).

    ``resume``: False (start at t = 0; the file is overwritten), True (the file must hold a
    checkpoint of this scene: CheckpointError otherwise) or ``"auto"`` (resume where the file
    holds a usable checkpoint of this scene, else start at t = 0).  The integration path asks
    :meth:`take` for its saved state, calls :meth:`due` after every accepted step and
    :meth:`save` when it is due; a path without checkpoints calls :meth:`unsupported`."""

    def __init__(self, policy: CheckpointPolicy, fingerprint: str, resume: bool | str = False):
        if resume not in RESUME_MODES:
            raise ValueError(f"resume = {resume!r}: allowed False, True or 'auto'")
        self.policy = policy
        self.path = Path(policy.path)
        self.every_s = float(policy.every_s)
        self.fingerprint = fingerprint
        self.payload: dict | None = None
        self.resumed_from_s: float | None = None
        self.n_written = 0
        self.active = True
        self.strict = resume is True
        self._remove_stale_temporaries()
        if resume:
            try:
                self.payload = self._load()
            except CheckpointError:
                if resume is True:
                    raise
        self.last = time.perf_counter()

    def _remove_stale_temporaries(self) -> None:
        """Temporary files of this path that a writer killed mid-write left behind."""
        folder = self.path.parent
        if not folder.is_dir():
            return
        prefix = f".{self.path.name}."
        for p in folder.iterdir():
            if p.name.startswith(prefix) and p.name.endswith(".tmp") and p.is_file():
                try:
                    p.unlink()
                except OSError:
                    pass

    def _load(self) -> dict:
        try:
            data = self.path.read_bytes()
        except FileNotFoundError:
            raise CheckpointError(self.path, "no checkpoint to resume from (a finished run "
                                             "removes its checkpoint; run without --resume "
                                             "to start from t = 0)") from None
        except OSError as exc:
            raise CheckpointError(self.path, f"cannot read it: {exc.strerror or exc}") from None
        payload = decode(data, self.path)
        if payload["fingerprint"] != self.fingerprint:
            raise CheckpointError(self.path, "written for another scene (the scene's SHA-256 "
                                             "differs: it or its overrides changed since); run "
                                             "without --resume to start from t = 0")
        now = _versions()
        if payload["versions"] != now:
            was = ", ".join(f"{k} {v}" for k, v in sorted(payload["versions"].items()))
            raise CheckpointError(self.path, f"written by {was}; this is "
                                             + ", ".join(f"{k} {v}" for k, v in sorted(now.items()))
                                             + " (a resume needs the same versions)")
        return payload

    # -- the integration path's side ------------------------------------------------------------
    def take(self, driver: str) -> dict | None:
        """The saved state of integration path ``driver`` (None: start at t = 0); a checkpoint
        of another path raises CheckpointError (resume True) or is dropped (``"auto"``)."""
        if self.payload is None:
            return None
        payload, self.payload = self.payload, None
        if payload["driver"] != driver:
            raise CheckpointError(self.path, f"written by the {payload['driver']!r} integration "
                                             f"path, this run takes {driver!r}")
        self.resumed_from_s = float(payload["t"])
        _TAKEN.set(str(self.path))
        return payload["state"]

    def unsupported(self, what: str) -> None:
        """A run path without checkpoints: CheckpointError where the policy requires them,
        else the run goes on without (and a strict resume has nothing to resume)."""
        self.active = False
        if self.policy.required:
            raise CheckpointError(self.path, f"{what} runs without checkpoints (they cover the "
                                             "integrated models: RK45, BDF, auto and "
                                             "generalized-alpha); run without --checkpoint-every "
                                             "and --resume")
        if self.payload is not None and self.strict:
            raise CheckpointError(self.path, f"{what} runs without checkpoints: nothing to "
                                             "resume")

    def due(self) -> bool:
        """Whether ``every_s`` wall seconds have passed since the start or the last write."""
        return self.active and time.perf_counter() - self.last >= self.every_s

    def save(self, driver: str, t: float, state: dict) -> None:
        """Write the checkpoint of path ``driver`` at simulated time t (s) atomically."""
        data = encode({"format": FORMAT, "fingerprint": self.fingerprint, "driver": driver,
                       "t": float(t), "versions": _versions(), "state": state})
        during = self.path.exists() and _fault("kill-during")
        with atomic_path(self.path) as tmp, open(tmp, "wb") as f:
            if during:                  # fault injection: die half-way through the write
                f.write(data[:len(data) // 2])
                f.flush()
                _kill_self()
            f.write(data)
        self.n_written += 1
        self.last = time.perf_counter()
        if _fault("kill-after"):
            _kill_self()

    def stats(self) -> dict:
        """The statistics a result records: checkpoints written, the time resumed from (none
        for a run that wrote none and did not resume)."""
        out: dict[str, Any] = {}
        if self.n_written:
            out["checkpoints_written"] = self.n_written
        if self.resumed_from_s is not None:
            out["resumed_from_s"] = self.resumed_from_s
        return out


_AMBIENT: contextvars.ContextVar = contextvars.ContextVar("sim_core_checkpointing",
                                                          default=None)
# the checkpoint file the running resume took its state from (restore_object_state's errors)
_TAKEN: contextvars.ContextVar = contextvars.ContextVar("sim_core_checkpoint_taken",
                                                        default="(resumed checkpoint)")


@contextlib.contextmanager
def checkpointing(policy: CheckpointPolicy | None, resume: bool | str = False):
    """Within the block, :func:`sim_core.api.simulate` calls that pass no ``checkpoint`` of
    their own use ``policy`` and ``resume`` (the command line's ``run``; code that reaches
    simulate() through layers that do not pass the arguments on).  ``policy`` None: none."""
    if resume not in RESUME_MODES:
        raise ValueError(f"resume = {resume!r}: allowed False, True or 'auto'")
    token = _AMBIENT.set(None if policy is None else (policy, resume))
    try:
        yield
    finally:
        _AMBIENT.reset(token)


def ambient() -> tuple[CheckpointPolicy, bool | str] | None:
    """The (policy, resume) of the innermost :func:`checkpointing` block, or None."""
    return _AMBIENT.get()


def object_state(obj, skip: tuple = ()) -> dict:
    """An object's attributes without its callables (and the names in ``skip``): the numbers
    and arrays of a solver object, for :func:`restore_object_state` onto a fresh one."""
    return {k: v for k, v in vars(obj).items() if k not in skip and not callable(v)}


def restore_object_state(obj, state: dict) -> None:
    """Set the attributes of :func:`object_state` on ``obj`` (a fresh object of the same class
    whose callables are its own).  An array attribute of ``obj`` takes only an array of its
    shape and dtype kind, a number only a number or None: a checkpoint body that differs
    raises :class:`CheckpointError` (the file :meth:`Checkpointer.take` read) before any
    attribute is set."""
    for k, v in state.items():
        cur = getattr(obj, k, None)
        what = None
        if isinstance(cur, np.ndarray) and not (isinstance(v, np.ndarray) and v.shape == cur.shape
                                                and v.dtype.kind == cur.dtype.kind):
            what = f"an array of shape {cur.shape} of {cur.dtype.kind}-kind"
        elif isinstance(cur, _NUMBER) and not isinstance(cur, (bool, np.bool_)) and not (
                v is None or (isinstance(v, _NUMBER) and not isinstance(v, (bool, np.bool_)))):
            what = "a number"
        if what:
            got = (f"shape {v.shape} of {v.dtype}" if isinstance(v, np.ndarray)
                   else type(v).__name__)
            raise CheckpointError(_TAKEN.get(), f"corrupt body ({type(obj).__name__}.{k}: {what} "
                                                f"expected, got {got}); remove it and run "
                                                "without --resume")
    for k, v in state.items():
        setattr(obj, k, v)


__all__ = ["CheckpointPolicy", "Checkpointer", "CheckpointError", "scene_fingerprint",
           "checkpointing", "ambient",
           "DEFAULT_EVERY_S", "object_state", "restore_object_state"]
