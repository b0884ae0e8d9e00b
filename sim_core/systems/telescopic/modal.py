"""Stroke-parametric modal reduced-order model (ROM) of the telescopic boom system, derived from
the full sim_core model (sim_core.systems.telescopic.build, Zhao-Qi-Wang 2024).  SI units throughout.

Table build (``python -m sim_core.systems.telescopic.modal --build [--booms 5]``)
-------------------------------------------------------------------------------
Tables exist for the paper's three booms (``data/modal_telescopic.npz``) and for five sections
(``data/modal_telescopic_5.npz``: the paper's three inside two larger ones,
``params.crane_sections``), both with the synchronized drive: every stage moves with the same
piston length L_s, so one stroke coordinate parametrises the equilibrium (``data_path``,
``TABLE_BOOMS``).  Each file records its boom count (``n_booms``; a file without it holds three)
and its grid, which sets the ranges the ROM accepts (``allowed_ranges``).  One grid point costs
about 2 s at 223 coordinates (five booms, n_nodes = 3; 99 points in 5 minutes on 2 shared
cores; build logs beside the data).

For every configuration (payload mass m_p kg, luffing angle theta deg) and every piston length
L_s (m) of a grid spanning the telescopic stroke range, with the *full* sim_core model at a coarse
discretisation (n_nodes = 3 per spline element, frictionless resultants, stress filter on):

1. every telescopic cylinder is frozen at L_s (``build_telescopic`` with stroke0 = L_s: the
   cylinder target is L_s with zero rate and acceleration at t = 0) and the static equilibrium
   z_s(L_s) under gravity and payload is solved (``constrained_static_equilibrium``).  The ropes
   (every rope unit of the crane) keep the unstretched lengths of the reference build at
   ``stroke_ref`` (the physical ropes of the scene; their lengths are stroke invariant,
   docs/model.md#input-ropes);
2. the reduced tangent stiffness K = -d(F_r + C^T lambda)/dz (``tangent_stiffness``: central
   differences, step 1e-8 max(1, max|z|), symmetrised; constraint multipliers frozen: geometric
   stiffness of the constraints included), the reduced damping
   D = -dF_r/dz_dot (stress-filter damping, SIMULTECH 2020 Eq. 53) and the reduced mass M_r (with
   the filter's (h^2/6) K mass term) are evaluated about z_s;
3. constrained modes: K N x = omega^2 M_r N x on the null space N of the constraint Jacobian
   C = g_Q P (cylinder frozen), mass-normalised (phi^T M_r phi = 1).  Out-of-plane modes (tip
   X, Z components zero by symmetry of the luffing plane) are dropped: they are not excited by
   the in-plane stroke motion.  The lowest ``N_MODES_TABLE`` in-plane modes are kept, signs
   aligned from grid point to grid point (phi_prev^T M_r phi > 0);
4. the stroke tangent dz_s/dL_s follows exactly from the implicit-function theorem on the
   equilibrium (KKT system [-K C^T; C 0] [dz; dlambda] = [0; e_cyl], e_cyl = 1 in the row of
   every cylinder), checked against the difference quotient of the neighbouring equilibria
   (reported by --build);
5. modal loads: Gamma_i = phi_i^T M_r dz_s/dL_s (participation of the stroke acceleration),
   and the velocity-dependent loads of the steady sliding motion Qdot = Q_s' v,
   b1_i v + b2_i v^2 = phi_i^T [F(Q_s, Q_s' v) - F(Q_s, 0)] (convective/filter terms of the
   full model, from F at v = +-v_ref), plus Gamma2_i = phi_i^T M_r d^2 z_s/dL_s^2 (difference
   quotient of dz_s/dL_s along the grid);
6. the static tip position r_s(L_s) (boom N, s = L) and the tip components of every mode
   phi_tip,i = J_tip P phi_i are tabulated, with the modal damping zeta_i = phi_i^T D phi_i /
   (2 omega_i) of the full model (the filter alone gives zeta ~ h omega / 4,
   docs/model.md#input-filter; the rope damping adds to it).

ROM dynamics (projection of M Q_ddot = F + C^T lambda onto the modes about the moving static
equilibrium Q = Q_s(L_s(t)) + sum_i phi_i q_i, with a = L_s_ddot, v = L_s_dot):

    q_i'' + 2 zeta_i omega_i q_i' + omega_i^2 q_i
        = -Gamma_i(L_s) a - (Gamma2_i(L_s) - b2_i(L_s)) v^2 + b1_i(L_s) v

    tip(t) = r_s(L_s) + sum_i phi_tip,i(L_s) q_i,   tip velocity = r_s' v + sum_i phi_tip,i q_i'

All coefficients are linearly interpolated in L_s (and bilinearly in payload and angle between
table configurations).  Neglected terms: the parametric terms of the time-varying basis
(phi_i' v q_i', phi_i'' v^2 q_i, modal coupling through d phi/dL_s), geometric non-linearity
of the vibration about the static equilibrium (amplitudes are mm-cm on 25-30 m of boom), modes
above the kept ones (static correction not added), off-diagonal modal damping, and friction
(the tables are frictionless: Section 8 friction of the full model is not represented).
"""

from __future__ import annotations

import argparse
import io
import math
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from sim_core.errors import SimulationError
from sim_core.result import atomic_write_bytes
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium
from sim_core.systems.telescopic.params import TelescopicParams

