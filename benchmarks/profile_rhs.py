"""Where the time of the right-hand side goes (issue "What accuracy costs in time").

One command (from the repository root):

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/profile_rhs.py

prints, for n_nodes = 5, 9, 17,

* ``mass_force``  one ``Model.mass_force`` (full-coordinate M and F),
* ``rhs``         one ``Model.rhs`` (mass_force + constraint reduction + Cholesky solve),
* ``eval real``   one real ``SplineElement.evaluate`` with the strains the model needs,
* ``eval cplx``   one complex-step ``evaluate`` as ``Model.element_contexts`` calls it,

for two models: the 9-node-style cantilever of tests/beam (Inertia + Elasticity + Gravity, one
element, clamped/free) and the shipped ``beam_through_sleeve`` scene (Inertia + Elasticity +
StressFilter + Gravity, sleeve end), then a cProfile top-15 (by own time) of the sleeve rhs.

Times are the best of ``--repeat`` runs of ``--number`` calls each (microseconds per call; the
thread CPU time and the minimum are robust against other processes on the machine).  ``--json FILE`` also writes the
table; ``--compare OLD.json`` adds the speed-up against an earlier table; ``--root DIR`` times
the sim_core of another checkout (e.g. the previous commit) with this same script.
"""

from __future__ import annotations

import argparse
import cProfile
import io
import json
import os
import pstats
import resource
import sys
import time

if os.environ.get("OPENBLAS_NUM_THREADS") != "1":
    print("warning: run with OPENBLAS_NUM_THREADS=1 for comparable numbers", file=sys.stderr)

import numpy as np

# --root DIR benchmarks another checkout (e.g. the previous commit) with this same script
_ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
if "--root" in sys.argv:
    _ROOT = os.path.abspath(sys.argv[sys.argv.index("--root") + 1])
sys.path.insert(0, _ROOT)

from sim_core import load_scene  # noqa: E402
from sim_core.model.boundary import boundary_condition, reference_basis
from sim_core.model.model import Model  # noqa: E402
from sim_core.physics.beam.moving_node_beam import Beam, BeamSection  # noqa: E402
from sim_core.physics.complex_step import COMPLEX_STEP as _CSTEP  # noqa: E402
from sim_core.physics.effects import Elasticity, Gravity, Inertia  # noqa: E402
from sim_core.systems.beam.build import build_model  # noqa: E402

NODES = (5, 9, 17)


def cantilever(n_nodes: int):
    """The cantilever of tests/beam/conftest.py with gravity (one element, 10 m steel beam)."""
    E, G, rho, L = 2.1e11, 8.0e10, 7850.0, 10.0
    A, I_t, I_b = 1e-2, 1e-5, 1.3e-5
    sec = BeamSection(EA=E * A, GJ=G * (I_t + I_b), EI_t=E * I_t, EI_b=E * I_b, rhoA=rho * A,
                      J_s=rho * (I_t + I_b))
    b = Beam("b", L, sec, (0.0, L), n_nodes=n_nodes, reference_basis=reference_basis([1, 0, 0]))
    eff = [Inertia(), Elasticity(), Gravity(np.array([0.0, 0.0, -9.81]))]
    cons = [boundary_condition([0], [b], 0, "left", "clamped", [0, 0, 0], [1, 0, 0]),
            boundary_condition([0], [b], 0, "right", "free")]
    m = Model([b], eff, [], cons)
    Q0 = b.straight_coordinates([0, 0, 0], [1, 0, 0])
    return m, Q0, np.zeros_like(Q0)


def sleeve(n_nodes: int):
    scene = load_scene("beam_through_sleeve", overrides={"beams.0.n_nodes": n_nodes})
    return build_model(scene)


def tune_glibc_malloc(trim: int = 256 * 2**20, mmap: int = 64 * 2**20) -> bool:
    """Stop glibc from returning freed heap memory to the kernel after every RHS.

    The element arrays of one RHS (a few hundred kB to MB) are freed at its end; with glibc's
    default thresholds the heap top is trimmed (and large blocks are mmapped) every call, so the
    next call takes a minor page fault on every 4 kB page it touches again.  Same effect as the
    environment variables MALLOC_TRIM_THRESHOLD_=268435456 MALLOC_MMAP_THRESHOLD_=67108864.
    Returns False where glibc's mallopt is not available.
    """
    import ctypes
    import ctypes.util
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
        return bool(libc.mallopt(M_TRIM_THRESHOLD, trim)) and bool(libc.mallopt(M_MMAP_THRESHOLD, mmap))
    except (OSError, AttributeError):
        return False


def perturbed_state(model: Model, Q0, Qd0, seed: int = 7):
    """A generic (bent, twisted, moving) state on the constraint manifold."""
    rng = np.random.default_rng(seed)
    z, zd = model.reduced_state(0.1, Q0, Qd0)
    z = z + 1e-3 * rng.standard_normal(z.shape)
    zd = zd + 1e-1 * rng.standard_normal(zd.shape)
    return z, zd


def best_time(fn, number: int, repeat: int) -> float:
    """Best over ``repeat`` of the mean CPU time (of this thread) of ``number`` calls, in
    microseconds.  CPU time, not wall time: other processes on the machine do not count."""
    fn()
    best = np.inf
    for _ in range(repeat):
        t0 = time.thread_time()
        for _ in range(number):
            fn()
        best = min(best, (time.thread_time() - t0) / number)
    return best * 1e6


