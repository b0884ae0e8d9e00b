"""A persistent compiled worker thread for the element batch of the right-hand side.

``Model`` hands the element batch (:class:`sim_core.physics._effects_numba.ElementBatch`) to a
second thread while it forms the constraint rows and point effects on the calling thread.
Through a ``ThreadPoolExecutor`` each hand-over costs a queue put, a thread wake-up, the
worker's Python prologue before the compiled batch releases the GIL (the caller yields the GIL
for it, ``time.sleep(0)``: ~0.1 ms in cProfile, the queue put ~0.04 ms) and a second wake-up
when the caller joins.  Without them the paper scene's right-hand side took 1.39 instead of
1.46 ms (interleaved A/B, 8 sub-elements; the element batch itself then sets the pace).

Here the worker is one compiled loop (numba, nogil) that never needs the GIL: the batch's
inputs and outputs live in a mailbox of numpy arrays owned by the worker, and one int64 state
word hands them over (acquire/release atomics; compare-and-swap where both threads may write).

* States: IDLE (the caller may post), REQUEST (inputs written, the worker computes), DONE (the
  outputs written; the caller reads them and sets IDLE: they stay valid until it posts again,
  as the worker writes only on a REQUEST), EXITED (no worker thread: the next post
  starts one), ERROR (the worker raised; the caller raises it as an
  :class:`sim_core.errors.ElementEvaluationError` at the request's time), STOP (the caller
  asks an idle worker to exit now: :meth:`ElementWorker.stop`).
* The worker spins on the state word (x86 ``pause``) for ``SPIN_S`` = 5 ms after its last
  request, then polls with ``usleep(sleep_us)``; after ``polls`` such polls (~1 s) it leaves
  IDLE -> EXITED by compare-and-swap and returns, so an idle model does not keep a thread.  A
  caller that finds EXITED starts a new thread.  The spin is set in time, from the pause rate
  measured once per process (:func:`spin_iterations`): a fixed 20 000 pauses lasted only
  ~0.2 ms on the test machine (~25 cycles each), shorter than the ~0.6 ms from one batch's end
  to the next right-hand side's post, so the worker was asleep at every post and woke up to
  0.2 ms late (right-hand side 1.44 -> 1.30 ms, back to back).
* The worker writes the elements one by one and publishes each (the ``PROGRESS`` word,
  release): :meth:`ElementWorker.wait_element` lets the caller use element e while the later
  ones are computed (:func:`sim_core.model._saddle_point_numba.kkt_factor_pipelined` factors each
  element's block of the saddle-point matrix meanwhile).
* The caller waits for DONE spinning in compiled code too (without the GIL), checking that
  the worker thread is alive and yielding its core (``sched_yield``) between rounds of
  ~0.5 ms, so that a worker that shares its core gets on.
* Forced on (``SIM_CORE_ELEMENT_WORKER=on``) in a process with fewer than two cores in its
  affinity set, the two threads share one core and neither spins
  (:meth:`ElementWorker.share_core`): the idle worker yields its core (``sched_yield``) for
  ``SPIN_S`` after each request, then polls, and the caller yields after every check.  A
  spinning thread there holds the core until the scheduler preempts it (milliseconds per
  hand-over: a short RK45 run of a beam took 4-7 times as long as on the calling thread);
  yielding hands it over at once.  The batch and its order are the same, so the numbers are
  bit-identical.

A forked child gets its own worker (the parent's thread does not exist there: the process id
is checked at every post).

Whether the worker runs at all is decided per model by a :class:`Governor`:

* The worker needs a core of its own: it spins while it waits and the caller spins while it
  waits for the worker.  With fewer than two cores in the process's affinity set
  (``os.sched_getaffinity``) the model never starts it (nor the thread pool): the element
  batch runs on the calling thread.
* With two or more the governor measures whether the worker actually gets a core.  The worker
  stamps each request with CLOCK_MONOTONIC at the post (caller), at its start and at its end
  (worker); the request's *delay* is (end - post) minus the batch's own compute time
  ``b`` (the smallest end - start seen, the batch uncontended).  A worker on a core of its own
  starts within microseconds and computes at its uncontended pace, so its delays are a small
  fraction of ``b``; one that shares a core with another runnable thread (another process on
  the second core: the worker, the caller and the other process take turns in scheduler
  slices of milliseconds) is delayed by slices, of the order of ``b`` or more per request
  (see :class:`Governor` for the thresholds).  When the delays of a window of requests exceed
  the budget the governor stops the worker (no thread, no spinning) and the batches run on the
  calling thread; it probes the worker again after 0.25 s, then after twice as long after
  every failed probe (up to 8 s), with a stricter budget to go back (hysteresis).
* OpenBLAS's own threads spin too: the first model to evaluate its elements sets the
  process's OpenBLAS libraries to the thread count asked for (``OPENBLAS_NUM_THREADS``, else
  ``OMP_NUM_THREADS``, else one; :func:`limit_blas_threads`), also where numpy was imported
  before sim_core could set those variables' defaults.
* The environment variable ``SIM_CORE_ELEMENT_WORKER`` overrides the decision: ``off`` (or
  ``0``) never starts a worker thread (nor the thread pool), ``on`` (or ``1``) always uses the
  worker where it is available, ``auto`` (the default) as above.

Every path computes the same compiled batch, so the results agree to round-off whichever runs
(``tests/beam/test_worker_cores.py``).  Where numba, the atomics, ``usleep`` or
``clock_gettime`` are not available (``AVAILABLE`` False) the model keeps the thread pool
(``Model.element_spin``).  ``tests/beam/test_element_worker.py`` checks the results against
the direct batch call (to round-off) on every hand-over path: consecutive requests, a request
not collected or a result not read before the next one (still one worker thread), exit after
idling and restart, a forked child, the elements published one by one, and the model's
right-hand side with and without the worker.
"""

