"""Hand calculations that pin down the three slider-moment models (contact.moment_model).

Setup, shared by every test: the paper's three booms at 60 deg with the 25 t payload, in the
static equilibrium of ``initial_equilibrium`` at L_s = 2, 5 and 8 m.  The booms are made
weightless (m' and rho scaled by 1e-6, so EA = E m'/rho is unchanged) and 100x stiffer (E =
2.1e13 Pa), so that the load is the payload alone and linear small-deflection statics is exact
to the rotations of the sections, phi <= P L^2 / (2 EI_3) ~ 1e-4 rad.

Notation: P = m_p g cos(theta) = 122.6 kN, the payload's weight across the booms (along e_b);
a = L - L_s the overlap of adjacent booms (L = 10 m); each contact region's force and moment
are those the constraint (or the seat) exerts on its second body, in section components
(s, t, b) (sim_core.physics.contact.friction.section_reaction).

couple: the bending angles are free, so no region carries a bending moment and each overlap is
a beam on two supports.  Boom 3 (loaded by P at its tip, L from its left end) rests on region
I_23 (its left end) and region II_23 (a from its left end):
    moments about I_23:  F_II23 a = P L      ->  F_II23 = P L / a
    shear:               F_I23 = F_II23 - P  ->  F_I23 = P L_s / a
Booms 2 and 3 together rest on I_12 (boom 2's left end) and II_12 (a from it), the tip L + L_s
from boom 2's left end:  F_II12 = P (L + L_s) / a,  F_I12 = P 2 L_s / a.
The neglected terms are the sections' rotation phi times the axial loads (rope and cylinder,
< 5 P): |error| < 5 phi P ~ 5e-4 P; the tolerance is 2e-3 of the force.

rigid (Section 6): both regions of a pair clamp the two booms together (equal displacement and
rotation at both ends of the overlap).  Where no other load acts inside the overlap, each
boom's deflection there is the cubic fixed by the same four end values, so the two booms have
the same curvature: M_2 / EI_2 = M_3 / EI_3, and the overlap's bending moment splits in
proportion to EI.  Just inside boom 2's free right end (region II_23) boom 2's moment is the
region's moment and the total is P L_s; just inside boom 3's left end (I_23) boom 3's moment is
the region's moment and the total is P L:
    |m_II23| = EI_2 / (EI_2 + EI_3) P L_s,     |m_I23| = EI_3 / (EI_2 + EI_3) P L.
The overlap of booms 2 and 3 is free of other loads for L_s >= 5 m (boom 1's right end meets
boom 2 at s = L - L_s <= L_s); at L_s = 2 m region II_12 lies inside it.  The spline beam
represents the jump of the shear force at the inner contact point, which is not a node,
over one sub-element, so the moments converge to the hand calculation at first order in the
sub-element length (measured: 9 % off at 8 sub-elements and L_s = 8 m, 4.4 % at 16, 2.2 % at
32).  The test therefore checks the first-order convergence and that the Richardson
extrapolation from 8 and 16 sub-elements, 2 m(16) - m(8), is within 5e-3 of the split.

seat: an elastic seat of stiffness k between the bending angles.  It tends to the rigid model
as k grows (the difference falls as 1/k once k is far above the booms' rotational stiffness
EI/a ~ 1e10 N m/rad here) and to the couple model as k falls (the seat moments, and with them
the change of the contact forces, fall in proportion to k).
"""

import functools

import numpy as np
import pytest

from sim_core.physics.constraints import material_point
from sim_core.physics.contact.friction import region_multipliers, section_reaction
from sim_core.systems.telescopic.params import TABLE2, TelescopicParams
from sim_core.systems.telescopic.build import build_telescopic, initial_equilibrium

L = 10.0
THETA = np.radians(60.0)
P = 25000.0 * 9.81 * np.cos(THETA)
EI2, EI3 = TABLE2[1][0], TABLE2[2][0]
WEIGHTLESS = 1e-6
REGIONS = ("I_12", "II_12", "I_23", "II_23")


@functools.lru_cache(maxsize=None)
def statics(model: str, Ls: float, n_nodes: int = 9, k: float = 1e8) -> dict:
    """{region: (f_s, f_t, f_b, m_s, m_t, m_b)} at the static equilibrium (N, N m)."""
    sections = tuple((EI, GJ, m * WEIGHTLESS) for EI, GJ, m in TABLE2)
    p = TelescopicParams(n_nodes=n_nodes, moment_model=model, seat_stiffness=k, stroke0=Ls,
                         E=2.1e13, rho=7850.0 * WEIGHTLESS, sections=sections,
                         contact_distribution=False)
    ts = build_telescopic(p)
    z, lam = initial_equilibrium(ts)
    m = ts.model
    Q, _ = m.full_state(0.0, z, 0 * z)
    basis = m.beams[0].reference_basis
    out = {}
    for j in range(2):
        points = {f"I_{j + 1}{j + 2}": material_point(m, j, s_index=ts.s2_index[j]),
                  f"II_{j + 1}{j + 2}": material_point(m, j + 1, s_index=ts.s3_index[j + 1])}
        for name, point in points.items():
            f, mo = section_reaction(point, Q, *region_multipliers(ts, name, Q, lam), basis)
            out[name] = np.concatenate([f, mo])
    return out


