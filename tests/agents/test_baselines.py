"""agents.baselines: the --quick run end to end, the table's shape, and the evaluation path
(the scripted rows' returns equal a direct episode-by-episode run of the schedule on the scalar
env)."""

import json

import gymnasium as gym
import numpy as np
import pytest

import boom_env  # noqa: F401
from agents import baselines as B

FAST_ROWS = ["random", "still", "cubic", "trapezoid", "zv_trapezoid", "ppo_vector"]


def _table_lines(path):
    return [ln for ln in path.read_text().splitlines() if ln.startswith("|")]


def _check_table(path):
    lines = _table_lines(path)
    header, sep, body = lines[0], lines[1], lines[2:]
    n = header.count(" | ") + 1
    assert n == len(B.HEADER)
    assert sep.count("|") == n + 1
    assert len(body) == len(B.ROWS)
    for ln in body:
        cells = [c for c in ln.replace("\\|", "").strip("|").split(" | ")]
        assert len(cells) == n, ln


def _direct_returns(name, seed, episodes):
    """Episode returns of the schedule on the scalar v1 env, episode i reset with seed + i."""
    acts = B.schedule_actions(name)
    out = []
    for i in range(episodes):
        env = gym.make(B.ENV_ID, **B.env_kwargs())
        env.reset(seed=seed + i)
        total, k, done = 0.0, 0, False
        while not done:
            a = acts[k] if k < len(acts) else 0.0
            _, r, term, trunc, _ = env.step(np.array([a], np.float32))
            total += r
            done = term or trunc
            k += 1
        out.append(total)
    return np.array(out)


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("baselines")
    assert B.main(["--quick", "--out", str(out), "--rows", *FAST_ROWS]) == 0
    return out


def test_quick_table_shape(quick_run):
    _check_table(quick_run / "baselines.md")
    assert (quick_run / "baselines_training.png").stat().st_size > 0


def test_scripted_rows_equal_direct_evaluation(quick_run):
    for name in B.SCRIPTED:
        rec = json.loads((quick_run / "runs" / "rows" / f"{name}.json").read_text())
        for s, r in rec["seeds"].items():
            got = np.array(r["returns"])
            want = _direct_returns(name, B.eval_seed(int(s)), len(got))
            np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)


def test_rerun_reuses_rows(quick_run):
    path = quick_run / "runs" / "rows" / "cubic.json"
    before = path.stat().st_mtime_ns
    assert B.main(["--quick", "--out", str(quick_run), "--rows", "cubic"]) == 0
    assert path.stat().st_mtime_ns == before
    _check_table(quick_run / "baselines.md")


@pytest.mark.slow
def test_quick_all_rows(tmp_path):
    """The trained rows through RL Zoo and agents.train_ppo (subprocesses, tens of seconds)."""
    assert B.main(["--quick", "--out", str(tmp_path)]) == 0
    _check_table(tmp_path / "baselines.md")
    for row in B.ROWS:
        rec = json.loads((tmp_path / "runs" / "rows" / f"{row}.json").read_text())
        assert all(np.isfinite(r["returns"]).all() for r in rec["seeds"].values())


@pytest.mark.parametrize("fidelity", [B.FULL_FIDELITY, B.TRAIN_FIDELITY])
def test_full_physics_column_runs_the_v1_task_on_the_full_model(fidelity):
    """The transfer column's and the training-fidelity column's episodes: the v1 env at the
    fidelity, reset with the evaluation seed (the ROM column's payload and angle), the policy
    acting on the full model's observation; the returns equal a direct run of the scalar env
    (shortened to 1 s)."""
    seed, kw = B.eval_seed(0), dict(t_max=1.0)
    got = B.full_physics_returns(B.scripted_actor("cubic"), seed, 1, None, fidelity, **kw)
    env = gym.make(B.ENV_ID, fidelity=fidelity, **B.env_kwargs(**kw))
    _, info0 = env.reset(seed=seed)
    acts = B.schedule_actions("cubic")
    total, k, done = 0.0, 0, False
    while not done:
        _, r, term, trunc, info = env.step(np.array([acts[k]], np.float32))
        total += r
        done = term or trunc
        k += 1
    assert k == 20 and info["fidelity"] == fidelity and not info["diverged"]
    assert got == [total]
    rom = gym.make(B.ENV_ID, **B.env_kwargs(**kw))
    _, rinfo = rom.reset(seed=seed)
    assert rinfo["payload"] == info0["payload"]
