"""Rigid bodies, body-frame points, joints and spring-dampers for multibody scenes (SI units).

Frame functions
---------------
A *frame function* maps the full coordinates Q to ``(r, J, R, W)``:

* ``r`` (3,) global position of a point (m), ``J = dr/dQ`` (3, N) (material/body point),
* ``R`` (3, 3) rotation of the body frame attached there (columns = body axes, global comps),
* ``W`` (3, N) global angular-velocity Jacobian: omega = W Q_dot and dR/dQ_j = [W_j]x R.

The first two entries have the meaning of :func:`sim_core.physics.constraints.material_point`, so the
existing builders :func:`~sim_core.physics.constraints.point_coincidence` and
:func:`~sim_core.physics.constraints.distance_driver` accept frame functions (they read only r, J).
All functions are complex-step safe in Q (the model forms the quadratic velocity terms by a
complex-step directional derivative of the Jacobians, second seed Eq. 8 right-hand side).

Rigid bodies in a slewing plane (reduced parametrization)
---------------------------------------------------------
All rigid bodies of the folding manipulator move in the luffing plane, which is turned about the
vertical slew axis by the turntable angle phi.  A body has in-plane coordinates (u, v, theta)
in the turntable frame (u horizontal, v up, theta about the plane normal) and shares phi:

    r = S(phi) B0 [(u, v, 0) + Rz(theta) p],   R = S(phi) B0 Rz(theta),
    omega = phi_dot a_slew + theta_dot n(phi),   n = S(phi) B0 e3,

with S(phi) the rotation by phi about the slew axis ``a_slew`` through the origin and B0 the
constant plane basis (columns e_u, e_v, n at phi = 0).  This is real 3-D rotation (the plane is
carried from XY to XZ), only the out-of-plane motion of the rigid bodies is removed.

:class:`RigidBody` adds the Newton-Euler terms of any body given by a frame function:
    M += m J_c^T J_c + W^T I_g W,
    F += J_c^T m (g - Jdot_c Qd) - W^T (I_g Wdot Qd + omega x I_g omega),  I_g = R I_b R^T
(the time derivative of I_g omega is I_g omega_dot + omega x I_g omega).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from sim_core.physics.complex_step import COMPLEX_STEP
from sim_core.physics.constraints import NonlinearConstraint


def _memo(fun):
    """One evaluation per state (real and complex-step state kept)."""
    memo: list = []

    def f(Q):
        for Qm, res in memo:
            if Qm.dtype == Q.dtype and Qm.shape == Q.shape and np.array_equal(Qm, Q):
                return res
        res = fun(Q)
        memo[:] = [m for m in memo if m[0].dtype != Q.dtype][:1] + [(Q.copy(), res)]
        return res
    return f


def _cross_cols(a: np.ndarray, W: np.ndarray) -> np.ndarray:
    """Column-wise W_j x a for W (3, N) and a (3,): returns (3, N)."""
    return np.stack([W[1] * a[2] - W[2] * a[1],
                     W[2] * a[0] - W[0] * a[2],
                     W[0] * a[1] - W[1] * a[0]])


def _cross3(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def rot_axis(axis: np.ndarray, angle) -> np.ndarray:
    """Rotation matrix by ``angle`` (rad, complex allowed) about the unit vector ``axis``."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]], float)
    c, s = np.cos(angle), np.sin(angle)
    return np.eye(3) * c + s * K + (1 - c) * np.outer(a, a)


# -- frame functions ---------------------------------------------------------------------------

def turntable_frame(n_coords: int, i_phi: int, slew_axis, plane_basis, point=(0.0, 0.0, 0.0)):
    """Frame of the turntable at a point given in plane coordinates (u, v, w) (m).

    R = S(phi) B0 (columns e_u, e_v, n); W has the single column phi = slew axis."""
    ax = np.asarray(slew_axis, float)
    B0 = np.asarray(plane_basis, float)
    p = np.asarray(point, float)

    def fun(Q):
        phi = Q[i_phi]
        R = rot_axis(ax, phi) @ B0
        r = R @ p
        J = np.zeros((3, n_coords), dtype=np.result_type(phi, float))
        W = np.zeros((3, n_coords))
        J[:, i_phi] = _cross3(ax, r)
        W[:, i_phi] = ax
        return r, J, R, W.astype(J.dtype)
    return _memo(fun)


