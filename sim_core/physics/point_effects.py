"""Effects acting at points of the bodies: payload point mass, rope drives over pulleys.

Each has ``add(t, Q, Qd, M, F)`` on the full coordinates and is assembled only when the scene
contains it.  Points are functions Q -> (r, dr/dQ, psi, dpsi/dQ) from
:func:`sim_core.physics.constraints.material_point` (material points with optional rigid offsets).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from sim_core.physics.complex_step import COMPLEX_STEP
from sim_core.physics.constraints import dependencies


@dataclass
class PointMass:
    """A point mass m (kg) rigidly attached at a point (payload at the tip of the innermost boom,
    Zhao-Qi-Wang 2024 Section 9): M += m J^T J,  F += m J^T (g - J_dot q_dot)."""

    point: Callable
    mass: float
    gravity: np.ndarray | None = None
    name: str = "payload"

    def coords(self, Q):
        """Coordinates the payload's force and mass depend on (None: possibly all)."""
        return dependencies((self.point,), Q)

    def velocity_coords(self, Q):
        """Coordinates whose rates enter the force (the point's: the convective term)."""
        return self.coords(Q)

    def local(self, t, Q, Qd, mass=True):
        """(idx, Me (or None), Fe) on the coordinates the point depends on."""
        idx = _cols(self.coords(Q), Q)
        _, Jc, _, _ = self.point(Q + 1j * COMPLEX_STEP * Qd)     # first: the real one is its real part
        _, J, _, _ = self.point(Q)
        J = J[:, idx]
        acc = (Jc[:, idx] @ Qd[idx]).imag / COMPLEX_STEP
        f = -self.mass * acc
        if self.gravity is not None:
            f = f + self.mass * self.gravity
        return idx, (self.mass * (J.T @ J) if mass else None), J.T @ f

    def add(self, t, Q, Qd, M, F):
        _add_local(self.local(t, Q, Qd, M is not None), M, F)


def ramp_tension(k, d, w):
    """Tension (N) of a tension-only rope of stiffness k (N/m) stretched by d (m), with a C1
    ramp over the first w (m): 0 when slack, k d^2 / (2 w) on the ramp, k (d - w/2) beyond."""
    x = d / w
    if x <= 0:
        return 0.0
    if x >= 1:
        return k * (d - 0.5 * w)
    return k * w * 0.5 * x * x


def ramp_energy(k, d, w):
    """Strain energy (J) of :func:`ramp_tension`: its integral over the stretch from slack
    (complex-step safe in k and d: the branches follow their real parts)."""
    dr = np.real(d)
    if dr <= 0.0:
        return 0.0 * k
    if dr <= np.real(w):
        return k * d ** 3 / (6.0 * w)
    return k * w * w / 6.0 + k * (0.5 * (d * d - w * w) - 0.5 * w * (d - w))


def path_length(points, Q):
    """(l, dl/dQ): the length (m) of the polyline through the points' positions at Q and its
    gradient (complex-step safe)."""
    pts = [p(Q) for p in points]
    ell = 0.0
    grad = np.zeros(len(Q))
    for (ra, Ja, _, _), (rb, Jb, _, _) in zip(pts[:-1], pts[1:]):
        d = rb - ra
        n = np.sqrt(d @ d)
        ell = ell + n
        grad = grad + (d / n) @ (Jb - Ja)
    return ell, grad


@dataclass
class RopeDrive:
    """Elastic, massless, tension-only rope over frictionless point pulleys (Section 9;
    docs/model.md#input-ropes): length l(Q) = sum |r_{i+1} - r_i| over anchor, pulleys, anchor;
    tension T = (EA/L0) * ramp(l - L0) with a C1 ramp over ``slack_width`` (m) so the switch to
    slack is smooth; generalized force F -= T dl/dQ."""

    points: Sequence[Callable]
    EA: float
    L0: float
    slack_width: float = 1e-6
    name: str = "rope"
    bilateral: bool = False     # statics only: T = (EA/L0)(l - L0) of either sign (see
                                # telescopic.initial_equilibrium); never in dynamics

    def coords(self, Q):
        """Coordinates the rope force depends on (None: possibly all)."""
        return dependencies(self.points, Q)

    def velocity_coords(self, Q):
        """The rope force does not depend on rates."""
        return np.zeros(0, dtype=int)

    def length(self, Q):
        return path_length(self.points, Q)

    def tension(self, ell):
        k = self.EA / self.L0
        if self.bilateral:
            return k * (ell - self.L0)
        return ramp_tension(k, ell - self.L0, self.slack_width)

    def tension_rate(self, ell):
        """dT/dl (N/m) of :meth:`tension`."""
        k = self.EA / self.L0
        if self.bilateral:
            return k
        x = (ell - self.L0) / self.slack_width
        return 0.0 if x <= 0 else (k if x >= 1 else k * x)

    def local(self, t, Q, Qd, mass=True):
        """(idx, None, Fe) on the coordinates where dl/dQ is not zero (those of the rope's
        points)."""
        ell, grad = self.length(Q)
        grad = np.real(grad)
        idx = np.flatnonzero(grad)
        return idx, None, -self.tension(float(np.real(ell))) * grad[idx]

    def add(self, t, Q, Qd, M, F):
        _add_local(self.local(t, Q, Qd, M is not None), M, F)


