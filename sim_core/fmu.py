"""A scene as an FMI 2.0 co-simulation FMU (``boom-sim fmu``), built with pythonfmu.

    from sim_core.fmu import build_fmu
    build_fmu("crane_lift_and_slew", "crane.fmu", step_size=0.01,
              overrides={"booms.n_nodes": 3}, parameters=["payload.mass"])

The FMU's variables (docs/fmu.md):

* inputs ``command_<actuator>``: the actuator's acceleration (m/s^2 or rad/s^2) held over each
  communication step, as :meth:`sim_core.Simulation.advance` takes it; the actuators not
  among ``inputs`` follow the scene's profiles;
* outputs: the scalar components of :meth:`sim_core.Simulation.outputs` at the step's end,
  ``<output>_x|_y|_z`` for a vector of the global frame (positions, velocities, deflections),
  ``<output>_<i>[_<j>...]`` for other arrays (0-based indices), ``actuator_<name>_position|_rate|_acceleration`` for the actuators' state;
* parameters: scene keys (``payload.mass``), applied with
  ``load_scene(scene, overrides)`` when the FMU leaves initialization mode.

The FMU's resources hold the scene file, the slave (:mod:`sim_core.fmu_slave`) and its
configuration ``boom_sim_fmu.json`` (with the resolved scene, for reference); its binaries are
pythonfmu's, which run the slave in the Python that loads it (the importer's, or the one the
binary finds), so the target machine needs Python with this package installed.
"""

from __future__ import annotations

import json
import re
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

from sim_core._version import __version__
from sim_core.api import load_scene
from sim_core.errors import SceneError
from sim_core.result import atomic_path
from sim_core.scene.io import read_scene
from sim_core.simulation import LIMIT_MODES, Simulation

#: the outputs an FMU has unless ``outputs`` names others (those the scene has)
DEFAULT_OUTPUTS = ("tip_position", "tip_deflection", "sway_angle", "telescopic_cylinder_force",
                   "luffing_cylinder_force", "slew_torque", "hoist_rope_force", "pad_forces",
                   "actuators")

#: the slave's module name in the FMU (resources/<name>.py)
SLAVE_MODULE = "boom_sim_fmu_slave"
_XYZ = ("x", "y", "z")
#: the outputs that are vectors of the global frame (named _x, _y, _z; docs/stepping.md)
_SPATIAL = ("_position", "_velocity", "_acceleration", "_deflection", "_deflection_rate",
            "angular_momentum")


def layout(out: dict, keys) -> list[dict]:
    """The FMU's output variables of ``Simulation.outputs`` values ``out``: one per scalar
    component of each key, {name, key, index (the path into the value), description}."""
    rows = []
    for key in keys:
        value = out[key]
        if key == "actuators":
            for act, state in value.items():
                for i, what in enumerate(("position", "rate", "acceleration")):
                    rows.append({"name": f"actuator_{act}_{what}", "key": key,
                                 "index": [act, i],
                                 "description": f"actuator {act}: {what} (SI: m or rad, per s, "
                                                "per s^2)"})
            continue
        arr = np.asarray(value, dtype=float)
        spatial = arr.shape == (3,) and key.endswith(_SPATIAL)
        for idx in np.ndindex(arr.shape):
            parts = [_XYZ[i] if spatial else str(i) for i in idx]
            rows.append({"name": "_".join([key, *parts]), "key": key,
                         "index": [int(i) for i in idx],
                         "description": f"{key}{list(idx) if idx else ''} (SI units, "
                                        "docs/stepping.md)"})
    return rows


