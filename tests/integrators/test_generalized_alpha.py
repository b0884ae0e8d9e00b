"""Generalized-α integrator (Chung & Hulbert 1993; Arnold & Brüls 2007) and scipy wrapper.

Every tolerance below is derived from a known property of the scheme; the derivation is in
the test's docstring or comment.  SI units: t in s, lengths in m, angles in rad.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim_core.errors import SimulationError
from sim_core.integrate import (
    GeneralizedAlphaParameters,
    IntegrationResult,
    SecondOrderSystem,
    finite_difference_tangent,
    integrate_generalized_alpha,
    integrate_scipy,
)

EPS = np.finfo(float).eps


# -- test systems ----------------------------------------------------------------------------

class Oscillators:
    """M q̈ = -K q - C v with M = I, K = R diag(ω²) Rᵀ (R a rotation couples the coordinates)."""

    def __init__(self, omegas, damping=None, rotation: float = 0.0, with_tangent: bool = True):
        w2 = np.asarray(omegas, float) ** 2
        self.n = len(w2)
        c, s = math.cos(rotation), math.sin(rotation)
        self.R = np.eye(self.n)
        if self.n == 2:
            self.R = np.array([[c, -s], [s, c]])
        self.K = self.R @ np.diag(w2) @ self.R.T
        self.C = np.zeros((self.n, self.n)) if damping is None else np.diag(damping)
        if with_tangent:
            self.tangent = lambda t, q, v: (self.K, self.C)

    def mass_and_force(self, t, q, v):
        return np.eye(self.n), -self.K @ q - self.C @ v


class DoublePendulum:
    """Planar double pendulum of point masses in absolute angles θ1, θ2 from the downward
    vertical: configuration-dependent mass M(q), Coriolis/centrifugal forces, joint damping c.
    Lagrange's equations (derived from T, V; no constraints)."""

    n = 2

    def __init__(self, m1=1.0, m2=0.7, l1=1.0, l2=0.8, g=9.81, c=0.0):
        self.m1, self.m2, self.l1, self.l2, self.g, self.c = m1, m2, l1, l2, g, c

    def mass_and_force(self, t, q, v):
        m1, m2, l1, l2, g, c = self.m1, self.m2, self.l1, self.l2, self.g, self.c
        d = q[0] - q[1]
        L = m2 * l1 * l2
        M = np.array([[(m1 + m2) * l1 ** 2, L * math.cos(d)], [L * math.cos(d), m2 * l2 ** 2]])
        f = np.array([-L * math.sin(d) * v[1] ** 2 - (m1 + m2) * g * l1 * math.sin(q[0]) - c * v[0],
                      L * math.sin(d) * v[0] ** 2 - m2 * g * l2 * math.sin(q[1]) - c * v[1]])
        return M, f


class DoublePendulumWithTangent(DoublePendulum):
    """Adds the analytic tangent K = ∂(M a)/∂q - ∂f/∂q at a = M⁻¹f, C = -∂f/∂v."""

    def tangent(self, t, q, v):
        m1, m2, l1, l2, g, c = self.m1, self.m2, self.l1, self.l2, self.g, self.c
        M, f = self.mass_and_force(t, q, v)
        a = np.linalg.solve(M, f)
        d = q[0] - q[1]
        L, cd, sd = m2 * l1 * l2, math.cos(d), math.sin(d)
        dMa = np.array([[-L * sd * a[1], L * sd * a[1]], [-L * sd * a[0], L * sd * a[0]]])
        df = np.array([[-L * cd * v[1] ** 2 - (m1 + m2) * g * l1 * math.cos(q[0]), L * cd * v[1] ** 2],
                       [L * cd * v[0] ** 2, -L * cd * v[0] ** 2 - m2 * g * l2 * math.cos(q[1])]])
        C = np.array([[c, 2 * L * sd * v[1]], [-2 * L * sd * v[0], c]])
        return dMa - df, C


