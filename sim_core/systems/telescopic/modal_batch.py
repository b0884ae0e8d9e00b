"""Batched stroke-parametric modal ROM of the telescopic crane with the payload swinging on its
hoist rope: N independent cranes stepped together by array operations.  SI units throughout.

The kernel of :class:`sim_core.vector_rom.VectorROM`.  It holds every crane's state as arrays
(stroke L_s (N,), stroke rate v (N,), modal coordinates q, q' (N, n_c)) and advances all of them
over one control interval of piecewise-constant commanded stroke acceleration in one call:
velocity saturation, inelastic end stops and the exact modal step of
:class:`sim_core.systems.telescopic.modal.ModalROM`, vectorised over the cranes.  Each crane has
its own payload, luffing angle and hoist-rope length: its coefficient tables are formed once per
configuration (:func:`coupled_tables`, at reset) and interpolated linearly in L_s at every step.

Lumped tables
-------------
The shipped modal tables (``modal.build_config``) are built from the full model with the payload
a point mass fixed at boom N's tip (``params.TelescopicParams.payload_swing = False``,
``build.build_telescopic``: ``PointMass`` at the tip): the payload's inertia moves with the tip in
every direction.  :func:`lumped_coefficients` interpolates them bilinearly in (angle, payload)
for all cranes at once, to round-off the arithmetic of ``modal.tables_for``.

Payload sway (``payload_swing``)
--------------------------------
A payload of mass m (payload and hook) on a hoist rope of length l below the tip is a spherical
pendulum whose suspension point is the moving tip.  Its rope is stiff along its length (EA / l =
4e7 N/m for the 2e8 N rope of the crane scenes at 5 m: 6.3 Hz with 25 t, above the bending modes
that matter), so vertically the payload moves with the tip, as in the lumped tables; horizontally
it is held only by the rope's inclination.  Let x_t be the tip's X coordinate (in the luffing
plane; Z up), theta the in-plane sway angle (rope from the vertical, positive towards +X) and psi
the out-of-plane one.  Small angles: the payload is at (x_t + l theta, y_t + l psi, z_t - l).
Its kinetic and potential energy minus that of a payload fixed at the tip is

    T - T_lumped = m x_t' l theta' + m l^2 theta'^2 / 2 + (out of plane: m l^2 psi'^2 / 2)
    V - V_lumped = m g l (theta^2 + psi^2) / 2

(the lumped energies keep the payload's vertical motion with the tip and its horizontal motion
up to the rope's inclination; the lateral tip is rigid: the tables hold no lateral modes).  With
the tip X coordinate of the ROM, x_t = r_s,x(L_s) + phi_x . q (``modal`` module docstring),
x_t' = s v + phi_x . q', s = d r_s,x / dL_s, Lagrange's equations in (q, theta) are

    q'' + m l phi_x theta'' + 2 zeta omega q' + omega^2 q = -Gamma a - (Gamma2 - b2) v^2 + b1 v
    m l phi_x . q'' + m l^2 theta'' + m g l theta       = -m l (s a + s' v^2)
    m l^2 psi'' + m g l psi = 0

i.e. the lumped modal equations plus a pendulum DOF whose inertia couples to the modes through
the tip's horizontal motion: M_c = [[I, m l phi_x], [m l phi_x^T, m l^2]] (positive definite:
m |phi_x|^2 < 1, the payload's share of the modes' horizontal inertia), K_c = diag(omega^2,
m g l), D_c = diag(2 zeta omega, 0).  The second equation is the pendulum of a moving support,
l theta'' + g theta = -x_t'' (the payload's horizontal acceleration is -g theta); the rope's
horizontal pull m g theta on the tip enters the first as the difference between it and the
inertia force -m x_t'' of the lumped payload, m (g theta + x_t'') = -m l theta''.  A short rope
(l -> 0: theta = -x_t'' / g) gives the lumped equations back.  The lumped modes act as Ritz
vectors of the hanging system: at 25 t, 60 deg, L_s = 5 m, l = 5 m the three-boom coupled
frequencies are 0.2156, 1.246, 5.97 Hz against 0.2155, 1.227, 5.65 Hz of the full model's
linearisation with ``payload_swing`` (tests/env/test_v1_sway.py).  Without the pendulum the
lumped first mode is at 0.712 Hz: the payload's horizontal inertia, ~95 % of the modes'
(m |phi_x|^2 = 0.95 there), leaves the bending modes when the payload hangs.

Small angles: the pendulum's frequency error at amplitude theta_0 is theta_0^2 / 16 (Landau-
Lifshitz Sec. 25) and the rope tension's deviation from m g is m g theta_0^2 / 2; the
environments truncate an episode beyond ``SWAY_LIMIT`` = 0.3 rad (0.56 % and 4.5 % there),
while stroke motions within the actuator limits sway the payload by a few degrees (quasi-static
tilt x_t'' / g <= 0.036 rad for three booms at a_max = 0.25 m/s^2, 45 deg).

Exact steps of the coupled system: at every point of a grid refined ``refine`` times over the
tables' L_s grid the coupled system is diagonalised (M_c-orthonormal eigenvectors Phi, signs
kept continuous along L_s), and the coupled modal quantities omega_c, Gamma_c = Phi^T (Gamma,
m l s), (Gamma2 - b2)_c = Phi^T (Gamma2 - b2, m l s'), b1_c = Phi^T (b1, 0), the tip maps
phi_x,c = Phi_q^T phi_x, phi_z,c and the sway map phi_theta,c = Phi_theta are tabulated, with the
modal damping zeta_c = (Phi^T D_c Phi)_jj / (2 omega_c) (off-diagonal terms neglected, as in
the lumped tables).  The equations then have the lumped form q_c'' + 2 zeta_c omega_c q_c' +
omega_c^2 q_c = -Gamma_c a - (Gamma2 - b2)_c v^2 + b1_c v, stepped exactly like ModalROM.  The
refinement makes the linear interpolation of the coupled quantities converge to the coupled
system of the linearly interpolated lumped coefficients where the pendulum and a bending mode
come close (five booms with long ropes; tests/env/test_v1_sway.py checks it).  psi is its own
undamped mode, omega = sqrt(g / l), excited only by a start sway.

Stroke kinematics
-----------------
The commanded acceleration a is held over the interval dt; the stroke rate saturates at
|v| = v_max (the acceleration is cut to 0 there) and the end stops L_min <= L_s <= L_max are
inelastic (v -> 0 on contact); each piece of constant acceleration is a segment stepped exactly,
a velocity jump dv at an end stop gives the modal velocities the jump dq_c' = -Gamma_c dv of
q_c'' = -Gamma_c a.  The same rules as boom_env's v0 environment, vectorised.

Stroke friction (``friction``)
------------------------------
The stages slide on their sliders with Coulomb friction (Zhao-Qi-Wang 2024 Section 8, Eq. 65:
static mu_s = 0.15, kinetic mu_k = 0.1 of the paper's Section 9.2 and the scene defaults).  With
the synchronized drive every overlap slides at the stroke rate, so the friction's virtual power
is -mu sum_r N_r |L_s'| and the force on the stroke coordinate is mu N, N = sum_r N_r the
sliders' total normal load: the transverse contact resultants |(f_t, f_b)| of the full model's
static equilibria (its default ``contact.friction_load = "resultant"``), tabulated over (angle,
payload, L_s) by :mod:`sim_core.systems.telescopic.friction_table` (329-875 kN for three booms
at 25 t, 60 deg).  Stick-slip needs a compliance between the commanded motion and the stages:
the telescopic cylinder's oil column.  The commanded acceleration moves the piston x_c (the
stroke kinematics above: rate limit of the pump flow, end stops of the piston); the stages
(stroke L_s, lag e = L_s - x_c) are driven through the oil column of stiffness
k_h = beta A / (L_s + l_0) (bulk modulus beta = 1e9 Pa with hoses, piston area A = 0.02 m^2,
dead length l_0 = 0.5 m: 8e6 N/m at L_s = 2 m, 2.4e6 N/m at 8 m; Merritt, Hydraulic Control
Systems, Sec. 5.2) and damping c_h = 2 zeta_h sqrt(k_h M_s) (zeta_h = 0.2: valve and leakage
losses), with M_s = sum_k k^2 m_k + (N - 1)^2 m_p the stages' and payload's rigid-body mass on
the stroke (boom k moves k L_s; ``friction_table.stroke_mass``: 114.6 t for three booms at
25 t, a stroke mode of 1.3 Hz at L_s = 2 m, 0.7 Hz at 8 m).  All forces are deviations from the
static equilibrium at rest (where the cylinder holds the weight and friction carries nothing):

    stick (L_s' = 0):  while |F_h| <= mu_s N,  F_h = k_h (x_c - L_s) + c_h x_c'
    slip:              M_s e'' + c_h e' + k_h e = -M_s x_c'' - mu_k N sign(L_s')

A held stage breaks away when |F_h| reaches mu_s N (F_h is quadratic in time within a segment of
constant x_c'': exact root) and moves towards F_h; a slipping stage sticks when L_s' returns to
zero with |F_h| <= mu_s N, else it slips on the other way.  Between these events the lag is the
exact damped oscillation of the slip equation with constant forcing (k_h, c_h, N frozen at the
piece's start), its stop found by bracketing and bisection of L_s'(t) = 0.  The modes are driven
by the stages' motion: q_c'' + ... = -Gamma_c L_s'' - (Gamma2 - b2)_c L_s'^2 + b1_c L_s', with
L_s'' = x_c'' + e''(t) exactly (the transient e'' = Re(B lam^2 e^(lam t)) has an exact
exponential particular solution in every mode) and the small convective terms with L_s' taken
along its chord over the piece.  Left out: the modes' inertia reaction on the stroke
(Gamma^T q'', one-way coupling: the stroke drives the modes), the friction's own modal load
(the sliders' friction forces act inside the booms), the variation of the normal load with the
dynamic contact forces (it is the static one), and the regularisation of the full model's
friction law (v_eps: this is the law's sticking limit; ``law = "regularised"`` below keeps it).

Regularised stroke friction (``law = "regularised"``)
------------------------------------------------------
The full model's own law instead of Coulomb stick (sim_core.physics.contact.
sliding_block_contact.FrictionLaw, paper Eq. 65 regularised with the switching speed v_eps):
mu(v) = mu_s v / v_eps for |v| <= v_eps, a cubic blend to mu_k up to 2 v_eps, mu_k sign(v)
beyond.  Below v_eps the law is a damper mu_s N / v_eps, so a stage whose column force stays
below breakaway creeps after the piston (overdamped, time constant (mu_s N / v_eps) / k_h:
0.6-5 s over the stroke for three booms at 25 t, 60 deg) instead of standing still.  The lag
obeys

    M_s e'' = -M_s x_c'' - k_h e - c_h e' - N mu(x_c' + e')

integrated by the trapezoidal rule in steps of at most CREEP_STEP within every piece of
constant piston acceleration, k_h, c_h and N frozen at each step's start.  The step's implicit
equation for e' is R(x) = g x + r0 + N mu(x_c'(t + h) + x) / 2 = 0 with g = M_s / h + k_h h / 4
+ c_h / 2; |mu| <= mu_s brackets a root, found by Newton within the bracket (bisection where
a Newton step leaves it).  At the scene's coefficients g exceeds N max|mu'| / 2 (the falling
branch, 1.5 (mu_s - mu_k) N / v_eps) for h <= 5 ms, so R increases and the root is unique.  The
modes are driven by the stage's mean acceleration over each step (ModalROM.advance's exact
step).  Trapezoidal, with the law's kink at v_eps: between first and second order in the step
(tests/env/test_v1_friction.py).  ``stuck`` then means |L_s'| < v_eps, the full model's stick
band.
"""

