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

Error-controlled steps (:func:`run_adaptive`, used where the scene gives no ``h``): the local
position error e_q = c_q h² (q̈_{n+1} - q̈_n) of
:mod:`sim_core.integrate.generalized_alpha` (the generalized-α form of the Newmark estimator
of Zienkiewicz & Xie 1991), its RMS over atol + rtol max(|q_n|, |q_{n+1}|), accept at <= 1,
h_new = h clip(safety err^(-1/3), fac_min, fac_max) with Gustafsson's predictive factor (as the
numpy reference's controller).  The tangent (M, K, C) is kept apart
from the inverse iteration matrix, so a new h costs one n x n inverse of
S = M + β' h² K + γ' h C, not a tangent; h is kept where the controller proposes a factor in
[1, 1.2) (RADAU5's rule, Hairer & Wanner, Solving ODEs II, Sect. IV.8).  Outputs come from the
cubic Hermite interpolants of the step (q from (q, v), v from (v, q̈): the numpy reference's
``_hermite``), so the steps are free of the output grid; the last step lands on t_end.

The numpy reference is :func:`sim_core.integrate.generalized_alpha.integrate_generalized_alpha`
with the same parameters (``tests/integrators/test_alpha_method.py`` compares both).
"""

from __future__ import annotations

import numpy as np

from sim_core._numba import AVAILABLE, numba
from sim_core.physics import _effects_numba as ec

OK, NEWTON_FAILED, STEP_TOO_SMALL, PAUSED = 0, 1, 2, 3   # return codes


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
                                            gravity, cstep, no_acc, True)
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
def _work_arrays(N, nr):
    """The compiled loops' work arrays: zeros (N,) (the lift's base for rates and
    accelerations), the full state Q, Q_dot, Q_ddot (N,) and the step's q_ddot_{n+1} iterate
    and (q, v, a)_{n+1} (nr,)."""
    return (np.zeros(N), np.empty(N), np.empty(N), np.empty(N), np.empty(nr), np.empty(nr),
            np.empty(nr), np.empty(nr))


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
    zeroN, Q, Qd, Qdd, x, qn, vn, an = _work_arrays(N, nr)
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
        iters = 0
        rate = 0.0
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
                # predictor: q̈_{n+1} = q̈_n, or linear extrapolation 2 q̈_n - q̈_{n-1}
                x[i] = qdd[i] + predictor * (qdd[i] - qdd_prev[i])
            converged, eta, iters, rate = _newton(
                q, v, qdd, a, h, am, af, beta, gamma, newton_atol, max_iter, Sinv, eta, Qp,
                rows, sgn, eidx, red, sg, n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w, q_pos,
                q_drows, bases, i_s1, rhoAs, Jrots, Ds, hf, grav, inertia, elasticity,
                gravity, cstep, x, qn, vn, an, stats)
            if converged:
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
            a[i] = an[i]
            q[i] = qn[i]
            v[i] = vn[i]
            qdd_prev[i] = qdd[i]
            qdd[i] = x[i]
        fresh = False
        stats[0] += 1
        if iters >= 3 and rate > refresh_rate:
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


@_jit
def _newton(q, v, qdd, a, h, am, af, beta, gamma, newton_atol, max_iter, Sinv, eta_in, Qp,
            rows, sgn, eidx, red, sg, n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w, q_pos, q_drows,
            bases, i_s1, rhoAs, Jrots, Ds, hf, grav, inertia, elasticity, gravity, cstep,
            x, qn, vn, an, stats):
    """One generalized-α step of size h from (q, v, q̈, a) by Newton's iteration on q̈_{n+1}
    from the starting iterate in x (the caller's predictor), with the inverse iteration matrix
    Sinv and the RADAU5 stop test (module doc).  Writes q̈_{n+1} into x and (q, v, a)_{n+1}
    into (qn, vn, an).  Returns (converged, eta, iterations, contraction rate)."""
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
    qb = np.empty(nr)
    vb = np.empty(nr)
    ac = np.empty(nr)
    for i in range(nr):
        ac[i] = c * (af * qdd[i] - am * a[i])
        qb[i] = q[i] + h * v[i] + h * h * ((0.5 - beta) * a[i] + beta * ac[i])
        vb[i] = v[i] + h * ((1.0 - gamma) * a[i] + gamma * ac[i])
    eta = max(eta_in, 2.2e-16) ** 0.8
    dnorm_old = -1.0
    rate = 0.0
    for k in range(max_iter):
        stats[2] += 1
        stats[1] += 1
        for i in range(nr):
            qn[i] = qb[i] + bq * x[i]
            vn[i] = vb[i] + bv * x[i]
        lift(qn, Qp, rows, sgn, Q)
        lift(vn, zeroN, rows, sgn, Qd)
        lift(x, zeroN, rows, sgn, Qdd)
        residual(Q, Qd, Qdd, eidx, red, sg, nr, n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w,
                 q_pos, q_drows, bases, i_s1, rhoAs, Jrots, Ds, hf, grav, inertia, elasticity,
                 gravity, cstep, r)
        dnorm = 0.0
        for i in range(nr):
            s = 0.0
            for j in range(nr):
                s += Sinv[i, j] * r[j]
            dx[i] = s
            if not np.isfinite(s):
                return False, eta, k + 1, rate
            w = newton_atol + 1e-15 * (abs(qb[i]) + abs(bq * x[i]))
            d = abs(bq * s) / w
            if d > dnorm:
                dnorm = d
        for i in range(nr):
            x[i] += dx[i]
        if dnorm_old > 0.0:
            rate = dnorm / dnorm_old
            if rate >= 1.0 or rate ** (max_iter - k) / (1.0 - rate) * dnorm > 1.0:
                return False, eta, k + 1, rate
            eta = rate / (1.0 - rate)
        if dnorm == 0.0 or eta * dnorm <= 1.0:
            for i in range(nr):
                qn[i] = qb[i] + bq * x[i]
                vn[i] = vb[i] + bv * x[i]
                an[i] = ac[i] + c * (1.0 - af) * x[i]
            return True, eta, k + 1, rate
        dnorm_old = dnorm
    return False, eta, max_iter, rate


@_jit
def run_adaptive(q, v, qdd, a, hs, t_out, k_out, max_steps, am, af, beta, gamma, c_err, rtol,
                 atol, safety, fac_min, fac_max, h_min, h_max, t_end, newton_atol, max_iter,
                 refresh_rate, rel_step, Qp, rows, sgn, eidx, red, sg, n, q_phi, q_psi, pow_p,
                 pow_t, q_ds, q_w, q_pos, q_drows, bases, i_s1, rhoAs, Jrots, Ds, hf, grav,
                 inertia, elasticity, gravity, cstep, no_acc, Y_out, stats, Mr, Kr, Cr, Sinv,
                 carry):
    """Error-controlled generalized-α steps (module doc) from hs[0] until t_end or
    ``max_steps`` accepted steps, writing the Hermite-interpolated states (q, v) at the output
    times t_out[k_out:] that the steps pass into Y_out's rows.

    In place: (q, v, q̈, a) the state and auxiliary acceleration; hs (float) = [t, next h,
    step that a belongs to (0: none), h of Sinv (0: none), smallest step, largest step (the
    step landing on t_end not counted), error of the last accepted step (0: none; for
    Gustafsson's predictive factor, as RADAU5 and the numpy reference)]; (Mr, Kr, Cr) the tangent and Sinv the inverse
    iteration matrix; carry = [tangent valid (1/0), Newton's eta, last attempt rejected
    (1/0)].  stats (int64): [steps, residuals, Newton iterations, tangents, inversions, failed
    Newton attempts, rejected steps (error test or Newton), ...].  A Newton failure forms the
    tangent at the current state and retries; with a fresh tangent it cuts h by 4.  Returns
    (code, k_out): OK at t_end, PAUSED after max_steps steps, NEWTON_FAILED where the state is
    not finite, STEP_TOO_SMALL where h would fall below h_min (hs[1] holds it)."""
    nr = q.shape[0]
    n_out = t_out.shape[0]
    N = Qp.shape[0]
    zeroN, Q, Qd, Qdd, x, qn, vn, an = _work_arrays(N, nr)
    ash = np.empty(nr)
    bqc = beta * (1.0 - af) / (1.0 - am)
    bvc = gamma * (1.0 - af) / (1.0 - am)
    done = 0
    fresh = False
    while hs[0] < t_end:
        if done >= max_steps:
            return PAUSED, k_out
        t = hs[0]
        h = hs[1]
        last = t + h >= t_end
        h_try = t_end - t if last else h
        if carry[0] < 0.5:
            lift(q, Qp, rows, sgn, Q)
            lift(v, zeroN, rows, sgn, Qd)
            lift(qdd, zeroN, rows, sgn, Qdd)
            M_, K_, C_, F_ = mass_tangent(Q, Qd, Qdd, rel_step, eidx, red, sg, nr, n, q_phi,
                                          q_psi, pow_p, pow_t, q_ds, q_w, q_pos, q_drows, bases,
                                          i_s1, rhoAs, Jrots, Ds, hf, grav, inertia, elasticity,
                                          gravity, cstep, no_acc)
            Mr[:, :] = M_
            Kr[:, :] = K_
            Cr[:, :] = C_
            stats[3] += 1
            carry[0] = 1.0
            hs[3] = 0.0
            fresh = True
        if h_try != hs[3]:
            Sinv[:, :] = np.linalg.inv(Mr + (bqc * h_try * h_try) * Kr + (bvc * h_try) * Cr)
            stats[4] += 1
            hs[3] = h_try
        # a_n belongs to the step hs[2]: moved to h_try by a_n ≈ q̈(t_n + Δα h) (reference)
        ratio = 1.0 if hs[2] == 0.0 else h_try / hs[2]
        for i in range(nr):
            ash[i] = qdd[i] + ratio * (a[i] - qdd[i])
            x[i] = qdd[i]                          # predictor: q̈_{n+1} = q̈_n
        ok, eta, iters, rate = _newton(q, v, qdd, ash, h_try, am, af, beta, gamma, newton_atol,
                                       max_iter, Sinv, carry[1], Qp, rows, sgn, eidx, red, sg,
                                       n, q_phi, q_psi, pow_p, pow_t, q_ds, q_w, q_pos, q_drows,
                                       bases, i_s1, rhoAs, Jrots, Ds, hf, grav, inertia,
                                       elasticity, gravity, cstep, x, qn, vn, an, stats)
        carry[1] = eta
        if not ok:
            stats[5] += 1
            if not fresh:
                carry[0] = 0.0                  # a tangent at this state, same h
                continue
            stats[6] += 1
            carry[2] = 1.0
            hs[1] = 0.25 * h_try
            if hs[1] < h_min:
                return STEP_TOO_SMALL, k_out
            continue
        ssum = 0.0
        finite = True
        for i in range(nr):
            w = atol + rtol * max(abs(q[i]), abs(qn[i]))
            e = c_err * h_try * h_try * (x[i] - qdd[i]) / w
            ssum += e * e
            if not (np.isfinite(qn[i]) and np.isfinite(vn[i])):
                finite = False
        if not finite:
            return NEWTON_FAILED, k_out
        err = np.sqrt(ssum / nr)
        if err > 1.0:
            stats[6] += 1
            carry[2] = 1.0
            hs[1] = h_try * max(fac_min, min(1.0, safety * err ** (-1.0 / 3.0)))
            if hs[1] < h_min:
                return STEP_TOO_SMALL, k_out
            continue
        # accepted: outputs in (t, t + h_try] from the step's cubic Hermite interpolants
        t_new = t_end if last else t + h_try
        while k_out < n_out and t_out[k_out] <= t_new:
            s = (t_out[k_out] - t) / h_try
            if s >= 1.0:
                for i in range(nr):
                    Y_out[k_out, i] = qn[i]
                    Y_out[k_out, nr + i] = vn[i]
            else:
                h00 = (2.0 * s - 3.0) * s * s + 1.0
                h10 = ((s - 2.0) * s + 1.0) * s
                h01 = (3.0 - 2.0 * s) * s * s
                h11 = (s - 1.0) * s * s
                for i in range(nr):
                    Y_out[k_out, i] = (h00 * q[i] + h_try * h10 * v[i] + h01 * qn[i]
                                       + h_try * h11 * vn[i])
                    Y_out[k_out, nr + i] = (h00 * v[i] + h_try * h10 * qdd[i] + h01 * vn[i]
                                            + h_try * h11 * x[i])
            k_out += 1
        for i in range(nr):
            q[i] = qn[i]
            v[i] = vn[i]
            a[i] = an[i]
            qdd[i] = x[i]
        h_prev_acc = hs[2]
        hs[0] = t_new
        hs[2] = h_try
        stats[0] += 1
        done += 1
        fresh = False
        if not last:
            hs[4] = min(hs[4], h_try)
            hs[5] = max(hs[5], h_try)
        if iters > 2 and rate > refresh_rate:
            carry[0] = 0.0                      # slow contraction: a new tangent next step
        # Gustafsson's predictive factor (RADAU5; the numpy reference's controller)
        pred = 1.0
        if hs[6] > 0.0 and err > 0.0 and h_prev_acc > 0.0:
            pred = min(1.0, (h_try / h_prev_acc) * (hs[6] / err) ** (1.0 / 3.0))
        hs[6] = max(err, 1e-10)
        fac = fac_max if err == 0.0 else min(fac_max, safety * pred * err ** (-1.0 / 3.0))
        if carry[2] > 0.5:
            fac = min(fac, 1.0)                 # no growth right after a rejection
        if 1.0 <= fac < 1.2:
            fac = 1.0                           # keep h and the inverse (module doc)
        hs[1] = min(h_max, h_try * max(fac_min, fac)) if not last else h
        carry[2] = 0.0
    return OK, k_out