from __future__ import annotations

import ctypes
import math
import os
import platform
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from sim_core._numba import numba
from sim_core.errors import ElementEvaluationError
from sim_core.physics import _effects_numba as element_compiled
from sim_core.physics.beam import _cardan_numba as cardan_compiled
from sim_core.physics.complex_step import COMPLEX_STEP

IDLE, REQUEST, DONE, EXITED, ERROR, STOP = 0, 1, 2, 3, 4, 5
PROGRESS = 4            # ctl word: elements of the current request written so far
T_POST, T_START, T_END = 5, 6, 7    # ctl words: CLOCK_MONOTONIC ns of the post, start, end
_CLOCK_CALLER, _CLOCK_WORKER = 8, 10    # ctl words 8-9, 10-11: each thread's struct timespec
YIELD_NS = 12           # ctl word: ns after a request's end that a core-sharing worker yields
CTL_WORDS = 13
SPIN_S = 5e-3           # seconds of spinning after a request before sleeping
WAIT_SPINS = 1 << 16    # the caller's spinning rounds between yields (~0.5 ms), own core
SLEEP_US = 200          # microseconds per sleeping poll
POLLS = 5000            # sleeping polls before the worker exits (~1 s idle)

AVAILABLE = False
if cardan_compiled.AVAILABLE and element_compiled.AVAILABLE:
    try:
        import llvmlite.binding as _llb
        from llvmlite import ir as _ir
        from numba import types as _types
        from numba.core import cgutils as _cgutils
        from numba.extending import intrinsic as _intrinsic

        _X86 = platform.machine().lower() in ("x86_64", "amd64", "i686", "x86")

        def _pointer(context, builder, sig, args):
            ary = context.make_array(sig.args[0])(context, builder, args[0])
            return _cgutils.get_item_pointer(context, builder, sig.args[0], ary, [args[1]])

        @_intrinsic
        def _load_acquire(typingctx, arr, idx):
            def codegen(context, builder, sig, args):
                return builder.load_atomic(_pointer(context, builder, sig, args), "acquire", 8)
            return _types.int64(arr, idx), codegen

        @_intrinsic
        def _store_release(typingctx, arr, idx, val):
            def codegen(context, builder, sig, args):
                builder.store_atomic(args[2], _pointer(context, builder, sig, args), "release", 8)
                return context.get_dummy_value()
            return _types.void(arr, idx, val), codegen

        @_intrinsic
        def _compare_and_swap(typingctx, arr, idx, old, new):
            def codegen(context, builder, sig, args):
                res = builder.cmpxchg(_pointer(context, builder, sig, args), args[2], args[3],
                                      "acq_rel", "acquire")
                return builder.extract_value(res, 1)
            return _types.boolean(arr, idx, old, new), codegen

        @_intrinsic
        def _cpu_pause(typingctx):
            def codegen(context, builder, sig, args):
                if _X86:            # spin-wait hint; elsewhere the loop just re-reads
                    fn = _cgutils.get_or_insert_function(
                        builder.module, _ir.FunctionType(_ir.VoidType(), []),
                        "llvm.x86.sse2.pause")
                    builder.call(fn, [])
                return context.get_dummy_value()
            return _types.void(), codegen

        @_intrinsic
        def _address(typingctx, arr, idx):
            def codegen(context, builder, sig, args):
                return builder.bitcast(_pointer(context, builder, sig, args),
                                       _ir.IntType(8).as_pointer())
            return _types.voidptr(arr, idx), codegen

        _libc = ctypes.CDLL(None)
        _llb.add_symbol("sim_core_worker_usleep",
                        ctypes.cast(_libc.usleep, ctypes.c_void_p).value)
        _usleep = _types.ExternalFunction("sim_core_worker_usleep", _types.int32(_types.uint32))
        _llb.add_symbol("sim_core_worker_clock_gettime",
                        ctypes.cast(_libc.clock_gettime, ctypes.c_void_p).value)
        _clock_gettime = _types.ExternalFunction("sim_core_worker_clock_gettime",
                                                 _types.int32(_types.int32, _types.voidptr))
        _llb.add_symbol("sim_core_worker_sched_yield",
                        ctypes.cast(_libc.sched_yield, ctypes.c_void_p).value)
        _sched_yield = _types.ExternalFunction("sim_core_worker_sched_yield", _types.int32())
        _MONOTONIC = time.CLOCK_MONOTONIC
        if ctypes.sizeof(ctypes.c_long) != 8:       # struct timespec as two int64 words
            raise OSError("struct timespec is not two 64-bit words here")
        AVAILABLE = True
    except Exception:        # pragma: no cover - no numba intrinsics or no libc usleep
        AVAILABLE = False


