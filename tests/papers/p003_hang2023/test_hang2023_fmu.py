"""003's FMUs (Hang2023Plant, Hang2023TSFDO, Hang2023ASMFTC): the three-FMU loop == in-process bit for bit,
rollback exact, libcosim == our Jacobi master to 1e-9, and the bad inputs of the issue through the FMUs:
a step above the stability limit of the published gain, an effectiveness outside [0, 1]."""
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from scenario_text import write

from orchestrator.common.errors import InputError
from orchestrator.cosim.fmu import release_fmu
from orchestrator.cosim.runner import run_scenario
from orchestrator.interop.libcosim import run_libcosim_subprocess
from orchestrator.scenario.ssp import export_ssp
from orchestrator.scenario.toml import load

SCEN = Path(__file__).resolve().parents[3] / "papers" / "p003_hang2023" / "scenarios"


def _scenario(tmp, stop=0.5, onset=0.25, exchange="ordered", step=0.0005, before=1.0):
    text = (SCEN / "hang2023_asmftc_f04.toml").read_text()
    text = text.replace("stop = 60.0", f"stop = {stop}").replace("effectiveness_onset = 20.0", f"effectiveness_onset = {onset}")
    text = text.replace('exchange = "ordered"', f'exchange = "{exchange}"').replace("step = 0.0005", f"step = {step}")
    text = text.replace("effectiveness_before = 1.0", f"effectiveness_before = {before}")
    return write(tmp, text, f"f04_{exchange}_{step}.toml")


@pytest.mark.fmu
@pytest.mark.slow
def test_three_fmu_loop_equals_in_process_bit_for_bit(fmu_dir, tmp_path):
    path = _scenario(tmp_path)
    fmu = run_scenario(load(path))
    inproc = run_scenario(load(path, in_process=True))
    assert fmu.complete and inproc.complete and fmu.columns == inproc.columns
    assert np.array_equal(fmu.data, inproc.data)
    assert fmu.column("plant.effectiveness_now")[-1] == 0.4 and np.abs(fmu.column("est.d0_hat")).max() > 0.05


def _open(fmu_dir, name, inst):
    path = str(fmu_dir / f"{name}.fmu")
    md = read_model_description(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=inst)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu, {v.name: v.valueReference for v in md.modelVariables}


@pytest.mark.fmu
@pytest.mark.parametrize("name, inputs, outputs", [
    ("Hang2023TSFDO", ("theta", "theta_dot", "u"), ("d0_hat", "w_hat[1]", "w_hat[2]", "membership[1]")),
    ("Hang2023ASMFTC", ("theta", "theta_dot", "d0_hat"), ("u", "s", "f_hat", "lambda_hat", "Phi")),
])
def test_rollback_is_exact(fmu_dir, name, inputs, outputs):
    fmu, vr = _open(fmu_dir, name, name + "_rb")
    try:
        ins, outs = [vr[n] for n in inputs], [vr[n] for n in outputs]
        t, h = 0.0, 5e-4

        def steps(t, n, k0):
            rows = []
            for k in range(n):
                fmu.setReal(ins, [0.05 * np.cos(0.01 * (k + k0)), -0.01, 0.1 * np.sin(0.02 * (k + k0))])
                fmu.doStep(t, h)
                t += h
                rows.append(fmu.getReal(outs))
            return rows, t

        _, t = steps(t, 100, 0)  # primed, moving
        state = fmu.getFMUstate()
        blob = fmu.serializeFMUstate(state)
        first, _ = steps(t, 10, 100)
        fmu.setFMUstate(state)
        second, _ = steps(t, 10, 100)
        fmu.setFMUstate(fmu.deSerializeFMUstate(blob))
        third, _ = steps(t, 10, 100)
        assert first == second == third and first[0] != first[-1]
    finally:
        release_fmu(fmu)


@pytest.mark.fmu
@pytest.mark.libcosim
@pytest.mark.slow
def test_libcosim_agrees_with_jacobi_master(fmu_dir, tmp_path):
    path = _scenario(tmp_path, exchange="jacobi")
    ssp = export_ssp(load(path), tmp_path / "h.ssp")
    lc = run_libcosim_subprocess(ssp, tmp_path / "libcosim.npz")
    jac = run_scenario(load(path))
    assert list(lc["columns"]) == jac.columns and np.array_equal(lc["time"], jac.time)
    scale = np.maximum(np.abs(jac.data).max(axis=0), 1e-12)
    assert (np.abs(lc["data"] - jac.data) / scale).max() <= 1e-9
    assert lc["data"][-1, jac.columns.index("plant.effectiveness_now")] == 0.4  # past the switch


@pytest.mark.fmu
@pytest.mark.parametrize("name", ["Hang2023Plant", "Hang2023TSFDO", "Hang2023ASMFTC"])
def test_fmu_needs_only_numpy(fmu_dir, name):
    """numpy, and numba for the compiled kernels (plant/kernels), which the blocks run without."""
    import zipfile

    with zipfile.ZipFile(fmu_dir / f"{name}.fmu") as z:
        req = z.read("resources/requirements.txt").decode().split()
    assert [r.split(">")[0] for r in req] == ["numba", "numpy"], req  # papers/ and the blocks are embedded


@pytest.mark.fmu
def test_step_above_the_stability_limit_is_one_message(fmu_dir, tmp_path):
    r = run_scenario(load(_scenario(tmp_path, stop=0.02, step=0.002)))
    assert not r.complete
    assert "instance 'est'" in r.error and "communication step 2 ms is above the accepted step" in r.error
    assert "stability limit 1.50" in r.error


@pytest.mark.fmu
def test_effectiveness_outside_unit_interval_is_one_message(fmu_dir, tmp_path):
    """The scenario layer refuses 1.5 before any FMU starts: one line naming the file and the
    parameter (plant/physical.py's fractions rule). The FMU keeps its own check for hosts that do
    not pass through the scenario layer (another FMI tool): the master reports its error status as
    one message naming the instance."""
    path = _scenario(tmp_path, stop=0.01, before=1.5)
    with pytest.raises(InputError) as e:
        load(path)
    line = str(e.value)
    assert "\n" not in line and str(path) in line and "instances.plant.parameters.effectiveness_before" in line
    assert "1.5" in line and "[0, 1]" in line
    sc = load(_scenario(tmp_path, stop=0.01, before=1.0))
    sc.instances["plant"].parameters["effectiveness_before"] = 1.5  # past the scenario layer, as a foreign host
    r = run_scenario(sc)
    assert not r.complete and "instance 'plant'" in r.error and "\n" not in r.error
    assert "effectiveness_before must be in [0, 1], got 1.5" in r.error


@pytest.mark.parametrize("module", ["papers.p002_zhang2014.paper", "papers.p003_hang2023.paper"])
def test_paper_descriptor_matches_the_catalog(module):
    from papers.paper import resolve
    from papers.registry import fmu_specs as catalog

    paper = resolve(module + ":PAPER")
    for spec in paper.fmus:
        assert catalog()[spec.model].factory == spec.factory
        assert resolve(spec.factory)().model_name == spec.model
    assert callable(resolve(paper.metrics)) and callable(resolve(paper.report))
    folder = Path(resolve(paper.package).__file__).parent
    for name in paper.demo:
        assert (folder / "scenarios" / f"{name}.toml").is_file()
