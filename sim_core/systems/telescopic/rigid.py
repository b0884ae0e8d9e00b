"""Rigid-boom limit of the telescopic system (scene effect ``flexible = false``).

The booms are rigid and slide along the common axis e_s of the luffed boom 1, which is held by
the pivot D1 and the (rigid) luffing cylinder D2-D3.  The telescopic cylinder prescribes the
piston length L_s(t) (cubic schedule, docs/model.md#input-drive) and the ropes over the pulley
on boom 2 move boom 3 (Zhao-Qi-Wang 2024 Section 9, Eqs. 74-76: boom 3 moves twice the piston
stroke when the ropes are inextensible).  Nothing of the beam model is built: no spline
elements, no contact constraints, no slider springs.

Positions along e_s of the left sections (a_1 = 0, a_2 = L_s(t), a_3):

* ``rope_elasticity = false``: a_3 = 2 a_2 (rope length constant; zero degrees of freedom);
* ``rope_elasticity = true``: a_3 is the one degree of freedom, driven by the tension-only
  extraction and retraction ropes of docs/model.md#input-ropes (same anchors, pulleys, EA and
  unstretched lengths as :func:`sim_core.systems.telescopic.build.build_telescopic`):

      (m_3 + m_p) a_3'' = T_e - T_r - (m_3 + m_p) g sin(theta)

  with l_e = l_e0 + 2 (a_2 - a_2,0) - (a_3 - a_3,0) and l_r = l_r0 - 2 (a_2 - a_2,0) + (a_3 - a_3,0)
  (all rope points lie on the axis in the straight rigid state).

Forces (d'Alembert, frictionless sliding; boom mass centres on the axis, or offset by z_c along
e_b with ``mass_centre_offset``, as in the flexible model):

* telescopic cylinder (pushing positive): F_tel = m_2 (a_2'' + g sin theta) + 2 T_e - 2 T_r
  (axial balance of boom 2; static form m_2 g sin th + 2 T, docs/model.md#check-static-luffing);
* luffing cylinder (pushing positive): moment balance of the whole boom set about D1 with the
  inertia forces -m_k a_k'' e_s added to the weights (static form:
  docs/model.md#check-static-luffing,
  :func:`sim_core.validation.closed_form.static_luffing_forces`).

Supported for 2 or 3 booms (the rope drive is the paper's three-boom drive; with 2 booms there
is no rope) and without friction (the rigid contact reactions are statically indeterminate:
constraints I and II both carry force and moment).
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.result import Result
from sim_core.systems.telescopic.luffing import luffing_geometry
from sim_core.systems.telescopic.params import boom_section

# extraction rope: anchor on boom 1 (axial +0.05 m from its left section), pulley on boom 2 at
# s = 9 m, anchor on boom 3 (-0.04 m); retraction rope: boom 1 right end + 0.68 m, pulley on
# boom 2 at s = 0.66 m, boom 3 left + 0.64 m (docs/model.md#input-ropes; same points as
# telescopic.py)
_EXT = (0.05, 9.0, -0.04)
_RET = (0.68, 0.66, 0.64)


class RigidTelescopic:
    """The rigid-boom telescopic system of :class:`sim_core.systems.telescopic.build.TelescopicParams` ``p``."""

    def __init__(self, p):
        from sim_core.physics.drive_profiles import CubicSmoothstepSchedule
        if p.n_booms not in (2, 3):
            raise ValueError(f"booms.count = {p.n_booms} with effects.flexible = false: the rigid "
                             "limit has the paper's drive (allowed: 2 or 3 booms)")
        if p.friction:
            raise ValueError("effects.friction = true with effects.flexible = false: rigid contact "
                             "reactions are statically indeterminate (allowed: friction = false)")
        self.p = p
        self.theta = math.radians(p.luffing_angle_deg)
        self.geo = luffing_geometry(self.theta)
        self.e = np.asarray(self.geo.e_s, float)
        self.origin = np.asarray(self.geo.origin, float)
        self.L = p.boom_length
        self.masses = [boom_section(k, p).rhoA * self.L for k in range(p.n_booms)]
        # mass centres offset along e_b (Table 2, docs/model.md#input-sections), when
        # switched on
        self.z_c = [boom_section(k, p).z_c for k in range(p.n_booms)]
        self.e_b = np.asarray(self.geo.rotation, float) @ np.array([0.0, 0.0, 1.0])
        self.schedule = CubicSmoothstepSchedule(v_max=p.v_max, t_ramp=p.t_ramp,
                                                t_hold_end=p.t_hold_end, sign=p.direction,
                                                s0=p.stroke0)
        self.g = p.gravity
        self.ropes = p.n_booms == 3
        self.elastic = self.ropes and p.rope_elasticity
        if self.elastic:
            Ls = p.stroke0
            self.a20, self.a30 = Ls, 2 * Ls
            self.le0 = (Ls + _EXT[1] - _EXT[0]) + (Ls + _EXT[1] - (2 * Ls + _EXT[2]))
            self.lr0 = (self.L + _RET[0] - (Ls + _RET[1])) + (2 * Ls + _RET[2] - (Ls + _RET[1]))
            self.EA = p.rope_EA * p.E / 2.1e11
            T0 = (self.masses[2] + p.payload) * self.g * math.sin(self.theta)   # check-static-luffing
            self.Le = self.le0 / (1.0 + T0 / self.EA)
            self.Lr = self.lr0                                                 # just taut

    @property
    def n_dof(self) -> int:
        return 1 if self.elastic else 0

    # -- ropes ------------------------------------------------------------------------------
    def tensions(self, a2, a3):
        """(T_e, T_r) in N of the extraction and retraction ropes (tension-only, linear EA)."""
        if not self.elastic:
            return 0.0, 0.0
        le = self.le0 + 2 * (a2 - self.a20) - (a3 - self.a30)
        lr = self.lr0 - 2 * (a2 - self.a20) + (a3 - self.a30)
        return (self.EA / self.Le * max(le - self.Le, 0.0),
                self.EA / self.Lr * max(lr - self.Lr, 0.0))

    def _rhs(self, t, y):
        a3, v3 = y
        T_e, T_r = self.tensions(self.schedule.stroke(t), a3)
        m = self.masses[2] + self.p.payload
        return [v3, (T_e - T_r) / m - self.g * math.sin(self.theta)]

    # -- forces -----------------------------------------------------------------------------
    def luffing_force(self, positions, accelerations) -> float:
        """Luffing-cylinder force (N, pushing positive) from the moment balance about D1 of the
        weights and inertia forces (docs/model.md#check-static-luffing with d'Alembert
        terms)."""
        gvec = np.array([0.0, 0.0, -self.g])
        d1 = np.asarray(self.geo.d1, float)
        M = 0.0
        bodies = [(m, a + 0.5 * self.L, acc, zc) for m, a, acc, zc in
                  zip(self.masses, positions, accelerations, self.z_c)]
        bodies.append((self.p.payload, positions[-1] + self.L, accelerations[-1], 0.0))
        for m, x, acc, zc in bodies:
            r = self.origin + x * self.e + zc * self.e_b
            M += float(np.cross(r - d1, m * (gvec - acc * self.e))[1])
        d3, d2 = np.asarray(self.geo.d3, float), np.asarray(self.geo.d2, float)
        u = (d3 - d2) / np.linalg.norm(d3 - d2)
        arm = float(np.cross(d3 - d1, u)[1])
        return -M / arm

    # -- run --------------------------------------------------------------------------------
    def simulate(self, t_end: float, n_output: int = 201, rtol: float = 1e-6,
                 atol: float = 1e-7, scene: dict | None = None,
                 max_wall_s: float | None = None) -> Result:
        """The rigid-limit outputs at n_output times in [0, t_end]; ``scene``: the validated scene
        the result records (a summary of the parameters where None); ``max_wall_s``: the
        wall-clock budget of the rope coordinate's integration (s, solver.max_wall_s), past
        which a SimulationError stops the run."""
        import time

        from scipy.integrate import solve_ivp
        t = np.linspace(0.0, t_end, n_output)
        sch = self.schedule
        a2, v2, acc2 = (np.array([f(tk) for tk in t]) for f in (sch.stroke, sch.rate, sch.accel))
        wall = time.perf_counter()
        stats = {"method": "RK45" if self.elastic else "kinematic", "n_steps": 0, "n_rhs": 0}
        if self.elastic:
            calls = [0]

            def rhs(tk, y):                        # the budget every 1000 evaluations
                calls[0] += 1
                if (max_wall_s is not None and calls[0] % 1000 == 0
                        and time.perf_counter() - wall > max_wall_s):
                    from sim_core.errors import SimulationError
                    raise SimulationError(tk, f"wall-clock budget solver.max_wall_s = "
                                          f"{max_wall_s:g} s exhausted", last_state=np.array(y))
                return self._rhs(tk, y)
            sol = solve_ivp(rhs, (0.0, t_end), [self.a30, 0.0], method="RK45", t_eval=t,
                            rtol=rtol, atol=atol)
            if not sol.success:
                from sim_core.errors import SimulationError
                raise SimulationError(float(sol.t[-1]), f"rigid telescopic rope dof: {sol.message}")
            a3, v3 = sol.y
            acc3 = np.array([self._rhs(tk, y)[1] for tk, y in zip(t, sol.y.T)])
            stats.update(n_rhs=int(sol.nfev), n_steps=int(len(sol.t)))
        elif self.ropes:
            a3, v3, acc3 = 2 * a2, 2 * v2, 2 * acc2
        else:
            a3 = v3 = acc3 = None
        stats["wall_time_s"] = time.perf_counter() - wall
        stats["real_time_factor"] = t_end / max(stats["wall_time_s"], 1e-12)
        n = len(t)
        pos = [np.zeros(n), a2] + ([a3] if a3 is not None else [])
        vel = [np.zeros(n), v2] + ([v3] if v3 is not None else [])
        acc = [np.zeros(n), acc2] + ([acc3] if acc3 is not None else [])
        sin = math.sin(self.theta)
        T = np.array([self.tensions(a2[i], a3[i]) if self.elastic else (0.0, 0.0)
                      for i in range(n)])
        if self.ropes and not self.elastic:         # inextensible: tension from boom 3's balance
            T[:, 0] = (self.masses[2] + self.p.payload) * (acc3 + self.g * sin)
        F_tel = self.masses[1] * (acc2 + self.g * sin) + 2 * T[:, 0] - 2 * T[:, 1]
        if not self.ropes:                           # 2 booms: boom 2 carries the payload
            F_tel = (self.masses[1] + self.p.payload) * (acc2 + self.g * sin)
        F_L = np.array([self.luffing_force([x[i] for x in pos], [x[i] for x in acc])
                        for i in range(n)])
        out = {"tip_position": self.origin + np.outer(pos[-1] + self.L, self.e),
               "tip_velocity": np.outer(vel[-1], self.e),
               "tip_acceleration": np.outer(acc[-1], self.e),
               "piston_stroke": a2 - self.p.stroke0,
               "telescopic_cylinder_force": F_tel,
               "luffing_cylinder_force": F_L,
               # kinematic model: the joints hold by construction (no constraint equations)
               "constraint_violation": np.zeros(n)}
        if self.ropes:
            out["rope_tension"] = T if self.elastic else T[:, 0]
        stats["n_dof"] = self.n_dof
        return Result(t, out, stats, scene if scene is not None else self.p.summary("telescopic_rigid"),
                      None)