def _now_ns(ctl, slot):
    """CLOCK_MONOTONIC in ns (ctl[slot], ctl[slot + 1]: this thread's struct timespec)."""
    _clock_gettime(_MONOTONIC, _address(ctl, slot))
    return ctl[slot] * 1000000000 + ctl[slot + 1]


def _loop(ctl, QE, QDE, Ms, Fs, par, n, t0, t1, t2, t3, t4, t5, t6, t7, bases, i_s1, rhoAs,
          Jrots, Ds, inertia, elasticity, cstep, no_acc):
    """The worker: serve REQUEST -> DONE (stamping its start and end, ctl[T_START], ctl[T_END])
    until told to STOP (-> EXITED) or idle for ctl[1] spins + ctl[2] polls of ctl[3] us, then
    IDLE -> EXITED and return.  With ctl[YIELD_NS] > 0 (a core shared with the caller) it
    yields its core (``sched_yield``) instead of spinning, for ctl[YIELD_NS] ns after each
    request's end, then polls.  par = (h, g_x, g_y, g_z)."""
    idle = 0
    spin = ctl[1]
    polls = ctl[2]
    yield_ns = ctl[YIELD_NS]
    while True:
        s = _load_acquire(ctl, 0)
        if s == STOP:
            _store_release(ctl, 0, EXITED)
            return
        if s == REQUEST:
            ctl[T_START] = _now_ns(ctl, _CLOCK_WORKER)
            grav = par[1:4].copy()
            gravity = grav[0] != 0.0 or grav[1] != 0.0 or grav[2] != 0.0
            for e in range(QE.shape[0]):    # element by element, each one published
                M, F = element_compiled._compiled_mass_force(
                    QE[e], QDE[e], n, t0, t1, t2, t3, t4, t5, t6, t7, bases[e], i_s1,
                    rhoAs[e], Jrots[e], Ds[e], par[0], grav, inertia, elasticity, gravity, True,
                    cstep, no_acc)
                Ms[e] = M
                Fs[e] = F
                _store_release(ctl, PROGRESS, e + 1)
            ctl[T_END] = _now_ns(ctl, _CLOCK_WORKER)
            _store_release(ctl, 0, DONE)
            idle = 0
        elif yield_ns > 0 and _now_ns(ctl, _CLOCK_WORKER) - ctl[T_END] < yield_ns:
            _sched_yield()
        elif idle < spin:
            idle += 1
            _cpu_pause()
        else:
            idle += 1
            _usleep(ctl[3])
            if idle >= spin + polls and _compare_and_swap(ctl, 0, IDLE, EXITED):
                return


def _pause_loop(ctl, n):
    """n rounds of the worker's idle spin (an acquire load of the state word and a spin-wait
    hint: what :func:`spin_iterations` times; the load keeps the loop where there is no
    ``pause`` to emit)."""
    s = 0
    for _ in range(n):
        s += _load_acquire(ctl, 0)
        _cpu_pause()
    return s


