"""The compiled section-state loop equals the numpy reference (sim_core.physics.beam.cardan)."""

import numpy as np
import pytest

from sim_core.physics.beam import _cardan_numba as cardan_compiled
from sim_core.physics.beam.cardan import section_state, section_state_numpy

FIELDS = ("eps", "deps_dx", "angles", "dpsi_drp", "tmat", "frame", "psi_prime")


@pytest.mark.skipif(not cardan_compiled.AVAILABLE, reason="numba not installed")
@pytest.mark.parametrize("complex_step", [False, True])
def test_compiled_section_state_equals_numpy(complex_step):
    """Random r', r'', gamma, gamma' in a random reference basis, real and complex-step inputs
    (the convective terms): every output agrees to round-off (1e-13 relative; the two differ only
    in the order of the floating-point operations), the complex parts too."""
    rng = np.random.default_rng(4)
    G = 40
    basis = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    args = [rng.normal(size=(G, 3)), rng.normal(size=(G, 3)), rng.normal(size=G),
            rng.normal(size=G)]
    args[0][:, 0] += 3.0              # e_s away from g1, the singular direction of the sequence
    if complex_step:
        args = [a + 1e-20j * rng.normal(size=a.shape) for a in args]
    a, b = section_state(*args, basis), section_state_numpy(*args, basis)
    for f in FIELDS:
        x, y = getattr(a, f), getattr(b, f)
        assert x.dtype == y.dtype, f
        np.testing.assert_allclose(x.real, y.real, rtol=0, atol=1e-13 * np.abs(y.real).max())
        if complex_step:
            assert np.abs(y.imag).max() > 0, f
            np.testing.assert_allclose(x.imag, y.imag, rtol=0,
                                       atol=1e-13 * np.abs(y.imag).max())