@dataclass
class SliderSeat:
    """Elastic seat of a slider (contact.moment_model = "seat"): the slider may rock relative to
    the boom section it runs on, resisted by a rotational spring of stiffness ``stiffness``
    (N m/rad) on the two bending Cardan angles (alpha, beta) of the contact sections.

    Section 6 of Zhao-Qi-Wang 2024 makes the two sections' Cardan angles coincide (Eqs. 47-48);
    the seat keeps the translations and the twist as constraints and replaces the two bending
    rows by the potential  V = k/2 |g|^2,  g = Psi_a - Psi_b (bending rows), whose generalized
    force is F = -k g_Q^T g.  Its virtual power on the contact coordinate s (through g_Q) is the
    moment term of the contact multiplier eta of Section 7.  With the model's sign convention
    (M z_ddot = F + C^T lambda) the seat acts as the angle rows' multipliers lambda = -k g, which
    is what :meth:`multipliers` returns for the contact outputs and the friction normal load."""

    constraint: object                       # the bending rows of an angle_coincidence
    stiffness: float                         # N m/rad
    name: str = "seat"
    time_invariant = True                    # local() does not depend on t

    def coords(self, Q):
        return self.constraint.coords(Q)

    def velocity_coords(self, Q):
        """The seat moment does not depend on rates."""
        return np.zeros(0, dtype=int)

    def multipliers(self, Q) -> np.ndarray:
        """The equivalent multipliers of the bending rows, -k g (N m)."""
        g, _ = self.constraint.evaluate(Q)
        return -self.stiffness * np.real(g)

    def energy(self, Q) -> float:
        """Strain energy of the seat spring, k/2 |g|^2 (J)."""
        g, _ = self.constraint.evaluate(Q)
        g = np.real(g)
        return 0.5 * self.stiffness * float(g @ g)

    def local(self, t, Q, Qd, mass=True):
        """(idx, None, -k g_Q^T g) on the coordinates the two sections depend on."""
        g, J = self.constraint.evaluate(Q)
        idx = _cols(self.coords(Q), Q)
        return idx, None, -self.stiffness * (J[:, idx].T @ g)

    def add(self, t, Q, Qd, M, F):
        _add_local(self.local(t, Q, Qd, M is not None), M, F)


def _cols(cols, Q) -> np.ndarray:
    """The coordinates a point effect depends on (all where a point does not say)."""
    return np.arange(len(Q)) if cols is None else np.asarray(cols, dtype=int)


def _add_local(terms, M, F) -> None:
    """Add a local (idx, Me, Fe) to the full (M, F); idx holds each coordinate once."""
    idx, Me, Fe = terms
    F[idx] += Fe
    if M is not None and Me is not None:
        M[np.ix_(idx, idx)] += Me


def compiled_order(effects, compiled_types) -> list:
    """A model's point effects in order as (True, index among the compiled ones) for an effect
    of ``compiled_types``, else (False, the effect): the merge plan of
    :func:`in_model_order`."""
    order, k = [], 0
    for pe in effects:
        if type(pe) in compiled_types:
            order.append((True, k))
            k += 1
        else:
            order.append((False, pe))
    return order


def in_model_order(order, compiled_blocks, t, Q, Qd, mass) -> list:
    """[(idx, Me or None, Fe)] of every effect in the model's order: the compiled blocks by
    ``order`` (:func:`compiled_order`), the other effects' own ``local`` at time t."""
    return [compiled_blocks[k] if compiled else k.local(t, Q, Qd, mass)
            for compiled, k in order]


