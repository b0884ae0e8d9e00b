"""Time integrators for second-order systems ``M(q) q̈ = f(t, q, v)`` (SI units).

* :func:`integrate_generalized_alpha` — Chung & Hulbert (1993) generalized-α in the
  Arnold & Brüls (2007) form, fixed-step or adaptive, modified Newton with analytic or
  finite-difference Jacobian.
* :func:`integrate_scipy` — first-order reformulation solved by ``scipy.integrate.solve_ivp``.
"""

from sim_core.integrate.generalized_alpha import (
    GeneralizedAlphaParameters,
    finite_difference_tangent,
    integrate_generalized_alpha,
    integrate_scipy,
)
from sim_core.integrate.protocol import IntegrationResult, IntegrationStats, SecondOrderSystem

__all__ = [
    "SecondOrderSystem",
    "IntegrationResult",
    "IntegrationStats",
    "GeneralizedAlphaParameters",
    "integrate_generalized_alpha",
    "integrate_scipy",
    "finite_difference_tangent",
]
