"""README's quick start runs top to bottom as written: its python block and its bash block
are read from README.md and run in an empty folder, every scene cut to a short ``t_end``
(the python block's ``load_scene`` gets ``solver.t_end`` on top of its overrides, every
``boom-sim run`` and ``sweep`` an extra ``--set solver.t_end=...`` and ``solver.n_output``
after its own), so that a change to the README's text is what is tested.  The Ray sweep runs in the slow pass."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

import sim_core
from sim_core import cli

ROOT = Path(__file__).resolve().parents[1]
#: simulated time of every quick-start run here, s (the README's runs are longer)
T_END = 0.1
#: output times of every quick-start command line run (few frames to animate and export)
N_OUTPUT = 11


def quick_start() -> list[tuple[str, str]]:
    """The (language, code) blocks of README's "Quick start" section, in order."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("\n## Quick start\n", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```(\w+)\n(.*?)```", section, flags=re.S)


def bash_commands() -> list[list[str]]:
    """The bash block's commands as argument lists (continued lines joined, comments cut)."""
    (code,) = [c for lang, c in quick_start() if lang == "bash"]
    lines = code.replace("\\\n", " ").splitlines()
    return [argv for argv in (shlex.split(line, comments=True) for line in lines) if argv]


def shortened(argv: list[str]) -> list[str]:
    """A README command with the short simulated time and few output times (a later --set
    wins)."""
    assert argv[0] == "boom-sim", argv
    if argv[1] in ("run", "sweep"):
        return [*argv, "--set", f"solver.t_end={T_END}", "--set", f"solver.n_output={N_OUTPUT}"]
    return list(argv)


def test_the_quick_start_has_a_python_and_a_bash_block():
    langs = [lang for lang, _ in quick_start()]
    assert langs == ["python", "bash"], langs
    assert all(argv[0] == "boom-sim" for argv in bash_commands())


def test_the_python_block_runs_as_written(tmp_path, monkeypatch):
    (code,) = [c for lang, c in quick_start() if lang == "python"]
    real = sim_core.load_scene

    def load_scene(name, overrides=None):
        return real(name, {**(overrides or {}), "solver.t_end": T_END})
    monkeypatch.setattr(sim_core, "load_scene", load_scene)
    monkeypatch.chdir(tmp_path)
    ns: dict = {}
    exec(compile(code, "README.md (quick start, python)", "exec"), ns)      # noqa: S102
    res = sim_core.Result.load(tmp_path / "out" / "result.npz")
    assert res.scene["name"] == "telescopic_extraction" and res.t[-1] == pytest.approx(T_END)
    assert ns["sim"].t == pytest.approx(0.05)


def test_the_bash_block_runs_as_written(tmp_path, monkeypatch, capsys):
    """Every command of the bash block but the Ray sweep, in order, in an empty folder: each
    exits with status 0 and writes what the README says it writes."""
    monkeypatch.chdir(tmp_path)
    commands = [argv for argv in bash_commands() if argv[1] != "sweep"]
    assert [argv[1] for argv in commands][:3] == ["list", "describe", "run"]
    for argv in commands:
        capsys.readouterr()
        assert cli.main(shortened(argv)[1:]) == 0, (shlex.join(argv), capsys.readouterr().err)
        if "--resume" in argv:           # nothing was cut short in this folder: a fresh run
            assert "starting from t = 0" in capsys.readouterr().err
    out = tmp_path / "out"
    for path in (out / "result.npz", out / "report.html", out / "anim.gif", tmp_path / "anim.gif",
                 out / "vtk" / "result.pvd", tmp_path / "lift" / "result.npz"):
        assert path.is_file(), path
    # the report written again by `boom-sim report` keeps the run's animation
    assert "data:image/gif;base64," in (out / "report.html").read_text(encoding="utf-8")


@pytest.mark.slow
def test_the_sweep_runs_as_written(tmp_path):
    """The bash block's sweep, run as the command line runs it (its own process, Ray)."""
    (argv,) = [argv for argv in bash_commands() if argv[1] == "sweep"]
    cmd = [sys.executable, "-c", "import sys; from sim_core.cli import main; "
                                 "sys.exit(main(sys.argv[1:]))", *shortened(argv)[1:]]
    done = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-2000:]
    out = tmp_path / argv[argv.index("--out") + 1]
    assert len(list(out.glob("**/result.npz"))) == 9
