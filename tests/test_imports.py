"""``import sim_core`` and its command line stay light: the simulator imports neither the
reinforcement-learning stack (torch, gymnasium, stable_baselines3) nor Ray, which
:mod:`sim_core.sweep` imports only when a sweep runs."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("torch", "gymnasium", "ray", "stable_baselines3")


def test_sim_core_and_its_cli_import_no_rl_stack_nor_ray():
    code = ("import json, sys\n"
            "import sim_core, sim_core.cli, sim_core.sweep\n"
            f"print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))\n")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [env.get("PYTHONPATH")] if p])
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout.strip().splitlines()[-1]) == []

