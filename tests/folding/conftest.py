"""Shared coarse settings of the folding tests (runtimes stated per test)."""

import numpy as np
import pytest

from sim_core.systems.folding.build import FoldingParams, build_folding


@pytest.fixture(scope="module")
def coarse_system():
    """Coarse folding system (4 sub-elements per boom) in a deformed, moving state."""
    fs = build_folding(FoldingParams(n_nodes=5))
    rng = np.random.default_rng(7)
    Q = fs.Q0 + 1e-3 * rng.standard_normal(fs.Q0.shape)
    m = fs.model
    # keep the fixed material ends exact (the Jacobians are at fixed s)
    for b, off in zip(m.beams, m.offsets):
        Q[off + b.s_coord(0)] = 0.0
        Q[off + b.s_coord(len(b.elements))] = b.length
    Q[fs.i_phi] = -0.4
    Qd = rng.standard_normal(Q.shape)
    return fs, Q, Qd