DATA = Path(__file__).parent / "data" / "modal_telescopic.npz"      # the paper's three booms
N_MODES_TABLE = 4
# Table grid (stroke range 2 -> 8 m of docs/model.md#input-drive plus margin for the end stops
# of boom_env).
L_GRID = np.linspace(1.75, 8.25, 11)       # avoids stroke_ref = 2 m (rope kink, see below)
PAYLOADS = (20000.0, 25000.0, 30000.0)          # kg
ANGLES = (45.0, 60.0, 75.0)                     # deg (the paper's 60 deg +- 15 deg)
# shipped table sets: boom count -> default payloads (kg) of its build.  Five sections (the
# paper's three inside two larger ones, params.crane_sections) carry 5-15 t: 10 t at 42 m keeps
# boom 1's root bending stress near the paper scene's (scene telescopic_extraction_5)
TABLE_BOOMS = {3: PAYLOADS, 5: (5000.0, 10000.0, 15000.0)}
N_NODES = 3
STROKE_REF = 2.0
V_REF = 0.5                                     # m/s, for the velocity-dependent loads
K_REL_STEP = 1e-8           # difference step of K per unit of max(1, max|z|) (tangent_stiffness)
CLUSTER_GAP = 0.02          # relative gap of omega^2 below which modes form one cluster

COLS = ("omega", "zeta", "gamma", "gamma2", "b1", "b2", "phi_x", "phi_z")


def data_path(n_booms: int = 3) -> Path:
    """File of the modal tables of an ``n_booms``-section crane (synchronized drive):
    ``data/modal_telescopic.npz`` for the paper's three booms, ``modal_telescopic_<N>.npz``
    otherwise.  ValueError for a count without shipped tables."""
    if n_booms not in TABLE_BOOMS:
        raise ValueError(f"n_booms = {n_booms!r}: modal tables exist for booms "
                         f"{', '.join(str(k) for k in TABLE_BOOMS)} (allowed values)")
    return DATA if n_booms == 3 else DATA.with_name(f"modal_telescopic_{n_booms}.npz")


def _require_synchronized(mechanism: str, hint: str = "") -> None:
    """ValueError unless the drive is synchronized: the tables follow one stroke coordinate."""
    if mechanism != "synchronized":
        raise ValueError(f"mechanism = {mechanism!r}: the modal tables follow one stroke "
                         f"coordinate (allowed: 'synchronized'){hint}")


def table_params(n_booms: int = 3) -> TelescopicParams:
    """The TelescopicParams the tables of ``n_booms`` sections are built from (payload, angle,
    stroke and n_nodes set per configuration; frictionless, synchronized drive)."""
    data_path(n_booms)
    return TelescopicParams(n_booms=n_booms, mechanism="synchronized")


def _frozen_system(params, L_s):
    return build_telescopic(replace(params, stroke0=float(L_s)))


def _ropes(model):
    return {pe.name: pe for pe in model.point_effects if hasattr(pe, "L0")}


def equilibrium_at(params, L_s, rope_L0: dict, z_guess=None):
    """(system, z, lambda): the full model (TelescopicParams ``params``) with every cylinder
    frozen at piston length L_s (m), the ropes at the unstretched lengths ``rope_L0`` (m, by
    name: every rope unit of the crane), in static equilibrium at t = 0.  ``z_guess``: start
    of the Newton iteration relative to the built configuration (continuation)."""
    from sim_core.model.statics import constrained_static_equilibrium
    ts = _frozen_system(params, L_s)
    m = ts.model
    ropes = _ropes(m)
    if set(ropes) != set(rope_L0):
        raise ValueError(f"rope_L0 names {sorted(rope_L0)} differ from the model's ropes "
                         f"{sorted(ropes)}")
    for name, r in ropes.items():
        r.L0 = rope_L0[name]
    z0, _ = m.reduced_state(0.0, ts.Q0, np.zeros_like(ts.Q0))
    if z_guess is not None:
        z0 = z0 + z_guess
    z, lam = constrained_static_equilibrium(m, z0, 0.0)
    return ts, z, lam


