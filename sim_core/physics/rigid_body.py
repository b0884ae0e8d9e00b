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
complex-step directional derivative of the Jacobians, SIMULTECH 2020 Eq. 8 right-hand side).

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

from sim_core.physics import _rigid_body_numba as frame_compiled
from sim_core.physics.beam import _moving_node_beam_numba as point_compiled
from sim_core.physics.complex_step import COMPLEX_STEP
from sim_core.physics.constraints import NonlinearConstraint, StateMemo
from sim_core.physics.point_effects import compiled_order, in_model_order

# beam section frames from the compiled point kernel; False: the element's numpy evaluate (the
# reference of tests/folding/test_rigid_body_paths.py)
COMPILED_BEAM_FRAMES = True
# planar body and turntable frames by the compiled loop (sim_core.physics._rigid_body_numba);
# False: the numpy code below (the reference)
COMPILED_PLANAR_FRAMES = True


def _memo(fun, cols):
    """One evaluation per state of the coordinates ``cols`` the frame depends on (a state that
    differs elsewhere, e.g. another body's coordinate perturbed for a Jacobian column, reuses
    it).  The last real and the last complex-step evaluation are kept; a real state equal to
    the real part of the last complex one is served from its real parts (equal to the real
    evaluation to O(h^2) = 1e-40 relative, as in
    :func:`sim_core.physics.constraints.material_point`).  ``cols(Q)`` -> int array; the
    function gets ``coords`` = ``cols`` (the structured Jacobian differences only those)."""
    memo = StateMemo()

    def f(Q):
        c = cols(Q)
        key, res = memo.lookup(Q, c)
        if res is None:
            res = memo.store(Q, c, key, fun(Q))
        return res
    f.coords = cols
    return f


def point_coords(owner, points, Q):
    """Union of the coordinates the point functions depend on at Q (None where one does not
    say), kept on ``owner`` while the points return the same index arrays (they do while a
    beam point stays in its element)."""
    cs = [getattr(p, "coords", None) for p in points]
    if any(c is None for c in cs):
        return None
    cs = [c(Q) for c in cs]
    key = tuple(id(c) for c in cs)
    hit = owner.__dict__.get("_coords_memo")
    if hit is None or hit[0] != key:
        hit = owner._coords_memo = (key, cs, np.unique(np.concatenate(cs)))   # cs keeps ids valid
    return hit[2]


def _add_local(terms, M, F) -> None:
    """Add a local (idx, Me, Fe) to the full (M, F); idx holds each coordinate once."""
    idx, Me, Fe = terms
    F[idx] += Fe
    if M is not None and Me is not None:
        M[np.ix_(idx, idx)] += Me


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

def _slew_basis(slew_axis, plane_basis):
    """Constants of S(phi) B0 = cos(phi) (B0 - a a^T B0) + sin(phi) [a]x B0 + a a^T B0 (the
    Rodrigues formula of :func:`rot_axis` times B0; a the unit slew axis)."""
    a = np.asarray(slew_axis, float) / np.linalg.norm(slew_axis)
    B0 = np.asarray(plane_basis, float)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]], float)
    P0 = np.outer(a, a) @ B0
    return a, B0 - P0, K @ B0, P0


def _cross_axis(a, r):
    """a x r for a constant real a (3,) and r (3,) real or complex."""
    return np.array([a[1] * r[2] - a[2] * r[1], a[2] * r[0] - a[0] * r[2],
                     a[0] * r[1] - a[1] * r[0]])


def turntable_frame(n_coords: int, i_phi: int, slew_axis, plane_basis, point=(0.0, 0.0, 0.0)):
    """Frame of the turntable at a point given in plane coordinates (u, v, w) (m).

    R = S(phi) B0 (columns e_u, e_v, n); W has the single column phi = slew axis."""
    ax, C0, S0, P0 = _slew_basis(slew_axis, plane_basis)
    p = np.asarray(point, float)
    cols = np.array([i_phi])
    cols.flags.writeable = False

    def fun(Q):
        if COMPILED_PLANAR_FRAMES and frame_compiled.AVAILABLE:
            return frame_compiled.planar_frame(Q, n_coords, i_phi, -1, -1, -1, C0, S0, P0, ax, p)
        phi = Q[i_phi]
        R = np.cos(phi) * C0 + np.sin(phi) * S0 + P0
        r = R @ p
        J = np.zeros((3, n_coords), dtype=R.dtype)
        W = np.zeros((3, n_coords), dtype=R.dtype)
        J[:, i_phi] = _cross_axis(ax, r)
        W[:, i_phi] = ax
        return r, J, R, W
    f = _memo(fun, lambda Q: cols)
    f.spec = ("planar", n_coords, (i_phi, -1, -1, -1), C0, S0, P0, ax, p)   # frame_compiled
    return f


