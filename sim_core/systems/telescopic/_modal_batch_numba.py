"""Compiled kernels of the batched modal ROM: one loop over the cranes doing, crane by crane,
what the array code of :mod:`sim_core.systems.telescopic.modal_batch` does for all at once (that
code is the reference; tests/env/test_v1_rom.py compares both).

* :func:`step_all`: the stroke kinematics over one control interval (velocity saturation,
  inelastic end stops, segment by segment) and the exact modal step of
  ``modal.ModalROM.advance`` for every segment (``BatchROM.step``);
* :func:`outputs_all`: tip deflection and sway with their rates (``BatchROM.outputs``);
* :func:`coupled_modes`: the coupled pendulum-boom eigenproblem K Phi = M Phi Lambda at every
  grid point of every crane with continuous signs along L_s and the coupled modal quantities
  (``modal_batch.coupled_tables``).
"""

from __future__ import annotations

import math

import numpy as np

from sim_core._numba import AVAILABLE, numba


def _interval(grid, L):
    """(i, w): interval and weight of L (clipped to the grid) as ModalTables._w."""
    n = grid.shape[0]
    if L < grid[0]:
        L = grid[0]
    elif L > grid[n - 1]:
        L = grid[n - 1]
    lo, hi = 0, n                                   # searchsorted(side="right") - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if grid[mid] <= L:
            lo = mid + 1
        else:
            hi = mid
    i = lo - 1
    if i > n - 2:
        i = n - 2
    if i < 0:
        i = 0
    return i, (L - grid[i]) / (grid[i + 1] - grid[i])


def _first_hit(L, v, a, stop):
    """Smallest t > 0 with L + v t + a t^2 / 2 = stop moving towards it (inf if never)."""
    if (stop > L and v <= 0 and a <= 0) or (stop < L and v >= 0 and a >= 0) or stop == L:
        return np.inf
    if abs(a) < 1e-15:
        if v != 0:
            t = (stop - L) / v
            return t if t > 0 else np.inf
        return np.inf
    disc = v * v + 2 * a * (stop - L)
    if disc < 0:
        return np.inf
    r = math.sqrt(disc)
    q = -(v + math.copysign(r, v))
    best = np.inf
    c1 = q / a
    if c1 > 1e-15:
        best = c1
    if q != 0.0:
        c2 = 2.0 * (L - stop) / q
        if c2 > 1e-15 and c2 < best:
            best = c2
    return best


def _piston_segment(Lk, vk, ak, t_left, vmax, Lmin, Lmax):
    """The next piece of constant piston acceleration within t_left (s) from (L_s, v): the
    commanded acceleration ak cut to 0 at the rate limit |v| = vmax and against an end stop
    it rests on; its duration tau ends at t_left, at the rate limit (after t_v) or at an end
    stop (after t_s).  Returns (acceleration, tau, t_v, t_s, saturated, stopped)."""
    ae = ak
    sat = False
    stop = False
    if (vk >= vmax - 1e-12 and ak > 0) or (vk <= -vmax + 1e-12 and ak < 0):
        ae = 0.0
        sat = True
    if ((Lk >= Lmax - 1e-12 and vk >= 0) and ae > 0) or \
            ((Lk <= Lmin + 1e-12 and vk <= 0) and ae < 0):
        ae = 0.0
        stop = True
    t_v = np.inf
    if ae > 0:
        t_v = (vmax - vk) / ae
    elif ae < 0:
        t_v = (-vmax - vk) / ae
    t_s = min(_first_hit(Lk, vk, ae, Lmax), _first_hit(Lk, vk, ae, Lmin))
    tau = min(min(t_left, t_v), t_s)
    return ae, tau, t_v, t_s, sat, stop


def _at_rest_unforced(fin, g, kk, b1, qj, qdj):
    """Whether a mode is at rest (q = q' = 0) without forcing (Gamma = K2 = b1 = 0, finite
    stroke inputs ``fin``) over a step: it then stays at rest exactly (the out-of-plane
    pendulum without a start sway), and the step skips its exponential and trigonometric
    functions (their result would be zero; only the sign of a zero can differ)."""
    return fin and g == 0.0 and kk == 0.0 and b1 == 0.0 and qj == 0.0 and qdj == 0.0


def _advance(dyn, grid, k, L, v0, a, tau, q, qd):
    """ModalROM.advance of crane k over tau at acceleration a from (L, v0): q, qd in place."""
    i, w = _interval(grid, L + 0.5 * v0 * tau + 0.125 * a * tau * tau)
    nc = q.shape[1]
    fin = math.isfinite(a) and math.isfinite(v0) and math.isfinite(tau)
    for j in range(nc):
        g = (1 - w) * dyn[k, i, 2, j] + w * dyn[k, i + 1, 2, j]
        kk = (1 - w) * dyn[k, i, 3, j] + w * dyn[k, i + 1, 3, j]
        b1 = (1 - w) * dyn[k, i, 4, j] + w * dyn[k, i + 1, 4, j]
        if _at_rest_unforced(fin, g, kk, b1, q[k, j], qd[k, j]):
            continue
        om = (1 - w) * dyn[k, i, 0, j] + w * dyn[k, i + 1, 0, j]
        z = (1 - w) * dyn[k, i, 1, j] + w * dyn[k, i + 1, 1, j]
        f0 = -g * a - kk * v0 * v0 + b1 * v0
        f1 = -2.0 * kk * v0 * a + b1 * a
        f2 = -kk * a * a
        w2 = om * om
        sig = z * om
        C = f2 / w2
        B = (f1 - 4.0 * sig * C) / w2
        A = (f0 - 2.0 * sig * B - 2.0 * C) / w2
        x0 = q[k, j] - A
        y0 = qd[k, j] - B
        wd = om * math.sqrt(1.0 - z * z)
        e = math.exp(-sig * tau)
        cs = math.cos(wd * tau)
        sn = math.sin(wd * tau)
        x = e * (x0 * cs + (y0 + sig * x0) / wd * sn)
        y = e * (y0 * cs - (w2 * x0 + sig * y0) / wd * sn)
        q[k, j] = x + A + B * tau + C * tau * tau
        qd[k, j] = y + B + 2.0 * C * tau


