"""boom_env: Gymnasium environments on top of sim_core (telescopic extraction/retraction).

    import gymnasium as gym
    env = gym.make("boom_env:boom_env/TelescopicExtraction-v0")   # imports boom_env, which registers the ids
    import boom_env  # noqa: F401  (or import it first and use the plain ids)
    env = gym.make("boom_env/TelescopicExtraction-v0")            # fidelity="rl" (modal ROM)
    env = gym.make("boom_env/TelescopicRetraction-v0", fidelity="paper")   # full model, slow

See boom_env.telescopic_env for observation, action, reward, start state and episode end.
"""

from gymnasium.envs.registration import register, registry

from .telescopic_env import TelescopicBoomEnv

DT = 0.05                  # s, control step (default of TelescopicBoomEnv)
T_MAX = 30.0               # s, episode length
MAX_EPISODE_STEPS = int(round(T_MAX / DT))

for _id, _task in (("boom_env/TelescopicExtraction-v0", "extraction"),
                   ("boom_env/TelescopicRetraction-v0", "retraction")):
    if _id not in registry:
        register(id=_id, entry_point="boom_env.telescopic_env:TelescopicBoomEnv",
                 max_episode_steps=MAX_EPISODE_STEPS,
                 kwargs={"task": _task, "dt": DT, "t_max": T_MAX})

# v1: the payload swings on its hoist rope (boom_env.telescopic_sway_env); gym.make_vec makes the
# native vector env (boom_env.vector_env) by default
for _id, _task in (("boom_env/TelescopicExtraction-v1", "extraction"),
                   ("boom_env/TelescopicRetraction-v1", "retraction")):
    if _id not in registry:
        register(id=_id, entry_point="boom_env.telescopic_sway_env:TelescopicSwayEnv",
                 vector_entry_point="boom_env.vector_env:TelescopicSwayVectorEnv",
                 max_episode_steps=MAX_EPISODE_STEPS,
                 kwargs={"task": _task, "dt": DT, "t_max": T_MAX})

__all__ = ["TelescopicBoomEnv", "MAX_EPISODE_STEPS"]
