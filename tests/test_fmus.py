"""Built FMUs: fmpy validation, exact dependencies, units, rollback."""
import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from fmus.build import validate
from fmus.catalog import CATALOG, block_class
from orchestrator.components import release_fmu


@pytest.mark.parametrize("name", sorted(CATALOG))
def test_fmpy_validation_reports_nothing(name, fmu_dir):
    assert validate(fmu_dir / f"{name}.fmu") == []


@pytest.mark.parametrize("name", sorted(CATALOG))
def test_model_description_matches_block(name, fmu_dir):
    md = read_model_description(str(fmu_dir / f"{name}.fmu"))
    block = block_class(name)()
    assert md.coSimulation.needsExecutionTool is False
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
    for v in block.outputs:
        assert deps[v.name] == sorted(block.feedthrough.get(v.name, ())), v.name
    assert {u.variable.name for u in md.initialUnknowns} == {v.name for v in block.outputs}
    units = {v.name: v.unit for v in md.modelVariables}
    for v in block.inputs + block.outputs + block.parameters:
        assert (units[v.name] or "1") == v.unit, v.name


def test_plant_dependencies_are_exact(fmu_dir):
    md = read_model_description(str(fmu_dir / "FlexibleSpacecraft.fmu"))
    deps = {u.variable.name: [d.name for d in u.dependencies] for u in md.outputs}
    assert deps["omega[1]"] == [] and deps["q[0]"] == [] and deps["eta[2]"] == []
    assert sorted(deps["tau_applied[2]"]) == ["u[1]", "u[2]", "u[3]"]


def _open(fmu_dir, name, instance):
    path = str(fmu_dir / f"{name}.fmu")
    md = read_model_description(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier, instanceName=instance)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    return fmu, {v.name: v.valueReference for v in md.modelVariables}


def test_plant_rollback_is_exact(fmu_dir):
    """Save state, step 10 times, restore, step again: identical outputs, bit for bit,
    also through serialisation (bytes) and with time-varying faults active."""
    fmu, vr = _open(fmu_dir, "FlexibleSpacecraft", "plant_rb")
    try:
        fmu.setReal([vr["omega_init[1]"], vr["eta_dot_init[2]"], vr["fault_scale"], vr["disturbance_scale"], vr["h_max"]], [0.02, 0.05, 1.0, 1.0, 0.004])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        out = [v for n, v in vr.items() if n.split("[")[0] in ("q", "omega", "eta", "eta_dot", "tau_applied", "f", "d_vib")]
        t, h = 0.0, 0.01
        for k in range(4500):  # into the fault period
            fmu.setReal([vr["u[1]"], vr["u[2]"]], [0.3 * np.sin(0.01 * k), -0.2])
            fmu.doStep(t, h)
            t += h
        state = fmu.getFMUstate()
        blob = fmu.serializeFMUstate(state)

        def ten(t):
            rows = []
            for k in range(10):
                fmu.setReal([vr["u[1]"]], [0.1 * k])
                fmu.doStep(t, h)
                t += h
                rows.append(fmu.getReal(out))
            return rows

        first = ten(t)
        fmu.setFMUstate(state)
        second = ten(t)
        fmu.setFMUstate(fmu.deSerializeFMUstate(blob))
        third = ten(t)
        assert first == second == third
        assert first[0] != first[-1]
        fmu.freeFMUstate(state)
    finally:
        release_fmu(fmu)


def test_parameters_are_fixed_after_initialisation(fmu_dir):
    from fmpy.fmi1 import FMICallException

    fmu, vr = _open(fmu_dir, "PDController", "ctrl_fixed")
    try:
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        with pytest.raises(FMICallException):
            fmu.setReal([vr["k_p"]], [1.0])
    finally:
        release_fmu(fmu)


def test_cli_validate(fmu_dir, capsys):
    from orchestrator.cli import main

    assert main(["validate", "--dir", str(fmu_dir)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) >= len(CATALOG) and all(line.endswith(": valid") for line in out)
