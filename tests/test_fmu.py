"""The crane as an FMI 2.0 co-simulation FMU (:mod:`sim_core.fmu`, ``boom-sim fmu``): its model
description passes fmpy's validation, and fmpy's co-simulation of it, with given input signals,
gives the numbers of :meth:`sim_core.Simulation.advance` on the same commands and steps (the
FMU runs that same code in this process: equal to the last bit is expected, a relative 1e-12
allowed for a different summation order of the element worker)."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

pytest.importorskip("pythonfmu")
fmpy = pytest.importorskip("fmpy")

from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from sim_core import SceneError, Simulation, load_scene  # noqa: E402
from sim_core.cli import main  # noqa: E402
from sim_core.fmu import build_fmu  # noqa: E402
from sim_core.scene.io import shipped_scenes  # noqa: E402

RTOL = 1e-12


def _component(out: dict, index: list):
    v = out
    for i in index:
        v = v[i]
    return float(v)


def _reference(scene: str, overrides: dict, layout: list, key_names: list, times, commands):
    """Outputs of Simulation.advance(h, commands(t)) at ``times``, one row per time, columns
    in ``layout``'s order."""
    sim = Simulation(load_scene(scene, overrides))
    rows = []
    for k, t in enumerate(times):
        if k:
            sim.advance(t - times[k - 1], commands(times[k - 1]))
        assert sim.t == pytest.approx(t, abs=1e-12)
        out = sim.outputs(key_names)
        rows.append([_component(out[o["key"]], o["index"]) for o in layout])
    return np.array(rows)


def _compare(res, cfg, ref):
    got = np.array([[row[o["name"]] for o in cfg["outputs"]] for row in res])
    scale = np.maximum(np.max(np.abs(ref), axis=0), 1e-300)
    err = np.max(np.abs(got - ref), axis=0) / scale
    worst = int(np.argmax(err))
    assert err[worst] <= RTOL, (cfg["outputs"][worst]["name"], err[worst])


def test_modal_crane_fmu_validates_and_matches_the_stepping_api(tmp_path):
    """The modal ROM (``telescopic_extraction_rl``) with payload.mass as a parameter and a
    piecewise-constant telescopic command (0.1 then -0.05 m/s^2, switched between two
    communication points: fmpy ends a step at the switch, the FMU's variable communication
    step, and holds each value over its steps)."""
    path, cfg = build_fmu("telescopic_extraction_rl", tmp_path / "rl.fmu", step_size=0.05,
                          parameters=["payload.mass"])
    assert validate_fmu(str(path)) == []
    md = fmpy.read_model_description(str(path))
    names = {v.name: v for v in md.modelVariables}
    assert names["payload.mass"].causality == "parameter"
    assert names["command_telescopic"].causality == "input"
    assert {"tip_position_x", "tip_position_z", "actuator_telescopic_position"} <= set(names)
    assert md.coSimulation.canGetAndSetFMUstate

    h, t_switch, t_stop = 0.05, 0.325, 0.6
    sig = np.array([(0.0, 0.1), (t_switch, 0.1), (t_switch, -0.05), (1.0, -0.05)],
                   dtype=[("time", float), ("command_telescopic", float)])
    res = fmpy.simulate_fmu(str(path), stop_time=t_stop, step_size=h, input=sig,
                            start_values={"payload.mass": 21000.0})
    times = res["time"]
    grid = np.sort(np.append(np.arange(13) * h, t_switch))
    assert np.allclose(times, grid, rtol=0, atol=1e-12)

    def commands(t):
        return {"telescopic": 0.1 if t < t_switch else -0.05}
    ref = _reference("telescopic_extraction_rl", {"payload.mass": 21000.0}, cfg["outputs"],
                     cfg["output_keys"], times, commands)
    _compare(res, cfg, ref)
    # the command reached the model: the stroke rate is the integral of the commands
    rate = 0.1 * np.minimum(times, t_switch) - 0.05 * np.maximum(times - t_switch, 0.0)
    assert np.allclose(res["actuator_telescopic_rate"], rate, rtol=1e-12, atol=1e-15)


def test_fmu_state_rolls_back_and_a_bad_command_fails_the_step(tmp_path):
    """fmi2GetFMUstate / fmi2SetFMUstate (Simulation.save_state / restore_state): steps after
    a restore repeat those after the save; a command beyond the actuator's acceleration limit
    fails fmi2DoStep (fmi2Discard: the step is not taken, the simulation stays as it was)."""
    path, cfg = build_fmu("telescopic_extraction_rl", tmp_path / "rl.fmu", step_size=0.05)
    md = fmpy.read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(str(path)),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="crane")
    fmu.instantiate()
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        outs = [vr[o["name"]] for o in cfg["outputs"]]
        fmu.setReal([vr["command_telescopic"]], [0.2])
        fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.05)
        state = fmu.getFMUstate()
        runs = []
        for _ in range(2):
            fmu.setFMUstate(state)
            fmu.setReal([vr["command_telescopic"]], [-0.1])
            for k in (1, 2):
                fmu.doStep(currentCommunicationPoint=0.05 * k, communicationStepSize=0.05)
            runs.append(fmu.getReal(outs))
        fmu.freeFMUstate(state)
        assert runs[0] == runs[1]
        before = fmu.getReal(outs)
        limit = Simulation("telescopic_extraction_rl").limits["telescopic"].accel
        fmu.setReal([vr["command_telescopic"]], [10.0 * limit])
        with pytest.raises(Exception, match=r"fmi2DoStep failed with status 2 \(discard\)"):
            fmu.doStep(currentCommunicationPoint=0.15, communicationStepSize=0.05)
        assert fmu.getReal(outs) == before
        fmu.terminate()
    finally:
        fmu.freeInstance()


