"""Many telescopic cranes stepped together: the batched modal reduced-order model.

    from sim_core.vector_rom import VectorROM
    rom = VectorROM(1024, booms=3, payload_swing=True)
    rom.configure(payload=np.linspace(20e3, 30e3, 1024), luffing_angle_deg=60.0, rope_length=5.0)
    rom.reset(stroke=2.0)
    saturated, end_stop, accel = rom.step(a)        # a: (1024,) commanded accelerations, m/s^2
    rom.tip_deflection(), rom.sway()                 # (1024, 4) each

The physics is that of :mod:`sim_core.systems.telescopic.modal` (the stroke-parametric modal ROM
of the full model, its shipped tables) with, where ``payload_swing`` is on, the payload hanging
on its hoist rope as a pendulum coupled to the tip
(:mod:`sim_core.systems.telescopic.modal_batch`: the equations, their sources and their range).
Each crane has its own payload, luffing angle and rope length; one call steps all of them (the
stroke kinematics with velocity saturation and end stops, the exact modal step), and N = 1 is
the same code.  SI units.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.systems.telescopic.modal import TABLE_BOOMS, allowed_ranges
from sim_core.systems.telescopic.modal_batch import (
    BULK_MODULUS,
    CYLINDER_AREA,
    DEAD_LENGTH,
    GRAVITY,
    HYDRAULIC_DAMPING,
    REFINE,
    ROPE_RANGE,
    SWAY_LIMIT,
    V_EPS,
    BatchROM,
    coupled_tables,
    coupled_tables_of,
    lumped_coefficients,
    lumped_tables,
    normal_loads,
    normal_loads_refined,
    refine_grid,
    stroke_masses,
    stroke_segments,
)

#: the stroke friction's laws (VectorROM friction_law): Coulomb stick and slip, or the full
#: model's regularised law
FRICTION_LAWS = ("coulomb", "regularised")

__all__ = ["VectorROM", "FRICTION_LAWS", "ROPE_RANGE", "SWAY_LIMIT", "TABLE_BOOMS",
           "allowed_ranges", "luffing_frame", "stroke_segments"]


def luffing_frame(luffing_angle_deg: float):
    """(origin (2,), e_s (2,)): boom 1's left-section origin and the boom axis in the luffing
    plane (X, Z), m, of the rigid crane at the luffing angle (deg) (docs/model.md#input-luffing;
    ``sim_core.systems.telescopic.luffing.luffing_geometry``), for drawing."""
    from sim_core.systems.telescopic.luffing import luffing_geometry
    geo = luffing_geometry(math.radians(float(luffing_angle_deg)))
    return np.asarray(geo.origin)[[0, 2]], np.asarray(geo.e_s)[[0, 2]]


FRICTION_STATE = ("e", "ed", "stuck", "sdir", "Ms", "ntab", "wf")


def _finite_positive(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} = {value!r}: must be a number")
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} = {value!r}: must be finite and > 0")
    return float(value)


class VectorROM:
    """N independent cranes of the modal ROM (module docstring).

    ``n_envs``: number of cranes; ``booms``: 3 or 5 (the boom counts with shipped tables);
    ``n_modes``: lumped bending modes kept (1..4); ``payload_swing``: the payload hangs on its
    rope (n_modes + 1 coupled in-plane modes and the out-of-plane pendulum) or is fixed at the
    tip (the tables as they are); ``dt`` s: the control interval of :meth:`step`; ``v_max``
    m/s: stroke-rate limit; ``stroke_limits`` (L_min, L_max) m: end stops (default: the
    tables' stroke range); ``refine``: refinement of the L_s grid of the coupled tables;
    ``use_compiled``: the compiled kernels where numba is available (False: their array
    reference, the same results to round-off).

    ``friction``: stick-slip of the stages on their sliders behind the hydraulic cylinder
    (:mod:`sim_core.systems.telescopic.modal_batch`, Stroke friction): the commanded
    acceleration then moves the piston, which drives the stages through the oil column
    (stiffness bulk_modulus * cylinder_area / (L_s + dead_length) N/m, damping ratio
    hydraulic_damping of the stroke mode) against mu N, N the sliders' total normal load of the
    full model's static equilibria (``friction_table``); mu_static, mu_dynamic default to the
    scene defaults (0.15, 0.1).  ``friction_law``: ``"coulomb"`` (default) the stages stick
    until the column's force reaches mu_static N; ``"regularised"`` the full model's law (a
    damper mu_static N / v_eps below ``v_eps`` m/s, default the scene's 0.01, so held stages
    creep; modal_batch, Regularised stroke friction).

    State arrays (read them, or use :meth:`save_state`): ``stroke`` (N,) m, ``stroke_rate``
    (N,) m/s, ``q``, ``qd`` (N, n_c) modal coordinates."""

    def __init__(self, n_envs: int, booms: int = 3, n_modes: int = 3, payload_swing: bool = True,
                 dt: float = 0.05, v_max: float = 0.5, stroke_limits=None, refine: int = REFINE,
                 use_compiled: bool = True, friction: bool = False,
                 cylinder_area: float = CYLINDER_AREA, bulk_modulus: float = BULK_MODULUS,
                 dead_length: float = DEAD_LENGTH, hydraulic_damping: float = HYDRAULIC_DAMPING,
                 mu_static: float | None = None, mu_dynamic: float | None = None,
                 friction_law: str = "coulomb", v_eps: float = V_EPS):
        if isinstance(n_envs, bool) or not isinstance(n_envs, (int, np.integer)) or n_envs < 1:
            raise ValueError(f"n_envs = {n_envs!r}: must be an integer >= 1")
        if isinstance(booms, bool) or booms not in TABLE_BOOMS:
            raise ValueError(f"booms = {booms!r}: allowed {', '.join(map(str, TABLE_BOOMS))}")
        if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) \
                or not 1 <= n_modes <= 4:
            raise ValueError(f"n_modes = {n_modes!r}: allowed 1..4")
        if payload_swing not in (True, False):
            raise ValueError(f"payload_swing = {payload_swing!r}: allowed True, False")
        if isinstance(refine, bool) or not isinstance(refine, (int, np.integer)) \
                or not 1 <= refine <= 32:
            raise ValueError(f"refine = {refine!r}: allowed 1..32")
        self.n_envs, self.booms, self.n_modes = int(n_envs), int(booms), int(n_modes)
        self.payload_swing, self.refine = bool(payload_swing), int(refine)
        dt = _finite_positive("dt", dt)
        v_max = _finite_positive("v_max", v_max)
        (p_lo, p_hi), (a_lo, a_hi), (L_lo, L_hi) = allowed_ranges(n_booms=self.booms)
        self.ranges = {"payload": (p_lo, p_hi), "luffing_angle_deg": (a_lo, a_hi),
                       "rope_length": ROPE_RANGE, "stroke": (L_lo, L_hi)}
        if stroke_limits is None:
            L_min, L_max = L_lo, L_hi
        else:
            try:
                L_min, L_max = (float(x) for x in stroke_limits)
            except (TypeError, ValueError):
                raise TypeError(f"stroke_limits = {stroke_limits!r}: must be two numbers "
                                "(L_min, L_max) m") from None
            if not (math.isfinite(L_min) and math.isfinite(L_max)
                    and L_lo - 1e-9 <= L_min < L_max <= L_hi + 1e-9):
                raise ValueError(f"stroke_limits = {stroke_limits!r}: must satisfy "
                                 f"{L_lo:g} <= L_min < L_max <= {L_hi:g} m (the tables' range)")
        self.stroke_limits = (L_min, L_max)
        self.gravity = GRAVITY
        n_c = self.n_modes + 2 if self.payload_swing else self.n_modes
        L_grid = lumped_coefficients([p_lo], [a_lo], self.n_modes, self.booms)[0]
        if self.payload_swing and self.refine > 1:
            k = np.arange(self.refine) / self.refine
            L_grid = np.concatenate([(L_grid[:-1, None] + k[None] * np.diff(L_grid)[:, None])
                                     .ravel(), L_grid[-1:]])
        fr = None
        if friction not in (True, False):
            raise ValueError(f"friction = {friction!r}: allowed True, False")
        if not isinstance(friction_law, str) or friction_law not in FRICTION_LAWS:
            raise ValueError(f"friction_law = {friction_law!r}: allowed "
                             + ", ".join(map(repr, FRICTION_LAWS)))
        v_eps = _finite_positive("v_eps", v_eps)
        if v_eps > 0.1:
            raise ValueError(f"v_eps = {v_eps!r}: allowed (0, 0.1] m/s")
        if friction:
            from sim_core.systems.telescopic.friction_table import load
            tab = load(self.booms)
            mu_s = float(tab["mu_static"]) if mu_static is None else mu_static
            mu_k = float(tab["mu_dynamic"]) if mu_dynamic is None else mu_dynamic
            for name, x, hi in (("mu_static", mu_s, 2.0), ("mu_dynamic", mu_k, 2.0),
                                ("hydraulic_damping", hydraulic_damping, 0.99)):
                x = _finite_positive(name, x) if name == "hydraulic_damping" else float(x)
                if not (math.isfinite(x) and 0.0 <= x <= hi):
                    raise ValueError(f"{name} = {x!r}: allowed [0, {hi:g}]")
            if mu_k > mu_s:
                raise ValueError(f"mu_dynamic = {mu_k!r} > mu_static = {mu_s!r}: allowed "
                                 "mu_dynamic <= mu_static")
            fr = {"law": friction_law, "v_eps": float(v_eps),
                  "kA": _finite_positive("bulk_modulus", bulk_modulus)
                  * _finite_positive("cylinder_area", cylinder_area),
                  "l0": _finite_positive("dead_length", dead_length),
                  "zeta_h": float(hydraulic_damping), "mu_static": float(mu_s),
                  "mu_dynamic": float(mu_k)}
        self.friction = fr
        self._b = BatchROM(self.n_envs, L_grid, n_c, dt, v_max, L_min, L_max, use_compiled, fr)
        self.payload = np.full(self.n_envs, np.nan)
        self.luffing_angle_deg = np.full(self.n_envs, np.nan)
        self.rope_length = np.full(self.n_envs, np.nan)

    # -- configuration -----------------------------------------------------------------------
    @property
    def dt(self) -> float:
        return self._b.dt

    @property
    def v_max(self) -> float:
        return self._b.v_max

    @property
    def n_coordinates(self) -> int:
        """Modal coordinates per crane: n_modes (+ 2 with payload_swing)."""
        return self._b.nc

    def _ids(self, envs):
        if envs is None:
            return np.arange(self.n_envs)
        ids = np.asarray(envs)
        if ids.dtype == bool:
            if ids.shape != (self.n_envs,):
                raise ValueError(f"envs mask of shape {ids.shape}: expected ({self.n_envs},)")
            return np.flatnonzero(ids)
        ids = ids.astype(int).reshape(-1)
        if ids.size and (ids.min() < 0 or ids.max() >= self.n_envs):
            raise ValueError(f"envs {ids}: allowed indices 0..{self.n_envs - 1}")
        return ids

    def _values(self, name, value, k):
        x = np.asarray(value, dtype=float)
        if x.ndim == 0:
            x = np.full(k, float(x))
        x = x.reshape(-1)
        if x.shape != (k,):
            raise ValueError(f"{name}: {x.size} values for {k} cranes")
        lo, hi = self.ranges[name]
        bad = ~(np.isfinite(x) & (x >= lo - 1e-9) & (x <= hi + 1e-9))
        if bad.any():
            raise ValueError(f"{name} = {x[bad][0]!r} outside the allowed range [{lo:g}, {hi:g}]")
        return x

    def configure(self, payload, luffing_angle_deg, rope_length=None, envs=None) -> None:
        """Set the payload (kg: payload and hook, hanging or at the tip), luffing angle (deg)
        and hoist-rope length (m; needed with payload_swing) of the cranes ``envs`` (indices or
        a boolean mask; default all): scalars or one value per crane.  Forms their coefficient
        tables (with payload_swing: one compiled call for all of them,
        ``modal_batch.coupled_tables_of``, about 0.1 ms per crane: a 4 x 4 eigenproblem at each
        of the refined grid's points).  Values outside the tables' ranges (``ranges``) raise
        ValueError."""
        ids = self._ids(envs)
        if ids.size == 0:
            return
        m = self._values("payload", payload, ids.size)
        ang = self._values("luffing_angle_deg", luffing_angle_deg, ids.size)
        if self.payload_swing:
            if rope_length is None:
                raise ValueError("rope_length is required with payload_swing = True (allowed "
                                 f"[{ROPE_RANGE[0]:g}, {ROPE_RANGE[1]:g}] m)")
            ell = self._values("rope_length", rope_length, ids.size)
            if self._b.compiled:                # one compiled call (the same arithmetic)
                _, dyn, out = coupled_tables_of(m, ang, ell, self.n_modes, self.booms,
                                                self.gravity, self.refine)
            else:
                L, coef, tip_dL = lumped_coefficients(m, ang, self.n_modes, self.booms)
                _, dyn, out = coupled_tables(coef, tip_dL, L, m, ell, self.gravity,
                                             self.refine, False)
            self.rope_length[ids] = ell
        else:
            dyn, out = lumped_tables(lumped_coefficients(m, ang, self.n_modes, self.booms)[1])
        self._b.dyn[ids] = dyn
        self._b.out[ids] = out
        if self.friction is not None:
            refine = self.refine if self.payload_swing else 1
            if self._b.compiled:
                _, nl = normal_loads_refined(m, ang, self.booms, refine)
            else:
                Lf, nl = normal_loads(m, ang, self.booms)
                _, nl = refine_grid(Lf, nl, refine)
            self._b.ntab[ids] = nl
            self._b.Ms[ids] = stroke_masses(m, self.booms)
        self.payload[ids] = m
        self.luffing_angle_deg[ids] = ang

    def reset(self, stroke, envs=None, sway=None) -> None:
        """Put the cranes ``envs`` at rest in static equilibrium at piston length ``stroke`` (m,
        scalar or per crane), no vibration; ``sway``: start sway (in-plane, out-of-plane angle
        rad), (2,) or (k, 2), payload at rest (needs payload_swing)."""
        ids = self._ids(envs)
        if ids.size == 0:
            return
        if np.isnan(self.payload[ids]).any():
            raise RuntimeError("reset before configure: set payload and angle first")
        L = np.asarray(stroke, float)
        L = np.full(ids.size, float(L)) if L.ndim == 0 else L.reshape(-1)
        lo, hi = self._b.L_min, self._b.L_max
        if L.shape != (ids.size,) or not np.all(np.isfinite(L) & (L >= lo) & (L <= hi)):
            raise ValueError(f"stroke = {stroke!r}: allowed [{lo:g}, {hi:g}] m, one per crane")
        b = self._b
        b.L[ids] = L
        b.v[ids] = 0.0
        b.q[ids] = 0.0
        b.qd[ids] = 0.0
        if self.friction is not None:
            b.e[ids] = 0.0
            b.ed[ids] = 0.0
            b.stuck[ids] = True
            b.sdir[ids] = 1.0
            b.wf[ids] = 0.0
        if sway is not None:
            if not self.payload_swing:
                raise ValueError("sway given with payload_swing = False")
            s = np.broadcast_to(np.asarray(sway, float), (ids.size, 2))
            if not np.all(np.isfinite(s) & (np.abs(s) <= SWAY_LIMIT)):
                raise ValueError(f"sway = {sway!r}: allowed |angle| <= {SWAY_LIMIT:g} rad")
            self._set_sway(ids, s)

    def _set_sway(self, ids, s):
        """Modal coordinates of a payload displaced by the angles s (k, 2) with the booms in
        their static equilibrium (bending coordinates zero): q_c = Phi^-1 (0, theta), psi."""
        b = self._b
        n = self.n_modes
        c = b._at(b.out, ids, b.stage_stroke()[ids])  # (k, 4, n_c)
        # the in-plane coupled modes map to (tip dX, tip dZ, theta) through their rows; solve
        # the n + 1 coupled coordinates from (bending = 0, theta): M_c-orthonormality gives
        # q_c = Phi^T M_c x; with x = (0, theta): q_c = theta Phi^T M_c e_theta, and
        # M_c e_theta = (m l phi_x, m l^2)
        m, ell = self.payload[ids], self.rope_length[ids]
        # Phi^T M_c e_theta = (phi_x,c m l + phi_theta,c m l^2): the tip-X map of the coupled
        # modes is Phi_q^T phi_x
        qc = (c[:, 0, :n + 1] * (m * ell)[:, None] + c[:, 2, :n + 1] * (m * ell * ell)[:, None])
        b.q[ids, :n + 1] = qc * s[:, 0:1]
        b.q[ids, n + 1] = s[:, 1]

    # -- stepping ----------------------------------------------------------------------------
    def step(self, accel):
        """Advance every crane over ``dt`` at the commanded stroke accelerations ``accel``
        (N,) m/s^2, held over the interval.  Returns (saturated (N,) bool: the rate limit cut
        the acceleration, end_stop (N,) bool: an end stop was hit or pressed, accel_applied
        (N,) m/s^2: the mean acceleration actually applied).  Non-finite accelerations raise
        ValueError."""
        return self._b.step(self._accel(accel))

    def step_outputs(self, accel):
        """:meth:`step` followed by :meth:`outputs`: returns (saturated, end_stop,
        accel_applied, tip_deflection (N, 4), sway (N, 4)), the same values as the two calls,
        computed in one compiled pass over the cranes (each crane's tables read once)."""
        return self._b.step_outputs(self._accel(accel))

    def _accel(self, accel) -> np.ndarray:
        """``accel`` as a contiguous float array (N,); ValueError for another shape or a
        non-finite value."""
        a = np.ascontiguousarray(accel, dtype=float).reshape(-1)
        if a.shape != (self.n_envs,):
            raise ValueError(f"accel of shape {np.shape(accel)}: expected ({self.n_envs},)")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"accel: {int(np.sum(~np.isfinite(a)))} non-finite values")
        return a

    # -- state and outputs -------------------------------------------------------------------
    @property
    def stroke(self) -> np.ndarray:
        """Stroke L_s of the stages (m): the piston's with friction off, the piston's plus the
        stage's lag on the oil column with friction on."""
        return self._b.stage_stroke()

    @property
    def stroke_rate(self) -> np.ndarray:
        return self._b.stage_rate()

    @property
    def piston_stroke(self) -> np.ndarray:
        """The commanded piston's stroke (m): the stroke kinematics' (= stroke without
        friction)."""
        return self._b.L

    @property
    def piston_rate(self) -> np.ndarray:
        return self._b.v

    @property
    def stuck(self) -> np.ndarray:
        """Whether each crane's stages stick (friction on; all False without friction); with
        friction_law "regularised": whether their rate is within the stick band, |L_s'| <
        v_eps (as the full model's)."""
        b = self._b
        return b.stuck.copy() if self.friction is not None else np.zeros(self.n_envs, bool)

    @property
    def friction_work(self) -> np.ndarray:
        """Work of the sliders' friction since the reset (J, >= 0; zeros without friction)."""
        b = self._b
        return b.wf.copy() if self.friction is not None else np.zeros(self.n_envs)

    def normal_load(self, envs=None) -> np.ndarray:
        """The sliders' total normal load N (N) at each crane's current stroke (friction on)."""
        if self.friction is None:
            raise ValueError("normal_load needs friction = True")
        ids = self._ids(envs)
        b = self._b
        return b._at(b.ntab[:, :, None, None], ids, b.stage_stroke()[ids])[:, 0, 0]

    @property
    def q(self) -> np.ndarray:
        return self._b.q

    @property
    def qd(self) -> np.ndarray:
        return self._b.qd

    def tip_deflection(self, envs=None) -> np.ndarray:
        """(k, 4): tip deflection dX, dZ (m) from the static tip at the current L_s, and their
        rates (m/s)."""
        return self._b.outputs(None if envs is None else self._ids(envs))[0]

    def sway(self, envs=None) -> np.ndarray:
        """(k, 4): sway angle in the luffing plane, across it (rad), and their rates (rad/s);
        zeros without payload_swing."""
        return self._b.outputs(None if envs is None else self._ids(envs))[1]

    def outputs(self, envs=None):
        """(tip_deflection, sway) in one call (see those)."""
        return self._b.outputs(None if envs is None else self._ids(envs))

    def save_state(self) -> dict:
        """Everything the future depends on (copies): state arrays, tables and configuration."""
        b = self._b
        st = {"L": b.L.copy(), "v": b.v.copy(), "q": b.q.copy(), "qd": b.qd.copy(),
              "dyn": b.dyn.copy(), "out": b.out.copy(), "payload": self.payload.copy(),
              "luffing_angle_deg": self.luffing_angle_deg.copy(),
              "rope_length": self.rope_length.copy()}
        if self.friction is not None:
            for k in FRICTION_STATE:
                st[k] = getattr(b, k).copy()
        return st

    def restore_state(self, state: dict) -> None:
        """Return to a :meth:`save_state` snapshot of this ROM."""
        b = self._b
        for k in ("L", "v", "q", "qd", "dyn", "out") + (FRICTION_STATE if self.friction
                                                        is not None else ()):
            getattr(b, k)[...] = state[k]
        for k in ("payload", "luffing_angle_deg", "rope_length"):
            getattr(self, k)[...] = state[k]