class TwoMass:
    """Wall -k1- m1 -k2- m2, stiffness ratio k2/k1 = 1e6 (no tangent: FD Jacobian)."""

    n = 2

    def __init__(self, k1=1.0, k2=1e6):
        self.K = np.array([[k1 + k2, -k2], [-k2, k2]])

    def mass_and_force(self, t, q, v):
        return np.eye(2), -self.K @ q


class NaNAfter:
    """Harmonic oscillator whose force turns NaN for t > t_bad."""

    n = 1

    def __init__(self, t_bad):
        self.t_bad = t_bad

    def mass_and_force(self, t, q, v):
        f = -q if t <= self.t_bad else np.full(1, np.nan)
        return np.eye(1), f


class BlowUp:
    """q̈ = 2 q³ with q(0) = q̇(0) = 1: exact solution q = 1/(1 - t), singular at t = 1 s."""

    n = 1

    def mass_and_force(self, t, q, v):
        return np.eye(1), 2.0 * q ** 3


# -- helpers ---------------------------------------------------------------------------------

def oscillator_flow(omega, h, q, v):
    """Exact flow of q̈ = -ω² q over h."""
    c, s = np.cos(omega * h), np.sin(omega * h)
    return q * c + v / omega * s, -q * omega * s + v * c


def amplification_matrix(p: GeneralizedAlphaParameters, Omega: float) -> np.ndarray:
    """Chung & Hulbert (1993) amplification matrix of (q, h v, h² a) for q̈ = -ω² q, Ω = ω h,
    written out from the published recurrence (independent of the implementation)."""
    am, af, g, b = p.alpha_m, p.alpha_f, p.gamma, p.beta
    A = np.zeros((3, 3))
    for j in range(3):
        q, v, a = np.eye(3)[j]
        w2 = Omega ** 2
        a1 = ((-am * a - (1 - af) * w2 * (q + v + (0.5 - b) * a) - af * w2 * q)
              / ((1 - am) + (1 - af) * w2 * b))
        A[:, j] = [q + v + (0.5 - b) * a + b * a1, v + (1 - g) * a + g * a1, a1]
    return A


def slope(x, y) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


# -- parameters ------------------------------------------------------------------------------

def test_chung_hulbert_parameters():
    p1 = GeneralizedAlphaParameters.from_rho_inf(1.0)
    assert (p1.alpha_m, p1.alpha_f, p1.gamma, p1.beta) == pytest.approx((0.5, 0.5, 0.5, 0.25))
    p0 = GeneralizedAlphaParameters.from_rho_inf(0.0)
    assert (p0.alpha_m, p0.alpha_f, p0.gamma, p0.beta) == pytest.approx((-1.0, 0.0, 1.5, 1.0))
    for rho in (0.0, 0.5, 0.8):
        p = GeneralizedAlphaParameters.from_rho_inf(rho)
        # spectral radius at Ω → ∞ is ρ∞; the triple root splits like Ω^(-2/3)
        r = max(abs(np.linalg.eigvals(amplification_matrix(p, 1e6))))
        assert r == pytest.approx(rho, abs=5 * 1e6 ** (-2 / 3))
        assert p.error_constant == pytest.approx(1 / 12 + p.delta_alpha ** 2 / 4)
    with pytest.raises(ValueError):
        GeneralizedAlphaParameters.from_rho_inf(1.5)


def test_protocol_runtime_check():
    assert isinstance(DoublePendulum(), SecondOrderSystem)
    assert isinstance(Oscillators([1.0]), SecondOrderSystem)


# -- (1) undamped oscillator, ρ∞ = 1 ---------------------------------------------------------

