"""Jacobians of the rigid-body terms and new constraints against complex step / finite
differences (sim_core.physics.rigid_body, sim_core.systems.folding.build.BoomRest).

Complex step (h = 1e-20) is exact to round-off, so analytic Jacobians must agree to ~1e-12
relative; the Lagrange-equation check of the quadratic velocity forces uses central differences
of M (truncation ~ eps^2 |M'''|, round-off ~ 1e-16 |M| / eps): with eps = 1e-5 the error bound
is ~1e-7 relative, we allow 1e-6.  Runtime ~5 s.
"""

import numpy as np
import pytest

from sim_core.physics.rigid_body import RigidBody, SpringDamperActuator
from sim_core.systems.folding.build import BoomRest

H = 1e-20


def cs_jac(fun, Q, n_out):
    """d fun / dQ by complex step, column by column."""
    J = np.zeros((n_out, len(Q)))
    for j in range(len(Q)):
        Qc = Q.astype(complex)
        Qc[j] += 1j * H
        J[:, j] = np.imag(fun(Qc)) / H
    return J


def skew_vec(S):
    return np.array([S[2, 1], S[0, 2], S[1, 0]])


FRAMES = ["A_turntable", "boom1_foot", "boom1_tip", "boom2_foot", "P1_boom", "C_boom", "G_boom",
          "barrel1", "rod2", "E_link_a", "G_link_b"]


@pytest.mark.parametrize("name", FRAMES)
def test_frame_jacobians(coarse_system, name):
    fs, Q, _ = coarse_system
    f = fs.frames[name]
    r, J, R, W = f(Q)
    Jcs = cs_jac(lambda q: f(q)[0], Q, 3)
    assert np.allclose(J, Jcs, rtol=0, atol=1e-11 * max(1.0, np.abs(Jcs).max()))
    # dR/dQ_j = [W_j]x R  ->  W_j = vec(dR/dQ_j R^T)
    Wcs = np.zeros_like(W)
    for j in np.flatnonzero(np.any(J != 0, axis=0) | np.any(W != 0, axis=0)):
        Qc = Q.astype(complex)
        Qc[j] += 1j * H
        dR = np.imag(f(Qc)[2]) / H
        Wcs[:, j] = skew_vec(dR @ R.T)
    assert np.allclose(W, Wcs, rtol=0, atol=1e-10)
    assert np.allclose(R.T @ R, np.eye(3), atol=1e-12)


def test_constraint_jacobians(coarse_system):
    fs, Q, _ = coarse_system
    for c in fs.model.nonlinear:
        g, J = c.evaluate(Q)
        Jcs = cs_jac(lambda q: c.evaluate(q)[0], Q, c.m)
        assert np.allclose(J, Jcs, rtol=0, atol=1e-10 * max(1.0, np.abs(Jcs).max())), c.name


def test_rest_gap_and_spring_gradients(coarse_system):
    fs, Q, _ = coarse_system
    rest = [pe for pe in fs.model.point_effects if isinstance(pe, BoomRest)][0]
    g, dg = rest.gap(Q)
    assert np.allclose(dg, cs_jac(lambda q: np.atleast_1d(rest.gap(q)[0]), Q, 1)[0], atol=1e-10)
    # spring without damper: F = -grad of 1/2 k (s - s_ref)^2
    cyl = [pe for pe in fs.model.point_effects if isinstance(pe, SpringDamperActuator)][0]
    sp = SpringDamperActuator(cyl.a, cyl.b, cyl.k, 0.0, cyl.s_ref0 - 0.01, None)
    F = np.zeros(len(Q))
    sp.add(0.0, Q, np.zeros_like(Q), None, F)
    V = lambda q: np.atleast_1d(0.5 * sp.k * (sp.length(q)[0] - sp.s_ref0) ** 2)
    assert np.allclose(F, -cs_jac(V, Q, 1)[0], rtol=1e-10, atol=1e-6)


@pytest.mark.parametrize("ibody", range(6))
def test_rigid_body_lagrange(coarse_system, ibody):
    """M and the quadratic velocity force of a RigidBody satisfy Lagrange's equations:
    F_quad = -(Mdot Qd - 1/2 d(Qd^T M Qd)/dQ), and the gravity force is -dV/dQ."""
    fs, Q, Qd = coarse_system
    body = [pe for pe in fs.model.point_effects if isinstance(pe, RigidBody)][ibody]
    N = len(Q)
    nobody = RigidBody(body.com, body.mass, body.inertia, None)

    def MF(q, qd):
        M = np.zeros((N, N))
        F = np.zeros(N)
        nobody.add(0.0, q, qd, M, F)
        return M, F

    M, F = MF(Q, Qd)
    eps = 1e-5
    Mp, _ = MF(Q + eps * Qd, Qd)
    Mm, _ = MF(Q - eps * Qd, Qd)
    Mdot_qd = (Mp - Mm) @ Qd / (2 * eps)
    dT = np.zeros(N)
    for j in np.flatnonzero(np.any(M != 0, axis=0)):
        e = np.zeros(N)
        e[j] = eps
        dT[j] = 0.5 * Qd @ (MF(Q + e, Qd)[0] - MF(Q - e, Qd)[0]) @ Qd / (2 * eps)
    expected = -(Mdot_qd - dT)
    scale = np.abs(expected).max()
    assert np.allclose(F, expected, rtol=0, atol=1e-6 * scale)
    # kinetic energy from M equals 1/2 m v_c^2 + 1/2 w.I_g w
    r, J, R, W = body.com(Q)
    v, w = J @ Qd, W @ Qd
    T = 0.5 * body.mass * v @ v + 0.5 * w @ (R @ body.inertia @ R.T) @ w
    assert np.isclose(0.5 * Qd @ M @ Qd, T, rtol=1e-12)
    # gravity: F = -dV/dQ, V = -m g . r_c
    g = np.array([-9.81, 0.0, 0.0])
    grav = RigidBody(body.com, body.mass, body.inertia, g)
    Fg = np.zeros(N)
    grav.add(0.0, Q, np.zeros(N), None, Fg)
    V = lambda q: np.atleast_1d(-body.mass * g @ body.com(q)[0])
    assert np.allclose(Fg, -cs_jac(V, Q, 1)[0], atol=1e-9 * body.mass * 9.81)
