"""agents: PPO baseline and scripted extraction schedules (not implemented yet; needs boom_env)."""
