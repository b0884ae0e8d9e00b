"""RK45 -> BDF stiffness switch of ``sim_core.integrate.driver.integrate`` (solver.method = "auto").

The detector is Hairer's DOPRI5 test (Hairer, Nørsett, Wanner, Solving ODEs I, Sec. II.10):
for a linear right-hand side f = λ y the two c = 1 stages give ρ = |λ| exactly, so h ρ is
|h λ|; RK45's real stability boundary is ≈ 3.3.
"""

import numpy as np
import pytest
from scipy.integrate import RK45

from sim_core.integrate.driver import integrate
from sim_core.integrate.switching import StiffnessDetector


class Linear:
    """y' = A y."""

    def __init__(self, A):
        self.A = np.asarray(A, dtype=float)

    def rhs(self, t, y):
        return self.A @ y


class ProtheroRobinson:
    """y' = λ (y - g(t)) + g'(t), g = sin(ω t): exact solution y = g for y(0) = 0; stiff for
    λ << 0 (the stiffness is only in the decay towards the smooth solution)."""

    def __init__(self, lam: float, omega: float = 2.0):
        self.lam, self.omega = lam, omega

    def rhs(self, t, y):
        g, gd = np.sin(self.omega * t), self.omega * np.cos(self.omega * t)
        return self.lam * (y - g) + gd


@pytest.mark.parametrize("lam", [-3.0, -250.0, -4.0e4])
def test_lipschitz_estimate_is_the_eigenvalue_of_a_linear_system(lam):
    """ρ = ||k7 - k6|| / ||y_new - g6|| = |λ| for f = λ y (to rounding)."""
    s = RK45(Linear([[lam]]).rhs, 0.0, np.array([1.0]), 1.0, rtol=1e-6, atol=1e-12)
    det = StiffnessDetector()
    s.step()
    det.update(s)
    h = s.t - s.t_old
    assert det.last_h_rho == pytest.approx(abs(lam) * h, rel=1e-8)


def test_oscillator_is_not_stiff():
    """Harmonic oscillator ω = 10 rad/s over 5 s: the step is set by accuracy (h ω well below
    the stability boundary), so "auto" never switches and equals RK45 exactly."""
    model = Linear([[0.0, 1.0], [-100.0, 0.0]])
    sol = {"rtol": 1e-6, "atol": 1e-9, "n_output": 11}
    t, y_rk, _ = integrate(model, np.array([1.0, 0.0]), 5.0, {**sol, "method": "RK45"})
    _, y_auto, st = integrate(model, np.array([1.0, 0.0]), 5.0, {**sol, "method": "auto"})
    assert st["n_method_switches"] == 0
    np.testing.assert_array_equal(y_auto, y_rk)
    np.testing.assert_allclose(y_rk[:, 0], np.cos(10.0 * t), atol=1e-4)


def test_stiff_problem_switches_to_bdf_and_stays_accurate():
    """Prothero-Robinson with λ = -1e5: RK45 needs h <≈ 3.3e-5 s for stability, i.e. ~3e4
    steps over 1 s; after the switch BDF follows the smooth solution with steps set by its
    accuracy.  The switch happens early (within the first 0.05 s: 15 stability-limited steps)
    and the result keeps the requested accuracy: the global error of a stable integration with
    local tolerance rtol = 1e-6 stays within a few 10 rtol |y|."""
    model = ProtheroRobinson(-1.0e5)
    sol = {"rtol": 1e-6, "atol": 1e-9, "n_output": 21}
    t, y_auto, st = integrate(model, np.zeros(1), 1.0, {**sol, "method": "auto"})
    assert 0.0 < st["first_switch_to_bdf_s"] < 0.05
    np.testing.assert_allclose(y_auto[:, 0], np.sin(2.0 * t), atol=1e-4)
    _, y_rk, st_rk = integrate(model, np.zeros(1), 1.0, {**sol, "method": "RK45"})
    np.testing.assert_allclose(y_rk[:, 0], np.sin(2.0 * t), atol=1e-4)
    # RK45's step count is set by stability: >= 1 s / (3.3 / 1e5) steps; auto takes far fewer
    assert st_rk["n_steps"] > 1.0 / (3.4 / 1.0e5)
    assert st["n_steps"] < 0.1 * st_rk["n_steps"]


