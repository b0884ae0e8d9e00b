"""BDF's Jacobian with its non-smooth friction columns refreshed (simulate.RefreshedJacobian).

* the refreshed columns (forward differences of the right-hand side) are the structured
  Jacobian's columns at the same state, the other columns and the velocity rows untouched;
* the policy: whole at a stretch's first request, refreshed on a later one, whole again after
  a refresh that Newton could not converge with (a second factorisation within its step);
* BDF through the breakaway of the friction contacts: the same solution as with whole
  Jacobians at every request (to the integration tolerance), with fewer whole ones.
"""

import numpy as np
import pytest

from sim_core.integrate.bdf import RefreshedJacobian
from sim_core.integrate.driver import _CountingRHS, integrate
from sim_core.model.state_jacobian import state_jacobian
from sim_core.systems.telescopic.params import TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium


@pytest.fixture(scope="module")
def friction_system():
    """The friction with its normal load from the slider springs: about ten times the
    resultant's (docs/validation.md), so the law's change of slope between the branches moves
    the contact-rate columns by more than 1 % of their size."""
    ts = build_telescopic(TelescopicParams(n_nodes=3, friction=True, friction_load="springs"))
    z0, _ = initial_equilibrium(ts)
    return ts, z0


def test_nonsmooth_columns_are_the_contact_rates(friction_system):
    """The columns are the reduced rates of the four contact coordinates (s_dot of Eq. 65)."""
    ts, _ = friction_system
    m = ts.model
    cols = m.nonsmooth_rate_columns()
    assert len(cols) == 4 and np.all(cols >= m.n_dof)
    full = ts.contact.velocity_coords(None)
    np.testing.assert_array_equal(np.sort(np.flatnonzero(np.any(m.P[full] != 0, axis=0))),
                                  cols - m.n_dof)


def test_refreshed_columns_equal_the_structured_jacobian(friction_system):
    """Base Jacobian at one state (contacts sticking), request at another (pair 1-2 on the
    smoothstep branch, pair 2-3 sticking): the refreshed columns equal the structured
    Jacobian's there (forward differences: to 1e-5 of the column's size), the rest is the base,
    and the velocity rows stay the exact identity (SecondOrderNewtonLU's Schur path)."""
    ts, z0 = friction_system
    m = ts.model
    n = m.n_dof
    rng = np.random.default_rng(5)
    y_base = np.concatenate([z0, 1e-4 * rng.standard_normal(n)])
    y = y_base.copy()
    full = ts.contact.velocity_coords(None)
    rows, sgn, _ = m._sel
    for i, v in zip(full, (0.014, -0.014, 0.002, -0.002)):
        j = int(np.flatnonzero(rows == i)[0])
        y[n + j] = v * sgn[j]
    rhs = _CountingRHS(m)
    jac = RefreshedJacobian(rhs)

    class Solver:
        nlu = 0
    jac.watch(Solver())
    J_base = jac(0.5, y_base)
    J = jac(0.5, y)
    assert rhs.n_jacobians == 1 and rhs.n_refreshes == 1
    J_ref = state_jacobian(m, 0.5, y)
    cols = m.nonsmooth_rate_columns()
    for c in cols:
        scale = np.max(np.abs(J_ref[n:, c]))
        np.testing.assert_allclose(J[n:, c], J_ref[n:, c], rtol=0, atol=1e-5 * scale)
        # the law's slope differs between the base state and here: the column did change
        assert np.max(np.abs(J_base[n:, c] - J_ref[n:, c])) > 1e-2 * scale
    other = np.setdiff1d(np.arange(2 * n), cols)
    np.testing.assert_array_equal(J[:, other], J_base[:, other])
    np.testing.assert_array_equal(J[:n], J_base[:n])


