"""The public entry points: load a scene, simulate it.

    from sim_core import load_scene, simulate
    result = simulate(load_scene("telescopic_extraction", {"solver.t_end": 4}))

:func:`simulate` hands the scene to its system kind (:mod:`sim_core.registry`), which builds
the system, integrates it, checks its own result and returns a :class:`sim_core.Result` that
records the scene.
"""

from __future__ import annotations

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
    if overrides:
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
        return system_kind(scene).run(scene, progress)
    ckpt = Checkpointer(checkpoint, scene_fingerprint(scene), resume)
    return system_kind(scene).run(scene, progress, checkpoint=ckpt)
