"""BDF on the reduced second-order system: the Newton matrix by its Schur complement and a
structured Jacobian whose non-smooth friction columns are refreshed between full evaluations.

scipy's ``BDF`` integrates the first-order form y = (z, v); :class:`SecondOrderNewtonLU`
factors its Newton matrix through the velocity block, :class:`RefreshedJacobian` supplies the
Jacobian, and :class:`bdf_newton_limit` sets scipy's Newton iteration limit around its steps.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

# Newton iterations per BDF step before scipy's BDF renews its Jacobian (scipy's default 4).
# scipy reads the limit from a module constant of its private module scipy.integrate._ivp.bdf
# (unchanged since scipy 1.0); integrate() raises it only around its own BDF steps
# (_bdf_newton_limit) and restores it after each.  Why: the structured Jacobian costs ~45
# right-hand sides at the paper's discretisation, while a Newton iteration with the stale one
# costs one, so a slower but converging iteration is cheaper than a new Jacobian (fewer
# Jacobians on the paper's extraction run); the step sizes are still set by the error test.
BDF_NEWTON_ITERATIONS = 8


class SecondOrderNewtonLU:
    """Newton-matrix factorisation for scipy's BDF on a first-order form y = (z, v) of a
    second-order system, y' = (v, a(t, z, v)): the Jacobian is [[0, I], [A_z, A_v]], so BDF's
    Newton matrix I - c J = [[I, -c I], [-c A_z, I - c A_v]] is eliminated to its Schur
    complement S = I - c A_v - c^2 A_z (n x n): one LU of size n instead of 2n (1/8 of the
    flops; 0.7 instead of 5.2 ms at the paper's 313 coordinates), and per solve
    x2 = S^-1 (b2 + c A_z b1), x1 = b1 + c x2.  The structure is checked on the matrix itself
    (the identity and -c I blocks exactly, as the structured Jacobian gives them); any other
    matrix (e.g. finite-difference Jacobians, whose dv/dv is not exactly I) takes the LU of
    the whole matrix.  Installed as the solver's ``lu`` / ``solve_lu`` (its public
    attributes); counts its factorisations in the solver's ``nlu``."""

    def __init__(self, solver):
        self.solver = solver
        self.n = solver.n // 2
        self.eye = np.eye(self.n)

    def lu(self, A):
        self.solver.nlu += 1
        n, eye = self.n, self.eye
        if 2 * n == A.shape[0] and n > 0:
            c = -A[0, n]
            if np.array_equal(A[:n, :n], eye) and np.array_equal(A[:n, n:], -c * eye):
                A21 = A[n:, :n].copy()                          # -c A_z
                S = A[n:, n:] + c * A21                         # A22 - A21 A12
                return ("schur", sla.lu_factor(S, overwrite_a=True), A21, c)
        return ("full", sla.lu_factor(A, overwrite_a=True))

    def solve_lu(self, LU, b):
        if LU[0] == "full":
            return sla.lu_solve(LU[1], b, overwrite_b=True)
        _, f, A21, c = LU
        n = self.n
        x2 = sla.lu_solve(f, b[n:] - A21 @ b[:n])
        return np.concatenate([b[:n] + c * x2, x2])


class bdf_newton_limit:
    """Context: scipy's BDF Newton iteration limit set to ``n`` (no-op where scipy has no
    such constant), restored on exit."""

    def __init__(self, n: int):
        import scipy.integrate._ivp.bdf as bdf_module
        self.module, self.n = bdf_module, int(n)

    def __enter__(self):
        self.old = getattr(self.module, "NEWTON_MAXITER", None)
        if self.old is not None:
            self.module.NEWTON_MAXITER = self.n
        return self

    def __exit__(self, *exc):
        if self.old is not None:
            self.module.NEWTON_MAXITER = self.old
        return False


class RefreshedJacobian:
    """BDF's Jacobian callable for one BDF stretch: the structured Jacobian, or -- when Newton
    fails with the one BDF has -- that Jacobian with its non-smooth columns refreshed.

    The friction law mu(v) (docs/model.md#input-friction, the paper's mu sign(s_dot) of Eq. 65)
    is only C0 at |v| = v_eps and its slope changes sign on the smoothstep branch; it enters the
    Jacobian only through the columns of the contact coordinates' rates
    (:meth:`sim_core.model.model.Model.nonsmooth_rate_columns`).  When a contact crosses a branch
    those few columns jump while the rest changes smoothly with the state, and scipy's BDF,
    which asks for a new Jacobian whenever Newton fails with the one it has, got a whole one
    each time (~60 ms at the paper's discretisation).  Here the first request of a stretch
    gets the whole Jacobian; a later one gets the last whole one with those columns'
    acceleration rows re-differenced from the right-hand side (forward differences, exactly
    representable steps: 1 + k evaluations for k columns, ~5 ms; the velocity rows keep the
    exact identity columns, so :class:`SecondOrderNewtonLU` keeps its Schur complement).
    When Newton did not converge with a refreshed Jacobian either (BDF halved that step and
    factored again: :meth:`after_step` sees a second factorisation within the step), the rest
    of it is stale too, and the next request gets a whole one.  Newton's convergence decides
    only the cost: BDF's error test still sets the steps.  Measured on the paper's stick-in
    (BDF from 15.3 to 16.0 s): the same 287 steps and 72 factorisations, 14 whole Jacobians ->
    1 whole + 13 refreshes, the final state within 1.5e-10 of the run with whole ones,
    2.25 -> 1.86 s; reusing the Jacobian without the refresh instead: 3703 steps."""

    def __init__(self, rhs):
        self.rhs = rhs
        self.solver = None                       # set by watch(); its nlu counts factorisations
        self.J = None                            # the last whole Jacobian (refreshed in place)
        self.pending = None                      # factorisations when the last refresh was made
        self.stale = False                       # Newton failed with a refreshed Jacobian
        self.cols = np.asarray(rhs.model.nonsmooth_rate_columns(), dtype=int)

    def watch(self, solver) -> None:
        """The BDF solver whose factorisations (``nlu``) tell whether a refresh sufficed."""
        self.solver = solver

    def after_step(self) -> None:
        """Call after each accepted step: a refresh in that step followed by more than one
        factorisation means Newton failed with it (BDF halves h and factors again)."""
        if self.pending is not None and self.solver is not None:
            self.stale = self.solver.nlu - self.pending > 1
        self.pending = None

    def __call__(self, t, y):
        if self.J is None or len(self.cols) == 0 or self.stale or self.solver is None:
            return self.whole(t, y)
        self.pending = self.solver.nlu
        return self._refresh(t, y)

    def whole(self, t, y):
        """The whole structured Jacobian at (t, y) (also the stretch's new base)."""
        self.J = self.rhs.jacobian(t, y)
        self.stale = False
        self.pending = None
        return self.J.copy()

    def _refresh(self, t, y):
        n = len(y) // 2
        failed = self.rhs.n_failed
        f0 = self.rhs(t, y)
        yy = y.copy()
        cols = np.empty((n, len(self.cols)))
        for k, j in enumerate(self.cols):
            x = y[j]
            e = (x + 1e-7 * max(1.0, abs(x))) - x          # exactly representable step
            yy[j] = x + e
            cols[:, k] = (self.rhs(t, yy)[n:] - f0[n:]) / e
            yy[j] = x
        if self.rhs.n_failed != failed:     # a failed evaluation (its placeholder values):
            return self.whole(t, y)         # the whole Jacobian, which raises the typed error
        self.J[n:, self.cols] = cols
        self.rhs.n_refreshes += 1
        return self.J.copy()
