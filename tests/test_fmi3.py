"""FMI 3.0 builds (pythonfmu3): valid, same results as FMI 2.0; runtime requirements inside
every FMU; a missing Python module in the host is reported with its name and the FMU."""
import json
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from fmus.catalog import CATALOG
from orchestrator.runner import run_scenario
from orchestrator.scenario import load
from scenario_text import write

ROOT = Path(__file__).resolve().parent.parent
FMI3_DIR = ROOT / "build" / "fmus" / "fmi3"


def _stale(folder: Path) -> bool:
    sources = [p for d in ("plant", "estimator", "controller", "fmus", "papers") for p in (ROOT / d).rglob("*.py")]
    newest = max(p.stat().st_mtime for p in sources)
    return any(not (folder / f"{n}.fmu").is_file() or (folder / f"{n}.fmu").stat().st_mtime < newest for n in CATALOG)


@pytest.fixture(scope="session")
def fmi3_dir(fmu_dir) -> Path:
    """build/fmus/fmi3 with every FMU of the catalog as FMI 3.0, built now if stale."""
    from fmus.build_fmi3 import build_all3

    if _stale(FMI3_DIR):
        build_all3(FMI3_DIR, list(CATALOG))
    return FMI3_DIR


def test_all_fmi3_fmus_validate(fmi3_dir):
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    for name in CATALOG:
        path = fmi3_dir / f"{name}.fmu"
        assert validate_fmu(str(path)) == [], name  # schema, model structure, units, start values
        md = read_model_description(str(path))
        assert md.fmiVersion == "3.0" and md.coSimulation is not None
        with zipfile.ZipFile(path) as z:
            xml = z.read("modelDescription.xml").decode()
        assert 'needsExecutionTool="false"' in xml and 'canGetAndSetFMUState="true"' in xml
        assert [v.name for v in md.modelVariables if v.causality == "independent"] == ["time"]
        assert all(v.type == "Float64" for v in md.modelVariables)
        # exact output dependencies from the block's feedthrough (not "all inputs")
        block = __import__("fmus.catalog", fromlist=["block_class"]).block_class(name)()
        for u in md.outputs:
            assert {d.name for d in u.dependencies} == set(block.feedthrough.get(u.variable.name, ())), (name, u.variable.name)
        with zipfile.ZipFile(path) as z:
            slave = z.read("resources/slavemodule.txt").decode().strip()
        assert slave.startswith("ftcsim3_")  # distinct from the FMI 2 module names


def test_units_declared_in_fmi3(fmi3_dir):
    from fmpy import read_model_description

    md = read_model_description(str(fmi3_dir / "FlexibleSpacecraft.fmu"))
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["u[1]"] == "N.m" and units["omega[1]"] == "rad/s"
    assert "N.m" in {u.name for u in md.unitDefinitions}


@pytest.mark.parametrize("name,stop", [("li2023_pd", 85.0), ("li2023_fasmc", 45.0)])
def test_fmi3_and_fmi2_give_identical_results(name, stop, tmp_path, fmi3_dir, scenarios):
    text = (scenarios / f"{name}.toml").read_text().replace("stop = 200.0", f"stop = {stop}", 1)
    toml = write(tmp_path, text, f"{name}.toml")
    r2 = run_scenario(load(toml), exchange="ordered")
    s3 = load(toml, fmu_dir=fmi3_dir)
    assert all(zipfile.ZipFile(i.fmu).read("modelDescription.xml").find(b'fmiVersion="3.0"') > 0
               for i in s3.instances.values())
    r3 = run_scenario(s3, exchange="ordered")
    assert r2.complete and r3.complete, (r2.error, r3.error)
    assert r3.columns == r2.columns and np.array_equal(r3.time, r2.time)
    assert np.abs(r3.data - r2.data).max() <= 1e-12
    assert np.abs(r2.vector("ctrl.u")).max() > 0.1  # a non-trivial run


@pytest.mark.parametrize("version", ["2", "3"])
def test_fmus_carry_their_runtime_requirements(version, fmu_dir, fmi3_dir):
    folder = fmu_dir if version == "2" else fmi3_dir
    for name in CATALOG:
        with zipfile.ZipFile(folder / f"{name}.fmu") as z:
            req = z.read("resources/requirements.txt").decode().split()
            info = json.loads(z.read("resources/ftcsim_build.json"))
            md = z.read("modelDescription.xml").decode()
        assert any(r.startswith("numpy") for r in req), (name, req)
        assert not any(r.startswith(("pythonfmu", "plant", "fmpy")) for r in req)  # embedded or not needed
        assert info["python"] == ".".join(map(str, sys.version_info[:3]))
        assert info["fmi_version"] == f"{version}.0"
        assert f"Python {info['python']}" in md  # generationTool


def test_missing_module_is_named_with_the_fmu(tmp_path, fmu_dir, scenarios):
    """An FMU whose Python code imports a module the host lacks: the run fails with one
    message naming the module and the FMU (fresh process: the real module is loaded here)."""
    bad = tmp_path / "PDController.fmu"
    with zipfile.ZipFile(fmu_dir / "PDController.fmu") as zin, zipfile.ZipFile(bad, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "resources/ftcsim_controller_pd.py":
                data = b"import ftcsim_missing_dependency_xyz  # noqa\n" + data
            zout.writestr(item, data)
    text = (scenarios / "li2023_pd.toml").read_text()
    text = text.replace('fmu = "PDController"', f'fmu = "{bad.as_posix()}"').replace("stop = 200.0", "stop = 1.0")
    toml = write(tmp_path, text)
    p = subprocess.run([sys.executable, "-m", "orchestrator.cli", "run", str(toml), "--out", str(tmp_path / "out"),
                        "--quiet", "--no-plots"], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert p.returncode == 1, p.stderr
    assert "cannot import module 'ftcsim_missing_dependency_xyz'" in p.stderr
    assert "instance 'ctrl' (PDController.fmu)" in p.stderr
    assert "requirements.txt" in p.stderr
