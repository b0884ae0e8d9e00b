"""The public entry points: load a scene, simulate it.

    from sim_core import load_scene, simulate
    result = simulate(load_scene("telescopic_extraction", {"solver.t_end": 4}))

:func:`simulate` hands the scene to its system kind (:mod:`sim_core.registry`), which builds
the system, integrates it, checks its own result and returns a :class:`sim_core.Result` that
records the scene.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

from sim_core.checkpoint import CheckpointPolicy, Checkpointer, ambient, scene_fingerprint
from sim_core.registry import system_kind
from sim_core.result import Result
from sim_core.scene.io import apply_overrides, read_scene


def load_scene(name_or_path: str | Path, overrides: dict[str, Any] | None = None) -> dict:
    """Load a shipped scene (by name) or a TOML file, apply dotted-key ``overrides``
    (``{"solver.t_end": 4}``) and validate it: the resolved scene, every default filled in.
    Bad input raises :class:`sim_core.SceneError` naming the field and the allowed range."""
    raw, source = read_scene(name_or_path)
    if overrides is not None:
        raw = apply_overrides(raw, overrides)
    return system_kind(raw).validate(raw, source)


def simulate(scene: dict, progress=None, *, checkpoint: CheckpointPolicy | None = None,
             resume: bool | str = False) -> Result:
    """Run a validated scene (:func:`load_scene`) and return its Result.

    ``progress``: an optional callable ``progress(t, wall_s)`` (simulated and wall time, s).  A failed solve
    raises :class:`sim_core.SimulationError` with the time and the reason, its partial result
    attached as ``.result`` where one exists; a result that fails its own checks grossly raises
    :class:`sim_core.errors.SuspectResult`, and a milder failure marks it (``Result.suspect``).

    ``checkpoint``: a :class:`sim_core.checkpoint.CheckpointPolicy` (file, wall seconds between
    checkpoints): the integration writes its whole state there, atomically, so that a killed
    run can continue.  ``resume``: False (start at t = 0), True (continue from the policy's
    checkpoint, which must be one of this scene: :class:`sim_core.checkpoint.CheckpointError`
    otherwise) or ``"auto"`` (continue where a usable checkpoint of this scene exists, else
    start at t = 0).  The resumed result is bit-identical to the uninterrupted run's
    (:mod:`sim_core.checkpoint`).  The file stays after the run;
    :meth:`~sim_core.checkpoint.CheckpointPolicy.clear` removes it.  Without ``checkpoint``,
    the policy of an enclosing :func:`sim_core.checkpoint.checkpointing` block applies.
    """
    if checkpoint is None and not resume and ambient() is not None:
        checkpoint, resume = ambient()
    if checkpoint is None:
        if resume:
            raise ValueError("resume needs the checkpoint policy to resume from (checkpoint=)")
        return _timed(lambda: system_kind(scene).run(scene, progress))
    ckpt = Checkpointer(checkpoint, scene_fingerprint(scene), resume)
    return _timed(lambda: system_kind(scene).run(scene, progress, checkpoint=ckpt))


def _load() -> list[float] | None:
    """The 1, 5 and 15 min load averages (runnable processes), None where the OS has none."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def _usable_cpus() -> int | None:
    """The logical CPUs this process may run on (its affinity), else the machine's count."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count()


def _timed(run) -> Result:
    """``run()`` with the machine state it ran in added to its Result's ``stats``.

    ``wall_s``: wall time of the whole call (model build, statics, integration, outputs, s);
    ``cpu_s``: this process's CPU time over it (``time.process_time``, every thread of the
    process: the element worker's spinning counts, so it can exceed ``wall_s``); ``load_start``
    / ``load_end``: the 1, 5, 15 min load averages at its start and end; ``usable_cpus``: the
    logical CPUs the process may run on.  A load above ``usable_cpus`` means the run shared
    its cores, and its wall time is longer than on an idle machine.  A failed solve's partial
    result (``SimulationError.result``) gets them too.
    """
    load_start, cpus = _load(), _usable_cpus()
    wall0, cpu0 = time.perf_counter(), time.process_time()

    def stamp(result) -> None:
        if isinstance(result, Result):
            result.stats.update({"wall_s": time.perf_counter() - wall0,
                                 "cpu_s": time.process_time() - cpu0,
                                 "load_start": load_start, "load_end": _load(),
                                 "usable_cpus": cpus})
    try:
        result = run()
    except Exception as exc:
        stamp(getattr(exc, "result", None))
        raise
    stamp(result)
    return result
