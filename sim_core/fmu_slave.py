"""The slave of a crane FMU (FMI 2.0 co-simulation, pythonfmu's ``Fmi2Slave``): the file that
:func:`sim_core.fmu.build_fmu` packs into the FMU's resources beside ``boom_sim_fmu.json``, the
FMU's configuration (the scene file, the fixed overrides, the parameters, the inputs and the
output layout).

At instantiation it reads the configuration; on leaving initialization mode it builds
``sim_core.Simulation(load_scene(scene, {**overrides, **parameters}))`` with the parameters'
values as set by the importer; every ``fmi2DoStep(t, h)`` runs ``Simulation.advance(h,
{actuator: command})`` with the inputs' current values (accelerations held over the step), and
the outputs are the scalar components of ``Simulation.outputs(names)`` at the step's end.  The
FMU's state (``fmi2GetFMUstate`` / ``fmi2SetFMUstate``) is ``Simulation.save_state`` with the
inputs.  The importer's Python runs this file: it needs this package (``sim_core``), of the
version that built the FMU, on its path.
"""

from __future__ import annotations

import json
from pathlib import Path
from xml.etree.ElementTree import SubElement

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Initial, Fmi2Status

#: the configuration file in the FMU's resources (written by sim_core.fmu.build_fmu)
CONFIG = "boom_sim_fmu.json"


class BoomSimSlave(Fmi2Slave):
    """A scene of sim_core as an FMI 2.0 co-simulation slave (module docstring)."""

    author = "telescopic-boom-sim"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        cfg = json.loads((Path(self.resources) / CONFIG).read_text(encoding="utf-8"))
        self._cfg = cfg
        self.modelName = cfg["model_name"]
        self.description = cfg["description"]
        self.version = cfg["sim_core_version"]
        self.default_experiment = DefaultExperiment(start_time=0.0, stop_time=cfg["stop_time"],
                                                    step_size=cfg["step_size"])
        self._params = {p["key"]: float(p["start"]) for p in cfg["parameters"]}
        self._commands = {a["actuator"]: 0.0 for a in cfg["inputs"]}
        self._sim = None
        self._values: dict | None = None        # the outputs' components at the current time
        for p in cfg["parameters"]:
            self.register_variable(Real(
                p["key"], causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
                initial=Fmi2Initial.exact, description=p["description"],
                getter=_getter(self._params, p["key"]), setter=_setter(self._params, p["key"])),
                nested=False)
        for a in cfg["inputs"]:
            self.register_variable(Real(
                a["name"], causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                description=a["description"], getter=_getter(self._commands, a["actuator"]),
                setter=_setter(self._commands, a["actuator"])), nested=False)
        for o in cfg["outputs"]:
            self.register_variable(Real(
                o["name"], causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                description=o["description"], getter=self._output_getter(o["name"])),
                nested=False)

    def to_xml(self, model_options=None):
        """pythonfmu's model description with ModelStructure/InitialUnknowns added: FMI 2.0
        (section 2.2.8) lists there every output whose ``initial`` is calculated, which all
        of these are (their values at t = 0 come from the scene's initial state)."""
        root = super().to_xml(model_options or {})
        structure = root.find("ModelStructure")
        outputs = structure.find("Outputs")
        if outputs is not None:
            initial = SubElement(structure, "InitialUnknowns")
            for unknown in outputs:
                SubElement(initial, "Unknown", attrib=dict(unknown.attrib))
        return root

    # -- the simulation -------------------------------------------------------------------------
    def _simulation(self):
        """The Simulation, built with the parameters' current values on first use."""
        if self._sim is None:
            from sim_core._version import __version__
            from sim_core.api import load_scene
            from sim_core.simulation import Simulation
            cfg = self._cfg
            if __version__ != cfg["sim_core_version"]:
                self.log(f"sim_core {__version__} runs an FMU built with sim_core "
                         f"{cfg['sim_core_version']}: the results may differ",
                         Fmi2Status.warning)
            overrides = dict(cfg["overrides"])
            for p in cfg["parameters"]:
                v = self._params[p["key"]]
                overrides[p["key"]] = int(round(v)) if p["integer"] else v
            scene = load_scene(Path(self.resources) / cfg["scene_file"], overrides)
            self._sim = Simulation(scene, limits=cfg["limits"])
        return self._sim

    def _output_getter(self, name: str):
        def get() -> float:
            if self._values is None:
                self._values = _components(self._simulation().outputs(self._cfg["output_keys"]),
                                           self._cfg["outputs"])
            return self._values[name]
        return get

    def exit_initialization_mode(self):
        try:
            self._simulation()
        except Exception as exc:      # a bad parameter (SceneError), a failed statics solve
            self.log(f"{type(exc).__name__}: {exc}", Fmi2Status.error)
            raise

    def do_step(self, current_time: float, step_size: float) -> bool:
        sim = self._simulation()
        if abs(current_time - sim.t) > 1e-9 * max(1.0, abs(sim.t)):
            self.log(f"doStep at t = {current_time:.9g} s, but the simulation stands at "
                     f"t = {sim.t:.9g} s (no rollback: steps must follow each other)",
                     Fmi2Status.error)
            return False
        try:
            sim.advance(step_size, dict(self._commands))
        except Exception as exc:       # every failure goes to the importer's log, typed
            self.log(f"{type(exc).__name__}: {exc}", Fmi2Status.error)
            return False
        self._values = None
        return True

    # -- fmi2GetFMUstate / fmi2SetFMUstate --------------------------------------------------------
    def _get_fmu_state(self) -> dict:
        return {"sim": self._simulation().save_state(), "commands": dict(self._commands)}

    def _set_fmu_state(self, state: dict) -> None:
        self._simulation().restore_state(state["sim"])
        self._commands.update(state["commands"])
        self._values = None


def _getter(table: dict, key: str):
    return lambda: table[key]


def _setter(table: dict, key: str):
    def put(value) -> None:
        table[key] = float(value)
    return put


def _components(out: dict, layout: list[dict]) -> dict:
    """{variable name: float} from ``Simulation.outputs``: each variable's output key and its
    index path into that output (the actuators' dict by name, arrays by position)."""
    values = {}
    for o in layout:
        v = out[o["key"]]
        for i in o["index"]:
            v = v[i]
        values[o["name"]] = float(v)
    return values
