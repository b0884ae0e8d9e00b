"""Tables of the sliders' normal load for the stroke friction of the reduced-order model.

    python -m sim_core.systems.telescopic.friction_table --build [--booms 5]

For every configuration (payload kg, luffing angle deg) and piston length L_s (m) of the modal
tables' grid (``modal.L_GRID``, ``modal.TABLE_BOOMS`` payloads, ``modal.ANGLES``), the full
model (n_nodes = 3, frictionless, the ropes at the reference lengths: ``modal.equilibrium_at``,
the configuration of the modal tables) is brought to its static equilibrium with the cylinders
frozen at L_s, and each contact region's normal load is read from the constraint multipliers
the way the full model's default friction law does (``contact.friction_load = "resultant"``,
:mod:`sim_core.physics.contact.friction`): N_r = |(f_t, f_b)|, the transverse resultant of the
region's contact force in section components.  With the synchronized drive every overlap slides
at the stroke rate L_s', so the friction's virtual power is -mu sum_r N_r |L_s'| and the
friction force on the stroke coordinate is mu N with N = sum_r N_r, the total tabulated here
(Zhao-Qi-Wang 2024 Section 8, Eq. 65, summed over the regions).

The file (``data/friction_telescopic.npz``, ``friction_telescopic_<N>.npz`` for N booms) holds
``N_total`` (angles, payloads, L) N, the regions' loads ``N_regions`` (..., regions), the grid,
the boom masses (kg, outermost first: the stroke's rigid-body mass, ``stroke_mass``) and the
friction coefficients of the scene defaults (mu_static, mu_dynamic).  A static solve costs
~0.3 s for three booms (~1.5 s for five); the whole build a few minutes.
"""

from __future__ import annotations

import argparse
import io
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from sim_core.result import atomic_write_bytes
from sim_core.systems.telescopic import modal
from sim_core.systems.telescopic.params import TelescopicParams, boom_section

DATA = Path(__file__).parent / "data" / "friction_telescopic.npz"


def data_path(n_booms: int = 3) -> Path:
    """The friction-load file of ``n_booms`` sections (ValueError without modal tables)."""
    modal.data_path(n_booms)
    return DATA if n_booms == 3 else DATA.with_name(f"friction_telescopic_{n_booms}.npz")


def boom_masses(p: TelescopicParams) -> np.ndarray:
    """Masses of the booms (kg, outermost first)."""
    return np.array([p.lengths[k] * boom_section(k, p).rhoA for k in range(p.n_booms)])


def stroke_mass(masses, payload: float) -> float:
    """Rigid-body mass referred to the stroke (kg): with the synchronized drive boom k
    (0-based from the outermost) moves k L_s and the payload (N - 1) L_s along the boom, so the
    kinetic energy of a rigid stroke motion is (1/2) M_s L_s'^2 with M_s = sum_k k^2 m_k +
    (N - 1)^2 m_p (three booms, 25 t: 114.6 t)."""
    m = np.asarray(masses, float)
    k = np.arange(len(m))
    return float(np.sum(k * k * m) + (len(m) - 1) ** 2 * payload)


def region_loads(ts, z, lam) -> np.ndarray:
    """N_r = |(f_t, f_b)| (N) of every contact region of the system ``ts`` at the reduced
    state z with multipliers lam (the resultant friction load of
    :class:`sim_core.physics.contact.friction.ContactFriction`)."""
    from sim_core.physics.contact.friction import ContactFriction
    m = ts.model
    Q, Qd = m.full_state(0.0, z, np.zeros_like(z))
    p = ts.params
    contact = ts.contact or ContactFriction(ts, p.mu_static, p.mu_dynamic, p.v_eps,
                                            distribution=False, friction_load="resultant")
    at = contact.at_state(0.0, Q, Qd)
    out = []
    for name, s_idx, rp, ra, Lf, Lm, mu, geom, m0 in at.regions:
        f = Lf @ lam[rp]
        out.append(float(np.hypot(f[1], f[2])))
    return np.array(out)


def build_config(payload, angle_deg, L_grid=modal.L_GRID, base=None, log=print):
    """N_regions (nL, regions) of one configuration over L_grid."""
    p = replace(base or TelescopicParams(), payload=float(payload),
                luffing_angle_deg=float(angle_deg), n_nodes=modal.N_NODES, friction=False,
                contact_distribution=False, friction_load="resultant")
    rope_L0 = modal.reference_rope_lengths(p, modal.STROKE_REF)
    order = np.argsort(np.abs(L_grid - modal.STROKE_REF))
    res = [None] * len(L_grid)
    guess = [None] * len(L_grid)
    for i in order:
        near = [j for j in range(len(L_grid)) if guess[j] is not None]
        zg = guess[min(near, key=lambda j: abs(L_grid[j] - L_grid[i]))] if near else None
        try:
            ts, z, lam = modal.equilibrium_at(p, L_grid[i], rope_L0, z_guess=zg)
        except Exception:
            if zg is None:
                raise
            ts, z, lam = modal.equilibrium_at(p, L_grid[i], rope_L0)
        z_ref = ts.model.reduced_state(0.0, ts.Q0, np.zeros_like(ts.Q0))[0]
        guess[i] = z - z_ref
        res[i] = region_loads(ts, z, lam)
    log(f"  m_p={payload:g} kg theta={angle_deg:g} deg: N = "
        + ", ".join(f"{x / 1e3:.0f}" for x in np.sum(res, axis=1)) + " kN over L_s")
    return np.array(res)


def build_tables(path=None, n_booms: int = 3, payloads=None, angles=modal.ANGLES,
                 L_grid=modal.L_GRID, log=print):
    """Build every configuration and write the file (atomically)."""
    base = modal.table_params(n_booms)
    path = data_path(n_booms) if path is None else path
    payloads = modal.TABLE_BOOMS[n_booms] if payloads is None else payloads
    t0 = time.perf_counter()
    reg = np.array([[build_config(m, a, L_grid, base, log) for m in payloads] for a in angles])
    buf = io.BytesIO()
    np.savez_compressed(buf, N_regions=reg, N_total=reg.sum(axis=-1), L_grid=np.asarray(L_grid),
                        payloads=np.asarray(payloads, float), angles=np.asarray(angles, float),
                        boom_masses=boom_masses(base), mu_static=base.mu_static,
                        mu_dynamic=base.mu_dynamic, n_booms=n_booms,
                        build_s=time.perf_counter() - t0)
    atomic_write_bytes(path, buf.getvalue())
    log(f"wrote {path} ({time.perf_counter() - t0:.0f} s)")


_CACHE: dict = {}


def load(n_booms: int = 3) -> dict:
    """The arrays of the friction-load file of ``n_booms`` sections (cached)."""
    path = data_path(n_booms)
    if path not in _CACHE:
        if not path.exists():
            raise FileNotFoundError(f"{path}: friction-load tables missing; build them with "
                                    "`python -m sim_core.systems.telescopic.friction_table "
                                    f"--build --booms {n_booms}`")
        with np.load(path) as f:
            _CACHE[path] = {k: f[k] for k in f.files}
    return _CACHE[path]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", action="store_true", help="(re)build the tables")
    ap.add_argument("--booms", type=int, default=3, choices=sorted(modal.TABLE_BOOMS))
    ap.add_argument("--out", default=None)
    a = ap.parse_args(argv)
    if a.build:
        build_tables(a.out, n_booms=a.booms)
    else:
        ap.print_help()


if __name__ == "__main__":
    main()
