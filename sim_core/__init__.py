"""sim_core: moving-boundary dynamics of flexible telescopic crane booms.

Reference: T. Zhao, Z. Qi, T. Wang, "Dynamic Contact Analysis of Flexible Telescopic Boom
Systems with Moving Boundary", Mathematics 12 (2024) 2496 (doi:10.3390/math12162496), and the
folding long-boom manipulator paper (SIMULTECH 2020).  SI units throughout.

    from sim_core import load_scene
    from sim_core import simulate
    result = simulate(load_scene("beam_through_sleeve"))
    result.t, result["tip_position"]
"""

import os as _os

# The models are small (50-400 coordinates): threaded BLAS only adds overhead and contention
# (on a small LU the thread start-up costs far more than the factorisation).  A default only:
# a value the user set is kept, and it has no effect if numpy was imported before sim_core.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")

from sim_core._version import __version__  # noqa: E402
from sim_core.api import load_scene, simulate  # noqa: E402
from sim_core.commands import Command  # noqa: E402
from sim_core.errors import ResultFormatError, SceneError, SimulationError  # noqa: E402
from sim_core.result import Result  # noqa: E402
from sim_core.simulation import Simulation  # noqa: E402

__all__ = ["load_scene", "simulate", "Simulation", "Command", "Result", "ResultFormatError",
           "SceneError", "SimulationError", "__version__"]
