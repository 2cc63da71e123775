"""Issue 37: Ecos and the fmu-manipulation-toolbox container run our FMI 3.0 packages (libcosim reads
FMI 1.0/2.0 only). li2023_pd exported with the FMI 3.0 FMUs, over its whole 200 s, against our Jacobi
master on the same package (docs/external-tools.md, "Running a package in another engine"): Ecos
records after its exchange (compared with our run sampling "after"), the container like us.
Minutes: make test-long."""
import numpy as np
import pytest

from orchestrator.cosim.runner import run_scenario
from orchestrator.interop.engines import run_engine
from orchestrator.scenario.ssp import export_ssp, load_ssp
from orchestrator.scenario.toml import load

pytestmark = [pytest.mark.engines, pytest.mark.fmu, pytest.mark.slow]


@pytest.fixture(scope="module")
def package(tmp_path_factory, fmi3_dir, scenarios):
    folder = tmp_path_factory.mktemp("li2023_pd_fmi3")
    scenario = load(scenarios / "li2023_pd.toml", fmu_dir=fmi3_dir)
    ssp = export_ssp(scenario, folder / "li2023_pd_fmi3.ssp", fmu_dir=fmi3_dir)
    ours = run_scenario(load_ssp(ssp), exchange="jacobi")
    after = run_scenario(load_ssp(ssp), exchange="jacobi", sample="after")
    assert ours.complete and after.complete and len(ours.time) == 20001
    return ssp, ours, after, folder


def _rel(a, b):
    scale = np.maximum(np.abs(b).max(axis=0), 1e-12)
    return float((np.abs(a - b) / scale).max())


def test_the_package_carries_fmi3_fmus(package):
    import io
    import zipfile

    ssp = package[0]
    with zipfile.ZipFile(ssp) as z:
        fmus = [n for n in z.namelist() if n.endswith(".fmu")]
        assert len(fmus) == 3 and all(b'fmiVersion="3.0"' in zipfile.ZipFile(io.BytesIO(z.read(n))).read(
            "modelDescription.xml") for n in fmus)


def test_ecos_runs_the_fmi3_package_like_our_jacobi_master(package):
    ssp, ours, after, folder = package
    z = run_engine("ecos", ssp, folder / "ecos.npz")
    assert list(z["columns"]) == ours.columns and z["data"].shape == ours.data.shape
    assert _rel(z["data"], after.data) <= 1e-9
    assert np.abs(z["time"] - ours.time).max() <= 1e-9


def test_the_container_runs_the_fmi3_package_like_our_jacobi_master(package):
    ssp, ours, _, folder = package
    z = run_engine("container", ssp, folder / "container.npz")
    assert list(z["columns"]) == ours.columns and z["data"].shape == ours.data.shape
    assert _rel(z["data"], ours.data) <= 1e-9
    assert np.abs(z["time"] - ours.time).max() <= 1e-9