def test_rho1_conserves_energy_and_has_trapezoidal_period_elongation():
    """For ρ∞ = 1 (α_m = α_f = 1/2, β = 1/4, γ = 1/2) and a linear system with a_0 = q̈_0 the
    scheme is the trapezoidal rule, a Cayley transform: the energy is conserved exactly
    (tolerance: roundoff, ~N·10·eps) and the only error is the known period elongation,
    rotation angle per step θ = 2 arctan(ωh/2) instead of ωh, ΔT/T = (ωh)²/12 + O((ωh)⁴)."""
    omega, h, n_steps = 2 * np.pi, 0.05, 1000           # ωh = 0.314, 50 periods
    sys = Oscillators([omega])
    r = integrate_generalized_alpha(sys, (0.0, n_steps * h), [1.0], [0.0], rho_inf=1.0, h=h,
                                    rtol=1e-10, atol=1e-12)
    E = 0.5 * r.v[:, 0] ** 2 + 0.5 * omega ** 2 * r.q[:, 0] ** 2
    assert np.max(np.abs(E / E[0] - 1.0)) < n_steps * 10 * EPS
    omega_num = 2.0 * np.arctan(omega * h / 2.0) / h
    assert np.max(np.abs(r.q[:, 0] - np.cos(omega_num * r.t))) < 1e-9
    elongation = omega / omega_num - 1.0
    assert elongation == pytest.approx((omega * h) ** 2 / 12, rel=(omega * h) ** 2)


@pytest.mark.parametrize("rho_inf", [1.0, 0.8, 0.5])
def test_second_order_convergence_oscillator(rho_inf):
    """Global error ∝ h² (Chung & Hulbert 1993: second order for γ = 1/2 - α_m + α_f)."""
    omega, T = 2 * np.pi, 2.0
    hs = T / np.array([50, 100, 200, 400])
    errs = []
    for h in hs:
        r = integrate_generalized_alpha(Oscillators([omega]), (0.0, T), [1.0], [0.0],
                                        rho_inf=rho_inf, h=h, rtol=1e-10, atol=1e-12)
        errs.append(np.hypot(r.q[-1, 0] - np.cos(omega * T),
                             (r.v[-1, 0] + omega * np.sin(omega * T)) / omega))
    assert abs(slope(hs, errs) - 2.0) < 0.2


def test_second_order_convergence_configuration_dependent_mass():
    """Arnold & Brüls (2007): second order in q and v for M(q) q̈ = f with a_0 = q̈_0."""
    T = 1.0
    ref = integrate_scipy(DoublePendulumWithTangent(), (0.0, T), [1.0, 0.5], [0.0, 0.0],
                          method="DOP853", rtol=1e-12, atol=1e-12, t_eval=[T])
    hs = T / np.array([50, 100, 200, 400])
    eq, ev = [], []
    for h in hs:
        r = integrate_generalized_alpha(DoublePendulumWithTangent(), (0.0, T), [1.0, 0.5], [0.0, 0.0],
                                        rho_inf=0.8, h=h, rtol=1e-11, atol=1e-11)
        eq.append(np.abs(r.q[-1] - ref.q[-1]).max())
        ev.append(np.abs(r.v[-1] - ref.v[-1]).max())
    assert abs(slope(hs, eq) - 2.0) < 0.2
    assert abs(slope(hs, ev) - 2.0) < 0.2


# -- (2) numerical dissipation ρ∞ < 1 ---------------------------------------------------------