def step_all(L, v, q, qd, a, dyn, grid, dt, vmax, Lmin, Lmax, sat, stop, acc):
    """BatchROM.step for every crane: L, v, q, qd advanced in place; sat, stop (bool) and acc
    (mean applied acceleration, m/s^2) written."""
    for k in range(L.shape[0]):
        _step_one(k, L, v, q, qd, a, dyn, grid, dt, vmax, Lmin, Lmax, sat, stop, acc)


def step_all_out(L, v, q, qd, a, dyn, grid, dt, vmax, Lmin, Lmax, sat, stop, acc, out, defl,
                 sway):
    """step_all and then outputs_all in one pass over the cranes (each crane's tables are
    read while they are in cache): the same arithmetic as the two calls."""
    for k in range(L.shape[0]):
        _step_one(k, L, v, q, qd, a, dyn, grid, dt, vmax, Lmin, Lmax, sat, stop, acc)
        _outputs_one(k, L[k], q, qd, out, grid, defl, sway, k)


def _step_one(k, L, v, q, qd, a, dyn, grid, dt, vmax, Lmin, Lmax, sat, stop, acc):
    """step_all for crane k."""
    nc = q.shape[1]
    Lk, vk, ak = L[k], v[k], a[k]
    t_left = dt
    s_sat = False
    s_stop = False
    dv = 0.0
    for _ in range(8):
        if t_left <= 1e-12:
            break
        ae, tau, t_v, t_s, sat_k, stop_k = _piston_segment(Lk, vk, ak, t_left, vmax, Lmin,
                                                           Lmax)
        s_sat = s_sat or sat_k
        s_stop = s_stop or stop_k
        if tau > 0:
            _advance(dyn, grid, k, Lk, vk, ae, tau, q, qd)
        L1 = Lk + vk * tau + 0.5 * ae * tau * tau
        v1 = vk + ae * tau
        if tau == t_s and tau < t_left + 1e-15:
            L1 = min(max(L1, Lmin), Lmax)
            jump = -v1
            v1 = 0.0
            s_stop = True
            i, w = _interval(grid, L1)
            for j in range(nc):
                gam = (1 - w) * dyn[k, i, 2, j] + w * dyn[k, i + 1, 2, j]
                qd[k, j] -= gam * jump
        elif tau == t_v:
            v1 = math.copysign(vmax, v1)
            s_sat = True
        dv += ae * tau
        t_left = t_left - tau
        Lk, vk = L1, v1
    if t_left > 1e-12:                           # pathological: hold the remainder
        _advance(dyn, grid, k, Lk, vk, 0.0, t_left, q, qd)
        Lk = Lk + vk * t_left
    L[k] = min(max(Lk, Lmin), Lmax)
    v[k] = vk
    sat[k] = s_sat
    stop[k] = s_stop
    acc[k] = dv / dt


def _advance_exp(dyn, grid, k, Lmid, a, v0, abar, tau, lam, Bl2, q, qd, el):
    """Exact modal step of crane k over tau for the forcing
    -Gamma a - K2 v^2 + b1 v - Gamma Re(Bl2 e^(lam t)), v = v0 + abar t (the stroke rate's
    chord over the piece) and the stage's hydraulic transient Re(Bl2 e^(lam t)) = e''(t)
    (lam complex; Bl2 = 0: the polynomial forcing of ModalROM.advance).  Coefficients at
    Lmid; el = e^(lam tau)."""
    i, w = _interval(grid, Lmid)
    nc = q.shape[1]
    fin = (math.isfinite(a) and math.isfinite(v0) and math.isfinite(abar)
           and math.isfinite(tau) and math.isfinite(Bl2.real) and math.isfinite(Bl2.imag))
    for j in range(nc):
        g = (1 - w) * dyn[k, i, 2, j] + w * dyn[k, i + 1, 2, j]
        kk = (1 - w) * dyn[k, i, 3, j] + w * dyn[k, i + 1, 3, j]
        b1 = (1 - w) * dyn[k, i, 4, j] + w * dyn[k, i + 1, 4, j]
        if _at_rest_unforced(fin, g, kk, b1, q[k, j], qd[k, j]):
            continue
        om = (1 - w) * dyn[k, i, 0, j] + w * dyn[k, i + 1, 0, j]
        z = (1 - w) * dyn[k, i, 1, j] + w * dyn[k, i + 1, 1, j]
        f0 = -g * a - kk * v0 * v0 + b1 * v0
        f1 = -2.0 * kk * v0 * abar + b1 * abar
        f2 = -kk * abar * abar
        w2 = om * om
        sig = z * om
        C = f2 / w2
        B = (f1 - 4.0 * sig * C) / w2
        A = (f0 - 2.0 * sig * B - 2.0 * C) / w2
        H = -g * Bl2 / (lam * lam + 2.0 * sig * lam + w2)
        x0 = q[k, j] - A - H.real
        y0 = qd[k, j] - B - (H * lam).real
        wd = om * math.sqrt(1.0 - z * z)
        e = math.exp(-sig * tau)
        cs = math.cos(wd * tau)
        sn = math.sin(wd * tau)
        x = e * (x0 * cs + (y0 + sig * x0) / wd * sn)
        y = e * (y0 * cs - (w2 * x0 + sig * y0) / wd * sn)
        He = H * el
        q[k, j] = x + A + B * tau + C * tau * tau + He.real
        qd[k, j] = y + B + 2.0 * C * tau + (He * lam).real


