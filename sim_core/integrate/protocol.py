"""Interface between models and integrators: the second-order system protocol and result types.

A model exposes ``M(q) q̈ = f(t, q, v)`` (SI units: t in s, q in m or rad, v = q̇ in m/s or
rad/s, M in kg or kg m², f in N or N m).  Integrators return an :class:`IntegrationResult`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class SecondOrderSystem(Protocol):
    """Second-order system ``M(q) q̈ = f(t, q, v)`` with ``n`` independent coordinates.

    Optional method (used when present)::

        def tangent(self, t, q, v) -> tuple[np.ndarray, np.ndarray]:
            '''(K, C), both (n, n): K = d(M a)/dq - df/dq at a = M^-1 f (N/m),
            C = -df/dv (N s/m).'''
    """

    n: int

    def mass_and_force(self, t: float, q: np.ndarray,
                       v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(M, f)``: M (n, n) dense symmetric positive definite, f (n,), M q̈ = f."""
        ...


@dataclass
class IntegrationStats:
    """Solver statistics.  Counters a solver does not produce stay ``None``.

    ``n_force_evaluations`` counts every call of ``mass_and_force`` made by the solver
    (Newton residuals, finite-difference Jacobians, initial step selection).
    ``min_step`` / ``max_step`` are the smallest / largest accepted steps (s).
    ``nfev``, ``njev``, ``nlu`` are scipy's own counters (first-order RHS, Jacobian, LU).
    """

    method: str
    n_steps: int = 0
    n_rejected: int | None = 0
    n_newton_iterations: int | None = 0
    n_jacobian_evaluations: int = 0
    n_force_evaluations: int = 0
    n_lu: int = 0
    min_step: float = float("nan")
    max_step: float = float("nan")
    n_error_rejections: int | None = 0
    n_newton_failures: int | None = 0
    nfev: int | None = None
    njev: int | None = None
    nlu: int | None = None
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass
class IntegrationResult:
    """Trajectory at the output times.

    ``t`` (n_out,) s; ``q``, ``v``, ``a`` (n_out, n): coordinates, velocities and
    accelerations q̈ (SI units of the coordinates per s⁰, s⁻¹, s⁻²).
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    stats: IntegrationStats

    @property
    def y(self) -> np.ndarray:
        """First-order state (n_out, 2n) = [q, v]."""
        return np.hstack([self.q, self.v])
