"""Tests of sim_core.physics.contact.sliding_block_contact (paper Section 8.2-8.3,
docs/model.md#input-springs).

Each test checks a physical or mathematical fact; every tolerance is derived in a comment.
Loads are of the order of the paper's 25 t case (region forces 1e5-1e6 N, moments 1e5 N m).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim_core.errors import SimulationError
from sim_core.physics.contact import (
    ContactSolution,
    ContactSolveError,
    FrictionLaw,
    SliderGeometry,
    SpringLaw,
    axial_residual,
    contact_residual,
    solve_micro_motion,
)
from sim_core.physics.contact import _sliding_block_contact_numba as micro_motion_compiled

RTOL_SOLVE = 1e-11     # solver default: max |S R| <= 1e-11 max |S c|
EQ_TOL = 1e-9          # brief: equations satisfied to 1e-9 relative (100x margin on RTOL_SOLVE)
SPRING = SpringLaw()   # docs/model.md#input-springs defaults k0 = 1e9 N/m, eps = 1e-6 m
P1, P2, P3 = 0, 1, 2


def region(pair=1, kind="inner"):
    return SliderGeometry.paper_region(pair, kind)


def load_scale(geom, f_c, m_c):
    """max |S c| of the five equations (moments divided by the geometry's length scale)."""
    L = geom.length_scale
    return max(abs(f_c[1]), abs(f_c[2]), *(abs(np.asarray(m_c)) / L))


def independent_resultants(geom, sol):
    """fbar_c, mbar_c summed from per-spring vectors and np.cross (not via the A matrix)."""
    r = geom.positions
    n = geom.normals
    f = sol.normal_force
    F = f[:, None] * geom.k_t * n                    # Eq. 64: normal force on the slider
    F[:, 0] -= sol.mu * f                            # friction on the slider (reaction of Eq. 65)
    return F.sum(axis=0), np.cross(r, F).sum(axis=0)  # Eq. 66


# ------------------------------------------------------------------------------- geometry

@pytest.mark.parametrize("pair,r_top,r_half", [(1, 0.0725, 0.3725), (2, 0.0525, 0.3525)])
@pytest.mark.parametrize("kind,k_t", [("inner", -1), ("outer", 1)])
def test_paper_region_layout(pair, r_top, r_half, kind, k_t):
    g = SliderGeometry.paper_region(pair, kind)
    assert g.k_t == k_t
    assert g.n_springs == 160                                     # docs/model.md#input-springs
    assert g.half_width == pytest.approx(0.15)
    np.testing.assert_allclose(g.arcs[:, 2], [r_top, r_top, r_half], rtol=0, atol=1e-15)
    assert [int(g.mask(arc=j).sum()) for j in (P1, P2, P3)] == [40, 40, 80]
    assert int(g.mask(k_s=1).sum()) == int(g.mask(k_s=-1).sum()) == 80
    # azimuths theta_i = theta_start + (i - 1/2) dtheta: first P3 spring at 180 + 2.25 deg
    th3 = g.theta[g.mask(arc=P3, k_s=1)]
    assert np.degrees(th3[0]) == pytest.approx(182.25, abs=1e-12)
    assert np.degrees(th3[-1]) == pytest.approx(357.75, abs=1e-12)
    # Eq. 59: each spring at distance r from its arc centre, at +-w along e_s
    centres = g.arcs[g.arc_index, :2]
    dist = np.hypot(g.positions[:, 1] - centres[:, 0], g.positions[:, 2] - centres[:, 1])
    np.testing.assert_allclose(dist, g.arcs[g.arc_index, 2], rtol=1e-14)
    np.testing.assert_allclose(g.positions[:, 0], 0.15 * g.k_s, rtol=0, atol=0)
    assert SliderGeometry.paper_region((pair, pair + 1), kind).arcs.tolist() == g.arcs.tolist()


def test_compression_map_matches_eqs_60_61():
    """delta = A x equals (r - rbar) . k_t n with r from Eq. 60 built with np.cross."""
    rng = np.random.default_rng(0)
    for kind in ("inner", "outer"):
        g = region(1, kind)
        x = rng.normal(size=5) * np.array([1e-5, 1e-5, 1e-4, 1e-4, 1e-4])
        u = np.array([0.0, x[0], x[1]])
        omega = np.array([x[2], x[3], x[4]])                      # (alpha, beta, gamma)
        disp = u + np.cross(omega, g.positions)                   # Eq. 60, r - rbar
        delta = (disp * g.normals).sum(axis=1) * g.k_t            # Eq. 61
        # the terms are ~1e-5 m; round-off of a 3-term dot product ~ 1e-16 * 1e-5
        np.testing.assert_allclose(g.A @ x, delta, rtol=0, atol=1e-19)


def test_geometry_validation():
    with pytest.raises(ValueError):
        SliderGeometry.paper_region(3, "inner")
    with pytest.raises(ValueError):
        SliderGeometry.paper_region(1, "middle")
    with pytest.raises(ValueError):
        SliderGeometry(0.15, [[0, 0, 0.1, 0, 1, 2.5]], -1)
    with pytest.raises(ValueError):
        SliderGeometry(0.15, [[0, 0, 0.1, 0, 1, 4]], 0)


# ------------------------------------------------------------------------------- (1) vertical load

@pytest.mark.parametrize("kind,active", [("inner", {P3}), ("outer", {P1, P2})])
@pytest.mark.parametrize("pair", [1, 2])
def test_pure_vertical_load(kind, active, pair):
    """Downward force on the section: only arcs whose push on the section points down carry it.

    Force on the section from spring i is -f k_t n (it opposes the compression): its e_b part is
    -k_t sin(theta) f.  Inner region (k_t = -1): sin < 0, the lower half circle P3 (the wall of
    the outer boom is pressed down by the inner boom's slider).  Outer region (k_t = +1): sin > 0,
    the top arcs P1, P2.  The distribution is mirror symmetric in y (paper: symmetric
    distributions), and the resultant equals the load to the solver tolerance.
    """
    g = region(pair, kind)
    F = 2.5e5
    f_c, m_c = np.array([0.0, 0.0, -F]), np.zeros(3)
    sol = solve_micro_motion(g, SPRING, f_c, m_c)
    f = sol.normal_force
    for j in (P1, P2, P3):
        on = f[g.mask(arc=j)]
        if j in active:
            assert np.all(on > 0.0)
        else:
            assert np.all(on == 0.0)              # exactly: delta < 0 gives k = 0
    push_b = -g.k_t * g.normals[:, 2] * f          # e_b part of the force on the section
    assert np.all(push_b <= 0.0)
    # resultant = load (Eqs. 67-71 and the e_s balance without friction); tolerance from rtol
    np.testing.assert_allclose(sol.force_on_section, f_c, rtol=0, atol=EQ_TOL * F)
    np.testing.assert_allclose(sol.moment_on_section, m_c, rtol=0,
                               atol=EQ_TOL * F * g.length_scale)
    # mirror symmetry y -> -y: P1 <-> P2 reversed in azimuth, P3 reversed; front == back.
    # The solution is symmetric up to the Newton tolerance; forces ~ F/80, relative error
    # ~ RTOL_SOLVE times the condition of the stiffness (~1e2) -> 1e-9 of max force.
    fmax = f.max()
    for ks in (1, -1):
        f1, f2 = f[g.mask(arc=P1, k_s=ks)], f[g.mask(arc=P2, k_s=ks)]
        f3 = f[g.mask(arc=P3, k_s=ks)]
        np.testing.assert_allclose(f1, f2[::-1], rtol=0, atol=EQ_TOL * fmax)
        np.testing.assert_allclose(f3, f3[::-1], rtol=0, atol=EQ_TOL * fmax)
    np.testing.assert_allclose(f[g.k_s == 1], f[g.k_s == -1], rtol=0, atol=EQ_TOL * fmax)
    # restoring: the section has moved up into the slider (u_b > 0), against the downward force
    # the compressed springs exert on it (inner: bottom wall up onto P3; outer: top wall up)
    assert sol.u_b > 0.0
    assert abs(sol.u_t) <= EQ_TOL * abs(sol.u_b)


# ------------------------------------------------------------------------------- (2) pure moment

@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("M", [1e5, -1e5])
def test_pure_moment_loads_slider_ends_oppositely(kind, M):
    """A moment about e_t is a couple of opposite vertical end forces +-M/(2w).

    Statics of the slider (frictionless, Eq. 66 / Eq. 70): m_t = -w sum_ks k_s Fbar_b(ks) and
    sum Fbar_b = 0, so the slider-side vertical resultant at end k_s is k_s M / (2 w) -- exactly,
    independently of the spring law.  Which arcs carry it follows from the sign of k_t sin(theta).
    """
    g = region(1, kind)
    w = g.half_width
    sol = solve_micro_motion(g, SPRING, np.zeros(3), np.array([0.0, M, 0.0]))
    F = sol.slider_force_vectors()
    for ks in (1, -1):
        Fb = F[g.k_s == ks, 2].sum()
        assert Fb == pytest.approx(ks * M / (2 * w), rel=EQ_TOL)
        # slider pushed along +e_b by springs with k_t sin(theta) > 0 (and vice versa)
        up_needed = np.sign(ks * M)
        arcs_on = {int(j) for j in np.unique(g.arc_index[(g.k_s == ks) & (sol.normal_force > 0)])}
        expect = {P3} if up_needed * g.k_t < 0 else {P1, P2}
        assert arcs_on == expect
    # the two ends are loaded oppositely and by equal amounts
    assert F[g.k_s == 1, 2].sum() == pytest.approx(-F[g.k_s == -1, 2].sum(), rel=EQ_TOL)
    # a pure couple produces no net lateral/vertical force and rotates about e_t only
    assert abs(sol.beta) > 0 and np.sign(sol.beta) == -np.sign(M)


# ------------------------------------------------------------------------------- (3) equilibrium

LOADS = [
    (np.array([0.0, 2e3, -2.5e5]), np.array([0.0, 1e5, 0.0]), 0.0),
    (np.array([1e4, -3e4, 1e5]), np.array([2e3, -5e4, 3e4]), 0.1),
    (np.array([0.0, 1e4, 6e5]), np.array([-1e4, 2e5, -1e4]), -0.15),
    (np.array([0.0, 5e2, -1e3]), np.array([10.0, 50.0, -20.0]), 0.12),
]


@pytest.mark.parametrize("pair", [1, 2])
@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("f_c,m_c,mu", LOADS)
def test_equilibrium_of_resultants(pair, kind, f_c, m_c, mu):
    """Eqs. 67-71 hold to 1e-9 relative, checked with resultants summed independently.

    Tolerance: the solver stops at 1e-11 of the load scale; summing 160 terms adds round-off
    ~ 160 * 1e-16 * sum f ~ 1e-13 of the load; 1e-9 leaves two decades of margin.
    """
    g = region(pair, kind)
    sol = solve_micro_motion(g, SPRING, f_c, m_c, mu)
    fbar, mbar = independent_resultants(g, sol)
    np.testing.assert_allclose(fbar, sol.f_bar, rtol=1e-12, atol=1e-12 * sol.total_normal_force)
    scale = load_scale(g, f_c, m_c)
    L = g.length_scale
    assert abs(f_c[1] + fbar[1]) <= EQ_TOL * scale                     # Eq. 67
    assert abs(f_c[2] + fbar[2]) <= EQ_TOL * scale                     # Eq. 68
    assert abs(m_c[1] + mbar[1]) <= EQ_TOL * scale * L                 # Eq. 69
    assert abs(m_c[2] + mbar[2]) <= EQ_TOL * scale * L                 # Eq. 70
    assert abs(m_c[0] + mbar[0]) <= EQ_TOL * scale * L                 # Eq. 71
    # compression-only: forces >= 0, zero exactly where delta <= 0
    assert np.all(sol.normal_force >= 0.0)
    assert np.all(sol.normal_force[sol.delta <= 0.0] == 0.0)
    np.testing.assert_allclose(sol.normal_force, SPRING.force(sol.delta), rtol=0, atol=0)


@pytest.mark.parametrize("f_c,m_c,mu", LOADS[:1])
def test_springs_push(f_c, m_c, mu):
    """The contact is restoring: c . x = -sum f delta < 0 (frictionless identity).

    The virtual work of the contact force on the section over its micro-motion is
    c . x = -sum f_i A_i x = -sum f_i delta_i (Eq. 61); springs that push make it negative.
    """
    for kind in ("inner", "outer"):
        g = region(1, kind)
        sol = solve_micro_motion(g, SPRING, f_c, m_c, mu)
        c5 = np.array([f_c[1], f_c[2], m_c[0], m_c[1], m_c[2]])
        work = float(c5 @ sol.x)
        e = float(sol.normal_force @ sol.delta)
        assert work < 0.0 and e > 0.0
        # c . x = -(sum f delta) + R . x; R . x is at the solver tolerance
        assert work == pytest.approx(-e, rel=1e-8)


# ------------------------------------------------------------------------------- (4) k0 x 10

E_MAX = 0.26    # max x (1 - 3x^2 + 2x^3) on [0, 1] (0.25997 at x = 0.4215): force deficit/(k0 eps)
D_MAX = 0.15    # int_0^1 x (1 - 3x^2 + 2x^3) dx = 1/2 - 3/4 + 2/5: energy deficit / (k0 eps^2)


def smoothing_bound(sol, spring):
    """Rigorous 2-norm bound of |f_smoothed - f_ideal| (frictionless), ideal law k0 delta+.

    Let Pi0 / Pi be the energies sum phi(A x) + c.x with the ideal / smoothed laws,
    0 <= phi0 - phi <= D_MAX k0 eps^2 per compressed spring.  phi0' is k0-Lipschitz, so with x0 the
    ideal minimiser Pi0(x) - Pi0(x0) >= |f0(Ax) - f0(Ax0)|^2 / (2 k0); and
    Pi0(x) - Pi0(x0) <= Pi(x) + D - Pi(x0) <= D (x minimises Pi, Pi <= Pi0).  Hence
    |f0(Ax) - f_ideal| <= k0 eps sqrt(2 D_MAX n_active), and |f - f0(Ax)| <= E_MAX k0 eps per
    spring in the transition 0 < delta < eps.
    """
    d = sol.delta
    n_act = int((d > 0).sum())
    n_tr = int(((d > 0) & (d < spring.eps)).sum())
    return spring.k0 * spring.eps * (math.sqrt(2 * D_MAX * n_act) + E_MAX * math.sqrt(n_tr))


def test_k0_times_10_equals_eps_times_10():
    """Exact scaling: f = k0 delta p(delta/eps) => (10 k0, eps) and (k0, 10 eps) give equal forces
    with x scaled by 1/10.  Tolerance: two independent Newton solves at 1e-11 -> 1e-9."""
    g = region(1, "inner")
    f_c, m_c = np.array([0.0, 2e3, -2.5e5]), np.array([3e3, 1e5, -2e3])
    a = solve_micro_motion(g, SpringLaw(1e10, 1e-6), f_c, m_c, 0.1)
    b = solve_micro_motion(g, SpringLaw(1e9, 1e-5), f_c, m_c, 0.1)
    np.testing.assert_allclose(a.normal_force, b.normal_force, rtol=0,
                               atol=EQ_TOL * b.normal_force.max())
    np.testing.assert_allclose(10 * a.x, b.x, rtol=0, atol=EQ_TOL * np.abs(b.x).max())


@pytest.mark.parametrize("eps,F,M", [
    (1e-6, 2.5e5, 1e5),       # default eps, realistic load: the bound holds but is loose (~75 %)
    (1e-6, 2.5e7, 1e7),       # default eps, 100x load: compressions >> 10 eps
    (1e-8, 2.5e5, 1e5),       # realistic load with eps = 1e-8 m
    (1e-8, 1e6, -3e5),
])
def test_insensitivity_to_k0(eps, F, M):
    """k0 -> 10 k0 changes the contact forces only through the smoothing zone (paper Section 8.3).

    The ideal law k0 delta+ is homogeneous, so its forces are independent of k0; both solutions
    lie within smoothing_bound of them.  Derived tolerance on the change:
        |f(k0) - f(10 k0)|_2 <= B = bound(k0) + bound(10 k0),
        |sum f(k0) - sum f(10 k0)| <= sqrt(n_active) B.
    Where B / sum f <= 1 % the paper's claim is asserted at that level.
    """
    g = region(1, "inner")
    f_c, m_c = np.array([0.0, 2e3, -F]), np.array([0.02 * F, M, 0.0])
    s1, s2 = SpringLaw(1e9, eps), SpringLaw(1e10, eps)
    a = solve_micro_motion(g, s1, f_c, m_c)
    b = solve_micro_motion(g, s2, f_c, m_c)
    B = smoothing_bound(a, s1) + smoothing_bound(b, s2)
    n_union = int(((a.delta > 0) | (b.delta > 0)).sum())
    diff2 = float(np.linalg.norm(a.normal_force - b.normal_force))
    dsum = abs(a.total_normal_force - b.total_normal_force)
    slack = EQ_TOL * a.total_normal_force               # two solver tolerances
    assert diff2 <= B + slack
    assert dsum <= math.sqrt(n_union) * B + slack
    rel_bound = math.sqrt(n_union) * B / a.total_normal_force
    if rel_bound <= 0.01:
        assert dsum / a.total_normal_force <= rel_bound
        # the per-end resultants are statically determined (exact), the micro-motions scale ~1/10
        for ks in (1, -1):
            np.testing.assert_allclose(a.slider_force_vectors()[g.k_s == ks].sum(axis=0),
                                       b.slider_force_vectors()[g.k_s == ks].sum(axis=0),
                                       rtol=0, atol=EQ_TOL * F)


# ------------------------------------------------------------------------------- (5) Jacobian

@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("mu", [0.0, 0.1])
def test_jacobian_matches_finite_differences(kind, mu):
    """Analytic dR/dx vs central differences.

    Steps h_j with max_i |A_ij| h_j = 1e-3 eps.  Truncation: f''' <= 18 k0/eps^2 on the
    transition, so the error per spring is <= h_d^2 f'''/6 = 3e-6 k0; round-off ~ 1e-16 sum f / h
    is far smaller.  Points within 2 h_d of the kinks of f'' (delta = 0, eps) would add a first-
    order error and are avoided.  Tolerance 1e-4 of |J|_max per column (30x margin).
    """
    g = region(1, kind)
    base = solve_micro_motion(g, SPRING, np.array([0.0, 3e3, -1.2e5]), np.array([2e3, 4e4, 1e3]))
    rng = np.random.default_rng(3)
    hd = 1e-3 * SPRING.eps
    h = hd / np.abs(g.A).max(axis=0)
    for trial in range(20):
        x = base.x * (1.0 + 0.3 * rng.normal(size=5))
        d = g.A @ x
        if np.min(np.minimum(np.abs(d), np.abs(d - SPRING.eps))) > 2 * hd:
            break
    else:
        pytest.fail("no point away from the kinks found")
    assert np.sum((d > 0) & (d < SPRING.eps)) > 0 and np.sum(d > SPRING.eps) > 0
    f_c, m_c = np.array([0.0, 1e3, -1e5]), np.array([1e3, 2e4, -3e3])
    R0, J = contact_residual(g, SPRING, f_c, m_c, mu, x)
    Jfd = np.empty((5, 5))
    for j in range(5):
        e = np.zeros(5)
        e[j] = h[j]
        Jfd[:, j] = (contact_residual(g, SPRING, f_c, m_c, mu, x + e)[0]
                     - contact_residual(g, SPRING, f_c, m_c, mu, x - e)[0]) / (2 * h[j])
    for j in range(5):
        col = np.abs(J[:, j]).max()
        assert col > 0
        np.testing.assert_allclose(J[:, j], Jfd[:, j], rtol=0, atol=1e-4 * col)


def central_gradient(fun, x):
    """Central differences of a scalar function of the load, relative steps 1e-4 (+1e3 N)."""
    fd = np.empty(len(x))
    for j in range(len(x)):
        e = np.zeros(len(x))
        e[j] = 1e-4 * (abs(x[j]) + 1e3)
        fd[j] = (fun(x + e) - fun(x - e)) / (2 * e[j])
    return fd


def test_aux_gradient_matches_finite_differences():
    """d(Eq. 72)/d(f_c, m_c, mu) by the implicit-function theorem vs central differences of
    re-solved problems.  Relative steps 1e-4; solver error 1e-12 of the load / 1e-4 step ~ 1e-8;
    truncation ~ (1e-4)^2 x curvature; tolerance 1e-5 of the largest entry."""
    g = region(1, "inner")
    f_c, m_c, mu = np.array([0.0, 4e3, -2.5e5]), np.array([5e3, 1e5, -4e3]), 0.1
    sol = solve_micro_motion(g, SPRING, f_c, m_c, mu, rtol=1e-13)
    d_fc, d_mc, d_mu = sol.aux_gradient()
    grad = np.concatenate([d_fc, d_mc])
    load = np.concatenate([f_c, m_c])

    def aux(load_vec, mu_v):
        s = solve_micro_motion(g, SPRING, load_vec[:3], load_vec[3:], mu_v, x0=sol.x, rtol=1e-13)
        return s.axial_residual

    fd = central_gradient(lambda x: aux(x, mu), load)
    np.testing.assert_allclose(grad, fd, rtol=0, atol=1e-5 * np.abs(grad).max())
    hm = 1e-5
    fd_mu = (aux(load, mu + hm) - aux(load, mu - hm)) / (2 * hm)
    assert d_mu == pytest.approx(fd_mu, rel=1e-5)


@pytest.mark.parametrize("mu", [0.0, 0.1, -0.15])
def test_normal_load_gradient_matches_finite_differences(mu):
    """d(sum f_ij)/d(f_t, f_b, m_s, m_t, m_b) (implicit function theorem, the friction Newton's
    sensitivity) vs central differences of re-solved problems; steps and tolerance as in the
    Eq. 72 gradient test above.  The axial force f_s does not enter Eqs. 67-71."""
    g = region(2, "outer")
    f_c, m_c = np.array([3e4, 4e3, -2.5e5]), np.array([5e3, 1e5, -4e3])
    sol = solve_micro_motion(g, SPRING, f_c, m_c, mu, rtol=1e-13)
    grad = sol.normal_load_gradient()
    c5 = np.array([f_c[1], f_c[2], *m_c])

    def load(c):
        s = solve_micro_motion(g, SPRING, np.array([f_c[0], c[0], c[1]]), c[2:], mu,
                               x0=sol.x, rtol=1e-13)
        return s.total_normal_force

    fd = central_gradient(load, c5)
    assert np.abs(grad).max() > 0.5           # the vertical load alone moves N by ~1 per N
    np.testing.assert_allclose(grad, fd, rtol=0, atol=1e-5 * np.abs(grad).max())


# ------------------------------------------------------------------------------- (6) laws

def test_spring_law_continuity_and_c1():
    """k and f vanish for delta < 0; k, dk/d delta, f, df/d delta continuous at 0 and eps.

    Values are compared across +-1e-9 eps; k is C1, so jumps are O(1e-9 k0) in k and
    O(1e-9 k0/eps) in dk/d delta; f' likewise O(1e-9 k0)."""
    s = SPRING
    k0, eps = s.k0, s.eps
    d = np.array([-1e-3, -eps, -1e-12, 0.0])
    assert np.all(s.force(d) == 0.0) and np.all(s.stiffness(d) == 0.0)
    assert np.all(s.tangent_stiffness(d) == 0.0) and np.all(s.stiffness_derivative(d) == 0.0)
    h = 1e-9 * eps
    for p in (0.0, eps):
        lo, hi = p - h, p + h
        assert abs(s.stiffness(hi) - s.stiffness(lo)) <= 1e-8 * k0
        assert abs(s.stiffness_derivative(hi) - s.stiffness_derivative(lo)) <= 1e-8 * k0 / eps
        assert abs(s.force(hi) - s.force(lo)) <= 1e-8 * k0 * eps
        assert abs(s.tangent_stiffness(hi) - s.tangent_stiffness(lo)) <= 1e-8 * k0
    # end values of the cubic transition (Eq. 63 boundary conditions)
    assert s.stiffness(eps) == k0 and s.stiffness_derivative(eps) == 0.0
    assert s.stiffness(0.0) == 0.0 and s.stiffness_derivative(0.0) == 0.0
    assert s.force(2 * eps) == pytest.approx(2 * k0 * eps, rel=1e-15)
    # tangent = d f / d delta = k + delta dk/d delta, checked by central differences inside
    dd = np.linspace(0.05, 0.95, 19) * eps
    hh = 1e-6 * eps
    fd = (s.force(dd + hh) - s.force(dd - hh)) / (2 * hh)
    ref = s.stiffness(dd) + dd * s.stiffness_derivative(dd)
    np.testing.assert_allclose(s.tangent_stiffness(dd), ref, rtol=1e-13)
    np.testing.assert_allclose(fd, ref, rtol=0, atol=1e-6 * k0)   # O(hh^2 f''') + round-off
    # monotone force (needed for a unique resultant-level solution)
    grid = np.linspace(-0.5, 2.0, 2001) * eps
    assert np.all(np.diff(s.force(grid)) >= 0.0)
    with pytest.raises(ValueError):
        SpringLaw(k0=-1.0)


def test_friction_law_continuity():
    """mu(v) odd, mu_s v/v_eps near 0, mu_s at v_eps, mu_d beyond 2 v_eps, continuous at the
    switches (jump over +-1e-9 v_eps bounded by the slope mu_s/v_eps times 2e-9 v_eps)."""
    law = FrictionLaw(mu_static=0.15, mu_dynamic=0.1, v_eps=0.01)
    v_eps = law.v_eps
    h = 1e-9 * v_eps
    for p in (0.0, v_eps, 2 * v_eps, -v_eps, -2 * v_eps):
        assert abs(law.mu(p + h) - law.mu(p - h)) <= 3e-9 * law.mu_static
    assert law.mu(0.0) == 0.0
    assert law.mu(v_eps) == pytest.approx(0.15, rel=1e-15)
    assert law.mu(0.5 * v_eps) == pytest.approx(0.075, rel=1e-15)
    assert law.mu(2 * v_eps) == pytest.approx(0.1, rel=1e-15)
    assert law.mu(0.5) == 0.1 and law.mu(-0.5) == -0.1
    v = np.linspace(-0.05, 0.05, 1001)
    np.testing.assert_allclose(law.mu(v), -law.mu(-v), rtol=0, atol=0)
    assert np.all(np.abs(law.mu(v)) <= 0.15)
    # the one-float path is the array formula
    np.testing.assert_allclose([law.mu(float(x)) for x in v], law.mu(v), rtol=1e-15, atol=0)
    # dmu_dv vs central differences away from |v| = v_eps (where mu is only C0)
    vv = np.array([0.3, 0.7, 1.2, 1.5, 1.8, 2.5, -1.4, -0.2]) * v_eps
    hh = 1e-7 * v_eps
    fd = (law.mu(vv + hh) - law.mu(vv - hh)) / (2 * hh)
    np.testing.assert_allclose(law.dmu_dv(vv), fd, rtol=0, atol=1e-6 * law.mu_static / v_eps)
    with pytest.raises(ValueError):
        FrictionLaw(0.1, 0.1, 0.0)


# ------------------------------------------------------------------------------- (7) friction

@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("v", [0.5, -0.5])
def test_friction_axial_resultant(kind, v):
    """With mu = mu(v) the axial friction on the section is mu(v) sum f along e_s (dragged in the
    direction the slider slides, s_dot = v); the slider-side resultant fbar_s = -mu sum f; the
    auxiliary residual (Eq. 72) is f_c,s - mu sum f and vanishes for f_c,s = mu sum f."""
    g = region(2, kind)
    law = FrictionLaw(0.15, 0.1, 0.01)
    mu = law.mu(v)
    assert mu == pytest.approx(0.1 * np.sign(v))
    f_c, m_c = np.array([0.0, 1e3, -2e5]), np.array([1e3, 8e4, 0.0])
    sol = solve_micro_motion(g, SPRING, f_c, m_c, mu)
    sf = sol.total_normal_force
    assert sol.force_on_section[0] == pytest.approx(mu * sf, rel=1e-14)
    assert sol.f_bar[0] == pytest.approx(-mu * sf, rel=1e-14)
    assert np.sign(sol.force_on_section[0]) == np.sign(v)
    assert sol.axial_residual == pytest.approx(-mu * sf, rel=1e-14)
    assert axial_residual(f_c, sol) == sol.axial_residual
    f_bal = np.array([mu * sf, f_c[1], f_c[2]])
    sol2 = solve_micro_motion(g, SPRING, f_bal, m_c, mu, x0=sol.x)
    # the axial component does not enter Eqs. 67-71: same solution, residual ~ round-off
    np.testing.assert_array_equal(sol2.normal_force, sol.normal_force)
    assert abs(sol2.axial_residual) <= 1e-12 * sf
    # friction dissipates: power on the slider moving at v e_s relative to the section <= 0
    assert float(sol.slider_force_vectors()[:, 0].sum()) * v < 0.0
    # friction changes the distribution through rbar x f^s (Eq. 66): moments still balance
    sol0 = solve_micro_motion(g, SPRING, f_c, m_c, 0.0)
    assert not np.allclose(sol0.normal_force, sol.normal_force, rtol=1e-6)
    _, mbar = independent_resultants(g, sol)
    np.testing.assert_allclose(mbar, -m_c, rtol=0, atol=EQ_TOL * load_scale(g, f_c, m_c)
                               * g.length_scale)


# ------------------------------------------------------------------------------- (8) zero load

def test_zero_load_returns_zero_micro_motion():
    g = region(1, "inner")
    for x0 in (None, np.array([1e-6, -2e-6, 1e-5, 0.0, 3e-6])):
        sol = solve_micro_motion(g, SPRING, np.zeros(3), np.zeros(3), 0.1, x0=x0)
        assert isinstance(sol, ContactSolution)
        assert np.all(sol.x == 0.0) and np.all(sol.normal_force == 0.0)
        assert np.all(sol.f_bar == 0.0) and np.all(sol.m_bar == 0.0) and sol.iterations == 0
    # a purely axial reaction is not carried by the springs: zero micro-motion, and the whole
    # axial force shows up in the auxiliary residual (it has to be balanced by friction)
    sol = solve_micro_motion(g, SPRING, np.array([5e4, 0.0, 0.0]), np.zeros(3), 0.1)
    assert np.all(sol.x == 0.0) and sol.axial_residual == 5e4


def test_tiny_load_in_cubic_regime():
    """Loads far below k0 eps per spring compress the springs inside the cubic transition;
    the solver still satisfies the equations (cold start along the linear solution's ray)."""
    g = region(1, "outer")
    f_c, m_c = np.array([0.0, 0.0, -1e-3]), np.array([0.0, 1e-4, 0.0])
    sol = solve_micro_motion(g, SPRING, f_c, m_c)
    assert sol.delta.max() < SPRING.eps
    assert np.abs(sol.residual[:2]).max() <= EQ_TOL * 1e-3


# ------------------------------------------------------------------------------- solver behaviour

def test_warm_start_and_typed_failure():
    g = region(1, "inner")
    f_c, m_c = np.array([0.0, 2e3, -2.5e5]), np.array([3e3, 1e5, -2e3])
    sol = solve_micro_motion(g, SPRING, f_c, m_c, 0.1)
    again = solve_micro_motion(g, SPRING, f_c, m_c, 0.1, x0=sol.x)
    assert again.iterations == 0
    near = solve_micro_motion(g, SPRING, 1.01 * f_c, 0.99 * m_c, 0.1, x0=sol.x)
    assert near.iterations <= 3                     # quadratic convergence from 1 % away
    with pytest.raises(ContactSolveError) as exc:
        solve_micro_motion(g, SPRING, f_c, m_c, 0.1, max_iter=0, t=1.5)
    assert isinstance(exc.value, SimulationError) and exc.value.t == 1.5
    assert exc.value.residual is not None and exc.value.last_state is not None
    with pytest.raises(ContactSolveError) as exc:
        solve_micro_motion(g, SPRING, np.array([0.0, np.nan, 0.0]), m_c)
    assert math.isnan(exc.value.t)


def random_loads(seed: int, count: int):
    """(geometry, f_c, m_c, mu): loads over ten decades, moments 0.01-1 of the force times 1 m,
    both regions of pairs 1 and 2, |mu| <= 0.15."""
    rng = np.random.default_rng(seed)
    geoms = [region(p, k) for p in (1, 2) for k in ("inner", "outer")]
    for i in range(count):
        mag = 10 ** rng.uniform(-2, 7)
        f_c = rng.normal(size=3) * mag
        m_c = rng.normal(size=3) * mag * 10 ** rng.uniform(-2, 0)
        yield geoms[i % 4], f_c, m_c, rng.uniform(-0.15, 0.15)


def test_random_loads_converge():
    """Random loads over ten decades, both regions, |mu| <= 0.15: all converge (bounded count)."""
    for g, f_c, m_c, mu in random_loads(7, 200):
        sol = solve_micro_motion(g, SPRING, f_c, m_c, mu)
        Lr = 1.0 / g.length_scale
        r = np.abs(sol.residual * np.array([1, 1, Lr, Lr, Lr])).max()
        assert r <= 10 * RTOL_SOLVE * load_scale(g, f_c, m_c)
        assert sol.iterations <= 20


@pytest.mark.skipif(not micro_motion_compiled.AVAILABLE, reason="numba not installed")
def test_compiled_newton_equals_the_python_loop(monkeypatch):
    """The compiled Newton (micro_motion_compiled) and the Python loop it replaces take the same
    steps: over random loads (ten decades, both regions, cold and warm starts) the same
    iteration counts and solutions within 1e-9 of the largest micro-motion (round-off in the
    order of the sums, amplified by the Newton solves); the same typed failure."""
    for g, f_c, m_c, mu in random_loads(11, 100):
        out = []
        for compiled in (True, False):
            monkeypatch.setattr(micro_motion_compiled, "AVAILABLE", compiled)
            cold = solve_micro_motion(g, SPRING, f_c, m_c, mu)
            warm = solve_micro_motion(g, SPRING, 1.02 * f_c, 0.97 * m_c, mu, x0=cold.x)
            out.append((cold, warm))
        for a, b in zip(*out):
            assert a.iterations == b.iterations
            np.testing.assert_allclose(a.x, b.x, rtol=0, atol=1e-9 * np.abs(b.x).max())
            assert a.total_normal_force == pytest.approx(b.total_normal_force, rel=1e-9)
    monkeypatch.setattr(micro_motion_compiled, "AVAILABLE", True)
    f_c, m_c = np.array([0.0, 2e3, -2.5e5]), np.array([3e3, 1e5, -2e3])
    with pytest.raises(ContactSolveError, match="no convergence in 0 Newton") as exc:
        solve_micro_motion(g, SPRING, f_c, m_c, 0.1, max_iter=0, t=2.5)
    assert exc.value.t == 2.5 and exc.value.residual is not None


@pytest.mark.parametrize("compiled", [True, False])
def test_normal_load_equals_the_full_solve(compiled, monkeypatch):
    """normal_load (the friction Newton's lean path: no ContactSolution; the Newton matrices
    formed once per mu) gives the full solve's normal load, its gradient and micro-motions,
    cold and warm started, and zero at zero load."""
    from sim_core.physics.contact.sliding_block_contact import newton_matrices, normal_load
    if compiled and not micro_motion_compiled.AVAILABLE:
        pytest.skip("numba not installed")
    monkeypatch.setattr(micro_motion_compiled, "AVAILABLE", compiled)
    for g, f_c, m_c, mu in random_loads(13, 40):
        mats = newton_matrices(g, SPRING, mu)
        for x0 in (None, solve_micro_motion(g, SPRING, 0.9 * f_c, 1.1 * m_c, mu).x):
            ref = solve_micro_motion(g, SPRING, f_c, m_c, mu, x0=x0)
            N, dN, x = normal_load(g, SPRING, f_c, m_c, mu, *mats, x0=x0)
            assert N == pytest.approx(ref.total_normal_force, rel=1e-12)
            np.testing.assert_allclose(dN, ref.normal_load_gradient(), rtol=1e-10,
                                       atol=1e-12 * np.abs(dN).max())
            np.testing.assert_allclose(x, ref.x, rtol=0, atol=1e-12 * np.abs(ref.x).max())
    N, dN, x = normal_load(g, SPRING, np.zeros(3), np.zeros(3), 0.1,
                           *newton_matrices(g, SPRING, 0.1))
    assert N == 0.0 and not dN.any()