@pytest.mark.parametrize("rho_inf", [0.5, 0.8])
def test_high_frequency_damped_by_rho_inf_low_frequency_kept(rho_inf):
    """Two modes, ω_l h = 0.02 and ω_h h = 1e4 (decoupled, so each is resolved relative to
    its own amplitude).  High mode: amplitude ratio per step → ρ∞ (Chung & Hulbert 1993).
    At Ω = ∞ the three roots coincide at -ρ∞ (a Jordan block), so the amplitude behaves like
    n² ρ∞ⁿ and the roots split by O(Ω^(-2/3)); over steps n1..n2 the mean rate is
    ρ∞ (n2/n1)^(2/(n2-n1)) (1 + O(Ω^(-2/3))).  Low mode: amplitude change per step O(Ω_l⁴),
    far below (ω_l h)² over the run.  With ρ∞ = 1 the high mode is not damped at all."""
    h, wl, wh, n_steps = 0.02, 1.0, 5e5, 300
    sys = Oscillators([wl, wh])
    kw = dict(h=h, rtol=1e-12, atol=1e-100)
    r = integrate_generalized_alpha(sys, (0.0, n_steps * h), [1.0, 1.0], [0.0, 0.0],
                                    rho_inf=rho_inf, **kw)
    amp_h = np.hypot(r.q[:, 1], r.v[:, 1] / wh)
    amp_l = np.hypot(r.q[:, 0], r.v[:, 0] / wl)
    n1, n2 = 100, 300
    rate = (amp_h[n2] / amp_h[n1]) ** (1.0 / (n2 - n1))
    predicted = rho_inf * (n2 / n1) ** (2.0 / (n2 - n1))
    assert rate == pytest.approx(predicted, rel=3 * (wh * h) ** (-2 / 3) + 0.01)
    assert abs(amp_l[-1] - 1.0) < 0.1 * (wl * h) ** 2
    assert amp_l[-1] <= 1.0 + 1e-12                      # dissipative, never amplifying

    r1 = integrate_generalized_alpha(sys, (0.0, 50 * h), [1.0, 1.0], [0.0, 0.0], rho_inf=1.0, **kw)
    amp1 = np.hypot(r1.q[:, 1], r1.v[:, 1] / wh)
    assert np.max(np.abs(amp1 - 1.0)) < 1e-6


# -- (3) stiff two-mass system ----------------------------------------------------------------

def test_stiff_two_mass_fixed_steps_far_above_explicit_limit():
    """k2/k1 = 1e6: ω_max = 1414 rad/s, explicit (central difference) limit 2/ω_max = 1.4 ms.
    h = 0.1 s (70× the limit) with ρ∞ = 0.8: the stiff mode is damped away (ρ∞ per step),
    the slow mode (ω = 0.707 rad/s) is followed with the phase error of a second-order
    scheme, ≈ ω T (ωh)²/12 (trapezoidal elongation; ρ∞ = 0.8 adds less than a factor 2)."""
    sys = TwoMass()
    w2, V = np.linalg.eigh(sys.K)
    w = np.sqrt(w2)
    h, T = 0.1, 20.0
    assert h > 50 * 2.0 / w[1]
    q0 = V[:, 0] + 1e-3 * V[:, 1]                       # stiff mode excited too
    r = integrate_generalized_alpha(sys, (0.0, T), q0, [0.0, 0.0], rho_inf=0.8, h=h)
    modal = r.q @ V
    slow_exact = np.cos(w[0] * r.t)
    phase_bound = w[0] * T * (w[0] * h) ** 2 / 12
    assert np.max(np.abs(modal[:, 0] - slow_exact)) < 2 * phase_bound
    assert abs(modal[-1, 1]) < 1e-3 * 1e-8
    assert r.stats.n_jacobian_evaluations == 1           # linear: FD Jacobian reused throughout


def test_stiff_two_mass_adaptive_steps_far_above_explicit_limit():
    """Started on the slow eigenvector, the error estimator only sees the slow dynamics, so
    the adaptive steps are hundreds of explicit limits (an explicit method would need
    ≥ T ω_max / 2 = 14 000 steps); global error ≤ sum of per-step tolerances."""
    sys = TwoMass()
    w2, V = np.linalg.eigh(sys.K)
    w = np.sqrt(w2)
    T, tol = 20.0, 1e-4
    r = integrate_generalized_alpha(sys, (0.0, T), V[:, 0], [0.0, 0.0], rho_inf=0.8,
                                    rtol=tol, atol=tol)
    assert np.median(np.diff(r.t)) > 100 * 2.0 / w[1]
    assert r.stats.n_steps < 0.02 * T * w[1] / 2
    exact = np.outer(np.cos(w[0] * r.t), V[:, 0])
    assert np.max(np.abs(r.q - exact)) < r.stats.n_steps * 2 * tol