from __future__ import annotations

import numpy as np

from sim_core.systems.telescopic import _modal_batch_numba as compiled
from sim_core.systems.telescopic.modal import COLS, load_raw

GRAVITY = 9.81                   # m/s^2, the tables' build (params.TelescopicParams.gravity)
# the telescopic cylinder's hydraulics (module docstring, Stroke friction)
CYLINDER_AREA = 0.02             # m^2, piston area (bore 160 mm)
BULK_MODULUS = 1.0e9             # Pa, effective oil bulk modulus (oil with hoses)
DEAD_LENGTH = 0.5                # m, oil column at L_s = 0 (dead volume / area)
HYDRAULIC_DAMPING = 0.2          # damping ratio of the stroke mode
V_EPS = 0.01                     # m/s, the full model's stick band (scene default contact.v_eps)
CREEP_STEP = 0.005               # s, the regularised law's trapezoidal step (module docstring)
SWAY_LIMIT = 0.3                 # rad, small-angle range (module docstring)
ROPE_RANGE = (1.0, 10.0)         # m, hoist-rope lengths accepted (tests/env/test_v1_sway.py)
REFINE = 4                       # refinement of the L_s grid for the coupled tables
# rows of the coupled tables: the step needs the first five, the outputs the last four
DYN_ROWS = ("omega", "zeta", "gamma", "k2", "b1")
OUT_ROWS = ("phi_x", "phi_z", "phi_sway", "phi_sway_out")
_I = {k: i for i, k in enumerate(COLS)}
_STACKED = {}                     # lumped_coefficients: stacked rows of a tables file


