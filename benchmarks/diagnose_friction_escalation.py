"""Why RK45's step collapses in the paper scene `telescopic_extraction` near t = 14.55 s.

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/diagnose_friction_escalation.py \
        [--n-nodes 3] [--t-end 20] [--set effects.contact_distribution=false ...]

Integrates the scene (scipy's RK45 directly, the same settings as sim_core) and every 0.5 s
prints one row: t (s), telescopic-cylinder force (N), extraction and retraction rope tensions
(N), and per contact region (I_12, II_12, I_23, II_23) the contact coordinate rate s_dot (m/s)
and the friction load N (sum of the slider spring forces, N).  When 40 consecutive accepted
steps are below 0.3 ms after t = 1 s it stops and analyses the state: the right-hand side
evaluated repeatedly (inner-iteration noise), the friction state of every region, the rope
stretches, and the eigenvalues of a central-difference Jacobian of the right-hand side with the
coordinates their eigenvectors load most (findings: CHANGELOG.md, docs/model.md).  ~10 min at
n_nodes = 3 on the 2-core machine.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.integrate import RK45

from sim_core import load_scene
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.schema import params_from_scene


def _value(v: str):
    return (v == "true") if v in ("true", "false") else float(v)


def state_row(ts, t, y):
    m = ts.model
    n = m.n_dof
    z, zd = y[:n], y[n:]
    Q, Qd = m.full_state(t, z, zd)
    _, lam = m.accelerations_and_multipliers(t, z, zd)
    row = [t, float(lam[ts.rows["telescopic_cylinder"]][0])]
    row += [pe.tension(float(pe.length(Q)[0])) for pe in m.point_effects if hasattr(pe, "L0")]
    if ts.contact is not None:
        for _, s_idx, _, sol in ts.contact.solve_regions(Q, Qd, lam):
            row += [float(Qd[s_idx]), sol if isinstance(sol, float) else sol.total_normal_force]
    return row


def analyse(ts, t, y):
    m = ts.model
    n = m.n_dof
    f = [m.rhs(t, y) for _ in range(3)]
    scale = np.max(np.abs(f[0]))
    print(f"snapshot t = {t:.6f} s; repeated rhs differ by {np.max(np.abs(f[1] - f[0])) / scale:.1e}"
          f" and {np.max(np.abs(f[2] - f[1])) / scale:.1e} (relative)")
    z, zd = y[:n], y[n:]
    Q, Qd = m.full_state(t, z, zd)
    _, lam = m.accelerations_and_multipliers(t, z, zd)
    if ts.contact is not None:
        for name, s_idx, mu, sol in ts.contact.solve_regions(Q, Qd, lam):
            N = sol if isinstance(sol, float) else sol.total_normal_force
            print(f"  {name}: s_dot = {Qd[s_idx]: .5f} m/s, mu = {mu: .4f}, N = {N:.4g} N, "
                  f"d mu/dv * N = {ts.contact.law.dmu_dv(float(Qd[s_idx])) * N:.3g} N s/m")
    for pe in m.point_effects:
        if hasattr(pe, "L0"):
            ell = float(pe.length(Q)[0])
            print(f"  {pe.name}: stretch {ell - pe.L0: .3e} m, tension {pe.tension(ell):.4g} N")
    J = np.empty((len(y), len(y)))
    for j in range(len(y)):
        e = np.zeros(len(y))
        e[j] = 1e-7 * max(1.0, abs(y[j]))
        J[:, j] = (m.rhs(t, y + e) - m.rhs(t, y - e)) / (2 * e[j])
    ev, V = np.linalg.eig(J)
    contact = {int(np.argmax(np.abs(m.P[i]))): f"s_2 of boom {k + 1}"
               for k, i in enumerate(ts.s2_index)}
    contact.update({int(np.argmax(np.abs(m.P[i]))): f"s_3 of boom {k + 1}"
                    for k, i in enumerate(ts.s3_index)})
    for k in np.argsort(-np.abs(ev))[:4]:
        top = np.argsort(-np.abs(V[:n, k]))[:3]
        names = [contact.get(int(i), f"z[{i}]") for i in top]
        print(f"  eigenvalue {ev[k]:.4g} 1/s (RK45 step bound ~{3.3 / abs(ev[k]):.1e} s); "
              f"eigenvector mostly on {names}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-nodes", type=int, default=3)
    ap.add_argument("--t-end", type=float, default=20.0)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    over = {"booms.n_nodes": args.n_nodes}
    over.update({k: _value(v) for k, _, v in (kv.partition("=") for kv in args.set)})
    ts = build_telescopic(params_from_scene(load_scene("telescopic_extraction", overrides=over)))
    m = ts.model
    z, _ = initial_equilibrium(ts)
    y0 = np.concatenate([z, 0 * z])
    sol = RK45(m.rhs, 0.0, y0, args.t_end, rtol=1e-6, atol=1e-7)
    print("t cyl_force rope_ext rope_retr" + (" sdot_I12 N_I12 sdot_II12 N_II12 sdot_I23 N_I23"
                                              " sdot_II23 N_II23" if ts.contact else ""))
    wall0, next_t, small = time.perf_counter(), 0.0, 0
    while sol.status == "running":
        sol.step()
        h = sol.t - sol.t_old
        if sol.t >= next_t:
            print(" ".join(f"{x:.4g}" for x in state_row(ts, sol.t, sol.y)),
                  f"wall={time.perf_counter() - wall0:.0f}s", flush=True)
            next_t += 0.5
        small = small + 1 if (sol.t > 1.0 and h < 3e-4) else 0
        if small > 40:
            analyse(ts, sol.t, sol.y)
            return 0
    print(f"completed t = {sol.t:.3f} s without a step collapse "
          f"(wall {time.perf_counter() - wall0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
