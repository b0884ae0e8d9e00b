"""The statics' structured tangent (central differences, ``statics.structured_force_tangent``)
from the compiled sweeps against the Python pieces.

The compiled element batch, payload-and-rope program and constraint program take forward
steps; the tangent's central differences are the mean of their sweeps with steps +h and -h,
(f(x + h) - f(x)) / h + (f(x - h) - f(x)) / (-h) = (f(x + h) - f(x - h)) / h, the same
difference quotient as the Python pieces' (f(x + h) - f(x - h)) / 2h.  Both read values equal to
round-off, so they agree to round-off / step: eps |F| / (1e-6 max(1, |x|)) ~ 1e-10 of a row's
scale (1e-7 allowed)."""

import numpy as np
import pytest

from sim_core.model import state_jacobian, statics
from sim_core.physics import _constraints_numba as constraint_compiled
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.params import TelescopicParams

pytestmark = pytest.mark.skipif(not constraint_compiled.AVAILABLE, reason="numba not installed")


@pytest.mark.parametrize("rope_elasticity", [True, False])
def test_central_tangent_from_compiled_sweeps_equals_the_python_pieces(monkeypatch,
                                                                       rope_elasticity):
    ts = build_telescopic(TelescopicParams(n_nodes=3, payload=1000.0,
                                           rope_elasticity=rope_elasticity))
    m = ts.model
    z, lam = initial_equilibrium(ts)
    rng = np.random.default_rng(5)
    z = z + 1e-4 * rng.standard_normal(m.n_dof)       # off the equilibrium: loads not balanced
    lam = lam * (1.0 + 0.1 * rng.standard_normal(len(lam)))
    got = statics.structured_force_tangent(m, 0.0, z, lam)

    monkeypatch.setattr(state_jacobian, "COMPILED_CONSTRAINT_COLUMNS", False)
    monkeypatch.setattr(m, "point_effects_compiled", False)
    monkeypatch.setattr(m, "_element_batch_plan", lambda Q, Qd: None)
    ref = statics.structured_force_tangent(m, 0.0, z, lam)

    scale = np.abs(ref).max(axis=1, keepdims=True)
    assert np.all(scale > 0.0)
    err = np.max(np.abs(got - ref) / scale)
    print(f"largest difference / row scale: {err:.2e}")
    assert err < 1e-7