# -- (4) configuration-dependent mass vs scipy Radau ------------------------------------------

@pytest.fixture(scope="module")
def pendulum_reference():
    T = 2.0
    te = np.linspace(0.0, T, 41)
    ref = integrate_scipy(DoublePendulumWithTangent(), (0.0, T), [1.0, 0.5], [0.0, 0.0],
                          method="Radau", rtol=1e-9, atol=1e-9, t_eval=te)
    return te, ref


def test_double_pendulum_matches_radau(pendulum_reference):
    """Per-step control: each step's local error ≤ atol + rtol |y|; without error
    amplification (regular motion, 2 s) the global error is ≤ Σ_steps (atol + rtol max|y|).
    Radau at 1e-9 is 3 orders more accurate than that bound.  The global error of this
    second-order method scales like tol^(2/3) (h ∝ tol^(1/3), error ∝ h²)."""
    te, ref = pendulum_reference
    errs, tols = [], [1e-5, 1e-7]
    for tol in tols:
        for system in (DoublePendulum(), DoublePendulumWithTangent()):
            r = integrate_generalized_alpha(system, (0.0, te[-1]), [1.0, 0.5], [0.0, 0.0],
                                            rho_inf=0.8, rtol=tol, atol=tol, t_eval=te)
            err = np.abs(r.q - ref.q).max()
            bound = r.stats.n_steps * (tol + tol * np.abs(ref.q).max())
            assert err < bound
            assert np.abs(r.v - ref.v).max() < r.stats.n_steps * (tol + tol * np.abs(ref.v).max())
        errs.append(err)
    assert 0.5 < slope(tols, errs) < 0.85


def test_fd_and_tangent_runs_agree(pendulum_reference):
    """Both Jacobians converge Newton to the same tolerance: the solutions agree to far
    below the integration tolerance; FD costs 2n evaluations per Jacobian."""
    te, _ = pendulum_reference
    kw = dict(rho_inf=0.8, rtol=1e-6, atol=1e-6, t_eval=te)
    rf = integrate_generalized_alpha(DoublePendulum(), (0.0, te[-1]), [1.0, 0.5], [0.0, 0.0], **kw)
    rt = integrate_generalized_alpha(DoublePendulumWithTangent(), (0.0, te[-1]), [1.0, 0.5],
                                     [0.0, 0.0], **kw)
    assert np.abs(rf.q - rt.q).max() < 1e-2 * 1e-6
    n_fd = 2 * 2 * rf.stats.n_jacobian_evaluations         # 2n columns per FD Jacobian
    assert rf.stats.n_force_evaluations >= rt.stats.n_force_evaluations + n_fd
    assert rf.stats.n_jacobian_evaluations >= 1


# -- (5) adaptive mode meets the tolerance ----------------------------------------------------

@pytest.mark.parametrize("rtol", [1e-3, 1e-5])
def test_adaptive_local_error_meets_tolerance(rtol):
    """ρ∞ = 1 on a linear oscillator is the one-step trapezoidal map (a_n = q̈_n), so the true
    local error of each accepted step is (q, v)_{n+1} - Φ_h(q_n, v_n) with the exact flow Φ.
    In scipy's norm it must be ≤ 1 (the acceptance test), up to the estimator's O(ωh)
    relative inaccuracy (ωh ≤ 0.3 here -> allow 1.3)."""
    omega, T = 2 * np.pi, 4.0
    atol = rtol
    r = integrate_generalized_alpha(Oscillators([omega]), (0.0, T), [1.0], [0.0],
                                    rho_inf=1.0, rtol=rtol, atol=atol)
    h = np.diff(r.t)
    assert np.max(omega * h) < 0.3
    qe, ve = oscillator_flow(omega, h, r.q[:-1, 0], r.v[:-1, 0])
    wq = atol + rtol * np.maximum(np.abs(r.q[:-1, 0]), np.abs(r.q[1:, 0]))
    wv = atol + rtol * np.maximum(np.abs(r.v[:-1, 0]), np.abs(r.v[1:, 0]))
    local = np.sqrt(0.5 * (((r.q[1:, 0] - qe) / wq) ** 2 + ((r.v[1:, 0] - ve) / wv) ** 2))
    assert np.max(local) < 1.3
    assert np.median(local) > 0.2                      # not wastefully small steps either
    assert r.stats.n_rejected <= 0.1 * r.stats.n_steps + 3