def _lerp_index(grid: np.ndarray, x: np.ndarray):
    """Interval index and weight of x on ``grid`` (arrays), clipped, as ``modal.tables_for``."""
    if len(grid) == 1:
        return np.zeros(x.shape, int), np.zeros(x.shape)
    i = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, len(grid) - 2)
    w = np.clip((x - grid[i]) / (grid[i + 1] - grid[i]), 0.0, 1.0)
    return i, w


def _stacked(r: dict, n_modes: int) -> np.ndarray:
    """The rows ``COLS`` (first n_modes modes) and tip_dL of the tables r side by side along
    the last axis (nA, nP, nL, 8 n_modes + 3), cached."""
    key = (id(r), n_modes)
    held = _STACKED.get(key)
    if held is None or held[0] is not r:
        held = _STACKED[key] = (r, np.ascontiguousarray(np.concatenate(
            [r[k][..., :n_modes] for k in COLS] + [r["tip_dL"]], axis=-1)))
    return held[1]


def lumped_coefficients(payloads, angles_deg, n_modes: int, n_booms: int = 3, path=None):
    """Bilinear interpolation in (angle, payload) of the shipped lumped-payload tables for every
    crane at once.  ``payloads`` kg, ``angles_deg`` deg: arrays (N,).

    Returns (L_grid (nL,) m, coef (N, nL, 8, n_modes) rows ``modal.COLS``, tip_dL (N, nL, 3)
    m/m, with its lateral part zeroed as ``tables_for`` does).  The arithmetic is that of
    ``modal.tables_for`` for the modal rows (same results to the last bit) and for tip_dL at
    the tabulated angles; between them ``tables_for`` turns tip_dL (about 2 e_s, a vector that
    turns with the boom) in the boom's frame, while here its global components are
    interpolated, which shortens it by at most 1 - cos(7.5 deg) = 0.86 % (the 15-degree grid's
    half interval): the pendulum's forcing by the tip's horizontal velocity s v is that much
    weaker between the grid angles.  Ranges are not checked here (the caller checks them:
    :class:`sim_core.vector_rom.VectorROM`)."""
    r = load_raw(path, n_booms)
    P, A = r["payloads"], r["angles"]
    payloads = np.asarray(payloads, float).reshape(-1)
    angles_deg = np.asarray(angles_deg, float).reshape(-1)
    ia, wa = _lerp_index(A, angles_deg)
    ip, wp = _lerp_index(P, payloads)
    # all rows and tip_dL side by side along the last axis: one interpolation for all of them
    # (elementwise the same arithmetic as one per row)
    x = _stacked(r, n_modes)
    ja = np.minimum(ia + 1, x.shape[0] - 1)
    jp = np.minimum(ip + 1, x.shape[1] - 1)
    a1, p1 = wa[:, None, None], wp[:, None, None]
    y = ((1 - a1) * ((1 - p1) * x[ia, ip] + p1 * x[ia, jp])
         + a1 * ((1 - p1) * x[ja, ip] + p1 * x[ja, jp]))
    nm = len(COLS) * n_modes
    coef = np.ascontiguousarray(y[..., :nm]).reshape(y.shape[:2] + (len(COLS), n_modes))
    tip_dL = y[..., nm:].copy()
    tip_dL[..., 1] = 0.0
    return r["L_grid"].astype(float), coef, tip_dL


