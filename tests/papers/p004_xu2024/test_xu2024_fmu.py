"""004's FMUs (today's ``ftcsim build``): valid, FMU loop == in-process bit for bit for fixed
seeds, and the Markov FMU's rollback across a jump is exact (its PCG64 state is in the FMU state)."""
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from fmus.build import build_fmu, validate
from orchestrator.cosim.fmu import release_fmu
from orchestrator.cosim.runner import run_scenario
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.toml import load
from papers.registry import fmu_specs

SCEN = Path(__file__).resolve().parents[3] / "papers" / "p004_xu2024" / "scenarios"
TS_LOOP = ("Xu2024TSPlant", "Xu2024MarkovFaults", "Xu2024SampledFTC", "Xu2024FaultActuator", "Xu2024Disturbance")


@pytest.fixture(scope="module")
def fmu_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("xu2024_fmus")
    for name in TS_LOOP:
        build_fmu(fmu_specs()[name], out)
    return out


@pytest.mark.fmu
@pytest.mark.slow
def test_fmus_validate(fmu_dir):
    for name in TS_LOOP:
        assert validate(fmu_dir / f"{name}.fmu") == [], name


@pytest.mark.fmu
@pytest.mark.slow
def test_fmu_loop_equals_in_process_bit_for_bit(fmu_dir):
    """xu2024_ts over 1 s (several mode jumps and ~13 samples) with seeds 3: every recorded
    signal identical in the five-FMU run and the in-process run."""
    runs = {}
    for mode in ("fmu", "inprocess"):
        sc = with_overrides(load(SCEN / "xu2024_ts.toml", fmu_dir=fmu_dir, in_process=(mode == "inprocess")), stop=1.0,
                            parameters={"faults.seed": 3.0, "ctrl.sample_seed": 3.0})
        runs[mode] = run_scenario(sc)
    a, b = runs["fmu"], runs["inprocess"]
    assert a.complete and b.complete and a.columns == b.columns
    assert np.array_equal(a.data, b.data)
    assert np.count_nonzero(np.diff(b.column("faults.mode"))) >= 1
    assert len(np.unique(b.column("ctrl.t_k"))) >= 10


@pytest.mark.fmu
@pytest.mark.slow
def test_markov_fmu_rollback_across_a_jump_is_exact(fmu_dir):
    path = str(fmu_dir / "Xu2024MarkovFaults.fmu")
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="faults_rb")
    try:
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.setReal([vr["seed"]], [9.0])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        out = [vr["mode"], vr["t_next_jump"], vr["n_jumps"]]
        t, h = 0.0, 0.001
        while fmu.getReal([vr["t_next_jump"]])[0] > t + 0.01:
            fmu.doStep(t, h)
            t += h
        n0 = fmu.getReal([vr["n_jumps"]])[0]
        state = fmu.getFMUstate()
        blob = fmu.serializeFMUstate(state)

        def run(t0):
            rows = []
            for k in range(40):
                fmu.doStep(t0 + k * h, h)
                rows.append(fmu.getReal(out))
            return rows

        first = run(t)
        assert first[-1][2] > n0  # a jump was crossed
        fmu.setFMUstate(state)
        assert run(t) == first
        fmu.setFMUstate(fmu.deSerializeFMUstate(blob))
        assert run(t) == first
        fmu.freeFMUstate(state)
    finally:
        release_fmu(fmu)
