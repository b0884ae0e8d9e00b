"""Stable-Baselines3 on a Gymnasium vector env: :class:`SB3VecEnv`.

    import gymnasium as gym, boom_env
    from boom_env.sb3_adapter import SB3VecEnv
    from stable_baselines3 import PPO
    venv = SB3VecEnv(gym.make_vec("boom_env/TelescopicExtraction-v1", num_envs=64))
    PPO("MlpPolicy", venv).learn(100_000)

SB3's :class:`~stable_baselines3.common.vec_env.VecEnv` resets a sub-env in the step that ends
its episode: that step returns the new episode's first observation, ``done = True`` and the
last observation of the old episode in ``infos[i]["terminal_observation"]``, with
``infos[i]["TimeLimit.truncated"]`` telling truncation from termination (done = terminated or
truncated).  Gymnasium's vector envs in ``AutoresetMode.NEXT_STEP`` (their default, and the
native v1 env's) reset it one step later instead.  The adapter bridges the two: after a step it
resets the sub-envs that finished with ``reset(options={"reset_mask": done})`` (Gymnasium >= 1.0
vector envs support partial resets), puts their final observations into the infos and the reset
observations into the batch.  A vector env in ``AutoresetMode.SAME_STEP`` is taken as it is
(its ``final_obs`` / ``final_info`` become the SB3 infos).  ``seed`` / ``set_options`` go to the
next reset, as SB3 documents; the seeds are Gymnasium's (sub-env i gets seed + i).

Desynchronised starts (``desync_steps`` = H > 0): every sub-env starts its episode at t = 0,
so with episodes of T steps and rollouts of n_steps << T every rollout of a fresh vector env
sees all sub-envs at the same time of their episodes, and every episode ends in the same
rollout: the batch is correlated in time.  After each :meth:`reset` of the whole vector env,
sub-env i stands still (action 0) for a number of steps drawn uniformly from [0, H) and is then
reset again, so the first episodes the learner sees start spread over H steps of the clock
(the draws from ``numpy.random.default_rng(desync_seed)``, a fresh generator per reset; a
sub-env whose episode ends while it waits is reset at once).  Rewards of the waiting steps are
discarded.

Infos: one dict per sub-env with the vector env's info entries of that sub-env (where its mask
``_key`` is set), plus the SB3 keys above.  Forming N dicts per step costs Python time that the
native vector env itself does not spend; ``info_keywords`` limits them to the keys named (None:
all; ``()``: only the SB3 keys).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from gymnasium.vector import AutoresetMode
from stable_baselines3.common.vec_env import VecEnv


class SB3VecEnv(VecEnv):
    """An SB3 VecEnv over a Gymnasium VectorEnv (module docstring)."""

    def __init__(self, venv, info_keywords: Sequence[str] | None = None,
                 desync_steps: int = 0, desync_seed: int | None = None):
        self.venv = venv
        self.info_keywords = None if info_keywords is None else tuple(info_keywords)
        if isinstance(desync_steps, bool) or not isinstance(desync_steps, (int, np.integer)) \
                or desync_steps < 0:
            raise ValueError(f"desync_steps = {desync_steps!r}: an integer >= 0 (steps)")
        self.desync_steps, self.desync_seed = int(desync_steps), desync_seed
        mode = venv.metadata.get("autoreset_mode", AutoresetMode.NEXT_STEP)
        if isinstance(mode, str):
            mode = AutoresetMode(mode)
        if mode not in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
            raise ValueError(f"autoreset_mode = {mode}: allowed NEXT_STEP, SAME_STEP (the "
                             "adapter resets finished sub-envs; DISABLED leaves it to the user)")
        self.autoreset_mode = mode
        self._actions = None
        super().__init__(venv.num_envs, venv.single_observation_space,
                         venv.single_action_space)

    # -- helpers ---------------------------------------------------------------------------
    def _split_infos(self, infos: dict, n: int) -> list[dict[str, Any]]:
        out = [{} for _ in range(n)]
        for key, value in infos.items():
            if key.startswith("_") or (self.info_keywords is not None
                                       and key not in self.info_keywords):
                continue
            mask = infos.get("_" + key)
            if isinstance(value, dict):
                sub = self._split_infos(value, n)
                for i in range(n):
                    if mask is None or mask[i]:
                        out[i][key] = sub[i]
                continue
            for i in range(n):
                if mask is None or mask[i]:
                    out[i][key] = value[i]
        return out

    # -- VecEnv API ------------------------------------------------------------------------
    def reset(self):
        seeds = self._seeds
        seed = None if all(s is None for s in seeds) else list(seeds)
        options = self._options[0] if self._options else {}
        obs, infos = self.venv.reset(seed=seed, options=dict(options) or None)
        self.reset_infos = self._split_infos(infos, self.num_envs)
        self._reset_seeds()
        self._reset_options()
        if self.desync_steps:
            obs = self._desynchronise(obs)
        return obs

    def _desynchronise(self, obs: np.ndarray) -> np.ndarray:
        """Sub-env i stands still for a uniform draw of [0, desync_steps) steps, then is reset
        (module docstring); the batch's observations after the last of these resets."""
        n, horizon = self.num_envs, self.desync_steps
        when = np.random.default_rng(self.desync_seed).integers(0, horizon, n)
        zero = np.zeros((n, *self.action_space.shape), self.action_space.dtype)
        for j in range(horizon):
            obs, _, term, trunc, _ = self.venv.step(zero)
            mask = (when == j) | term | trunc
            if mask.any():
                obs, infos = self.venv.reset(options={"reset_mask": mask})
                resets = self._split_infos(infos, n)
                for i in np.flatnonzero(mask):
                    self.reset_infos[i] = resets[i]
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        obs, rew, term, trunc, infos = self.venv.step(self._actions)
        done = np.logical_or(term, trunc)
        if self.autoreset_mode == AutoresetMode.SAME_STEP:
            final_obs = infos.get("final_obs")
            final_info = infos.get("final_info", {})
            dicts = self._split_infos(infos, self.num_envs)
            fin = self._split_infos(final_info, self.num_envs) if final_info else None
            for i in np.flatnonzero(done):
                if fin is not None:
                    dicts[i].update(fin[i])
                dicts[i]["terminal_observation"] = final_obs[i]
                dicts[i]["TimeLimit.truncated"] = bool(trunc[i] and not term[i])
            return obs, rew.astype(np.float32), done, dicts
        dicts = self._split_infos(infos, self.num_envs)
        if done.any():
            final = obs.copy()
            obs_reset, reset_infos = self.venv.reset(options={"reset_mask": done.copy()})
            obs = np.where(done[:, None], obs_reset, obs) if obs.ndim == 2 else obs_reset
            resets = self._split_infos(reset_infos, self.num_envs)
            for i in np.flatnonzero(done):
                dicts[i]["terminal_observation"] = final[i]
                dicts[i]["TimeLimit.truncated"] = bool(trunc[i] and not term[i])
                self.reset_infos[i] = resets[i]
        return obs, rew.astype(np.float32), done, dicts

    def close(self) -> None:
        self.venv.close()

    def _target(self):
        return getattr(self.venv, "unwrapped", self.venv)

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        value = getattr(self._target(), attr_name)
        return [value for _ in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        setattr(self._target(), attr_name, value)

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs):
        method = getattr(self._target(), method_name)
        result = method(*method_args, **method_kwargs)
        return [result for _ in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False for _ in self._get_indices(indices)]

    def get_images(self):
        frame = self.venv.render()
        return [frame] + [None] * (self.num_envs - 1)