def _advance_free(dyn, grid, k, L, tau, q, qd):
    """Exact modal step of crane k over tau without forcing (the stage held: L' = L'' = 0),
    coefficients at L: _advance_exp with a = v0 = abar = Bl2 = 0 in real arithmetic (its
    particular solution is then zero; the same operations on the homogeneous part)."""
    i, w = _interval(grid, L)
    nc = q.shape[1]
    for j in range(nc):
        x0 = q[k, j]
        y0 = qd[k, j]
        if x0 == 0.0 and y0 == 0.0 and math.isfinite(tau):
            continue                                   # at rest: stays at rest
        om = (1 - w) * dyn[k, i, 0, j] + w * dyn[k, i + 1, 0, j]
        z = (1 - w) * dyn[k, i, 1, j] + w * dyn[k, i + 1, 1, j]
        w2 = om * om
        sig = z * om
        wd = om * math.sqrt(1.0 - z * z)
        e = math.exp(-sig * tau)
        cs = math.cos(wd * tau)
        sn = math.sin(wd * tau)
        q[k, j] = e * (x0 * cs + (y0 + sig * x0) / wd * sn)
        qd[k, j] = e * (y0 * cs - (w2 * x0 + sig * y0) / wd * sn)


def _lag(u0, ud0, sig, wd, t):
    """(u, u') at t of the free damped oscillator u'' + 2 sig u' + (sig^2 + wd^2) u = 0."""
    e = math.exp(-sig * t)
    cs = math.cos(wd * t)
    sn = math.sin(wd * t)
    u = e * (u0 * cs + (ud0 + sig * u0) / wd * sn)
    ud = e * (ud0 * cs - ((sig * sig + wd * wd) * u0 + sig * ud0) / wd * sn)
    return u, ud


def _lag_exp(u0, ud0, sig, wd, t):
    """_lag and e^(lam t), lam = -sig + i wd: (u, u', e^(lam t)), the latter as cmath.exp
    forms it (exp(re) cos(im), exp(re) sin(im)) from the same three functions."""
    e = math.exp(-sig * t)
    cs = math.cos(wd * t)
    sn = math.sin(wd * t)
    u = e * (u0 * cs + (ud0 + sig * u0) / wd * sn)
    ud = e * (ud0 * cs - ((sig * sig + wd * wd) * u0 + sig * ud0) / wd * sn)
    return u, ud, complex(e * cs, e * sn)


def _breakaway(A0, A1, A2, lim, tmax):
    """Earliest t in (0, tmax] with |A0 + A1 t + A2 t^2| >= lim (inf if none); |A0| <= lim."""
    best = np.inf
    for sgn in (1.0, -1.0):
        c0 = A0 - sgn * lim
        if A2 == 0.0:
            if A1 != 0.0:
                t = -c0 / A1
                if t > 0.0 and t < best:
                    best = t
            continue
        disc = A1 * A1 - 4.0 * A2 * c0
        if disc < 0.0:
            continue
        r = math.sqrt(disc)
        qq = -0.5 * (A1 + math.copysign(r, A1))
        for t in (qq / A2, (c0 / qq) if qq != 0.0 else np.inf):
            if t > 0.0 and t < best:
                best = t
    return best if best <= tmax else np.inf