def _wait_progress(ctl, e, spins):
    """Spin until element e is written (True) or ``spins`` rounds have passed (False)."""
    for _ in range(spins):
        if _load_acquire(ctl, PROGRESS) > e:
            return True
        _cpu_pause()
    return False


def _wait(ctl, spins):
    """Spin until DONE or ERROR (returned) or ``spins`` rounds (-1)."""
    for _ in range(spins):
        s = _load_acquire(ctl, 0)
        if s == DONE or s == ERROR:
            return s
        _cpu_pause()
    return -1


def _post(ctl):
    """IDLE -> REQUEST, stamped with the post's time (ctl[T_POST]); False where the state was
    not IDLE."""
    ctl[T_POST] = _now_ns(ctl, _CLOCK_CALLER)
    return _compare_and_swap(ctl, 0, IDLE, REQUEST)


def _stamp(ctl):
    """ctl[T_POST] = now (a request posted by a new thread's start, not by :func:`_post`)."""
    ctl[T_POST] = _now_ns(ctl, _CLOCK_CALLER)


def _stop(ctl):
    """IDLE -> STOP (the worker then exits); False where the state was not IDLE."""
    return _compare_and_swap(ctl, 0, IDLE, STOP)


def _set(ctl, state):
    _store_release(ctl, 0, state)


def _get(ctl):
    return _load_acquire(ctl, 0)


if AVAILABLE:
    _jit = numba.njit(cache=True, nogil=True)
    _loop = _jit(_loop)
    _wait = _jit(_wait)
    _wait_progress = _jit(_wait_progress)
    _post = _jit(_post)
    _stamp = _jit(_stamp)
    _stop = _jit(_stop)
    _now_ns = _jit(_now_ns)
    _set = _jit(_set)
    _get = _jit(_get)
    _pause_loop = _jit(_pause_loop)

_PAUSE_RATE: list[float] = []        # spin-wait hints per second on this machine (measured once)


def spin_iterations(seconds: float) -> int:
    """Idle-spin rounds of the worker that last about ``seconds``: the x86 ``pause`` takes ~10
    cycles on older cores and ~140 on newer ones (~25 on the test machine), so the worker's spin
    is set in time, from the rate measured once per process (the fastest of three ~2 ms
    rounds)."""
    if not _PAUSE_RATE:
        ctl = np.zeros(1, dtype=np.int64)
        _pause_loop(ctl, 10)                  # compiled / loaded before timing
        n, best = 1000, 0.0
        while n < (1 << 34):                  # ~2 ms per round
            t0 = time.perf_counter()
            _pause_loop(ctl, n)
            if time.perf_counter() - t0 > 2e-3:
                break
            n *= 4
        for _ in range(3):
            t0 = time.perf_counter()
            _pause_loop(ctl, n)
            best = max(best, n / max(time.perf_counter() - t0, 1e-9))
        _PAUSE_RATE.append(best)
    return max(int(seconds * _PAUSE_RATE[0]), 1)