def test_refresh_policy():
    """Whole first; refreshed on the next request; after a refreshed step that factored twice
    (Newton failed with the refresh, BDF halved the step) whole again; a refreshed step with
    one factorisation keeps refreshing; a right-hand side that fails within a refresh gives
    the whole Jacobian (whose own failure is the typed SimulationError)."""
    class Model:
        n_dof = 2

        def nonsmooth_rate_columns(self):
            return np.array([3])

        def rhs(self, t, y):
            if t == 0.5:
                raise FloatingPointError("overflow")
            return np.array([y[2], y[3], -y[0], -np.tanh(y[3] / 0.01)])

    rhs = _CountingRHS(Model())
    rhs.jacobian = lambda t, y: (setattr(rhs, "n_jacobians", rhs.n_jacobians + 1)
                                 or np.array([[0, 0, 1, 0], [0, 0, 0, 1],
                                              [-1, 0, 0, 0], [0, 0, 0, 0]], dtype=float))

    class Solver:
        nlu = 0
    s = Solver()
    jac = RefreshedJacobian(rhs)
    jac.watch(s)
    y = np.array([0.0, 0.0, 0.0, 0.005])
    jac(0.0, y)
    assert (rhs.n_jacobians, rhs.n_refreshes) == (1, 0)
    J = jac(0.1, y)                                   # a refresh: d(-tanh(v/0.01))/dv
    assert (rhs.n_jacobians, rhs.n_refreshes) == (1, 1)
    assert J[3, 3] == pytest.approx(-100.0 / np.cosh(0.5) ** 2, rel=1e-5)
    s.nlu += 1                                        # its step factored once: it sufficed
    jac.after_step()
    jac(0.2, y)
    assert (rhs.n_jacobians, rhs.n_refreshes) == (1, 2)
    s.nlu += 2                                        # factored twice: Newton failed with it
    jac.after_step()
    jac(0.3, y)
    assert (rhs.n_jacobians, rhs.n_refreshes) == (2, 2)
    jac(0.4, y)                                       # after a whole one: refreshes again
    assert (rhs.n_jacobians, rhs.n_refreshes) == (2, 3)
    jac(0.5, y)              # a failed evaluation in the refresh: the whole one instead
    assert (rhs.n_jacobians, rhs.n_refreshes) == (3, 3)


def test_bdf_through_breakaway_same_solution_fewer_whole_jacobians(friction_system, monkeypatch):
    """BDF from static equilibrium through the first 0.6 s of the extraction: contact pair 1-2
    passes v_eps and the smoothstep branch, pair 2-3 sticks and chatters, so Newton fails
    with the Jacobian it has several times.  With refreshes: fewer whole Jacobians, and the
    same solution as with a whole one at every request, within the integration error: Newton's
    convergence changes only the cost, so the two BDF solutions at rtol 1e-6 may differ by no
    more than either differs from the exact solution (a BDF run at rtol 1e-8 here).  Both are
    measured in units of (atol + rtol |y|): through the chattering stick of pair 2-3 the global
    error is ~135 such units at t = 0.5 s, the two runs' difference 7-21 units (it depends on
    the friction Newton's warm start, which the shared model carries from test to test)."""
    ts, z0 = friction_system
    m = ts.model
    y0 = np.concatenate([z0, np.zeros_like(z0)])
    sol = {"rtol": 1e-6, "atol": 1e-7, "n_output": 7, "method": "BDF"}
    _, y_ref, st_ref = integrate(m, y0, 0.6, sol)
    monkeypatch.setattr(RefreshedJacobian, "__call__", lambda self, t, y: self.whole(t, y))
    _, y_whole, st_whole = integrate(m, y0, 0.6, sol)
    assert st_whole["n_jacobian_refreshes"] == 0
    assert st_ref["n_jacobian_refreshes"] >= 1
    assert st_ref["n_jacobians"] < st_whole["n_jacobians"]
    monkeypatch.undo()
    _, y_exact, _ = integrate(m, y0, 0.6, {**sol, "rtol": 1e-8, "atol": 1e-9})
    unit = sol["atol"] + sol["rtol"] * np.abs(y_exact)
    difference = np.max(np.abs(y_ref - y_whole) / unit)
    global_error = np.max(np.abs(y_whole - y_exact) / unit)
    assert difference <= global_error, (difference, global_error)
