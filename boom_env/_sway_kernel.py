"""The per-step bookkeeping of the v1 task for N cranes in one loop (observation, reward, success,
truncation, divergence check): :func:`task_step`, compiled with numba where it is importable
(numba is a dependency of sim_core), else run as plain Python (the same code, slower).  Its
definitions are those of the boom_env.telescopic_sway_env module docstring."""

from __future__ import annotations

import math
import os

import numpy as np

# divergence codes of task_step
OK, NON_FINITE, DEFLECTION, SWAY = 0, 1, 2, 3
# layout of the float parameter vector ``par`` of task_step
PAR = ("dt", "a_max", "t_max", "max_steps", "w_time", "w_progress", "w_deflection", "w_rate",
       "w_effort", "w_jerk", "w_end_stop", "w_sway", "w_sway_rate", "bonus", "d_ref", "dv_ref",
       "sway_ref", "sway_rate_ref", "tol_stroke", "tol_speed", "tol_deflection",
       "tol_deflection_rate", "tol_sway", "tol_sway_rate", "sway_limit", "rate_max",
       "reward_scale")
P = {k: i for i, k in enumerate(PAR)}


def task_step(par, L, v, acc, stop, defl_new, sway_new, defl, sway, a, a_prev, L_target,
              travel, t, steps, params, low, high, obs, last_obs, reward, reward_unscaled,
              settled, truncated, code):
    """One step of the task for every crane; updates defl, sway (the last good values),
    a_prev, t, steps, last_obs in place and writes obs, reward, reward_unscaled, settled,
    truncated and code (0: fine; 1, 2, 3: non-finite state, tip deflection or sway outside
    the observation bounds, the last good observation is kept)."""
    n = L.shape[0]
    d = obs.shape[1]
    dt = par[0]
    a_max = par[1]
    t_max = par[2]
    max_steps = par[3]
    sway_limit = par[24]
    rate_max = par[25]
    for k in range(n):
        c = 0
        fin = math.isfinite(L[k]) and math.isfinite(v[k])
        for j in range(4):
            if not (math.isfinite(defl_new[k, j]) and math.isfinite(sway_new[k, j])):
                fin = False
        if not fin:
            c = 1
        elif (abs(defl_new[k, 0]) > 1.0 or abs(defl_new[k, 1]) > 1.0
              or abs(defl_new[k, 2]) > 10.0 or abs(defl_new[k, 3]) > 10.0):
            c = 2
        elif (abs(sway_new[k, 0]) > sway_limit or abs(sway_new[k, 1]) > sway_limit
              or abs(sway_new[k, 2]) > rate_max or abs(sway_new[k, 3]) > rate_max):
            c = 3
        code[k] = c
        if c == 0:
            for j in range(4):
                defl[k, j] = defl_new[k, j]
                sway[k, j] = sway_new[k, j]
        t[k] += dt
        steps[k] += 1
        ak = a[k]
        r = -dt * (par[4] + par[5] * abs(L[k] - L_target[k]) / travel[k]
                   + par[8] * (ak / a_max) ** 2)
        d2 = defl[k, 0] ** 2 + defl[k, 1] ** 2
        dv2 = defl[k, 2] ** 2 + defl[k, 3] ** 2
        s2 = sway[k, 0] ** 2 + sway[k, 1] ** 2
        sv2 = sway[k, 2] ** 2 + sway[k, 3] ** 2
        if c == 0:
            r -= dt * (par[6] * d2 / par[14] ** 2 + par[7] * dv2 / par[15] ** 2
                       + par[11] * s2 / par[16] ** 2 + par[12] * sv2 / par[17] ** 2)
        r -= par[9] * ((ak - a_prev[k]) / a_max) ** 2
        if stop[k]:
            r -= par[10]
        a_prev[k] = ak
        ok = (c == 0 and abs(L[k] - L_target[k]) < par[18] and abs(v[k]) < par[19]
              and d2 < par[20] ** 2 and dv2 < par[21] ** 2 and s2 < par[22] ** 2
              and sv2 < par[23] ** 2)
        if ok:
            r += par[13]
        settled[k] = ok
        reward_unscaled[k] = r
        reward[k] = r * par[26]
        truncated[k] = (c != 0 or t[k] >= t_max - 1e-9
                        or (max_steps > 0 and steps[k] >= max_steps))
        if c != 0:
            for j in range(d):
                obs[k, j] = last_obs[k, j]
        else:
            for j in range(d):
                if j == 0:
                    x = L[k]
                elif j == 1:
                    x = v[k]
                elif j == 2:
                    x = acc[k]
                elif j == 3:
                    x = L_target[k]
                elif j == 4:
                    x = max(t_max - t[k], 0.0)
                elif j < 9:
                    x = defl[k, j - 5]
                elif j < 13:
                    x = sway[k, j - 9]
                else:
                    x = params[k, j - 13]
                if x != x:
                    x = 0.0
                x = min(max(x, low[j]), high[j])
                obs[k, j] = x
                last_obs[k, j] = x


def observe(L, v, acc, L_target, t, t_max, defl, sway, params, low, high, out):
    """Observations (k, d) of cranes without a step (after a reset): out written."""
    n = L.shape[0]
    d = out.shape[1]
    npar = params.shape[1]
    for k in range(n):
        row = np.empty(d)
        row[0] = L[k]
        row[1] = v[k]
        row[2] = acc[k]
        row[3] = L_target[k]
        row[4] = max(t_max - t[k], 0.0)
        for j in range(4):
            row[5 + j] = defl[k, j]
            row[9 + j] = sway[k, j]
        for j in range(npar):
            row[13 + j] = params[k, j]
        for j in range(d):
            x = row[j]
            if x != x:
                x = 0.0
            out[k, j] = min(max(x, low[j]), high[j])


_numba = None
if os.environ.get("SIM_CORE_NUMBA", "1").strip().lower() not in ("0", "off", "false", "no"):
    try:                                        # numba is a dependency of sim_core; the same
        import numba as _numba                  # switch (SIM_CORE_NUMBA=0) turns it off
    except ImportError:                         # pragma: no cover
        _numba = None

COMPILED = _numba is not None
if COMPILED:
    task_step = _numba.njit(cache=True, nogil=True)(task_step)
    observe = _numba.njit(cache=True, nogil=True)(observe)
