"""Static equilibrium and linearized free vibration of a model.

Static equilibrium solves the reduced force balance P^T F(t, Q(z), 0) = 0 by Newton's method
with a finite-difference tangent (the models here have at most a few hundred coordinates).
Linearized modes solve K phi = omega^2 M phi with K = -dF_r/dz at the equilibrium.

The solvers check the run's wall-clock budget and interrupt flag
(:func:`sim_core.run_control.check`, phase ``statics``) before every Newton iteration and
every corrector iteration of the load continuation.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from sim_core import run_control
from sim_core.errors import NoStaticEquilibrium, SimulationError
from sim_core.model.model import Model


def reduced_static_force(model: Model, t: float, z: np.ndarray) -> np.ndarray:
    Q, _ = model.full_state(t, z, np.zeros_like(z))
    _, F = model.mass_force(t, Q, np.zeros_like(Q), mass=False)
    return model.P.T @ F


def tangent_stiffness(model: Model, t: float, z: np.ndarray, rel_step: float = 1e-7) -> np.ndarray:
    """K = -dF_r/dz by central differences, symmetrized part returned separately by caller."""
    n = len(z)
    K = np.empty((n, n))
    scale = max(1.0, float(np.max(np.abs(z)))) if n else 1.0
    h = rel_step * scale
    for j in range(n):
        dz = np.zeros(n)
        dz[j] = h
        K[:, j] = -(reduced_static_force(model, t, z + dz) - reduced_static_force(model, t, z - dz)) / (2 * h)
    return K


def static_equilibrium(model: Model, z0: np.ndarray, t: float = 0.0, tol: float = 1e-7,
                       max_iter: int = 40) -> np.ndarray:
    """Newton iteration for P^T F = 0.

    Converged when |r| <= tol * |r_0| (the finite-difference tangent leaves a residual floor of
    about 1e-9 |r_0|) or when the Newton update stalls at round-off.
    """
    z = np.array(z0, dtype=float)
    r = reduced_static_force(model, t, z)
    scale = max(np.linalg.norm(r), 1e-12)
    for _ in range(max_iter):
        if np.linalg.norm(r) <= tol * scale:
            return z
        run_control.check("statics", t)
        dz = np.linalg.solve(tangent_stiffness(model, t, z), r)
        z = z + dz
        r = reduced_static_force(model, t, z)
        if not np.all(np.isfinite(r)):
            break
        if np.linalg.norm(dz) <= 1e-13 * (1.0 + np.linalg.norm(z)):
            return z
    raise SimulationError(t, f"static equilibrium: Newton did not converge (|r| = {np.linalg.norm(r):.3g} N)")


def linear_modes(model: Model, z_eq: np.ndarray, t: float = 0.0):
    """Natural angular frequencies (rad/s, ascending) and mode shapes about an equilibrium."""
    Q, Qd = model.full_state(t, z_eq, np.zeros_like(z_eq))
    M, _ = model.mass_force(t, Q, Qd)
    Mr = model.P.T @ M @ model.P
    K = tangent_stiffness(model, t, z_eq)
    K = 0.5 * (K + K.T)
    w2, vec = sla.eigh(K, Mr)
    return np.sqrt(np.clip(w2, 0.0, None)), vec


def static_parts(model: Model, t: float = 0.0):
    """z -> (P^T F(z) at rest, Phi(z), C(z) = g_Q P): the pieces of the static residual with
    nonlinear constraints (forces in N, violations in m or rad)."""
    from sim_core.physics.constraints import constraint_terms

    def parts(zz):
        Q, _ = model.full_state(t, zz, np.zeros_like(zz))
        _, F = model.mass_force(t, Q, np.zeros_like(Q), mass=False)
        phi, J, _, _ = constraint_terms(model.nonlinear, t, Q, np.zeros_like(Q))
        return model.P.T @ F, phi, model._times_P(J)
    return parts


def force_tangent(parts, z: np.ndarray, lam: np.ndarray, rel_step: float = 1e-6,
                   r0: np.ndarray | None = None) -> np.ndarray:
    """d(P^T F + C^T lambda)/dz at fixed lambda by finite differences (N/m, N/rad), step
    rel_step * max(1, |z|_inf): central differences, or forward ones from the residual ``r0``
    at z when it is given (half the model evaluations; the folding boom's statics use them).

    Central differences: the Newton system of stiff booms is dominated by cancellation (entries
    EA/l ~ 1e13 N/m against residuals ~ 1e5 N), and the O(h) truncation error of forward
    differences (~1e-6 relative) makes the Newton step useless at 8 sub-elements
    (benchmarks/diagnose_static_tangent.py shows it); the O(h^2) error of central ones does
    not."""
    n = len(z)
    h = rel_step * max(1.0, float(np.max(np.abs(z))))
    K = np.empty((n, n))
    for j in range(n):
        zj = z.copy()
        zj[j] += h
        Fp, _, Cp = parts(zj)
        if r0 is not None:
            K[:, j] = ((Fp + Cp.T @ lam) - r0) / h
            continue
        zj[j] -= 2 * h
        Fm, _, Cm = parts(zj)
        K[:, j] = ((Fp + Cp.T @ lam) - (Fm + Cm.T @ lam)) / (2 * h)
    return K


def structured_force_tangent(model: Model, t: float, z: np.ndarray, lam: np.ndarray,
                             central: bool = True, rel_step: float = 1e-6) -> np.ndarray:
    """d(P^T F + C^T lambda)/dz at rest and fixed lambda (N/m, N/rad), the tangent of
    :func:`static_parts`' residual, from the local pieces of the state Jacobian
    (:func:`sim_core.model.state_jacobian.residual_derivatives` at Q_dot = Q_ddot = 0, friction
    left out): each element differenced in its own coordinates, each constraint, rope and the
    payload in their points', so a tangent costs about as much as one structured Jacobian
    instead of 2 n_dof whole-model force evaluations (:func:`force_tangent`).  Central local
    differences with the step rel_step * max(1, |x_j|) by default: the cancellation argument of
    :func:`force_tangent` holds per element as for the whole model."""
    from sim_core.model.state_jacobian import residual_derivatives

    zero = np.zeros_like(z)
    Q, Qd = model.full_state(t, z, zero)
    Qdd = np.zeros(model.n_coords)
    dR1 = residual_derivatives(model, t, Q, Qd, Qdd, np.asarray(lam, float), rel_step,
                               central=central, friction=False, rates=False)[0]
    XP = model._times_P
    return XP(XP(dR1[:, :model.n_coords]).T).T


def constrained_static_equilibrium(model: Model, z0: np.ndarray, t: float = 0.0,
                                   tol: float = 1e-7, max_iter: int = 30,
                                   continuation: bool = True):
    """Static equilibrium with nonlinear constraints: P^T F(z) + C(z)^T lambda = 0, Phi(z) = 0.

    Newton on (z, lambda) with the structured central-difference tangent of the force part
    (:func:`structured_force_tangent`; the constraint Jacobian C is analytic).  Returns
    (z, lambda); lambda are the static constraint reactions (e.g. the luffing-cylinder force).
    Converged when the force residual is below tol times
    the largest applied generalized force and |Phi| < 1e-10 m, or when the update stalls at
    round-off.

    When Newton does not converge, or stalls (five iterations in a row that backtrack to less
    than 1/16 of the Newton step: the start is outside its region of convergence), and
    ``continuation`` is on and the model has weight, the equilibrium is traced from the
    unloaded state by :func:`load_continuation`, which either reaches the full weight or raises
    :class:`~sim_core.errors.NoStaticEquilibrium` at a limit point (e.g. the soft booms at 0 deg
    luffing angle).
    """
    z = np.array(z0, float)
    n = len(z)
    parts = static_parts(model, t)
    Fr, phi, C = parts(z)
    lam = np.linalg.lstsq(C.T, -Fr, rcond=None)[0]
    scale = max(np.linalg.norm(Fr), 1.0)
    stalled = 0
    for _ in range(max_iter):
        r1 = Fr + C.T @ lam
        if np.linalg.norm(r1) <= tol * scale and np.max(np.abs(phi), initial=0.0) < 1e-10:
            return z, lam
        run_control.check("statics", t)
        K = structured_force_tangent(model, t, z, lam)
        m = C.shape[0]
        A = np.block([[K, C.T], [C, np.zeros((m, m))]])
        try:
            d = np.linalg.solve(A, -np.concatenate([r1, phi]))
        except np.linalg.LinAlgError:
            raise SimulationError(t, "constrained static equilibrium: singular tangent") from None
        # the full Newton step is taken when it lowers the force residual or leaves the
        # constraints nearly closed (|phi| < 1 mm: the quadratic phase closes them); otherwise
        # backtracking on the merit |r| + k_ref |phi| (k_ref: force per metre of the tangent).
        # (Weighting phi by the axial stiffness ~1e10 N/m alone rejected good full steps and cost
        # 3x the iterations on the 25 t telescopic equilibrium.)
        k_ref = float(np.max(np.abs(np.diag(K)))) or 1.0
        merit0 = np.linalg.norm(r1) + k_ref * np.linalg.norm(phi)
        step = 1.0
        while True:
            z_try, lam_try = z + step * d[:n], lam + step * d[n:]
            Fr_t, phi_t, C_t = parts(z_try)
            r_t = np.linalg.norm(Fr_t + C_t.T @ lam_try)
            merit = r_t + k_ref * np.linalg.norm(phi_t)
            if not np.isfinite(merit):
                pass
            elif step == 1.0 and (r_t < np.linalg.norm(r1)
                                  or np.max(np.abs(phi_t), initial=0.0) < 1e-3):
                break
            elif merit < merit0:
                break
            if step < 1e-3:
                break
            step *= 0.5
        if not np.isfinite(merit):
            raise SimulationError(t, "constrained static equilibrium: non-finite residual")
        z, lam, Fr, phi, C = z_try, lam_try, Fr_t, phi_t, C_t
        if step * np.linalg.norm(d[:n]) <= 1e-13 * (1.0 + np.linalg.norm(z)):   # stalled
            return z, lam
        stalled = stalled + 1 if step < 1.0 / 16 else 0
        if stalled >= 5:
            break
    if continuation and _weights(model):
        return load_continuation(model, np.asarray(z0, float), t, tol=tol)
    raise SimulationError(t, "constrained static equilibrium: Newton did not converge "
                             f"(|r| = {np.linalg.norm(Fr + C.T @ lam):.3g} N, |phi| = {np.max(np.abs(phi)):.3g})")


def _weights(model: Model) -> list[tuple[object, str]]:
    """(object, attribute) of every weight of the model: Gravity effects and point masses."""
    from sim_core.physics.effects import Gravity
    out = [(e, "g") for e in model.effects if isinstance(e, Gravity)]
    out += [(pe, "gravity") for pe in model.point_effects
            if getattr(pe, "gravity", None) is not None]
    return out


@contextmanager
def gravity_scaled(model: Model, factor: float):
    """Within the block every weight of the model (distributed and point masses) is scaled by
    ``factor`` (the load factor of :func:`load_continuation`); restored afterwards."""
    saved = [(obj, attr, getattr(obj, attr)) for obj, attr in _weights(model)]
    try:
        for obj, attr, g in saved:
            setattr(obj, attr, factor * np.asarray(g, float))
        yield
    finally:
        for obj, attr, g in saved:
            setattr(obj, attr, g)


@dataclass
class EquilibriumPath:
    """Points of a traced equilibrium path: load factor (weight / full weight), scaled
    displacement |z - z_unloaded| / |dz/dlambda at 0| (1 = the linear response to the full
    weight), arclength of the continuation (predictor step lengths summed, same scaled metric)
    and the load-factor component of the unit path tangent (changes sign at a limit point)."""

    load_factor: list[float] = field(default_factory=list)
    arclength: list[float] = field(default_factory=list)
    displacement: list[float] = field(default_factory=list)
    tangent_load: list[float] = field(default_factory=list)

    def add(self, load_factor: float, arclength: float, displacement: float,
            tangent_load: float) -> None:
        self.load_factor.append(float(load_factor))
        self.arclength.append(float(arclength))
        self.displacement.append(float(displacement))
        self.tangent_load.append(float(tangent_load))


def load_continuation(model: Model, z0: np.ndarray, t: float = 0.0, tol: float = 1e-7,
                      target: float = 1.0, ds0: float = 0.05, ds_max: float = 0.25,
                      max_steps: int = 80, path: EquilibriumPath | None = None):
    """Static equilibrium traced in the load factor of the weight from 0 to ``target`` by
    pseudo-arclength continuation (Riks 1979; Crisfield 1981), so that a limit point (fold) of
    the path is passed instead of stalling Newton there.

    Path: R(z, mu, lam_g) = P^T F(z; lam_g g) + C(z)^T mu = 0, Phi(z) = 0, with the weight scaled
    by lam_g (:func:`gravity_scaled`; F is affine in lam_g, dR/dlam_g = F(z; g) - F(z; 0)).
    Arclength metric: (|dz| / z_ref)^2 + dlam_g^2, z_ref = |dz/dlam_g| at lam_g = 0, so that
    the linear response to the full weight has length ~1.  Predictor: along the unit tangent
    (oriented by continuity with the previous one) plus the curvature through the previous
    point, x_k + t ds + q ds^2 (a tangent-only predictor left residuals of ~1x the weight on a
    cantilever at 1 % of its load: bending by theta shortens a boom by ~theta^2 / 2 of its
    length, and the stiff axial direction turns the missing shortening into large forces).
    Corrector: full Newton on the bordered system (force tangent at each iterate, constraint
    rows, hyperplane through the predictor normal to the tangent), to 1e-5 of the weight and
    1e-8 m per path point (each point only seeds the next; the end point is solved to ``tol`` by
    Newton at lam_g = target).  Step length: x1.5 after <= 5 corrector iterations, x0.7 after
    more than 7, halved after a failed corrector.

    Returns (z, mu) at lam_g = target.  Raises :class:`NoStaticEquilibrium` when the tangent's
    load component turns negative (the path turned back: a limit point below ``target``), with
    the largest load factor on the path (parabola through the three points around it), and
    :class:`SimulationError` when the step length falls below 1e-4 or after ``max_steps``.
    ``path`` (optional) collects the traced points."""
    path = path if path is not None else EquilibriumPath()
    parts = static_parts(model, t)

    def at(factor, z):
        with gravity_scaled(model, factor):
            return parts(z)

    with gravity_scaled(model, 0.0):
        z, mu = constrained_static_equilibrium(model, z0, t, tol=tol, continuation=False)
    n = len(z)
    z_un = z.copy()
    lg = 0.0
    W = max(np.linalg.norm(at(1.0, z)[0] - at(0.0, z)[0]), 1.0)     # generalized full weight
    # path points to 1e-5 of the weight and 1e-8 m (a point only seeds the next one; the end
    # point is solved to ``tol`` by Newton at lam_g = target)
    tol_path = max(tol, 1e-5)
    z_ref = None
    prev_dir = None
    prev = None                    # previous converged point and the step length to it
    ds = ds0
    s = 0.0                        # arclength of the current point
    with gravity_scaled(model, lg):
        K = structured_force_tangent(model, t, z, mu)

    def bordered(K, Fl, C, a_z, c):
        m = C.shape[0]
        B = np.zeros((n + m + 1, n + m + 1))
        B[:n, :n] = K
        B[:n, n:n + m] = C.T
        B[n:n + m, :n] = C
        B[:n, n + m] = Fl
        B[n + m, :n] = a_z
        B[n + m, n + m] = c
        return B

    for _ in range(max_steps):
        run_control.check("statics", t)
        # ---- unit tangent at the converged point (z, mu, lg); K: force tangent there
        F0, phi, C = at(0.0, z)
        Fl = at(1.0, z)[0] - F0
        m = C.shape[0]
        A = np.block([[K, C.T], [C, np.zeros((m, m))]])
        try:
            vn = np.linalg.solve(A, np.concatenate([-Fl, np.zeros(m)]))
        except np.linalg.LinAlgError:
            raise SimulationError(t, f"load continuation: singular tangent at {lg:.3g} x weight") from None
        v, nu = vn[:n], vn[n:]
        if z_ref is None:
            z_ref = max(float(np.linalg.norm(v)), 1e-12)
        c = 1.0 / np.sqrt((np.linalg.norm(v) / z_ref) ** 2 + 1.0)
        direction = np.concatenate([c * v / z_ref, [c]])
        if prev_dir is not None and direction @ prev_dir < 0:
            c, direction = -c, -direction
        path.add(lg, s, np.linalg.norm(z - z_un) / z_ref, c)
        if prev_dir is not None and c < 0:                       # the path turned back
            lams = np.array(path.load_factor[-3:])
            ss = np.array(path.arclength[-3:])
            lam_max = float(np.max(path.load_factor))
            if len(lams) == 3:
                a2, a1, a0 = np.polyfit(ss - ss[1], lams, 2)
                if a2 < 0:
                    lam_max = max(lam_max, float(a0 - a1 ** 2 / (4 * a2)))
            raise NoStaticEquilibrium(t, lam_max, zip(path.load_factor, path.displacement))
        prev_dir = direction
        a_z = c * v / z_ref ** 2                         # hyperplane normal (scaled metric)
        # ---- predictor along the tangent, Newton corrector on the hyperplane through it
        while True:
            zi, mui, li = z + ds * c * v, mu + ds * c * nu, lg + ds * c
            if prev is not None:
                # curvature from the previous point: x(s) = x_k + t s + q s^2 through x_{k-1}
                # at s = -h (error O(ds^3) instead of the tangent's O(ds^2); the second-order
                # axial shortening of bent booms is what the plain tangent predictor misses)
                zp, mp, lp, h = prev
                w2 = (ds / h) ** 2
                zi = zi + w2 * (zp - z + h * c * v)
                mui = mui + w2 * (mp - mu + h * c * nu)
                li = li + w2 * (lp - lg + h * c)
            ok, r_prev = False, np.inf
            for its in range(1, 11):
                Fi, phii, Ci = at(li, zi)
                Ri = Fi + Ci.T @ mui
                rn = np.linalg.norm(Ri)
                if not (np.isfinite(rn) and np.all(np.isfinite(phii))) or rn > 10 * r_prev:
                    break
                if rn <= tol_path * W and np.max(np.abs(phii), initial=0.0) < 1e-8:
                    ok = True
                    break
                r_prev = rn
                run_control.check("statics", t)
                with gravity_scaled(model, li):          # full Newton: tangent at the iterate
                    Ki = structured_force_tangent(model, t, zi, mui)
                Fli = at(1.0, zi)[0] - at(0.0, zi)[0]     # dR/dlam_g at the iterate
                try:
                    d = np.linalg.solve(bordered(Ki, Fli, Ci, a_z, c),
                                        -np.concatenate([Ri, phii, [0.0]]))
                except np.linalg.LinAlgError:
                    break
                zi, mui, li = zi + d[:n], mui + d[n:n + m], li + d[n + m]
            if ok:
                break
            ds *= 0.5
            if ds < 1e-4:
                raise SimulationError(t, "load continuation: step length below 1e-4 at "
                                         f"{lg:.3g} x weight (corrector does not converge)")
        if li >= target:
            # the target lies between the last two points: Newton at exactly lam_g = target
            w = (target - lg) / (li - lg)
            with gravity_scaled(model, target):
                zt, mt = constrained_static_equilibrium(model, z + w * (zi - z), t, tol=tol,
                                                        continuation=False)
            path.add(target, s + w * ds, np.linalg.norm(zt - z_un) / z_ref, np.nan)
            return zt, mt
        prev = (z, mu, lg, ds)
        z, mu, lg, s = zi, mui, li, s + ds
        # the last corrector tangent stands for the one at the converged point (one quadratically
        # convergent Newton step away)
        K = Ki
        ds = min(ds * 1.5, ds_max) if its <= 5 else (ds * 0.7 if its > 7 else ds)
    raise SimulationError(t, f"load continuation: {max_steps} steps, reached {lg:.3g} x weight")
