"""Static equilibrium and linearized free vibration of a model.

Static equilibrium solves the reduced force balance P^T F(t, Q(z), 0) = 0 by Newton's method
with a finite-difference tangent (the models here have at most a few hundred coordinates).
Linearized modes solve K phi = omega^2 M phi with K = -dF_r/dz at the equilibrium.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from .errors import SimulationError
from .model import Model


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
    from .constraints import constraint_terms

    def parts(zz):
        Q, _ = model.full_state(t, zz, np.zeros_like(zz))
        _, F = model.mass_force(t, Q, np.zeros_like(Q), mass=False)
        phi, J, _, _ = constraint_terms(model.nonlinear, t, Q, np.zeros_like(Q))
        return model.P.T @ F, phi, J @ model.P
    return parts


def constrained_static_equilibrium(model: Model, z0: np.ndarray, t: float = 0.0,
                                   tol: float = 1e-7, max_iter: int = 30):
    """Static equilibrium with nonlinear constraints: P^T F(z) + C(z)^T lambda = 0, Phi(z) = 0.

    Newton on (z, lambda) with a central-difference tangent of the force part (the constraint
    Jacobian C is analytic).  Returns (z, lambda); lambda are the static constraint reactions
    (e.g. the luffing-cylinder force).  Converged when the force residual is below tol times
    the largest applied generalized force and |Phi| < 1e-10 m, or when the update stalls at
    round-off.
    """
    z = np.array(z0, float)
    n = len(z)
    parts = static_parts(model, t)
    Fr, phi, C = parts(z)
    lam = np.linalg.lstsq(C.T, -Fr, rcond=None)[0]
    scale = max(np.linalg.norm(Fr), 1.0)
    for _ in range(max_iter):
        r1 = Fr + C.T @ lam
        if np.linalg.norm(r1) <= tol * scale and np.max(np.abs(phi), initial=0.0) < 1e-10:
            return z, lam
        # central differences: the Newton system of stiff booms is dominated by cancellation
        # (entries EA/l ~ 1e13 N/m against residuals ~ 1e5 N), and the O(h) truncation error of
        # forward differences (~1e-6 relative) made the Newton step useless at 8 sub-elements
        # (benchmarks/diagnose_static_tangent.py); the O(h^2) error of central ones does not
        h = 1e-6 * max(1.0, float(np.max(np.abs(z))))
        K = np.empty((n, n))
        for j in range(n):
            zj = z.copy()
            zj[j] += h
            Fp, _, Cp = parts(zj)
            zj[j] -= 2 * h
            Fm, _, Cm = parts(zj)
            K[:, j] = ((Fp + Cp.T @ lam) - (Fm + Cm.T @ lam)) / (2 * h)
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
    raise SimulationError(t, "constrained static equilibrium: Newton did not converge "
                             f"(|r| = {np.linalg.norm(Fr + C.T @ lam):.3g} N, |phi| = {np.max(np.abs(phi)):.3g})")
