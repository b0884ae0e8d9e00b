"""Where the time of the paper scene's right-hand side goes, and what each speed-up bought.

One command (from the repository root):

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/telescopic_rhs_speed.py

The paper's extraction scene (25 t, friction with the slider-spring distribution, stress filter,
elastic ropes) at 8 sub-elements per spline element, at the static equilibrium with a small
random velocity and every contact point sliding (the state of ``jacobian_speed.py``).  It times
one ``Model.rhs`` (wall time, ``time.perf_counter``: the last variant uses a second thread,
whose time a per-thread CPU clock would not see; minimum and median of 40 runs of 4 calls, the
variants interleaved so that they share the machine's state).  Every call gets a state of its own (the
base state with a relative perturbation of 1e-9), as in a run: the point functions keep their
last evaluation, and a benchmark that repeats one state measures cache hits.  Variants:

* ``fixed point, numpy``      the friction multipliers by fixed-point iteration, numpy section
  state, Python micro-motion Newton (the code before 2026-11-24's changes),
* ``Newton, numpy``           the friction solved by Newton in the four friction values,
* ``+ compiled section``      and the section state (Eqs. 24-33) as a compiled numba loop,
* ``+ compiled micro-motion`` and the micro-motion Newton (Eqs. 59-71) compiled too,
* ``+ compiled points``       and the one-point kinematics of the constraint, rope and contact
  points (``sim_core.physics.beam._moving_node_beam_numba``),
* ``+ compiled elements``     and the element mass matrices and forces
  (``sim_core.physics._effects_numba``),
* ``+ block saddle-point solve`` and the saddle-point system by block elimination over the
  beams (``Model.kkt_blocks``, compiled: ``sim_core.model._saddle_point_numba``; before: the LU of
  the whole matrix),
* ``+ compiled scatter``      and the element and point-effect blocks added into the reduced
  arrays by the compiled loop of ``sim_core.model._assembly_numba`` (before: its numpy version),
* ``+ elements on a worker thread`` and the compiled element batch on a second thread while
  the constraint rows are formed (``Model.element_thread``; the rows before run the batch on
  the calling thread),
* ``+ GIL handed to the worker`` and the calling thread releasing the GIL once after
  submitting the batch (``Model.element_yield``; without it the batch started ~0.27 ms late,
  waiting for the GIL while the constraint rows ran Python),
* ``+ points in one compiled call`` and every material point's kinematics, rigid offset and
  full-length Jacobians in one compiled call (``constraints.POINTS_IN_ONE_CALL``),
* ``+ friction Newton in one compiled call`` and the friction-multiplier Newton's loop
  compiled (``Model.multiplier_newton_compiled``),
* ``+ constraint rows in one compiled program`` and the constraint rows of all constraints
  in one compiled call (``constraints.COMPILED_ROWS``, ``sim_core.physics._constraints_numba``),
* ``+ friction Newton warm-started`` and the friction-multiplier Newton started from the last
  solution (``Model.multiplier_warm_start``; before: from zero friction),
* ``+ payload and ropes in one compiled call`` and the payload's and the ropes' blocks from
  one compiled evaluation of their points (``Model.point_effects_compiled``),
* ``+ persistent compiled worker`` and the element batch handed to a compiled worker loop
  through a mailbox and an atomic state word instead of the thread pool
  (``Model.element_spin``, ``sim_core.model.workers``: no queue, no thread wake-up, no
  GIL hand-over),
* ``+ factor pipelined with the worker`` and each element's saddle-point block added and
  factored as soon as the worker publishes the element (``Model.kkt_pipeline``,
  ``saddle_point_compiled.kkt_factor_pipelined``; before: after the whole batch),
* ``+ solves without the refinement step`` and the compiled elimination's solves without
  their step of iterative refinement (``Model.kkt_refine`` off, the default since
  2026-11-24: with W = L^-1 B the residual is at the whole LU's level without it),

All variants assemble the reduced system block by block and evaluate each material point once
for the real and complex-step states (the full N x N mass matrix is never formed and
projected).  They also share the improvements that have no switch: the friction section maps
in closed form, the saddle-point factor on the border columns that touch each block, the
element convective rows from tables, the element blocks scattered in one call; in the element
kernel the kinematics once at the complex-step state, J_r in its Kronecker structure (the
translational mass without the BLAS product, omega and eps_dot as real parts of the convective
sums), the saddle-point blocks per element, the refinement residual from the blocks, the
constraint program on each point's own columns, the saddle-point blocks by W = L^-1 B, the
constant boundary conditions' lift formed once and the micro-motion Newton's 5 x 5 solves
inline.  The tables this script wrote for earlier code are in the git history of
``results/telescopic_rhs_speed.md`` and the CHANGELOG.

then a cProfile of the last variant without the worker thread, grouped by what the time is
spent on.  Ratios within one
run are what the table is for; the machine may be shared.

Writes benchmarks/results/telescopic_rhs_speed.md (atomically).
"""

