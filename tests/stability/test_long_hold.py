"""Hard case 7: a long hold at rest - energy and constraint violation stay bounded (no drift).

Default run: 120 s hold after the paper's extraction on the fast model (the modal ROM of
sim_core.systems.telescopic.modal, the env's dynamics), and a 1 s hold of the full flexible model at its
static equilibrium.  Slow: 120 s hold of the full flexible model."""

import numpy as np
import pytest

from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.modal import ModalROM, tables_for

from .conftest import assert_stable, build_at_equilibrium, energy_tol, run_window
from .thresholds import (
    CONSTRAINT_TOL,
    HOLD_DECAY_FRACTION,
    HOLD_TIP_DRIFT,
    MIN_STEP_FRICTIONLESS,
    ROM_ENERGY_GROWTH,
)


def _rom_energy(rom):
    w = rom.tb.coefficients(rom.L)[0]
    return 0.5 * float(np.sum(rom.qd ** 2 + (w * rom.q) ** 2))


def test_rom_hold_120s_after_bang_bang_extraction():
    """The ROM is driven hard (a_max = 0.25 m/s^2 bang-bang, 2 -> ~6 m) and then held at rest
    for 120 s in 0.05 s steps (2400 exact steps): the modal energy never grows (damped linear
    oscillator), the state stays finite and the residual vibration decays."""
    rom = ModalROM(tables_for(25000.0, 60.0), 2.0, 0.0)
    for a in [0.25] * 40 + [-0.25] * 40:                  # 2 s up, 2 s down: v back to 0
        rom.advance(a, 0.05)
    assert abs(rom.v) < 1e-12
    e_prev = e0 = _rom_energy(rom)
    d0 = np.hypot(*rom.deflection()[:2])
    assert e0 > 0.0 and d0 > 0.0
    for _ in range(2400):
        rom.advance(0.0, 0.05)
        e = _rom_energy(rom)
        assert np.isfinite(e) and e <= e_prev * (1 + ROM_ENERGY_GROWTH) + 1e-300
        e_prev = e
    assert np.all(np.isfinite(rom.q)) and np.all(np.isfinite(rom.qd))
    assert np.hypot(*rom.deflection()[:2]) < HOLD_DECAY_FRACTION * d0
    assert abs(rom.v) < 1e-12


def _full_hold(paper_params, t_end, n_out):
    # schedule that never starts within the window: the cylinder holds L_s = 2 m
    p = TelescopicParams(**paper_params, contact_distribution=False)
    ts, y0 = build_at_equilibrium(p, target=lambda t: (p.stroke0, 0.0, 0.0))
    res = run_window(ts, y0, t_end, n_out, energy=True)
    assert_stable(res, MIN_STEP_FRICTIONLESS, CONSTRAINT_TOL)
    e = res["energy"]
    assert np.max(np.abs(e - e[0])) <= energy_tol(ts, res), np.max(np.abs(e - e[0]))
    assert np.max(np.abs(res["cylinder_work"])) == 0.0                 # rate 0: no work
    drift = np.linalg.norm(res["tip_position"] - res["tip_position"][0], axis=1)
    assert np.max(drift) <= HOLD_TIP_DRIFT, np.max(drift)
    return res


def test_full_model_short_hold(paper_params):
    """1 s at rest from the static equilibrium (frictionless, filter off: conservative)."""
    _full_hold(paper_params, 1.0, 11)


@pytest.mark.slow
def test_full_model_hold_120s(paper_params):
    """120 s at rest, full flexible model (~10^4 RK45 steps): no energy or constraint drift."""
    res = _full_hold(paper_params, 120.0, 121)
    # the violation does not grow: the last 10 s stay at the level of the first 10 s (x10)
    cv = res["constraint_violation"]
    assert np.max(cv[-11:]) <= 10 * max(np.max(cv[:11]), 1e-12) or np.max(cv) < 1e-9
