"""Jacobians and convective terms of the moving-node element against finite differences.

Every analytic derivative of sim_core.physics.beam (Cardan angles, strains, material Jacobians at fixed
s, the complex-step convective terms, the elastic force as energy gradient) is compared with
central differences; tolerances are set by the O(h^2) truncation + round-off of the differences.
"""

import numpy as np
import pytest

from sim_core.model.boundary import reference_basis
from sim_core.model.model import Model
from sim_core.physics.beam.cardan import section_state
from sim_core.physics.beam.moving_node_beam import Beam, SplineElement
from sim_core.physics.complex_step import COMPLEX_STEP as _CSTEP
from sim_core.physics.effects import Elasticity, Inertia
from tests.beam.conftest import L, section


def _curved_element_coords(el: SplineElement, rng, s1=0.4, sn=7.3):
    """A smoothly curved, twisted, slightly stretched configuration (not a special case)."""
    q = el.straight_coordinates([0.1, -0.2, 0.3], [1.0, 0.2, 0.1], s1, sn)
    q[:3 * (el.n + 4)] += 0.05 * rng.normal(size=3 * (el.n + 4))
    q[el.tor_slice] = 0.1 * rng.normal(size=2 * el.n)
    return q


def _fd_jac(f, x, h):
    cols = []
    for j in range(len(x)):
        dx = np.zeros_like(x)
        dx[j] = h
        cols.append((f(x + dx) - f(x - dx)) / (2 * h))
    return np.stack(cols, axis=-1)


def test_section_strain_jacobian(rng):
    G = reference_basis([1.0, 0.3, -0.2])
    x = np.concatenate([[1.02, 0.25, -0.18], 0.3 * rng.normal(size=3), [0.2, 0.05]])

    def eps(xv):
        st = section_state(xv[None, 0:3], xv[None, 3:6], xv[None, 6], xv[None, 7], G)
        return st.eps[0]

    st = section_state(x[None, 0:3], x[None, 3:6], x[None, 6], x[None, 7], G)
    np.testing.assert_allclose(st.deps_dx[0], _fd_jac(eps, x, 1e-6), rtol=1e-7, atol=1e-8)


def test_curvature_matches_frame_derivative(rng):
    """Eq. 33 curvatures satisfy e_s' = kappa x e_s on a spline element (frame by Eq. 24)."""
    el = SplineElement(9, 5, section(), reference_basis([1, 0, 0]))
    q = _curved_element_coords(el, rng)
    s0 = np.array([3.0])
    h = 1e-5
    k = el.evaluate(q, s=s0)
    kp = el.evaluate(q, s=s0 + h)
    km = el.evaluate(q, s=s0 - h)
    dframe = (kp.sec.frame[0] - km.sec.frame[0]) / (2 * h)       # rows e_t', e_b', e_s'
    et, eb, es = k.sec.frame[0]
    ks, kt, kb = k.sec.eps[0, 1:]
    kappa = ks * es + kt * et + kb * eb
    for i in range(3):
        np.testing.assert_allclose(dframe[i], np.cross(kappa, k.sec.frame[0][i]), atol=1e-6)


@pytest.mark.parametrize("which", ["J_r", "J_w", "B_xi", "B_s"])
def test_element_jacobians_at_fixed_s(which, rng):
    el = SplineElement(6, 4, section(), reference_basis([1, 0, 0]))
    q = _curved_element_coords(el, rng)
    k0 = el.evaluate(q, material_strain=True)
    s, sub = k0.s, k0.sub
    qd = rng.normal(size=el.n_coords)

    if which == "J_r":
        f = lambda qq: el.evaluate(qq, s=s, sub=sub).r                        # noqa: E731
    elif which in ("B_xi",):
        xi = el.q_xi

        def f(qq):  # strain at fixed xi
            ell = (qq[el.i_sn] - qq[el.i_s1]) / (el.n - 1)
            return el.evaluate(qq, s=qq[el.i_s1] + (sub + xi) * ell, sub=sub).sec.eps
    elif which == "B_s":
        f = lambda qq: el.evaluate(qq, s=s, sub=sub).sec.eps                  # noqa: E731
    if which == "J_w":
        # angular velocity = T(Psi) d(Psi)/dt|_s: compare J_w qd with T * FD of the angles
        h = 1e-6
        ang = lambda qq: el.evaluate(qq, s=s, sub=sub).sec.angles             # noqa: E731
        dpsi = (ang(q + h * qd) - ang(q - h * qd)) / (2 * h)
        expected = np.einsum("gij,gj->gi", k0.sec.tmat, dpsi)
        got = np.einsum("gin,n->gi", k0.J_w, qd)
        np.testing.assert_allclose(got, expected, rtol=1e-6, atol=1e-7 * np.max(np.abs(expected)))
        return
    h = 1e-6
    expected = (f(q + h * qd) - f(q - h * qd)) / (2 * h)
    J = getattr(k0, which)
    got = np.einsum("gin,n->gi", J, qd)
    np.testing.assert_allclose(got, expected, rtol=1e-6, atol=1e-7 * np.max(np.abs(expected)))


