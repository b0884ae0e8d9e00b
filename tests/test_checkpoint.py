"""Checkpoint and resume of a single run (:mod:`sim_core.checkpoint`, ``boom-sim run
--checkpoint-every S``, ``--resume``).

The claim tested: a run killed with SIGKILL and resumed from its last checkpoint gives the
result of the uninterrupted run bit for bit (every output array and the output times equal,
np.array_equal), for every system kind and integration path; no tolerance is needed because
the checkpoint holds the integrator's whole state (scipy's solver objects without their
callables, the RK45/BDF switch, generalized-alpha's state, the model's warm starts), so the
resumed process takes exactly the same steps.  The runs are real ``boom-sim`` processes,
killed from outside once a checkpoint past a third of the run is on disk.  Also: a resume
of a changed scene, a missing, truncated or corrupt checkpoint, or one whose body has a valid
checksum but not the structure its integration path writes, exit with status 2 and one
line; a writer killed half-way through a checkpoint leaves the previous one whole.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from sim_core import cli, load_scene, simulate
from sim_core import checkpoint as ck
from sim_core.checkpoint import CheckpointError, CheckpointPolicy, decode, encode
from sim_core.result import Result

ROOT = Path(__file__).resolve().parents[1]

# the sleeve scene, short (numpy generalized-alpha, error-controlled: the beam kind's default
# path; ~200 steps)
BEAM = ["beam_through_sleeve", "--set", "solver.t_end=0.02", "--set", "effects.filtering=false",
        "--set", "beams.0.n_nodes=5", "--set", "solver.n_output=11"]
# the cantilever, compiled fixed-step generalized-alpha
CANTILEVER = ["cantilever_release", "--set", "solver.t_end=2"]
# the folding manipulator: BDF with the structured Jacobian (~250 steps)
FOLDING = ["folding_boom", "--set", "solver.t_end=2", "--set", "solver.n_output=21"]
# the paper's crane: "auto" (RK45, two switches to BDF and back within the first second)
TELESCOPIC = ["telescopic_extraction", "--set", "solver.t_end=1", "--set", "solver.n_output=11"]


def _env(**extra) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    env["MPLBACKEND"] = "Agg"
    env.pop(ck.FAULT_ENV, None)
    env.update(extra)
    return env


def _command(scene_args, out: Path, *more: str) -> list[str]:
    return [sys.executable, "-m", "sim_core.cli", "run", *scene_args, "--out", str(out),
            "--quiet", "--no-plots", "--no-report", *more]


def boom_sim_run(scene_args, out: Path, *more: str, timeout: float = 300.0, **env):
    return subprocess.run(_command(scene_args, out, *more), capture_output=True, text=True,
                          env=_env(**env), cwd=ROOT, timeout=timeout)


def t_end_of(scene_args) -> float:
    return float(next(a.split("=", 1)[1] for a in scene_args if a.startswith("solver.t_end=")))


def run_and_kill(scene_args, out: Path, every: str = "0.05", past: float = 1 / 3,
                 timeout: float = 300.0) -> float:
    """Start a run with checkpoints every ``every`` wall seconds, SIGKILL it once a checkpoint
    past ``past`` of t_end is on disk; returns the time of the checkpoint seen."""
    t_end = t_end_of(scene_args)
    proc = subprocess.Popen(_command(scene_args, out, "--checkpoint-every", every),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=_env(), cwd=ROOT)
    path = out / "checkpoint.pkl"
    deadline = time.monotonic() + timeout
    seen = -1.0
    try:
        while seen < past * t_end:
            if proc.poll() is not None:
                pytest.fail(f"the run ended (status {proc.returncode}) before a checkpoint past "
                            f"t = {past * t_end:g} s was seen (last: {seen:g} s): "
                            f"{proc.stderr.read()[-2000:]}")
            if time.monotonic() > deadline:
                pytest.fail("no checkpoint within the timeout")
            try:
                seen = decode(path.read_bytes(), path)["t"]
            except FileNotFoundError:
                pass
            time.sleep(0.01)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        proc.stdout.close()
        proc.stderr.close()
    assert proc.returncode == -signal.SIGKILL
    assert not (out / "result.npz").exists()
    return seen


def assert_same_result(a: Result, b: Result) -> None:
    """Bit-identical outputs: the same output times and every output array equal."""
    assert np.array_equal(a.t, b.t)
    assert sorted(a.keys()) == sorted(b.keys())
    for k in a.keys():
        x, y = np.asarray(a[k]), np.asarray(b[k])
        assert x.shape == y.shape and np.array_equal(x, y, equal_nan=True), \
            f"{k}: largest difference {np.nanmax(np.abs(x - y)) if x.shape == y.shape else None}"


def reference_run(scene_args, out: Path) -> Result:
    """The uninterrupted run, without checkpoints."""
    ref = boom_sim_run(scene_args, out, "--checkpoint-every", "0")
    assert ref.returncode == 0, ref.stderr
    return Result.load(out / "result.npz")


@pytest.fixture(scope="module")
def beam_reference(tmp_path_factory) -> Result:
    return reference_run(BEAM, tmp_path_factory.mktemp("beam_ref"))


def kill_resume_compare(scene_args, tmp_path: Path, reference: Result | None = None,
                        every: str = "0.05") -> dict:
    """The uninterrupted run (no checkpoints) against a run with checkpoints every ``every``
    wall seconds, killed past a third and resumed."""
    if reference is None:
        reference = reference_run(scene_args, tmp_path / "ref")
    out = tmp_path / "killed"
    seen = run_and_kill(scene_args, out, every)
    resumed = boom_sim_run(scene_args, out, "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert_same_result(reference, Result.load(out / "result.npz"))
    summary = json.loads((out / "summary.json").read_text())
    # it did resume, from the checkpoint seen or a later one, before t_end
    assert seen <= summary["resumed_from_s"] < t_end_of(scene_args)
    assert not (out / "checkpoint.pkl").exists()      # the finished run removed it
    return summary


# -- kill and resume, every kind -----------------------------------------------------------------

def test_beam_numpy_alpha_killed_and_resumed_is_bit_identical(tmp_path, beam_reference):
    summary = kill_resume_compare(BEAM, tmp_path, beam_reference)
    assert summary["method"] == "generalized_alpha" and not summary["compiled"]


@pytest.mark.slow
def test_beam_compiled_fixed_alpha_killed_and_resumed_is_bit_identical(tmp_path):
    summary = kill_resume_compare(CANTILEVER, tmp_path)
    assert summary["method"] == "generalized_alpha" and summary["compiled"]


@pytest.mark.slow
def test_folding_bdf_killed_and_resumed_is_bit_identical(tmp_path):
    summary = kill_resume_compare(FOLDING, tmp_path, every="0.2")
    assert summary["method"] == "BDF"


@pytest.mark.slow
def test_telescopic_auto_killed_and_resumed_is_bit_identical(tmp_path):
    summary = kill_resume_compare(TELESCOPIC, tmp_path, every="0.5")
    assert summary["method"] == "auto" and summary["n_method_switches"] >= 2


# -- every integration path, in-process (a run stopped after a checkpoint, then resumed) ----------

class _Stop(BaseException):
    """Ends an in-process run after a checkpoint (as a kill would: nothing else is written)."""


def stopped_after(scene: dict, path: Path, monkeypatch, n: int = 1, every: float = 1e-9):
    """Run ``scene`` with checkpoints every ``every`` wall seconds, stopped after the n-th."""
    save = ck.Checkpointer.save

    def save_then_stop(self, *args):
        save(self, *args)
        if self.n_written >= n:
            raise _Stop()

    monkeypatch.setattr(ck.Checkpointer, "save", save_then_stop)
    with pytest.raises(_Stop):
        simulate(scene, checkpoint=CheckpointPolicy(path, every_s=every))
    monkeypatch.setattr(ck.Checkpointer, "save", save)
    assert path.is_file()


ADAPTIVE_CANTILEVER = "adaptive cantilever"
PATHS = {   # (scene, overrides, checkpoints before the stop, their interval s)
    "numpy alpha, error control": (BEAM[0], dict(a.split("=", 1) for a in BEAM[2::2]), 20, 1e-9),
    "numpy alpha, fixed h": (BEAM[0], {**dict(a.split("=", 1) for a in BEAM[2::2]),
                                       "solver.h": "1e-4"}, 60, 1e-9),
    "compiled alpha, fixed h": ("cantilever_release", {"solver.t_end": "0.1",
                                                       "solver.n_output": "21"}, 8, 1e-9),
    "compiled alpha, error control": (ADAPTIVE_CANTILEVER, {"solver.t_end": "0.6",
                                                            "solver.rtol": "1e-5",
                                                            "solver.atol": "1e-7"}, 1, 1e-9),
    "RK45": (BEAM[0], {**dict(a.split("=", 1) for a in BEAM[2::2]), "solver.t_end": "0.004",
                       "solver.method": "RK45"}, 60, 1e-9),
    "BDF": ("folding_boom", {"solver.t_end": "0.5", "solver.n_output": "11"}, 5, 1e-9),
    "ROS2": ("telescopic_extraction", {"booms.n_nodes": "3", "solver.method": "ROS2",
                                       "solver.t_end": "1.0", "solver.n_output": "21",
                                       "solver.jacobian_interval": "0.3"}, 7, 1e-9),
}


@pytest.mark.parametrize("path", list(PATHS))
def test_every_integration_path_resumes_bit_identically(path, tmp_path, monkeypatch):
    name, overrides, n, every = PATHS[path]
    if name == ADAPTIVE_CANTILEVER:     # the cantilever without its fixed step
        text = (ROOT / "sim_core" / "scenes" / "cantilever_release.toml").read_text()
        name = tmp_path / "cantilever_adaptive.toml"
        name.write_text("\n".join(ln for ln in text.splitlines() if not ln.startswith("h = ")))
    scene = load_scene(name, overrides)
    reference = simulate(scene)
    policy = CheckpointPolicy(tmp_path / "checkpoint.pkl", every_s=1e9)
    stopped_after(scene, policy.path, monkeypatch, n, every)
    t_stop = decode(policy.path.read_bytes(), policy.path)["t"]
    resumed = simulate(scene, checkpoint=policy, resume=True)
    assert 0.0 < resumed.stats["resumed_from_s"] == t_stop < scene["solver"]["t_end"]
    assert_same_result(reference, resumed)
    for key in ("n_steps", "n_rhs"):            # the work of the whole run is counted
        assert resumed.stats.get(key) == reference.stats.get(key)


# -- atomic writes -------------------------------------------------------------------------------

def test_writer_killed_mid_write_leaves_the_previous_checkpoint(tmp_path, beam_reference):
    """The fault hook kills the process half-way through its second checkpoint: the first
    is whole (it loads), the half-written temporary is beside it; the resume removes that
    temporary and finishes with the uninterrupted result."""
    out = tmp_path / "run"
    marker = tmp_path / "marker"
    killed = boom_sim_run(BEAM, out, "--checkpoint-every", "0.05",
                          **{ck.FAULT_ENV: f"kill-during:{marker}"})
    assert killed.returncode == -signal.SIGKILL and marker.exists()
    path = out / "checkpoint.pkl"
    payload = decode(path.read_bytes(), path)          # the previous checkpoint, whole
    assert 0.0 < payload["t"] < t_end_of(BEAM)
    stale = [p for p in out.iterdir() if p.name.startswith(".checkpoint.pkl.")]
    assert len(stale) == 1 and 0 < stale[0].stat().st_size
    with pytest.raises(CheckpointError, match="not a boom-sim checkpoint|truncated"):
        decode(stale[0].read_bytes(), stale[0])         # the half-written one is no checkpoint
    resumed = boom_sim_run(BEAM, out, "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert not [p for p in out.iterdir() if p.name.startswith(".")]
    assert_same_result(beam_reference, Result.load(out / "result.npz"))


# -- refusals: one line, exit status 2 -----------------------------------------------------------

@pytest.fixture
def checkpointed(tmp_path, monkeypatch):
    """OUT/checkpoint.pkl of the short beam run, written in-process, the run stopped after it."""
    out = tmp_path / "run"
    scene = load_scene(BEAM[0], dict(a.split("=", 1) for a in BEAM[2::2]))
    stopped_after(scene, out / "checkpoint.pkl", monkeypatch)
    return out


def _one_line_error(capsys, *parts: str) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("boom-sim: error: checkpoint "), err
    for p in parts:
        assert p in err[0], err[0]
    return err[0]


def test_resume_of_a_changed_scene_is_refused(checkpointed, capsys):
    before = (checkpointed / "checkpoint.pkl").read_bytes()
    args = ["run", *BEAM, "--set", "solver.rtol=1e-5", "--out", str(checkpointed), "--quiet",
            "--no-plots", "--no-report", "--resume"]
    assert cli.main(args) == 2
    _one_line_error(capsys, "another scene", "SHA-256")
    assert (checkpointed / "checkpoint.pkl").read_bytes() == before    # left as it was
    assert not (checkpointed / "result.npz").exists()


def test_resume_without_a_checkpoint_starts_from_zero(tmp_path, capsys):
    """--resume where no checkpoint exists runs from t = 0, says so, and gives the result of
    the same run without --resume."""
    args = ["run", *BEAM, "--quiet", "--no-plots", "--no-report"]
    assert cli.main([*args, "--out", str(tmp_path / "empty"), "--resume"]) == 0
    err = capsys.readouterr().err
    assert "no checkpoint in" in err and "starting from t = 0" in err
    assert cli.main([*args, "--out", str(tmp_path / "plain")]) == 0
    resumed = Result.load(tmp_path / "empty" / "result.npz")
    plain = Result.load(tmp_path / "plain" / "result.npz")
    assert np.array_equal(resumed.t, plain.t) and resumed.t[-1] == 0.02
    for name in plain.outputs:
        np.testing.assert_array_equal(resumed[name], plain[name], err_msg=name)


@pytest.mark.parametrize("damage", ["truncated", "flipped", "garbage", "foreign object"])
def test_damaged_checkpoint_is_a_typed_one_line_error(checkpointed, capsys, damage):
    path = checkpointed / "checkpoint.pkl"
    data = path.read_bytes()
    if damage == "truncated":
        data = data[:len(data) // 2]
    elif damage == "flipped":
        i = len(data) - 100
        data = data[:i] + bytes([data[i] ^ 0xFF]) + data[i + 1:]
    elif damage == "garbage":
        data = b"\x00" * 100
    else:       # a well-formed file whose pickle names a class: refused by the unpickler
        data = encode({"fingerprint": "x", "driver": "scipy", "t": 0.0, "versions": {},
                       "state": Path("x")})
    path.write_bytes(data)
    with pytest.raises(CheckpointError) as err:
        decode(data, path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)
    args = ["run", *BEAM, "--out", str(checkpointed), "--quiet", "--no-plots", "--no-report",
            "--resume"]
    assert cli.main(args) == 2
    line = _one_line_error(capsys)
    assert any(w in line for w in ("truncated or corrupt", "not a boom-sim checkpoint",
                                   "corrupt body")), line


def _malform(payload: dict, damage: str) -> dict:
    """The beam's checkpoint body (numpy generalized-alpha, error control) with one kind of
    damage that a correct checksum over it does not reveal."""
    st = payload["state"]
    if damage == "state missing a key":
        del st["ga"]
    elif damage == "nested key missing":
        del st["ga"]["ga"]["q"]
    elif damage == "number as text":
        st["wall_s"] = "12"
    elif damage == "time not finite":
        payload["t"] = float("nan")
    elif damage == "unknown path":
        payload["driver"] = "euler"
    elif damage == "state a list":
        payload["state"] = [1, 2]
    elif damage == "array of another length":
        st["ga"]["ga"]["v"] = np.zeros(st["ga"]["ga"]["q"].size + 1)
    elif damage == "integers for floats":
        st["shim_y"] = st["shim_y"].astype(np.int64)
    elif damage == "matrix for a vector":
        st["stall"]["times"] = np.zeros((3, 3))
    elif damage == "output rows of the wrong shape":
        st["ga"]["out"]["ys"] = [(np.zeros(2),) * 3]
    return payload


@pytest.mark.parametrize("damage", [
    "state missing a key", "nested key missing", "number as text", "time not finite",
    "unknown path", "state a list", "array of another length", "integers for floats",
    "matrix for a vector", "output rows of the wrong shape"])
def test_a_malformed_body_with_a_valid_checksum_is_a_one_line_refusal(checkpointed, capsys,
                                                                      damage):
    """A body that unpickles (numbers, containers, arrays) under a correct checksum but does
    not have the structure its integration path writes: refused with the damaged files'
    error (exit 2, one line naming what is wrong), never a traceback."""
    path = checkpointed / "checkpoint.pkl"
    data = encode(_malform(decode(path.read_bytes(), path), damage))
    path.write_bytes(data)
    with pytest.raises(CheckpointError, match="corrupt body") as err:
        decode(data, path)
    assert "\n" not in str(err.value)
    args = ["run", *BEAM, "--out", str(checkpointed), "--quiet", "--no-plots", "--no-report",
            "--resume"]
    assert cli.main(args) == 2
    _one_line_error(capsys, "corrupt body", "remove it and run without --resume")
    assert not (checkpointed / "result.npz").exists()


def test_a_restored_solver_attribute_keeps_its_shape_and_kind(tmp_path):
    """scipy's solver state is put back attribute by attribute: an array of another shape or
    kind, or text for a number, is refused before anything is set."""
    class Solver:
        def __init__(self):
            self.y, self.h_abs, self.status = np.zeros(4), 0.1, "running"

    for bad in ({"y": np.zeros(5)}, {"y": np.zeros(4, dtype=np.int64)}, {"y": [0.0] * 4},
                {"h_abs": "0.1"}, {"h_abs": np.zeros(2)}):
        s = Solver()
        with pytest.raises(CheckpointError, match="corrupt body"):
            ck.restore_object_state(s, {"status": "failed", **bad})
        assert s.status == "running"            # nothing set
    s = Solver()
    ck.restore_object_state(s, {"y": np.ones(4), "h_abs": np.float64(0.2), "status": "done",
                                "h_previous": 0.05})
    assert s.y.tolist() == [1.0] * 4 and s.h_abs == 0.2 and s.h_previous == 0.05


def test_a_pickled_function_never_loads(tmp_path):
    """The restricted unpickler refuses anything outside numbers, containers and arrays (a
    pickle naming a function would call it on loading)."""
    data = encode({"fingerprint": "x", "driver": "scipy", "t": 0.0, "versions": {},
                   "state": os.system})
    with pytest.raises(CheckpointError, match=r"corrupt body \(UnpicklingError: unexpected "
                                              r"object posix\.system\)"):
        decode(data, tmp_path / "c.pkl")


def test_auto_resume_ignores_a_checkpoint_of_another_scene(checkpointed):
    """The sweeps' retries resume with ``"auto"``: a checkpoint of another scene is ignored
    and the run starts at t = 0 (no ``resumed_from_s``)."""
    scene = load_scene(BEAM[0], {**dict(a.split("=", 1) for a in BEAM[2::2]),
                                 "solver.rtol": "1e-5"})
    res = simulate(scene, checkpoint=CheckpointPolicy(checkpointed / "checkpoint.pkl",
                                                      every_s=1e9), resume="auto")
    assert "resumed_from_s" not in res.stats and res.t[-1] == pytest.approx(0.02)


def test_modal_scene_refuses_an_explicit_checkpoint_and_runs_by_default(tmp_path, capsys):
    args = ["run", "telescopic_extraction_rl", "--set", "solver.t_end=1", "--out",
            str(tmp_path / "rl"), "--quiet", "--no-plots", "--no-report"]
    assert cli.main(args + ["--checkpoint-every", "5"]) == 2
    _one_line_error(capsys, "model.reduction = 'modal'", "runs without checkpoints")
    assert cli.main(args) == 0                  # the default policy: no checkpoint, no error
    assert (tmp_path / "rl" / "result.npz").is_file()
    assert not (tmp_path / "rl" / "checkpoint.pkl").exists()


def test_bad_checkpoint_interval_is_refused(tmp_path, capsys):
    assert cli.main(["run", *BEAM, "--out", str(tmp_path), "--checkpoint-every", "-1"]) == 2
    assert "--checkpoint-every -1" in capsys.readouterr().err
    with pytest.raises(ValueError, match="every_s"):
        CheckpointPolicy(tmp_path / "c.pkl", every_s=0.0)