def planar_body_frame(n_coords: int, i_phi: int, i_body: int, slew_axis, plane_basis,
                      point=(0.0, 0.0, 0.0)):
    """Frame of a rigid body with plane coordinates Q[i_body:i_body+3] = (u, v, theta) at the
    body-frame point ``point`` (m).  See the module docstring for the kinematics."""
    ax = np.asarray(slew_axis, float)
    B0 = np.asarray(plane_basis, float)
    p = np.asarray(point, float)
    iu, iv, it = i_body, i_body + 1, i_body + 2

    def fun(Q):
        phi, th = Q[i_phi], Q[it]
        S = rot_axis(ax, phi) @ B0
        c, s = np.cos(th), np.sin(th)
        Rz = np.array([[c, -s, 0 * c], [s, c, 0 * c], [0 * c, 0 * c, 1 + 0 * c]])
        dRz = np.array([[-s, -c, 0 * c], [c, -s, 0 * c], [0 * c, 0 * c, 0 * c]])
        loc = np.array([Q[iu], Q[iv], 0 * Q[iu]]) + Rz @ p
        r = S @ loc
        dt = np.result_type(Q, float)
        J = np.zeros((3, n_coords), dtype=dt)
        W = np.zeros((3, n_coords), dtype=dt)
        J[:, iu] = S[:, 0]
        J[:, iv] = S[:, 1]
        J[:, it] = S @ (dRz @ p)
        J[:, i_phi] = _cross3(ax, r)
        W[:, i_phi] = ax
        W[:, it] = S[:, 2]
        return r, J, S @ Rz, W
    return _memo(fun)


def beam_frame(model, ibeam: int, s: float, point_global_offset=None, frame0=None):
    """Frame of the cross-section of beam ``ibeam`` at material point s (fixed node coordinates).

    R has columns (e_t, e_b, e_s) of the section (sim_core.physics.beam.cardan), W the global small
    rotation per dQ (as in :func:`sim_core.physics.constraints.material_point`).  An optional rigid
    offset is given as its *global* vector at the configuration ``frame0`` (the section
    rotation R0 there); it is stored in section components p = R0^T o and follows the section:
    r_o = r + R p, J_o = J - [R p]x W.
    """
    beam = model.beams[ibeam]
    off = int(model.offsets[ibeam])
    N = model.n_coords
    p = None
    if point_global_offset is not None:
        p = np.asarray(frame0, float).T @ np.asarray(point_global_offset, float)

    def fun(Q):
        e = model.element_at(ibeam, Q.real, float(s))
        idx = off + beam.index_map[e]
        kin = beam.elements[e].evaluate(Q[idx], s=np.array([s]), strains=False)
        J = np.zeros((3, N), dtype=kin.J_r.dtype)
        Jp = np.zeros((3, N), dtype=kin.J_r.dtype)
        J[:, idx] = kin.J_r[0]
        Jp[:, idx] = kin.J_psi[0]
        frame = kin.sec.frame[0]                       # rows e_t, e_b, e_s
        W = frame[[2, 0, 1]].T @ (kin.sec.tmat[0] @ Jp)
        R = frame.T
        r = kin.r[0]
        if p is not None:
            o = R @ p
            J = J + _cross_cols(o, W)
            r = r + o
        return r, J, R, W
    return _memo(fun)


# -- rigid body inertia ------------------------------------------------------------------------

@dataclass
class RigidBody:
    """Newton-Euler terms of a rigid body (mass m kg, inertia I_b kg m^2 about the mass centre
    in body axes) whose mass-centre frame is the frame function ``com``; gravity g m/s^2."""

    com: Callable
    mass: float
    inertia: np.ndarray
    gravity: np.ndarray | None = None
    name: str = "rigid_body"

    def add(self, t, Q, Qd, M, F):
        r, J, R, W = self.com(Q)
        _, Jc, _, Wc = self.com(Q + 1j * COMPLEX_STEP * Qd)
        acc = (Jc @ Qd).imag / COMPLEX_STEP                     # Jdot Qd
        wdot = (Wc @ Qd).imag / COMPLEX_STEP                    # Wdot Qd
        Ig = R @ np.asarray(self.inertia, float) @ R.T
        om = W @ Qd
        if M is not None:
            M += self.mass * (J.T @ J) + W.T @ Ig @ W
        f = -self.mass * acc
        if self.gravity is not None:
            f = f + self.mass * np.asarray(self.gravity, float)
        F += J.T @ f - W.T @ (Ig @ wdot + _cross3(om, Ig @ om))

    def momentum(self, Q, Qd, point=np.zeros(3)):
        """Linear momentum (kg m/s) and angular momentum about ``point`` (kg m^2/s)."""
        r, J, R, W = self.com(Q)
        v = J @ Qd
        Ig = R @ np.asarray(self.inertia, float) @ R.T
        return self.mass * v, np.cross(r - point, self.mass * v) + Ig @ (W @ Qd)


@dataclass
class CoordinateInertia:
    """A rotor on one coordinate (turntable about the slew axis): M[i, i] += I (kg m^2)."""

    index: int
    inertia: float
    name: str = "turntable"

    def add(self, t, Q, Qd, M, F):
        if M is not None:
            M[self.index, self.index] += self.inertia


