"""Action parameterisations of the PPO agent on top of the boom_env action (the cylinder
acceleration a = action * a_max, m/s^2)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np


class AccelerationIncrement(gym.Wrapper):
    """The policy commands the *change* of the cylinder acceleration per control step:

        a_k / a_max = clip(a_{k-1} / a_max + du_max * u_k, -1, 1),   u_k in [-1, 1],

    with a_{k-1} the acceleration the env applied in the previous step (observation index 2, so
    the wrapped env stays Markov in its observation; after velocity saturation or an end stop
    that is 0).  The jerk is bounded by du_max * a_max / dt (default 0.1 * 0.25 / 0.05 =
    0.5 m/s^3; the paper's cubic schedule peaks at 6 V / T^2 = 0.19 m/s^3), so Gaussian
    exploration noise integrates into smooth accelerations instead of exciting the axial
    (3.6 Hz) and bending modes with white-noise jerk.  Observations and rewards are the env's."""

    def __init__(self, env: gym.Env, du_max: float = 0.1):
        super().__init__(env)
        if not 0 < du_max <= 2:
            raise ValueError(f"du_max = {du_max!r}: allowed (0, 2]")
        self.du_max = float(du_max)
        self._a = 0.0

    def _from_obs(self, obs) -> float:
        return float(obs[2]) / self.env.unwrapped.a_max

    def reset(self, **kwargs):
        obs, info = self.env.reset(**kwargs)
        self._a = self._from_obs(obs)
        return obs, info

    def command(self, u) -> np.ndarray:
        """The env action for policy output u (does not change the wrapper state)."""
        u = float(np.clip(np.asarray(u, dtype=np.float64).reshape(-1)[0], -1.0, 1.0))
        return np.array([np.clip(self._a + self.du_max * u, -1.0, 1.0)], dtype=np.float32)

    def step(self, action):
        obs, r, term, trunc, info = self.env.step(self.command(action))
        self._a = self._from_obs(obs)
        return obs, r, term, trunc, info


class RandomStart(gym.Wrapper):
    """Exploration aid for training: with probability ``p`` an episode starts at rest at a
    piston length drawn uniformly from [lo, hi] (m) instead of the task's start (reset option
    ``stroke_start`` of boom_env), so that stopping at the target, and the success bonus, are
    met early in training.  Evaluation always starts at the task's start (2 m)."""

    def __init__(self, env: gym.Env, p: float = 0.5, lo: float = 2.0, hi: float = 7.9):
        super().__init__(env)
        if not 0 <= p <= 1:
            raise ValueError(f"p = {p!r}: allowed [0, 1]")
        self.p, self.lo, self.hi = float(p), float(lo), float(hi)

    def reset(self, *, seed=None, options=None):
        if seed is not None:
            self.env.reset(seed=seed)          # seeds the env's np_random
        rng = self.env.unwrapped.np_random
        options = dict(options or {})
        if "stroke_start" not in options and rng.uniform() < self.p:
            options["stroke_start"] = float(rng.uniform(self.lo, self.hi))
        return self.env.reset(options=options)


class ActionRepeat(gym.Wrapper):
    """The policy acts every ``repeat`` env steps: its action is held (zero-order hold) for
    repeat * dt seconds (4 x 0.05 s = 0.2 s by default) and the rewards of those steps are
    summed, so the undiscounted episode return is the env's.  A 30 s episode is then 150
    decisions instead of 600: the credit for stopping at the target is 4x fewer decisions
    away, and each training step carries 4x more simulated time (the env is cheap next to the
    PPO update).  The held command is well inside the bandwidth that matters: the first
    bending mode is 0.4-1.2 Hz (period >= 0.8 s) and the tip responds to the acceleration
    steps' jerk either way.  Evaluation holds the action the same way
    (``agents.evaluate.PPOPolicy``, meta ``action_repeat``)."""

    def __init__(self, env: gym.Env, repeat: int = 4):
        super().__init__(env)
        if int(repeat) != repeat or repeat < 1:
            raise ValueError(f"repeat = {repeat!r}: allowed integers >= 1")
        self.repeat = int(repeat)

    def step(self, action):
        total = 0.0
        for _ in range(self.repeat):
            obs, r, term, trunc, info = self.env.step(action)
            total += float(r)
            if term or trunc:
                break
        return obs, total, term, trunc, info


class ScheduleTracker:
    """Feed-forward of a scripted schedule plus a tracking feedback on its stroke reference:
    the base controller of residual policy learning (Johannink et al. 2019, "Residual
    reinforcement learning for robot control"; Silver et al. 2018, "Residual policy learning").

    For env step k (time t_k = k dt) the command is

        a_k / a_max = clip(a_ff,k - (kp e_k + kd e'_k) / a_max + scale * u_k, -1, 1),

    with a_ff,k the schedule's mean acceleration over the step (``RateSchedule.actions``),
    e_k = L_s - L_ref(t_k), e'_k = v - v_ref(t_k) the deviation from the schedule's own stroke
    history (L_ref = L_start + trapezoidal integral of v_ref: exact for the env's piecewise
    constant acceleration, so e = e' = 0 when u = 0) and u_k in [-1, 1] the residual.  After the
    schedule's end the reference rests at its last value.  With u = 0 the command is the
    scripted schedule exactly; the feedback (kp = w^2, kd = 2 w, w = 1 rad/s: critically damped,
    below the 2.7 rad/s first bending mode at full extension so it leaves the vibration band to
    the residual) only acts on deviations the residual or the exploration noise caused and
    brings the stroke back to the schedule's end point.  Everything it uses (t, L_s, v) is in the
    env observation, so the wrapped problem stays Markov; e and e' are appended to the
    observation because the policy needs them in that form."""

    def __init__(self, schedule, dt: float, a_max: float, n_steps: int, scale: float = 0.25,
                 omega: float = 1.0):
        if not 0 < scale <= 2:
            raise ValueError(f"scale = {scale!r}: allowed (0, 2]")
        if not omega >= 0:
            raise ValueError(f"omega = {omega!r} rad/s: allowed >= 0")
        self.name, self.scale = schedule.name, float(scale)
        self.a_max, self.dt = float(a_max), float(dt)
        self.kp, self.kd = omega * omega, 2.0 * omega
        self.a_ff = schedule.actions(dt, a_max, n_steps)
        t = dt * np.arange(n_steps + 1)
        self.v_ref = np.array([schedule.rate(tk) for tk in t])
        self.dL_ref = np.concatenate([[0.0], np.cumsum(0.5 * dt * (self.v_ref[1:] + self.v_ref[:-1]))])
        self.L0 = 0.0

    @classmethod
    def for_env(cls, schedule, env: gym.Env, scale: float = 0.25, omega: float = 1.0):
        """The tracker for ``env``'s control step, a_max and episode length."""
        u = env.unwrapped
        return cls(schedule, u.dt, u.a_max, int(round(u.t_max / u.dt)), scale, omega)

    def reset(self, stroke: float) -> None:
        """Anchor the stroke reference at the episode's start piston length (m)."""
        self.L0 = float(stroke)

    def error(self, obs, k: int) -> tuple[float, float]:
        """(e m, e' m/s) at step boundary k (obs = the env observation there)."""
        j = min(k, len(self.v_ref) - 1)
        return float(obs[0]) - (self.L0 + self.dL_ref[j]), float(obs[1]) - self.v_ref[j]

    def augment(self, obs, k: int) -> np.ndarray:
        e, ed = self.error(obs, k)
        return np.concatenate([np.asarray(obs, dtype=np.float32),
                               np.array([e, ed], dtype=np.float32)])

    def command(self, obs, k: int, u) -> float:
        """Normalised env action for residual u at step k."""
        u = float(np.clip(np.asarray(u, dtype=np.float64).reshape(-1)[0], -1.0, 1.0))
        e, ed = self.error(obs, k)
        ff = float(self.a_ff[k]) if k < len(self.a_ff) else 0.0
        return float(np.clip(ff - (self.kp * e + self.kd * ed) / self.a_max + self.scale * u,
                             -1.0, 1.0))


class ResidualOnSchedule(gym.Wrapper):
    """The policy's action is a residual on a scripted schedule with tracking feedback
    (:class:`ScheduleTracker`); observation = env observation + (e m, e' m/s), the deviation
    from the schedule's stroke history (bounds +-(L_max - L_min), +-2 v_max).  Reward: the env's
    minus a tracking term  w_track * (e / e_ref)^2 * dt,  e_ref = 1 cm (the comparison's stroke
    tolerance), default w_track = 0 (the env's reward unchanged).  Not combinable with
    :class:`RandomStart` (the reference starts at the reset stroke and travels the schedule's
    distance, so the start must be the task's)."""

    E_REF = 0.01    # m

    def __init__(self, env: gym.Env, schedule=None, scale: float = 0.25, omega: float = 1.0,
                 w_track: float = 0.0):
        super().__init__(env)
        if not w_track >= 0:
            raise ValueError(f"w_track = {w_track!r}: allowed >= 0")
        self.w_track = float(w_track)
        if schedule is None:
            from .schedules import cubic
            schedule = cubic()
        self.tracker = ScheduleTracker.for_env(schedule, env, scale, omega)
        lo, hi = env.observation_space.low, env.observation_space.high
        span = float(hi[0] - lo[0])
        vm = float(hi[1])
        self.observation_space = gym.spaces.Box(
            np.concatenate([lo, [-span, -2 * vm]]).astype(np.float32),
            np.concatenate([hi, [span, 2 * vm]]).astype(np.float32), dtype=np.float32)
        self._k, self._obs = 0, None

    def reset(self, **kwargs):
        obs, info = self.env.reset(**kwargs)
        self.tracker.reset(obs[0])
        self._k, self._obs = 0, obs
        return self.tracker.augment(obs, 0), info

    def step(self, action):
        a = self.tracker.command(self._obs, self._k, action)
        obs, r, term, trunc, info = self.env.step(np.array([a], dtype=np.float32))
        self._k += 1
        self._obs = obs
        aug = self.tracker.augment(obs, self._k)
        if self.w_track:
            r = float(r) - self.w_track * (float(aug[-2]) / self.E_REF) ** 2 * self.env.unwrapped.dt
        info = dict(info, residual_command=a)
        return aug, r, term, trunc, info


class DeflectionOffset(gym.ObservationWrapper):
    """Training aid for robustness: adds a constant offset, drawn per episode uniformly from
    [-max_offset, max_offset] m for each component, to the observed tip deflection (dX, dZ;
    observation indices 5, 6).  The reward is the env's (true deflection).  Purpose: a policy
    trained with random offsets cannot rely on the absolute deflection, against a deflection
    reference that is off on the model the policy runs on (on the full model the env's
    reference is the tables' static tip change added to the tip at reset).  Off by default
    (``agents.train_ppo --obs-offset``, default 0): with the current modal tables that
    reference is within ~0.1 mm on the full model, and the residual policies trained without
    offsets do better there than those trained with 5 mm offsets (agents/README.md)."""

    def __init__(self, env: gym.Env, max_offset: float = 5e-3):
        super().__init__(env)
        if not 0 <= max_offset <= 0.1:
            raise ValueError(f"max_offset = {max_offset!r} m: allowed [0, 0.1]")
        self.max_offset = float(max_offset)
        self._off = np.zeros(2)

    def reset(self, **kwargs):
        obs, info = self.env.reset(**kwargs)
        self._off = self.env.unwrapped.np_random.uniform(-self.max_offset, self.max_offset, 2)
        return self.observation(obs), info

    def observation(self, obs):
        out = np.array(obs, dtype=np.float32, copy=True)
        out[5:7] += self._off.astype(np.float32)
        return out
