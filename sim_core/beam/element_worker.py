"""A persistent compiled worker thread for the element batch of the right-hand side.

``Model`` hands the element batch (:class:`sim_core.beam.element_compiled.ElementBatch`) to a
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
  starts one), ERROR (the worker raised; the caller re-raises).
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
  ones are computed (:func:`sim_core.saddle_point_compiled.kkt_factor_pipelined` factors each
  element's block of the saddle-point matrix meanwhile).
* The caller waits for DONE spinning in compiled code too (without the GIL), checking that
  the worker thread is alive between rounds.

A forked child gets its own worker (the parent's thread does not exist there: the process id
is checked at every post).  Where numba, the atomics or ``usleep`` are not available
(``AVAILABLE`` False) the model keeps the thread pool (``Model.element_spin``).
``tests/beam/test_element_worker.py`` checks the results against the direct batch call (to
round-off) on every hand-over path: consecutive requests, a request not collected or a result
not read before the next one (still one worker thread), exit after idling and restart, a forked
child, the elements published one by one, and the model's right-hand side with and without the
worker.
"""

from __future__ import annotations

import ctypes
import os
import platform
import threading
import time

import numpy as np

from . import cardan_compiled, element_compiled

IDLE, REQUEST, DONE, EXITED, ERROR = 0, 1, 2, 3, 4
PROGRESS = 4            # ctl word: elements of the current request written so far
SPIN_S = 5e-3           # seconds of spinning after a request before sleeping
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

        _libc = ctypes.CDLL(None)
        _llb.add_symbol("sim_core_worker_usleep",
                        ctypes.cast(_libc.usleep, ctypes.c_void_p).value)
        _usleep = _types.ExternalFunction("sim_core_worker_usleep", _types.int32(_types.uint32))
        AVAILABLE = True
    except Exception:        # pragma: no cover - no numba intrinsics or no libc usleep
        AVAILABLE = False


def _loop(ctl, QE, QDE, Ms, Fs, par, n, t0, t1, t2, t3, t4, t5, t6, t7, bases, i_s1, rhoAs,
          Jrots, Ds, inertia, elasticity, cstep, no_acc):
    """The worker: serve REQUEST -> DONE until idle for ctl[1] spins + ctl[2] polls of ctl[3]
    us, then IDLE -> EXITED and return.  par = (h, g_x, g_y, g_z)."""
    idle = 0
    spin = ctl[1]
    polls = ctl[2]
    while True:
        if _load_acquire(ctl, 0) == REQUEST:
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
            _store_release(ctl, 0, DONE)
            idle = 0
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
    """IDLE -> REQUEST; False where the state was not IDLE."""
    return _compare_and_swap(ctl, 0, IDLE, REQUEST)


def _set(ctl, state):
    _store_release(ctl, 0, state)


def _get(ctl):
    return _load_acquire(ctl, 0)


if AVAILABLE:
    _jit = cardan_compiled.numba.njit(cache=True, nogil=True)
    _loop = _jit(_loop)
    _wait = _jit(_wait)
    _wait_progress = _jit(_wait_progress)
    _post = _jit(_post)
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
    coordinates).  ``submit(QE, QDE, h, g)`` posts a batch and returns a function that waits for
    (Ms (E, nq, nq), Fs (E, nq)): the mailbox's arrays, valid until the next submit."""

    def __init__(self, batch: "element_compiled.ElementBatch", E: int, nq: int,
                 spin: int | None = None, polls: int = POLLS, sleep_us: int = SLEEP_US):
        self.batch = batch
        self.ctl = np.zeros(8, dtype=np.int64)
        self.ctl[0] = EXITED
        self.ctl[1:4] = spin_iterations(SPIN_S) if spin is None else spin, polls, sleep_us
        self.QE = np.zeros((E, nq))
        self.QDE = np.zeros((E, nq))
        self.Ms = np.zeros((E, nq, nq))
        self.Fs = np.zeros((E, nq))
        self.par = np.zeros(4)
        self.thread: threading.Thread | None = None
        self.pid = None
        self.error: BaseException | None = None
        self.starts = 0                   # worker threads started (tests)

    def _start(self) -> None:
        b = self.batch
        args = (self.ctl, self.QE, self.QDE, self.Ms, self.Fs, self.par,
                *b.element_arguments(), b.inertia, b.elasticity, element_compiled._CSTEP,
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
        was not (DONE), a failed worker (ERROR: its loop has returned) and a forked child (no
        worker thread of its own) are EXITED."""
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

    def submit(self, QE, QDE, h: float, g):
        self._settle()
        self.QE[...] = QE
        self.QDE[...] = QDE
        self.par[0] = h
        self.par[1:4] = g
        self.ctl[PROGRESS] = 0              # published by the post's release below
        if not _post(self.ctl):          # EXITED (IDLE otherwise, after _settle)
            self.ctl[0] = REQUEST
            self._start()
        return self.result

    def wait_element(self, e: int) -> None:
        """Wait until element e of the posted request is written (Ms[e], Fs[e]; the rest of
        the request may still run: :meth:`result` collects it)."""
        while not _wait_progress(self.ctl, e, 1 << 16):
            self._check(_get(self.ctl))

    def result(self):
        """Wait for the posted request: (Ms, Fs), the mailbox's arrays."""
        while True:
            s = _wait(self.ctl, 1 << 16)
            if s == DONE:             # the worker writes the mailbox only on a REQUEST,
                _set(self.ctl, IDLE)      # so IDLE already: it may exit while idle
                return self.Ms, self.Fs
            self._check(s)

    def _check(self, s) -> None:
        """Between waiting rounds (``s``: the state word): raise the worker's error (ERROR),
        or that its thread ended with the request open."""
        if s == ERROR:
            exc, self.error = self.error, None
            self.ctl[0] = EXITED
            raise RuntimeError("element worker failed") from exc
        if not self.thread.is_alive() and _get(self.ctl) == REQUEST:
            self.ctl[0] = EXITED      # pragma: no cover - the thread died without ERROR
            raise RuntimeError("element worker thread ended without a result")
