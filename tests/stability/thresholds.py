"""Thresholds of the numerical-stability suite, in one place, each with where it comes from.

None of these is fitted to make a run pass: each is set from the integrator tolerances, the
physics of the case or the observed convergence of the model, with the margin stated.  Runs
use sim_core's defaults (RK45, rtol = 1e-6, atol = 1e-7: the paper's ode45 settings) unless a
test says otherwise.
"""

# ---------------------------------------------------------------- minimum accepted RK45 step
# Frictionless full model, n_nodes = 3: RK45 is an explicit method, so its step is bounded by
# the stability limit of the stiffest (axial / high bending) modes, observed 11-18 ms at
# E = 2.1e11 Pa and ~1/sqrt(10) of that at E = 2.1e12 Pa (frequencies scale with sqrt(E)).
# A stalled integrator (chattering, a near-singular contact geometry, a zero-length element)
# collapses the step by many decades (the rejection cascade of _CountingRHS retries down to
# ~1e-10 s).  Floor: 1e-4 s, a decade and a half below the stiffest stability-limited step.
MIN_STEP_FRICTIONLESS = 1e-4          # s

# With Coulomb friction the regularised law mu = mu_s v / v_eps (|v| <= v_eps) acts as a viscous
# damper c = mu_s N / v_eps on the contact coordinates (N ~ 1e5 N, v_eps = 0.01 m/s): a stiff
# real eigenvalue that limits RK45 to ~0.5-1 ms steps (observed 0.55 ms minimum on the paper's
# scene).  Chattering of the stick-slip switch would show as a collapse far below that.
# Floor: 1e-5 s, fifty times below the observed stick-regime stability bound.
MIN_STEP_FRICTION = 1e-5              # s

# ---------------------------------------------------------------- constraint violation
# Constraints are enforced at acceleration level with Baumgarte stabilisation (alpha = beta =
# 20 1/s).  The drift is fed by the local integration error (atol 1e-7 on positions, rtol 1e-6
# on ~10 m coordinates: ~1e-6 m per step at worst) and damped by Baumgarte within ~0.05 s;
# observed 1e-10..1e-7 m (the existing overlap-transition test uses the same 1e-6 bound).
# Units: m for point coincidences, rad for angle rows, m for the drivers.
CONSTRAINT_TOL = 1e-6


def constraint_tol(extent_m: float, rtol: float = 1e-6, atol: float = 1e-7) -> float:
    """Violation bound (m) for the geometry extremes (end stops, contact points passing), where
    a spline element shrinks to 0.1 m and its high frequencies work the explicit integrator
    hardest: RK45 bounds the *RMS* of the scaled local errors, so a single coordinate may take
    up to atol + rtol * |q| per step and more (|q| up to extent_m, the largest tip distance from
    the pivot, ~30 m fully extended); Baumgarte (xi = 10 1/s) removes drift on 1/xi = 0.1 s, i.e.
    ~10 steps of ~10 ms can accumulate.  Bound: 10 (atol + rtol extent_m) (1.2e-4 m at 12 m) - a
    stability criterion (a drifting or blowing-up run exceeds it by decades; measured 1e-6 -
    3e-6 m in these runs, against 1e-10 - 1e-7 m in normal operation, see CONSTRAINT_TOL)."""
    return 10.0 * (atol + rtol * extent_m)