class ElementWorker:
    """The mailbox and worker thread of one :class:`ElementBatch` (E elements of nq
    coordinates).  ``submit(QE, QDE, h, g, t)`` posts a batch and returns a function that waits
    for (Ms (E, nq, nq), Fs (E, nq)): the mailbox's arrays, valid until the next submit.  A
    failure of the worker's batch reaches the caller as
    :class:`sim_core.errors.ElementEvaluationError` at the request's time t."""

    def __init__(self, batch: "element_compiled.ElementBatch", E: int, nq: int,
                 spin: int | None = None, polls: int = POLLS, sleep_us: int = SLEEP_US):
        self.batch = batch
        self.ctl = np.zeros(CTL_WORDS, dtype=np.int64)
        self.ctl[0] = EXITED
        self.ctl[1:4] = spin_iterations(SPIN_S) if spin is None else spin, polls, sleep_us
        self._spin = int(self.ctl[1])
        self.shared_core = False          # the worker shares the caller's core (share_core)
        self.wait_spins = WAIT_SPINS      # the caller's spinning rounds between yields
        self.QE = np.zeros((E, nq))
        self.QDE = np.zeros((E, nq))
        self.Ms = np.zeros((E, nq, nq))
        self.Fs = np.zeros((E, nq))
        self.par = np.zeros(4)
        self.thread: threading.Thread | None = None
        self.pid = None
        self.error: BaseException | None = None
        self.t = math.nan                 # simulated time of the posted request, s
        self.starts = 0                   # worker threads started (tests)
        self.served = 0                   # requests collected
        self.fresh = False                # the posted request started a new thread
        # (post, start, end) in ns of the last collected request and whether it started a
        # thread (its start then includes the thread's start-up): read by the Governor
        self.timing: tuple[int, int, int, bool] | None = None

    def _start(self) -> None:
        b = self.batch
        args = (self.ctl, self.QE, self.QDE, self.Ms, self.Fs, self.par,
                *b.element_arguments(), b.inertia, b.elasticity, COMPLEX_STEP,
                element_compiled._NO_ACC)

        def run():
            try:
                _loop(*args)
            except BaseException as exc:  # noqa: BLE001 - handed to the caller
                self.error = exc
                _set(self.ctl, ERROR)

        self.pid = os.getpid()
        self.starts += 1
        self.thread = threading.Thread(target=run, daemon=True, name="sim_core-element-worker")
        self.thread.start()

    def _settle(self) -> None:
        """Leave the state IDLE or EXITED, so that a post either succeeds or (EXITED) starts
        the one worker: wait out a request whose result was not collected, drop a result that
        was not (DONE); a failed worker (ERROR: its loop has returned), a stopped one (STOP:
        joined) and a forked child (no worker thread of its own) are EXITED."""
        if self.pid != os.getpid() or self.thread is None:
            self.ctl[0] = EXITED
            return
        s = _get(self.ctl)
        if s == REQUEST:
            self.result()               # -> IDLE (or raises the worker's error)
        elif s == DONE:
            _set(self.ctl, IDLE)
        elif s == ERROR:
            self.error = None
            self.ctl[0] = EXITED
        elif s == STOP:
            self.thread.join()
            self.ctl[0] = EXITED

    def submit(self, QE, QDE, h: float, g, t: float = math.nan):
        self._settle()
        self.QE[...] = QE
        self.QDE[...] = QDE
        self.par[0] = h
        self.par[1:4] = g
        self.t = t
        self.ctl[PROGRESS] = 0              # published by the post's release below
        self.fresh = False
        if not _post(self.ctl):          # EXITED (IDLE otherwise, after _settle)
            _stamp(self.ctl)
            self.ctl[0] = REQUEST
            self.fresh = True
            self._start()
        return self.result

    def stop(self) -> None:
        """End the worker thread now (no spinning, no polling until it would exit by itself):
        an open request is collected first; the next :meth:`submit` starts a new thread."""
        if self.thread is None or self.pid != os.getpid():
            return
        self._settle()
        if _stop(self.ctl):
            self.thread.join()
        self._settle()

    def share_core(self, shared: bool) -> None:
        """Wait without spinning where the worker shares one core with the caller (a process
        restricted to one processor with the worker forced on): there a spinning thread only
        holds the core the other one needs until the scheduler preempts it (milliseconds per
        hand-over).  Shared: the idle worker yields its core (``sched_yield``) for ``SPIN_S``
        after each request, then polls; the caller checks once between yields.  Only the
        waiting changes: the same compiled batch computes the same numbers in the same order.
        A running worker thread is stopped first (it reads its waiting settings when it
        starts)."""
        shared = bool(shared)
        if shared == self.shared_core:
            return
        self.stop()
        self.shared_core = shared
        self.ctl[1] = 0 if shared else self._spin
        self.ctl[YIELD_NS] = int(SPIN_S * 1e9) if shared else 0
        self.wait_spins = 1 if shared else WAIT_SPINS

    def wait_element(self, e: int) -> None:
        """Wait until element e of the posted request is written (Ms[e], Fs[e]; the rest of
        the request may still run: :meth:`result` collects it).  Between spinning rounds
        (``wait_spins``: ~0.5 ms, one round on a shared core) the calling thread yields its
        core (a worker that shares it gets on)."""
        while not _wait_progress(self.ctl, e, self.wait_spins):
            self._check(_get(self.ctl))
            os.sched_yield()

    def result(self):
        """Wait for the posted request: (Ms, Fs), the mailbox's arrays (yielding the core
        between spinning rounds, as :meth:`wait_element`)."""
        while True:
            s = _wait(self.ctl, self.wait_spins)
            if s == DONE:             # the worker writes the mailbox only on a REQUEST,
                c = self.ctl
                self.timing = (int(c[T_POST]), int(c[T_START]), int(c[T_END]), self.fresh)
                self.served += 1
                _set(c, IDLE)             # so IDLE already: it may exit while idle
                return self.Ms, self.Fs
            self._check(s)
            os.sched_yield()

    def _check(self, s) -> None:
        """Between waiting rounds (``s``: the state word): raise the worker's error (ERROR) as
        an ElementEvaluationError at the request's time, or that its thread ended with the
        request open."""
        if s == ERROR:
            exc, self.error = self.error, None
            self.ctl[0] = EXITED
            raise ElementEvaluationError(
                self.t, f"element batch failed on the worker thread: "
                        f"{type(exc).__name__}: {exc}") from exc
        if not self.thread.is_alive() and _get(self.ctl) == REQUEST:
            self.ctl[0] = EXITED      # pragma: no cover - the thread died without ERROR
            raise ElementEvaluationError(self.t, "element worker thread ended without a result")