@pytest.mark.parametrize("Ls", [2.0, 5.0, 8.0])
def test_couple_contact_forces_are_the_overlap_couple(Ls):
    a = L - Ls
    expected = {"I_23": P * Ls / a, "II_23": P * L / a,
                "I_12": P * 2 * Ls / a, "II_12": P * (L + Ls) / a}
    got = statics("couple", Ls)
    for name, F in expected.items():
        assert got[name][2] == pytest.approx(F, rel=2e-3), (name, got[name][2], F)
        # nothing else: no bending moment, no lateral force, no axial force without friction
        assert np.all(np.abs(got[name][[0, 1]]) < 1e-3 * F), got[name]
        assert np.all(np.abs(got[name][3:]) < 1e-6 * F * L), got[name]


@pytest.mark.parametrize("Ls", [5.0, 8.0])
def test_rigid_overlap_moment_splits_in_proportion_to_EI(Ls):
    split = {"II_23": EI2 / (EI2 + EI3) * P * Ls, "I_23": EI3 / (EI2 + EI3) * P * L}
    coarse, fine = statics("rigid", Ls, 9), statics("rigid", Ls, 17)
    for name, M in split.items():
        e8 = abs(coarse[name][4]) / M - 1.0            # m_t: the moment about e_t
        e16 = abs(fine[name][4]) / M - 1.0
        # first order: halving the sub-element halves the error (ratio 2 within 20 %)
        assert abs(e16) < abs(e8) and e8 / e16 == pytest.approx(2.0, rel=0.2), (name, e8, e16)
        assert abs(2 * e16 - e8) < 5e-3, (name, e8, e16)


def test_rigid_contact_moments_turn_the_paper_way():
    """Section 9.2 (1), (2): the moment on boom 2 at its inner contact point (I_23) turns about
    +e_t, the moment on boom 3 at its outer contact point (II_23) about -e_t, and they are the
    only moment components (the payload acts in the luffing plane)."""
    for Ls in (2.0, 5.0, 8.0):
        got = statics("rigid", Ls)
        assert got["I_23"][4] > 0.0 > got["II_23"][4], got
        for name in REGIONS:
            assert abs(got[name][3]) + abs(got[name][5]) < 1e-6 * abs(got[name][4])


def test_seat_tends_to_rigid_as_its_stiffness_grows():
    rigid = statics("rigid", 5.0, 5)
    d = [max(np.max(np.abs(statics("seat", 5.0, 5, k)[nm] - rigid[nm])) for nm in REGIONS)
         for k in (1e13, 1e14)]
    scale = max(np.max(np.abs(rigid[nm])) for nm in REGIONS)
    assert d[1] < 1e-2 * scale
    assert d[0] / d[1] == pytest.approx(10.0, rel=0.2), d       # the difference falls as 1/k


def test_seat_tends_to_couple_as_its_stiffness_falls():
    couple = statics("couple", 5.0, 5)
    seats = [statics("seat", 5.0, 5, k) for k in (1e4, 1e5)]
    d = [max(np.max(np.abs(s[nm] - couple[nm])) for nm in REGIONS) for s in seats]
    assert d[0] < 1e-5 * max(abs(couple[nm][2]) for nm in REGIONS)
    assert d[1] / d[0] == pytest.approx(10.0, rel=0.2), d       # in proportion to k
    # what changes is the seat moment, carried across the overlap a as a force pair
    for s in seats:
        moment = max(abs(s[nm][4]) for nm in REGIONS)
        assert max(abs(s[nm][2] - couple[nm][2]) for nm in REGIONS) <= 2.0 * moment / 5.0 * 1.01


def test_seat_moments_with_the_compiled_payload_and_ropes_equal_the_python_path():
    """The seats are evaluated in Python beside the compiled payload and ropes
    (point_effects.CompiledPointEffects.uncompiled): the right-hand side equals the one with
    every point effect in Python, to round-off, and the seats act (their moments are not 0)."""
    p = TelescopicParams(n_nodes=3, moment_model="seat", friction=True)
    ts = build_telescopic(p)
    m = ts.model
    z, _ = initial_equilibrium(ts)
    y = np.concatenate([z, 1e-3 * np.ones_like(z)])
    assert m._compiled_point_effects() is not None
    fast = m.rhs(0.2, y)
    m.point_effects_compiled = False
    try:
        ref = m.rhs(0.2, y)
    finally:
        m.point_effects_compiled = True
    np.testing.assert_allclose(fast, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
    Q, _ = m.full_state(0.2, z, 0 * z)
    assert max(np.abs(seat.multipliers(Q)).max() for seat in ts.seats.values()) > 1.0
