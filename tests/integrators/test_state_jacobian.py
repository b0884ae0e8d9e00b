"""Structured Jacobian of the state equations (sim_core.model.state_jacobian) against differences of
the whole right-hand side, and BDF with it converging with the tolerance.

Tolerance of the Jacobian checks.  Both sides are central differences (the structured one of
local pieces plus an exact implicit-function solve, the reference of model.rhs as a black box),
so each carries a truncation error O(h^2) and a rounding error ~ eps |f| / h.  The test measures
the reference's own uncertainty as the spread between two step sizes (3e-8 and 1e-7 relative)
and asserts the structured Jacobian lies within 20 times that spread (floor 1e-7, the
multiplier fixed-point tolerance 1e-8 of the friction iteration times its contraction).
Measured on the telescopic system: spread ~1.5e-7, difference ~2.3e-7.
"""

from __future__ import annotations

import numpy as np
import pytest

from sim_core import load_scene
from sim_core.integrate.driver import integrate
from sim_core.model.state_jacobian import state_jacobian
from sim_core.systems.beam.build import build_model
from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium


def _reference_columns(model, t, y, cols, h_rel):
    out = np.empty((len(y), len(cols)))
    for k, j in enumerate(cols):
        h = h_rel * max(abs(y[j]), 1.0)
        yp, ym = y.copy(), y.copy()
        yp[j] += h
        ym[j] -= h
        out[:, k] = (model.rhs(t, yp) - model.rhs(t, ym)) / (2.0 * h)
    return out


def _check(model, t, y, cols):
    """Relative (Frobenius) error of the acceleration rows of the structured Jacobian in the
    columns ``cols`` against the reference, and the reference's own spread."""
    n = model.n_dof
    J = state_jacobian(model, t, y, central=True, rel_step=1e-7)
    ref = _reference_columns(model, t, y, cols, 3e-8)
    ref2 = _reference_columns(model, t, y, cols, 1e-7)
    # the velocity rows are the identity block, exactly
    assert np.array_equal(J[:n, n:], np.eye(n)) and not np.any(J[:n, :n])
    scale = np.linalg.norm(ref[n:])
    err = np.linalg.norm(J[n:, cols] - ref[n:]) / scale
    spread = np.linalg.norm(ref2[n:] - ref[n:]) / scale
    return err, spread


@pytest.fixture(scope="module")
def telescopic():
    """Paper system at 2 sub-elements with friction (stiff booms and 1 t: a quick statics); the
    retraction rope 1 mm slack (its tension-only ramp of 1e-6 m would put a kink inside the
    reference's difference steps)."""
    p = TelescopicParams(n_nodes=3, E=2.1e12, payload=1000.0, friction=True)
    ts = build_telescopic(p)
    z, _ = initial_equilibrium(ts)
    for pe in ts.model.point_effects:
        if pe.name == "retraction_rope":
            pe.L0 += 1e-3
    return ts, z


def _state(ts, z, v_contact, seed=1):
    m = ts.model
    rng = np.random.default_rng(seed)
    Q, Qd = m.full_state(3.0, z, 1e-3 * rng.standard_normal(len(z)))
    Qd[ts.s2_index[0]], Qd[ts.s2_index[1]] = v_contact, v_contact
    Qd[ts.s3_index[1]], Qd[ts.s3_index[2]] = -v_contact, -v_contact
    zz, zd = m.reduced_state(3.0, Q, Qd)
    return np.concatenate([zz, zd])


def _columns(m, ts, seed=2, k=30):
    """The contact coordinates and their rates (friction law, Eq. 65) plus random others."""
    rows = list(m._sel[0])
    n = m.n_dof
    special = [rows.index(i) for i in ts.s2_index + ts.s3_index[1:]]
    rng = np.random.default_rng(seed)
    others = rng.choice(2 * n, size=k, replace=False)
    return np.unique(np.concatenate([special, np.add(special, n), others]))


@pytest.mark.parametrize("v_contact", [0.05, 0.004], ids=["sliding", "sticking"])
def test_telescopic_jacobian_matches_whole_rhs_differences(telescopic, v_contact):
    """Sliding (|s_dot| > 2 v_eps) and sticking (|s_dot| < v_eps, where the regularised law is
    a stiff damper): constraints, friction with its multiplier dependence, ropes, payload."""
    ts, z = telescopic
    y = _state(ts, z, v_contact)
    err, spread = _check(ts.model, 3.0, y, _columns(ts.model, ts))
    assert err < max(20.0 * spread, 1e-7), (err, spread)


