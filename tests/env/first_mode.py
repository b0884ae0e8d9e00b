"""The first in-plane mode of a modal table against the full model's state Jacobian: the shared
procedure of the three- and five-section table checks (tests/env/test_modal.py,
tests/env/test_booms5.py)."""

from dataclasses import replace

import numpy as np


def first_mode_table_and_jacobian(n_booms: int, payload: float, angle: float, L_s: float):
    """(omega_table, zeta_table, omega, zeta) of the first in-plane mode at a grid point: the
    table's, and the eigenvalue of the full model's state Jacobian (central differences) at the
    static equilibrium with the table's rope lengths that lies on the constraint manifold
    (C dz = 0) and moves the tip in the luffing plane, the smallest such |lambda|; omega =
    |lambda|, zeta = -Re(lambda) / |lambda| (rad/s, -)."""
    from sim_core.model.state_jacobian import state_jacobian
    from sim_core.physics.constraints import constraint_terms
    from sim_core.systems.telescopic.modal import (
        L_GRID,
        N_NODES,
        equilibrium_at,
        load_raw,
        reference_rope_lengths,
        table_params,
    )
    r = load_raw(n_booms=n_booms)
    ia = int(np.flatnonzero(np.isclose(r["angles"], angle))[0])
    ip = int(np.flatnonzero(np.isclose(r["payloads"], payload))[0])
    iL = int(np.flatnonzero(np.isclose(L_GRID, L_s))[0])
    w_tab, z_tab = r["omega"][ia, ip, iL, 0], r["zeta"][ia, ip, iL, 0]
    p = replace(table_params(n_booms), payload=payload, luffing_angle_deg=angle,
                n_nodes=N_NODES, friction=False)
    ts, z, _ = equilibrium_at(p, L_s, reference_rope_lengths(p))
    m = ts.model
    n = len(z)
    J = state_jacobian(m, 0.0, np.concatenate([z, np.zeros(n)]), central=True)
    ev, V = np.linalg.eig(J)
    Q, _ = m.full_state(0.0, z, np.zeros(n))
    C = constraint_terms(m.nonlinear, 0.0, Q, np.zeros_like(Q))[1] @ m.P
    _, Jt, _, _ = ts.tip(Q)
    best = None
    for k in np.flatnonzero(ev.imag > 1e-6):
        dz = V[:n, k]
        on_manifold = np.linalg.norm(C @ dz) <= 1e-6 * np.linalg.norm(C) * np.linalg.norm(dz)
        tip = np.abs(Jt @ m.P @ dz)
        in_plane = np.hypot(tip[0], tip[2]) > 10.0 * tip[1]
        if on_manifold and in_plane and (best is None or abs(ev[k]) < abs(ev[best])):
            best = k
    assert best is not None, "no in-plane oscillatory mode on the constraint manifold"
    w, zeta = abs(ev[best]), -ev[best].real / abs(ev[best])
    print(f"first in-plane mode: table {w_tab / 2 / np.pi:.6f} Hz zeta {z_tab:.6f}; state "
          f"Jacobian {w / 2 / np.pi:.6f} Hz zeta {zeta:.6f}")
    return w_tab, z_tab, w, zeta
