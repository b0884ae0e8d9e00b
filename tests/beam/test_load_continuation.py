"""Load continuation of the static equilibrium (sim_core.model.statics.load_continuation): on a
cantilever whose equilibrium Newton finds directly, the traced path ends on the same
equilibrium; the weights are restored after scaling."""

import numpy as np
import pytest

from sim_core.model.statics import (
    EquilibriumPath,
    constrained_static_equilibrium,
    gravity_scaled,
    load_continuation,
)

from .conftest import cantilever


def test_continuation_ends_on_the_newton_equilibrium():
    """Cantilever under 5 g (tip deflection ~2 m of 10 m, strongly nonlinear): the path traced
    from the unloaded state to the full weight ends where Newton from the straight beam lands.
    Both solve the same equations to a residual of tol = 1e-7 of the weight, so they may differ
    by ~1e-7 of the linear response z_ref (the compliance K^-1 maps the residual); bound 1e-5
    z_ref leaves two decades for the condition of the bent beam's tangent."""
    m, Q0 = cantilever(n_nodes=5, gravity=[0.0, 0.0, -5 * 9.81])
    z0, _ = m.reduced_state(0.0, Q0, np.zeros_like(Q0))
    z_newton, _ = constrained_static_equilibrium(m, z0, continuation=False)
    path = EquilibriumPath()
    z_path, _ = load_continuation(m, z0, path=path)
    assert path.load_factor[0] == 0.0 and path.load_factor[-1] == 1.0
    assert np.all(np.diff(path.load_factor) > 0)            # no limit point on this path
    z_ref = np.linalg.norm(z_newton - z0) / path.displacement[-1]
    assert np.linalg.norm(z_path - z_newton) < 1e-5 * z_ref
    # the deflection is large: the path is nonlinear (displacement / load factor departs from
    # the linear response 1 by more than the 1e-5 checked above)
    assert abs(path.displacement[-1] - 1.0) > 1e-3


def test_gravity_scaled_restores_the_weights():
    m, _ = cantilever(n_nodes=3, gravity=[0.0, 0.0, -9.81])
    g = m.effects[-1].g.copy()
    with pytest.raises(RuntimeError):
        with gravity_scaled(m, 0.25):
            assert np.allclose(m.effects[-1].g, 0.25 * g)
            raise RuntimeError
    assert np.array_equal(m.effects[-1].g, g)