def refine_grid(L: np.ndarray, values: np.ndarray, refine: int):
    """Grid refined ``refine`` times (uniformly inside every interval) and ``values`` (axis 1
    along L) interpolated linearly onto it: the same piecewise-linear function of L_s."""
    if refine == 1:
        return L, values
    k = np.arange(refine) / refine
    Lr = np.concatenate([(L[:-1, None] + k[None] * np.diff(L)[:, None]).ravel(), L[-1:]])
    w = np.concatenate([np.tile(k, len(L) - 1), [1.0]])
    i = np.concatenate([np.repeat(np.arange(len(L) - 1), refine), [len(L) - 2]])
    sh = (1, -1) + (1,) * (values.ndim - 2)
    w = w.reshape(sh)
    return Lr, (1 - w) * values[:, i] + w * values[:, i + 1]


def lumped_tables(coef: np.ndarray):
    """Tables of the cranes without sway: the lumped coefficients in the rows ``DYN_ROWS`` +
    ``OUT_ROWS`` (no sway maps).  Returns (dyn (N, nL, 5, n), out (N, nL, 4, n))."""
    c = coef
    dyn = np.stack([c[:, :, _I["omega"]], c[:, :, _I["zeta"]], c[:, :, _I["gamma"]],
                    c[:, :, _I["gamma2"]] - c[:, :, _I["b2"]], c[:, :, _I["b1"]]], axis=2)
    zero = np.zeros_like(c[:, :, 0])
    out = np.stack([c[:, :, _I["phi_x"]], c[:, :, _I["phi_z"]], zero, zero], axis=2)
    return dyn, out


def coupled_tables(coef: np.ndarray, tip_dL: np.ndarray, L: np.ndarray, payloads, rope_lengths,
                   gravity: float = GRAVITY, refine: int = REFINE, use_compiled: bool = True):
    """Coupled modal tables of the cranes with the payload swinging (module docstring).

    ``coef`` (N, nL, 8, n), ``tip_dL`` (N, nL, 3) from :func:`lumped_coefficients` on grid ``L``;
    ``payloads`` kg (N,), ``rope_lengths`` m (N,).  Returns (L_r (nLr,), dyn (N, nLr, 5, n + 2),
    out (N, nLr, 4, n + 2)): n + 1 coupled in-plane modes, then the out-of-plane pendulum.
    ``use_compiled``: the compiled kernel where numba is available (the array code below is
    its reference)."""
    N, nL, _, n = coef.shape
    m = np.asarray(payloads, float).reshape(N, 1)
    ell = np.asarray(rope_lengths, float).reshape(N, 1)
    # s = d r_s,x / dL_s and its derivative (central differences of the exact tangents along
    # the table grid): the payload's share of the rigid stroke motion
    s = tip_dL[..., 0]
    ds = np.gradient(s, L, axis=1)
    both = np.concatenate([coef.reshape(N, nL, -1), s[..., None], ds[..., None]], axis=2)
    Lr, both = refine_grid(L, both, refine)
    nLr = len(Lr)
    c = np.ascontiguousarray(both[..., :-2].reshape(N, nLr, 8, n))
    s, ds = np.ascontiguousarray(both[..., -2]), np.ascontiguousarray(both[..., -1])
    if use_compiled and compiled.AVAILABLE:
        dyn = np.empty((N, nLr, len(DYN_ROWS), n + 2))
        out = np.empty((N, nLr, len(OUT_ROWS), n + 2))
        zmax = compiled.coupled_modes(c, s, ds, m[:, 0].copy(), ell[:, 0].copy(),
                                      float(gravity), dyn, out)
        if zmax >= 1.0:
            raise ValueError("coupled modal damping >= 1: the exact step needs underdamped "
                             "modes")
        return Lr, dyn, out
    om, ze = c[:, :, _I["omega"]], c[:, :, _I["zeta"]]
    phx = c[:, :, _I["phi_x"]]
    ml = (m * ell)[..., None]                       # (N, 1, 1)
    M = np.zeros((N, nLr, n + 1, n + 1))
    M[..., np.arange(n), np.arange(n)] = 1.0
    M[..., :n, n] = ml * phx
    M[..., n, :n] = ml * phx
    M[..., n, n] = (m * ell * ell)
    k_diag = np.concatenate([om * om, np.broadcast_to(m * gravity * ell, (N, nLr))[..., None]],
                            axis=2)
    # K Phi = M Phi Lambda: with M = C C^T, (C^-1 K C^-T) Y = Y Lambda, Phi = C^-T Y
    C = np.linalg.cholesky(M)
    Ci = np.linalg.inv(C)
    A = Ci * k_diag[..., None, :] @ np.swapaxes(Ci, -1, -2)
    A = 0.5 * (A + np.swapaxes(A, -1, -2))
    lam, Y = np.linalg.eigh(A)
    Phi = np.swapaxes(Ci, -1, -2) @ Y                 # (N, nLr, n + 1, n + 1), columns: modes
    # continuous signs along L_s: the M-projection on the neighbour's mode is positive
    for j in range(nLr):
        if j == 0:
            g0 = np.einsum("nij,ni->nj", Phi[:, 0, :n], c[:, 0, _I["gamma"]]) \
                + Phi[:, 0, n] * (m * ell * s[:, :1])
            sg = np.where(g0 < 0, -1.0, 1.0)
        else:
            sg = np.einsum("nij,nik,nkj->nj", Phi[:, j - 1], M[:, j], Phi[:, j])
            sg = np.where(sg < 0, -1.0, 1.0)
        Phi[:, j] *= sg[:, None, :]
    Pq, Pt = Phi[..., :n, :], Phi[..., n, :]
    omega_c = np.sqrt(np.maximum(lam, 0.0))
    d_diag = 2.0 * ze * om                           # lumped modal damping, pendulum undamped
    zeta_c = np.einsum("nlij,nli,nlij->nlj", Pq, d_diag, Pq) / (2.0 * omega_c)
    if np.any(zeta_c >= 1.0):
        raise ValueError("coupled modal damping >= 1: the exact step needs underdamped modes")
    cg = lambda row: np.einsum("nlij,nli->nlj", Pq, c[:, :, _I[row]])   # noqa: E731
    gamma_c = cg("gamma") + Pt * (m * ell * s)[..., None]
    k2_c = cg("gamma2") - cg("b2") + Pt * (m * ell * ds)[..., None]
    b1_c = cg("b1")
    phx_c, phz_c = cg("phi_x"), cg("phi_z")
    w_out = np.broadcast_to(np.sqrt(gravity / ell)[..., None], (N, nLr, 1))
    z1 = np.zeros((N, nLr, 1))

    def col(x, extra):
        return np.concatenate([x, extra], axis=2)
    dyn = np.stack([col(omega_c, w_out), col(zeta_c, z1), col(gamma_c, z1), col(k2_c, z1),
                    col(b1_c, z1)], axis=2)
    out = np.stack([col(phx_c, z1), col(phz_c, z1), col(Pt, z1), col(np.zeros_like(Pt),
                                                                      np.ones((N, nLr, 1)))],
                   axis=2)
    return Lr, dyn, out