def test_bdf_method_and_statistics():
    model = ProtheroRobinson(-1.0e5)
    t, y, st = integrate(model, np.zeros(1), 1.0,
                         {"rtol": 1e-6, "atol": 1e-9, "n_output": 5, "method": "BDF"})
    assert st["method"] == "BDF" and st["n_jacobians"] >= 1
    np.testing.assert_allclose(y[:, 0], np.sin(2.0 * t), atol=1e-4)


def test_unknown_method_is_rejected():
    with pytest.raises(ValueError, match="solver.method"):
        integrate(Linear([[-1.0]]), np.ones(1), 1.0, {"rtol": 1e-6, "atol": 1e-9,
                                                      "n_output": 3, "method": "Radau"})


class StiffInterval(ProtheroRobinson):
    """Prothero-Robinson with λ(t) = -1 - 1e5 b(t), b a smooth bump equal to 1 on
    [0.3, 0.6] s and 0 outside [0.25, 0.65] s: stiff only inside the interval; g = sin(10 t)
    keeps BDF's accuracy-limited steps small enough that its stretches end inside [0, 1] s."""

    def __init__(self):
        super().__init__(-1.0, omega=10.0)

    @staticmethod
    def bump(t):
        def ramp(x):                      # C1 0 -> 1 on [0, 1]
            x = min(max(x, 0.0), 1.0)
            return x * x * (3.0 - 2.0 * x)
        return ramp((t - 0.25) / 0.05) * (1.0 - ramp((t - 0.6) / 0.05))

    def rhs(self, t, y):
        self.lam = -1.0 - 1.0e5 * self.bump(t)
        return super().rhs(t, y)


def test_switches_back_to_rk45_after_the_stiff_interval():
    """BDF inside the stiff interval, RK45 before and after: the first switch to BDF falls in
    the ramp-up [0.25, 0.3] s (+ the detector's 15 steps); at the end of a BDF stretch inside
    the interval a fresh Jacobian gives h rho = h 1e5 >> 3.25, so BDF goes on without a
    hand-back trial (none of RK45's 15 stability-limited steps there); the one switch back to
    RK45 comes after lambda has decayed (0.65 s), and the run costs far fewer evaluations than
    RK45 alone (whose steps are stability-limited to 3.3e-5 s over ~0.35 s: > 1e4 steps)."""
    sol = {"rtol": 1e-6, "atol": 1e-9, "n_output": 41}
    t, y, st = integrate(StiffInterval(), np.zeros(1), 2.0, {**sol, "method": "auto"})
    np.testing.assert_allclose(y[:, 0], np.sin(10.0 * t), atol=1e-4)
    assert 0.2 < st["first_switch_to_bdf_s"] < 0.35
    assert st["n_bdf_kept"] >= 1                       # a stretch ended inside the interval
    assert st["n_method_switches"] == 2                # to BDF, and back to RK45 once
    assert st["last_switch_s"] > 0.65
    _, _, st_rk = integrate(StiffInterval(), np.zeros(1), 2.0, {**sol, "method": "RK45"})
    assert st["n_rhs"] < 0.2 * st_rk["n_rhs"]


def test_spectral_radius_estimate():
    """Power-iteration estimate against the eigenvalues: a dominant real eigenvalue, and a
    dominant complex pair (damped oscillator, the shape of a filtered beam mode)."""
    from sim_core.integrate.switching import spectral_radius
    rng = np.random.default_rng(3)
    V = rng.normal(size=(6, 6))
    A = V @ np.diag([-4.0e4, -300.0, -20.0, -1.0, -0.5, 0.1]) @ np.linalg.inv(V)
    assert spectral_radius(A) == pytest.approx(4.0e4, rel=0.05)
    w, zeta = 245.0, 0.6                                # |lambda| = w for the pair
    osc = np.array([[0.0, 1.0], [-w * w, -2.0 * zeta * w]])
    B = np.zeros((4, 4))
    B[:2, :2] = osc
    B[2:, 2:] = [[-1.0, 0.0], [0.0, -2.0]]
    assert spectral_radius(B) == pytest.approx(w, rel=0.1)
    assert spectral_radius(None) == 0.0


