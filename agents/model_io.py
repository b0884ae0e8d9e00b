"""Model folders without pickle: the VecNormalize statistics as JSON and SB3 ``.zip`` models
loaded with every cloudpickled entry replaced.

A model folder is data a user may have downloaded.  Neither loader here runs code from it:

* the normalisation statistics live in ``*_vecnormalize.json`` (:func:`save_vecnorm`,
  :func:`load_vecnorm`): ``obs_rms`` and ``ret_rms`` (mean, var, count), ``clip_obs``,
  ``clip_reward``, ``gamma``, ``epsilon``, ``norm_obs``, ``norm_reward``.  JSON numbers are
  written with ``repr`` and read back as the same float64, so the statistics are identical to
  SB3's pickled ones;
* :func:`load_sb3` reads the ``data`` JSON of an SB3 ``.zip`` first and passes SB3's ``load``
  a ``custom_objects`` entry for every entry SB3 would otherwise unpickle with cloudpickle
  (policy class, spaces, schedules, buffers, last observations): classes from an allow-list
  by name, ``Box`` spaces rebuilt from their JSON fields, constant schedules from their
  value, anything else None.  SB3 reads the ``.pth`` weights with ``torch.load(...,
  weights_only=True)``.  The archive is read once into memory, so the file checked is the
  file loaded.
"""

from __future__ import annotations

import io
import json
import math
import re
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["VECNORM_SUFFIX", "VecNormStats", "save_vecnorm", "load_vecnorm",
           "vecnorm_path_for", "to_vecnormalize", "load_sb3", "sb3_custom_objects",
           "convert_trusted_pickle"]

VECNORM_SUFFIX = "_vecnormalize.json"
_FORMAT = "boom-sim vecnormalize statistics 1"
_MAX_BYTES = 16 << 20                   # a model folder's JSON statistics: a few kB


class ModelFileError(ValueError):
    """A model folder's file is not what the loader reads: one line naming the file, the
    entry and what is wrong."""

    def __init__(self, path, problem: str):
        super().__init__(f"{path}: {problem}")


@dataclass(frozen=True)
class _RMS:
    """Running mean and variance (SB3's RunningMeanStd without its update)."""

    mean: np.ndarray
    var: np.ndarray
    count: float


@dataclass(frozen=True)
class VecNormStats:
    """SB3 VecNormalize's statistics and settings, without its environment."""

    obs_rms: _RMS
    ret_rms: _RMS
    clip_obs: float
    clip_reward: float
    gamma: float
    epsilon: float
    norm_obs: bool
    norm_reward: bool

    def normalize_obs(self, obs: np.ndarray) -> np.ndarray:
        """SB3 ``VecNormalize.normalize_obs``: clip((obs - mean) / sqrt(var + eps), +-clip_obs)
        as float32 where ``norm_obs``, else the observation unchanged."""
        if not self.norm_obs:
            return np.array(obs, copy=True)
        return np.clip((obs - self.obs_rms.mean) / np.sqrt(self.obs_rms.var + self.epsilon),
                       -self.clip_obs, self.clip_obs).astype(np.float32)


def vecnorm_path_for(model_path: str | Path) -> Path:
    """The statistics file beside a model ``DIR/NAME.zip``: ``DIR/NAME_vecnormalize.json``."""
    p = Path(model_path)
    return p.with_name(p.stem + VECNORM_SUFFIX)


def _rms_dict(rms) -> dict:
    return {"mean": np.asarray(rms.mean, dtype=np.float64).tolist(),
            "var": np.asarray(rms.var, dtype=np.float64).tolist(), "count": float(rms.count)}


def save_vecnorm(vn, path: str | Path) -> Path:
    """Write the statistics of a VecNormalize (or a :class:`VecNormStats`) to ``path`` as JSON,
    atomically.  Only a flat Box observation (one ``obs_rms``) is supported."""
    from sim_core.result import atomic_write_bytes
    if isinstance(vn.obs_rms, dict):
        raise ValueError("save_vecnorm: dict observations (one statistic per key) are not "
                         "supported")
    body = {"format": _FORMAT, "obs_rms": _rms_dict(vn.obs_rms), "ret_rms": _rms_dict(vn.ret_rms),
            **{k: float(getattr(vn, k)) for k in ("clip_obs", "clip_reward", "gamma", "epsilon")},
            **{k: bool(getattr(vn, k)) for k in ("norm_obs", "norm_reward")}}
    atomic_write_bytes(path, (json.dumps(body, indent=1) + "\n").encode())
    return Path(path)


def _number(path, body: dict, key: str, lo: float, hi: float) -> float:
    v = body.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
            or not lo <= v <= hi:
        raise ModelFileError(path, f"{key} = {v!r}: must be a finite number in [{lo:g}, {hi:g}]")
    return float(v)