def cylinder_inertia(m: float, radius: float, length: float) -> np.ndarray:
    """Solid uniform cylinder along body axis 1 about its centre: diag(m r^2/2, I_t, I_t),
    I_t = m (3 r^2 + L^2)/12 (kg m^2)."""
    it = m * (3 * radius ** 2 + length ** 2) / 12.0
    return np.diag([0.5 * m * radius ** 2, it, it])


# -- spring-damper actuator --------------------------------------------------------------------

@dataclass
class SpringDamperActuator:
    """Hydraulic cylinder as a spring-damper on the pin distance s (SCENARIOS B, PD):

        F = k (s - s_ref(t)) + c (s_dot - v(t)),  s_ref = s_ref0 + int_0^t v dt

    F > 0 is tension; the generalized force is -F ds/dQ.  ``profile`` gives the integral of v
    (``stroke``, offset 0) and v (``rate``), e.g. :class:`sim_core.physics.drive_profiles.Eq52Profile`.
    The pushing force of the cylinder is -F (N)."""

    a: Callable
    b: Callable
    k: float
    c: float
    s_ref0: float
    profile: object | None = None
    name: str = "cylinder"

    def length(self, Q):
        ra, Ja, _, _ = self.a(Q)
        rb, Jb, _, _ = self.b(Q)
        d = rb - ra
        s = np.sqrt(d @ d)
        return s, (d / s) @ (Jb - Ja)

    def reference(self, t):
        if self.profile is None:
            return self.s_ref0, 0.0
        if getattr(self, "_last_t", None) != t:
            smp = self.profile.sample(float(t))
            self._last_t, self._last = t, (float(smp.s), float(smp.v))
        return self.s_ref0 + self._last[0], self._last[1]

    def tension(self, t, Q, Qd):
        s, g = self.length(Q)
        s_ref, v = self.reference(t)
        return self.k * (s - s_ref) + self.c * (g @ Qd - v), s, g

    def add(self, t, Q, Qd, M, F):
        f, _, g = self.tension(t, Q, Qd)
        F -= f * g


# -- joints --------------------------------------------------------------------------------------

def planar_pin(name: str, fa, fb, plane_frame) -> NonlinearConstraint:
    """Revolute joint (axis = plane normal) between two bodies that both stay in the luffing
    plane: the two in-plane components of r_a - r_b vanish (the third is identically zero).
    ``plane_frame`` is the turntable frame function (its R columns e_u, e_v, n)."""
    def evaluate(Q):
        ra, Ja, _, _ = fa(Q)
        rb, Jb, _, _ = fb(Q)
        _, _, R, W = plane_frame(Q)
        d = ra - rb
        E = R[:, :2]
        g = E.T @ d
        # dE/dQ_j = W_j x E  ->  d/dQ_j (E_k . d) = (W_j x E_k) . d = W_j . (E_k x d)
        J = E.T @ (Ja - Jb) + np.stack([_cross3(E[:, k], d) @ W for k in range(2)])
        return g, J
    return NonlinearConstraint(name, 2, evaluate)


def revolute_axis(name: str, fa, fb, c_a, p_b, q_b) -> NonlinearConstraint:
    """Orientation part of a revolute joint: the hinge axis n = R_a c_a (c_a in body a's axes)
    stays normal to the two body-b vectors u = R_b p_b, R_b q_b (p_b, q_b orthonormal, normal
    to the axis in b's axes): rows u . n = 0 with Jacobian (u x n) . (W_b - W_a)."""
    c_a, p_b, q_b = (np.asarray(x, float) for x in (c_a, p_b, q_b))

    def evaluate(Q):
        _, _, Ra, Wa = fa(Q)
        _, _, Rb, Wb = fb(Q)
        n = Ra @ c_a
        g, J = [], []
        for w in (p_b, q_b):
            u = Rb @ w
            g.append(u @ n)
            J.append(_cross3(u, n) @ (Wb - Wa))
        return np.array(g), np.vstack(J)
    return NonlinearConstraint(name, 2, evaluate)


def prismatic_offset(name: str, fa, fb, axis_normal_a) -> NonlinearConstraint:
    """Translational joint, lateral row: (r_b - r_a) . (R_a m) = 0 with m a body-a vector normal
    to the sliding axis (the relative rotation is a separate, linear row)."""
    m_a = np.asarray(axis_normal_a, float)

    def evaluate(Q):
        ra, Ja, Ra, Wa = fa(Q)
        rb, Jb, _, _ = fb(Q)
        e = Ra @ m_a
        d = rb - ra
        return np.atleast_1d(d @ e), (e @ (Jb - Ja) + _cross3(e, d) @ Wa)[None, :]
    return NonlinearConstraint(name, 1, evaluate)