@pytest.mark.parametrize("rho_inf", [1.0, 0.8])
def test_adaptive_global_error_scales_with_rtol(rho_inf):
    """Per-step control of an O(h³) local error: h ∝ tol^(1/3), global error ∝ h² ∝ tol^(2/3);
    for ρ∞ = 1 the map is an isometry in the energy norm, so the global error is bounded by
    the sum of the local errors (≤ N · 1.3 · √2 · max weight in the energy norm)."""
    omega, T = 2 * np.pi, 4.0
    tols = np.array([1e-3, 1e-4, 1e-5, 1e-6])
    errs = []
    for tol in tols:
        r = integrate_generalized_alpha(Oscillators([omega]), (0.0, T), [1.0], [0.0],
                                        rho_inf=rho_inf, rtol=tol, atol=tol)
        e = np.hypot(r.q[:, 0] - np.cos(omega * r.t), (r.v[:, 0] + omega * np.sin(omega * r.t)) / omega)
        errs.append(e.max())
        if rho_inf == 1.0:
            w_energy = np.hypot(2 * tol, tol * (1 + omega) / omega)   # (q, v/ω) weights
            assert e.max() < r.stats.n_steps * 1.3 * math.sqrt(2) * w_energy
    assert abs(slope(tols, errs) - 2 / 3) < 0.1


def test_t_eval_interpolation_is_consistent():
    """Cubic-Hermite output between steps has the accuracy of the steps themselves, and the
    interpolated q̈ satisfies q̈ = -ω² q to ω² × (position error)."""
    omega = 2 * np.pi
    te = np.linspace(0.0, 2.0, 137)
    r = integrate_generalized_alpha(Oscillators([omega]), (0.0, 2.0), [1.0], [0.0],
                                    rho_inf=0.9, rtol=1e-6, atol=1e-6, t_eval=te)
    full = integrate_generalized_alpha(Oscillators([omega]), (0.0, 2.0), [1.0], [0.0],
                                       rho_inf=0.9, rtol=1e-6, atol=1e-6)
    step_err = np.abs(full.q[:, 0] - np.cos(omega * full.t)).max()
    assert np.array_equal(r.t, te)
    assert np.abs(r.q[:, 0] - np.cos(omega * te)).max() < 2 * step_err
    assert np.abs(r.a[:, 0] + omega ** 2 * r.q[:, 0]).max() < omega ** 2 * step_err
    assert r.stats.n_steps == full.stats.n_steps
    fixed = integrate_generalized_alpha(Oscillators([omega]), (0.0, 2.0), [1.0], [0.0],
                                        rho_inf=0.9, h=0.01, t_eval=te)
    assert np.array_equal(fixed.t, te) and fixed.stats.n_steps == 200
    assert np.abs(fixed.q[:, 0] - np.cos(omega * te)).max() < 2 * omega ** 3 * 2.0 * 0.01 ** 2


# -- (6) failures -----------------------------------------------------------------------------

@pytest.mark.parametrize("fixed", [False, True])
def test_nan_raises_simulation_error_with_time(fixed):
    kw = {"h": 0.01} if fixed else {}
    with pytest.raises(SimulationError) as info:
        integrate_generalized_alpha(NaNAfter(0.5), (0.0, 1.0), [1.0], [0.0], **kw)
    exc = info.value
    assert 0.4 < exc.t <= 0.5
    assert exc.last_state is not None and np.isfinite(exc.last_state).all()
    assert "NaN" in exc.reason


