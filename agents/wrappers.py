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
