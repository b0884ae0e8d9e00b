"""The compiled one-point kinematics equals SplineElement.evaluate at that point."""

import numpy as np
import pytest

from sim_core.model.boundary import reference_basis
from sim_core.physics.beam import _moving_node_beam_numba as point_compiled
from sim_core.physics.beam.moving_node_beam import Beam, BeamSection


def _bent_element(n_nodes=9):
    sec = BeamSection(EA=2e9, GJ=1e7, EI_t=3e7, EI_b=4e7, rhoA=80.0, J_s=0.3)
    b = Beam("b", 10.0, sec, (0.0, 4.0, 10.0), n_nodes=n_nodes,
             reference_basis=reference_basis([1, 0, 0.3]))
    q = b.straight_coordinates([0.5, -0.2, 1.0], [1.0, 0.1, 0.3])
    rng = np.random.default_rng(5)
    q = q + 1e-2 * rng.standard_normal(q.shape)           # bent, twisted, stretched
    el, idx = b.elements[1], b.index_map[1]
    return el, q[idx], 1e-1 * rng.standard_normal(len(idx))


@pytest.mark.skipif(not point_compiled.AVAILABLE, reason="numba not installed")
@pytest.mark.parametrize("complex_step", [False, True])
@pytest.mark.parametrize("where", [0.0, 0.37, 0.999])
def test_point_kinematics_equals_evaluate(complex_step, where):
    """r, r', J_r, J_psi, the Cardan angles, psi', the frame and T at a material point (real,
    and complex-step in the coordinates and in s as the constraint rows use it): equal to
    round-off.  Tolerance 1e-12 of each quantity's scale; psi' (curvatures of a nearly straight
    element, a small difference of r'' terms of size |P|/l^2) gets 1e-10 per m."""
    el, qe, qde = _bent_element()
    s = (1 - where) * qe[el.i_s1] + where * qe[el.i_sn]
    if complex_step:
        qe, s = qe + 1e-20j * qde, s + 1e-20j * 0.4
    got = point_compiled.point_kinematics(el, qe, s)
    kin = el.evaluate(qe, s=np.array([s]), strains=False)
    sec = kin.sec
    ref = (kin.r[0], kin.rp[0], kin.J_r[0], kin.J_psi[0], sec.angles[0], sec.psi_prime[0],
           sec.frame[0], sec.tmat[0])
    names = ("r", "rp", "J_r", "J_psi", "angles", "psi_prime", "frame", "tmat")
    for name, a, b in zip(names, got, ref):
        assert a.dtype == b.dtype, name
        for part in (np.real, np.imag) if complex_step else (np.real,):
            scale = max(np.abs(part(b)).max(), 1.0 if part is np.real else 1e-20)
            tol = (1e-10 if name == "psi_prime" else 1e-12) * scale
            np.testing.assert_allclose(part(a), part(b), rtol=0, atol=tol, err_msg=name)
        if complex_step and name in ("r", "J_r", "angles"):
            assert np.abs(np.imag(b)).max() > 0, name       # the perturbation is carried


@pytest.mark.skipif(not point_compiled.AVAILABLE, reason="numba not installed")
def test_compiled_kernels_follow_numpy_error_handling():
    """The compiled kernels compute silently; like numpy they raise FloatingPointError on a
    non-finite result where np.errstate says raise (the integrator's right-hand side: a blown-up
    stage is then rejected and retried, tests/scenes/test_partial_result.py), and otherwise let
    NaN propagate."""
    from sim_core.physics._effects_numba import element_mass_force

    el, qe, qde = _bent_element(5)
    bad = qe.copy()
    bad[0] = np.inf
    s = 0.5 * (qe[el.i_s1] + qe[el.i_sn])
    args = dict(rhoA=80.0, Jrot=np.array([0.3, 0.1, 0.1]), D=np.array([2e9, 1e7, 3e7, 4e7]),
                h=0.01, g=np.array([0.0, 0.0, -9.81]))
    with np.errstate(invalid="raise", over="raise"):
        with pytest.raises(FloatingPointError, match="point kinematics"):
            point_compiled.point_kinematics(el, bad, s)
        with pytest.raises(FloatingPointError, match="element mass matrix"):
            element_mass_force(el, bad, qde, **args)
    with np.errstate(invalid="ignore", over="ignore"):
        assert not np.all(np.isfinite(point_compiled.point_kinematics(el, bad, s)[2]))
        assert not np.all(np.isfinite(element_mass_force(el, bad, qde, **args)[1]))