class CompiledPointEffects:
    """The local blocks of a list of payloads and ropes from one compiled evaluation of their
    points (:mod:`sim_core.physics._constraints_numba`: a rope's length is a chain of distances, the
    rows the rope-length constraint uses; a payload's point is a coincidence row of one point,
    whose Jacobian is J and whose quadratic term is the convective acceleration J_dot q_dot).
    The same formulas as ``PointMass.local`` and ``RopeDrive.local`` (the reference:
    ``tests/telescopic/test_assembly_paths.py``); :meth:`build` returns None where an effect
    is of another kind or a point is not a material or fixed point."""

    def __init__(self, effects, rows, program, order=None, uncompiled=()):
        self.effects, self.rows, self.program = effects, rows, program
        # the model's point effects in order: (True, compiled index) or (False, effect)
        self.order = order if order is not None else [(True, i) for i in range(len(effects))]
        self.uncompiled = list(uncompiled)

    @staticmethod
    def build(effects) -> "CompiledPointEffects | None":
        """The compiled program of the payloads and ropes among ``effects``; time-invariant
        effects of other kinds with a ``local`` form (:class:`SliderSeat`) are evaluated in
        Python beside it (``uncompiled``), and so are effects that read the time their
        ``local`` is given (``takes_time``: the hoist rope of a prescribed length; every caller
        passes t).  None where no payload or rope is there, or an effect of another kind is
        neither."""
        from sim_core.physics._constraints_numba import DIFF_R, ROPE, program_for
        from sim_core.physics.constraints import NonlinearConstraint
        compiled = [pe for pe in effects if type(pe) in (PointMass, RopeDrive)]
        other = [pe for pe in effects if type(pe) not in (PointMass, RopeDrive)]
        if not compiled or not all((getattr(pe, "time_invariant", False)
                                    or getattr(pe, "takes_time", False))
                                   and hasattr(pe, "local") for pe in other):
            return None
        order = compiled_order(effects, (PointMass, RopeDrive))
        cons, rows, row = [], [], 0
        for pe in compiled:
            if isinstance(pe, PointMass):
                spec, m = (DIFF_R, (0, 1, 2), (pe.point,)), 3
            else:
                spec, m = (ROPE, (), tuple(pe.points)), 1
            cons.append(NonlinearConstraint(pe.name, m, None, program=spec))
            rows.append(slice(row, row + m))
            row += m
        program = program_for(cons)
        return None if program is None else CompiledPointEffects(compiled, rows, program, order,
                                                                 other)

    def jacobian(self, Q, Qd, Qdd, steps):
        """(d/dQ, d/dQ_dot) (N, N) of the effects' F - M Q_ddot at frozen Q_ddot (their pieces
        of the structured Jacobian, :mod:`sim_core.model.state_jacobian`).  Each is G^T mu over its
        rows: payload mu = m (g - J Q_ddot - J_dot Q_dot), rope mu = -T(l) (G its row dl/dQ),
        so d/dQ_j = (dG/dQ_j)^T mu + G^T dmu/dQ_j: the first term and d(G Q_ddot + J_dot Q_dot)
        /dQ_j from the program's forward-difference columns (steps ``steps(x)``, as the Python
        pieces), the rope's dmu/dQ_j = -T'(l) G[j] analytic; d/dQ_dot: the payload's
        -2 m G^T g_QQ Q_dot (the program's rate part), the ropes' none."""
        prog = self.program
        N = prog.N
        g, G, quad, G_rate = prog.terms(Q, Qd, rate_part=True)
        mu = np.zeros(prog.m)
        for pe, sl in zip(self.effects, self.rows):
            if isinstance(pe, PointMass):
                mu[sl] = -pe.mass * (G[sl] @ Qdd + quad[sl])
                if pe.gravity is not None:
                    mu[sl] += pe.mass * pe.gravity
            else:
                mu[sl.start] = -pe.tension(float(g[sl.start]))
        deps = prog.dependencies(Q)
        cols = np.flatnonzero(deps.any(axis=0))
        zero = np.zeros(prog.m)
        d1, d2 = prog.columns(Q, Qd, Qdd, mu, zero, zero, zero, 0.0, 0.0, cols,
                              steps(Q[cols]), deps)
        dQ = np.zeros((N, N))
        dQd = np.zeros((N, N))
        dQ[:, cols] = d1
        for pe, sl in zip(self.effects, self.rows):
            if isinstance(pe, PointMass):
                dQ[:, cols] -= pe.mass * (G[sl].T @ d2[sl])
                dQd -= 2.0 * pe.mass * (G[sl].T @ G_rate[sl])
            else:
                row = G[sl.start]
                dQ[:, cols] -= pe.tension_rate(float(g[sl.start])) * np.outer(row, row[cols])
        return dQ, dQd

    def local(self, Q, Qd, mass=True, t=float("nan")) -> list:
        """[(idx, Me or None, Fe)] of every effect, in the model's order (as its ``local``;
        the time-invariant uncompiled effects get ``t``)."""
        g, G, quad, _ = self.program.terms(Q, Qd)
        out = []
        for pe, sl in zip(self.effects, self.rows):
            if isinstance(pe, PointMass):
                idx = _cols(pe.coords(Q), Q)
                J = G[sl][:, idx]
                f = -pe.mass * quad[sl]
                if pe.gravity is not None:
                    f = f + pe.mass * pe.gravity
                out.append((idx, (pe.mass * (J.T @ J) if mass else None), J.T @ f))
            else:
                grad = G[sl.start]
                idx = np.flatnonzero(grad)
                out.append((idx, None, -pe.tension(float(g[sl.start])) * grad[idx]))
        if not self.uncompiled:
            return out
        return in_model_order(self.order, out, t, Q, Qd, mass)
