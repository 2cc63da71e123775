"""An independent FMI engine: libcosim (Open Simulation Platform) runs our exported SSP
packages and agrees with our master in Jacobi mode over the whole run.

libcosim runs in a subprocess (``orchestrator.libcosim_run``): this process already has
the same pythonfmu FMUs loaded through fmpy. The runs are shortened to 101 s: past the
fault onset (40 s), the attitude command switch (80 s) and the fault jump at 100 s,
which falls exactly on a communication point (sensitive to the time grid)."""
import numpy as np
import pytest
from scenario_text import write

from orchestrator.libcosim_run import run_libcosim_subprocess
from orchestrator.runner import run_scenario
from orchestrator.scenario import load
from orchestrator.ssp import export_ssp

pytestmark = [pytest.mark.libcosim, pytest.mark.fmu]

STOP = 101.0


def _max_rel(a, b):
    scale = np.maximum(np.abs(b).max(axis=0), 1e-12)
    return float((np.abs(a - b) / scale).max())


@pytest.mark.parametrize("name", ["li2023_pd", "li2023_fasmc"])
def test_libcosim_agrees_with_jacobi_master(name, tmp_path, fmu_dir, scenarios):
    text = (scenarios / f"{name}.toml").read_text()
    assert "stop = 200.0" in text
    toml = write(tmp_path, text.replace("stop = 200.0", f"stop = {STOP}", 1), f"{name}.toml")
    scenario = load(toml)
    ssp = export_ssp(scenario, tmp_path / f"{name}.ssp")

    lc = run_libcosim_subprocess(ssp, tmp_path / "libcosim.npz")
    jacobi = run_scenario(load(toml), exchange="jacobi")
    ordered = run_scenario(load(toml), exchange="ordered")
    assert jacobi.complete and ordered.complete
    assert list(lc["columns"]) == jacobi.columns
    assert lc["data"].shape == jacobi.data.shape == (int(round(STOP / scenario.step)) + 1, len(jacobi.columns))
    assert np.array_equal(lc["time"], jacobi.time)  # same communication points, bit for bit

    rel = _max_rel(lc["data"], jacobi.data)
    assert rel <= 1e-9, rel
    # the comparison has teeth: the exchange scheme makes a visible difference
    assert _max_rel(lc["data"], ordered.data) > 1e-4
    # the run really goes through the fault and the new target
    q_e = jacobi.vector("ctrl.q_e")[:, 1:]
    assert np.linalg.norm(q_e[np.searchsorted(jacobi.time, 81.0)]) > 0.1
    assert np.abs(jacobi.vector("plant.f")[-1]).max() >= 1.0