_GRID_DATA = {}                   # refinement indices and gradient coefficients of a grid


def _grid_data(L: np.ndarray, refine: int):
    """(ri, rw, uniform, gdx, ga, gb, gc, L_r) of the grid L: refine_grid's interval index and
    weight of every refined point, numpy.gradient's spacing (uniform: one step; else its
    second-order interior coefficients and the edge steps) and the refined grid, cached."""
    key = (L.tobytes(), refine)
    if key not in _GRID_DATA:
        nL = len(L)
        if refine == 1:
            ri, rw = np.arange(nL), np.zeros(nL)
        else:
            k = np.arange(refine) / refine
            rw = np.concatenate([np.tile(k, nL - 1), [1.0]])
            ri = np.concatenate([np.repeat(np.arange(nL - 1), refine), [nL - 2]])
        dx = np.diff(L)
        uniform = bool((dx == dx[0]).all())
        dx1, dx2 = dx[0:-1], dx[1:]
        ga = -(dx2) / (dx1 * (dx1 + dx2))
        gb = (dx2 - dx1) / (dx1 * dx2)
        gc = dx1 / (dx2 * (dx1 + dx2))
        Lr = refine_grid(L, L[None, :], refine)[0]
        _GRID_DATA[key] = (ri.astype(np.int64), rw.astype(float), uniform,
                           np.array([dx[0], dx[-1]]), ga, gb, gc, Lr)
    return _GRID_DATA[key]


def coupled_tables_of(payloads, angles_deg, rope_lengths, n_modes: int, n_booms: int = 3,
                      gravity: float = GRAVITY, refine: int = REFINE):
    """lumped_coefficients and coupled_tables in one go (the tables of the cranes (payload kg,
    angle deg, rope m), arrays (k,)): (L_r, dyn, out).  Compiled where numba is available:
    one call forms the lumped coefficients, the tip slope's gradient and the refinement with
    the same arithmetic as the array functions (tests/env/test_v1_rom.py compares them), then
    coupled_modes; a few hundred microseconds less per call than the array path, which
    matters for the autoresets of a few cranes at a time."""
    m = np.ascontiguousarray(payloads, float).reshape(-1)
    ang = np.ascontiguousarray(angles_deg, float).reshape(-1)
    ell = np.ascontiguousarray(rope_lengths, float).reshape(-1)
    if not compiled.AVAILABLE:
        L, coef, tip_dL = lumped_coefficients(m, ang, n_modes, n_booms)
        return coupled_tables(coef, tip_dL, L, m, ell, gravity, refine, False)
    r = load_raw(None, n_booms)
    x = _stacked(r, n_modes)
    L = r["L_grid"].astype(float)
    ri, rw, uniform, gdx, ga, gb, gc, Lr = _grid_data(L, refine)
    k, nLr = m.size, len(ri)
    c = np.empty((k, nLr, len(COLS), n_modes))
    s = np.empty((k, nLr))
    ds = np.empty((k, nLr))
    compiled.lumped_refined(x, r["payloads"].astype(float), r["angles"].astype(float), m, ang,
                            n_modes, uniform, gdx, ga, gb, gc, ri, rw, c, s, ds)
    dyn = np.empty((k, nLr, len(DYN_ROWS), n_modes + 2))
    out = np.empty((k, nLr, len(OUT_ROWS), n_modes + 2))
    zmax = compiled.coupled_modes(c, s, ds, m, ell, float(gravity), dyn, out)
    if zmax >= 1.0:
        raise ValueError("coupled modal damping >= 1: the exact step needs underdamped modes")
    return Lr, dyn, out


def normal_loads_refined(payloads, angles_deg, n_booms: int = 3, refine: int = 1):
    """normal_loads refined by refine_grid: (L_r, N (k, nLr)); compiled where available."""
    from sim_core.systems.telescopic.friction_table import load
    if not compiled.AVAILABLE:
        Lf, nl = normal_loads(payloads, angles_deg, n_booms)
        return refine_grid(Lf, nl, refine)
    r = load(n_booms)
    m = np.ascontiguousarray(payloads, float).reshape(-1)
    ang = np.ascontiguousarray(angles_deg, float).reshape(-1)
    key = (id(r), "N_total")
    held = _STACKED.get(key)
    if held is None or held[0] is not r:
        held = _STACKED[key] = (r, np.ascontiguousarray(r["N_total"], float)[..., None])
    L = r["L_grid"].astype(float)
    ri, rw = _grid_data(L, refine)[:2]
    Lr = _grid_data(L, refine)[7]
    out = np.empty((m.size, len(ri)))
    compiled.normal_refined(held[1], r["payloads"].astype(float), r["angles"].astype(float), m,
                            ang, ri, rw, out)
    return Lr, out