def _stage_piece(dyn, grid, ntab, k, xc, vc, ae, e, ed, stuck, sdir, tmax, Ms, kA, l0, zh,
                 mus, muk, q, qd, wf):
    """One stick or slip piece of crane k's stage within a commanded segment (piston at xc, vc
    with acceleration ae, at most tmax long).  Returns (tau, xc, vc, e, ed, stuck, sdir)."""
    L = xc + e
    i, w = _interval(grid, L)
    Nn = (1 - w) * ntab[k, i] + w * ntab[k, i + 1]
    kh = kA / (L + l0)
    ch = 2.0 * zh * math.sqrt(kh * Ms)
    if stuck:
        # hydraulic force on the held stage: kh (xc(t) - L) + ch vc(t), quadratic in t
        A0 = kh * (xc - L) + ch * vc
        A1 = kh * vc + ch * ae
        A2 = 0.5 * kh * ae
        tb = _breakaway(A0, A1, A2, mus * Nn, tmax)
        tau = min(tb, tmax)
        _advance_free(dyn, grid, k, L, tau, q, qd)
        xc1 = xc + vc * tau + 0.5 * ae * tau * tau
        vc1 = vc + ae * tau
        if tb <= tmax:
            F = A0 + A1 * tb + A2 * tb * tb
            return tau, xc1, vc1, L - xc1, -vc1, False, (1.0 if F > 0 else -1.0)
        return tau, xc1, vc1, L - xc1, -vc1, True, sdir
    # slip in direction sdir: e'' + (ch/M) e' + (kh/M) e = -ae - sdir muk N / M
    wh2 = kh / Ms
    sig = zh * math.sqrt(wh2)
    wd = math.sqrt(wh2) * math.sqrt(1.0 - zh * zh)
    ess = -(ae + sdir * muk * Nn / Ms) / wh2
    u0 = e - ess
    v0 = vc + ed
    # the stage stops where v = vc + ae t + e'(t) changes sign against sdir.  Over a piece
    # (<= dt = 0.05 s against the lag's period >= 0.75 s: omega_d tau <= 0.4) v is a quadratic
    # in t to ~(omega_d tau)^3 / 6 = 1 %: its values at the middle and the end bracket a sign
    # change, or the quadratic through v(0), v(tau/2), v(tau) dips below zero inside, where the
    # bisection then looks; the root is bisected on the exact v(t)
    tstop = np.inf
    tm = 0.5 * tmax
    vm = sdir * (vc + ae * tm + _lag(u0, ed, sig, wd, tm)[1])
    ue, ude, ele = _lag_exp(u0, ed, sig, wd, tmax)
    ve = sdir * (vc + ae * tmax + ude)
    va = sdir * v0
    lo, hi = -1.0, -1.0
    if vm <= 0.0:
        lo, hi = 0.0, tm
    elif ve <= 0.0:
        lo, hi = tm, tmax
    else:
        # quadratic through (0, va), (tm, vm), (tmax, ve): minimum inside and below zero?
        c2 = 2.0 * (va - 2.0 * vm + ve) / (tmax * tmax)
        c1 = (4.0 * vm - 3.0 * va - ve) / tmax
        if c2 > 0.0:
            ts = -c1 / (2.0 * c2)
            if 0.0 < ts < tmax and va + c1 * ts + c2 * ts * ts <= 0.0:
                vt = sdir * (vc + ae * ts + _lag(u0, ed, sig, wd, ts)[1])
                if vt <= 0.0:
                    lo, hi = 0.0, ts
    if hi > 0.0:
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if sdir * (vc + ae * mid + _lag(u0, ed, sig, wd, mid)[1]) > 0.0:
                lo = mid
            else:
                hi = mid
            if hi - lo <= 1e-13:
                break
        tstop = max(hi, 1e-12)
    tau = min(tstop, tmax)
    if tstop <= tmax:
        u1, ud1, el = _lag_exp(u0, ed, sig, wd, tau)
    else:
        u1, ud1, el = ue, ude, ele
    e1 = u1 + ess
    ed1 = ud1
    xc1 = xc + vc * tau + 0.5 * ae * tau * tau
    vc1 = vc + ae * tau
    L1 = xc1 + e1
    v1 = vc1 + ed1
    # e''(t) = Re(B lam^2 e^(lam t)) with u(t) = Re(B e^(lam t)), lam = -sig + i wd
    lam = complex(-sig, wd)
    Bc = complex(u0, -(ed + sig * u0) / wd)
    abar = (v1 - v0) / tau if tau > 0.0 else 0.0
    if tau > 0.0:
        # the modes: rigid part ae, transient Re(B lam^2 e^(lam t)), v by its chord
        _advance_exp(dyn, grid, k, 0.5 * (L + L1), ae, v0, abar, tau, lam, Bc * lam * lam, q,
                     qd, el)
        wf[k] += muk * Nn * abs(L1 - L)
    if tstop <= tmax:
        ed1 = -vc1                                     # v = 0 exactly
        F = -kh * e1 + ch * vc1                        # kh (xc - L) + ch (vc - v) at v = 0
        if abs(F) <= mus * Nn:
            return tau, xc1, vc1, e1, ed1, True, sdir
        return tau, xc1, vc1, e1, ed1, False, (1.0 if F > 0 else -1.0)
    return tau, xc1, vc1, e1, ed1, False, sdir


def step_all_friction(xc, vc, e, ed, stuck, sdir, q, qd, a, dyn, ntab, grid, dt, vmax, Lmin,
                      Lmax, Ms, kA, l0, zh, mus, muk, veps, hmax, sat, stop, acc, wf):
    """BatchROM.step with stroke friction: the commanded piston (xc, vc) follows the stroke
    kinematics of step_all (saturation, end stops); the stage lags it by e on the oil column and
    sticks or slips on the sliders (modal_batch module docstring, Stroke friction), or, with
    hmax > 0, follows the full model's regularised law with stick band veps in trapezoidal
    steps of at most hmax (Regularised stroke friction).  Arrays advanced in place; acc is the
    stage's mean acceleration, wf accumulates the friction work (J)."""
    for k in range(xc.shape[0]):
        _step_friction_one(k, xc, vc, e, ed, stuck, sdir, q, qd, a, dyn, ntab, grid, dt, vmax,
                           Lmin, Lmax, Ms, kA, l0, zh, mus, muk, veps, hmax, sat, stop, acc,
                           wf)


