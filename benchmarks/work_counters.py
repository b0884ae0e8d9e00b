"""The integrators' work counters of every shipped scene over a short run: regressions in the
work a scene takes (more steps, right-hand sides, Jacobians, factorisations) caught without
timing anything.

    python benchmarks/work_counters.py            # print each scene's counters, compare them
    python benchmarks/work_counters.py --write    # and write tests/data/work_counters.json

Each scene runs from its static equilibrium to the short ``solver.t_end`` of :data:`T_END`
(every other setting as shipped) and records the counters of its ``Result.stats`` (summary.json)
that :data:`COUNTERS` names, those its integration path has:

* ``n_steps`` accepted steps, ``n_rejected`` rejected ones (generalized-alpha), ``n_rhs``
  right-hand sides (stage evaluations, force evaluations), ``n_failed_rhs`` failed ones;
* ``n_jacobians`` (RK45/BDF/auto: structured Jacobians) or ``n_jac`` (generalized-alpha),
  ``n_jacobian_refreshes`` (their non-smooth columns refreshed);
* ``n_lu`` LU factorisations (BDF's Newton matrix, generalized-alpha's iteration matrix);
* ``n_newton_iterations``, ``n_newton_failures`` (generalized-alpha), ``n_method_switches``
  (auto).

The modal scenes (``*_rl``) step in closed form and have none.  The counts are deterministic on
one machine (the same BLAS and libm); another machine may accept or reject a step differently
near the error tolerance, so ``tests/test_work_counters.py`` compares with a tolerance
(:data:`RISE`, :data:`RISE_ABS`).  After an intended change of the work (a new integrator
setting, a model change), regenerate the file with ``--write`` and commit it with the change.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, ROOT)
# the test session's settings (tests/conftest.py): one BLAS thread, the element worker on
# whatever the load (its governor would otherwise choose by the machine's load, and the
# worker's order of summation can move a step's acceptance by round-off)
for _var, _val in (("OPENBLAS_NUM_THREADS", "1"), ("OMP_NUM_THREADS", "1"),
                   ("MKL_NUM_THREADS", "1"), ("SIM_CORE_ELEMENT_WORKER", "on")):
    os.environ.setdefault(_var, _val)

from sim_core import load_scene, simulate  # noqa: E402
from sim_core.result import atomic_write_bytes  # noqa: E402
from sim_core.scene.io import shipped_scenes  # noqa: E402

DATA = os.path.join(ROOT, "tests", "data", "work_counters.json")

#: the counters of Result.stats compared (those a scene's integration path records)
COUNTERS = ("n_steps", "n_rejected", "n_rhs", "n_failed_rhs", "n_jacobians", "n_jac",
            "n_jacobian_refreshes", "n_lu", "n_newton_iterations", "n_newton_failures",
            "n_method_switches")

#: a counter may rise by RISE (relative) or RISE_ABS counts, whichever is larger, before the
#: test fails: step acceptance near the tolerance may differ between BLAS/libm builds
RISE = 0.10
RISE_ABS = 2

#: solver.t_end (s) of each shipped scene: the whole set runs in about a minute on one core of
#: an idle machine (most of it the models' build and statics), each integration taking tens of
#: steps or more; the crane scenes reach their first stiff-friction switch to BDF within it
T_END = {
    "beam_through_sleeve": 0.5,
    "cantilever_release": 0.1,
    "crane_hexagonal_4": 0.2,
    "crane_hexagonal_4_retraction": 0.2,
    "crane_lift_and_slew": 0.5,
    "crane_lift_off": 0.5,
    "crane_telescoping_sequence": 0.2,
    "crane_telescoping_stages": 0.2,
    "folding_boom": 0.2,
    "telescopic_extraction": 0.2,
    "telescopic_extraction_5": 0.1,
    "telescopic_extraction_rigid": 0.2,
    "telescopic_extraction_rl": 0.5,
    "telescopic_retraction": 0.2,
    "telescopic_retraction_5": 0.1,
    "telescopic_retraction_rl": 0.5,
}


def counters(scene: str, t_end: float) -> dict:
    """The run's method and its work counters (:data:`COUNTERS` it records)."""
    stats = simulate(load_scene(scene, {"solver.t_end": t_end})).stats
    return {"method": str(stats.get("method")),
            "counters": {k: int(stats[k]) for k in COUNTERS if k in stats}}


def compare(scene: str, got: dict, ref: dict) -> tuple[list[str], list[str]]:
    """(failures, notes) of a scene's counters against the committed ones: a rise beyond the
    tolerance or a changed set of counters or method fails; a decrease is a note."""
    fail, note = [], []
    if got["method"] != ref["method"] or set(got["counters"]) != set(ref["counters"]):
        fail.append(f"{scene}: method/counters {got['method']} {sorted(got['counters'])} "
                    f"differ from the committed {ref['method']} {sorted(ref['counters'])}")
        return fail, note
    for k, v in got["counters"].items():
        r = ref["counters"][k]
        allowed = r + max(RISE * r, RISE_ABS)
        if v > allowed:
            fail.append(f"{scene}: {k} = {v}, committed {r} (allowed up to {allowed:g})")
        elif v < r:
            note.append(f"{scene}: {k} = {v} fell from {r}")
    return fail, note


HOW_TO_REGENERATE = ("an intended change of the work: regenerate the committed counters with "
                     "'python benchmarks/work_counters.py --write' and commit "
                     "tests/data/work_counters.json with the change (say why in the commit)")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--write", action="store_true", help=f"write {os.path.relpath(DATA, ROOT)}")
    p.add_argument("--scenes", nargs="*", default=None, help="only these scenes (no --write)")
    args = p.parse_args(argv)
    missing = sorted(set(shipped_scenes()) - set(T_END))
    if missing:
        p.error(f"no t_end in T_END for the shipped scenes {missing}")
    names = args.scenes or sorted(T_END)
    if args.write and args.scenes:
        p.error("--write runs every scene (no --scenes)")
    ref = {}
    if os.path.exists(DATA):
        with open(DATA) as f:
            ref = json.load(f)["scenes"]
    out, failures = {}, []
    for name in names:
        out[name] = {"t_end": T_END[name], **counters(name, T_END[name])}
        print(name, json.dumps(out[name]), flush=True)
        if name in ref and not args.write:
            fail, note = compare(name, out[name], ref[name])
            failures += fail
            for line in fail + note:
                print("  " + line)
    if args.write:
        doc = {"generated_by": "python benchmarks/work_counters.py --write",
               "rise_allowed": {"relative": RISE, "absolute": RISE_ABS},
               "scenes": out}
        atomic_write_bytes(DATA, (json.dumps(doc, indent=1, sort_keys=True) + "\n").encode())
        print(f"wrote {DATA}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
