"""Run a scene: assemble the model, integrate, collect outputs into a :class:`Result`.

First integrator (issue 2): scipy ``solve_ivp`` RK45 on the first-order reduced system, with
the stress filter of the second seed (Eq. 53) as an effect when the scene switches it on.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.integrate import RK45

from .assemble import build_model
from .errors import SimulationError
from .result import Result
from .statics import static_equilibrium


class _CountingRHS:
    """Wraps model.rhs: counts evaluations.  A stage evaluation that fails (overflow, singular
    KKT matrix, non-finite accelerations) is a *recoverable* failure, as in SUNDIALS: the stage
    returns huge derivatives so that the error estimate rejects the step and RK45 retries with a
    smaller one.  After ``max_failures`` consecutive failed evaluations, or if an accepted state
    is non-finite (checked by the caller), it raises SimulationError with the time and reason."""

    BIG = 1e100
    max_failures = 40

    def __init__(self, model):
        self.model = model
        self.nfev = 0
        self.last_t = 0.0
        self.failures = 0
        self.n_failed = 0
        self.last_reason = ""

    def __call__(self, t, y):
        self.nfev += 1
        self.last_t = t
        reason = None
        try:
            with np.errstate(over="raise", divide="raise", invalid="raise", under="ignore"):
                out = self.model.rhs(t, y)
            if not np.all(np.isfinite(out)):
                reason = "non-finite accelerations"
        except (FloatingPointError, np.linalg.LinAlgError) as exc:
            reason = f"non-finite or singular dynamics: {exc}"
        if reason is None:
            self.failures = 0
            return out
        self.failures += 1
        self.n_failed += 1
        self.last_reason = reason
        if self.failures > self.max_failures:
            raise SimulationError(t, f"{reason} ({self.failures} consecutive failed stage "
                                     "evaluations; step size could not recover)", last_state=y)
        return np.full(len(y), self.BIG)


def integrate_rk45(model, y0: np.ndarray, t_end: float, sol: dict, progress=None):
    """Explicit RK45 (scipy's Dormand-Prince stepper) on model.rhs with dense output at
    ``sol["n_output"]`` equally spaced times.  Returns (t, y, stats); raises SimulationError with
    the time, step and last good state on failure or non-finite values, or when the optional
    wall-clock budget ``sol["max_wall_s"]`` (s) is exhausted (the outputs reached so far are
    attached, so a budgeted run still yields a partial result)."""
    t_eval = np.linspace(0.0, t_end, sol["n_output"])
    rhs = _CountingRHS(model)
    kwargs = {"max_step": sol["max_step"]} if "max_step" in sol else {}
    budget = sol.get("max_wall_s")
    wall0 = time.perf_counter()
    solver = RK45(rhs, 0.0, y0, t_end, rtol=sol["rtol"], atol=sol["atol"], **kwargs)
    ys = [y0]
    k_out = 1
    steps = []

    def stats():
        wall = time.perf_counter() - wall0
        return {"wall_time_s": wall, "n_steps": len(steps), "n_rhs": int(rhs.nfev),
                "n_failed_rhs": int(rhs.n_failed),
                "min_step_s": float(min(steps)) if steps else 0.0,
                "max_step_s": float(max(steps)) if steps else 0.0,
                "method": "RK45", "real_time_factor": t_end / max(wall, 1e-12)}

    try:
        while solver.status == "running":
            msg = solver.step()
            if solver.status == "failed" or not np.all(np.isfinite(solver.y)):
                why = (f" after {rhs.failures} failed stage evaluations ({rhs.last_reason})"
                       if rhs.failures else "")
                raise SimulationError(solver.t, f"RK45 failed: {msg}{why}", step=solver.step_size,
                                      last_state=solver.y)
            steps.append(solver.t - solver.t_old)
            if k_out < len(t_eval) and t_eval[k_out] <= solver.t:
                dense = solver.dense_output()
                while k_out < len(t_eval) and t_eval[k_out] <= solver.t:
                    ys.append(dense(t_eval[k_out]))
                    k_out += 1
            if progress is not None:
                progress(solver.t, time.perf_counter() - wall0)
            if budget is not None and solver.status == "running" \
                    and time.perf_counter() - wall0 > budget:
                raise SimulationError(solver.t, f"wall-clock budget solver.max_wall_s = {budget:g} s "
                                      f"exhausted (last step {solver.step_size:.3g} s)",
                                      step=solver.step_size, last_state=solver.y)
    except SimulationError as exc:
        # keep what was computed: the caller turns it into a partial Result (exc.result)
        exc.partial = (t_eval[:len(ys)], np.array(ys), stats())
        raise
    return t_eval[:len(ys)], np.array(ys), stats()


def run_with_partial(integrate, collect):
    """integrate() -> (t, y, stats); collect(t, y, stats, error) -> Result.  On a
    SimulationError the outputs up to the failure are collected and attached as exc.result."""
    try:
        ts, ys, st = integrate()
    except SimulationError as exc:
        part = getattr(exc, "partial", None)
        if part is not None and len(part[0]):
            exc.result = collect(*part, str(exc))
        raise
    return collect(ts, ys, st, None)


def simulate(scene: dict, progress=None) -> Result:
    """Integrate a validated scene (see :func:`sim_core.load_scene`) and return a Result.

    Outputs: ``tip_position``, ``tip_velocity``, ``tip_acceleration`` (right end of the last
    beam, material point s = L), ``energy_kinetic``, ``energy_strain``, ``energy_gravity`` (J),
    ``element_ends`` (material coordinates of all breakpoints, m) and ``reactions`` (one column
    per constraint row, N or N m).
    """
    if scene.get("kind") == "telescopic":
        from .telescopic import simulate_telescopic
        from .telescopic_scene import params_from_scene
        sol = scene["solver"]
        if scene.get("model", {}).get("reduction") == "modal":
            from .modal_telescopic import simulate_modal
            res = simulate_modal(params_from_scene(scene), scene["model"]["n_modes"],
                                 sol["t_end"], sol["n_output"])
            res.scene = scene
            return res
        res = simulate_telescopic(params_from_scene(scene), sol["t_end"], sol["n_output"],
                                  sol["rtol"], sol["atol"], progress, sol.get("max_wall_s"))
        res.scene = scene
        return res
    if scene.get("kind") == "folding":
        from .folding import simulate_folding
        from .folding_scene import params_from_scene as folding_params
        sol = scene["solver"]
        res = simulate_folding(folding_params(scene), sol["t_end"], sol["n_output"],
                               sol["rtol"], sol["atol"], progress, sol.get("max_step"),
                               sol.get("max_wall_s"))
        res.scene = scene
        return res
    model, Q0, Qd0 = build_model(scene)
    sol = scene["solver"]
    z0, zd0 = model.reduced_state(0.0, Q0, Qd0)
    if scene["initial"]["static_equilibrium"]:
        z0 = static_equilibrium(model, z0)
    y0 = np.concatenate([z0, zd0])
    return run_with_partial(lambda: integrate_rk45(model, y0, sol["t_end"], sol, progress),
                            lambda ts, ys, stats, err: _beam_result(model, scene, ts, ys, stats, err))


def _beam_result(model, scene, ts, ys, stats, error) -> Result:
    n = model.n_dof
    g = np.array(scene["gravity"]["g"]) if scene["effects"]["gravity"] else None
    last = len(model.beams) - 1
    L = model.beams[last].length
    out: dict[str, list] = {k: [] for k in ("tip_position", "tip_velocity", "tip_acceleration",
                                            "energy_kinetic", "energy_strain", "energy_gravity",
                                            "element_ends", "reactions")}
    for t, y in zip(ts, ys):
        z, zd = y[:n], y[n:]
        zdd = model.accelerations(t, z, zd)
        r, v, a = model.point_motion(last, L, t, z, zd, zdd)
        Q, Qd = model.full_state(t, z, zd)
        en = model.energies(t, Q, Qd, g)
        out["tip_position"].append(r)
        out["tip_velocity"].append(v)
        out["tip_acceleration"].append(a)
        out["energy_kinetic"].append(en["T"])
        out["energy_strain"].append(en["U"])
        out["energy_gravity"].append(en["V"])
        out["element_ends"].append([Q[off + b.s_coord(k)] for b, off in zip(model.beams, model.offsets)
                                    for k in range(len(b.breakpoints))])
        out["reactions"].append(model.reactions(t, z, zd))
    outputs = {k: np.real(np.array(v, dtype=float)) for k, v in out.items()}
    outputs["state"] = ys
    stats["n_dof"] = int(n)
    return Result(ts, outputs, stats, scene, error)