@pytest.mark.parametrize("moment_model", ["seat", "couple"])
def test_telescopic_jacobian_of_the_other_moment_models(moment_model):
    """The seat's elastic moments (point_effects.SliderSeat, evaluated beside the compiled
    payload and ropes) and the couple model's twist-only angle rows, sliding, with friction
    from the contact resultant."""
    p = TelescopicParams(n_nodes=3, E=2.1e12, payload=1000.0, friction=True,
                         moment_model=moment_model)
    ts = build_telescopic(p)
    z, _ = initial_equilibrium(ts)
    for pe in ts.model.point_effects:
        if pe.name == "retraction_rope":
            pe.L0 += 1e-3
    if moment_model == "seat":
        assert ts.model._compiled_point_effects().uncompiled == list(ts.seats.values())
    y = _state(ts, z, 0.05)
    err, spread = _check(ts.model, 3.0, y, _columns(ts.model, ts))
    assert err < max(20.0 * spread, 1e-7), (err, spread)


def test_beam_jacobian_matches_whole_rhs_differences():
    """No nonlinear constraints: sleeve (time-dependent linear constraint), point load,
    gravity, stress filter - every column."""
    sc = load_scene("beam_through_sleeve")
    sc["beams"][0]["n_nodes"] = 5
    model, Q0, Qd0 = build_model(sc)
    rng = np.random.default_rng(3)
    z, zd = model.reduced_state(1.0, Q0, Qd0)
    z = z + 1e-3 * rng.standard_normal(len(z))
    zd = zd + 1e-2 * rng.standard_normal(len(zd))
    y = np.concatenate([z, zd])
    err, spread = _check(model, 1.0, y, np.arange(len(y)))
    assert err < max(20.0 * spread, 1e-7), (err, spread)


def test_bdf_with_structured_jacobian_converges_with_the_tolerance():
    """BDF's error is its discretisation error, not a Newton artefact of the Jacobian: against
    a tight RK45 reference, the error (RMS, in units of atol + rtol |y| at rtol 1e-6) falls at
    least 10x when rtol and atol are 100x tighter (variable-order BDF, order p >= 1: error ~
    tol^(p / (p + 1)), at least tol^(1/2)).  Measured: 2.6 -> 0.12 over 0.1 s."""
    sc = load_scene("beam_through_sleeve")
    sc["beams"][0]["n_nodes"] = 5
    model, Q0, Qd0 = build_model(sc)
    z0, zd0 = model.reduced_state(0.0, Q0, Qd0)
    y0 = np.concatenate([z0, zd0])
    _, y_ref, _ = integrate(model, y0, 0.1, {"rtol": 1e-10, "atol": 1e-12, "n_output": 6})
    errors = []
    for rtol, atol in ((1e-6, 1e-8), (1e-8, 1e-10)):
        _, y, st = integrate(model, y0, 0.1, {"rtol": rtol, "atol": atol, "n_output": 6,
                                              "method": "BDF", "jacobian": "structured"})
        assert st["n_jacobians"] >= 1
        # each structured Jacobian costs 2 x (element coordinates) + 1 element evaluations per
        # element, reported in right-hand sides
        el = model.beams[0].elements[0]
        assert st["jacobian_cost_rhs"] == pytest.approx(st["n_jacobians"] * (2 * el.n_coords + 1))
        e = (y - y_ref) / (1e-8 + 1e-6 * np.abs(y_ref))
        errors.append(np.max(np.sqrt(np.mean(e ** 2, axis=1))))
    assert errors[1] < errors[0] / 10.0, errors


def test_unknown_jacobian_is_rejected():
    from sim_core.errors import SceneError
    from sim_core.scene.fields import solver_table
    with pytest.raises(SceneError, match="solver.jacobian"):
        solver_table({"t_end": 1.0, "jacobian": "analytic"})


def test_folding_jacobian_without_point_dependencies():
    """The folding manipulator's constraint rows with their point dependencies removed: those
    pieces are differenced in every coordinate (the general path) - same check, on a random
    subset of columns."""
    from sim_core.systems.folding.build import FoldingParams, build_folding
    fs = build_folding(FoldingParams(n_nodes=3))
    m = fs.model
    for c in m.nonlinear:
        c.points = None                  # coords(Q) -> None: every coordinate is differenced
    assert all(c.coords(fs.Q0) is None for c in m.nonlinear)
    rng = np.random.default_rng(0)
    z, _ = m.reduced_state(0.0, fs.Q0, np.zeros_like(fs.Q0))
    y = np.concatenate([z + 1e-4 * rng.standard_normal(len(z)), 1e-2 * rng.standard_normal(len(z))])
    cols = rng.choice(len(y), size=30, replace=False)
    err, spread = _check(m, 0.5, y, cols)
    assert err < max(20.0 * spread, 1e-7), (err, spread)
