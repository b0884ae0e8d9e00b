"""A model folder loads without unpickling anything from it: the VecNormalize statistics are
JSON (agents.model_io), and an SB3 ``.zip`` is loaded with a ``custom_objects`` value for every
cloudpickled entry of its ``data`` JSON.  A pickle payload planted in either (one that would
create a marker file when unpickled) never runs; the committed model loads with the same
statistics and the same actions as SB3's own pickle-based loader."""

from __future__ import annotations

import base64
import io
import json
import pickle
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from agents import model_io as mi  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
MODEL = ROOT / "agents" / "models" / "ppo_extraction.zip"
#: the git blob of the pickled statistics the JSON file replaced
PICKLED_BLOB = "1c9c9d909216ca4ef62ef42fb14136127d0fa406"


class _Marker:
    """Unpickling this object creates the file ``path`` (os.system would do anything)."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (Path.touch, (Path(self.path),))


def test_the_committed_statistics_are_the_pickled_ones():
    """The JSON holds exactly the numbers of the pickled VecNormalize it replaced (read from
    the repository's history, a file of this project)."""
    try:
        raw = subprocess.run(["git", "cat-file", "blob", PICKLED_BLOB], cwd=ROOT,
                             capture_output=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("no git history here")
    vn = pickle.loads(raw)      # noqa: S301 - this project's own blob, by its hash
    st = mi.load_vecnorm(mi.vecnorm_path_for(MODEL))
    for name in ("obs_rms", "ret_rms"):
        a, b = getattr(vn, name), getattr(st, name)
        assert np.array_equal(a.mean, b.mean) and np.array_equal(a.var, b.var)
        assert a.count == b.count
    for k in ("clip_obs", "clip_reward", "gamma", "epsilon", "norm_obs", "norm_reward"):
        assert getattr(vn, k) == getattr(st, k), k
    obs = np.random.default_rng(0).normal(3.0, 2.0, size=(20, 11))
    assert np.array_equal(vn.normalize_obs(obs), st.normalize_obs(obs))


def test_no_pickle_files_are_committed():
    out = subprocess.run(["git", "ls-files", "agents", "boom_env", "benchmarks"], cwd=ROOT,
                         capture_output=True, text=True)
    if out.returncode:
        pytest.skip("no git here")
    assert not [f for f in out.stdout.split() if f.endswith(".pkl")
                and (ROOT / f).exists()]


def test_a_pickled_statistics_file_is_refused_unrun(tmp_path):
    marker = tmp_path / "ran"
    path = tmp_path / "model_vecnormalize.json"
    path.write_bytes(pickle.dumps(_Marker(marker)))
    with pytest.raises(mi.ModelFileError, match="not JSON"):
        mi.load_vecnorm(path)
    assert not marker.exists()


@pytest.mark.parametrize("edit, match", [
    (lambda b: b.pop("obs_rms"), "obs_rms"),
    (lambda b: b["obs_rms"].update(mean="x"), r"obs_rms\.mean"),
    (lambda b: b["obs_rms"].update(var=[1.0, 2.0]), "differ in length"),
    (lambda b: b["obs_rms"].update(var=[-1.0] * 11), r"obs_rms\.var"),
    (lambda b: b.update(clip_obs=float("nan")), "clip_obs"),
    (lambda b: b.update(norm_obs="yes"), "norm_obs"),
    (lambda b: b.update(format="other"), "format")])
def test_malformed_statistics_are_a_one_line_error(tmp_path, edit, match):
    body = json.loads(mi.vecnorm_path_for(MODEL).read_text())
    edit(body)
    path = tmp_path / "s.json"
    path.write_text(json.dumps(body))
    with pytest.raises(mi.ModelFileError, match=match) as err:
        mi.load_vecnorm(path)
    assert "\n" not in str(err.value)


def _with_data(tmp_path, edit) -> Path:
    """A copy of the committed model whose ``data`` JSON is changed by ``edit``."""
    src = zipfile.ZipFile(MODEL)
    data = json.loads(src.read("data"))
    edit(data)
    out = tmp_path / "model.zip"
    with zipfile.ZipFile(out, "w") as z:
        for name in src.namelist():
            z.writestr(name, json.dumps(data) if name == "data" else src.read(name))
    return out


def _payload(marker: Path) -> str:
    import cloudpickle
    return base64.b64encode(cloudpickle.dumps(_Marker(marker))).decode()


@pytest.mark.parametrize("key", ["policy_class", "observation_space", "lr_schedule",
                                 "_last_obs", "ep_info_buffer", "planted_entry"])
def test_a_pickle_payload_in_a_model_zip_never_runs(tmp_path, key):
    from stable_baselines3 import PPO
    marker = tmp_path / "ran"

    def plant(data):
        entry = dict(data.get(key) or {":type:": "<class 'object'>"})
        entry[":serialized:"] = _payload(marker)
        data[key] = entry
    path = _with_data(tmp_path, plant)
    # SB3's own loader would run it (the test's payload is live) ...
    if key in ("_last_obs", "planted_entry"):
        PPO.load(path, device="cpu")
        assert marker.exists()
        marker.unlink()
    # ... the project's loader does not
    model = mi.load_sb3(PPO, path, device="cpu")
    assert not marker.exists()
    assert model.observation_space.shape == (11,)


def test_a_foreign_policy_class_is_refused(tmp_path):
    from stable_baselines3 import PPO

    def plant(data):
        data["policy_class"]["__init__"] = "<function Popen.__init__ at 0x0>"
    with pytest.raises(mi.ModelFileError, match="policy_class"):
        mi.load_sb3(PPO, _with_data(tmp_path, plant), device="cpu")


def test_torch_weights_are_read_weights_only(tmp_path):
    """SB3 reads the .pth members with torch.load(weights_only=True): a pickle payload in
    policy.pth fails to load and does not run."""
    import torch
    from stable_baselines3 import PPO
    marker = tmp_path / "ran"
    src = zipfile.ZipFile(MODEL)
    buf = io.BytesIO()
    torch.save({"x": _Marker(marker)}, buf)
    out = tmp_path / "model.zip"
    with zipfile.ZipFile(out, "w") as z:
        for name in src.namelist():
            z.writestr(name, buf.getvalue() if name == "policy.pth" else src.read(name))
    with pytest.raises(Exception):      # torch's UnpicklingError (weights only)
        mi.load_sb3(PPO, out, device="cpu")
    assert not marker.exists()


def test_the_committed_model_acts_as_sb3_loads_it():
    """Same spaces, schedules and deterministic actions as SB3's own loader (this project's
    own file, so SB3's unpickling is safe here)."""
    from stable_baselines3 import PPO

    from agents.evaluate import PPOPolicy
    ours = mi.load_sb3(PPO, MODEL, device="cpu")
    theirs = PPO.load(MODEL, device="cpu")
    assert ours.observation_space == theirs.observation_space
    assert ours.action_space == theirs.action_space
    assert type(ours.policy) is type(theirs.policy)
    assert ours.clip_range(1.0) == theirs.clip_range(1.0)
    x = np.random.default_rng(1).normal(size=(50, 11)).astype(np.float32)
    assert np.array_equal(ours.predict(x, deterministic=True)[0],
                          theirs.predict(x, deterministic=True)[0])
    # the evaluation's policy finds the JSON statistics beside the model
    pol = PPOPolicy(MODEL)
    assert pol.obs_rms is not None and pol.clip_obs == 10.0


def test_a_constant_schedule_hyper_parameter_loads_as_its_value():
    """RL Zoo saves SAC's learning_rate as a cloudpickled ConstantSchedule; the loader takes its
    value from the JSON field beside the pickle (so SB3 rebuilds its schedule) and unpickles
    nothing; a payload in its ``:serialized:`` field is never read."""
    entry = {":type:": "<class 'stable_baselines3.common.utils.ConstantSchedule'>",
             ":serialized:": "not base64 at all", "val": "0.00073"}
    assert mi.sb3_custom_objects({"learning_rate": entry}) == {"learning_rate": 0.00073}
    with pytest.raises(mi.ModelFileError):
        mi.sb3_custom_objects({"learning_rate": {**entry, "val": "__import__('os')"}})
