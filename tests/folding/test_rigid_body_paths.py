"""The fast paths of the rigid-body frames and terms against their references
(sim_core.physics.rigid_body, sim_core.systems.folding.build).

* planar body and turntable frames: the compiled loop (sim_core.physics._rigid_body_numba) and
  the numpy closed form against the Rodrigues rotation of the module docstring
  (r = S(phi) B0 [(u, v, 0) + Rz(theta) p], R = S(phi) B0 Rz(theta)), real and complex-step
  states; the same arithmetic up to rounding: 1e-13 relative;
* beam section frames: the compiled point kernel against the element's numpy evaluate (the same
  formulas, differently ordered sums): 1e-12 relative;
* the frames' ``coords`` (the keys of their evaluation caches and the columns the structured
  Jacobian differences): a frame evaluated at a state whose other coordinates are random equals
  the frame at the original state (fresh systems, so no cache is shared);
* the accelerations with the saddle-point blocks equal those of the whole-matrix LU, and the
  structured state Jacobian equals central differences of the right-hand side.
Runtime ~15 s (two coarse systems, 4 sub-elements per boom).
"""

import numpy as np
import pytest

from sim_core.model.state_jacobian import state_jacobian
from sim_core.physics import rigid_body
from sim_core.physics.rigid_body import beam_frame, rot_axis
from sim_core.systems.folding.build import (
    PLANE_BASIS,
    SLEW_AXIS,
    FoldingParams,
    build_folding,
)

H = 1e-20
PLANAR = ["turntable", "A_turntable", "base1_turntable", "barrel1", "rod1", "barrel2", "rod2",
          "link_a", "E_link_a", "link_b", "G_link_b"]
BEAM = ["boom1_foot", "boom1_tip", "boom2_foot", "boom2_tip", "P1_boom", "C_boom", "F_boom",
        "G_boom"]


def _reference_planar(Q, i_phi, iu, iv, it, p):
    """The frame of the module docstring by the Rodrigues rotation (rot_axis) and Rz(theta)."""
    S = rot_axis(SLEW_AXIS, Q[i_phi]) @ PLANE_BASIS
    th = Q[it] if it is not None else 0.0 * Q[i_phi]
    c, s = np.cos(th), np.sin(th)
    Rz = np.array([[c, -s, 0 * c], [s, c, 0 * c], [0 * c, 0 * c, 1 + 0 * c]])
    dRz = np.array([[-s, -c, 0 * c], [c, -s, 0 * c], [0 * c, 0 * c, 0 * c]])
    u = Q[iu] if iu is not None else 0.0 * Q[i_phi]
    v = Q[iv] if iv is not None else 0.0 * Q[i_phi]
    r = S @ (np.array([u, v, 0 * u]) + Rz @ p)
    J = np.zeros((3, len(Q)), dtype=np.result_type(Q, float))
    W = np.zeros_like(J)
    if iu is not None:
        J[:, iu], J[:, iv], J[:, it] = S[:, 0], S[:, 1], S @ (dRz @ p)
        W[:, it] = S[:, 2]
    J[:, i_phi] = np.cross(SLEW_AXIS, r)
    W[:, i_phi] = SLEW_AXIS
    return r, J, S @ Rz, W


def _layout(fs, name):
    """(iu, iv, itheta, body point p) of a named planar frame (None for the turntable)."""
    pts = {"A_turntable": None, "base1_turntable": None, "turntable": None}
    if name in pts:
        return None, None, None
    body = name.split("_", 1)[1] if name.startswith(("E_", "G_")) else name
    iu = fs.bodies[body]
    it = fs.bodies[body.replace("rod", "barrel")] + 2
    return iu, iu + 1, it


