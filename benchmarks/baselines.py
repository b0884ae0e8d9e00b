"""The baselines table of the v1 extraction task in the repository: ``agents.baselines`` with
the repository's paths and the machine state.

    OPENBLAS_NUM_THREADS=1 python benchmarks/baselines.py [--rows ROW ...] [--seeds S ...]
        [--force] [--table-only] [--reeval] [--budget ROW=STEPS] [--full-episodes N]

Writes benchmarks/results/baselines.md (the table, with :func:`_machine.machine_lines`),
docs/img/baselines_training.png (the training curves) and the run cache agents/runs/baselines
(trained models and each row's returns per seed; a rerun reuses finished rows).  The options
and the rows: ``python -m agents.baselines --help``.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

_HERE = Path(__file__).resolve().parent
ROOT = _HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(_HERE))

from _machine import cpu_times, machine_lines  # noqa: E402

from agents.baselines import main as _main  # noqa: E402

DEFAULTS = (ROOT / "benchmarks" / "results" / "baselines.md", ROOT / "agents" / "runs" / "baselines",
            ROOT / "docs" / "img" / "baselines_training.png")


def _snapshot():
    return cpu_times(), os.getloadavg()


def _lines(before, after):
    return machine_lines(before[0], after[0], before[1], after[1])


def main(argv=None) -> int:
    return _main(argv, defaults=DEFAULTS, machine=(_snapshot, _lines))


if __name__ == "__main__":
    raise SystemExit(main())