def test_full_crane_fmu_matches_the_stepping_api(tmp_path):
    """The full model (``crane_lift_and_slew``, 3 nodes a boom) from the command line: every
    actuator an input and accelerated (within its limits),
    the default outputs (tip, sway angles, cylinder forces, slew torque, rope force, the
    actuators), fmpy's run equal to Simulation.advance's."""
    out = tmp_path / "crane.fmu"
    assert main(["fmu", "crane_lift_and_slew", "--out", str(out), "--set", "booms.n_nodes=3",
                 "--step", "0.02", "--param", "payload.mass"]) == 0
    assert validate_fmu(str(out)) == []
    with zipfile.ZipFile(out) as z:        # the FMU carries its scene and configuration
        cfg = json.loads(z.read("resources/boom_sim_fmu.json"))
        scene_file = z.read("resources/scene.toml")
    assert scene_file == shipped_scenes()["crane_lift_and_slew"].read_bytes()
    assert cfg["overrides"] == {"booms.n_nodes": "3"}
    assert cfg["resolved_scene"]["payload"]["mass"] == 25000.0
    md = fmpy.read_model_description(str(out))
    assert [v.name for v in md.modelVariables if v.causality == "output"] == \
        [o["name"] for o in cfg["outputs"]]
    assert {"sway_angle_0", "sway_angle_1", "luffing_cylinder_force",
            "hoist_rope_force"} <= {o["name"] for o in cfg["outputs"]}
    cmd = {"telescopic": 0.2, "luffing": 0.01, "slew": 0.01, "hoist": -0.5}
    sig = np.array([(0.0, *cmd.values()), (1.0, *cmd.values())],
                   dtype=[("time", float)] + [(f"command_{a}", float) for a in cmd])
    res = fmpy.simulate_fmu(str(out), stop_time=0.1, step_size=0.02, input=sig,
                            start_values={"payload.mass": 21000.0})
    assert np.allclose(res["time"], np.arange(6) * 0.02, rtol=0, atol=1e-12)
    ref = _reference("crane_lift_and_slew", {"booms.n_nodes": "3", "payload.mass": 21000.0},
                     cfg["outputs"], cfg["output_keys"], res["time"], lambda t: cmd)
    _compare(res, cfg, ref)
    for a, acc in cmd.items():     # the commands reached the drives: rate = acceleration t
        assert res[f"actuator_{a}_rate"][-1] == pytest.approx(acc * 0.1, rel=1e-12)


def test_bad_fmu_options_are_scene_errors(tmp_path):
    with pytest.raises(SceneError, match="--outputs"):
        build_fmu("telescopic_extraction_rl", tmp_path / "x.fmu", step_size=0.05,
                  outputs=["no_such_output"])
    with pytest.raises(SceneError, match="--param 'payload.nope'"):
        build_fmu("telescopic_extraction_rl", tmp_path / "x.fmu", step_size=0.05,
                  parameters=["payload.nope"])
    with pytest.raises(SceneError, match="--inputs"):
        build_fmu("telescopic_extraction_rl", tmp_path / "x.fmu", step_size=0.05,
                  inputs=["slew"])
    with pytest.raises(SceneError, match="--step"):
        build_fmu("telescopic_extraction_rl", tmp_path / "x.fmu", step_size=0.0)
    assert not list(tmp_path.iterdir())


def test_output_variables_name_each_component():
    """Vectors of the global frame get _x, _y, _z; other arrays (three drives' forces, the pads'
    forces per overlap, pad and component) their indices; the actuators their state."""
    from sim_core.fmu import layout
    out = {"tip_position": np.arange(3.0), "drive_forces": np.arange(3.0),
           "pad_forces": np.arange(4.0).reshape(1, 2, 2), "hoist_rope_force": 5.0,
           "actuators": {"slew": (1.0, 2.0, 3.0)}}
    rows = layout(out, list(out))
    assert [r["name"] for r in rows] == [
        "tip_position_x", "tip_position_y", "tip_position_z",
        "drive_forces_0", "drive_forces_1", "drive_forces_2",
        "pad_forces_0_0_0", "pad_forces_0_0_1", "pad_forces_0_1_0", "pad_forces_0_1_1",
        "hoist_rope_force",
        "actuator_slew_position", "actuator_slew_rate", "actuator_slew_acceleration"]
    assert [_component(out[r["key"]], r["index"]) for r in rows] == \
        [0.0, 1.0, 2.0, 0.0, 1.0, 2.0, 0.0, 1.0, 2.0, 3.0, 5.0, 1.0, 2.0, 3.0]


def test_a_parameter_out_of_range_fails_initialization_naming_it(tmp_path):
    path, _ = build_fmu("telescopic_extraction_rl", tmp_path / "rl.fmu", step_size=0.05,
                        parameters=["payload.mass"])
    log = []
    with pytest.raises(Exception, match="fmi2ExitInitializationMode failed"):
        fmpy.simulate_fmu(str(path), stop_time=0.1, step_size=0.05,
                          start_values={"payload.mass": -1.0},
                          logger=lambda *args: log.append(args[4]), debug_logging=True)
    assert any(b"payload.mass = -1.0: out of range" in m for m in log)
