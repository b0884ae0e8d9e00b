"""The generalized-alpha step loop of beam models in one compiled call.

The scheme of :mod:`sim_core.integrate.generalized_alpha` (Chung & Hulbert 1993; the form of
Arnold & Bruels 2007 with the true accelerations as Newton unknowns), at a fixed step, for the
models :meth:`sim_core.model.model.Model.element_loop_plan` covers (every force in the compiled
element batch, constant selecting boundary conditions):

* the residual r(x) = P^T [F(Q, Q_dot) - M(Q) Q_ddot] comes from the element kernel
  (:mod:`sim_core.physics._effects_numba`, with the accelerations: M Q_ddot through the
  kernel's weighted rows, the mass matrix never formed), called from the loop: no Python and no
  allocation between steps.  The physics is the model's, nonlinear and unchanged;
* the iteration matrix S = M + beta' h^2 K + gamma' h C (Arnold & Bruels 2007, Sect. 3) uses the
  structured tangent (per-element forward differences of the same kernel, as
  :mod:`sim_core.model.state_jacobian`), inverted once and reused across steps; it is formed
  again only where Newton contracts slowly (rate > ``refresh_rate``) or fails;
* Newton stops by the test of RADAU5 (Hairer & Wanner, Solving ODEs II, Sect. IV.8):
  eta |dq| <= 1, eta = theta / (1 - theta) carried over between steps, |dq| the largest
  position increment over ``newton_atol`` (m) + 1e-15 |q| (the second term keeps the test above
  the coordinates' roundoff).

The numpy reference is :func:`sim_core.integrate.generalized_alpha.integrate_generalized_alpha`
with the same parameters (``tests/integrators/test_alpha_method.py`` compares both).
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba
from sim_core.physics import _effects_numba as ec

OK, NEWTON_FAILED = 0, 1            # return codes of run_steps


def _identity(f):
    return f


_jit = numba.njit(cache=True) if AVAILABLE else _identity


@_jit
def lift(x, base, rows, sgn, out):
    """out = base + P x for a selection P (out[rows] += sgn x)."""
    out[:] = base
    for i in range(rows.shape[0]):
        out[rows[i]] += sgn[i] * x[i]


@_jit
def residual(Q, Qd, Qdd, eidx, red, sg, n_red, n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w,
              q_pos, q_drows, bases, i_s1, rhoAs, Jrots, Ds, hf, grav, inertia, elasticity,
              gravity, cstep, r):
    """r = P^T [F(Q, Q̇) - M(Q) Q̈] (reduced, N) from the element kernel, one call per element."""
    for i in range(n_red):
        r[i] = 0.0
    E, nq = eidx.shape
    qe = np.empty(nq)
    qde = np.empty(nq)
    qdde = np.empty(nq)
    for e in range(E):
        for k in range(nq):
            j = eidx[e, k]
            qe[k] = Q[j]
            qde[k] = Qd[j]
            qdde[k] = Qdd[j]
        Fe = ec.mass_force_kernel(qe, qde, n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w, q_pos,
                                     q_drows, bases[e], i_s1, rhoAs[e], Jrots[e], Ds[e], hf,
                                     grav, inertia, elasticity, gravity, False, cstep, qdde)[1]
        for k in range(nq):
            j = red[eidx[e, k]]
            if j >= 0:
                r[j] += sg[eidx[e, k]] * Fe[k]


@_jit
def mass_tangent(Q, Qd, Qdd, rel_step, eidx, red, sg, n_red, n, q_phi, q_psi, pow_p, pow_t,
                  q_ds, q_w, q_pos, q_drows, bases, i_s1, rhoAs, Jrots, Ds, hf, grav, inertia,
                  elasticity, gravity, cstep, no_acc):
    """(M_r, K_r, C_r, F_r) at (Q, Q̇, Q̈): reduced mass matrix (kg), K = -P^T ∂(F - M Q̈)/∂Q P
    (N/m), C = -P^T ∂F/∂Q̇ P (N s/m) by the structured per-element forward differences
    (step rel_step max(|x|, 1), exactly representable), F_r = P^T F (N)."""
    E, nq = eidx.shape
    QE = np.empty((E, nq))
    QDE = np.empty((E, nq))
    QDDE = np.empty((E, nq))
    HQ = np.empty((E, nq))
    HQD = np.empty((E, nq))
    for e in range(E):
        for k in range(nq):
            j = eidx[e, k]
            QE[e, k] = Q[j]
            QDE[e, k] = Qd[j]
            QDDE[e, k] = Qdd[j]
            hq = rel_step * max(abs(Q[j]), 1.0)
            HQ[e, k] = (Q[j] + hq) - Q[j]
            hv = rel_step * max(abs(Qd[j]), 1.0)
            HQD[e, k] = (Qd[j] + hv) - Qd[j]
    Ms, Fs = ec.mass_force_batch_kernel(QE, QDE, n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w,
                                           q_pos, q_drows, bases, i_s1, rhoAs, Jrots, Ds, hf,
                                           grav, inertia, elasticity, gravity, cstep, no_acc)
    DP, DR = ec.differences_batch_kernel(QE, QDE, QDDE, HQ, HQD, n, q_phi, q_psi, pow_p,
                                            pow_t, q_ds, q_w, q_pos, q_drows, bases, i_s1,
                                            rhoAs, Jrots, Ds, hf, grav, inertia, elasticity,
                                            gravity, cstep, no_acc)
    Mr = np.zeros((n_red, n_red))
    Kr = np.zeros((n_red, n_red))
    Cr = np.zeros((n_red, n_red))
    Fr = np.zeros(n_red)
    for e in range(E):
        for a in range(nq):
            ia = red[eidx[e, a]]
            if ia < 0:
                continue
            sa = sg[eidx[e, a]]
            Fr[ia] += sa * Fs[e, a]
            for b in range(nq):
                ib = red[eidx[e, b]]
                if ib < 0:
                    continue
                s = sa * sg[eidx[e, b]]
                Mr[ia, ib] += s * Ms[e, a, b]
                Kr[ia, ib] -= s * DP[e, a, b]
                Cr[ia, ib] -= s * DR[e, a, b]
    return Mr, Kr, Cr, Fr


@_jit
def run_steps(q, v, qdd, a, n_steps, h, am, af, beta, gamma, newton_atol, max_iter, refresh_rate,
         rel_step, record_every, predictor, Qp, rows, sgn, eidx, red, sg, n, q_phi, q_psi, pow_p, pow_t,
         q_ds, q_w, q_pos, q_drows, bases, i_s1, rhoAs, Jrots, Ds, hf, grav, inertia,
         elasticity, gravity, cstep, no_acc, Q_out, V_out, A_out, stats, Sinv, qdd_prev, carry):
    """Fixed-step generalized-α loop (module doc).  (q, v, qdd, a): state and auxiliary
    acceleration at t0, updated in place.  (Sinv, qdd_prev, carry): the inverse iteration
    matrix, the previous accelerations and [Sinv valid (1.0/0.0), Newton's eta], carried
    from one call to the next in place, so a run may be split into calls (outputs, progress,
    wall budget) without forming the tangent again.  predictor: 0.0 starts Newton from q̈_n, 1.0 from
    the linear extrapolation 2 q̈_n - q̈_{n-1}.  Records every ``record_every``-th step into
    Q_out, V_out, A_out (row 0 = initial state).  stats (int64): [steps, residuals,
    Newton iterations, tangents, inversions, failed attempts].  Returns (code, steps done)."""
    nr = q.shape[0]
    N = Qp.shape[0]
    bq = beta * (1.0 - af) / (1.0 - am) * h * h
    bv = gamma * (1.0 - af) / (1.0 - am) * h
    c = 1.0 / (1.0 - am)
    zeroN = np.zeros(N)
    Q = np.empty(N)
    Qd = np.empty(N)
    Qdd = np.empty(N)
    r = np.empty(nr)
    dx = np.empty(nr)
    x = np.empty(nr)
    qb = np.empty(nr)
    vb = np.empty(nr)
    ac = np.empty(nr)
    qn = np.empty(nr)
    vn = np.empty(nr)
    fresh = False           # tangent formed at the current accepted state
    have = carry[0] > 0.5   # Sinv valid
    eta = carry[1]
    k_out = 1
    for i in range(nr):
        Q_out[0, i] = q[i]
        V_out[0, i] = v[i]
        A_out[0, i] = qdd[i]
    for step in range(n_steps):
        converged = False
        for attempt in range(2):
            if not have:
                lift(q, Qp, rows, sgn, Q)
                lift(v, zeroN, rows, sgn, Qd)
                lift(qdd, zeroN, rows, sgn, Qdd)
                Mr, Kr, Cr, Fr = mass_tangent(Q, Qd, Qdd, rel_step, eidx, red, sg, nr, n,
                                               q_phi, q_psi, pow_p, pow_t, q_ds, q_w, q_pos,
                                               q_drows, bases, i_s1, rhoAs, Jrots, Ds, hf,
                                               grav, inertia, elasticity, gravity, cstep,
                                               no_acc)
                Sinv[:, :] = np.linalg.inv(Mr + bq * Kr + bv * Cr)
                stats[3] += 1
                stats[4] += 1
                have = True
                fresh = True
            for i in range(nr):
                ac[i] = c * (af * qdd[i] - am * a[i])
                qb[i] = q[i] + h * v[i] + h * h * ((0.5 - beta) * a[i] + beta * ac[i])
                vb[i] = v[i] + h * ((1.0 - gamma) * a[i] + gamma * ac[i])
                # predictor: q̈_{n+1} = q̈_n, or linear extrapolation 2 q̈_n - q̈_{n-1}
                x[i] = qdd[i] + predictor * (qdd[i] - qdd_prev[i])
            eta = max(eta, 2.2e-16) ** 0.8
            dnorm_old = -1.0
            rate = 0.0
            ok = False
            for k in range(max_iter):
                stats[2] += 1
                stats[1] += 1
                for i in range(nr):
                    qn[i] = qb[i] + bq * x[i]
                    vn[i] = vb[i] + bv * x[i]
                lift(qn, Qp, rows, sgn, Q)
                lift(vn, zeroN, rows, sgn, Qd)
                lift(x, zeroN, rows, sgn, Qdd)
                residual(Q, Qd, Qdd, eidx, red, sg, nr, n, q_phi, q_psi, pow_p, pow_t, q_ds,
                          q_w, q_pos, q_drows, bases, i_s1, rhoAs, Jrots, Ds, hf, grav,
                          inertia, elasticity, gravity, cstep, r)
                dnorm = 0.0
                finite = True
                for i in range(nr):
                    s = 0.0
                    for j in range(nr):
                        s += Sinv[i, j] * r[j]
                    dx[i] = s
                    if not np.isfinite(s):
                        finite = False
                    w = newton_atol + 1e-15 * (abs(qb[i]) + abs(bq * x[i]))
                    d = abs(bq * s) / w
                    if d > dnorm:
                        dnorm = d
                if not finite:
                    break
                for i in range(nr):
                    x[i] += dx[i]
                if dnorm_old > 0.0:
                    rate = dnorm / dnorm_old
                    if rate >= 1.0 or rate ** (max_iter - k) / (1.0 - rate) * dnorm > 1.0:
                        break
                    eta = rate / (1.0 - rate)
                if dnorm == 0.0 or eta * dnorm <= 1.0:
                    ok = True
                    break
                dnorm_old = dnorm
            if ok:
                converged = True
                break
            stats[5] += 1
            if fresh:
                break
            have = False                           # retry with a tangent at this state
        if not converged:
            carry[0] = 0.0
            carry[1] = eta
            return NEWTON_FAILED, step
        for i in range(nr):
            a[i] = ac[i] + c * (1.0 - af) * x[i]
            q[i] = qb[i] + bq * x[i]
            v[i] = vb[i] + bv * x[i]
            qdd_prev[i] = qdd[i]
            qdd[i] = x[i]
        fresh = False
        stats[0] += 1
        if k >= 2 and rate > refresh_rate:
            have = False                           # slow contraction: new tangent next step
        if (step + 1) % record_every == 0:
            for i in range(nr):
                Q_out[k_out, i] = q[i]
                V_out[k_out, i] = v[i]
                A_out[k_out, i] = qdd[i]
            k_out += 1
    carry[0] = 1.0 if have else 0.0
    carry[1] = eta
    return OK, n_steps
