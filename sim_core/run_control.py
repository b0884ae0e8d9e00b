"""A run's wall-clock budget, its interrupt flag and the lock of its output folder.

:class:`RunBudget` is one deadline for a whole run: ``solver.max_wall_s`` wall seconds from
the run's start, spent by every phase together -- the static equilibrium, the time
integration, the collection of the outputs and, on the command line, the figures and the
report.  Each phase calls :meth:`RunBudget.check` between its units of work (a Newton
iteration of the statics, a step or a compiled call of the integrator, an output time, a
figure), which raises :class:`~sim_core.errors.WallBudgetExhausted` once the budget is
spent, or :class:`~sim_core.errors.RunInterrupted` once :meth:`RunBudget.interrupt` was
called (``boom-sim run`` calls it from its SIGINT handler, so Ctrl-C never raises
KeyboardInterrupt inside compiled code).  How far past the budget a run ends is the length
of the longest unit of work plus the writing of the partial result (``docs/user_guide.md``,
"Budgets and interruption").

The budget of the run in progress is ambient (:func:`run_budget`, a context variable), so
the phases find it without passing it through every call: :func:`budget_scope` enters the
enclosing run's budget, or starts one where there is none (a :func:`sim_core.simulate` call
from Python), and :func:`current` returns it (a budget without limit outside any run).

:func:`folder_lock` holds an exclusive ``fcntl.flock`` on ``OUT/.boom-sim.lock`` while a
command writes into OUT, so a second writer is refused at once (:class:`FolderBusy`); the
file goes when the command ends.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import time
from pathlib import Path

from sim_core.errors import RunInterrupted, SimulationError, WallBudgetExhausted

#: the lock file :func:`folder_lock` holds in an output folder
LOCK_FILE = ".boom-sim.lock"


class RunBudget:
    """The wall-clock deadline and the interrupt flag of one run.

    ``max_wall_s``: the budget, s (None: unlimited; the interrupt flag still counts).
    ``start``: the run's start on ``time.perf_counter``'s clock (default: now)."""

    def __init__(self, max_wall_s: float | None = None, start: float | None = None):
        self.max_wall_s = None if max_wall_s is None else float(max_wall_s)
        self.start = time.perf_counter() if start is None else float(start)
        self.interrupted = False
        self._credit = 0.0

    def elapsed(self) -> float:
        """Wall seconds of the budget spent: since the start, plus :meth:`credit`."""
        return time.perf_counter() - self.start + self._credit

    def credit(self, seconds: float) -> None:
        """Count ``seconds`` spent elsewhere as spent (a resumed run: the integration time of
        the process that wrote the checkpoint)."""
        self._credit += float(seconds)

    def interrupt(self) -> None:
        """Ask the run to stop at its next check (signal-safe: only sets a flag)."""
        self.interrupted = True

    def exceeded(self, phase: str, t: float = 0.0, step: float | None = None,
                 last_state=None) -> SimulationError | None:
        """The typed error a check at this moment raises (None: go on): the interruption
        first, then the budget.  ``t``: the simulated time reached, s."""
        if self.interrupted:
            return RunInterrupted(t, phase, step=step, last_state=last_state)
        if self.max_wall_s is not None:
            spent = self.elapsed()
            if spent > self.max_wall_s:
                return WallBudgetExhausted(t, self.max_wall_s, phase, spent, step=step,
                                           last_state=last_state)
        return None

    def check(self, phase: str, t: float = 0.0, step: float | None = None,
              last_state=None) -> None:
        """Raise :meth:`exceeded`'s error where there is one."""
        exc = self.exceeded(phase, t, step, last_state)
        if exc is not None:
            raise exc


_CURRENT: contextvars.ContextVar = contextvars.ContextVar("sim_core_run_budget", default=None)
_UNLIMITED = RunBudget(None)


@contextlib.contextmanager
def run_budget(budget: RunBudget):
    """Make ``budget`` the ambient budget of the block (:func:`current`)."""
    token = _CURRENT.set(budget)
    try:
        yield budget
    finally:
        _CURRENT.reset(token)


@contextlib.contextmanager
def budget_scope(max_wall_s: float | None):
    """The enclosing run's budget where there is one (the command line starts it before
    loading the scene), else a budget of ``max_wall_s`` started now, ambient for the block."""
    outer = _CURRENT.get()
    if outer is not None:
        yield outer
        return
    with run_budget(RunBudget(max_wall_s)) as b:
        yield b


def current() -> RunBudget:
    """The ambient budget (:func:`run_budget`), or one without limit outside any run."""
    b = _CURRENT.get()
    return _UNLIMITED if b is None else b


def for_solver(max_wall_s: float | None) -> RunBudget:
    """The ambient budget, or outside any run one of ``max_wall_s`` started now (an
    integration called on its own: its budget counts from its start)."""
    b = _CURRENT.get()
    return RunBudget(max_wall_s) if b is None else b


