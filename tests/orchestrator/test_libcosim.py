"""An independent FMI engine: libcosim (Open Simulation Platform) runs our exported SSP
packages like our master in Jacobi mode. The fixed-step comparison over the whole 200 s of
li2023_pd and li2023_fasmc shares its reference runs with the other engines
(tests/orchestrator/test_engines.py); here: the multirate package and the time grid.

libcosim runs in a subprocess (``orchestrator.interop.libcosim``): this process already has
the same pythonfmu FMUs loaded through fmpy."""
import numpy as np
import pytest
from scenario_text import write

from orchestrator.cosim.runner import run_scenario
from orchestrator.interop.libcosim import run_libcosim_subprocess
from orchestrator.scenario.ssp import export_ssp, load_ssp
from orchestrator.scenario.toml import load

pytestmark = [pytest.mark.libcosim, pytest.mark.fmu]



def _max_rel(a, b):
    scale = np.maximum(np.abs(b).max(axis=0), 1e-12)
    return float((np.abs(a - b) / scale).max())


MULTIRATE = {  # li2023_fasmc, plant and observer at 1 ms, controller at 10 ms, 1.2 s
    "stop = 200.0": "stop = 1.2", "step = 0.01": "step = 0.001", 'exchange = "ordered"': 'exchange = "jacobi"',
    '[instances.ctrl]\nfmu = "FASMC"': '[instances.ctrl]\nfmu = "FASMC"\nstep = 0.01',
    "fault_onset = 40.0\nu_max": "fault_onset = 0.5\nu_max",  # the fault steps inside the window
    "times = [0.0, 80.0]": "times = [0.0, 1.0035]",  # a command switch between two controller samples
}


def test_libcosim_runs_the_multirate_package_like_our_jacobi_multirate_run(tmp_path, fmu_dir, scenarios):
    """The export carries the controller's step as libcosim's step-size hint; libcosim's fixed-step
    algorithm with that decimation agrees with our Jacobi multirate run to 1e-9 relative."""
    text = (scenarios / "li2023_fasmc.toml").read_text()
    for old, new in MULTIRATE.items():
        assert old in text
        text = text.replace(old, new, 1)
    toml = write(tmp_path, text, "multirate.toml")
    scenario = load(toml)
    assert scenario.step_policy == "multirate" and scenario.instances["ctrl"].step == 0.01
    ssp = export_ssp(scenario, tmp_path / "multirate.ssp")
    back = load_ssp(ssp)  # the hint reads back as the instance's step
    assert back.step_policy == "multirate" and back.instances["ctrl"].step == 0.01
    assert back.instances["plant"].step is None

    lc = run_libcosim_subprocess(ssp, tmp_path / "libcosim.npz")
    ours = run_scenario(load(toml))
    assert ours.complete and ours.info["step_statistics"]["do_steps"] == {"plant": 1200, "est": 1200, "ctrl": 120}
    assert list(lc["columns"]) == ours.columns
    assert np.array_equal(lc["time"], ours.time) and len(ours.time) == 1201
    rel = _max_rel(lc["data"], ours.data)
    assert rel <= 1e-9, rel
    # teeth: libcosim really held the controller for 10 base steps (decimation 10, not 1) ...
    u = lc["data"][:, list(lc["columns"]).index("ctrl.u[1]")]
    blocks = u[:-1].reshape(-1, 10)  # rows 10j .. 10j+9 hold the sample of t_10j
    assert np.all(blocks == blocks[:, :1]) and len(np.unique(blocks[:, 0])) > 10
    # ... and the fault and the command switch happened inside the window
    assert np.abs(ours.vector("plant.f")[-1]).max() >= 1.0
