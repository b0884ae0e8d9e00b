"""Running a beam scene: the model from the scene, its static start, the integration and the
outputs (tip kinematics, energies, element ends, reactions) with the energy-balance check.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core import run_control
from sim_core.errors import ElementEvaluationError, SimulationError
from sim_core.integrate.checks import ENERGY_FAIL, ENERGY_SUSPECT, STORED_FLOOR, verdict
from sim_core.integrate.driver import integrate, run_with_partial
from sim_core.model.statics import static_equilibrium
from sim_core.physics.drive_profiles import sleeve_motion
from sim_core.result import Result
from sim_core.systems.beam.build import build_model


def _kinetic_density(model, ibeam: int, s: float, t: float, y: np.ndarray) -> float:
    """Kinetic energy per unit material length at material point s of beam ``ibeam``, J/m:
    (rhoA |v|^2 + w . J w) / 2 with the material velocity v and angular velocity w (section
    components), as :meth:`sim_core.model.model.Model.energies` integrates it."""
    n = model.n_dof
    Q, Qd = model.full_state(t, y[:n], y[n:])
    _, kin, idx = model.point(ibeam, s, Q)
    v = np.real(kin.J_r[0] @ Qd[idx])
    w = np.real(kin.J_w[0] @ Qd[idx])
    sec = model.beams[ibeam].elements[0].section
    return 0.5 * float(sec.rhoA * np.dot(v, v) + np.dot(w * w, sec.J))


def beam_energy_check(model, scene: dict, res: Result) -> dict:
    """Energy balance of a beam scene's result at its output times: E = T + U + V (kinetic,
    strain, gravity, J, ``energy_*`` outputs) plus the potential -f . r of every point load
    that is fixed (speed 0, on from t = 0), against the energy W(t) fed in, integrated by the
    trapezoidal rule over the outputs:

    * prescribed motions: the constraints' power lambda . b'(t) (lambda the reactions, b' the
      constraints' rates: the sleeves' flow of material coordinates);
    * material crossing a sleeve end at rate s' carries its kinetic energy density e_T
      (:func:`_kinetic_density`) into or out of the modelled part: -s' e_T at a left end,
      +s' e_T at a right end.  The inertia forces are those of the material points (virtual
      power, Zhao-Qi-Wang 2024 Eq. 34), so the flux of kinetic energy with the material is
      not in lambda . b'; the elastic and gravity forces are gradients of U(Q) and V(Q), whose
      limits are coordinates, so their fluxes are (measured on beam_through_sleeve at rtol
      1e-6: the balance without the flux is off by 3.85 J/s = rhoA |s'|^3 / 2, with it
      closed to 6e-6 of E_x);
    * moving or switched point loads: f . v at the loaded material point.

    Without the stress filter every other force is conservative, so E(t) - E(0) - W(t) = 0 up
    to the integration error; with it the filter only takes energy out (beyond its mass-like
    term's small store), so only growth is checked.  The value is
    max_t |E - E(0) - W| (growth: max_t of E - E(0) - W) over the exchanged energy E_x =
    ptp(T) + ptp(U) + ptp(V) + ptp(W), at least STORED_FLOOR (max T + max U); the limits are
    ENERGY_SUSPECT and ENERGY_FAIL plus the quadrature error of W (its trapezoid on every
    second output against all outputs), over E_x.  Healthy runs stay far below the limits (the
    released cantilever: 1e-9 at rtol 1e-6, 2.3e-6 at rtol 1e-3; beam_through_sleeve: no
    growth)."""
    if not len(res.t) or "state" not in res:
        return {}
    ts = np.asarray(res.t, dtype=float)
    n = model.n_dof
    Y = np.asarray(res["state"])
    T, U, V = (np.asarray(res[k], dtype=float) for k in
               ("energy_kinetic", "energy_strain", "energy_gravity"))
    V = V.copy()
    P = np.zeros(len(ts))                         # power fed in, W
    fed = []
    moving = [c for c in model.constraints if not c.constant]
    if moving:
        # every loop over the outputs checks the run's wall budget and Ctrl-C (run_control)
        P += np.array([float(np.dot(np.real(res["reactions"][k]), model.linear_targets(t, 1)))
                       for k, t in run_control.checked(enumerate(ts))])
        fed.append("prescribed motion")
    for bc in scene.get("boundary", []):
        if bc["kind"] != "sleeve" or bc["speed"] == 0.0:
            continue
        # material crossing a sleeve end carries its kinetic energy density across the
        # modelled part's boundary (the strain and gravity densities are in lambda . b')
        bps = scene["beams"][bc["beam"]]["breakpoints"]
        s0, sign = (bps[0], -1.0) if bc["end"] == "left" else (bps[-1], 1.0)
        motion = sleeve_motion(bc, s0)
        for k, (t, y) in run_control.checked(enumerate(zip(ts, Y))):
            s_b, rate, _ = motion(t)
            P[k] += sign * rate * _kinetic_density(model, bc["beam"], s_b, t, y)
        if "material flow" not in fed:
            fed.append("material flow")
    for pl_scene, pl in zip(scene.get("point_loads", []), model.point_loads):
        if pl_scene["speed"] == 0.0 and pl_scene["start"] <= 0.0:
            for k, (t, y) in run_control.checked(enumerate(zip(ts, Y))):
                Q, _ = model.full_state(t, y[:n], y[n:])
                r, _, _ = model.point(pl.beam, pl.s_of_t(t), Q)
                V[k] -= float(np.dot(np.asarray(pl.force(t), float), np.real(r)))
        else:
            for k, (t, y) in run_control.checked(enumerate(zip(ts, Y))):
                _, v, _ = model.point_motion(pl.beam, pl.s_of_t(t), t, y[:n], y[n:])
                P[k] += float(np.dot(np.asarray(pl.force(t), float), np.real(v)))
            fed.append("point load")
    W = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(ts))])
    quad = 0.0
    if fed and len(ts) >= 3:
        tc, Pc = ts[::2], P[::2]
        Wc = np.concatenate([[0.0], np.cumsum(0.5 * (Pc[1:] + Pc[:-1]) * np.diff(tc))])
        quad = float(np.max(np.abs(Wc - W[::2])))
    E = T + U + V
    resid = E - E[0] - W
    scale = float(np.ptp(T) + np.ptp(U) + np.ptp(V) + np.ptp(W))
    scale = max(scale, STORED_FLOOR * float(np.max(T) + np.max(U)), 1e-300)
    dissipative = bool(scene.get("effects", {}).get("filtering"))
    value = float(np.max(resid)) if dissipative else float(np.max(np.abs(resid)))
    value = value / scale if np.isfinite(value) else math.inf
    q = quad / scale
    what = ("energy growth" if dissipative else "energy drift") + \
        " / exchanged energy (E = T + U + V" + (", W: " + ", ".join(fed) if fed else "") + \
        f"; E_x = {scale:.3g} J" + (f", quadrature {q:.2g}" if fed else "") + ")"
    return {"energy_balance": verdict(value, ENERGY_SUSPECT + q, ENERGY_FAIL + q, what)}


@run_control.budgeted
def run(scene: dict, progress=None, checkpoint=None) -> Result:
    """Integrate a validated beam scene (:func:`sim_core.systems.beam.schema.validate`) from
    its initial state (or its static equilibrium) and return a Result.

    Outputs: ``tip_position``, ``tip_velocity``, ``tip_acceleration`` (right end of the last
    beam, material point s = L), ``energy_kinetic``, ``energy_strain``, ``energy_gravity`` (J),
    ``element_ends`` (material coordinates of all breakpoints, m) and ``reactions`` (one column
    per constraint row, N or N m).

    Every finished run checks its own result (:func:`run_with_partial`): the beam scenes'
    energy balance (:func:`beam_energy_check`) and, where the result has one, the constraint
    violation (:func:`result_checks`).  The verdicts are in ``result.stats`` (``checks``,
    ``suspect``, ``failed_checks``; ``Result.suspect``, ``Result.suspect_note()``); a gross
    failure raises :class:`sim_core.errors.SuspectResult` with the result attached.

    ``checkpoint``: a :class:`sim_core.checkpoint.Checkpointer` the integration writes to and
    resumes from (None: no checkpoints).
    """
    model, Q0, Qd0 = build_model(scene)
    sol = scene["solver"]
    z0, zd0 = model.reduced_state(0.0, Q0, Qd0)
    if scene["initial"]["static_equilibrium"]:
        z0 = static_equilibrium(model, z0)
    y0 = np.concatenate([z0, zd0])
    return run_with_partial(lambda: integrate(model, y0, sol["t_end"], sol, progress, checkpoint),
                            lambda ts, ys, stats, err: _beam_result(model, scene, ts, ys, stats, err),
                            lambda res: beam_energy_check(model, scene, res))


def _beam_result(model, scene, ts, ys, stats, error) -> Result:
    """The beam scene's outputs at the output times.  An output state where the model cannot
    be evaluated (non-finite or singular dynamics, a failed element batch: a dense-output
    state far off the solution) ends the outputs there; for a finished run (``error`` None)
    that raises SimulationError at its time with the outputs before it attached."""
    n = model.n_dof
    g = np.array(scene["gravity"]["g"]) if scene["effects"]["gravity"] else None
    last = len(model.beams) - 1
    L = model.beams[last].length
    out: dict[str, list] = {k: [] for k in ("tip_position", "tip_velocity", "tip_acceleration",
                                            "energy_kinetic", "energy_strain", "energy_gravity",
                                            "element_ends", "reactions")}
    failure = None
    stop = run_control.OutputGuard(partial=error is not None)    # the run's budget, Ctrl-C
    for t, y in zip(ts, ys):
        if stop(t):
            break
        z, zd = y[:n], y[n:]
        try:
            with np.errstate(over="raise", divide="raise", invalid="raise", under="ignore"):
                solved = model.accelerations_and_multipliers(t, z, zd)
                zdd = solved[0]
                r, v, a = model.point_motion(last, L, t, z, zd, zdd)
                Q, Qd = model.full_state(t, z, zd)
                en = model.energies(t, Q, Qd, g)
                reac = model.reactions(t, z, zd, solved)
            if not (np.all(np.isfinite(zdd)) and np.all(np.isfinite(reac))
                    and np.isfinite(en["T"] + en["U"] + en["V"])):
                raise FloatingPointError("non-finite accelerations, reactions or energies")
        except (ValueError, ArithmeticError, np.linalg.LinAlgError,
                ElementEvaluationError) as exc:
            failure = (float(t), exc)
            break
        out["tip_position"].append(r)
        out["tip_velocity"].append(v)
        out["tip_acceleration"].append(a)
        out["energy_kinetic"].append(en["T"])
        out["energy_strain"].append(en["U"])
        out["energy_gravity"].append(en["V"])
        out["element_ends"].append([Q[off + b.s_coord(k)] for b, off in zip(model.beams, model.offsets)
                                    for k in range(len(b.breakpoints))])
        out["reactions"].append(reac)
    k = len(out["tip_position"])
    outputs = {name: np.real(np.array(v, dtype=float)) for name, v in out.items()}
    outputs["state"] = np.asarray(ys)[:k]
    stats["n_dof"] = int(n)
    res = Result(np.asarray(ts)[:k], outputs, stats, scene, error)
    if failure is not None and error is None:
        t, cause = failure
        why = cause.reason if isinstance(cause, SimulationError) else \
            f"{type(cause).__name__}: {cause}"
        exc = SimulationError(t, "the model cannot be evaluated at the integrated state of this "
                                 f"output time ({why}): the solution left the model's domain "
                                 "(steps far too large for its dynamics; tighten solver.rtol)",
                              last_state=np.asarray(ys)[k])
        res.error = str(exc)
        exc.result = res
        raise exc
    return stop.finish(res)