def planar_body_frame(n_coords: int, i_phi: int, i_body: int, slew_axis, plane_basis,
                      point=(0.0, 0.0, 0.0), i_theta: int | None = None):
    """Frame of a rigid body with plane coordinates Q[i_body:i_body+3] = (u, v, theta) at the
    body-frame point ``point`` (m); with ``i_theta`` the angle is Q[i_theta] instead (a body
    that shares another's angle: the rod of a prismatic joint), the body then has only the
    coordinates (u, v) = Q[i_body:i_body+2].  See the module docstring for the kinematics:
    r = S B0 [(u, v, 0) + Rz p], J_u, J_v = columns e_u, e_v of S B0, J_theta = S B0 dRz/dtheta p,
    J_phi = a x r; R = S B0 Rz; W_phi = a, W_theta = n = S B0 e3."""
    ax, C0, S0, P0 = _slew_basis(slew_axis, plane_basis)
    p = np.asarray(point, float)
    iu, iv, it = i_body, i_body + 1, i_body + 2 if i_theta is None else int(i_theta)
    cols = np.array([i_phi, iu, iv, it])
    cols.flags.writeable = False

    def fun(Q):
        if COMPILED_PLANAR_FRAMES and frame_compiled.AVAILABLE:
            return frame_compiled.planar_frame(Q, n_coords, i_phi, iu, iv, it, C0, S0, P0, ax, p)
        phi, th = Q[i_phi], Q[it]
        S = np.cos(phi) * C0 + np.sin(phi) * S0 + P0
        c, s = np.cos(th), np.sin(th)
        e_u, e_v, n = S[:, 0], S[:, 1], S[:, 2]
        # Rz p = (c p0 - s p1, s p0 + c p1, p2), dRz/dtheta p = (-s p0 - c p1, c p0 - s p1, 0)
        r = (Q[iu] + c * p[0] - s * p[1]) * e_u + (Q[iv] + s * p[0] + c * p[1]) * e_v + p[2] * n
        dt = np.result_type(Q, float)
        J = np.zeros((3, n_coords), dtype=dt)
        W = np.zeros((3, n_coords), dtype=dt)
        J[:, iu] = e_u
        J[:, iv] = e_v
        J[:, it] = (-s * p[0] - c * p[1]) * e_u + (c * p[0] - s * p[1]) * e_v
        J[:, i_phi] = _cross_axis(ax, r)
        W[:, i_phi] = ax
        W[:, it] = n
        R = np.empty((3, 3), dtype=dt)
        R[:, 0] = c * e_u + s * e_v
        R[:, 1] = c * e_v - s * e_u
        R[:, 2] = n
        return r, J, R, W
    f = _memo(fun, lambda Q: cols)
    f.spec = ("planar", n_coords, (i_phi, iu, iv, it), C0, S0, P0, ax, p)    # frame_compiled
    return f