# ---------------------------------------------------------------- energy balance
# The runs keep the paper's stress filter (h = 0.01 s): it adds (h^2/6) int B'DB to the mass
# matrix, which caps the highest frequencies near sqrt(6)/h ~ 245 rad/s and so the explicit
# RK45 step near 10 ms (without it the axial modes force ~0.3 ms steps: too slow for this
# suite).  Its extra terms are an inertia-like energy >= 0 and a dissipation (h/2) eps_dot' D
# eps_dot, so from rest the balance is the inequality E(t) - E(0) - W_cylinder(t) <= tol.
# Frictionless and filter off the model is conservative: E(t) - E(0) = W_cylinder(t)
# (the luffing cylinder has fixed length; pivot and contact constraints are scleronomic and
# frictionless; Baumgarte forces do O(violation * lambda) ~ 1e-6 m * 1e5 N = 0.1 J of work).
# Error budget: RK45 at rtol 1e-6 keeps the state's relative error ~1e-6 per step, i.e. an
# energy error ~1e-6 of the energy exchanged per step, accumulated over <= ~100 steps: 1e-4;
# the cylinder work is integrated as an extra state of the same run (sim_core.systems.telescopic.energy_audit;
# a trapezoidal sum on the 25 ms output grid was off by ~250 J during the 0.1 s drive ramps).
# Tolerance: 1e-3 of the energy scale (range of the mechanical energy over the run, plus
# |work|), ten times the budget.
ENERGY_REL_TOL = 1e-3
# Absolute part: the energy is evaluated from states that RK45 carries with a position error
# ~ rtol * |q| + atol ~ 1e-6 * 10 m = 1e-5 m, so the gravity potential alone is uncertain by
# (total weight) * 1e-5 m (~3 J for the paper's 25 t scene).  Tolerance: total weight times
# 1e-4 m (ten times that position error).
ENERGY_POSITION_ERROR = 1e-4          # m

# With friction (dissipative) the inequality holds a fortiori (friction only removes energy).

# ---------------------------------------------------------------- long hold
# Hold at rest: the modal ROM's energy 1/2 sum(q_dot^2 + omega^2 q^2) (mass-normalised modes)
# of a damped linear oscillator with zeta > 0 must not grow: each exact step multiplies it by at
# most 1 (+ round-off): relative growth per step <= 1e-12 (double precision, a few ops).
ROM_ENERGY_GROWTH = 1e-12
# The static tip must not drift during a hold: the ROM's deflection returns to its static value
# (zero), so after 120 s of filter damping (zeta ~ h omega / 4 >= 0.5 %, omega >= 2 pi 0.9 rad/s:
# e-folding time <= 35 s, > 3 e-foldings) the residual vibration is below 5 % of its peak.
HOLD_DECAY_FRACTION = 0.05
# Full model at rest in equilibrium: tip drift bound.  The equilibrium is solved to 1e-7 of
# the force scale (statics Newton tol) -> initial residual displacement ~1e-7 * static sag
# (~0.1 m) ~ 1e-8 m; plus the Baumgarte drift level CONSTRAINT_TOL.  Bound: 1e-5 m (10 um).
HOLD_TIP_DRIFT = 1e-5                 # m

# ---------------------------------------------------------------- contact geometry
# Inner and outer contact points must stay ordered inside their element: the spline element
# between boom k's left end and its outer contact node has length L - L_s; a "zero-length
# element" would be L - L_s -> 0.  Minimum element length allowed in the end-stop runs: 1 mm
# (the runs stop 0.1 m from the geometric limits; the stroke error of RK45 is ~1e-7 m).
MIN_ELEMENT_LENGTH = 1e-3             # m

# ---------------------------------------------------------------- env (Gymnasium)
# Bang-bang episodes must reach both end stops / velocity saturation (the action really is at
# maximum magnitude) and keep the deflection well inside the observation bounds (1 m): the
# ROM's quasi-static deflection for a = 0.25 m/s^2 is mm-scale; 0.1 m is a factor > 10.
ENV_MAX_DEFLECTION = 0.1              # m

# ---------------------------------------------------------------- property-based runs
# Bounded steps: each hypothesis run of the rigid limit with elastic ropes must finish with at
# most this many RK45 steps per simulated second.  The rope dof's frequency is
# sqrt(EA_eff / ((m3 + m_p) L0)) <= ~100 rad/s for the valid ranges; RK45 at rtol 1e-6 needs
# ~10-50 steps per period: <= 1000 steps/s; bound 1e4 steps/s (a hang shows as 1e6+).
MAX_STEPS_PER_SECOND = 1e4
