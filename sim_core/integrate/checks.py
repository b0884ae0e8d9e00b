"""Cheap checks of a finished run's own result: the constraint violation, and the energy
balance of the system kinds that have one.  A failed check marks the result as suspect
(``Result.suspect``); a gross failure raises :class:`sim_core.errors.SuspectResult`.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.errors import SuspectResult
from sim_core.result import Result

# -- result checks ---------------------------------------------------------------------------

# Energy balance (beam scenes): max_t |E(t) - E(0) - W(t)| over the exchanged energy E_x (see
# beam_energy_check).  Motion amplitudes scale with the square root of the energy, so a
# relative energy error e is an amplitude error of about e / 2: 0.02 ~ 1 % (suspect), 0.2 ~
# 10 % (not a solution: SuspectResult).  Healthy runs stay orders of magnitude below: the
# 10 m cantilever released under gravity (2 sub-elements, RK45, 2 s) 1e-8 at rtol 1e-4 and
# 2.3e-6 at rtol 1e-3, its tip within 1.4e-5 m of the modal solution; a run whose
# error control let a stiff mode grow (rtol 3e-3) is dominated by that mode's energy: 0.61,
# tip 1.1 m off.  (The ratio cannot exceed ~1 without work W: E_x bounds the drift.)
ENERGY_SUSPECT = 0.02
ENERGY_FAIL = 0.2
# E_x is at least this fraction of the stored energy (max T + max U): a run at rest (a static
# equilibrium, exchanging ~1e-10 of it) is judged against the energy it holds, not against
# its round-off-sized exchanges (the cantilever at its static equilibrium: drift 4e-11 U at
# rtol 1e-6, 5e-8 U at rtol 1e-3)
STORED_FLOOR = 1e-3
# Constraint violation (outputs named constraint_violation, m): a multiple of the integration
# tolerance at the structure's length scale, capped at a fraction of that scale
CONSTRAINT_TOL_FACTOR = 100.0
CONSTRAINT_SUSPECT_FRACTION = 0.01
CONSTRAINT_FAIL_FRACTION = 0.1


def verdict(value: float, limit: float, fail: float, what: str) -> dict:
    """One check: ``value`` against the suspect ``limit`` and the ``fail`` limit."""
    value = float(value)
    return {"value": value, "limit": float(limit), "fail_limit": float(fail),
            "ok": bool(value <= limit), "gross": bool(value > fail), "what": what}


def result_checks(res: Result) -> dict:
    """The checks every scene kind's result allows: the constraint violation where the result
    has one (``constraint_violation``, m, of nonlinear constraints held by Baumgarte
    stabilisation).  Its limit: CONSTRAINT_TOL_FACTOR (atol + rtol L), L the structure's size
    (the largest |tip_position|, else 1 m), at most CONSTRAINT_SUSPECT_FRACTION L.  The
    violation is driven by the integration error (each position accurate to about atol +
    rtol |q| per step, |q| <= L) and damped by the stabilisation within ~1/xi = 0.1 s, so it
    stays within a few tolerances (the paper runs: 4.6e-8 m, 2.3e-7 m at n_nodes 9 and 3, with
    atol + rtol L ~ 2e-5 m); a hundredfold is a solution that left its constraints.  Above
    CONSTRAINT_FAIL_FRACTION L (10 % of the structure) it raises."""
    out = {}
    if "constraint_violation" in res and len(res.t):
        cv = np.asarray(res["constraint_violation"], dtype=float)
        L = 1.0
        if "tip_position" in res:
            L = max(float(np.max(np.linalg.norm(np.reshape(res["tip_position"],
                                                           (len(res.t), -1))[:, :3], axis=1))),
                    1e-3)
        rtol, atol = res.stats.get("rtol"), res.stats.get("atol")
        limit = CONSTRAINT_SUSPECT_FRACTION * L
        if rtol is not None and atol is not None:
            limit = min(CONSTRAINT_TOL_FACTOR * (atol + rtol * L), limit)
        value = float(np.max(np.abs(cv))) if cv.size else 0.0
        if not np.isfinite(value):
            value = math.inf
        out["constraint_violation"] = verdict(
            value, limit, CONSTRAINT_FAIL_FRACTION * L,
            f"largest constraint violation, m or rad (structure size {L:.3g} m)")
    return out


def check_result(res: Result, checks: dict) -> Result:
    """Record the checks in ``res.stats`` (``checks``: name -> verdict; ``suspect``: whether
    any failed; ``failed_checks``: their names) and raise :class:`SuspectResult` (the result
    attached as ``.result``, its ``error`` set) where one failed grossly."""
    failed = [k for k, c in checks.items() if not c["ok"]]
    res.stats["checks"] = checks
    res.stats["suspect"] = bool(failed)
    res.stats["failed_checks"] = failed
    gross = {k: c for k, c in checks.items() if c["gross"]}
    if gross:
        t = float(res.t[-1]) if len(res.t) else 0.0
        why = "; ".join(f"{k} = {c['value']:.3g} > {c['fail_limit']:.3g} ({c['what']})"
                        for k, c in gross.items())
        exc = SuspectResult(t, f"the result fails its own checks: {why}", gross)
        res.error = str(exc)
        exc.result = res
        raise exc
    return res