@pytest.fixture(scope="module")
def systems():
    """Two independent coarse systems (no shared evaluation caches) and a moving state."""
    p = FoldingParams(n_nodes=5)
    fs, fs2 = build_folding(p), build_folding(p)
    rng = np.random.default_rng(11)
    Q = fs.Q0 + 1e-3 * rng.standard_normal(fs.Q0.shape)
    for b, off in zip(fs.model.beams, fs.model.offsets):
        Q[off + b.s_coord(0)] = 0.0
        Q[off + b.s_coord(len(b.elements))] = b.length
    Q[fs.i_phi] = -0.7
    Qd = rng.standard_normal(Q.shape)
    return fs, fs2, Q, Qd


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("name", PLANAR)
def test_planar_frames_equal_rotation_formula(systems, monkeypatch, name, compiled):
    """A new frame of the named point (its own cache), by the compiled loop or the numpy code,
    against the Rodrigues reference, real and complex-step."""
    monkeypatch.setattr(rigid_body, "COMPILED_PLANAR_FRAMES", compiled)
    fs, _, Q, Qd = systems
    N = len(Q)
    iu, iv, it = _layout(fs, name)
    prm = fs.params
    p = np.array({"A_turntable": (*prm.hinge_A, 0.0), "base1_turntable": (*prm.cyl1_base, 0.0),
                  "E_link_a": (prm.link_a_length, 0.0, 0.0),
                  "G_link_b": (prm.link_b_length, 0.0, 0.0)}.get(name, (0.0, 0.0, 0.0)), float)
    if iu is None:
        f = rigid_body.turntable_frame(N, fs.i_phi, SLEW_AXIS, PLANE_BASIS, p)
    else:
        f = rigid_body.planar_body_frame(N, fs.i_phi, iu, SLEW_AXIS, PLANE_BASIS, p, i_theta=it)
    for state in (Q + 1j * H * Qd, Q):
        got = f(state)
        ref = _reference_planar(state, fs.i_phi, iu, iv, it, p)
        for a, b in zip(got, ref):
            assert a.dtype == b.dtype
            assert np.allclose(a, b, rtol=0, atol=1e-13 * max(1.0, np.abs(b).max()))
        if np.iscomplexobj(state):      # the complex step carries the directional derivative
            assert np.allclose(got[0].imag, H * (ref[1].real @ Qd), rtol=1e-12, atol=1e-32)
    # the scene's frame of the same point is the same function of Q
    for a, b in zip(fs.frames[name](Q), f(Q)):
        assert np.allclose(a, b, rtol=0, atol=1e-14 * max(1.0, np.abs(b).max()))


@pytest.mark.parametrize("name", BEAM)
def test_beam_frames_compiled_equal_numpy(systems, monkeypatch, name):
    fs, _, Q, Qd = systems
    f = fs.frames[name]
    for state in (Q + 1j * H * Qd, Q):
        fast = f(state)
        monkeypatch.setattr(rigid_body, "COMPILED_BEAM_FRAMES", False)
        # a fresh frame of the same point (its own cache), evaluated by the numpy reference
        ref = _same_beam_frame(fs, name)(state)
        monkeypatch.setattr(rigid_body, "COMPILED_BEAM_FRAMES", True)
        for a, b in zip(fast, ref):
            assert np.allclose(a, b, rtol=0, atol=1e-12 * max(1.0, np.abs(b).max())), name


def _same_beam_frame(fs, name):
    """A new frame function of the named boom point (the construction of build_folding)."""
    p, m = fs.params, fs.model
    L = p.boom_length
    from sim_core.systems.folding.build import linkage_points
    pts = linkage_points(p, 0.0, np.pi)
    spec = {"boom1_foot": (0, 0.0, None), "boom1_tip": (0, L, None),
            "boom2_foot": (1, 0.0, None), "boom2_tip": (1, L, None),
            "P1_boom": (0, p.cyl1_pin[0], p.cyl1_pin[1] * pts["n1"]),
            "C_boom": (0, L + p.cyl2_base[0], p.cyl2_base[1] * pts["n1"]),
            "F_boom": (0, L + p.link_a_base[0], p.link_a_base[1] * pts["n1"]),
            "G_boom": (1, p.link_b_end[0], p.link_b_end[1] * pts["n2"])}
    ib, s, off = spec[name]
    if off is None:
        return beam_frame(m, ib, s)
    R0 = beam_frame(m, ib, s)(fs.Q0)[2]
    return beam_frame(m, ib, s, PLANE_BASIS[:, :2] @ off, R0)


