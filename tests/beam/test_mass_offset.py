"""Mass-centre offset from the reference line (paper Table 2 z_c; docs/model.md#input-sections:
a rigid offset in inertia and gravity, stiffness on the reference line)."""

import math

import numpy as np
import pytest

from sim_core.model.boundary import boundary_condition, reference_basis
from sim_core.model.model import Model
from sim_core.model.statics import static_equilibrium
from sim_core.physics.beam.moving_node_beam import Beam, BeamSection
from sim_core.physics.effects import Elasticity, Gravity, Inertia

E, RHO, G_MOD = 2.1e11, 7850.0, 8.0e10
A, I = 1e-2, 1e-4


def _cantilever(y_c, z_c, effects, loads=(), length=4.0, n_nodes=3):
    sec = BeamSection(EA=E * A, GJ=G_MOD * 2 * I, EI_t=E * I, EI_b=E * I, rhoA=RHO * A,
                      J_s=RHO * 2 * I, J_t=RHO * I, J_b=RHO * I, y_c=y_c, z_c=z_c)
    b = Beam("b", length, sec, (0.0, length), n_nodes=n_nodes,
             reference_basis=reference_basis([1, 0, 0]))
    cons = [boundary_condition([0], [b], 0, "left", "clamped", [0, 0, 0], [1, 0, 0]),
            boundary_condition([0], [b], 0, "right", "free")]
    return Model([b], effects, list(loads), cons), b, sec


def test_offset_weight_twists_a_horizontal_cantilever():
    """A horizontal cantilever along X with its mass centre offset by y_c along e_t (lateral)
    under gravity -Z carries a distributed torque rhoA g y_c per length: the twist grows as
    phi(x) = rhoA g y_c (L x - x^2 / 2) / GJ, tip phi_L = rhoA g y_c L^2 / (2 GJ) (torsion of a
    cantilever under uniform torque).  Tolerance 2 %: the rotation is ~1e-4 rad (geometric
    non-linearity negligible); the cubic-spline twist field reproduces the quadratic exactly, the
    residual is the bending-torsion coupling of the sagging beam."""
    y_c, L = 0.2, 4.0
    g = np.array([0.0, 0.0, -9.81])
    model, b, sec = _cantilever(y_c, 0.0, [Elasticity(), Gravity(g)], length=L)
    Q0 = b.straight_coordinates([0, 0, 0], [1, 0, 0])
    z0, _ = model.reduced_state(0.0, Q0, np.zeros_like(Q0))
    z = static_equilibrium(model, z0)
    Q, _ = model.full_state(0.0, z, np.zeros_like(z))
    _, kin, _ = model.point(0, L, Q)
    frame = kin.sec.frame[0]                  # rows e_t, e_b, e_s
    phi = math.atan2(frame[0, 2], frame[0, 1])   # rotation of e_t about X (towards Z)
    ref = sec.rhoA * 9.81 * y_c * L * L / (2 * sec.GJ)
    assert abs(phi) == pytest.approx(ref, rel=0.02)
    # the offset is on +e_t: the weight pulls that side down (twist towards -Z)
    assert np.sign(phi) == -1.0


def _random_state(model, b, rng, amp=0.05):
    Q0 = b.straight_coordinates([0, 0, 0], [1, 0, 0])
    z0, _ = model.reduced_state(0.0, Q0, np.zeros_like(Q0))
    z = z0 + amp * rng.normal(size=z0.size)
    return model.full_state(0.0, z, rng.normal(size=z0.size))


@pytest.mark.parametrize("offset", [(0.0, 0.15), (0.1, 0.15)])
def test_offset_kinetic_energy_is_the_mass_matrix_form(offset, rng):
    """T = 1/2 Qd^T M Qd with the assembled (offset) mass matrix equals the kinetic energy of
    Model.energies, which forms the mass-centre velocity v + omega x d on its own code path."""
    model, b, _ = _cantilever(*offset, [Inertia()])
    Q, Qd = _random_state(model, b, rng)
    M, _ = model.mass_force(0.0, Q, Qd)
    T = model.energies(0.0, Q, Qd)["T"]
    assert 0.5 * Qd @ M @ Qd == pytest.approx(T, rel=1e-12)
    np.testing.assert_allclose(M, M.T, atol=1e-12 * np.abs(M).max())


@pytest.mark.parametrize("offset", [(0.0, 0.0), (0.0, 0.15), (0.1, 0.15)])
def test_offset_convective_forces_do_no_work(offset, rng):
    """Energy consistency of the inertia terms: with T = 1/2 Qd^T M(Q) Qd the power of the
    velocity-dependent inertia forces must be Qd . F = -1/2 Qd^T (dM/dt) Qd (then dT/dt equals
    the power of the applied forces: the beam conserves energy).  dM/dt = directional central
    difference of the assembled mass matrix along Qd (h = 1e-5: truncation ~h^2 ~ 1e-10
    relative).  Tolerance 1e-7.  The same check with the offset's omega x (omega x d) term
    dropped fails by orders of magnitude (shown below), so the test can fail."""
    import sim_core.physics.effects as eff
    model, b, _ = _cantilever(*offset, [Inertia()])
    Q, Qd = _random_state(model, b, rng)

    def mismatch():
        _, F = model.mass_force(0.0, Q, Qd)
        h = 1e-5
        Mp, _ = model.mass_force(0.0, Q + h * Qd, Qd, mass=True)
        Mm, _ = model.mass_force(0.0, Q - h * Qd, Qd, mass=True)
        rhs = -0.5 * Qd @ ((Mp - Mm) / (2 * h)) @ Qd
        return abs(Qd @ F - rhs) / abs(rhs)
    assert mismatch() < 1e-7
    if offset != (0.0, 0.0):
        original = eff._offset_convective
        try:
            eff._offset_convective = lambda frame, d, omega, w_dot: original(frame, d, 0 * omega, w_dot)
            assert mismatch() > 1e-4
        finally:
            eff._offset_convective = original
