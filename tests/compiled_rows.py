"""Checks shared by the tests of the compiled constraint programs (the telescopic point program,
``tests/telescopic/test_constraint_compiled.py``; the folding joint program,
``tests/folding/test_joint_program.py``) against the Python closures, their reference.

Both evaluate the same rows in the same algebra in another order, so the rows agree to
round-off of each quantity's scale; the structured Jacobian's columns are the same forward
differences with the same steps of values equal to round-off, so they agree to round-off /
step (eps / 1.5e-8 ~ 1e-8 of a row's scale; 1e-6 allowed)."""

import numpy as np

from sim_core.model import state_jacobian
from sim_core.physics import constraints
from sim_core.physics.constraints import NonlinearConstraint


def assert_rows_equal_python(cons, t, Q, Qd, monkeypatch):
    """Phi, G = g_Q, Phi_dot and b_ddot - g_QQ[Q_dot, Q_dot] from the compiled program equal
    the Python closures' (Phi_dot = G Q_dot - b_dot and the quadratic term are sums of terms of
    size |G| |Q_dot| and |G_Q| |Q_dot|^2 that nearly cancel: their tolerance is round-off of
    those sizes)."""
    monkeypatch.setattr(constraints, "COMPILED_ROWS", False)
    ref = constraints.constraint_terms(cons, t, Q, Qd)
    monkeypatch.setattr(constraints, "COMPILED_ROWS", True)
    got = constraints.constraint_terms(cons, t, Q, Qd)
    phi, G, dphi, rhs = ref
    gq = np.abs(G).max() * np.abs(Qd).max()
    for name, a, b, scale in (("phi", got[0], phi, max(np.abs(phi).max(), 1e-3)),
                              ("G", got[1], G, np.abs(G).max()),
                              ("dphi", got[2], dphi, gq),
                              ("rhs", got[3], rhs,
                               max(np.abs(rhs).max(), gq * max(np.abs(Qd).max(), 1.0)))):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * scale, err_msg=name)


def jacobian_difference(model, t, y, monkeypatch, owner, switch: str) -> float:
    """The largest difference, relative to its row's scale, between the structured state
    Jacobian with ``owner.switch`` on (the compiled path) and off (the Python pieces)."""
    monkeypatch.setattr(owner, switch, False)
    ref = state_jacobian.state_jacobian(model, t, y)
    monkeypatch.setattr(owner, switch, True)
    got = state_jacobian.state_jacobian(model, t, y)
    scale = np.maximum(np.abs(ref).max(axis=1, keepdims=True), 1e-300)
    err = float(np.max(np.abs(got - ref) / scale))
    print(f"largest difference / row scale: {err:.2e}")
    return err


def height_row(point):
    """A hand-written row (no compiled program): the height of ``point`` (a point or frame
    function)."""
    def evaluate(Q):
        r, J, _, _ = point(Q)
        return r[2:3], J[2:3]
    return NonlinearConstraint("tip_height", 1, evaluate, points=(point,))