def measure(name: str, builder, n_nodes: int, number: int, repeat: int) -> dict:
    model, Q0, Qd0 = builder(n_nodes)
    t = 0.1
    z, zd = perturbed_state(model, Q0, Qd0)
    Q, Qd = model.full_state(t, z, zd)
    y = np.concatenate([z, zd])
    el = model.beams[0].elements[0]
    idx = model.offsets[0] + model.beams[0].index_map[0]
    qe, qde = Q[idx], Qd[idx]
    strains = "strains" in model.needs
    mat = "material_strain" in model.needs
    kin = el.evaluate(qe, strains=strains, material_strain=mat)
    qc = qe + 1j * _CSTEP * qde
    row = {"model": name, "n_nodes": n_nodes, "n_elements": sum(len(b.elements) for b in model.beams),
           "n_coords": model.n_coords, "n_dof": model.n_dof}
    row["mass_force_us"] = best_time(lambda: model.mass_force(t, Q, Qd), number, repeat)
    row["rhs_us"] = best_time(lambda: model.rhs(t, y), number, repeat)
    # evaluate() may form fields on first access: read what the callers read
    all_fields = ("sec", "J_r", "J_w", "B_xi", "B_s", "J_psi")
    conv_fields = ("J_r", "J_w", "B_s") if mat else ("J_r", "J_w")

    def touch(k, names):
        for name in names:
            getattr(k, name)

    row["eval_real_us"] = best_time(
        lambda: touch(el.evaluate(qe, strains=strains, material_strain=mat), all_fields),
        4 * number, repeat)
    row["eval_cplx_us"] = best_time(
        lambda: touch(el.evaluate(qc, s=kin.s, sub=kin.sub, strains=mat, material_strain=mat),
                      conv_fields), 4 * number, repeat)
    f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(number):
        model.mass_force(t, Q, Qd)
    row["faults_per_mass_force"] = (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0) / number
    return row


TIMES = ("mass_force_us", "rhs_us", "eval_real_us", "eval_cplx_us")


def _ratio(old: dict, new: dict) -> dict:
    return {**new, **{k: old[k] / new[k] for k in TIMES}}


def print_table(rows: list[dict], fmt: str = ".0f", unit: str = "microseconds per call",
                faults: bool = True) -> None:
    head = (f"{'model':<20}{'nodes':>6}{'coords':>8}{'mass_force':>12}{'rhs':>10}"
            f"{'eval real':>11}{'eval cplx':>11}" + (f"{'faults/mf':>11}" if faults else "")
            + f"   ({unit})")
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r['model']:<20}{r['n_nodes']:>6}{r['n_coords']:>8}"
              + "".join(f"{r[k]:>{w}{fmt}}" for k, w in zip(TIMES, (12, 10, 11, 11)))
              + (f"{r.get('faults_per_mass_force', float('nan')):>11.0f}" if faults else ""))


def profile(builder, n_nodes: int, calls: int, top: int) -> str:
    model, Q0, Qd0 = builder(n_nodes)
    z, zd = perturbed_state(model, Q0, Qd0)
    y = np.concatenate([z, zd])
    model.rhs(0.1, y)
    pr = cProfile.Profile()
    pr.enable()
    for _ in range(calls):
        model.rhs(0.1, y)
    pr.disable()
    buf = io.StringIO()
    st = pstats.Stats(pr, stream=buf)
    st.strip_dirs().sort_stats("tottime").print_stats(top)
    return buf.getvalue()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--number", type=int, default=10, help="calls per timing run")
    ap.add_argument("--repeat", type=int, default=40, help="timing runs (best is reported)")
    ap.add_argument("--root", help="repository root whose sim_core is timed (default: this one)")
    ap.add_argument("--compare", help="JSON table of an earlier run: print speed-ups against it")
    ap.add_argument("--nodes", type=int, nargs="+", default=list(NODES))
    ap.add_argument("--profile-nodes", type=int, default=9)
    ap.add_argument("--profile-calls", type=int, default=200)
    ap.add_argument("--top", type=int, default=15)
    ap.add_argument("--no-profile", action="store_true")
    ap.add_argument("--json", help="also write the table to this JSON file")
    ap.add_argument("--malloc-tuned", action="store_true",
                    help="raise glibc's trim/mmap thresholds first (see benchmarks/README.md)")
    args = ap.parse_args(argv)
    if args.malloc_tuned:
        print("glibc malloc tuned:", tune_glibc_malloc())

    rows = []
    for name, builder in (("cantilever", cantilever), ("beam_through_sleeve", sleeve)):
        for n in args.nodes:
            rows.append(measure(name, builder, n, args.number, args.repeat))
    print(f"numpy {np.__version__}, OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    print(f"sim_core from {_ROOT}")
    print_table(rows)
    if args.compare:
        with open(args.compare) as f:
            old = {(r["model"], r["n_nodes"]): r for r in json.load(f)}
        print(f"\nspeed-up against {args.compare} (old time / new time):")
        print_table([_ratio(old[(r["model"], r["n_nodes"])], r) for r in rows
                     if (r["model"], r["n_nodes"]) in old], fmt=".2f", unit="x", faults=False)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    if not args.no_profile:
        print(f"\ncProfile of {args.profile_calls} x Model.rhs, beam_through_sleeve, "
              f"n_nodes={args.profile_nodes} (top {args.top} by own time):")
        print(profile(sleeve, args.profile_nodes, args.profile_calls, args.top))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
