"""Shared coarse settings of the folding tests (runtimes stated per test)."""

import numpy as np
import pytest

from sim_core.systems.folding.build import FoldingParams, build_folding


def moving_state(fs, seed: int):
    """(Q, Q_dot): the system's initial coordinates perturbed by 1 mm (the fixed material ends
    kept exact: the Jacobians are at fixed s), slewed to -0.4 rad, random rates."""
    rng = np.random.default_rng(seed)
    Q = fs.Q0 + 1e-3 * rng.standard_normal(fs.Q0.shape)
    m = fs.model
    for b, off in zip(m.beams, m.offsets):
        Q[off + b.s_coord(0)] = 0.0
        Q[off + b.s_coord(len(b.elements))] = b.length
    Q[fs.i_phi] = -0.4
    return Q, rng.standard_normal(Q.shape)


@pytest.fixture(scope="module")
def coarse_system():
    """Coarse folding system (4 sub-elements per boom) in a deformed, moving state."""
    fs = build_folding(FoldingParams(n_nodes=5))
    return (fs, *moving_state(fs, 7))
