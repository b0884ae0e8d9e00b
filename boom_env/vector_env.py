"""Native vector env of the v1 tasks: N cranes stepped in one array call.

    import gymnasium as gym, boom_env
    envs = gym.make_vec("boom_env/TelescopicExtraction-v1", num_envs=1024,
                        vectorization_mode="vector_entry_point")
    obs, infos = envs.reset(seed=0)                       # sub-env i seeded with seed + i
    obs, rewards, terminations, truncations, infos = envs.step(actions)   # actions (N, 1)

:class:`TelescopicSwayVectorEnv` is a :class:`gymnasium.vector.VectorEnv` over
:class:`boom_env.telescopic_sway_env.SwayTask` (the spaces, reward, start state and episode end
of the v1 env, module docstring of boom_env.telescopic_sway_env).  The plant of all N cranes is
one :class:`sim_core.vector_rom.VectorROM`, advanced by one compiled call per step; per-crane
work in Python happens only at resets (a crane's random draws and its coupled tables).

Autoreset: ``AutoresetMode.NEXT_STEP`` (Gymnasium's default, ``metadata["autoreset_mode"]``):
a sub-env that terminated or truncated at step t is reset at step t + 1, whose action it ignores;
that step returns its reset observation, reward 0, terminated = truncated = False and its reset
info.  Seeding as :class:`gymnasium.vector.SyncVectorEnv` of the scalar env: ``reset(seed=s)``
seeds sub-env i with s + i (a list: one seed each) and its own generator draws the randomised
payload, angle and rope length at every reset, so this env and a ``SyncVectorEnv`` of
:class:`~boom_env.telescopic_sway_env.TelescopicSwayEnv` give the same trajectories to round-off
(tests/env/test_vector_env.py).  ``max_episode_steps`` (set by ``gym.make_vec`` from the
registration) truncates like the TimeLimit wrapper of the scalar env.

Infos: a dict of arrays (N, ...) with the boolean masks ``_key`` (all True: every sub-env
reports every key at every step), the keys of the scalar env's info (``reason``: an object
array of strings).  ``render_mode="rgb_array"`` renders sub-env 0.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .telescopic_sway_env import SwayTask, _positive


class TelescopicSwayVectorEnv(VectorEnv):
    """N v1 cranes in one vector env (module docstring).  ``num_envs``: N; the other keyword
    arguments are those of :class:`boom_env.telescopic_sway_env.TelescopicSwayEnv`."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20,
                "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1, render_mode=None, render_exaggeration: float = 20.0,
                 render_sway_exaggeration: float = 5.0, **kwargs):
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) \
                or num_envs < 1:
            raise ValueError(f"num_envs = {num_envs!r}: must be an integer >= 1")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode = {render_mode!r}: allowed "
                             f"{self.metadata['render_modes']}")
        self.num_envs = int(num_envs)
        self.render_mode = render_mode
        self.exaggeration = _positive("render_exaggeration", render_exaggeration)
        self.sway_exaggeration = _positive("render_sway_exaggeration", render_sway_exaggeration)
        self.core = SwayTask(self.num_envs, **kwargs)
        self.single_action_space = spaces.Box(-1.0, 1.0, (1,), np.float32)
        self.single_observation_space = spaces.Box(self.core.obs_low, self.core.obs_high,
                                                   dtype=np.float32)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._autoreset = np.zeros(self.num_envs, bool)
        self._fidelity = np.array([self.core.fidelity] * self.num_envs, dtype=object)
        self._fig = {}
        self._reset_called = False

    @property
    def dt(self) -> float:
        return self.core.dt

    def _infos(self, diverged, reason, success, reward_unscaled):
        arr = self.core.info_arrays(diverged, reason, success, reward_unscaled)
        arr["fidelity"] = self._fidelity.copy()
        infos = {}
        masks = np.ones((len(arr), self.num_envs), bool)   # one row (its own memory) per key
        for j, (k, v) in enumerate(arr.items()):
            infos[k] = v
            infos["_" + k] = masks[j]
        return infos

    def reset(self, *, seed=None, options=None):
        """Reset all sub-envs (or those of ``options["reset_mask"]``, a bool array (N,)):
        ``seed`` None, an int (sub-env i gets seed + i) or a list of N ints / None."""
        n = self.num_envs
        if seed is None:
            seeds = [None] * n
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            seeds = [int(seed) + i for i in range(n)]
        else:
            seeds = list(seed)
            if len(seeds) != n:
                raise ValueError(f"seed: {len(seeds)} seeds for num_envs = {n}")
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if mask is None:
            ids = np.arange(n)
        else:
            mask = np.asarray(mask)
            if mask.shape != (n,) or mask.dtype != np.bool_:
                raise ValueError(f"options['reset_mask'] must be a bool array of shape ({n},)")
            ids = np.flatnonzero(mask)
        for i in ids:
            if seeds[i] is not None or self.core.rngs[i] is None:
                self.core.rngs[i], _ = seeding.np_random(seeds[i])
        self.core.reset_envs(ids, options)
        self._autoreset[ids] = False
        self._reset_called = True
        z = np.zeros(n, bool)
        return self.core.last_obs.copy(), self._infos(z, [""] * n, z, np.zeros(n))

    def step(self, actions):
        if not self._reset_called:
            raise RuntimeError("step() before reset()")
        a = self.core.check_actions(actions)
        redo = self._autoreset
        any_redo = bool(redo.any())
        if any_redo:
            a = np.where(redo, 0.0, a)
        obs, r, term, trunc, div, reason = self.core.step(a)
        ru = self.core.reward_unscaled
        if any_redo:
            ids = np.flatnonzero(redo)
            self.core.reset_envs(ids)
            obs = self.core.last_obs.copy()
            r = np.where(redo, 0.0, r)
            ru = np.where(redo, 0.0, ru)
            term = term & ~redo
            trunc = trunc & ~redo
            div = div & ~redo
            for i in ids:
                reason[i] = ""
        self._autoreset = term | trunc
        infos = self._infos(div, reason, term, ru)
        # obs, r, term, trunc are fresh arrays of this step (SwayTask.step): no copies
        return obs, r, term, trunc, infos

    def render(self):
        if self.render_mode is None:
            return None
        return self.core.draw(self._fig, 0, self.exaggeration, self.sway_exaggeration)

    def close_extras(self, **kwargs):
        self._fig = {}