def beam_frame(model, ibeam: int, s: float, point_global_offset=None, frame0=None):
    """Frame of the cross-section of beam ``ibeam`` at material point s (fixed node coordinates).

    R has columns (e_t, e_b, e_s) of the section (sim_core.physics.beam.cardan), W the global small
    rotation per dQ (as in :func:`sim_core.physics.constraints.material_point`).  An optional rigid
    offset is given as its *global* vector at the configuration ``frame0`` (the section
    rotation R0 there); it is stored in section components p = R0^T o and follows the section:
    r_o = r + R p, J_o = J - [R p]x W.  The section kinematics come from the compiled point
    kernel (:func:`sim_core.physics.beam._moving_node_beam_numba.point_kinematics`) where
    ``COMPILED_BEAM_FRAMES`` and numba are on, else from the element's numpy ``evaluate``
    (the reference).
    """
    beam = model.beams[ibeam]
    off = int(model.offsets[ibeam])
    N = model.n_coords
    p = None
    if point_global_offset is not None:
        p = np.asarray(frame0, float).T @ np.asarray(point_global_offset, float)
    where = [off + imap for imap in beam.index_map]
    for idx in where:                   # shared by every call: read-only
        idx.flags.writeable = False

    def cols(Q):
        return where[model.element_at(ibeam, Q.real, float(s))]

    def fun(Q):
        e = model.element_at(ibeam, Q.real, float(s))
        idx = where[e]
        el = beam.elements[e]
        if COMPILED_BEAM_FRAMES and point_compiled.AVAILABLE:
            r, _, J_r, J_psi, _, _, frame, tmat = point_compiled.point_kinematics(el, Q[idx], s)
        else:
            kin = el.evaluate(Q[idx], s=np.array([s]), strains=False)
            r, J_r, J_psi = kin.r[0], kin.J_r[0], kin.J_psi[0]
            frame, tmat = kin.sec.frame[0], kin.sec.tmat[0]     # frame: rows e_t, e_b, e_s
        # W = [e_s e_t e_b] tmat J_psi on the element's columns (tmat: section components
        # ordered (s, t, b) of the small rotation per d(alpha, beta, gamma))
        Wl = (frame[2][:, None] * tmat[0] + frame[0][:, None] * tmat[1]
              + frame[1][:, None] * tmat[2]) @ J_psi
        R = frame.T
        if p is not None:
            o = R @ p
            # column-wise W_j x o = [[0, o2, -o1], [-o2, 0, o0], [o1, -o0, 0]] W_j
            ox = np.array([[0.0 * o[0], o[2], -o[1]], [-o[2], 0.0 * o[0], o[0]],
                           [o[1], -o[0], 0.0 * o[0]]])
            J_r = J_r + ox @ Wl
            r = r + o
        J = np.zeros((3, N), dtype=J_r.dtype)
        W = np.zeros((3, N), dtype=J_r.dtype)
        J[:, idx] = J_r
        W[:, idx] = Wl
        return r, J, R, W
    f = _memo(fun, cols)
    f.spec = ("beam", model, ibeam, float(s), p)                   # frame_compiled
    return f


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

    def coords(self, Q):
        """Coordinates the body's mass and force depend on (its frame's)."""
        return point_coords(self, (self.com,), Q)

    def velocity_coords(self, Q):
        """Coordinates whose rates enter the force (the frame's: the convective terms)."""
        return self.coords(Q)

    def local(self, t, Q, Qd, mass=True):
        """(idx, Me (or None), Fe) on the coordinates ``idx`` of the body's frame (all where the
        frame does not say): the terms of the class docstring restricted to the columns of J, W
        that are not identically zero."""
        # the complex-step state first: the real one is served from its real parts
        _, Jc, _, Wc = self.com(Q + 1j * COMPLEX_STEP * Qd)
        _, J, R, W = self.com(Q)
        idx = self.coords(Q)
        idx = np.arange(len(Q)) if idx is None else idx
        J, W, qd = J[:, idx], W[:, idx], Qd[idx]
        acc = (Jc[:, idx] @ qd).imag / COMPLEX_STEP             # Jdot Qd (m/s^2)
        wdot = (Wc[:, idx] @ qd).imag / COMPLEX_STEP            # Wdot Qd (rad/s^2)
        Ig = R @ np.asarray(self.inertia, float) @ R.T
        om = W @ qd
        Me = self.mass * (J.T @ J) + W.T @ Ig @ W if mass else None
        f = -self.mass * acc
        if self.gravity is not None:
            f = f + self.mass * np.asarray(self.gravity, float)
        return idx, Me, J.T @ f - W.T @ (Ig @ wdot + _cross3(om, Ig @ om))

    def add(self, t, Q, Qd, M, F):
        _add_local(self.local(t, Q, Qd, M is not None), M, F)

    def momentum(self, Q, Qd, point=np.zeros(3)):
        """Linear momentum (kg m/s) and angular momentum about ``point`` (kg m^2/s)."""
        r, J, R, W = self.com(Q)
        v = J @ Qd
        Ig = R @ np.asarray(self.inertia, float) @ R.T
        return self.mass * v, np.cross(r - point, self.mass * v) + Ig @ (W @ Qd)


