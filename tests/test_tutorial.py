"""docs/tutorial.md runs as written: its fenced bash and python blocks are read from the page and
run in order, in an empty folder, each as its own process (bash blocks with ``bash -e``, python
blocks with this interpreter), with this environment's ``python`` and ``boom-sim`` first on
PATH.  Nothing is shortened behind the reader's back: the page itself cuts the runs short
(``--set solver.t_end=2``, a one-rollout training budget).

Each block is followed by an HTML comment saying what the test does with it:
``<!-- tutorial: run -->`` (the default pass), ``<!-- tutorial: run slow -->`` (the slow pass,
which runs every block in order: the crane run and the agent's training) or
``<!-- tutorial: skip (reason) -->`` (the install block).  A block without one fails the test,
so no command of the page goes untested by accident.  After the runs the tests check what the
page says the commands produce."""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "tutorial.md"
FENCE = re.compile(r"^```(\w*)\n(.*?)^```\n(?:<!-- tutorial: ([^>]*?) -->)?", re.S | re.M)


def blocks() -> list[tuple[str, str, str]]:
    """The (language, code, mode) of every fenced block of the page, in order; mode is the
    marker's text ('' where the block has none)."""
    return [(lang, code, mode or "") for lang, code, mode in
            FENCE.findall(PAGE.read_text(encoding="utf-8"))]


def run_block(lang: str, code: str, cwd: Path) -> str:
    """Run one block in ``cwd``; its stdout (the test fails with its stderr on a non-zero
    exit)."""
    env = dict(os.environ)
    env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + env.get("PATH", "")
    argv = (["bash", "-e", "-o", "pipefail", "-c", code] if lang == "bash"
            else [sys.executable, "-c", code])
    proc = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, f"tutorial block failed ({lang}):\n{code}\n{proc.stderr[-4000:]}"
    return proc.stdout


def run_page(cwd: Path, slow: bool) -> list[str]:
    """Run the page's blocks marked ``run`` (and ``run slow`` where ``slow``) in order;
    their stdouts joined per block."""
    outs = []
    for lang, code, mode in blocks():
        if mode == "run" or (slow and mode == "run slow"):
            outs.append(run_block(lang, code, cwd))
    return outs


def test_every_block_is_marked_and_runs_as_bash_or_python():
    found = blocks()
    assert len(found) == PAGE.read_text(encoding="utf-8").count("\n```\n"), \
        "a fenced block the marker pattern does not see"
    for lang, code, mode in found:
        assert mode in ("run", "run slow") or mode.startswith("skip ("), (mode, code)
        assert lang in ("bash", "python"), (lang, code)
    modes = [mode for _, _, mode in found]
    assert sum(m.startswith("skip") for m in modes) == 1, "only the install block is skipped"
    assert "run slow" in modes and modes.count("run") >= 5


@pytest.fixture(scope="module")
def page_run(tmp_path_factory):
    cwd = tmp_path_factory.mktemp("tutorial")
    return cwd, "\n".join(run_page(cwd, slow=False))


def test_the_page_runs_and_its_results_hold_what_it_says(page_run):
    """The default pass: every block marked ``run``, then the facts the page states."""
    from sim_core import Result
    cwd, out = page_run
    ext = cwd / "results" / "extraction"
    for name in ("result.npz", "summary.json", "report.html", "cylinder_forces.png"):
        assert (ext / name).is_file(), name
    summary = json.loads((ext / "summary.json").read_text())
    assert summary["suspect"] is False and set(summary["checks"]) == {
        "constraint_violation", "energy_balance"}
    assert "suspect: False []" in out
    res25 = Result.load(ext / "result.npz")
    res15 = Result.load(cwd / "results" / "extraction_15t" / "result.npz")
    assert res25.t[-1] == pytest.approx(2.0) and res15.t[-1] == pytest.approx(2.0)
    assert res15.scene["payload"]["mass"] == 15000.0
    # the lighter payload: the luffing cylinder holds less at rest (t = 0, same geometry)
    assert res15["luffing_cylinder_force"][0] < res25["luffing_cylinder_force"][0]
    assert not (cwd / "results" / "extraction_15t" / "report.html").exists()

    # your own crane: the renamed scene, the base boom's area that of a regular hexagonal tube
    # of 0.8 m across flats and a 7 mm wall, A = (sqrt(3)/2) (w^2 - (w - 2t)^2), as printed
    # (4 significant digits)
    assert "scene my_crane:" in out
    area = float(re.search(r"^boom 1: .*? A ([0-9.e+-]+) m\^2", out, re.M).group(1))
    w, t = 0.8, 0.007
    assert area == pytest.approx(math.sqrt(3) / 2 * (w ** 2 - (w - 2 * t) ** 2), rel=5e-4)

    # the two refusals the page quotes: a 10 mm base wall leaves 18 mm for the 20 mm pads, a
    # negative payload is out of range (exit status 2, the key named)
    from sim_core import SceneError, load_scene
    page = " ".join(PAGE.read_text(encoding="utf-8").split())
    quoted = re.search(r"a 10 mm wall gives `(.*?)`", page).group(1)
    with pytest.raises(SceneError) as err:
        load_scene(cwd / "my_crane.toml", {"boom.0.section.wall": 0.010})
    assert str(err.value).startswith(quoted)
    proc = subprocess.run([sys.executable, "-m", "sim_core.cli", "describe",
                           "telescopic_extraction", "--set", "payload.mass=-1"],
                          capture_output=True, text=True, cwd=cwd)
    assert proc.returncode == 2 and "payload.mass" in proc.stderr

    # the controller reaches the target within the env's 1 cm and stays within its limits
    stroke = float(re.search(r"L_s = ([0-9.]+) m", out).group(1))
    assert stroke == pytest.approx(8.0, abs=0.01)

    # agents.evaluate: the cubic schedule reaches the target (within 1 cm)
    ev = json.loads((cwd / "evaluation.json").read_text())
    assert set(ev) == {"cubic", "zv_trapezoid"}
    assert ev["cubic"]["final_stroke_error_m"] < 0.01
    assert (cwd / "evaluation.png").is_file()


@pytest.mark.slow
def test_the_whole_page_runs_with_the_crane_run_and_the_training(tmp_path):
    """The slow pass: every block in order, the crane's run and the PPO training included."""
    out = "\n".join(run_page(tmp_path, slow=True))
    summary = json.loads((tmp_path / "results" / "my_crane" / "summary.json").read_text())
    assert summary["scene"] == "my_crane" and summary["suspect"] is False
    run = tmp_path / "my_agents" / "runs" / "ppo_vector" / "seed0"
    assert (run / "model.zip").is_file() and (run / "model_vecnormalize.json").is_file()
    table = (tmp_path / "my_agents" / "baselines.md").read_text()
    assert "`ppo_vector`" in table and "`cubic`" in table
    lines = re.findall(r"^(cubic schedule|PPO): return (-?[0-9.]+) \+- [0-9.]+, success",
                       out, re.M)
    assert [name for name, _ in lines] == ["cubic schedule", "PPO"]
    # as the page says, one rollout of PPO from scratch scores below the paper's schedule
    assert float(lines[1][1]) < float(lines[0][1])
