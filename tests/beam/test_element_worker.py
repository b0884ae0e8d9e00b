"""The persistent element worker (sim_core/model/workers.py) returns exactly the batch.

The worker runs the same compiled batch as a direct call, on another thread, with its inputs and
outputs in a mailbox handed over by one atomic state word.  So its result must equal the direct
call to round-off (1e-12 of the largest entry; the same call twice differs by ~2e-16 where BLAS
sums in another order on differently aligned arrays), for every hand-over path: consecutive
requests (the mailbox is reused), a request whose result was never collected before the next
one or a result never read (one worker thread serves both), a worker that exited after idling
and is started again, a forked child (the parent's thread does not exist there), and the model's
right-hand side with and without it.  A stale or half-written result (the previous state's
matrices, a missing acquire/release) differs from the direct call by orders of magnitude more
(the states differ by 1e-3 m, 0.1 m/s).
"""

import multiprocessing
import time

import numpy as np
import pytest

from sim_core import load_scene
from sim_core.model import workers as element_worker
from sim_core.systems.telescopic.build import build_telescopic
from sim_core.systems.telescopic.schema import params_from_scene

pytestmark = pytest.mark.skipif(not element_worker.AVAILABLE,
                                reason="numba atomics or libc usleep not available")


@pytest.fixture(scope="module")
def paper():
    """The paper's extraction model, its element batch and three moving states."""
    ts = build_telescopic(params_from_scene(load_scene("telescopic_extraction")))
    m = ts.model
    rng = np.random.default_rng(7)
    states = []
    for k in range(3):
        Q = ts.Q0 + 1e-3 * rng.standard_normal(ts.Q0.shape)
        Qd = 0.1 * rng.standard_normal(ts.Q0.shape)
        states.append((Q, Qd))
    batch, kw = m._element_batch_plan(*states[0])
    ix = m._element_idx
    inputs = [(np.ascontiguousarray(Q[ix]), np.ascontiguousarray(Qd[ix])) for Q, Qd in states]
    z0, _ = m.reduced_state(0.0, ts.Q0, np.zeros_like(ts.Q0))
    # the direct batch compiled (or loaded) before any worker starts: on a fresh install its
    # first call takes seconds, longer than a worker idles before it exits, and a test that
    # counts one worker thread would then see a second one
    _direct(batch, kw, *inputs[0])
    return m, batch, kw, inputs, z0


def _direct(batch, kw, QE, QDE):
    return batch(QE, QDE, kw["h"], kw["g"])


def _same(a, b, rel=1e-12):
    """Equal up to round-off: BLAS (the Gram product) may sum in another order on differently
    aligned arrays (two calls of the same path differ by ~2e-16 relative)."""
    return all(np.max(np.abs(x - y)) <= rel * np.max(np.abs(y)) for x, y in zip(a, b))


def test_consecutive_requests_equal_the_direct_batch(paper):
    _, batch, kw, inputs, _ = paper
    w = element_worker.ElementWorker(batch, *inputs[0][0].shape)
    for QE, QDE in inputs + inputs[::-1]:
        Ms, Fs = w.submit(QE, QDE, kw["h"], kw["g"])()
        assert _same((Ms, Fs), _direct(batch, kw, QE, QDE))
    assert w.starts == 1                 # one thread served them all


def test_uncollected_result_then_next_request(paper):
    _, batch, kw, inputs, _ = paper
    w = element_worker.ElementWorker(batch, *inputs[0][0].shape)
    w.submit(*inputs[0], kw["h"], kw["g"])          # result never collected
    Ms, Fs = w.submit(*inputs[1], kw["h"], kw["g"])()
    assert _same((Ms, Fs), _direct(batch, kw, *inputs[1]))
    assert w.starts == 1