def _rms(path, body: dict, key: str, n: int | None) -> _RMS:
    d = body.get(key)
    if not isinstance(d, dict) or set(d) != {"mean", "var", "count"}:
        raise ModelFileError(path, f"{key}: must be an object with mean, var and count")
    out = []
    for part in ("mean", "var"):
        v = d[part]
        ok = (isinstance(v, (list, float, int)) and not isinstance(v, bool)
              and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                      for x in (v if isinstance(v, list) else [v])))
        a = np.asarray(v, dtype=np.float64) if ok else None
        if a is None or a.ndim > 1 or (n is not None and a.size != n) \
                or not np.all(np.isfinite(a)) or (part == "var" and np.any(a < 0)):
            raise ModelFileError(path, f"{key}.{part}: must be a list of "
                                       f"{n if n is not None else 'the'} finite numbers"
                                       + (" >= 0" if part == "var" else ""))
        out.append(a)
    if out[0].shape != out[1].shape:
        raise ModelFileError(path, f"{key}: mean and var differ in length")
    return _RMS(out[0], out[1], _number(path, d, "count", 0.0, 1e300))


def load_vecnorm(path: str | Path) -> VecNormStats:
    """The statistics written by :func:`save_vecnorm`; :class:`ModelFileError` for a file that
    is not such JSON (wrong types, missing keys, arrays of another length)."""
    path = Path(path)
    with open(path, "rb") as f:
        data = f.read(_MAX_BYTES + 1)
    if len(data) > _MAX_BYTES:
        raise ModelFileError(path, f"larger than {_MAX_BYTES} bytes: not a statistics file")
    try:
        body = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError):
        raise ModelFileError(path, "not JSON text (a pickled VecNormalize? convert it with "
                                   "agents.model_io.convert_trusted_pickle)") from None
    if not isinstance(body, dict) or body.get("format") != _FORMAT:
        raise ModelFileError(path, f"not a statistics file (format must be {_FORMAT!r})")
    obs = _rms(path, body, "obs_rms", None)
    flags = {}
    for k in ("norm_obs", "norm_reward"):
        if not isinstance(body.get(k), bool):
            raise ModelFileError(path, f"{k} = {body.get(k)!r}: must be true or false")
        flags[k] = body[k]
    return VecNormStats(obs_rms=obs, ret_rms=_rms(path, body, "ret_rms", None),
                        clip_obs=_number(path, body, "clip_obs", 0.0, 1e300),
                        clip_reward=_number(path, body, "clip_reward", 0.0, 1e300),
                        gamma=_number(path, body, "gamma", 0.0, 1.0),
                        epsilon=_number(path, body, "epsilon", 0.0, 1.0), **flags)


def to_vecnormalize(stats: VecNormStats, venv):
    """An SB3 VecNormalize around ``venv`` carrying ``stats`` (for further training)."""
    from stable_baselines3.common.running_mean_std import RunningMeanStd
    from stable_baselines3.common.vec_env import VecNormalize
    vn = VecNormalize(venv, norm_obs=stats.norm_obs, norm_reward=stats.norm_reward,
                      clip_obs=stats.clip_obs, clip_reward=stats.clip_reward, gamma=stats.gamma,
                      epsilon=stats.epsilon)
    for name in ("obs_rms", "ret_rms"):
        src, rms = getattr(stats, name), RunningMeanStd(shape=getattr(stats, name).mean.shape)
        rms.mean, rms.var, rms.count = src.mean.copy(), src.var.copy(), src.count
        setattr(vn, name, rms)
    return vn


def convert_trusted_pickle(pkl: str | Path, out: str | Path | None = None) -> Path:
    """Convert a pickled VecNormalize that this machine's own training wrote (RL Zoo's
    ``vecnormalize.pkl``, SB3's checkpoints) to the JSON statistics.  This unpickles: never
    call it on a file from elsewhere."""
    import pickle
    with open(pkl, "rb") as f:
        vn = pickle.load(f)  # noqa: S301 - the caller's own training output only
    out = Path(out) if out is not None else Path(pkl).with_suffix(".json")
    return save_vecnorm(vn, out)


# -- SB3 zip models ------------------------------------------------------------------------------

_CLASS_NAME = re.compile(r"<function (\w+)\.__init__ ")
_CONSTANT = re.compile(r"ConstantSchedule\(val=([-+0-9.eE]+|inf)\)")


def _allowed_classes() -> dict[str, type]:
    """The policy and buffer classes a model may name (SB3's own), by class name."""
    from stable_baselines3 import A2C, DDPG, DQN, PPO, SAC, TD3
    from stable_baselines3.common import buffers
    out = {c.__name__: c for algo in (A2C, DDPG, DQN, PPO, SAC, TD3)
           for c in algo.policy_aliases.values()}
    out.update({c.__name__: c for c in (buffers.RolloutBuffer, buffers.DictRolloutBuffer,
                                        buffers.ReplayBuffer, buffers.DictReplayBuffer)})
    return out