def step_all_friction_out(xc, vc, e, ed, stuck, sdir, q, qd, a, dyn, ntab, grid, dt, vmax,
                          Lmin, Lmax, Ms, kA, l0, zh, mus, muk, veps, hmax, sat, stop, acc, wf,
                          out, defl, sway):
    """step_all_friction and then outputs_all at the stage strokes xc + e in one pass over the
    cranes (each crane's tables are read while they are in cache): the same arithmetic as the
    two calls."""
    for k in range(xc.shape[0]):
        _step_friction_one(k, xc, vc, e, ed, stuck, sdir, q, qd, a, dyn, ntab, grid, dt, vmax,
                           Lmin, Lmax, Ms, kA, l0, zh, mus, muk, veps, hmax, sat, stop, acc,
                           wf)
        _outputs_one(k, xc[k] + e[k], q, qd, out, grid, defl, sway, k)


def _step_friction_one(k, xc, vc, e, ed, stuck, sdir, q, qd, a, dyn, ntab, grid, dt, vmax,
                       Lmin, Lmax, Ms, kA, l0, zh, mus, muk, veps, hmax, sat, stop, acc, wf):
    """step_all_friction for crane k."""
    Lk, vk, ak = xc[k], vc[k], a[k]
    ek, edk, st, sd = e[k], ed[k], stuck[k], sdir[k]
    v_start = vk + edk
    t_left = dt
    s_sat = False
    s_stop = False
    for _ in range(8):
        if t_left <= 1e-12:
            break
        ae, tau, t_v, t_s, sat_k, stop_k = _piston_segment(Lk, vk, ak, t_left, vmax, Lmin,
                                                           Lmax)
        s_sat = s_sat or sat_k
        s_stop = s_stop or stop_k
        if hmax > 0.0:
            # the regularised law: trapezoidal steps of at most hmax over the segment
            n = max(1, int(math.ceil(tau / hmax - 1e-9)))
            h = tau / n
            for _j in range(n):
                ek, edk = _creep_substep(dyn, grid, ntab, k, Lk, vk, ae, ek, edk, h, Ms[k], kA,
                                         l0, zh, mus, muk, veps, q, qd, wf)
                Lk = Lk + vk * h + 0.5 * ae * h * h
                vk = vk + ae * h
        else:
            # Coulomb: the stage within this commanded segment, piece by piece
            t_seg = 0.0
            for _p in range(64):
                rem = tau - t_seg
                if rem <= 1e-13:
                    break
                piece, Lk, vk, ek, edk, st, sd = _stage_piece(
                    dyn, grid, ntab, k, Lk, vk, ae, ek, edk, st, sd, rem, Ms[k], kA, l0, zh,
                    mus, muk, q, qd, wf)
                t_seg += piece
            if t_seg < tau - 1e-13:                   # pathological: finish kinematically
                r = tau - t_seg
                Lk = Lk + vk * r + 0.5 * ae * r * r
                vk = vk + ae * r
        if tau == t_s and tau < t_left + 1e-15:
            Lk = min(max(Lk, Lmin), Lmax)
            edk += vk                              # the piston stops; the stage does not
            vk = 0.0
            s_stop = True
        elif tau == t_v:
            edk += vk - math.copysign(vmax, vk)
            vk = math.copysign(vmax, vk)
            s_sat = True
        t_left = t_left - tau
    if t_left > 1e-12:
        Lk = Lk + vk * t_left
    xc[k] = min(max(Lk, Lmin), Lmax)
    vc[k] = vk
    e[k] = ek
    ed[k] = edk
    if hmax > 0.0:
        st = abs(vk + edk) < veps
    stuck[k] = st
    sdir[k] = sd
    sat[k] = s_sat
    stop[k] = s_stop
    acc[k] = (vk + edk - v_start) / dt


def _mu_regularised(v, mus, muk, veps):
    """(mu(v), d mu / dv) of the full model's regularised friction law
    (sim_core.physics.contact.sliding_block_contact.FrictionLaw): mu_s v / v_eps below v_eps,
    the cubic blend to mu_k up to 2 v_eps, mu_k sign(v) beyond."""
    a = abs(v)
    if a <= veps:
        return mus * v / veps, mus / veps
    t = a / veps - 1.0
    if t >= 1.0:
        return math.copysign(muk, v), 0.0
    return (math.copysign(mus + (muk - mus) * t * t * (3.0 - 2.0 * t), v),
            (muk - mus) * 6.0 * t * (1.0 - t) / veps)