def test_complex_step_convective_terms_match_finite_differences(rng):
    """(J)^. q_dot at fixed s by complex step == central differences of J(q + t q_dot) q_dot."""
    el = SplineElement(6, 4, section(), reference_basis([1, 0, 0]))
    q = _curved_element_coords(el, rng)
    qd = rng.normal(size=el.n_coords)
    k0 = el.evaluate(q, material_strain=True)
    kc = el.evaluate(q + 1j * _CSTEP * qd, s=k0.s, sub=k0.sub, material_strain=True)
    h = 1e-6
    kp = el.evaluate(q + h * qd, s=k0.s, sub=k0.sub, material_strain=True)
    km = el.evaluate(q - h * qd, s=k0.s, sub=k0.sub, material_strain=True)
    for name in ("J_r", "J_w", "B_s"):
        cs = np.einsum("gin,n->gi", getattr(kc, name), qd).imag / _CSTEP
        fd = (np.einsum("gin,n->gi", getattr(kp, name), qd)
              - np.einsum("gin,n->gi", getattr(km, name), qd)) / (2 * h)
        np.testing.assert_allclose(cs, fd, rtol=1e-5, atol=1e-6 * np.max(np.abs(fd)))


def _two_element_model(rng, n_gauss=5):
    """Closed material domain [0, L] split at a moving junction (the outer-contact node).

    The quadrature points sit at fixed xi, so with a sliding junction they move through the
    material; the continuous identities checked below then hold for the discrete sums only up
    to quadrature error (about 2e-4 relative with the default 5 points on this coarse, strongly
    distorted configuration).  10 points make that error negligible, isolating the derivatives.
    """
    b = Beam("b", L, section(rotary_bending=True), (0.0, 4.0, L), n_nodes=5, n_gauss=n_gauss,
             reference_basis=reference_basis([1, 0, 0]))
    m = Model([b], [Inertia(), Elasticity()])
    Q = b.straight_coordinates([0, 0, 0], [1, 0, 0])
    Q = Q + 0.03 * rng.normal(size=Q.size)
    Q[b.s_coord(0)], Q[b.s_coord(1)], Q[b.s_coord(2)] = 0.0, 4.3, L
    return m, b, Q


def test_elastic_force_is_minus_energy_gradient(rng):
    m, b, Q = _two_element_model(rng)
    F = m.mass_force(0.0, Q, np.zeros_like(Q), mass=False)[1]
    U = lambda x: m.energies(0.0, x, np.zeros_like(x))["U"]                   # noqa: E731
    dir_ = rng.normal(size=Q.size)
    dir_[b.s_coord(0)] = dir_[b.s_coord(2)] = 0.0
    h = 1e-6
    dU = (U(Q + h * dir_) - U(Q - h * dir_)) / (2 * h)
    assert F @ dir_ == pytest.approx(-dU, rel=1e-6)


def test_energy_form_equals_material_virtual_power_in_closed_domain(rng):
    """Sum over elements of int B_s^T sigma ds (Eq. 34) == energy gradient when the boundary
    fluxes cancel at the shared moving node and vanish at the fixed material ends."""
    m, b, Q = _two_element_model(rng, n_gauss=10)
    F_energy = m.mass_force(0.0, Q, np.zeros_like(Q), mass=False)[1]
    F_mat = np.zeros_like(Q)
    for el, imap in zip(b.elements, b.index_map):
        k = el.evaluate(Q[imap], material_strain=True)
        wl = el.q_w * k.ell
        np.add.at(F_mat, imap, -np.einsum("g,gin,gi->n", wl, k.B_s, k.sec.eps * el.section.D))
    free = np.ones(Q.size, bool)
    free[[b.s_coord(0), b.s_coord(2)]] = False          # the fixed material ends
    np.testing.assert_allclose(F_mat[free], F_energy[free], rtol=1e-7,
                               atol=1e-8 * np.max(np.abs(F_energy)))


def test_inertia_equals_lagrange_equations_with_moving_node(rng):
    """For the closed domain, M q_ddot + convective == d/dt dT/dq_dot - dT/dq (finite differences
    of the kinetic energy of material velocities), with the junction node sliding."""
    m, b, Q = _two_element_model(rng, n_gauss=10)
    Qd = rng.normal(size=Q.size)
    Qd[b.s_coord(0)] = Qd[b.s_coord(2)] = 0.0     # material ends fixed, junction slides
    m_in = Model([b], [Inertia()])
    M, F = m_in.mass_force(0.0, Q, Qd)
    conv = -F                                      # F = -convective for Inertia alone
    T = lambda q, qd: m_in.energies(0.0, q, qd)["T"]                         # noqa: E731
    h = 1e-6
    Mdot_qd = (m_in.mass_force(0.0, Q + h * Qd, Qd)[0] - m_in.mass_force(0.0, Q - h * Qd, Qd)[0]) @ Qd / (2 * h)
    dTdq = np.array([(T(Q + h * e, Qd) - T(Q - h * e, Qd)) / (2 * h) for e in np.eye(Q.size)])
    lagr = Mdot_qd - dTdq
    free = np.ones(Q.size, bool)
    free[[b.s_coord(0), b.s_coord(2)]] = False
    np.testing.assert_allclose(conv[free], lagr[free], rtol=1e-5, atol=1e-6 * np.max(np.abs(lagr)))
    # and the mass matrix is the Hessian of T in the velocities: T = q_dot^T M q_dot / 2
    assert T(Q, Qd) == pytest.approx(0.5 * Qd @ M @ Qd, rel=1e-12)