def _array_text(path, key: str, text, n: int, dtype) -> np.ndarray:
    try:
        a = np.array(str(text).strip().strip("[]").split(), dtype=dtype)
    except (TypeError, ValueError):
        a = None
    if a is None or a.size != n:
        raise ModelFileError(path, f"data entry {key!r}: bounds are not {n} numbers")
    return a


def _box(path, key: str, entry: dict):
    from gymnasium import spaces
    if entry.get(":type:") != "<class 'gymnasium.spaces.box.Box'>":
        raise ModelFileError(path, f"data entry {key!r}: a {entry.get(':type:')!s:.60}, the "
                                   "loader reads Box spaces only")
    shape = entry.get("_shape")
    dtype = entry.get("dtype")
    if not (isinstance(shape, list) and shape and all(isinstance(s, int) and 0 < s <= 1 << 20
                                                      for s in shape)) \
            or dtype not in ("float32", "float64"):
        raise ModelFileError(path, f"data entry {key!r}: shape {shape!r:.60} or dtype "
                                   f"{dtype!r:.30} is not a float Box's")
    n = int(np.prod(shape))
    low, high = (_array_text(path, key, entry.get(b), n, dtype).reshape(shape)
                 for b in ("low", "high"))
    return spaces.Box(low=low, high=high, shape=tuple(shape), dtype=dtype)


def _schedule(path, key: str, entry: dict, data: dict):
    m = _CONSTANT.fullmatch(str(entry.get("value_schedule", "")))
    if m:
        return float(m.group(1))
    if key == "lr_schedule" and isinstance(data.get("learning_rate"), (int, float)):
        return float(data["learning_rate"])      # SB3 rebuilds it from learning_rate
    raise ModelFileError(path, f"data entry {key!r}: only constant schedules load without "
                               "unpickling")


def _finite(path, key: str, value) -> float:
    """A finite number from a JSON field (SB3 writes some as text)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = float("nan")
    if not np.isfinite(x):
        raise ModelFileError(path, f"data entry {key!r}: {value!r:.40} is not a finite number")
    return x


def sb3_custom_objects(data: dict, path="model") -> dict:
    """``custom_objects`` for SB3's ``load`` holding a value for every cloudpickled entry of a
    model's ``data`` JSON (so that SB3 unpickles none)."""
    allowed = None
    out = {}
    for key, entry in data.items():
        if not (isinstance(entry, dict) and ":serialized:" in entry):
            continue
        if key in ("observation_space", "action_space"):
            out[key] = _box(path, key, entry)
        elif key in ("policy_class", "rollout_buffer_class", "replay_buffer_class"):
            allowed = allowed or _allowed_classes()
            m = _CLASS_NAME.match(str(entry.get("__init__", "")))
            if not m or m.group(1) not in allowed:
                raise ModelFileError(path, f"data entry {key!r}: not one of the classes of "
                                           "stable_baselines3 the loader allows")
            out[key] = allowed[m.group(1)]
        elif key in ("lr_schedule", "clip_range", "clip_range_vf", "exploration_schedule"):
            out[key] = _schedule(path, key, entry, data)
        elif str(entry.get(":type:", "")).endswith(".ConstantSchedule'>"):
            out[key] = _finite(path, key, entry.get("val"))   # a constant-schedule hyper-parameter
        elif key == "train_freq":
            # TrainFreq(frequency, unit) is in the pickle only; acting does not use it, so it
            # loads as every step (pass custom_objects={"train_freq": ...} to train on)
            out[key] = 1
        else:                   # last observations, episode buffers, noise: rebuilt by learn()
            out[key] = None
    return out


def load_sb3(cls, path: str | Path, **kwargs):
    """``cls.load(path, **kwargs)`` (cls: an SB3 algorithm) without unpickling anything of the
    archive; :class:`ModelFileError` for an archive it cannot read that way."""
    path = Path(path)
    raw = path.read_bytes()
    try:
        with zipfile.ZipFile(io.BytesIO(raw)) as z:
            data = json.loads(z.read("data").decode("utf-8"))
    except (zipfile.BadZipFile, KeyError, UnicodeDecodeError, ValueError):
        raise ModelFileError(path, "not a Stable-Baselines3 model archive (no readable 'data' "
                                   "entry)") from None
    if not isinstance(data, dict):
        raise ModelFileError(path, "the 'data' entry is not a JSON object")
    custom = {**sb3_custom_objects(data, path), **kwargs.pop("custom_objects", {})}
    return cls.load(io.BytesIO(raw), custom_objects=custom, **kwargs)