def test_result_left_unread_then_next_request(paper):
    """The worker has finished (DONE) and nobody read it: the next request goes to the same
    worker (a second thread on the same mailbox would race it)."""
    _, batch, kw, inputs, _ = paper
    w = element_worker.ElementWorker(batch, *inputs[0][0].shape)
    w.submit(*inputs[0], kw["h"], kw["g"])
    deadline = time.monotonic() + 10.0
    while w.ctl[0] != element_worker.DONE and time.monotonic() < deadline:
        time.sleep(0.001)
    assert w.ctl[0] == element_worker.DONE
    Ms, Fs = w.submit(*inputs[1], kw["h"], kw["g"])()
    assert _same((Ms, Fs), _direct(batch, kw, *inputs[1]))
    assert w.starts == 1 and w.thread.is_alive()


def test_worker_exits_when_idle_and_is_restarted(paper):
    _, batch, kw, inputs, _ = paper
    w = element_worker.ElementWorker(batch, *inputs[0][0].shape, spin=10, polls=5, sleep_us=100)
    w.submit(*inputs[0], kw["h"], kw["g"])()
    deadline = time.monotonic() + 10.0
    while w.ctl[0] != element_worker.EXITED and time.monotonic() < deadline:
        time.sleep(0.01)
    assert w.ctl[0] == element_worker.EXITED
    w.thread.join(5.0)
    assert not w.thread.is_alive()
    Ms, Fs = w.submit(*inputs[2], kw["h"], kw["g"])()
    assert _same((Ms, Fs), _direct(batch, kw, *inputs[2]))
    assert w.starts == 2


def _child(w, batch, kw, QE, QDE, queue):
    Ms, Fs = w.submit(QE, QDE, kw["h"], kw["g"])()
    queue.put(_same((Ms, Fs), _direct(batch, kw, QE, QDE)) and w.starts == 2)


def test_forked_child_starts_its_own_worker(paper):
    _, batch, kw, inputs, _ = paper
    w = element_worker.ElementWorker(batch, *inputs[0][0].shape)
    w.submit(*inputs[0], kw["h"], kw["g"])()         # the parent's worker is running (IDLE)
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    p = ctx.Process(target=_child, args=(w, batch, kw, *inputs[1], queue))
    p.start()
    ok = queue.get(timeout=60)
    p.join(60)
    assert ok and p.exitcode == 0
    Ms, Fs = w.submit(*inputs[2], kw["h"], kw["g"])()   # the parent's still serves it
    assert _same((Ms, Fs), _direct(batch, kw, *inputs[2]))


def test_model_rhs_with_and_without_the_worker(paper):
    m, _, _, _, z0 = paper
    rng = np.random.default_rng(3)
    ys = [np.concatenate([z0 + 1e-4 * rng.standard_normal(m.n_dof),
                          1e-2 * rng.standard_normal(m.n_dof)]) for _ in range(3)]
    out = {}
    try:
        for spin in (True, False):
            m.element_spin = spin
            out[spin] = []
            for y in ys:            # the same friction-Newton start (its warm start is state)
                m.__dict__.pop("_g_warm", None)
                out[spin].append(m.rhs(0.5, y))
    finally:
        m.element_spin = True
    assert m.__dict__.get("_spin_worker") is not None        # the worker path was taken
    for a, b in zip(out[True], out[False]):
        assert np.all(np.isfinite(a)) and _same([a], [b])


def test_elements_are_published_one_by_one(paper):
    """The worker publishes each element as it is written (its progress word, read by the
    pipelined factorisation): after wait_element(e) element e is the direct batch's, before
    the whole request is collected."""
    _, batch, kw, inputs, _ = paper
    w = element_worker.ElementWorker(batch, *inputs[0][0].shape)
    ref = _direct(batch, kw, *inputs[1])
    w.submit(*inputs[0], kw["h"], kw["g"])()
    w.submit(*inputs[1], kw["h"], kw["g"])
    for e in range(inputs[1][0].shape[0]):
        w.wait_element(e)
        assert _same((w.Ms[e], w.Fs[e]), (ref[0][e], ref[1][e]))
    Ms, Fs = w.result()
    assert _same((Ms, Fs), ref) and w.starts == 1