def linearize_at(params, L_s, rope_L0: dict, z_guess=None, lam_guess=None,
                 k_rel_step=K_REL_STEP, k_central=True):
    """Equilibrium, modes and modal loads of the full model with the cylinders frozen at L_s (m).
    ``k_rel_step``, ``k_central``: the differences of K (``tangent_stiffness``).

    Returns a dict (see module docstring) with z-space quantities for continuation."""
    from sim_core.physics.constraints import constraint_terms
    ts, z, lam = equilibrium_at(params, L_s, rope_L0, z_guess)
    m = ts.model
    n = len(z)
    zero = np.zeros(n)

    def parts(zz, zd=zero):
        Q, Qd = m.full_state(0.0, zz, zd)
        _, F = m.mass_force(0.0, Q, Qd, mass=False)
        phi, J, _, _ = constraint_terms(m.nonlinear, 0.0, Q, Qd)
        C = J @ m.P
        return m.P.T @ F, C

    Fr0, C = parts(z)
    K = tangent_stiffness(parts, z, lam, k_rel_step, k_central)
    Q, _ = m.full_state(0.0, z, zero)
    M, _ = m.mass_force(0.0, Q, np.zeros_like(Q))
    Mr = m.P.T @ M @ m.P
    Nb = sla.null_space(C)
    w2, X = sla.eigh(Nb.T @ K @ Nb, Nb.T @ Mr @ Nb)
    phi = Nb @ X                                       # mass-normalised: phi^T Mr phi = I
    w2, phi = _separate_planes(w2, phi, _end_displacements(ts, Q))
    _, Jt, _, _ = ts.tip(Q)
    tip_modes = Jt @ m.P @ phi                         # (3, n_modes_all)
    inplane = np.hypot(tip_modes[0], tip_modes[2]) > 10.0 * np.abs(tip_modes[1])
    keep = np.flatnonzero(inplane & (w2 > 0))[:N_MODES_TABLE]
    # stroke tangent from the implicit-function theorem (cylinder row: g = L_s)
    mC = C.shape[0]
    e = np.zeros(mC)
    for name in ts.drives:                             # synchronized: every stage moves with L_s
        e[ts.rows[name]] = 1.0
    # particular solution of C dz = e plus the null-space correction N y with N^T K dz = 0
    # (robust to redundant constraint rows, which make the KKT matrix singular)
    dz_p = np.linalg.lstsq(C, e, rcond=None)[0]
    y = -np.linalg.solve(Nb.T @ K @ Nb, Nb.T @ K @ dz_p)
    dz_dL = dz_p + Nb @ y
    # velocity-dependent loads of the steady sliding motion Qdot = Q_s' v
    Fp, _ = parts(z, dz_dL * V_REF)
    Fm, _ = parts(z, -dz_dL * V_REF)
    b1 = (Fp - Fm) / (2 * V_REF)
    b2 = (Fp + Fm - 2 * Fr0) / (2 * V_REF ** 2)
    P = phi[:, keep]
    omega = np.sqrt(w2[keep])
    # modal damping: directional derivatives of F along each kept mode's velocity
    hv = 1e-4
    D_modal = np.array([-(P[:, k] @ (parts(z, hv * P[:, k])[0] - parts(z, -hv * P[:, k])[0]))
                        / (2 * hv) for k in range(P.shape[1])])
    tensions = {nm: r.tension(float(np.real(r.length(Q)[0]))) for nm, r in _ropes(m).items()}
    return {"z": z, "lam": lam, "z_rel": z - m.reduced_state(0.0, ts.Q0, np.zeros_like(ts.Q0))[0],
            "phi": P, "Mr": Mr, "omega": omega,
            "zeta": D_modal / (2 * omega), "tensions": tensions,
            "gamma": P.T @ Mr @ dz_dL, "dz_dL": dz_dL, "b1": P.T @ b1, "b2": P.T @ b2,
            "tip": ts.tip(Q)[0], "tip_modes": tip_modes[:, keep], "tip_dL": Jt @ m.P @ dz_dL,
            "all_freq_hz": np.sqrt(np.clip(w2[:12], 0, None)) / (2 * np.pi)}


def _end_displacements(ts, Q):
    """(3, 2 N_booms, n) map of reduced coordinates to the global X, Y (lateral), Z
    displacements of both ends of every boom, at the configuration Q."""
    from sim_core.physics.constraints import material_point
    m = ts.model
    L = ts.params.boom_length
    J = [material_point(m, k, s_fixed=s)(Q)[1] @ m.P for k in range(len(m.beams))
         for s in (0.0, L)]
    return np.stack(J, axis=1)


def _separate_planes(w2, phi, D, gap=CLUSTER_GAP, tol=1e-3):
    """Modes (omega^2 (n_m,), mass-normalised phi (n, n_m)) with near-degenerate in-plane and
    lateral modes separated.

    The luffing plane X-Z is a plane of symmetry of the scene: in-plane and lateral modes
    decouple exactly.  Where an in-plane and a lateral frequency nearly coincide (relative gap
    of omega^2 below ``gap``; five booms at L_s = 1.75 m, 10 t, 60 deg: 1.4171 and 1.4197 Hz)
    the difference error of K (its asymmetric part, ``tangent_stiffness``) mixes them, and the
    tip criterion of the caller drops both.  Within each such cluster the lateral displacements
    of the boom ends, ``D[1] @ phi`` (D: (3, p, n) from ``_end_displacements``), split the mode
    space: their row space (singular values above ``tol`` times the largest end displacement of
    the cluster's modes) holds the lateral combinations, its null space the in-plane ones.  Each
    part is re-diagonalised (Rayleigh-Ritz with K = diag(omega^2) in the cluster's M-orthonormal
    basis), so the vectors stay M-orthonormal; the discarded coupling between the parts is
    the noise (zero by symmetry), and the separated frequencies are Rayleigh quotients inside
    the cluster (exact to the cluster's width, and to the noise's share of it where the mixing
    is slight).  Clusters of one kind only are left as they are."""
    w2 = np.array(w2, dtype=float)
    phi = np.array(phi, dtype=float)
    i = 0
    nm = len(w2)
    while i < nm:
        j = i
        while j + 1 < nm and w2[j + 1] - w2[j] <= gap * abs(w2[j + 1]):
            j += 1
        if j > i:
            idx = np.arange(i, j + 1)
            Yc = D[1] @ phi[:, idx]
            scale = np.max(np.linalg.norm(D @ phi[:, idx], axis=(0, 1)))
            _, sv, Vt = np.linalg.svd(Yc)
            r = int(np.sum(sv > tol * scale))
            if 0 < r < len(idx):
                W = np.diag(w2[idx])
                new_w, new_v = [], []
                for S in (Vt[:r].T, Vt[r:].T):          # lateral, in-plane combinations
                    vals, R = np.linalg.eigh(S.T @ W @ S)
                    new_w.append(vals)
                    new_v.append(phi[:, idx] @ S @ R)
                w2[idx] = np.concatenate(new_w)
                phi[:, idx] = np.hstack(new_v)
        i = j + 1
    order = np.argsort(w2, kind="stable")
    return w2[order], phi[:, order]