# -- when to use the worker ----------------------------------------------------------------------

MODE_ENV = "SIM_CORE_ELEMENT_WORKER"
_clock = time.monotonic         # the governor's wall clock, s (a module name: tests replace it)


def mode() -> str:
    """``SIM_CORE_ELEMENT_WORKER``: "auto" (default), "on" or "off" ("1"/"0", "true"/"false",
    "yes"/"no" also read as on/off; anything else is an error)."""
    raw = os.environ.get(MODE_ENV, "auto").strip().lower()
    if raw in ("", "auto"):
        return "auto"
    if raw in ("on", "1", "true", "yes"):
        return "on"
    if raw in ("off", "0", "false", "no"):
        return "off"
    raise ValueError(f"{MODE_ENV} = {raw!r}: allowed 'auto', 'on', 'off'")


def available_cores() -> int:
    """Processors this process may run on (its affinity set; the CPU count where the platform
    has no affinity call)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):    # pragma: no cover - no sched_getaffinity
        return os.cpu_count() or 1


BLAS_ENV = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
_BLAS_SET: list = []        # [(pid, {library: threads})]: done once per process


def _openblas_libraries() -> list[str]:
    """Paths of the OpenBLAS libraries mapped into this process (numpy's and scipy's wheels
    each bring one), from /proc/self/maps (empty where there is none)."""
    try:
        with open("/proc/self/maps") as f:
            return sorted({line.split()[-1] for line in f
                           if "openblas" in line.lower() and line.split()[-1].startswith("/")})
    except OSError:
        return []


def blas_threads_wanted() -> int:
    """The BLAS thread count asked for: ``OPENBLAS_NUM_THREADS``, else ``OMP_NUM_THREADS``,
    else 1 (:mod:`sim_core` sets both to 1 by default when it is imported before numpy)."""
    for var in BLAS_ENV[:2]:
        try:
            n = int(os.environ.get(var, "").strip())
        except ValueError:
            continue
        if n >= 1:
            return n
    return 1


def limit_blas_threads() -> dict:
    """Run every loaded OpenBLAS on :func:`blas_threads_wanted` threads (once per process).
    Returns {library file: thread count read back}.

    The environment variables only act when OpenBLAS starts, i.e. when numpy is first
    imported: a program that imports numpy before sim_core gets OpenBLAS's default, one
    thread per core.  OpenBLAS threads spin while they wait for work, so they too need cores of
    their own, and the model's matrices are small (the paper scene's Newton matrix: 313 x
    313): a second thread gains little on an idle machine and loses badly on a busy one --
    with other processes running, the LU of a 313 x 313 matrix took 9.6 ms on two OpenBLAS
    threads against 0.54 ms on one, and 4 s of the paper scene (its BDF stretches factor that
    matrix) 46 s of wall time against 7.7 s."""
    pid = os.getpid()
    if _BLAS_SET and _BLAS_SET[0][0] == pid:
        return _BLAS_SET[0][1]
    n = blas_threads_wanted()
    done: dict = {}
    for path in _openblas_libraries():
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for prefix in ("", "scipy_"):
            for suffix in ("", "64_"):
                setter = getattr(lib, f"{prefix}openblas_set_num_threads{suffix}", None)
                getter = getattr(lib, f"{prefix}openblas_get_num_threads{suffix}", None)
                if setter is None or getter is None:
                    continue
                if int(getter()) != n:
                    setter(ctypes.c_int(n))
                done[os.path.basename(path)] = int(getter())
    _BLAS_SET[:] = [(pid, done)]
    return done


class Governor:
    """Decides, request by request, whether a model's element batch goes to its worker thread
    (``use_worker``) or runs on the calling thread, from what the worker's requests took.

    ``allowed``: a thread may be used at all (mode "on", or "auto" with at least two cores in
    the affinity set).  ``forced``: mode "on" (no measurement, the worker always; with fewer
    than two cores it waits without spinning, :meth:`ElementWorker.share_core`).  Creating
    one also sets the process's OpenBLAS thread count to the one asked for (one unless the
    user set another: :func:`limit_blas_threads`).

    In "auto" the delay of a request is (end - post) - b, b the batch's uncontended compute
    time (the smallest end - start so far); the first request of a new thread is not counted
    (its start includes the thread's start-up).  Requests are judged in windows of ``window``:

    * worker in use: it is stopped (``worker.stop()``, the batches run on the calling thread)
      as soon as the window's summed delay exceeds ``window * tau_off`` (after at least
      ``min_requests`` of its requests, so that one late request does not decide),
      tau_off = max(``alpha_off`` b, ``floor_off_s``);
    * calling thread: after ``backoff`` s (wall) a probe window goes to the worker; it stays
      there if the whole window's summed delay is at most ``window * tau_on``, tau_on =
      max(``alpha_on`` b, ``floor_on_s``); otherwise back to the calling thread (the probe is
      cut short as above) and the next probe waits twice as long, up to ``max_backoff`` s.

    Why these numbers.  A worker on a core of its own starts within microseconds of the post
    (it spins on the state word) and computes at its uncontended pace: its delay is the
    hand-over (cache-line transfers, the odd interrupt) -- measured on the paper's model at 8
    sub-elements with the second core mostly free: 0.1-48 us, mean ~15 us, against b = 0.5
    ms.  A worker that shares its core with another runnable thread waits for scheduler
    slices (Linux CFS: 0.75-3 ms): with two threads of this process and one other process on
    two cores each thread runs about 2/3 of the time, and a request posted while the worker
    is off waits for the rest of a slice -- a mean delay of the order of a millisecond, of b
    or far more than b for small batches (the worker pinned to the caller's core: stopped
    within the first window, tests/beam/test_worker_cores.py).  alpha_off = 0.25 lies nearly
    an order of magnitude from either; it is also about where the worker stops paying: on the
    paper's model it saves 0.17 ms per right-hand side (0.99 against 1.16 ms on the calling
    thread, 0.34 b), which a mean delay of 0.25 b mostly eats, while the two spinning threads
    take two cores from the machine.  alpha_on = 0.10 (hysteresis) keeps a worker whose delays
    sit near alpha_off from being stopped and resumed over and over.  The floors (20 us,
    10 us) keep batches of a few microseconds (a 2-sub-element beam: 15-40 us) from being
    judged on timer and interrupt noise.  Probing: a failed probe is cut short after at most
    window * tau_off of summed delay plus one request's (4 ms + a slice on the paper's model),
    under 0.1 % of the run at the longest backoff (8 s); a freed core is found within 8 s."""

    window = 32
    min_requests = 8
    alpha_off, alpha_on = 0.25, 0.10
    floor_off_s, floor_on_s = 20e-6, 10e-6
    first_backoff, max_backoff = 0.25, 8.0

    def __init__(self, cores: int | None = None, how: str | None = None):
        self.mode = mode() if how is None else how
        self.cores = available_cores() if cores is None else int(cores)
        self.forced = self.mode == "on"
        self.allowed = self.forced or (self.mode == "auto" and self.cores >= 2)
        self.using = self.allowed        # the worker is in use (else the calling thread)
        self.b_ns = math.inf             # uncontended batch time, ns
        self.backoff = self.first_backoff
        self.next_probe = 0.0            # _clock() of the next probe
        self.probing = False
        self._reset_window()
        self._seen = (None, -1)          # (worker, served) last read
        self.stops = 0                   # worker -> calling thread
        self.resumes = 0                 # calling thread -> worker (after a probe)
        self.delays: list[float] = []    # the last window's delays, s (diagnostics)
        self.blas = limit_blas_threads()

    def _reset_window(self) -> None:
        self.n = 0
        self.sum_delay = 0.0
        self.delays = []

    def threads(self) -> bool:
        """A helper thread may be used now (the worker, or the thread pool of the Jacobian's
        element columns)."""
        return self.allowed and (self.using or self.forced)

    def use_worker(self, worker: ElementWorker) -> bool:
        """Read the worker's last collected request (if new) and say where the next batch
        goes: True the worker, False the calling thread (the worker is stopped first)."""
        if not self.allowed:
            return False
        if self.forced:
            if worker.shared_core != (self.cores < 2):
                worker.share_core(self.cores < 2)
            return True
        if self.using:
            self._observe(worker)
            if self.using:
                return True
            worker.stop()
            return False
        if _clock() >= self.next_probe:
            self.using, self.probing = True, True
            self._reset_window()
            self._seen = (worker, worker.served)     # delays from the probe's own requests
            return True
        return False

    def _observe(self, worker: ElementWorker) -> None:
        if self._seen[0] is worker and self._seen[1] == worker.served:
            return                                 # nothing collected since the last look
        self._seen = (worker, worker.served)
        if worker.timing is None:
            return
        post, start, end, fresh = worker.timing
        if fresh:
            return
        self.b_ns = min(self.b_ns, float(end - start))
        delay = max(float(end - post) - self.b_ns, 0.0) * 1e-9
        self.n += 1
        self.sum_delay += delay
        self.delays.append(delay)
        b = self.b_ns * 1e-9
        if self.n >= self.min_requests and \
                self.sum_delay > self.window * max(self.alpha_off * b, self.floor_off_s):
            self._fall_back()
        elif self.n >= self.window:
            if self.probing and self.sum_delay > self.window * max(self.alpha_on * b,
                                                                   self.floor_on_s):
                self._fall_back()
            else:
                if self.probing:
                    self.resumes += 1
                    self.backoff = self.first_backoff
                self.probing = False
                self._reset_window()

    def _fall_back(self) -> None:
        self.using = False
        self.stops += 1
        self.next_probe = _clock() + self.backoff
        if self.probing:
            self.backoff = min(2.0 * self.backoff, self.max_backoff)
        self.probing = False
        self._reset_window()

    def summary(self) -> dict:
        """State for the run's statistics: cores, mode, whether the worker is in use, its
        stops and resumes, the uncontended batch time (s)."""
        return {"cores_available": self.cores, "element_worker_mode": self.mode,
                "worker_in_use": self.threads(), "worker_stops": self.stops,
                "worker_resumes": self.resumes,
                "element_batch_s": (self.b_ns * 1e-9 if math.isfinite(self.b_ns) else None),
                "blas_threads": (max(self.blas.values()) if self.blas else None)}


# -- the thread pool of the element batches ---------------------------------------------------

_POOL: list = []          # [(pid, ThreadPoolExecutor)]


def thread_pool() -> ThreadPoolExecutor:
    """One worker thread per process for the element batches (a forked child gets its own: the
    parent's thread does not exist there)."""
    if not _POOL or _POOL[0][0] != os.getpid():
        _POOL[:] = [(os.getpid(), ThreadPoolExecutor(1, thread_name_prefix="sim_core-elements"))]
    return _POOL[0][1]


class SharedElements:
    """Elements 0..E-1 handed out one at a time to whichever thread asks next (``run``: take
    and compute until none is left), so that the worker and the calling thread share a batch
    whatever the calling thread's own work took."""

    def __init__(self, E: int, work):
        self.E, self.work = E, work
        self._next = 0
        self._lock = threading.Lock()

    def _take(self) -> int:
        with self._lock:
            e = self._next
            self._next += 1
        return e

    def run(self) -> None:
        e = self._take()
        while e < self.E:
            self.work(e)
            e = self._take()

    def stop(self) -> None:
        """No further element is handed out (the one being computed finishes)."""
        with self._lock:
            self._next = self.E


class WorkerBatch:
    """The element batch posted to the persistent worker (:class:`element_worker.
    ElementWorker`): call it to wait for (Ms, Fs) (finite-checked, as :func:`checked_batch`), or
    hand ``worker`` to :func:`saddle_point_compiled.kkt_factor_pipelined`."""

    def __init__(self, worker):
        self.worker = worker

    def __call__(self):
        return checked_batch(self.worker.result())


def evaluation_error(exc: BaseException, t: float) -> ElementEvaluationError:
    return ElementEvaluationError(t, f"element batch failed: {type(exc).__name__}: {exc}")


def run_inline(job, t: float):
    """job() (an element batch) at once on the calling thread; a function that returns its
    result finite-checked (as :func:`checked_batch`).  A division by zero or an overflow in the
    compiled kernel is an :class:`ElementEvaluationError` at time t, as where the batch runs on
    the worker."""
    try:
        out = job()
    except (ZeroDivisionError, OverflowError) as exc:
        raise evaluation_error(exc, t) from exc
    return lambda: checked_batch(out)


def checked_batch(out):
    """The element batch's result (a pair of arrays) after numpy's finite check of the calling
    thread (np.errstate is per thread: a non-finite block raises FloatingPointError where the
    caller's numpy would)."""
    a, b = out
    cardan_compiled.check_finite(a.sum() + b.sum(), "element mass matrix or forces")
    return a, b
