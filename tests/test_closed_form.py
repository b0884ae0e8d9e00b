"""Tests of sim_core.validation.closed_form against independent numerics and the numbers of
docs/model.md#inputs-and-decisions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.linalg import eigh_tridiagonal

from sim_core.errors import SceneError
from sim_core.physics.drive_profiles import CubicSmoothstepSchedule
from sim_core.validation import closed_form as cf

TH = math.radians(60.0)


# ----------------------------------------------------- docs/model.md#check-cantilever-statics
def test_cantilever_statics_by_quadrature():
    P, q, L, EI = 1.2e4, 3.1e3, 10.0, 7.22e8
    for res, M in ((cf.cantilever_tip_load(P, L, EI), lambda x: P * (L - x)),
                   (cf.cantilever_uniform_load(q, L, EI), lambda x: 0.5 * q * (L - x) ** 2)):
        slope = quad(lambda x: M(x) / EI, 0, L)[0]             # w' = int M/EI
        defl = quad(lambda x: (L - x) * M(x) / EI, 0, L)[0]    # w = int (L - x) M/EI
        assert res.slope == pytest.approx(slope, rel=1e-12)
        assert res.deflection == pytest.approx(defl, rel=1e-12)


# ------------------------------------------------- docs/model.md#check-cantilever-frequencies
def test_cantilever_roots_and_frequencies():
    b = cf.cantilever_beta_L(3)
    np.testing.assert_allclose(b, [1.8751, 4.6941, 7.8548], atol=6e-5)
    assert np.all(np.abs(1 + np.cos(b) * np.cosh(b)) < 1e-9)
    EI, m, L = 7.22e8, 318.86, 10.0
    np.testing.assert_allclose(cf.cantilever_bending_omegas(EI, m, L),
                               b**2 * math.sqrt(EI / (m * L**4)))


def test_fixed_free_bar_against_finite_differences():
    EA, m, L, n = 8.53e9, 318.86, 10.0, 4000
    h = L / n                                   # nodes 1..n; node n free (half-cell at the end)
    d = np.full(n, 2.0) * EA / h**2
    d[-1] = EA / h**2
    mass = np.full(n, 1.0)
    mass[-1] = 0.5
    # symmetric scaling of K x = w^2 m M x with lumped M
    s = 1 / np.sqrt(mass)
    dd = d * s * s / m
    ee = -EA / h**2 * s[:-1] * s[1:] / m
    w1 = math.sqrt(eigh_tridiagonal(dd, ee, select="i", select_range=(0, 0))[0][0])
    assert cf.fixed_free_axial_f1(EA, m, L) == pytest.approx(w1 / (2 * math.pi), rel=1e-5)
    assert cf.fixed_free_torsion_f1(4.0, 1.0, 0.25) == pytest.approx(2.0)


# ------------------------------------------------------------ docs/model.md#check-moving-load
@pytest.mark.parametrize("alpha", [0.1, 0.3, 0.5])
def test_fryba_series_equals_modal_ode(alpha):
    P, L, EI, m, n = 1.0e5, 20.0, 8.39e7, 544.6, 15
    om1 = (math.pi / L) ** 2 * math.sqrt(EI / m)
    c = alpha * om1 * L / math.pi
    T = L / c
    j = np.arange(1, n + 1)
    omj = j**2 * om1

    def rhs(t, y):   # q_j'' + w_j^2 q_j = 2P/(mL) sin(j pi c t / L)
        q, qd = y[:n], y[n:]
        return np.concatenate([qd, 2 * P / (m * L) * np.sin(j * math.pi * c * t / L) - omj**2 * q])

    t = np.linspace(0.0, T, 801)
    w0 = 2 * P * L**3 / (math.pi**4 * EI)
    sol = solve_ivp(rhs, (0, T), np.zeros(2 * n), method="DOP853", t_eval=t,
                    rtol=1e-10, atol=1e-12 * w0)
    x = np.array([0.5 * L, 0.25 * L, 0.8 * L])
    w_ode = np.sin(np.outer(x, j) * math.pi / L) @ sol.y[:n]           # (3, nt)
    w_ser = cf.fryba_deflection(x[:, None], t[None, :], P, c, L, EI, m, n_terms=n)
    peak = np.max(np.abs(w_ser))
    assert w_ser.shape == (3, t.size)
    assert np.max(np.abs(w_ser - w_ode)) < 1e-6 * peak


def test_fryba_quasistatic_limit_and_errors():
    P, L, EI, m = 1.0e4, 20.0, 8.39e7, 544.6
    om1 = (math.pi / L) ** 2 * math.sqrt(EI / m)
    c = 1e-4 * om1 * L / math.pi
    w = cf.fryba_deflection(L / 2, L / (2 * c), P, c, L, EI, m, n_terms=200)
    assert float(w) == pytest.approx(P * L**3 / (48 * EI), rel=1e-4)
    assert cf.fryba_deflection(0.3 * L, np.array([0.0]), P, c, L, EI, m)[0] == 0.0
    with pytest.raises(SceneError, match="alpha"):
        cf.fryba_deflection(L / 2, 0.1, P, om1 * L / math.pi, L, EI, m)   # alpha = 1
    with pytest.raises(SceneError, match="t = "):
        cf.fryba_deflection(L / 2, 1.01 * L / c, P, c, L, EI, m)
    with pytest.raises(SceneError, match="EI = -1"):
        cf.fryba_deflection(L / 2, 0.0, P, c, L, -1.0, m)


# ----------------------------------------------------------------- docs/model.md#check-sleeve
def test_bigoni_sleeve_energy_release():
    P, EI, ell = 50.0, 2.0e3, 1.3
    r = cf.bigoni_sleeve(P, ell, EI)
    assert r.tip_deflection == pytest.approx(P * ell**3 / (3 * EI))
    assert r.configurational_force == pytest.approx((P * ell) ** 2 / (2 * EI))

    def potential(l):   # total potential energy at fixed load: U - P w = -P^2 l^3/(6EI)
        w = cf.bigoni_sleeve(P, l, EI).tip_deflection
        return 0.5 * P * w - P * w

    h = 1e-5
    release = -(potential(ell + h) - potential(ell - h)) / (2 * h)
    assert r.configurational_force == pytest.approx(release, rel=1e-7)


# ------------------------------------------------------ geometry, docs/model.md#input-luffing
def test_luffing_geometry_matches_scenarios():
    g = cf.luffing_geometry(TH)
    assert g.cylinder_length == pytest.approx(8.147, abs=5e-4)
    np.testing.assert_allclose(g.origin, [0.4035, 0.0, 0.8999], atol=5e-5)
    assert g.lever == pytest.approx(0.714, abs=5e-4)
    assert g.lever < np.linalg.norm(g.d1 - g.d2)              # AMB note: lever <= |D1 D2|
    rb1, rb3 = np.array(cf.RBAR1_DEFAULT), np.array(cf.RBAR3_DEFAULT)
    direct = np.array(cf.R1_DEFAULT) - np.array(cf.R2_DEFAULT) + g.rotation @ (rb3 - rb1)
    assert g.cylinder_length == pytest.approx(np.linalg.norm(direct), rel=1e-14)
    np.testing.assert_allclose(g.origin + g.rotation @ rb1, cf.R1_DEFAULT, atol=1e-15)
    np.testing.assert_allclose(g.e_s, [0.5, 0.0, math.sqrt(3) / 2], atol=1e-15)   # tip lifted


def test_top_centre_start_points():
    np.testing.assert_allclose(cf.boom3_top_centre(TH, 2.0), [7.404, 13.024], atol=5e-4)
    np.testing.assert_allclose(cf.boom3_top_centre(TH, 8.0), [13.404, 23.417], atol=5e-4)
    assert cf.boom3_top_centre(TH, np.array([2.0, 5.0, 8.0])).shape == (3, 2)


# ------------------------------------------------------------ docs/model.md#input-rigid-limit
@pytest.mark.parametrize("sign, Ls0", [(1, 2.0), (-1, 8.0)])
def test_rigid_tip_kinematics(sign, Ls0):
    sch = CubicSmoothstepSchedule(sign=sign, s0=Ls0)
    r0 = cf.boom3_top_centre(TH, Ls0)
    t = np.linspace(0.0, 20.0, 201)
    k = cf.rigid_tip_kinematics(t, sch, TH, r0)
    ref = cf.boom3_top_centre(TH, sch.stroke(t))                    # rigid tip at L_s(t)
    np.testing.assert_allclose(np.stack([k.x, k.z], -1), ref, atol=1e-12)
    np.testing.assert_allclose(cf.boom3_top_centre(TH, Ls0 + sign * 6.0), [k.x[-1], k.z[-1]],
                               atol=1e-12)
    h = 1e-6
    kp = cf.rigid_tip_kinematics(t + h, sch, TH, r0)
    km = cf.rigid_tip_kinematics(t - h, sch, TH, r0)
    np.testing.assert_allclose((kp.x - km.x) / (2 * h), k.vx, atol=1e-7)
    np.testing.assert_allclose((kp.vz - km.vz) / (2 * h), k.az, atol=1e-7)
    assert k.vz[80] == pytest.approx(sign * 2 * 0.5 * math.sin(TH))


# --------------------------------------------------------- docs/model.md#check-static-luffing
def _potential(theta, Ls, mp, g=9.81):
    """Gravity potential of the rigid boom (independent: Z of each mass point)."""
    geo = cf.luffing_geometry(theta)
    m, zc = cf.M_PER_LENGTH_DEFAULT, cf.Z_C_DEFAULT
    z = [geo.origin[2] + math.sin(theta) * (k * Ls + 5.0) + math.cos(theta) * zc[k]
         for k in range(3)]
    zp = geo.origin[2] + math.sin(theta) * (2 * Ls + 10.0)
    return g * (sum(10 * m[k] * z[k] for k in range(3)) + mp * zp)


@pytest.mark.parametrize("Ls, mp", [(2.0, 1000.0), (2.0, 25000.0), (8.0, 25000.0)])
def test_static_forces_by_virtual_work(Ls, mp):
    f = cf.static_luffing_forces(TH, Ls, mp)
    h = 1e-6
    dV = (_potential(TH + h, Ls, mp) - _potential(TH - h, Ls, mp)) / (2 * h)
    dL = (cf.luffing_geometry(TH + h).cylinder_length
          - cf.luffing_geometry(TH - h).cylinder_length) / (2 * h)
    assert f.luffing_force > 0                                   # compression
    assert f.luffing_force == pytest.approx(dV / dL, rel=1e-6)   # F_L dL = dV
    assert f.luffing_force * f.lever == pytest.approx(f.gravity_moment, rel=1e-12)
    dVs = (_potential(TH, Ls + h, mp) - _potential(TH, Ls - h, mp)) / (2 * h)
    assert f.telescopic_force == pytest.approx(dVs, rel=1e-6)    # F_tel dL_s = dV
    m3 = 10 * cf.M_PER_LENGTH_DEFAULT[2]
    assert f.rope_tension == pytest.approx((m3 + mp) * 9.81 * math.sin(TH))
    assert f.retraction_rope_tension == 0.0


def test_closed_form_validation_messages():
    with pytest.raises(SceneError, match=r"^L = 0\.0 is invalid; allowed range"):
        cf.cantilever_tip_load(1.0, 0.0, 1.0)
    with pytest.raises(SceneError, match=r"^n_modes = 0"):
        cf.cantilever_beta_L(0)
    with pytest.raises(SceneError, match=r"m_per_length\[1\] = nan"):
        cf.static_luffing_forces(TH, 2.0, 0.0, m_per_length=(1.0, math.nan, 1.0))