def _creep_substep(dyn, grid, ntab, k, xc, vc, ae, e, ed, h, Ms, kA, l0, zh, mus, muk, veps,
                   q, qd, wf):
    """One trapezoidal step h of crane k's stage lag e under the regularised law (modal_batch
    module docstring, Regularised stroke friction): M e'' = -M ae - k_h e - c_h e' - N mu(v),
    v = vc + e', k_h, c_h and N frozen at the step's start; the modes driven at the stage's
    mean acceleration over the step.  Returns (e1, ed1)."""
    L0 = xc + e
    i, w = _interval(grid, L0)
    Nn = (1 - w) * ntab[k, i] + w * ntab[k, i + 1]
    kh = kA / (L0 + l0)
    ch = 2.0 * zh * math.sqrt(kh * Ms)
    v0 = vc + ed
    vc1 = vc + ae * h
    mu0 = _mu_regularised(v0, mus, muk, veps)[0]
    # R(x) = g x + r0 + N mu(vc1 + x) / 2 = 0 for x = ed1: |mu| <= mus brackets a root;
    # Newton within the bracket, bisection where it leaves it (at the scene's coefficients
    # g > N max|mu'| / 2 for h <= 5 ms, M / h alone ~1e7 N s/m: R increases, one root)
    g = Ms / h + 0.25 * kh * h + 0.5 * ch
    r0 = -Ms * ed / h + Ms * ae + kh * (e + 0.25 * h * ed) + 0.5 * ch * ed + 0.5 * Nn * mu0
    lo = (-r0 - 0.5 * Nn * mus) / g
    hi = (-r0 + 0.5 * Nn * mus) / g
    x = min(max(ed, lo), hi)
    for _ in range(60):
        mu1, dmu1 = _mu_regularised(vc1 + x, mus, muk, veps)
        R = g * x + r0 + 0.5 * Nn * mu1
        if R > 0.0:
            hi = x
        else:
            lo = x
        dR = g + 0.5 * Nn * dmu1
        xn = x - R / dR
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= 1e-15 * (1.0 + abs(x)) or hi - lo <= 1e-15 * (1.0 + abs(x)):
            x = xn
            break
        x = xn
    ed1 = x
    e1 = e + 0.5 * h * (ed + ed1)
    v1 = vc1 + ed1
    _advance(dyn, grid, k, L0, v0, (v1 - v0) / h, h, q, qd)
    wf[k] += 0.5 * h * Nn * (mu0 * v0 + _mu_regularised(v1, mus, muk, veps)[0] * v1)
    return e1, ed1


def outputs_all(L, q, qd, out, grid, defl, sway):
    """BatchROM.outputs for every crane: defl (N, 4), sway (N, 4) written."""
    for k in range(L.shape[0]):
        _outputs_one(k, L[k], q, qd, out, grid, defl, sway, k)


def outputs_sel(L, q, qd, out, grid, ids, defl, sway):
    """outputs_all for the cranes ids (stage strokes L (N,)): row j of defl, sway (k, 4) is
    crane ids[j]."""
    for j in range(ids.shape[0]):
        k = ids[j]
        _outputs_one(k, L[k], q, qd, out, grid, defl, sway, j)


def _outputs_one(k, Lk, q, qd, out, grid, defl, sway, row):
    """outputs_all for crane k at stage stroke Lk, into row ``row`` of defl and sway."""
    nc = q.shape[1]
    i, w = _interval(grid, Lk)
    w0 = 1.0 - w
    p0 = p1 = p2 = p3 = 0.0
    r0 = r1 = r2 = r3 = 0.0
    for j in range(nc):
        qj = q[k, j]
        dj = qd[k, j]
        c = w0 * out[k, i, 0, j] + w * out[k, i + 1, 0, j]
        p0 += c * qj
        r0 += c * dj
        c = w0 * out[k, i, 1, j] + w * out[k, i + 1, 1, j]
        p1 += c * qj
        r1 += c * dj
        c = w0 * out[k, i, 2, j] + w * out[k, i + 1, 2, j]
        p2 += c * qj
        r2 += c * dj
        c = w0 * out[k, i, 3, j] + w * out[k, i + 1, 3, j]
        p3 += c * qj
        r3 += c * dj
    defl[row, 0] = p0
    defl[row, 1] = p1
    defl[row, 2] = r0
    defl[row, 3] = r1
    sway[row, 0] = p2
    sway[row, 1] = p3
    sway[row, 2] = r2
    sway[row, 3] = r3


def _jacobi_eigh(A, V, lam):
    """Eigenvalues (ascending, into lam) and orthonormal eigenvectors (columns, into V) of the
    small symmetric matrix A (cyclic Jacobi rotations until the off-diagonal part is below
    1e-15 of the diagonal's scale; Golub & Van Loan, Matrix Computations, Sec. 8.5).  A is
    overwritten; V, lam are work arrays of the caller (no allocation per call)."""
    n = A.shape[0]
    for r in range(n):
        for p in range(n):
            V[r, p] = 0.0
        V[r, r] = 1.0
    for _ in range(50):
        off = 0.0
        scale = 0.0
        for p in range(n):
            scale += A[p, p] * A[p, p]
            for q in range(p + 1, n):
                off += A[p, q] * A[p, q]
        if off <= 1e-30 * scale:
            break
        for p in range(n - 1):
            for q in range(p + 1, n):
                apq = A[p, q]
                if apq == 0.0:
                    continue
                theta = (A[q, q] - A[p, p]) / (2.0 * apq)
                t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                if theta < 0.0:
                    t = -t
                cs = 1.0 / math.sqrt(t * t + 1.0)
                sn = t * cs
                for r in range(n):
                    arp = A[r, p]
                    arq = A[r, q]
                    A[r, p] = cs * arp - sn * arq
                    A[r, q] = sn * arp + cs * arq
                for r in range(n):
                    apr = A[p, r]
                    aqr = A[q, r]
                    A[p, r] = cs * apr - sn * aqr
                    A[q, r] = sn * apr + cs * aqr
                for r in range(n):
                    vrp = V[r, p]
                    vrq = V[r, q]
                    V[r, p] = cs * vrp - sn * vrq
                    V[r, q] = sn * vrp + cs * vrq
    # ascending order by insertion sort of the columns (stable, as argsort of distinct values)
    for p in range(n):
        lam[p] = A[p, p]
    for i in range(1, n):
        j = i
        while j > 0 and lam[j - 1] > lam[j]:
            x = lam[j - 1]
            lam[j - 1] = lam[j]
            lam[j] = x
            for r in range(n):
                x = V[r, j - 1]
                V[r, j - 1] = V[r, j]
                V[r, j] = x
            j -= 1