def tangent_stiffness(parts, z, lam, rel_step=K_REL_STEP, central=True, symmetrise=True):
    """K = -d(F_r + C^T lambda)/dz at frozen multipliers lambda, symmetrised (SI units of
    force per unit of each coordinate); ``parts(z) -> (F_r, C)`` gives the reduced force and
    the constraint Jacobian.

    Central differences with one step h = rel_step max(1, max|z|) for every coordinate
    (truncation error h^2/6 times the third derivative of the potential).  The step matters:
    a tension-only rope near zero tension has its slack kink (a C1 ramp over slack_width =
    1e-6 m, point_effects.RopeDrive) within micrometres of the equilibrium, and forward
    differences with h = 1e-7 max|z| (2.3e-6 at five booms) give K an asymmetry of
    7e-4 max|K| there: at five booms, 75 deg, 5 t, L_s = 3.05 m the third in-plane mode moves
    from 4.40 to 5.05 Hz and the tip slope of the stroke tangent from 4.00 to 3.54 m/m.  The
    exact K is symmetric (conservative elastic, gravity, rope and constraint forces), so the
    asymmetric part of the differenced K measures its error: 3e-9 max|K| with the default step
    there.  ``central=False``, ``rel_step=1e-7``: forward differences (for that comparison).
    ``symmetrise=False``: the differenced K as it is (for its error estimate)."""
    n = len(z)
    f0, C0 = parts(z)
    r0 = f0 + C0.T @ lam
    h = rel_step * max(1.0, float(np.max(np.abs(z))))
    K = np.empty((n, n))
    for j in range(n):
        dz = np.zeros(n)
        dz[j] = h
        fp, Cp = parts(z + dz)
        if central:
            fm, Cm = parts(z - dz)
            K[:, j] = -((fp + Cp.T @ lam) - (fm + Cm.T @ lam)) / (2.0 * h)
        else:
            K[:, j] = -((fp + Cp.T @ lam) - r0) / h
    return 0.5 * (K + K.T) if symmetrise else K


def reference_rope_lengths(p, stroke_ref=STROKE_REF) -> dict:
    """Unstretched rope lengths (m) of the scene ``p`` (TelescopicParams): those of its static
    equilibrium at piston length ``stroke_ref``, where the retraction rope is set just taut
    (docs/model.md#input-ropes).  The ropes keep them at every other piston length."""
    ref = build_telescopic(replace(p, stroke0=stroke_ref))
    initial_equilibrium(ref)
    return {k: r.L0 for k, r in _ropes(ref.model).items()}


def build_config(payload, angle_deg, L_grid=L_GRID, stroke_ref=STROKE_REF, n_nodes=N_NODES,
                 base=None, log=print):
    """Tables of one (payload kg, angle deg) configuration: dict of arrays over L_grid."""
    p = replace(base or TelescopicParams(), payload=float(payload),
                luffing_angle_deg=float(angle_deg), n_nodes=n_nodes, friction=False)
    rope_L0 = reference_rope_lengths(p, stroke_ref)
    order = np.argsort(np.abs(L_grid - stroke_ref))   # continuation outward from stroke_ref
    res = [None] * len(L_grid)
    for i in order:
        t0 = time.perf_counter()
        near = [j for j in range(len(L_grid)) if res[j] is not None]
        guess = res[min(near, key=lambda j: abs(L_grid[j] - L_grid[i]))]["z_rel"] if near else None
        try:
            res[i] = linearize_at(p, L_grid[i], rope_L0, z_guess=guess)
        except SimulationError as exc:
            if guess is None:
                raise
            # the neighbour's equilibrium is too far for Newton (five booms, 45 deg, 10 t,
            # 7.6 -> 8.25 m): load continuation from the built configuration instead
            log(f"  L_s={L_grid[i]:.3f} m: continuation from the neighbour failed ({exc}); "
                "solved from the built configuration")
            res[i] = linearize_at(p, L_grid[i], rope_L0)
        log(f"  m_p={payload:g} kg theta={angle_deg:g} deg L_s={L_grid[i]:.3f} m: in-plane f = "
            + ", ".join(f"{w / 2 / np.pi:.3f}" for w in res[i]["omega"])
            + " Hz, zeta = " + ", ".join(f"{x:.4f}" for x in res[i]["zeta"])
            + ", ropes " + ", ".join(f"{k} {v / 1e3:.1f} kN" for k, v in res[i]["tensions"].items())
            + f" ({time.perf_counter() - t0:.1f} s)")
    # sign alignment along the grid (reference: positive Gamma at the first point)
    for i in range(len(L_grid)):
        r = res[i]
        for k in range(r["phi"].shape[1]):
            if i == 0:
                s = np.sign(r["gamma"][k]) or 1.0
            else:
                prev = res[i - 1]
                s = np.sign(prev["phi"][:, k] @ r["Mr"] @ r["phi"][:, k]) or 1.0
                mac = abs(prev["phi"][:, k] @ r["Mr"] @ r["phi"][:, k])
                if mac < 0.8:
                    log(f"  warning: mode {k} at L_s={L_grid[i]:.2f} m correlates {mac:.2f} "
                        "with the previous grid point (mode crossing?)")
            for key in ("phi", "tip_modes"):
                r[key][..., k] *= s
            for key in ("gamma", "b1", "b2"):
                r[key][k] *= s
    dzdL = np.array([r["dz_dL"] for r in res])
    d2 = np.gradient(dzdL, L_grid, axis=0)
    zs = np.array([r["z"] for r in res])
    fd = np.gradient(zs, L_grid, axis=0)
    log(f"  check dz/dL_s: implicit-function vs grid difference quotient, max rel. diff "
        f"{np.max(np.linalg.norm(fd - dzdL, axis=1) / np.linalg.norm(dzdL, axis=1)):.2e}")
    out = {"omega": np.array([r["omega"] for r in res]),
           "zeta": np.array([r["zeta"] for r in res]),
           "gamma": np.array([r["gamma"] for r in res]),
           "gamma2": np.array([r["phi"].T @ r["Mr"] @ d2[i] for i, r in enumerate(res)]),
           "b1": np.array([r["b1"] for r in res]), "b2": np.array([r["b2"] for r in res]),
           "phi_x": np.array([r["tip_modes"][0] for r in res]),
           "phi_z": np.array([r["tip_modes"][2] for r in res]),
           "tip_static": np.array([r["tip"] for r in res]),
           "tip_dL": np.array([r["tip_dL"] for r in res]),
           "freq_all_hz": np.array([r["all_freq_hz"] for r in res])}
    return out