def stroke_segments(L, v, a, dt, v_max, L_min, L_max):
    """The stroke kinematics of one interval for one crane (scalars; the rules of the kernel's
    loop, ``BatchROM.step``): returns (segments [(a_eff m/s^2, duration s, rate jump m/s at its
    end), ...], L_end m, v_end m/s), for a plant that follows them (the full model)."""
    import math
    t_left, segs = float(dt), []
    for _ in range(8):
        if t_left <= 1e-12:
            break
        ae = a
        if (v >= v_max - 1e-12 and a > 0) or (v <= -v_max + 1e-12 and a < 0):
            ae = 0.0
        if ((L >= L_max - 1e-12 and v >= 0) and ae > 0) or \
                ((L <= L_min + 1e-12 and v <= 0) and ae < 0):
            ae = 0.0
        t_v = math.inf
        if ae > 0:
            t_v = (v_max - v) / ae
        elif ae < 0:
            t_v = (-v_max - v) / ae
        t_s = min(compiled._first_hit(L, v, ae, L_max), compiled._first_hit(L, v, ae, L_min))
        tau = min(t_left, t_v, t_s)
        L1 = L + v * tau + 0.5 * ae * tau * tau
        v1 = v + ae * tau
        jump = 0.0
        if tau == t_s and tau < t_left + 1e-15:
            L1 = min(max(L1, L_min), L_max)
            jump, v1 = -v1, 0.0
        elif tau == t_v:
            v1 = math.copysign(v_max, v1)
        segs.append((ae, tau, jump))
        t_left -= tau
        L, v = L1, v1
    if t_left > 1e-12:
        segs.append((0.0, t_left, 0.0))
        L = L + v * t_left
    return segs, min(max(L, L_min), L_max), v


def _first_hit(L, v, a, stop):
    """Smallest t > 0 with L + v t + a t^2 / 2 = stop moving towards it (inf if never); arrays.
    The scalar rules of boom_env v0's ``_first_hit``, vectorised."""
    t = np.full(L.shape, np.inf)
    never = ((stop > L) & (v <= 0) & (a <= 0)) | ((stop < L) & (v >= 0) & (a >= 0)) | (stop == L)
    lin = ~never & (np.abs(a) < 1e-15)
    with np.errstate(divide="ignore", invalid="ignore"):
        tl = np.where(v != 0, (stop - L) / np.where(v != 0, v, 1.0), np.inf)
        t = np.where(lin & (tl > 0), tl, t)
        quad = ~never & ~lin
        disc = v * v + 2 * a * (stop - L)
        ok = quad & (disc >= 0)
        r = np.sqrt(np.where(ok, disc, 0.0))
        qq = -(v + np.copysign(r, v))
        a_safe = np.where(a != 0, a, 1.0)
        c1 = qq / a_safe
        c2 = np.where(qq != 0, 2.0 * (L - stop) / np.where(qq != 0, qq, 1.0), np.inf)
        c1 = np.where(c1 > 1e-15, c1, np.inf)
        c2 = np.where(c2 > 1e-15, c2, np.inf)
        t = np.where(ok, np.minimum(c1, c2), t)
    return t


def normal_loads(payloads, angles_deg, n_booms: int = 3):
    """(L_grid (nL,) m, N (k, nL) N): the sliders' total normal load of
    ``friction_table`` interpolated bilinearly in (angle, payload) for every crane."""
    from sim_core.systems.telescopic.friction_table import load
    r = load(n_booms)
    P, A = r["payloads"], r["angles"]
    payloads = np.asarray(payloads, float).reshape(-1)
    angles_deg = np.asarray(angles_deg, float).reshape(-1)
    ia, wa = _lerp_index(A, angles_deg)
    ip, wp = _lerp_index(P, payloads)
    x = r["N_total"]
    ja = np.minimum(ia + 1, x.shape[0] - 1)
    jp = np.minimum(ip + 1, x.shape[1] - 1)
    a1, p1 = wa[:, None], wp[:, None]
    N = ((1 - a1) * ((1 - p1) * x[ia, ip] + p1 * x[ia, jp])
         + a1 * ((1 - p1) * x[ja, ip] + p1 * x[ja, jp]))
    return r["L_grid"].astype(float), N


def stroke_masses(payloads, n_booms: int = 3):
    """Stroke mass M_s (kg) of every crane (``friction_table.stroke_mass``)."""
    from sim_core.systems.telescopic.friction_table import load, stroke_mass
    masses = load(n_booms)["boom_masses"]
    # stroke_mass(masses, 0) + (N - 1)^2 m for all payloads at once (the same arithmetic)
    rigid = np.float64(stroke_mass(masses, 0.0))
    return rigid + (len(masses) - 1) ** 2 * np.asarray(payloads, float).reshape(-1)


