"""002's FMUs (Zhang2014Plant, Zhang2014Hinf): FMU loop == in-process bit for bit, FMI 3.0 == FMI 2.0,
rollback exact, libcosim == our Jacobi master to 1e-9 (SSP export), a scenario error is one message."""
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

SCEN = Path(__file__).resolve().parents[3] / "papers" / "p002_zhang2014" / "scenarios"


def _scenario(tmp, stop, name="zhang2014_hinf_w05", exchange="ordered"):
    write(tmp, (SCEN / "zhang2014_hinf_w1.toml").read_text(), "zhang2014_hinf_w1.toml")
    text = (SCEN / f"{name}.toml").read_text()
    text += f'\n[timing]\nstart = 0.0\nstop = {stop}\nstep = 0.01\nexchange = "{exchange}"\n'
    return write(tmp, text, f"{name}_short.toml")


@pytest.mark.fmu
def test_fmu_loop_equals_in_process_bit_for_bit(fmu_dir, tmp_path):
    path = _scenario(tmp_path, 5.0)
    fmu = run_scenario(load(path))
    inproc = run_scenario(load(path, in_process=True))
    assert fmu.complete and inproc.complete and fmu.columns == inproc.columns
    assert np.array_equal(fmu.data, inproc.data)
    assert abs(fmu.column("plant.theta")[-1] - 0.08) > 0.01  # it moved (0.099 rad at 5 s)


@pytest.mark.fmu
@pytest.mark.slow
def test_fmi3_equals_fmi2(fmu_dir, fmi3_dir, tmp_path):
    d3 = fmi3_dir  # validation of every FMI 3.0 FMU: tests/fmus/test_fmus.py
    path = _scenario(tmp_path, 2.0)
    r2 = run_scenario(load(path))
    r3 = run_scenario(load(path, fmu_dir=d3))
    assert r3.complete and np.array_equal(r2.data, r3.data)


@pytest.mark.fmu
def test_plant_rollback_is_exact(fmu_dir):
    path = str(fmu_dir / "Zhang2014Plant.fmu")
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="z_rb")
    try:
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.setReal([vr["effectiveness"], vr["eta_dot_init[1]"]], [0.5, 0.02])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        out = [vr[n] for n in ("theta", "theta_dot", "eta[1]", "eta_dot[2]", "tau_applied", "d_vib")]
        t, h = 0.0, 0.01
        for k in range(200):
            fmu.setReal([vr["u"]], [-0.3 * np.cos(0.1 * k)])
            fmu.doStep(t, h)
            t += h
        state = fmu.getFMUstate()
        blob = fmu.serializeFMUstate(state)

        def ten(t):
            rows = []
            for k in range(10):
                fmu.setReal([vr["u"]], [0.1 * k])
                fmu.doStep(t, h)
                t += h
                rows.append(fmu.getReal(out))
            return rows

        first = ten(t)
        fmu.setFMUstate(state)
        second = ten(t)
        fmu.setFMUstate(fmu.deSerializeFMUstate(blob))
        third = ten(t)
        assert first == second == third and first[0] != first[-1]
    finally:
        release_fmu(fmu)


@pytest.mark.fmu
@pytest.mark.libcosim
@pytest.mark.slow
def test_libcosim_agrees_with_jacobi_master(fmu_dir, tmp_path):
    path = _scenario(tmp_path, 10.0, "zhang2014_hinf_w02", exchange="jacobi")
    ssp = export_ssp(load(path), tmp_path / "z.ssp")
    lc = run_libcosim_subprocess(ssp, tmp_path / "libcosim.npz")
    jac = run_scenario(load(path))
    assert list(lc["columns"]) == jac.columns and np.array_equal(lc["time"], jac.time)
    scale = np.maximum(np.abs(jac.data).max(axis=0), 1e-12)
    assert (np.abs(lc["data"] - jac.data) / scale).max() <= 1e-9
    ordered = run_scenario(load(_scenario(tmp_path, 10.0, "zhang2014_hinf_w02")))
    assert (np.abs(lc["data"] - ordered.data) / scale).max() > 1e-4  # the comparison has teeth


def test_scenario_with_a_wrong_coupling_size_is_one_message(tmp_path):
    text = (SCEN / "zhang2014_hinf_w1.toml").read_text().replace(
        "effectiveness_onset = 0.0", "effectiveness_onset = 0.0\nF = [1.0, 2.0, 3.0]")
    with pytest.raises(InputError, match=r"instances.plant.parameters.F.*expected shape \(2,\) for 2 elements, got \(3,\)"):
        load(write(tmp_path, text), in_process=True)