def build_tables(path=None, payloads=None, angles=ANGLES, L_grid=L_GRID, log=print,
                 reuse=None, n_booms: int = 3, base: TelescopicParams | None = None):
    """Build all configurations and write them to ``path`` (npz, written atomically; default
    ``data_path(n_booms)``).  ``n_booms``: sections of the crane (synchronized drive; ``base``:
    other TelescopicParams to start from, its n_booms wins); ``payloads`` default to
    ``TABLE_BOOMS[n_booms]``.  ``reuse``: existing tables file(s) (a path or a list of paths);
    configurations they hold for the same boom count on the same L_s grid are copied, not
    rebuilt (this also merges tables built in separate processes, one per angle)."""
    if base is None:
        base = table_params(n_booms)
    n_booms = base.n_booms
    _require_synchronized(base.mechanism)
    path = data_path(n_booms) if path is None else path
    payloads = TABLE_BOOMS.get(n_booms, PAYLOADS) if payloads is None else payloads
    t0 = time.perf_counter()
    data = {}
    olds = []
    used = {}                                    # reused files: their build times, s
    for src in ([] if reuse is None else [reuse] if isinstance(reuse, (str, Path)) else reuse):
        if Path(src).exists():
            with np.load(src) as f:
                old = {k: f[k] for k in f.files}
            same_booms = int(old.get("n_booms", 3)) == n_booms
            if (same_booms and old["L_grid"].shape == np.shape(L_grid)
                    and np.allclose(old["L_grid"], L_grid)):
                olds.append((src, old))
    for a in angles:
        for mp_ in payloads:
            cfg = None
            for src, old in olds:
                ia = np.flatnonzero(np.isclose(old["angles"], a))
                ip = np.flatnonzero(np.isclose(old["payloads"], mp_))
                if len(ia) and len(ip):
                    cfg = {k: old[k][ia[0], ip[0]] for k in COLS + ("tip_static", "tip_dL",
                                                                     "freq_all_hz")}
                    log(f"  m_p={mp_:g} kg theta={a:g} deg: reused from {src}")
                    used[str(src)] = float(old.get("build_s", 0.0))
                    break
            if cfg is None:
                cfg = build_config(mp_, a, L_grid, base=base, log=log)
            for k, v in cfg.items():
                data.setdefault(k, []).append(v)
    arrays = {k: np.array(v).reshape(len(angles), len(payloads), *np.shape(v[0]))
              for k, v in data.items()}
    meta = dict(L_grid=np.asarray(L_grid), payloads=np.asarray(payloads), angles=np.asarray(angles),
                n_nodes=N_NODES, stroke_ref=STROKE_REF,
                build_s=time.perf_counter() - t0 + sum(used.values()),   # reused builds included
                n_booms=n_booms, mechanism="synchronized")
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays, **meta)
    atomic_write_bytes(path, buf.getvalue())
    log(f"wrote {path} ({time.perf_counter() - t0:.0f} s)")


# ---------------------------------------------------------------------------------------------
@dataclass
class ModalTables:
    """Tables of one configuration, interpolated in L_s: coefficient matrix rows per grid point."""

    L: np.ndarray            # (nL,) m
    coef: np.ndarray         # (nL, 8, n_modes) rows COLS
    tip_static: np.ndarray   # (nL, 3) m
    tip_dL: np.ndarray       # (nL, 3) m/m
    payload: float
    angle_deg: float

    @property
    def n_modes(self) -> int:
        return self.coef.shape[2]

    @property
    def L_range(self) -> tuple[float, float]:
        return float(self.L[0]), float(self.L[-1])

    def _w(self, L):
        L = min(max(float(L), self.L[0]), self.L[-1])
        i = min(int(np.searchsorted(self.L, L, side="right")) - 1, len(self.L) - 2)
        w = (L - self.L[i]) / (self.L[i + 1] - self.L[i])
        return i, w

    def coefficients(self, L):
        """(8, n_modes) array of omega rad/s, zeta, Gamma kg^0.5, Gamma2 kg^0.5/m, b1 kg^0.5/s,
        b2 kg^0.5/m, phi_tip_x, phi_tip_z (m kg^-0.5) at piston length L (m)."""
        i, w = self._w(L)
        return (1 - w) * self.coef[i] + w * self.coef[i + 1]

    def static_tip(self, L):
        """Static-equilibrium tip position (3,) m and d r_s/dL_s (3,) at L (m): cubic Hermite
        interpolation of the tabulated positions and exact (implicit-function) derivatives,
        error O(dL^4) instead of the O(dL^2) of linear interpolation (the sag is mm-relevant)."""
        i, w = self._w(L)
        hL = self.L[i + 1] - self.L[i]
        p0, p1 = self.tip_static[i], self.tip_static[i + 1]
        m0, m1 = self.tip_dL[i] * hL, self.tip_dL[i + 1] * hL
        w2, w3 = w * w, w * w * w
        r = ((2 * w3 - 3 * w2 + 1) * p0 + (w3 - 2 * w2 + w) * m0 + (-2 * w3 + 3 * w2) * p1
             + (w3 - w2) * m1)
        dr = ((6 * w2 - 6 * w) * p0 + (3 * w2 - 4 * w + 1) * m0 + (-6 * w2 + 6 * w) * p1
              + (3 * w2 - 2 * w) * m1) / hL
        return r, dr


