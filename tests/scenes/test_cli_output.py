"""The command line's output when it is read by another program or a person."""

import subprocess
import sys


def test_describe_into_a_closed_pipe_is_quiet():
    """`boom-sim describe ... | head -1`: the reader closes the pipe early; the command exits
    0 without a BrokenPipeError traceback."""
    cmd = f"{sys.executable} -m sim_core.cli describe telescopic_extraction | head -1"
    out = subprocess.run(["bash", "-o", "pipefail", "-c", cmd], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "Traceback" not in out.stderr and "BrokenPipe" not in out.stderr
    assert out.stdout.startswith("scene telescopic_extraction:")


def test_progress_bar_has_no_empty_field(tmp_path):
    """The progress bar shows '[mm:ss wall, RTF x]' (no empty ', ,' field)."""
    out = subprocess.run([sys.executable, "-m", "sim_core.cli", "run", "telescopic_extraction_rl",
                          "--out", str(tmp_path), "--set", "solver.t_end=1", "--no-plots"],
                         capture_output=True, text=True, check=True)
    assert ", ," not in out.stderr and "wall" in out.stderr


def test_help_shows_no_rest_markup():
    """`boom-sim --help` and every command's help read as plain text: no reST literals
    (``x``) or roles (:mod:`x`) taken over from the docstrings."""
    from sim_core.cli import main
    import contextlib
    import io
    import pytest
    for args in (["--help"], *([c, "--help"] for c in ("run", "sweep", "list", "describe",
                                                         "plot", "animate", "export", "report"))):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf), pytest.raises(SystemExit) as exc:
            main(args)
        assert exc.value.code == 0
        text = buf.getvalue()
        assert "usage: boom-sim" in text
        assert "``" not in text and ":mod:`" not in text and ":class:`" not in text, (args, text)