def check(phase: str, t: float = 0.0, step: float | None = None, last_state=None) -> None:
    """:meth:`RunBudget.check` of the ambient budget."""
    current().check(phase, t, step, last_state)


def checked(items, phase: str = "outputs"):
    """``items`` one by one, the ambient budget checked (:func:`check`) before each: for
    loops over a run's output times outside the output collection (its result checks)."""
    for item in items:
        check(phase)
        yield item


def budgeted(run):
    """A system kind's ``run(scene, progress=None, checkpoint=None)`` under the scene's
    ``solver.max_wall_s`` (:func:`budget_scope`).  A run stopped by the budget or Ctrl-C
    before any output (in the statics) carries a result without output times, its error
    set, so that what the caller writes says why the run ended."""
    def wrapped(scene: dict, progress=None, checkpoint=None):
        with budget_scope(scene.get("solver", {}).get("max_wall_s")):
            try:
                return run(scene, progress, checkpoint)
            except (WallBudgetExhausted, RunInterrupted) as exc:
                if getattr(exc, "result", None) is None:
                    import numpy as np

                    from sim_core.result import Result
                    exc.result = Result(np.zeros(0), {}, {"phase": exc.phase}, scene,
                                        " ".join(str(exc).split()))
                raise
    wrapped.__doc__, wrapped.__name__ = run.__doc__, run.__name__
    wrapped.__module__, wrapped.__qualname__ = run.__module__, run.__qualname__
    return wrapped


#: wall seconds the outputs of a partial result may still take once the budget is spent or
#: the run interrupted (the outputs end where they got by then)
PARTIAL_GRACE_S = 2.0


class OutputGuard:
    """The check of an output loop (phase ``outputs``): ``guard(t)`` before each output time
    is True where the loop must stop.

    For a finished integration (``partial`` False) it stops once the budget is spent or the
    run interrupted, and :meth:`finish` raises that error with the outputs collected so far
    attached.  For a partial result (``partial`` True: the integration failed, ran out of
    budget or was interrupted) it stops only after :data:`PARTIAL_GRACE_S` more wall
    seconds, so that a run out of budget still writes the outputs it can collect at once."""

    def __init__(self, partial: bool, phase: str = "outputs"):
        self.budget = current()
        self.partial = bool(partial)
        self.phase = phase
        self.t0 = time.perf_counter()
        self.error: SimulationError | None = None

    def __call__(self, t: float) -> bool:
        exc = self.budget.exceeded(self.phase, float(t))
        if exc is None or (self.partial and time.perf_counter() - self.t0 <= PARTIAL_GRACE_S):
            return False
        self.error = exc
        return True

    def finish(self, result):
        """``result`` (the outputs collected), or for a finished integration the guard
        stopped: raise its error with ``result`` attached (``result.error`` set)."""
        if self.error is None:
            return result
        if self.partial:            # a failed run's outputs, cut short: say where
            result.stats["outputs_cut_at_s"] = self.error.t
            return result
        result.error = str(self.error)
        self.error.result = result
        raise self.error


# -- the output folder's lock ----------------------------------------------------------------

class FolderBusy(RuntimeError):
    """Another process holds the output folder's lock (:func:`folder_lock`)."""


@contextlib.contextmanager
def folder_lock(folder: str | Path, option: str = "--out"):
    """Hold an exclusive, non-blocking ``fcntl.flock`` on ``folder/.boom-sim.lock`` (the
    folder must exist) for the block; the holder's process id is written into the file.
    Raises :class:`FolderBusy` (one line naming ``option``, the folder and the holder) where
    another process holds it.  The file is removed when the block ends (while still locked;
    a process that locked the file just removed finds it gone and locks the new one), and a
    killed writer's lock goes with its file descriptor.  Without ``fcntl`` (Windows) nothing
    is locked."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - no flock on this platform
        yield
        return
    path = Path(folder) / LOCK_FILE
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip()
            os.close(fd)
            raise FolderBusy(
                f"{option} {str(folder)!r} is in use by another boom-sim"
                + (f" (process {holder})" if holder.isdigit() else "")
                + ": wait for it to finish or choose another folder") from None
        try:
            same = os.fstat(fd).st_ino == os.stat(path).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)              # locked a file its holder removed meanwhile: again
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, str(os.getpid()).encode(), 0)
        yield
    finally:
        with contextlib.suppress(OSError):
            os.unlink(path)
        os.close(fd)


__all__ = ["RunBudget", "run_budget", "budget_scope", "current", "for_solver", "check",
           "OutputGuard", "PARTIAL_GRACE_S", "checked", "budgeted",
           "folder_lock", "FolderBusy", "LOCK_FILE"]