def coupled_modes(c, s, ds, m, ell, gravity, dyn, out):
    """modal_batch.coupled_tables from the refined lumped coefficients c (N, nL, 8, n) rows
    modal.COLS, s, ds (N, nL) and per-crane m, ell (N,): dyn (N, nL, 5, n + 2) and out (N, nL,
    4, n + 2) written.  Returns the largest coupled damping ratio (the caller checks < 1)."""
    N, nL, _, n = c.shape
    nq = n + 1
    zmax = 0.0
    M = np.zeros((nq, nq))
    Phi_prev = np.zeros((nq, nq))
    kd = np.empty(nq)
    A = np.empty((nq, nq))
    Y = np.empty((nq, nq))
    lam = np.empty(nq)
    Phi = np.empty((nq, nq))
    for k in range(N):
        ml = m[k] * ell[k]
        for j in range(nL):
            M[:, :] = 0.0
            for i in range(n):
                M[i, i] = 1.0
                M[i, n] = ml * c[k, j, 6, i]
                M[n, i] = ml * c[k, j, 6, i]
            M[n, n] = ml * ell[k]
            for i in range(n):
                kd[i] = c[k, j, 0, i] * c[k, j, 0, i]
            kd[n] = m[k] * gravity * ell[k]
            # M = C C^T with C = [[I, 0], [b^T, dd]], dd = sqrt(c - b.b) (b = m l phi_x):
            # A = C^-1 K C^-T is diag(k_q) bordered by u = -k_q b / dd and
            # alpha = (k_q . b^2 + k_p) / dd^2 (an arrowhead matrix); Phi = C^-T Y
            bb = 0.0
            kb2 = 0.0
            for i in range(n):
                bi = ml * c[k, j, 6, i]
                bb += bi * bi
                kb2 += kd[i] * bi * bi
            dd = math.sqrt(ml * ell[k] - bb)
            A[:, :] = 0.0
            for i in range(n):
                A[i, i] = kd[i]
                A[i, n] = -kd[i] * ml * c[k, j, 6, i] / dd
                A[n, i] = A[i, n]
            A[n, n] = (kb2 + kd[n]) / (dd * dd)
            _jacobi_eigh(A, Y, lam)
            for col in range(nq):
                yp = Y[n, col] / dd
                for i in range(n):
                    Phi[i, col] = Y[i, col] - ml * c[k, j, 6, i] * yp
                Phi[n, col] = yp
            for col in range(nq):
                if j == 0:
                    g0 = Phi[n, col] * ml * s[k, 0]
                    for i in range(n):
                        g0 += Phi[i, col] * c[k, 0, 2, i]
                    sg = -1.0 if g0 < 0 else 1.0
                else:
                    proj = 0.0
                    for r in range(nq):
                        mr = 0.0
                        for t in range(nq):
                            mr += M[r, t] * Phi[t, col]
                        proj += Phi_prev[r, col] * mr
                    sg = -1.0 if proj < 0 else 1.0
                if sg < 0:
                    for r in range(nq):
                        Phi[r, col] = -Phi[r, col]
            Phi_prev[:, :] = Phi
            for col in range(nq):
                om = math.sqrt(max(lam[col], 0.0))
                dd = 0.0
                gam = Phi[n, col] * ml * s[k, j]
                k2 = Phi[n, col] * ml * ds[k, j]
                b1 = 0.0
                px = 0.0
                pz = 0.0
                for i in range(n):
                    p = Phi[i, col]
                    dd += p * p * 2.0 * c[k, j, 1, i] * c[k, j, 0, i]
                    gam += p * c[k, j, 2, i]
                    k2 += p * (c[k, j, 3, i] - c[k, j, 5, i])
                    b1 += p * c[k, j, 4, i]
                    px += p * c[k, j, 6, i]
                    pz += p * c[k, j, 7, i]
                zc = dd / (2.0 * om)
                if zc > zmax:
                    zmax = zc
                dyn[k, j, 0, col] = om
                dyn[k, j, 1, col] = zc
                dyn[k, j, 2, col] = gam
                dyn[k, j, 3, col] = k2
                dyn[k, j, 4, col] = b1
                out[k, j, 0, col] = px
                out[k, j, 1, col] = pz
                out[k, j, 2, col] = Phi[n, col]
                out[k, j, 3, col] = 0.0
            dyn[k, j, 0, nq] = math.sqrt(gravity / ell[k])
            for row in range(1, 5):
                dyn[k, j, row, nq] = 0.0
            for row in range(3):
                out[k, j, row, nq] = 0.0
            out[k, j, 3, nq] = 1.0
    return zmax


def _lerp1(grid, x):
    """modal_batch._lerp_index for one value: (interval, weight clipped to [0, 1])."""
    n = grid.shape[0]
    if n == 1:
        return 0, 0.0
    lo, hi = 0, n                                   # searchsorted(side="right") - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if grid[mid] <= x:
            lo = mid + 1
        else:
            hi = mid
    i = min(max(lo - 1, 0), n - 2)
    w = (x - grid[i]) / (grid[i + 1] - grid[i])
    return i, min(max(w, 0.0), 1.0)


