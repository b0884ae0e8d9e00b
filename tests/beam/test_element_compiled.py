"""The compiled element mass matrix and force vector equal the numpy model path.

Reference: ``Model.element_mass_force(Model.element_context(t, el, qe, qde))`` of a Model built
like ``benchmarks/profile_rhs.py::cantilever`` (one steel beam, clamped/free), here with two
elements, rotary inertia about all three section axes, an oblique reference basis and the stress
filter.  The element under test (the second one: both of its material ends are coordinates) is
bent, twisted, stretched and moving: a random perturbation of the straight beam in all
coordinates (positions, r', r'', gamma, gamma', s_1, s_n) and random velocities of all of them.

Tolerance: 1e-10 times the largest absolute entry of each reference array.  Both paths compute
the same algebra; they differ only in the order of the sums (basis contractions, Jacobian
products, the Gram product A^T A by dsyrk/gemm vs numpy's, the force as one product with the
stacked rows vs one per effect, B_xi formed as B_s plus eps' ds/dchi on the s columns), so the
difference is round-off of sums whose terms are at most of the size of the largest entry (the
elastic terms, EA ~ 2e9 N, dominate F; a few hundred terms per entry).  The observed differences
are ~1e-15 (M) and ~1e-13 (F) of the maximum.
"""

import numpy as np
import pytest

from sim_core.model.boundary import boundary_condition, reference_basis
from sim_core.model.model import Model
from sim_core.physics import _effects_numba as element_compiled
from sim_core.physics.beam.moving_node_beam import Beam, BeamSection
from sim_core.physics.effects import Elasticity, Gravity, Inertia, StressFilter, effect_parameters

pytestmark = pytest.mark.skipif(not element_compiled.AVAILABLE, reason="numba not installed")

E, G_MOD, RHO, L = 2.1e11, 8.0e10, 7850.0, 10.0
A, I_T, I_B = 1e-2, 1e-5, 1.3e-5
GRAVITY = np.array([0.0, 0.0, -9.81])


def _effects(which):
    make = {"inertia": Inertia, "elasticity": Elasticity,
            "filter": lambda: StressFilter(0.01), "gravity": lambda: Gravity(GRAVITY)}
    return [make[w]() for w in which]


def _moving_element(n_nodes, effects, seed=3):
    """(model, element, qe, qde, section) of a bent, twisted, stretched, moving element."""
    sec = BeamSection(EA=E * A, GJ=G_MOD * (I_T + I_B), EI_t=E * I_T, EI_b=E * I_B,
                      rhoA=RHO * A, J_s=RHO * (I_T + I_B), J_t=RHO * I_T, J_b=RHO * I_B)
    b = Beam("b", L, sec, (0.0, 4.0, L), n_nodes=n_nodes,
             reference_basis=reference_basis([1, 0, 0.3]))
    cons = [boundary_condition([0], [b], 0, "left", "clamped", [0, 0, 0], [1, 0, 0]),
            boundary_condition([0], [b], 0, "right", "free")]
    model = Model([b], effects, [], cons)
    q = b.straight_coordinates([0.5, -0.2, 1.0], [1.0, 0.1, 0.3])
    rng = np.random.default_rng(seed)
    q = q + 1e-2 * rng.standard_normal(q.shape)
    qd = rng.standard_normal(q.shape)
    el, idx = b.elements[1], b.index_map[1]
    return model, el, q[idx], qd[idx], sec


def _check(got, ref, name):
    scale = np.abs(ref).max()
    assert scale > 0, name
    err = np.abs(got - ref).max()
    assert err <= 1e-10 * scale, f"{name}: max |diff| {err:.3e} > 1e-10 * {scale:.3e}"


ALL = ("inertia", "elasticity", "filter", "gravity")
EFFECT_SETS = {
    "all": ALL,
    "no_filter": ("inertia", "elasticity", "gravity"),
    "no_gravity": ("inertia", "elasticity", "filter"),
    # each effect alone, so that no term hides under a larger one in the tolerance
    "inertia": ("inertia",),
    "elasticity": ("elasticity",),
    "filter": ("filter",),
    "gravity": ("gravity",),
}