_CACHE: dict = {}


def load_raw(path=None, n_booms: int = 3) -> dict:
    """The arrays of a tables file (``path``, default ``data_path(n_booms)``), cached."""
    path = data_path(n_booms) if path is None else path
    key = str(path)
    if key not in _CACHE:
        if not Path(path).exists():
            raise FileNotFoundError(f"{path}: modal tables missing; build them with "
                                    "`python -m sim_core.systems.telescopic.modal --build "
                                    f"--booms {n_booms}`")
        with np.load(path) as f:
            raw = {k: f[k] for k in f.files}
        held = int(raw.get("n_booms", 3))           # files without the key: the paper's 3 booms
        if held != n_booms:
            raise ValueError(f"{path} holds tables of {held} booms, not n_booms = {n_booms}")
        _CACHE[key] = raw
    return _CACHE[key]


def allowed_ranges(path=None, n_booms: int = 3):
    """(payload (lo, hi) kg, luffing angle (lo, hi) deg, L_s (lo, hi) m) covered by the tables
    of ``n_booms`` sections (read from the file: a partial build narrows them)."""
    r = load_raw(path, n_booms)
    return ((float(r["payloads"][0]), float(r["payloads"][-1])),
            (float(r["angles"][0]), float(r["angles"][-1])),
            (float(r["L_grid"][0]), float(r["L_grid"][-1])))


def tables_for(payload: float, angle_deg: float, n_modes: int = N_MODES_TABLE,
               path=None, n_booms: int = 3) -> ModalTables:
    """Bilinear interpolation of the configuration tables of ``n_booms`` sections in (angle,
    payload).

    Raises ValueError outside the tabulated ranges (no extrapolation) and for a boom count
    without tables."""
    r = load_raw(path, n_booms)
    P, A = r["payloads"], r["angles"]
    if not (P[0] - 1e-9 <= payload <= P[-1] + 1e-9):
        raise ValueError(f"payload = {payload!r} kg outside the modal tables' range "
                         f"[{P[0]:g}, {P[-1]:g}] kg (rebuild with --build to extend)")
    if not (A[0] - 1e-9 <= angle_deg <= A[-1] + 1e-9):
        raise ValueError(f"luffing_angle_deg = {angle_deg!r} outside the modal tables' range "
                         f"[{A[0]:g}, {A[-1]:g}] deg (rebuild with --build to extend)")
    if not 1 <= n_modes <= r["omega"].shape[-1]:
        raise ValueError(f"n_modes = {n_modes!r}: allowed 1..{r['omega'].shape[-1]}")

    def lerp_idx(grid, x):
        if len(grid) == 1:
            return 0, 0.0
        i = min(max(int(np.searchsorted(grid, x, side="right")) - 1, 0), len(grid) - 2)
        return i, float(np.clip((x - grid[i]) / (grid[i + 1] - grid[i]), 0.0, 1.0))

    ia, wa = lerp_idx(A, angle_deg)
    ip, wp = lerp_idx(P, payload)

    def get(k):
        x = r[k]
        ja, jp = min(ia + 1, x.shape[0] - 1), min(ip + 1, x.shape[1] - 1)
        return ((1 - wa) * ((1 - wp) * x[ia, ip] + wp * x[ia, jp])
                + wa * ((1 - wp) * x[ja, ip] + wp * x[ja, jp]))

    coef = np.stack([get(k)[:, :n_modes] for k in COLS], axis=1)
    tip, tip_dL = get("tip_static"), get("tip_dL").copy()
    if 0.0 < wa < 1.0:                 # between two tabulated angles
        tip, tip_dL = _static_tip_in_boom_frame(r, n_booms, ia, ip, wp, angle_deg)
    # the scene is symmetric about the luffing plane: the static tip has no lateral (Y) part and
    # neither has its stroke derivative: the tables' Y derivative is differencing noise (below
    # 1e-6 m/m with the central-difference K of tangent_stiffness) and is set to zero.
    tip_dL[:, 1] = 0.0
    return ModalTables(r["L_grid"].astype(float), coef, tip, tip_dL,
                       float(payload), float(angle_deg))