class BatchROM:
    """State and tables of N cranes; :meth:`step` advances all of them (module docstring).

    ``L`` m, ``v`` m/s (N,); ``q``, ``qd`` (N, n_c) modal coordinates and rates; ``dyn`` (N, nL,
    5, n_c), ``out`` (N, nL, 4, n_c) the per-crane tables on the grid ``grid`` (nL,) m."""

    def __init__(self, n_envs: int, grid: np.ndarray, n_c: int, dt: float, v_max: float,
                 L_min: float, L_max: float, use_compiled: bool = True, friction=None):
        self.compiled = bool(use_compiled and compiled.AVAILABLE)
        # stroke friction (module docstring): None, or dict of kA (N: bulk modulus times
        # piston area), l0 (m, dead oil length), zeta_h, mu_static, mu_dynamic; with
        # law = "regularised" also v_eps (m/s)
        self.friction = friction
        if friction is not None:
            self.e = np.zeros(n_envs)             # stage lag behind the piston, m
            self.ed = np.zeros(n_envs)            # its rate, m/s
            self.stuck = np.ones(n_envs, bool)
            self.sdir = np.ones(n_envs)
            self.Ms = np.ones(n_envs)             # stroke mass, kg
            self.ntab = np.zeros((n_envs, len(grid)))   # sliders' total normal load, N
            self.wf = np.zeros(n_envs)            # friction work, J
        self.n = int(n_envs)
        self.grid = np.ascontiguousarray(grid, float)
        self.nc = int(n_c)
        self.dt, self.v_max, self.L_min, self.L_max = float(dt), float(v_max), float(L_min), \
            float(L_max)
        nL = len(self.grid)
        # one block of rows per crane and grid point, the step's rows (dyn) then the outputs'
        # (out): a step reads a crane's tables at two neighbouring grid points, one contiguous
        # run of memory (the tables of 1024 cranes are ~15 MB, far beyond the caches)
        nd = len(DYN_ROWS)
        self.tab = np.zeros((self.n, nL, nd + len(OUT_ROWS), self.nc))
        self.dyn = self.tab[:, :, :nd]
        self.out = self.tab[:, :, nd:]
        self.L = np.full(self.n, self.L_min)
        self.v = np.zeros(self.n)
        self.q = np.zeros((self.n, self.nc))
        self.qd = np.zeros((self.n, self.nc))

    # -- tables --------------------------------------------------------------------------
    def _at(self, tab, ids, L):
        """Rows of ``tab`` (N, nL, r, n_c) at strokes L of the cranes ``ids``: the linear
        interpolation of ModalTables.coefficients (L clipped to the grid)."""
        g = self.grid
        Lc = np.clip(L, g[0], g[-1])
        i = np.minimum(np.searchsorted(g, Lc, side="right") - 1, len(g) - 2)
        w = ((Lc - g[i]) / (g[i + 1] - g[i]))[:, None, None]
        return (1 - w) * tab[ids, i] + w * tab[ids, i + 1]

    def _law(self) -> tuple[float, float]:
        """(v_eps m/s, step s) of the kernels' friction law: (0, 0) Coulomb stick and slip,
        (v_eps, CREEP_STEP) the full model's regularised law (module docstring)."""
        f = self.friction
        return (f["v_eps"], CREEP_STEP) if f.get("law") == "regularised" else (0.0, 0.0)

    # -- exact modal step ----------------------------------------------------------------
    def _advance(self, ids, a, tau):
        """ModalROM.advance for the cranes ``ids`` over tau (s) at acceleration a (m/s^2)."""
        L, v0 = self.L[ids], self.v[ids]
        c = self._at(self.dyn, ids, L + 0.5 * v0 * tau + 0.125 * a * tau * tau)
        w, z, g, k, b1 = c[:, 0], c[:, 1], c[:, 2], c[:, 3], c[:, 4]
        a_ = a[:, None]
        v_ = v0[:, None]
        t_ = tau[:, None]
        f0 = -g * a_ - k * v_ * v_ + b1 * v_
        f1 = -2.0 * k * v_ * a_ + b1 * a_
        f2 = -k * a_ * a_
        w2 = w * w
        sig = z * w
        Cc = f2 / w2
        B = (f1 - 4.0 * sig * Cc) / w2
        A = (f0 - 2.0 * sig * B - 2.0 * Cc) / w2
        x0 = self.q[ids] - A
        y0 = self.qd[ids] - B
        wd = w * np.sqrt(1.0 - z * z)
        e = np.exp(-sig * t_)
        ph = wd * t_
        cs, sn = np.cos(ph), np.sin(ph)
        x = e * (x0 * cs + (y0 + sig * x0) / wd * sn)
        y = e * (y0 * cs - (w2 * x0 + sig * y0) / wd * sn)
        self.q[ids] = x + A + B * t_ + Cc * t_ * t_
        self.qd[ids] = y + B + 2.0 * Cc * t_

    def step(self, a):
        """Advance every crane over dt at commanded acceleration a (N,) m/s^2 (finite).

        Returns (saturated (N,) bool, end_stop (N,) bool, mean applied acceleration (N,)
        m/s^2): the stroke kinematics of the module docstring, segment by segment."""
        n = self.n
        a = np.asarray(a, float)
        if self.friction is not None:
            f = self.friction
            sat = np.empty(n, bool)
            stop = np.empty(n, bool)
            acc = np.empty(n)
            compiled.step_all_friction(self.L, self.v, self.e, self.ed, self.stuck, self.sdir,
                                       self.q, self.qd, a, self.dyn, self.ntab, self.grid,
                                       self.dt, self.v_max, self.L_min, self.L_max, self.Ms,
                                       f["kA"], f["l0"], f["zeta_h"], f["mu_static"],
                                       f["mu_dynamic"], *self._law(), sat, stop, acc, self.wf)
            return sat, stop, acc
        if self.compiled:
            sat = np.empty(n, bool)
            stop = np.empty(n, bool)
            acc = np.empty(n)
            compiled.step_all(self.L, self.v, self.q, self.qd, a, self.dyn, self.grid, self.dt,
                              self.v_max, self.L_min, self.L_max, sat, stop, acc)
            return sat, stop, acc
        t_left = np.full(n, self.dt)
        sat = np.zeros(n, bool)
        stop = np.zeros(n, bool)
        dv_sum = np.zeros(n)
        ids = np.arange(n)
        vmax, Lmin, Lmax = self.v_max, self.L_min, self.L_max
        for _ in range(8):
            if ids.size == 0:
                break
            L, v, aa, tl = self.L[ids], self.v[ids], a[ids], t_left[ids]
            ae = aa.copy()
            s1 = ((v >= vmax - 1e-12) & (aa > 0)) | ((v <= -vmax + 1e-12) & (aa < 0))
            ae[s1] = 0.0
            s2 = (((L >= Lmax - 1e-12) & (v >= 0)) & (ae > 0)) | \
                (((L <= Lmin + 1e-12) & (v <= 0)) & (ae < 0))
            ae[s2] = 0.0
            sat[ids[s1]] = True
            stop[ids[s2]] = True
            with np.errstate(divide="ignore", invalid="ignore"):
                t_v = np.where(ae > 0, (vmax - v) / ae,
                               np.where(ae < 0, (-vmax - v) / ae, np.inf))
            t_s = np.minimum(_first_hit(L, v, ae, Lmax), _first_hit(L, v, ae, Lmin))
            tau = np.minimum(np.minimum(tl, t_v), t_s)
            moving = tau > 0
            if moving.all():
                self._advance(ids, ae, tau)
            elif moving.any():
                self._advance(ids[moving], ae[moving], tau[moving])
            L1 = L + v * tau + 0.5 * ae * tau * tau
            v1 = v + ae * tau
            hit = (tau == t_s) & (tau < tl + 1e-15)
            vs = ~hit & (tau == t_v)
            if hit.any():
                L1[hit] = np.clip(L1[hit], Lmin, Lmax)
                jump = -v1[hit]
                v1[hit] = 0.0
                stop[ids[hit]] = True
                hid = ids[hit]
                gam = self._at(self.dyn[:, :, 2:3], hid, L1[hit])[:, 0]
                self.qd[hid] -= gam * jump[:, None]
            if vs.any():
                v1[vs] = np.copysign(vmax, v1[vs])
                sat[ids[vs]] = True
            dv_sum[ids] += ae * tau
            t_left[ids] = tl - tau
            self.L[ids] = L1
            self.v[ids] = v1
            ids = ids[t_left[ids] > 1e-12]
        if ids.size:                                   # pathological: hold the remainder
            self._advance(ids, np.zeros(ids.size), t_left[ids])
            self.L[ids] += self.v[ids] * t_left[ids]
        np.clip(self.L, Lmin, Lmax, out=self.L)
        return sat, stop, dv_sum / self.dt

    def step_outputs(self, a):
        """:meth:`step` and then :meth:`outputs` of all cranes: (saturated, end_stop, accel,
        deflection, sway), the same values; compiled, one pass over the cranes."""
        if not self.compiled:
            sat, stop, acc = self.step(a)
            return (sat, stop, acc) + self.outputs()
        n = self.n
        a = np.asarray(a, float)
        sat = np.empty(n, bool)
        stop = np.empty(n, bool)
        acc = np.empty(n)
        defl = np.empty((n, 4))
        sway = np.empty((n, 4))
        if self.friction is not None:
            f = self.friction
            compiled.step_all_friction_out(
                self.L, self.v, self.e, self.ed, self.stuck, self.sdir, self.q, self.qd, a,
                self.dyn, self.ntab, self.grid, self.dt, self.v_max, self.L_min, self.L_max,
                self.Ms, f["kA"], f["l0"], f["zeta_h"], f["mu_static"], f["mu_dynamic"],
                *self._law(), sat, stop, acc, self.wf, self.out, defl, sway)
        else:
            compiled.step_all_out(self.L, self.v, self.q, self.qd, a, self.dyn, self.grid,
                                  self.dt, self.v_max, self.L_min, self.L_max, sat, stop, acc,
                                  self.out, defl, sway)
        return sat, stop, acc, defl, sway

    # -- outputs -------------------------------------------------------------------------
    def stage_stroke(self):
        """Stroke of the booms' stages (m): the piston's L plus the lag e with friction."""
        return self.L if self.friction is None else self.L + self.e

    def stage_rate(self):
        return self.v if self.friction is None else self.v + self.ed

    def outputs(self, ids=None):
        """(deflection (k, 4): dX, dZ m of the tip from the static tip and their rates m/s;
        sway (k, 4): in-plane, out-of-plane angle rad and their rates rad/s) of the cranes
        ``ids`` (default all)."""
        L = self.stage_stroke()
        if ids is None:
            if self.compiled:
                defl = np.empty((self.n, 4))
                sway = np.empty((self.n, 4))
                compiled.outputs_all(L, self.q, self.qd, self.out, self.grid, defl, sway)
                return defl, sway
            ids = np.arange(self.n)
        if self.compiled:
            ids = np.ascontiguousarray(ids, np.int64)
            defl = np.empty((ids.size, 4))
            sway = np.empty((ids.size, 4))
            compiled.outputs_sel(L, self.q, self.qd, self.out, self.grid, ids, defl, sway)
            return defl, sway
        c = self._at(self.out, ids, L[ids])
        q, qd = self.q[ids][:, None, :], self.qd[ids][:, None, :]
        pos = np.sum(c * q, axis=2)                   # (k, 4)
        rate = np.sum(c * qd, axis=2)
        return (np.stack([pos[:, 0], pos[:, 1], rate[:, 0], rate[:, 1]], axis=1),
                np.stack([pos[:, 2], pos[:, 3], rate[:, 2], rate[:, 3]], axis=1))
