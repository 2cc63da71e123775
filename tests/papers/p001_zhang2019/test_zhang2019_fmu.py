"""Paper 001's three FMUs (FMI 2.0 and 3.0): valid, exact dependencies and units, the same
results as the blocks in-process bit for bit, exact rollback of the controller FMU (fractional
history included, also through serialisation), libcosim on the exported SSP package agreeing
with our Jacobi mode, bad parameters reported with the instance and the parameter named."""
import dataclasses
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from zhang2019_runs import scenario

from fmus.build import validate
from orchestrator.common.errors import InputError
from orchestrator.cosim.fmu import release_fmu
from orchestrator.cosim.runner import run_scenario
from papers.registry import block_factory

ROOT = Path(__file__).resolve().parents[3]
MODELS = ("RigidSpacecraftWheels", "ASMFEO", "FONTSM")
pytestmark = pytest.mark.fmu


def _stale(folder: Path) -> bool:
    sources = [p for d in ("plant", "estimator", "controller", "fmus", "papers") for p in (ROOT / d).rglob("*.py")]
    newest = max(p.stat().st_mtime for p in sources)
    return any(not (folder / f"{m}.fmu").is_file() or (folder / f"{m}.fmu").stat().st_mtime < newest for m in MODELS)


@pytest.fixture(scope="module")
def fmus2(fmu_dir) -> Path:
    """build/fmus with every catalog FMU (tests/conftest.py builds what is stale)."""
    return fmu_dir


@pytest.fixture(scope="module")
def fmus3(fmi3_dir) -> Path:
    return fmi3_dir


@pytest.mark.parametrize("model", MODELS)
def test_fmus_validate_with_exact_dependencies_and_units(model, fmus2, fmus3):
    for folder in (fmus2, fmus3):
        assert validate(folder / f"{model}.fmu") == []
    md = read_model_description(str(fmus2 / f"{model}.fmu"))
    block = block_factory(model)()
    deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
    for v in block.outputs:
        assert deps[v.name] == sorted(block.feedthrough.get(v.name, ())), v.name
    units = {v.name: (v.unit or "1") for v in md.modelVariables}
    assert all(units[v.name] == v.unit for v in block.inputs + block.outputs + block.parameters)
    starts = {v.name: float(v.start) for v in md.modelVariables if v.causality == "parameter"}
    assert all(starts[v.name] == v.start for v in block.parameters)  # 001's numbers are the defaults


def test_plant_feedthrough_is_structural():
    md_deps = block_factory("RigidSpacecraftWheels")().feedthrough
    assert md_deps["u_wheel[2]"] == ("u_c[2]",)
    assert "omega[1]" not in md_deps and "sigma[3]" not in md_deps


@pytest.mark.parametrize("name", ["zhang2019_fontsm", "zhang2019_passive"])
def test_fmu_run_equals_in_process_bit_for_bit(name, fmus2, fmus3):
    """0.5 s with the faults moved to 0.2 s (through the switch) at 1 ms: FMI 2.0, FMI 3.0 and
    the in-process blocks give identical rows."""
    ref = run_scenario(scenario(name, stop=0.5, onset=0.2))
    for folder in (fmus2, fmus3):
        r = run_scenario(scenario(name, stop=0.5, onset=0.2, in_process=False, fmu_dir=folder))
        assert r.complete and r.columns == ref.columns
        assert np.array_equal(r.data, ref.data)
    e = ref.vector("plant.e")
    assert e[0, 1] == 1.0 and e[-1, 1] == 0.6


def test_controller_fmu_rollback_is_exact_with_its_fractional_history(fmus2):
    path = str(fmus2 / "FONTSM.fmu")
    md = read_model_description(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="ctrl_rb")
    vr = {v.name: v.valueReference for v in md.modelVariables}
    ins = [vr[f"sigma[{i}]"] for i in (1, 2, 3)] + [vr[f"omega[{i}]"] for i in (1, 2, 3)]
    outs = [vr[v.name] for v in md.modelVariables if v.causality == "output"]
    try:
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.setReal([vr["fo_memory"]], [0.25])  # bounded: the history is compacted along the way
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        h = 0.001
        signal = lambda k: [0.2 * np.cos(0.003 * k), -0.1, 0.05 * np.sin(0.01 * k), 0.01, -0.02 * np.cos(0.02 * k), 0.0]  # noqa: E731
        t = 0.0
        for k in range(400):
            fmu.setReal(ins, signal(k))
            fmu.doStep(t, h)
            t += h
        state = fmu.getFMUstate()
        blob = fmu.serializeFMUstate(state)

        def run(t):
            rows = []
            for k in range(400, 450):
                fmu.setReal(ins, signal(k))
                rows.append(fmu.getReal(outs))
                fmu.doStep(t, h)
                t += h
            return rows

        first = run(t)
        fmu.setFMUstate(state)
        second = run(t)
        fmu.setFMUstate(fmu.deSerializeFMUstate(blob))
        third = run(t)
        assert first == second == third
        assert first[0] != first[-1]
        fmu.freeFMUstate(state)
    finally:
        release_fmu(fmu)


@pytest.mark.libcosim
def test_libcosim_runs_the_exported_ssp_like_our_jacobi_mode(fmus2, tmp_path):
    from orchestrator.interop.libcosim import run_libcosim_subprocess
    from orchestrator.scenario.ssp import export_ssp

    s = scenario("zhang2019_fontsm", stop=0.5, onset=0.2, in_process=False, fmu_dir=fmus2)
    ssp = export_ssp(s, tmp_path / "zhang2019_fontsm.ssp", fmu_dir=fmus2)
    lc = run_libcosim_subprocess(ssp, tmp_path / "lc.npz")
    jacobi = run_scenario(scenario("zhang2019_fontsm", stop=0.5, onset=0.2, in_process=False, fmu_dir=fmus2), exchange="jacobi")
    ordered = run_scenario(scenario("zhang2019_fontsm", stop=0.5, onset=0.2, in_process=False, fmu_dir=fmus2), exchange="ordered")
    assert list(lc["columns"]) == jacobi.columns and np.array_equal(lc["time"], jacobi.time)
    scale = np.maximum(np.abs(jacobi.data).max(axis=0), 1e-12)
    assert (np.abs(lc["data"] - jacobi.data) / scale).max() <= 1e-9
    assert (np.abs(lc["data"] - ordered.data) / scale).max() > 1e-4  # the comparison has teeth
    assert jacobi.vector("plant.u_f")[-1, 0] == 0.04  # through the fault switch on the grid


def test_bad_parameter_through_the_fmu_names_instance_and_parameter(fmus2):
    # refused before any FMU starts, in the block's own words (issue 35: its initialize is run in-process)
    with pytest.raises(InputError, match="ctrl.fo_memory: FONTSM refuses these values at initialisation: fo_memory"):
        scenario("zhang2019_fontsm", stop=0.01, in_process=False, fmu_dir=fmus2, overrides={"ctrl": {"fo_memory": 0.0}})
    # and the FMU refuses it itself when a host hands it over (the checks bypassed): an FMI error naming both
    s = scenario("zhang2019_fontsm", stop=0.01, in_process=False, fmu_dir=fmus2)
    ctrl = dataclasses.replace(s.instances["ctrl"], parameters={**s.instances["ctrl"].parameters, "fo_memory": 0.0})
    r = run_scenario(dataclasses.replace(s, instances={**s.instances, "ctrl": ctrl}))
    assert not r.complete
    assert "instance 'ctrl'" in r.error and "fo_memory: the fractional memory length must be > 0 s" in r.error