def fmu_config(scene_arg: str, *, step_size: float, overrides: dict | None = None,
               parameters=(), outputs=None, inputs=None, limits: str = "raise",
               stop_time: float | None = None, model_name: str | None = None) -> tuple[dict, str]:
    """The FMU's configuration (``boom_sim_fmu.json``) and the scene file it carries: the
    scene is loaded with ``overrides`` (fixed) and simulated to t = 0 to learn its actuators
    and outputs.  Bad input raises :class:`sim_core.SceneError` naming the option."""
    overrides = dict(overrides or {})
    if not (isinstance(step_size, (int, float)) and np.isfinite(step_size) and step_size > 0):
        raise SceneError(f"--step {step_size!r}: the communication step must be > 0 s")
    if limits not in LIMIT_MODES:
        raise SceneError(f"--limits {limits!r}: allowed {', '.join(LIMIT_MODES)}")
    raw, source = read_scene(scene_arg)
    scene = load_scene(scene_arg, overrides)
    sim = Simulation(scene, limits=limits)
    params = []
    for key in parameters:
        if key in overrides:
            raise SceneError(f"--param {key!r}: also fixed with --set; give it once")
        value = _scene_value(scene, key)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SceneError(f"--param {key!r}: the scene value {value!r} is not a number (a "
                             "parameter is a real scene value, e.g. payload.mass)")
        params.append({"key": key, "start": float(value), "integer": isinstance(value, int),
                       "description": f"scene key {key} (SI units), applied at initialization"})
    acts = sim.actuators if inputs is None else tuple(inputs)
    for a in acts:
        if a not in sim.actuators:
            raise SceneError(f"--inputs {a!r}: not an actuator of this scene (allowed: "
                             f"{', '.join(sim.actuators)})")
    units = {a: sim.limits[a].unit for a in acts}
    full = sim.outputs()
    if outputs is None:
        keys = [k for k in DEFAULT_OUTPUTS if k in full]
    else:
        keys = list(outputs)
        bad = [k for k in keys if k not in full or k == "time"]
        if bad:
            raise SceneError(f"--outputs {', '.join(bad)}: not an output of this scene "
                             f"(allowed: {', '.join(k for k in full if k != 'time')})")
    name = model_name or re.sub(r"\W", "_", str(scene.get("name") or Path(source).stem))
    if not re.fullmatch(r"[A-Za-z_]\w*", name):
        raise SceneError(f"--name {name!r}: the model identifier must be a C identifier "
                         "(letters, digits, _)")
    cfg = {
        "model_name": name,
        "description": f"telescopic-boom-sim scene {scene.get('name')}: "
                       f"{scene.get('description', '')}".strip(),
        "sim_core_version": __version__,
        "scene_file": "scene" + Path(source).suffix,
        "overrides": overrides,
        "parameters": params,
        "inputs": [{"actuator": a, "name": f"command_{a}",
                    "description": f"actuator {a}: acceleration held over the step, "
                                   f"{units[a]}/s^2"} for a in acts],
        "output_keys": keys,
        "outputs": layout(full, keys),
        "limits": limits,
        "step_size": float(step_size),
        "stop_time": float(stop_time if stop_time is not None else scene["solver"]["t_end"]),
        "resolved_scene": {k: v for k, v in scene.items() if k != "source"},
    }
    return cfg, source


def build_fmu(scene_arg: str, out: str | Path, *, step_size: float,
              overrides: dict | None = None, parameters=(), outputs=None, inputs=None,
              limits: str = "raise", stop_time: float | None = None,
              model_name: str | None = None) -> tuple[Path, dict]:
    """Pack a scene as an FMI 2.0 co-simulation FMU at ``out`` (written atomically); returns
    the path and the configuration (:func:`fmu_config`).  Needs pythonfmu
    (``pip install 'telescopic-boom-sim[fmu]'``)."""
    try:
        from pythonfmu.builder import FmuBuilder
    except ImportError:
        raise SceneError("boom-sim fmu needs pythonfmu: pip install "
                         "'telescopic-boom-sim[fmu]'") from None
    cfg, source = fmu_config(scene_arg, step_size=step_size, overrides=overrides,
                             parameters=parameters, outputs=outputs, inputs=inputs,
                             limits=limits, stop_time=stop_time, model_name=model_name)
    out = Path(out)
    with tempfile.TemporaryDirectory(prefix="boom_sim_fmu_") as tmp:
        tmp = Path(tmp)
        script = tmp / f"{SLAVE_MODULE}.py"
        shutil.copyfile(Path(__file__).with_name("fmu_slave.py"), script)
        config = tmp / "files" / "boom_sim_fmu.json"
        config.parent.mkdir()
        config.write_text(json.dumps(cfg, indent=1), encoding="utf-8")
        scene_file = tmp / "files" / cfg["scene_file"]
        shutil.copyfile(source, scene_file)
        try:
            with atomic_path(out, suffix=".fmu") as part:
                FmuBuilder.build_FMU(script, dest=part, project_files=[config, scene_file],
                                     canGetAndSetFMUstate=True, needsExecutionTool=True,
                                     canHandleVariableCommunicationStepSize=True)
        finally:
            # pythonfmu imports the script by its name: a later build imports it afresh
            sys.modules.pop(SLAVE_MODULE, None)
            if str(tmp) in sys.path:
                sys.path.remove(str(tmp))
    return out, cfg


def _scene_value(scene: dict, key: str):
    """The resolved scene's value at a dotted key; SceneError naming it where there is none."""
    node = scene
    for part in key.split("."):
        if isinstance(node, list) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        elif isinstance(node, dict) and part in node:
            node = node[part]
        else:
            raise SceneError(f"--param {key!r}: no such key in the resolved scene")
    return node