def _bilinear(x, P, A, m, ang, q, l, col):
    """Bilinear interpolation in (angle, payload) of x[:, :, l, col] for crane q: the
    arithmetic of modal_batch.lumped_coefficients (same operations, same order)."""
    ia, wa = _lerp1(A, ang[q])
    ip, wp = _lerp1(P, m[q])
    ja = min(ia + 1, x.shape[0] - 1)
    jp = min(ip + 1, x.shape[1] - 1)
    return ((1 - wa) * ((1 - wp) * x[ia, ip, l, col] + wp * x[ia, jp, l, col])
            + wa * ((1 - wp) * x[ja, ip, l, col] + wp * x[ja, jp, l, col]))


def _refine_at(v, ri, rw, r):
    """modal_batch.refine_grid at refined point r of the values v (along L)."""
    i = ri[r]
    w = rw[r]
    if w == 0.0:
        return v[i]
    return (1 - w) * v[i] + w * v[i + 1]


def lumped_refined(x, P, A, m, ang, n, uniform, gdx, ga, gb, gc, ri, rw, c, s, ds):
    """The inputs of coupled_modes for the cranes (m, ang): the lumped coefficients
    (modal_batch.lumped_coefficients from the stacked rows x (nA, nP, nL, 8 n + 3), the last
    three tip_dL), s = d r_s,x / dL_s, its gradient along L (numpy.gradient's formulas: uniform
    spacing gdx[0], else the coefficients ga, gb, gc and the edge spacings gdx[0], gdx[1]) and
    the refinement (refine_grid: intervals ri, weights rw), as modal_batch.coupled_tables forms
    them with array operations.  Writes c (k, nLr, 8, n), s, ds (k, nLr)."""
    k = m.shape[0]
    nL = x.shape[2]
    nm = 8 * n
    nLr = ri.shape[0]
    row = np.empty(nL)
    sl = np.empty(nL)
    g = np.empty(nL)
    for q in range(k):
        for l in range(nL):
            sl[l] = _bilinear(x, P, A, m, ang, q, l, nm)
        if uniform:
            for l in range(1, nL - 1):
                g[l] = (sl[l + 1] - sl[l - 1]) / (2. * gdx[0])
            g[0] = (sl[1] - sl[0]) / gdx[0]
            g[nL - 1] = (sl[nL - 1] - sl[nL - 2]) / gdx[0]
        else:
            for l in range(1, nL - 1):
                g[l] = ga[l - 1] * sl[l - 1] + gb[l - 1] * sl[l] + gc[l - 1] * sl[l + 1]
            g[0] = (sl[1] - sl[0]) / gdx[0]
            g[nL - 1] = (sl[nL - 1] - sl[nL - 2]) / gdx[1]
        for r in range(nLr):
            s[q, r] = _refine_at(sl, ri, rw, r)
            ds[q, r] = _refine_at(g, ri, rw, r)
        for col in range(nm):
            for l in range(nL):
                row[l] = _bilinear(x, P, A, m, ang, q, l, col)
            for r in range(nLr):
                c[q, r, col // n, col % n] = _refine_at(row, ri, rw, r)


def normal_refined(x, P, A, m, ang, ri, rw, out):
    """modal_batch.normal_loads refined by refine_grid: out (k, nLr) from the normal-load
    table x (nA, nP, nL, 1)."""
    nL = x.shape[2]
    row = np.empty(nL)
    for q in range(m.shape[0]):
        for l in range(nL):
            row[l] = _bilinear(x, P, A, m, ang, q, l, 0)
        for r in range(ri.shape[0]):
            out[q, r] = _refine_at(row, ri, rw, r)


if AVAILABLE:
    _jit = numba.njit(cache=True, nogil=True)
    _interval = _jit(_interval)
    _jacobi_eigh = _jit(_jacobi_eigh)
    _first_hit = _jit(_first_hit)
    _piston_segment = _jit(_piston_segment)
    _at_rest_unforced = _jit(_at_rest_unforced)
    _advance = _jit(_advance)
    _step_one = _jit(_step_one)
    step_all = _jit(step_all)
    _advance_exp = _jit(_advance_exp)
    _lag = _jit(_lag)
    _lag_exp = _jit(_lag_exp)
    _advance_free = _jit(_advance_free)
    _breakaway = _jit(_breakaway)
    _stage_piece = _jit(_stage_piece)
    _step_friction_one = _jit(_step_friction_one)
    step_all_friction = _jit(step_all_friction)
    _outputs_one = _jit(_outputs_one)
    outputs_all = _jit(outputs_all)
    outputs_sel = _jit(outputs_sel)
    step_all_out = _jit(step_all_out)
    step_all_friction_out = _jit(step_all_friction_out)
    _mu_regularised = _jit(_mu_regularised)
    _creep_substep = _jit(_creep_substep)
    coupled_modes = _jit(coupled_modes)
    _lerp1 = _jit(_lerp1)
    _bilinear = _jit(_bilinear)
    _refine_at = _jit(_refine_at)
    lumped_refined = _jit(lumped_refined)
    normal_refined = _jit(normal_refined)
