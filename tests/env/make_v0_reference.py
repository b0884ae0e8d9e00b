"""Writes tests/env/data/v0_reference.json: trajectories of ``TelescopicBoomEnv`` (v0) under fixed
action sequences, for both fidelities, which tests/env/test_env_public_api.py replays.

The fixture pins v0's behaviour (observation, reward, flags, stroke and tip deflection of every
step): the test asserts that the env reproduces it to round-off.  Regenerate it only on a
deliberate change of v0's dynamics (and list the change in the env's version history):

    python -m tests.env.make_v0_reference

Episodes (``EPISODES``): uniform random actions from the default start (three and five booms,
the five with other payload, angle and the parameter observation), and a sequence that runs
into the velocity limit and the upper end stop and then reverses (the end-stop velocity jump
and the saturation both act); the full model (``fidelity="paper"``) frictionless and with
friction on shorter episodes (it runs at a few real-time factors).
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np

OUT = Path(__file__).parent / "data" / "v0_reference.json"

#: name -> (constructor kwargs, reset options, action recipe, steps)
EPISODES = {
    "rl3_random": ({}, {}, "random", 100),
    "rl3_stops": ({}, {"stroke_start": 7.5, "stroke_target": 8.0}, "stops", 100),
    "rl5_random": ({"booms": 5, "payload": 12000.0, "luffing_angle_deg": 52.0,
                    "observe_parameters": True}, {}, "random", 100),
    "rl5_stops": ({"booms": 5}, {"stroke_start": 7.5, "stroke_target": 8.0}, "stops", 100),
    "paper3_stops": ({"fidelity": "paper"}, {"stroke_start": 7.5, "stroke_target": 8.0},
                     "stops", 100),
    "paper3_friction": ({"fidelity": "paper", "paper_friction": True}, {}, "random", 30),
    "paper5_random": ({"fidelity": "paper", "booms": 5}, {}, "random", 12),
}


def actions(recipe: str, n: int) -> np.ndarray:
    """(n, 1) float32 actions: 'random' uniform in [-1, 1] (a fixed generator), 'stops' full
    acceleration for half the steps (the rate saturates after 40 steps, the stroke reaches the
    upper end stop from 7.5 m after about 50) and full braking for the rest."""
    if recipe == "random":
        return np.random.default_rng(20240).uniform(-1.0, 1.0, (n, 1)).astype(np.float32)
    a = np.ones((n, 1), np.float32)
    a[n // 2:] = -1.0
    return a


def run(kwargs: dict, options: dict, acts: np.ndarray) -> dict:
    """Reset and step the env through ``acts``; arrays of every step (row 0: the reset)."""
    from boom_env.telescopic_env import TelescopicBoomEnv
    env = TelescopicBoomEnv(**kwargs)
    obs, info = env.reset(seed=0, options=options)
    rec = {"obs": [obs], "reward": [0.0], "terminated": [False], "truncated": [False],
           "stroke": [info["stroke"]], "stroke_rate": [info["stroke_rate"]],
           "tip_deflection": [info["tip_deflection"]], "velocity_saturated": [False],
           "end_stop": [False], "diverged": [False]}
    for a in acts:
        obs, r, term, trunc, info = env.step(a)
        for k, v in (("obs", obs), ("reward", r), ("terminated", term), ("truncated", trunc),
                     ("stroke", info["stroke"]), ("stroke_rate", info["stroke_rate"]),
                     ("tip_deflection", info["tip_deflection"]),
                     ("velocity_saturated", info["velocity_saturated"]),
                     ("end_stop", info["end_stop"]), ("diverged", info["diverged"])):
            rec[k].append(v)
        if term or trunc:
            break
    return {k: np.asarray(v) for k, v in rec.items()}


def main() -> None:
    os.environ.setdefault("SIM_CORE_ELEMENT_WORKER", "on")     # as the test session runs
    arrays = {}
    for name, (kw, opt, recipe, n) in EPISODES.items():
        t0 = time.perf_counter()
        acts = actions(recipe, n)
        rec = run(kw, opt, acts)
        arrays[f"{name}/actions"] = acts
        arrays.update({f"{name}/{k}": v for k, v in rec.items()})
        print(f"{name}: {len(rec['obs']) - 1} steps, {time.perf_counter() - t0:.1f} s, "
              f"saturated {int(rec['velocity_saturated'].sum())}, end stops "
              f"{int(rec['end_stop'].sum())}, max |d| "
              f"{1e3 * np.abs(rec['tip_deflection']).max():.3g} mm")
    OUT.parent.mkdir(exist_ok=True)
    # JSON keeps every float exactly (shortest round-trip repr)
    text = json.dumps({k: v.tolist() for k, v in arrays.items()}, separators=(",", ":"))
    OUT.write_text(text + "\n")
    print(f"wrote {OUT} ({len(text) / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
