"""Tip velocity of the folding boom for several stress-filter windows h (SIMULTECH 2020: the paper
compares h = 0, 0.001, 0.002, 0.005 s; h = 0 is not run: without the filter the axial modes
force RK45 to ~1e-6 s steps).

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/folding_filter_h.py [--h 0.001 0.002 0.005]

Scenario: the short luffing window of tests/folding/test_filter.py (2 sub-elements per boom,
gravity off, the Eq. 52 profile compressed to 0.1 s phases so that its acceleration jumps excite
the booms, 0.6 s), the same for every h.  Writes benchmarks/results/folding_filter_h/
tip_velocity_h.png (the sim_core figure, one line per h), tip_velocity_spectrum.png (energy
spectrum of the tip velocity, Hann window) and summary.csv (h, RHS evaluations, steps, wall s,
energy above 20 Hz).  ~20 min on the shared 2-core machine.
"""

from __future__ import annotations

import argparse
import csv
import io
import time
from pathlib import Path

import numpy as np

from sim_core.figures import save_figure
from sim_core.result import atomic_write_bytes
from sim_core.systems.folding.build import FoldingParams, simulate_folding
from sim_core.systems.folding.plots import plot_folding

OUT = Path(__file__).parent / "results" / "folding_filter_h"


def run(h: float):
    p = FoldingParams(n_nodes=3, gravity=0.0, filter_h=h, t1=0.1, t2=0.1, t3=0.1,
                      stage_starts=(0.0, 10.0, 20.0), cyl1_stroke=0.05, rest_k=0.0)
    return simulate_folding(p, t_end=0.6, n_output=601, rtol=1e-6, atol=1e-8)


def spectrum(res):
    v = res["tip_velocity"]
    dt = res.t[1] - res.t[0]
    V = np.fft.rfft((v - v.mean(axis=0)) * np.hanning(len(res.t))[:, None], axis=0)
    return np.fft.rfftfreq(len(res.t), dt), np.sum(np.abs(V) ** 2, axis=1)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, nargs="+", default=[0.001, 0.002, 0.005])
    args = ap.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    runs, rows = {}, []
    for h in args.h:
        t0 = time.perf_counter()
        res = run(h)
        wall = time.perf_counter() - t0
        runs[h] = res
        f, S = spectrum(res)
        rows.append((h, res.stats["n_rhs"], res.stats["n_steps"], round(wall, 1),
                     float(np.sum(S[f > 20.0]))))
        print(rows[-1], flush=True)
    first = runs[args.h[0]]
    first.scene = {"name": "folding (luffing window)"}
    plot_folding(first, OUT, h_runs=runs)
    for name in ("tip_displacement.png", "folding_cylinders.png"):
        (OUT / name).unlink(missing_ok=True)            # only the h comparison is wanted here
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4))
    for h, res in sorted(runs.items()):
        f, S = spectrum(res)
        ax.semilogy(f[1:], S[1:], label=f"h = {h:g} s")
    ax.axvline(20.0, color="k", lw=0.8, ls="--")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("|FFT of tip velocity|^2")
    ax.set_xlim(0, 200)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    save_figure(fig, OUT / "tip_velocity_spectrum.png")
    text = io.StringIO(newline="")
    w = csv.writer(text)
    w.writerow(["h_s", "n_rhs", "n_steps", "wall_s", "energy_above_20Hz"])
    w.writerows(rows)
    atomic_write_bytes(OUT / "summary.csv", text.getvalue().encode())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