def test_nan_in_initial_state_and_scipy_wrapper():
    with pytest.raises(SimulationError) as info:
        integrate_generalized_alpha(NaNAfter(-1.0), (0.0, 1.0), [1.0], [0.0])
    assert info.value.t == 0.0
    with pytest.raises(SimulationError) as info:
        integrate_scipy(NaNAfter(0.5), (0.0, 1.0), [1.0], [0.0], method="RK45")
    assert 0.4 < info.value.t <= 0.5


def test_finite_time_blow_up_raises():
    """q = 1/(1 - t): the step shrinks towards t = 1 s until h_min / Newton failures."""
    with pytest.raises(SimulationError) as info:
        integrate_generalized_alpha(BlowUp(), (0.0, 2.0), [1.0], [1.0], rtol=1e-4, atol=1e-4,
                                    max_steps=5000)
    assert 0.9 < info.value.t < 1.0
    assert "h_min" in info.value.reason
    with pytest.raises(SimulationError) as info:
        integrate_scipy(BlowUp(), (0.0, 2.0), [1.0], [1.0], method="Radau", rtol=1e-3, atol=1e-3)
    assert 0.9 < info.value.t <= 1.0


def test_max_steps_raises():
    with pytest.raises(SimulationError, match="max_steps"):
        integrate_generalized_alpha(Oscillators([2 * np.pi]), (0.0, 10.0), [1.0], [0.0],
                                    rtol=1e-8, atol=1e-8, max_steps=50)


# -- (7) finite-difference Jacobian ------------------------------------------------------------

def test_fd_jacobian_matches_analytic_tangent():
    """Forward differences with δ = √eps max(|x|, 1): truncation δ|r''|/2 and cancellation
    eps|r|/δ are both ~√eps relative; allow 100 √eps of the matrix scale."""
    sys = DoublePendulumWithTangent(c=0.3)
    q, v = np.array([0.4, -0.7]), np.array([1.3, -0.8])
    K, C = sys.tangent(0.0, q, v)
    Kf, Cf = finite_difference_tangent(sys, 0.0, q, v)
    assert np.abs(Kf - K).max() < 100 * math.sqrt(EPS) * np.abs(K).max()
    assert np.abs(Cf - C).max() < 100 * math.sqrt(EPS) * np.abs(C).max()
    # Newton iteration matrices S = M + β'h²K + γ'hC agree to the same order
    p = GeneralizedAlphaParameters.from_rho_inf(0.8)
    M, _ = sys.mass_and_force(0.0, q, v)
    h = 0.01
    S = M + p.beta_prime * h * h * K + p.gamma_prime * h * C
    Sf = M + p.beta_prime * h * h * Kf + p.gamma_prime * h * Cf
    assert np.abs(S - Sf).max() < 100 * math.sqrt(EPS) * np.abs(S).max()


# -- scipy wrapper ---------------------------------------------------------------------------

@pytest.mark.parametrize("method", ["Radau", "BDF", "RK45"])
def test_scipy_wrapper_result_and_stats(method):
    omega = 2 * np.pi
    te = np.linspace(0.0, 1.0, 11)
    r = integrate_scipy(Oscillators([omega]), (0.0, 1.0), [1.0], [0.0], method=method,
                        rtol=1e-8, atol=1e-10, t_eval=te)
    assert isinstance(r, IntegrationResult)
    assert r.q.shape == r.v.shape == r.a.shape == (11, 1)
    assert np.abs(r.q[:, 0] - np.cos(omega * te)).max() < 1e-5
    assert np.allclose(r.a[:, 0], -omega ** 2 * r.q[:, 0])
    assert r.stats.nfev > 0 and r.stats.n_steps > 0 and r.stats.n_force_evaluations >= r.stats.nfev
    if method != "RK45":
        assert r.stats.njev >= 1 and r.stats.nlu >= 1
