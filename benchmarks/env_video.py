"""Side-by-side animation of the v1 env: the paper's cubic schedule against a trained policy
or another stroke schedule, payload swinging on its rope.

    python benchmarks/env_video.py                       # docs/img/v1_cubic_vs_policy.gif
    python benchmarks/env_video.py --other zv_trapezoid --out /tmp/x.gif

Both runs are ``boom_env/TelescopicExtraction-v1`` (25 t, 60 deg, 5 m rope, friction on), the
schedules of :mod:`agents.schedules` turned into actions by their mean acceleration per step;
``--other ppo_vector`` (the default) is the large-batch PPO of the baselines table, training
seed 0, acting deterministically (its model from the run cache agents/runs/baselines that
``python benchmarks/baselines.py`` fills).
Every ``--every``-th frame of the env's ``rgb_array`` render (tip deflection x20, sway x5, as
the titles say) is kept, the two frames put side by side and scaled by ``--scale``; the GIF is
written atomically.  Each panel's caption names its schedule and the episode's return.
"""

from __future__ import annotations

import argparse
import io
import os
import sys
from pathlib import Path

import numpy as np

_HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(_HERE, ".."))
sys.path.insert(0, ROOT)

OUT = os.path.join(ROOT, "docs", "img", "v1_cubic_vs_policy.gif")


def actor(name: str):
    """act(obs (d,), k) -> normalised action of the schedule or trained baseline ``name``."""
    from agents import baselines, schedules
    if name in schedules.NAMES:
        acts = np.concatenate([baselines.schedule_actions(name), [0.0]])
        return lambda obs, k: float(acts[min(k, len(acts) - 1)])
    if name not in baselines.TRAINED or name == "ppo_residual":
        raise SystemExit(f"--other {name!r}: a schedule ({', '.join(schedules.NAMES)}) or "
                         "a trained baseline (ppo_vector, sac, ppo_scratch)")
    cache = baselines.load_cache(Path(ROOT) / "agents" / "runs" / "baselines" / "rows" /
                                 f"{name}.json")
    rec = cache["seeds"].get("0")
    if rec is None:
        raise SystemExit(f"--other {name}: no trained seed 0 in agents/runs/baselines (run "
                         f"python benchmarks/baselines.py --rows {name} --seeds 0)")
    act = baselines.actor_for(name, 0, rec)
    return lambda obs, k: float(np.asarray(act(obs[None], np.array([k]))).ravel()[0])


def run(name: str, every: int, seconds: float):
    import gymnasium as gym

    import boom_env  # noqa: F401
    act = actor(name)
    env = gym.make("boom_env/TelescopicExtraction-v1", render_mode="rgb_array")
    obs, _ = env.reset(seed=0)
    n = int(round(seconds / env.unwrapped.dt))
    frames, ret = [env.render()], 0.0
    for k in range(n):
        obs, r, term, trunc, info = env.step(np.array([act(obs, k)], np.float32))
        ret += info["reward_unscaled"]
        if (k + 1) % every == 0:
            frames.append(env.render())
        if term or trunc:
            break
    env.close()
    return frames, ret


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--other", default="ppo_vector",
                    help="right panel: a schedule (agents.schedules) or a trained baseline "
                         "of the run cache (default %(default)s)")
    ap.add_argument("--every", type=int, default=4, help="keep every n-th step (default 4)")
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--scale", type=float, default=0.6)
    ap.add_argument("--out", default=OUT)
    a = ap.parse_args()
    if a.every < 1 or not a.seconds > 0 or not 0 < a.scale <= 2:
        ap.error("--every >= 1, --seconds > 0, 0 < --scale <= 2")
    from PIL import Image, ImageDraw

    from sim_core.result import atomic_write_bytes
    left, r_left = run("cubic", a.every, a.seconds)
    right, r_right = run(a.other, a.every, a.seconds)
    images = []
    for fl, fr in zip(left, right):
        img = Image.fromarray(np.concatenate([fl, fr], axis=1))
        d = ImageDraw.Draw(img)
        w = fl.shape[1]
        d.text((60, fl.shape[0] - 14), f"cubic (return {r_left:.0f})", fill=(0, 0, 0))
        d.text((w + 60, fl.shape[0] - 14), f"{a.other} (return {r_right:.0f})", fill=(0, 0, 0))
        size = (int(img.width * a.scale), int(img.height * a.scale))
        images.append(img.resize(size, Image.LANCZOS).convert("P", palette=Image.ADAPTIVE))
    buf = io.BytesIO()
    dt_ms = int(round(1000 * 0.05 * a.every))
    images[0].save(buf, format="GIF", save_all=True, append_images=images[1:], duration=dt_ms,
                   loop=0, optimize=True)
    atomic_write_bytes(a.out, buf.getvalue())
    print(f"wrote {a.out} ({len(images)} frames, {len(buf.getvalue()) / 1e6:.1f} MB; returns "
          f"unscaled: cubic {r_left:.1f}, {a.other} {r_right:.1f})")


if __name__ == "__main__":
    main()