@pytest.mark.parametrize("name", PLANAR + BEAM)
def test_frame_coords_are_its_dependencies(systems, name):
    """A frame at a state whose coordinates outside ``coords`` are random equals the frame at
    the original state to round-off (evaluated on the second system: no cache in common); the
    columns of J and W outside ``coords`` are zero."""
    fs, fs2, Q, _ = systems
    f, f2 = fs.frames[name], fs2.frames[name]
    cols = f.coords(Q)
    other = np.setdiff1d(np.arange(len(Q)), cols)
    r, J, R, W = f(Q)
    assert not np.any(J[:, other]) and not np.any(W[:, other])
    Q2 = Q.copy()
    Q2[other] += 1e-2 * np.random.default_rng(5).standard_normal(len(other))
    # keep the material ends (the element of a beam point is located by them)
    for b, off in zip(fs.model.beams, fs.model.offsets):
        Q2[off + b.s_coord(0)] = Q[off + b.s_coord(0)]
        Q2[off + b.s_coord(len(b.elements))] = Q[off + b.s_coord(len(b.elements))]
    for a, b in zip(f2(Q2), (r, J, R, W)):       # (r, J, R, W) may be a complex one's real part
        assert np.allclose(a, b, rtol=0, atol=1e-14 * max(1.0, np.abs(b).max())), name


def test_frame_cache_real_from_complex(systems):
    """The real evaluation after a complex-step one is its real part: equal to a fresh real
    evaluation (second system) to round-off."""
    fs, fs2, Q, Qd = systems
    for name in PLANAR + BEAM:
        fs.frames[name](Q + 1j * H * Qd)
        served = fs.frames[name](Q + 0.0)
        fresh = fs2.frames[name](Q + 0.0)
        for a, b in zip(served, fresh):
            assert a.dtype == np.float64
            assert np.allclose(a, b, rtol=0, atol=1e-14 * max(1.0, np.abs(b).max())), name


def test_block_elimination_equals_whole_matrix(systems):
    """The accelerations and multipliers with the saddle-point blocks (the booms' coordinates;
    the rigid bodies' in the border) equal those of the whole-matrix LU: the same linear system,
    solved to round-off times its condition (~1e-9 relative measured at the paper's mesh)."""
    fs, _, Q, Qd = systems
    m = fs.model
    z, zd = m.reduced_state(16.0, Q, Qd)
    zdd, lam = m.accelerations_and_multipliers(16.0, z, zd)
    m.kkt_blocks = False
    try:
        zdd0, lam0 = m.accelerations_and_multipliers(16.0, z, zd)
    finally:
        m.kkt_blocks = True
    assert np.allclose(zdd, zdd0, rtol=0, atol=1e-8 * np.abs(zdd0).max())
    assert np.allclose(lam, lam0, rtol=0, atol=1e-8 * np.abs(lam0).max())


def test_structured_jacobian_equals_differences(systems):
    """The structured state Jacobian (local differences of the frames' coordinates only) equals
    central differences of the whole right-hand side: forward-difference truncation
    ~sqrt(eps) ~ 1.5e-8 relative per piece, amplified by the saddle-point solve; allow 1e-5 of
    the largest entry of each block row."""
    fs, _, Q, Qd = systems
    m = fs.model
    n = m.n_dof
    t = 16.0
    z, zd = m.reduced_state(t, Q, 0.1 * Qd)
    y = np.concatenate([z, zd])
    jac = state_jacobian(m, t, y)
    ref = np.zeros_like(jac)
    for j in range(2 * n):
        h = 1e-6 * max(1.0, abs(y[j]))
        yp, ym = y.copy(), y.copy()
        yp[j] += h
        ym[j] -= h
        ref[:, j] = (m.rhs(t, yp) - m.rhs(t, ym)) / (2 * h)
    for rows in (slice(0, n), slice(n, 2 * n)):
        for cols in (slice(0, n), slice(n, 2 * n)):
            scale = max(np.abs(ref[rows, cols]).max(), 1e-12)
            assert np.abs(jac[rows, cols] - ref[rows, cols]).max() <= 1e-5 * scale
