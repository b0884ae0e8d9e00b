"""Second-order view of a model with nonlinear constraints (SecondOrderSystem with M = I).

Models with nonlinear constraints (e.g. the telescopic system, ``sim_core.systems.telescopic.build``) do not
expose ``mass_and_force``: their accelerations come from the KKT system of the reduced mass
matrix and the constraint Jacobian with Baumgarte stabilization,

    [M_r  G^T] [z̈]   [f_r                         ]
    [G    0  ] [λ] = [c - 2 ξ1 Φ̇ - ξ2² Φ (Baumgarte)],

solved inside ``model.accelerations(t, z, ż)`` (J. Baumgarte, "Stabilization of constraints
and integrals of motion in dynamical systems", Comput. Methods Appl. Mech. Eng. 1 (1972) 1–16).
:class:`Index1System` presents that *Baumgarte-stabilized index-1 ODE*

    z̈ = a(t, z, ż)   as   M = I,  f = a(t, z, ż)

to the integrators of this package (generalized-α, scipy Radau/BDF).  It is an ODE, not the
index-3 DAE: the constraints are kept by the Baumgarte feedback (drift decays with the rates
ξ1, ξ2 of the model), not by the integrator, and the Newton matrix of an implicit method is
I + β' h² K + γ' h C with K = -∂a/∂z, C = -∂a/∂ż (finite differences, no analytic tangent).

Units: t in s, z in the model's coordinates (m, rad), ż per s, z̈ per s², M dimensionless
(identity), f = z̈.
"""

from __future__ import annotations

import numpy as np


class Index1System:
    """``SecondOrderSystem`` adapter: M = I (n × n), f = ``model.accelerations(t, z, ż)``.

    ``model`` needs ``n_dof`` and ``accelerations(t, z, zd)``; ``n_calls`` counts the
    evaluations of ``model.accelerations`` (one KKT solve each)."""

    def __init__(self, model):
        self.model = model
        self.n = int(model.n_dof)
        self._eye = np.eye(self.n)
        self.n_calls = 0

    def mass_and_force(self, t: float, q: np.ndarray, v: np.ndarray):
        """(I, z̈) with z̈ the Baumgarte-stabilized KKT accelerations of the model."""
        self.n_calls += 1
        return self._eye, np.asarray(self.model.accelerations(t, q, v), dtype=float)
