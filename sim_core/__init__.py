"""sim_core: moving-boundary dynamics of flexible telescopic crane booms.

Reference: T. Zhao, Z. Qi, T. Wang, "Dynamic Contact Analysis of Flexible Telescopic Boom
Systems with Moving Boundary", Mathematics 12 (2024) 2496 (the "first seed"), and the
folding long-boom manipulator paper (SIMULTECH 2020, the "second seed").  SI units throughout.

    from sim_core import load_scene, simulate
    result = simulate(load_scene("beam_through_sleeve"))
    result.t, result["tip_position"]
"""

__version__ = "0.1.0"

from .errors import SceneError, SimulationError  # noqa: E402
from .result import Result  # noqa: E402
from .scene import load_scene  # noqa: E402
from .simulate import simulate  # noqa: E402

__all__ = ["load_scene", "simulate", "Result", "SceneError", "SimulationError", "__version__"]