from __future__ import annotations

import cProfile
import os
import platform
import pstats
import sys
import time
from datetime import datetime, timezone

import numpy as np

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..")))

from jacobian_speed import sliding_state  # noqa: E402  (benchmarks/)

from sim_core.model import _assembly_numba as assembly_compiled  # noqa: E402
from sim_core.physics import _effects_numba as element_compiled
from sim_core.physics import constraints
from sim_core.physics.beam import _cardan_numba as cardan_compiled  # noqa: E402
from sim_core.physics.beam import _moving_node_beam_numba as point_compiled
from sim_core.physics.contact import _sliding_block_contact_numba as micro_motion_compiled  # noqa: E402
from sim_core.result import atomic_write_bytes  # noqa: E402

OUT = os.path.join(os.path.dirname(__file__), "results", "telescopic_rhs_speed.md")

# (label, multiplier Newton, compiled: section state, micro-motion Newton, point kinematics,
# element mass and forces, block elimination of the saddle-point system, compiled scatter,
# the element batch on a worker thread, the GIL handed to the worker after submitting,
# material points in one compiled call, the friction Newton's loop in one compiled call, the
# constraint rows as one compiled program, the friction Newton warm-started, the payload and
# ropes from one compiled evaluation of their points, the persistent compiled worker, the
# saddle-point factor pipelined with it, the solves without the refinement step)
# each variant switches on one more of these, in this order (the first: none)
_LABELS = (
    "fixed point, numpy", "Newton, numpy", "+ compiled section", "+ compiled micro-motion",
    "+ compiled points", "+ compiled elements", "+ block saddle-point solve",
    "+ compiled scatter", "+ elements on a worker thread", "+ GIL handed to the worker",
    "+ points in one compiled call", "+ friction Newton in one compiled call",
    "+ constraint rows in one compiled program", "+ friction Newton warm-started",
    "+ payload and ropes in one compiled call", "+ persistent compiled worker",
    "+ factor pipelined with the worker", "+ solves without the refinement step",
)
VARIANTS = tuple((label,) + (True,) * k + (False,) * (len(_LABELS) - 1 - k)
                 for k, label in enumerate(_LABELS))

# cProfile groups: (label, "module file:function" names whose cumulative time is the group's;
# none of them calls another group's functions)
GROUPS = (
    ("friction (section maps, micro-motion solves, sensitivities)",
     ("friction.py:at_state", "friction.py:values",
      "friction.py:newton")),
    ("constraint rows (Jacobian, quadratic terms)", ("constraints.py:constraint_terms",)),
    ("saddle-point factorisation", ("saddle_point.py:kkt_factor",)),
    ("saddle-point solves", ("_decomp_lu.py:lu_solve", "saddle_point.py:once",
                             "_saddle_point_numba.py:solve")),
    ("point effects (payload, ropes)", ("point_effects.py:local",)),
    ("elements (kinematics, mass, forces)", ("model.py:element_terms",
                                             "model.py:_element_blocks_started")),
)


def _configure(m, newton: bool, section: bool, micro: bool, points: bool,
               elements: bool, blocks: bool, scatter: bool, thread: bool, handover: bool,
               points_one_call: bool, newton_compiled: bool, rows_compiled: bool,
               warm_start: bool, point_effects_compiled: bool, spin: bool, pipeline: bool,
               no_refine: bool) -> None:
    m.multiplier_newton = newton
    m.kkt_pipeline = pipeline
    m.kkt_refine = not no_refine
    m.element_spin = spin
    m.point_effects_compiled = point_effects_compiled
    m.multiplier_warm_start = warm_start
    constraints.COMPILED_ROWS = rows_compiled
    m.element_thread = thread
    m.element_yield = handover
    m.multiplier_newton_compiled = newton_compiled
    constraints.POINTS_IN_ONE_CALL = points_one_call
    m.kkt_blocks = blocks
    assembly_compiled.AVAILABLE = scatter and cardan_compiled.numba is not None
    cardan_compiled.AVAILABLE = section and cardan_compiled.numba is not None
    micro_motion_compiled.AVAILABLE = micro and micro_motion_compiled.numba is not None
    point_compiled.AVAILABLE = points and cardan_compiled.numba is not None
    element_compiled.AVAILABLE = elements and cardan_compiled.numba is not None