def test_bdf_newton_limit_is_raised_only_inside_bdf_steps():
    """integrate() raises scipy's BDF Newton iteration limit (a module constant) around its
    own BDF steps only: the right-hand side sees the raised limit during BDF steps, scipy's
    own value before and after the run."""
    import scipy.integrate._ivp.bdf as bdf_module

    from sim_core.integrate.bdf import BDF_NEWTON_ITERATIONS

    before = bdf_module.NEWTON_MAXITER
    seen = []

    class Recording(ProtheroRobinson):
        def rhs(self, t, y):
            seen.append(bdf_module.NEWTON_MAXITER)
            return super().rhs(t, y)

    integrate(Recording(-1.0e5), np.zeros(1), 0.2,
              {"rtol": 1e-6, "atol": 1e-9, "n_output": 3, "method": "BDF"})
    assert bdf_module.NEWTON_MAXITER == before
    assert BDF_NEWTON_ITERATIONS != before
    # the solver's set-up evaluations (before the first step) see scipy's value, every step's
    # evaluation the raised one
    first = seen.index(BDF_NEWTON_ITERATIONS)
    assert set(seen[:first]) == {before} and set(seen[first:]) == {BDF_NEWTON_ITERATIONS}


def test_second_order_newton_lu_equals_the_whole_lu():
    """BDF's Newton matrix I - c J for J = [[0, I], [A_z, A_v]] by its Schur complement
    (n x n) solves like the LU of the whole 2n x 2n matrix; a matrix without that exact
    structure takes the whole LU."""
    from scipy.integrate import BDF

    from sim_core.integrate.bdf import SecondOrderNewtonLU

    rng = np.random.default_rng(5)
    n = 6
    J = np.zeros((2 * n, 2 * n))
    J[:n, n:] = np.eye(n)
    J[n:] = rng.normal(size=(n, 2 * n)) * 1e4                       # stiff rows
    solver = BDF(lambda t, y: J @ y, 0.0, np.ones(2 * n), 1.0, jac=J)
    newton = SecondOrderNewtonLU(solver)
    b = rng.normal(size=2 * n)
    for c in (1e-4, 3e-2):
        A = np.eye(2 * n) - c * J
        LU = newton.lu(A.copy())
        assert LU[0] == "schur"
        np.testing.assert_allclose(newton.solve_lu(LU, b.copy()), np.linalg.solve(A, b),
                                   rtol=1e-10, atol=1e-12)
    A = np.eye(2 * n) - 1e-3 * J
    A[0, n] *= 1.0 + 1e-15                               # not exactly -c I: the whole LU
    LU = newton.lu(A.copy())
    assert LU[0] == "full"
    np.testing.assert_allclose(newton.solve_lu(LU, b.copy()), np.linalg.solve(A, b),
                               rtol=1e-10, atol=1e-12)


class StiffIntervalNotFriction(StiffInterval):
    """StiffInterval whose stiffness the model declares not to be a friction law's
    (``friction_in_slope_band`` False, as a telescopic model with every contact sliding)."""

    def friction_in_slope_band(self, t, z, zd):
        return False


def test_auto_keeps_rk45_where_the_stiffness_is_not_the_frictions():
    """With the model saying its friction is outside the slope band, the detector's alarms
    keep RK45 (no switch; the alarms are counted) and the run is RK45's: BDF is reserved for
    the friction law's stiffness (MethodSwitch, ``stiff_friction``)."""
    sol = {"rtol": 1e-6, "atol": 1e-9, "n_output": 41}
    t, y, st = integrate(StiffIntervalNotFriction(), np.zeros(1), 1.0, {**sol, "method": "auto"})
    _, y_rk, st_rk = integrate(StiffIntervalNotFriction(), np.zeros(1), 1.0,
                               {**sol, "method": "RK45"})
    assert st["n_method_switches"] == 0
    assert st["n_rk45_kept"] >= 1
    assert st["n_rhs"] == st_rk["n_rhs"]
    np.testing.assert_array_equal(y, y_rk)
