"""Test-session settings: single-threaded BLAS (the models are small; threading only adds
overhead and contention on the 2-core CI machine)."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")
# the element worker on whatever the load (its governor would otherwise switch it off on a busy
# machine mid-test, and tests that compare paths would compare different ones); the governor's
# own tests (tests/beam/test_worker_cores.py) set the mode they need
os.environ.setdefault("SIM_CORE_ELEMENT_WORKER", "on")

import numpy as np  # noqa: E402
import pytest  # noqa: E402


@pytest.fixture
def rng():
    """Seeded generator: tests are deterministic."""
    return np.random.default_rng(12345)