def states(y, count: int, seed: int = 1):
    """``count`` states near y (relative perturbation 1e-9): no call repeats a state."""
    rng = np.random.default_rng(seed)
    return [y * (1.0 + 1e-9 * rng.standard_normal(len(y))) for _ in range(count)]


def time_variants(m, t, y, runs: int = 40, calls: int = 4) -> dict:
    times = {v[0]: [] for v in VARIANTS}
    for label, *flags in VARIANTS:                # warm-up (numba compilation, caches)
        _configure(m, *flags)
        m.rhs(t, y)
    ys = states(y, runs * len(VARIANTS) * calls)
    k = 0
    for _ in range(runs):
        for label, *flags in VARIANTS:
            _configure(m, *flags)
            t0 = time.perf_counter()
            for _ in range(calls):
                m.rhs(t, ys[k])
                k += 1
            times[label].append((time.perf_counter() - t0) / calls)
    return {k: np.array(v) for k, v in times.items()}


def profile_groups(m, t, y, calls: int = 40) -> tuple[float, list[tuple[str, float]]]:
    ys = states(y, calls, seed=2)
    pr = cProfile.Profile()
    pr.enable()
    for yk in ys:
        m.rhs(t, yk)
    pr.disable()
    st = pstats.Stats(pr)
    total = 0.0
    cum: dict[str, float] = {}
    for (path, _, name), (_, _, _, ct, _) in st.stats.items():
        key = f"{os.path.basename(path)}:{name}"
        cum[key] = cum.get(key, 0.0) + ct
        if key == "model.py:rhs":
            total = ct
    rows = []
    for label, names in GROUPS:
        rows.append((label, sum(cum.get(n, 0.0) for n in names)))
    rows.append(("rest (state maps, reductions, bookkeeping)", total - sum(v for _, v in rows)))
    return total, rows


def main() -> int:
    m, t, y = sliding_state(9)
    times = time_variants(m, t, y)
    base = np.min(times[VARIANTS[0][0]])
    lines = [
        "# The paper scene's right-hand side: time and where it goes",
        "",
        f"Measured {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC on {platform.machine()} "
        f"({os.cpu_count()} cores), numpy {np.__version__}, OPENBLAS_NUM_THREADS="
        f"{os.environ.get('OPENBLAS_NUM_THREADS')}; `benchmarks/telescopic_rhs_speed.py`.",
        "Paper extraction scene, 8 sub-elements (n_dof 313), contact points sliding.  Wall time "
        "of one `Model.rhs` (the last variant uses a second thread), 40 interleaved runs of 4 "
        "calls, each call at a state of its own.",
        "",
        "| variant | min (ms) | median (ms) | speed-up (min) |",
        "|---|---|---|---|",
    ]
    for label, *_ in VARIANTS:
        a = times[label] * 1e3
        lines.append(f"| {label} | {a.min():.1f} | {np.median(a):.1f} | {base * 1e3 / a.min():.2f} |")
    # profiled on one thread: cProfile sees only the calling thread
    one_thread = VARIANTS[-1][1:8] + (False, False) + VARIANTS[-1][10:]   # no worker
    _configure(m, *one_thread)
    total, rows = profile_groups(m, t, y)
    lines += ["", f"Where the time of `{VARIANTS[-1][0]}` without the worker thread goes "
              f"(cProfile, 40 calls, one thread; "
              f"the profiler adds overhead to every Python call, so shares, not times; the last "
              f"variant overlaps the elements' share with the constraint rows'):", "",
              "| part | share |", "|---|---|"]
    for label, v in rows:
        lines.append(f"| {label} | {100 * v / total:.0f} % |")
    text = "\n".join(lines) + "\n"
    print(text)
    atomic_write_bytes(OUT, text.encode())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
