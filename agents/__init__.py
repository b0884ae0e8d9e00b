"""agents: a PPO baseline (Stable-Baselines3) that learns a telescopic extraction schedule on
``boom_env/TelescopicExtraction-v0``, and scripted schedules through the same env.

* ``agents.schedules`` — the paper's cubic schedule, a trapezoid of the same duration, a
  zero-vibration (ZV) shaped trapezoid tuned to the first bending mode.
* ``agents.train_ppo`` — ``python -m agents.train_ppo --timesteps N --seed S --out DIR``.
* ``agents.evaluate`` — ``python -m agents.evaluate --model PATH --episodes K --json``.
* ``agents.report`` — learning curves of several seeds and the comparison table.
* ``agents.wrappers`` — the acceleration-increment action of the PPO agent.
"""