def _static_tip_in_boom_frame(r: dict, n_booms: int, ia: int, ip: int, wp: float,
                              angle_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """The static tip r_s (nL, 3) m and d r_s/dL_s (nL, 3) at a luffing angle between the
    tabulated angles A[ia] < theta < A[ia + 1], interpolated in boom 1's frame.

    The tip turns with the boom about the pivot: r_s = O(theta) + R(theta) rho
    (:func:`sim_core.systems.telescopic.luffing.luffing_geometry`), so interpolating r_s
    itself linearly in theta cuts the chord of an arc of radius |rho| (~20 m): 0.1-0.2 m off
    between grid angles 15 deg apart.  In the boom's frame rho is the rigid geometry plus the
    sag under gravity, whose transverse part goes with the transverse load, cos theta, and its
    axial part with sin theta: rho_b is interpolated linearly in cos theta and rho_s in
    sin theta (exact for rho = rho_0 + c cos theta e_b + a sin theta e_s), after the linear
    interpolation in the payload at each tabulated angle; d r_s/dL_s likewise (without the
    origin), then both are turned to the angle's global frame.  Against the full model's static
    equilibria (3 booms, the tables' 3 nodes per element) the tip's change from L_s = 2 to 8 m
    is then within a few mm at 50-74 deg, about 1 mm at the tabulated 60 deg
    (tests/env/test_modal.py); a quadratic through the three tabulated angles does no better
    (the tables' own mm-scale scatter)."""
    from sim_core.systems.telescopic.luffing import luffing_geometry
    A = r["angles"]
    jp = min(ip + 1, r["tip_static"].shape[1] - 1)
    points = table_params(n_booms).luffing.points()
    ends = []
    for j in (ia, ia + 1):
        th_j = math.radians(float(A[j]))
        g = luffing_geometry(th_j, *points)
        tip = (1 - wp) * r["tip_static"][j, ip] + wp * r["tip_static"][j, jp]
        dL = (1 - wp) * r["tip_dL"][j, ip] + wp * r["tip_dL"][j, jp]
        ends.append(((tip - g.origin) @ g.rotation, dL @ g.rotation, th_j))
    th = math.radians(angle_deg)
    g = luffing_geometry(th, *points)
    (rho0, drho0, th0), (rho1, drho1, th1) = ends
    w_s = (math.sin(th) - math.sin(th0)) / (math.sin(th1) - math.sin(th0))
    w_b = (math.cos(th) - math.cos(th0)) / (math.cos(th1) - math.cos(th0))
    w = np.array([w_s, w_b, w_b])          # axial (s); lateral (t, zero) and transverse (b)
    rho = (1 - w) * rho0 + w * rho1
    drho = (1 - w) * drho0 + w * drho1
    return g.origin + rho @ g.rotation.T, drho @ g.rotation.T


class ModalROM:
    """State (L_s m, v m/s, q (n,), q_dot (n,)) of the stroke-parametric modal ROM.

    ``advance(a, dt)`` integrates one interval of constant piston acceleration a (m/s^2): the
    stroke kinematics exactly (L += v dt + a dt^2/2) and the modal equations exactly for the
    coefficients frozen at the interval's mid-stroke (midpoint rule in L_s: second order in
    the coefficient change v dt, which is <= 0.025 m per 0.05 s step against a 0.65 m table
    grid).  With v = v0 + a t the right-hand side is a quadratic in t; the particular solution
    is the matching quadratic and the homogeneous part the closed-form damped oscillation
    (all tabulated modes have zeta < 1)."""

    def __init__(self, tables: ModalTables, L0: float, v0: float = 0.0):
        self.tb = tables
        n = tables.n_modes
        self.L, self.v = float(L0), float(v0)
        self.q = np.zeros(n)
        self.qd = np.zeros(n)

    def advance(self, a: float, dt: float) -> None:
        L, v0 = self.L, self.v
        c = self.tb.coefficients(L + 0.5 * v0 * dt + 0.125 * a * dt * dt)
        w, z, g, g2, b1, b2 = c[0], c[1], c[2], c[3], c[4], c[5]
        # f(t) = -g a - (g2 - b2) (v0 + a t)^2 + b1 (v0 + a t) = f0 + f1 t + f2 t^2
        k = g2 - b2
        f0 = -g * a - k * v0 * v0 + b1 * v0
        f1 = -2.0 * k * v0 * a + b1 * a
        f2 = -k * a * a
        w2 = w * w
        sig = z * w
        C = f2 / w2
        B = (f1 - 4.0 * sig * C) / w2
        A = (f0 - 2.0 * sig * B - 2.0 * C) / w2
        x0 = self.q - A
        y0 = self.qd - B
        wd = w * np.sqrt(1.0 - z * z)
        e = np.exp(-sig * dt)
        cs, sn = np.cos(wd * dt), np.sin(wd * dt)
        x = e * (x0 * cs + (y0 + sig * x0) / wd * sn)
        y = e * (y0 * cs - (w2 * x0 + sig * y0) / wd * sn)
        self.q = x + A + B * dt + C * dt * dt
        self.qd = y + B + 2.0 * C * dt
        self.L = L + v0 * dt + 0.5 * a * dt * dt
        self.v = v0 + a * dt

    def deflection(self):
        """(dX, dZ, dX', dZ') of the tip from the static tip at the current L_s (m, m/s)."""
        c = self.tb.coefficients(self.L)
        return (float(c[6] @ self.q), float(c[7] @ self.q), float(c[6] @ self.qd),
                float(c[7] @ self.qd))

    def tip(self):
        """Tip position (3,) m, velocity (3,) m/s and deflection from the static tip (3,) m
        with its rate (3,) m/s (Y components zero: in-plane modes only)."""
        c = self.tb.coefficients(self.L)
        rs, drs = self.tb.static_tip(self.L)
        dx = np.array([c[6] @ self.q, 0.0, c[7] @ self.q])
        dv = np.array([c[6] @ self.qd, 0.0, c[7] @ self.qd])
        return rs + dx, drs * self.v + dv, dx, dv


def check_params(p) -> None:
    """Raise ValueError if TelescopicParams p differ from the table build in anything the ROM
    does not interpolate (only payload, luffing angle, stroke history and n_nodes may vary;
    contact_distribution acts on outputs only when friction is off).  Tables exist for the
    boom counts of TABLE_BOOMS with the synchronized drive."""
    if p.n_booms not in TABLE_BOOMS:
        raise ValueError(f"n_booms = {p.n_booms!r}: the modal tables are built for booms "
                         f"{', '.join(str(k) for k in TABLE_BOOMS)} (allowed values); use the "
                         "full model (model.reduction = 'none')")
    _require_synchronized(p.mechanism, "; use the full model (model.reduction = 'none')")
    ref = table_params(p.n_booms)
    for k in ("n_booms", "boom_length", "L_h", "E", "rho", "rope_EA", "gravity", "filter_h",
              "sections", "torsion", "rope_elasticity", "flexible"):
        if not hasattr(ref, k):             # options of later sim_core versions
            continue
        if getattr(p, k) != getattr(ref, k):
            raise ValueError(f"{k} = {getattr(p, k)!r}: the modal tables are built for "
                             f"{getattr(ref, k)!r}; use the full model (model.reduction = 'none')")
    if p.friction:
        raise ValueError("friction = True: the modal tables are frictionless")


def simulate_modal(p, n_modes: int, t_end: float, n_output: int, dt_max: float = 0.05,
                   scene: dict | None = None, max_wall_s: float | None = None):
    """ROM run of the scene's cubic schedule (TelescopicParams p): Result with tip_position,
    tip_velocity, tip_deflection (m, from the static tip at the current L_s), piston_stroke (m)
    and modal_coordinates.  The piston acceleration is piecewise constant on sub-intervals of
    length <= dt_max (s), equal to the schedule's mean acceleration (v(t1) - v(t0)) / h there:
    the stroke rate is exact at the interval ends and the stroke error is at most
    h^3 max|jerk| / 12 per interval (the same kinematics as boom_env fed with these actions).
    ``max_wall_s``: the wall-clock budget (s, solver.max_wall_s), checked after every output;
    past it a SimulationError carries the outputs so far as ``.result``."""
    from sim_core.physics.drive_profiles import CubicSmoothstepSchedule
    from sim_core.result import Result
    check_params(p)
    tb = tables_for(p.payload, p.luffing_angle_deg, n_modes, n_booms=p.n_booms)
    sched = CubicSmoothstepSchedule(v_max=p.v_max, t_ramp=p.t_ramp, t_hold_end=p.t_hold_end,
                                    sign=p.direction, s0=p.stroke0)
    lo, hi = tb.L_range
    travel = sched.stroke(np.linspace(0, t_end, 201))
    if travel.min() < lo - 1e-9 or travel.max() > hi + 1e-9:
        raise ValueError(f"stroke history L_s in [{travel.min():g}, {travel.max():g}] m leaves the "
                         f"modal tables' range [{lo:g}, {hi:g}] m")
    wall0 = time.perf_counter()
    t_out = np.linspace(0.0, t_end, n_output)
    rom = ModalROM(tb, p.stroke0, 0.0)
    out = {k: [] for k in ("tip_position", "tip_velocity", "tip_deflection", "piston_stroke",
                           "modal_coordinates")}

    def record():
        r, v, d, _ = rom.tip()
        out["tip_position"].append(r)
        out["tip_velocity"].append(v)
        out["tip_deflection"].append(d)
        out["piston_stroke"].append(rom.L - p.stroke0)
        out["modal_coordinates"].append(rom.q.copy())

    def result(error=None):
        wall = time.perf_counter() - wall0
        stats = {"wall_time_s": wall, "method": "modal ROM (exact frozen-coefficient steps)",
                 "n_modes": n_modes, "real_time_factor": t_end / max(wall, 1e-12),
                 "n_dof": n_modes}
        return Result(t_out[:len(out["piston_stroke"])],
                      {k: np.array(v, float) for k, v in out.items()}, stats,
                      scene if scene is not None else p.summary(), error)

    record()
    t = 0.0
    for t_next in t_out[1:]:
        n = max(1, int(np.ceil((t_next - t) / dt_max - 1e-9)))
        h = (t_next - t) / n
        v = sched.rate(t + h * np.arange(n + 1))          # one vectorised schedule call
        for k in range(n):
            rom.advance(float(v[k + 1] - v[k]) / h, h)
        t = t_next
        record()
        if (max_wall_s is not None and t < t_end
                and time.perf_counter() - wall0 > max_wall_s):
            exc = SimulationError(t, f"wall-clock budget solver.max_wall_s = {max_wall_s:g} s "
                                  "exhausted", last_state=rom.q.copy())
            exc.result = result(str(exc))
            raise exc
    return result()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", action="store_true", help="(re)build the tables")
    ap.add_argument("--booms", type=int, default=3, choices=sorted(TABLE_BOOMS),
                    help="sections of the crane (synchronized drive; default: %(default)s)")
    ap.add_argument("--quick", action="store_true",
                    help="one configuration (the middle payload, 60 deg) only")
    ap.add_argument("--out", default=None,
                    help="tables file (default: data/modal_telescopic.npz for 3 booms, "
                         "data/modal_telescopic_<N>.npz otherwise)")
    ap.add_argument("--angles", type=float, nargs="+", default=list(ANGLES),
                    help="luffing angles, deg (default: %(default)s)")
    ap.add_argument("--payloads", type=float, nargs="+", default=None,
                    help="payload masses, kg (default: 20 25 30 t for 3 booms, 5 10 15 t for 5)")
    ap.add_argument("--reuse", nargs="+", default=None,
                    help="existing tables file(s) whose configurations are copied, not rebuilt "
                         "(also merges per-angle builds)")
    a = ap.parse_args(argv)
    payloads = tuple(sorted(a.payloads or TABLE_BOOMS[a.booms]))
    if a.build:
        if a.quick:
            build_tables(a.out, payloads=(payloads[len(payloads) // 2],), angles=(60.0,),
                         n_booms=a.booms)
        else:
            build_tables(a.out, payloads=payloads, angles=tuple(sorted(a.angles)),
                         reuse=a.reuse, n_booms=a.booms)
    else:
        ap.print_help()


if __name__ == "__main__":
    main()
