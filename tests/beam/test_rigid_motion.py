"""Rigid-body motion of an unloaded, weightless beam: zero strain, zero internal force."""

import numpy as np
from scipy.spatial.transform import Rotation

from sim_core.model.boundary import reference_basis
from sim_core.model.model import Model
from sim_core.physics.beam.moving_node_beam import Beam
from sim_core.physics.effects import Elasticity
from tests.beam.conftest import L, section


def _rigidly_moved(b: Beam, Q: np.ndarray, R: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Apply r -> R r + c to positions, R to derivatives; s and torsion unchanged."""
    out = Q.copy()
    for e, (el, imap) in enumerate(zip(b.elements, b.index_map)):
        for k in range(el.n):
            i = imap[el.index("r", k, 0)]
            out[i:i + 3] = R @ Q[i:i + 3] + c
        for what in ("rp1", "rpn", "rpp1", "rppn"):
            i = imap[el.index(what, 0, 0)]
            out[i:i + 3] = R @ Q[i:i + 3]
    return out


def test_rigid_motion_with_moving_nodes_gives_zero_strain_and_force():
    # two elements, junction moved to an arbitrary material point (a moving node)
    b = Beam("b", L, section(), (0.0, 3.7, L), n_nodes=7,
             reference_basis=reference_basis([1.0, 0.0, 0.0]))
    m = Model([b], [Elasticity()])
    Q = b.straight_coordinates([0, 0, 0], [1, 0, 0])
    for ang in ([0.3, -0.2, 0.5], [0.0, 0.7, 0.0], [1.0, 0.4, -0.3]):
        R = Rotation.from_rotvec(ang).as_matrix()
        Qr = _rigidly_moved(b, Q, R, np.array([1.0, -2.0, 3.0]))
        Qr[b.s_coord(1)] = 5.2        # junction slides: still the same straight material line
        # node positions of a straight line at the new material coordinates
        for e, (el, imap) in enumerate(zip(b.elements, b.index_map)):
            s1, sn = Qr[imap[el.i_s1]], Qr[imap[el.i_sn]]
            for k, s in enumerate(np.linspace(s1, sn, el.n)):
                i = imap[el.index("r", k, 0)]
                Qr[i:i + 3] = R @ np.array([s, 0.0, 0.0]) + np.array([1.0, -2.0, 3.0])
        F = m.mass_force(0.0, Qr, np.zeros_like(Qr), mass=False)[1]
        EA = b.section.EA
        # round-off: strains ~ 1e-15, forces ~ EA * 1e-15 * (number of points)
        assert np.max(np.abs(F)) < 1e-12 * EA
        # curvature round-off: |r| ~ 14 m times eps 1.1e-16 times the second-derivative basis
        # weights (~1e2) over l^2 (~0.6 m^2) gives ~3e-13 1/m; bound 1e-12
        for el, imap in zip(b.elements, b.index_map):
            kin = el.evaluate(Qr[imap])
            assert np.max(np.abs(kin.sec.eps)) < 1e-12
