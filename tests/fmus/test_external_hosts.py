"""Issue 24: an exported package runs in Ecos with Ecos's plain commands.

Ecos applies an SSP's SSV values only under a parameter-set name; with a plain ``init()`` it ran
the FMUs' defaults (pd: q = (1, 0, 0, 0) instead of the scenario's). The package now carries, per
instance, a configured copy of our FMU whose modelDescription start values are the scenario's
(fmus/configure.py), which the FMU starts from (fmus/block_runtime.py). Checked here: Ecos
in-process with plain ``init()`` against our Jacobi master (recording after the transfer, as
Ecos does) over 60 s of li2023_pd, to 1e-9; and Ecos's command line (a non-Python host) with the
environment ``ftcsim host-env`` prints, against the same run to the 6 decimals of its CSV."""
import os
import shutil
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fmus.block_runtime import model_description_starts
from fmus.configure import configured_fmu, honours_start_values
from fmus.host_env import host_environment
from orchestrator.api import load
from orchestrator.cosim.runner import run_scenario
from orchestrator.interop.engines import run_engine
from orchestrator.scenario.ssp import export_ssp, load_ssp

STOP = 60.0


@pytest.fixture(scope="module")
def pd60(tmp_path_factory, fmu_dir):
    folder = tmp_path_factory.mktemp("pd60")
    ssp = export_ssp(load("li2023_pd", stop=STOP), folder / "li2023_pd.ssp")
    after = run_scenario(load_ssp(ssp), exchange="jacobi", sample="after")
    assert after.complete and len(after.time) == 6001
    return ssp, after, folder


@pytest.mark.fmu
def test_the_package_carries_configured_copies_of_our_fmus(pd60, fmu_dir, tmp_path):
    ssp, _, _ = pd60
    sc = load_ssp(ssp)
    plant = sc.instances["plant"]
    assert honours_start_values(plant.fmu)
    with zipfile.ZipFile(plant.fmu) as z:
        z.extractall(tmp_path / "plant")
    starts = model_description_starts(tmp_path / "plant" / "resources")
    with zipfile.ZipFile(fmu_dir / "FlexibleSpacecraft.fmu") as z:
        z.extractall(tmp_path / "stock")
    defaults = model_description_starts(tmp_path / "stock" / "resources")
    for name, value in plant.parameters.items():
        assert starts[name] == value
    changed = [n for n, v in plant.parameters.items() if defaults[n] != v]
    assert "q_init[1]" in changed  # the package's values are not the FMU's defaults
    # and an FMU that does not say it honours its start values is never configured
    assert not honours_start_values(tmp_path / "nothing.fmu")
    with pytest.raises(ValueError, match="no variables"):
        configured_fmu(fmu_dir / "PDController.fmu", {"not_a_variable": 1.0})


@pytest.mark.fmu
def test_a_configured_fmu_starts_from_its_start_values(fmu_dir, tmp_path):
    """The same FMU in our master: set nothing, and its outputs follow the configured q_init."""
    from fmu_driver import Driver

    cfg = tmp_path / "FlexibleSpacecraft.fmu"
    q = [0.8, 0.0, 0.6, 0.0]
    cfg.write_bytes(configured_fmu(fmu_dir / "FlexibleSpacecraft.fmu", {f"q_init[{i}]": x for i, x in enumerate(q)}))
    for path, expected in ((fmu_dir / "FlexibleSpacecraft.fmu", [1.0, 0.0, 0.0, 0.0]), (cfg, q)):
        drv = Driver(path, "plant")
        try:
            drv.initialize()
            assert drv.get([f"q[{i}]" for i in range(4)]) == pytest.approx(expected, abs=1e-15)
        finally:
            drv.free()


@pytest.mark.engines
@pytest.mark.slow
def test_ecos_plain_init_agrees_with_our_jacobi_master(pd60):
    ssp, after, folder = pd60
    z = run_engine("ecos", ssp, folder / "ecos.npz")  # orchestrator.interop.engines.run_ecos: sim.init(start) only
    assert list(z["columns"]) == after.columns and z["data"].shape == after.data.shape
    scale = np.maximum(np.abs(after.data).max(axis=0), 1e-12)
    assert float((np.abs(z["data"] - after.data) / scale).max()) <= 1e-9
    assert np.abs(z["time"] - after.time).max() <= 1e-9


@pytest.mark.engines
@pytest.mark.slow
def test_ecos_cli_runs_a_package_with_the_documented_environment(pd60, tmp_path):
    """docs/external-tools.md: ``eval "$(ftcsim host-env)"``, then ``ecos simulate --path PKG.ssp
    --stepSize 0.01 --stopTime 60`` (the wheel's binary, made executable; libtbb from the tbb wheel)."""
    ssp, after, _ = pd60
    import importlib.util

    ecos = tmp_path / "ecos"  # found without importing ecospy (its library needs libtbb loaded first)
    shutil.copyfile(Path(importlib.util.find_spec("ecospy").origin).parent / "binaries" / "ecos", ecos)
    ecos.chmod(ecos.stat().st_mode | stat.S_IXUSR)
    pkg = tmp_path / ssp.name
    shutil.copyfile(ssp, pkg)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "LD_"))}
    env.update(host_environment(), LD_LIBRARY_PATH=str(Path(sys.prefix) / "lib"))
    p = subprocess.run([str(ecos), "simulate", "--path", str(pkg), "--stepSize", "0.01", "--stopTime", str(STOP)],
                       cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, (p.stdout + p.stderr)[-2000:]
    # Ecos separates by ", " and does not quote names: matrix names (J[1,2]) hold a bare comma
    csv = pd.read_csv(tmp_path / "li2023_pd.csv", sep=", ", engine="python")
    assert len(csv) == len(after.time) and abs(csv["time"].iloc[-1] - STOP) < 1e-9
    for name in ("plant.q[1]", "plant.q[2]", "plant.omega[3]", "ctrl.u[1]", "ctrl.u[3]"):
        inst, var = name.split(".", 1)
        ours = after.data[:, after.columns.index(name)]
        theirs = csv[f"{inst}::{var}[REAL]"].to_numpy()
        assert np.abs(theirs - ours).max() <= 1e-6, name  # the CSV prints 6 decimals