class CompiledRigidBodies:
    """The local blocks of the rigid bodies among a model's point effects from one compiled
    call (:class:`sim_core.physics._rigid_body_numba.BodyProgram`: the formulas of
    :meth:`RigidBody.local`, the reference; ``tests/folding/test_joint_program.py`` compares
    both); the other effects with a ``local`` form are evaluated in Python beside it
    (``uncompiled``).  The interface of :class:`sim_core.physics.point_effects.CompiledPointEffects`
    (``local``, ``jacobian``, ``uncompiled``)."""

    def __init__(self, program, order, uncompiled, N):
        self.program, self.order, self.uncompiled, self.N = program, order, uncompiled, N

    @staticmethod
    def build(effects) -> "CompiledRigidBodies | None":
        """None where numba is off, no rigid body is there, a body's mass-centre frame is not
        a planar frame, or another effect has no ``local`` form."""
        if not (COMPILED_PLANAR_FRAMES and frame_compiled.AVAILABLE):
            return None
        bodies = [pe for pe in effects if type(pe) is RigidBody]
        other = [pe for pe in effects if type(pe) is not RigidBody]
        specs = [getattr(b.com, "spec", None) for b in bodies]
        if (not bodies or any(sp is None or sp[0] != "planar" for sp in specs)
                or not all(hasattr(pe, "local") for pe in other)):
            return None
        N = specs[0][1]
        order = compiled_order(effects, (RigidBody,))
        program = frame_compiled.BodyProgram(
            N, [b.com for b in bodies], [b.mass for b in bodies],
            [np.asarray(b.inertia, float) for b in bodies],
            [np.zeros(3) if b.gravity is None else np.asarray(b.gravity, float)
             for b in bodies])
        return CompiledRigidBodies(program, order, other, N)

    def _bodies(self, Q, Qd, mass):
        cols, nc, Me, Fe = self.program.blocks(Q, Qd, mass)
        return [(cols[b, :nc[b]].copy(), Me[b, :nc[b], :nc[b]].copy() if mass else None,
                 Fe[b, :nc[b]].copy()) for b in range(len(nc))]

    def local(self, Q, Qd, mass=True, t=float("nan")) -> list:
        """[(idx, Me or None, Fe)] of every effect, in the model's order (as its ``local``)."""
        return in_model_order(self.order, self._bodies(Q, Qd, mass), t, Q, Qd, mass)

    def jacobian(self, Q, Qd, Qdd, steps):
        """(d/dQ, d/dQ_dot) (N, N) of the bodies' F - M Q_ddot at frozen Q_ddot (their pieces
        of the structured Jacobian, :mod:`sim_core.model.state_jacobian`) by forward
        differences with the steps ``steps(x)`` in the bodies' columns, every body at once."""
        N = self.N

        def residual(Qx, Qdx):
            r = np.zeros(N)
            for idx, Me, Fe in self._bodies(Qx, Qdx, True):
                r[idx] += Fe - Me @ Qdd[idx]
            return r
        f_idx = self.program.f_idx                 # planar frames: fixed columns
        cols = np.unique(f_idx[f_idx >= 0])
        base = residual(Q, Qd)
        dQ = np.zeros((N, N))
        dQd = np.zeros((N, N))
        for D, x in ((dQ, Q.copy()), (dQd, Qd.copy())):
            for j, h in zip(cols, steps(x[cols])):
                xj = x[j]
                x[j] = xj + h
                up = residual(x, Qd) if D is dQ else residual(Q, x)
                x[j] = xj
                D[:, j] = (up - base) / h
        return dQ, dQd


@dataclass
class CoordinateInertia:
    """A rotor on one coordinate (turntable about the slew axis): M[i, i] += I (kg m^2)."""

    index: int
    inertia: float
    name: str = "turntable"

    def local(self, t, Q, Qd, mass=True):
        """(idx, Me (or None), Fe) on the one coordinate; no force."""
        return (np.array([self.index]), np.array([[float(self.inertia)]]) if mass else None,
                np.zeros(1))

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
    """Hydraulic cylinder as a spring-damper on the pin distance s (PD,
    docs/model.md#input-folding-drive):

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

    def coords(self, Q):
        """Coordinates the force depends on (the two pins' frames')."""
        return point_coords(self, (self.a, self.b), Q)

    def velocity_coords(self, Q):
        """Coordinates whose rates enter the force (the damper's pin-distance rate)."""
        return self.coords(Q)

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

    def local(self, t, Q, Qd, mass=True):
        """(idx, None, Fe): the force -F ds/dQ on the pins' coordinates (all where unknown)."""
        f, _, g = self.tension(t, Q, Qd)
        idx = self.coords(Q)
        idx = np.arange(len(Q)) if idx is None else idx
        return idx, None, -f * g[idx]

    def add(self, t, Q, Qd, M, F):
        _add_local(self.local(t, Q, Qd, M is not None), M, F)


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
    return NonlinearConstraint(name, 2, evaluate, points=(fa, fb, plane_frame),
                               joint_program=("planar_pin", (), (fa, fb, plane_frame)))


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
    return NonlinearConstraint(name, 2, evaluate, points=(fa, fb),
                               joint_program=("hinge_axis", (c_a, p_b, q_b), (fa, fb)))


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
    return NonlinearConstraint(name, 1, evaluate, points=(fa, fb),
                               joint_program=("prismatic", (m_a,), (fa, fb)))