@pytest.mark.parametrize("n_nodes", [3, 9])
@pytest.mark.parametrize("which", list(EFFECT_SETS), ids=list(EFFECT_SETS))
def test_equals_model_element_mass_force(n_nodes, which):
    effects = _effects(EFFECT_SETS[which])
    model, el, qe, qde, sec = _moving_element(n_nodes, effects)
    M_ref, F_ref = model.element_mass_force(model.element_context(0.0, el, qe, qde))
    kw = effect_parameters(effects, sec)
    M, F = element_compiled.element_mass_force(el, qe, qde, **kw)
    assert M.shape == (el.n_coords, el.n_coords) and F.shape == (el.n_coords,)
    _check(F, F_ref, "F")
    if which in ("elasticity", "gravity"):      # no mass term: both are zero
        assert not M.any() and not M_ref.any()
    else:
        _check(M, M_ref, "M")
    # force only: the same F, no mass matrix
    M0, F0 = element_compiled.element_mass_force(el, qe, qde, needs_mass=False, **kw)
    assert M0 is None
    _check(F0, F_ref, "F (needs_mass=False)")
    # F - M qdd through the weighted rows (qdde), as the structured Jacobian takes it, and
    # Model.element_residual on both paths
    qdde = np.random.default_rng(5).standard_normal(el.n_coords)
    R_ref = F_ref - M_ref @ qdde
    M1, R = element_compiled.element_mass_force(el, qe, qde, qdde=qdde, **kw)
    assert M1 is None
    _check(R, R_ref, "F - M qdd")
    _check(model.element_residual(0.0, el, qe, qde, qdde), R_ref, "Model.element_residual")
    element_compiled.AVAILABLE = False
    try:
        _check(model.element_residual(0.0, el, qe, qde, qdde), R_ref,
               "Model.element_residual (reference path)")
    finally:
        element_compiled.AVAILABLE = True


def test_explicit_arguments():
    """The documented signature (all effects on) without the effect_parameters helper."""
    model, el, qe, qde, sec = _moving_element(9, _effects(ALL), seed=11)
    M_ref, F_ref = model.element_mass_force(model.element_context(0.0, el, qe, qde))
    M, F = element_compiled.element_mass_force(el, qe, qde, sec.rhoA, sec.J, sec.D, 0.01,
                                               GRAVITY)
    _check(M, M_ref, "M")
    _check(F, F_ref, "F")


def test_uncovered_effects_rejected():
    sec = BeamSection(EA=1.0, GJ=1.0, EI_t=1.0, EI_b=1.0, rhoA=1.0, J_s=1.0, z_c=0.04)
    with pytest.raises(ValueError):
        effect_parameters([Inertia()], sec)
    with pytest.raises(ValueError):
        effect_parameters([Inertia(), Inertia()],
                                           BeamSection(1.0, 1.0, 1.0, 1.0, 1.0, 1.0))


@pytest.mark.parametrize("n_nodes", [3, 9])
def test_quadrature_row_tables(n_nodes):
    """The rows of the arbitrary-point polynomial D_all at the Gauss points are the position
    and torsion tables q_phi, q_psi (the real parts the convective terms take from them), and
    q_drows are their xi-derivatives (against central differences at xi +- 1e-6)."""
    model, el, qe, qde, sec = _moving_element(n_nodes, _effects(ALL))
    el.basis_tables()
    na, nt = el.n + 4, 2 * el.n
    xi, sub = el.q_pos - el.q_sub, el.q_sub

    def rows_at(x):
        return np.einsum("gp,gpk->gk", x[:, None] ** np.arange(6), el.D_all[sub])
    rows = rows_at(xi)
    G = rows.shape[0]
    np.testing.assert_allclose(rows[:, :7 * na].reshape(G, 7, na), el.q_phi, rtol=0,
                               atol=1e-12 * np.abs(el.q_phi).max())
    np.testing.assert_allclose(rows[:, 7 * na:7 * na + 5 * nt].reshape(G, 5, nt), el.q_psi,
                               rtol=0, atol=1e-12 * np.abs(el.q_psi).max())
    h = 1e-6
    drows = el.q_drows
    np.testing.assert_allclose(drows, (rows_at(xi + h) - rows_at(xi - h)) / (2 * h), rtol=0,
                               atol=1e-6 * np.abs(drows).max())
