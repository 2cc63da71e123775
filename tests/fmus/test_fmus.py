"""Built FMUs, FMI 2.0 and 3.0 alike: validation, exact dependencies, units, fixed parameters,
exact rollback (also through serialisation), runtime requirements, identical results."""
import json
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmu_driver import Driver
from scenario_text import write

from fmus.build import module_name
from orchestrator.cosim.runner import run_scenario
from orchestrator.scenario.fmu_checks import check_fmu
from orchestrator.scenario.toml import load
from papers.registry import block_factory
from papers.registry import fmu_specs as catalog

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.fmu
NAMES = sorted(n for n, s in catalog().items() if s.available())  # BasiliskSpacecraft4 needs ftcsim[basilisk]


@pytest.mark.parametrize("name", NAMES)
def test_fmu_is_valid_and_loadable(name, any_fmu_dir):
    fmi, folder = any_fmu_dir
    assert check_fmu(folder / f"{name}.fmu") == []  # load checks + fmpy.validate_fmu


@pytest.mark.parametrize("name", NAMES)
def test_model_description_matches_block(name, any_fmu_dir):
    fmi, folder = any_fmu_dir
    path = folder / f"{name}.fmu"
    md = read_model_description(str(path))
    block = block_factory(name)()
    assert md.fmiVersion == f"{fmi}.0"
    assert md.coSimulation.needsExecutionTool is False
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    assert md.coSimulation.canHandleVariableCommunicationStepSize
    deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
    assert set(deps) == {v.name for v in block.outputs}
    for v in block.outputs:
        assert deps[v.name] == sorted(block.feedthrough.get(v.name, ())), v.name
    assert {u.variable.name for u in md.initialUnknowns} == {v.name for v in block.outputs}
    units = {v.name: v.unit for v in md.modelVariables}
    for v in block.inputs + block.outputs + block.parameters:
        assert (units[v.name] or "1") == v.unit, v.name
    starts = {v.name: float(v.start) for v in md.modelVariables if v.causality == "parameter"}
    assert starts == {v.name: v.start for v in block.parameters}  # the paper's defaults
    with zipfile.ZipFile(path) as z:
        code = json.loads(z.read("resources/ftcsim_build.json"))["code_sha256"]
        assert z.read("resources/slavemodule.txt").decode().strip() == f"{module_name(name, fmi)}_{code[:10]}"
        embedded = {n: z.read(n).decode() for n in z.namelist() if n.startswith("resources/") and n.endswith(".py")}
    # no design code: the LMI layer, the orchestrator and the design modules stay out, and nothing
    # embedded imports cvxpy (stored gains such as designed_gains.py are plain data and may ship); the one
    # exception is the Basilisk plant, which is the Basilisk bridge itself (orchestrator/interop/basilisk:
    # only the bridge may import Basilisk), and carries no more of the orchestrator than its package
    bridge = ("resources/orchestrator/__init__.py", "resources/orchestrator/interop/__init__.py",
              "resources/orchestrator/interop/basilisk/")
    assert not [n for n in embedded if "/lmi/" in n or ("/orchestrator/" in n and not n.startswith(bridge))
                or n.rsplit("/", 1)[-1] in ("design.py", "design_cli.py")]
    if name != "BasiliskSpacecraft4":
        assert not [n for n in embedded if "/orchestrator/" in n]
    assert not [n for n, src in embedded.items() if re.search(r"^\s*(import|from)\s+cvxpy", src, re.M)]
    if fmi == "3":
        assert [v.name for v in md.modelVariables if v.causality == "independent"] == ["time"]


def test_plant_dependencies_are_exact(fmu_dir):
    md = read_model_description(str(fmu_dir / "FlexibleSpacecraft.fmu"))
    deps = {u.variable.name: [d.name for d in u.dependencies] for u in md.outputs}
    assert deps["omega[1]"] == [] and deps["q[0]"] == [] and deps["eta[2]"] == []
    assert sorted(deps["tau_applied[2]"]) == ["u[1]", "u[2]", "u[3]"]


def _steps(drv, t, h, n, inputs):
    rows = []
    outs = drv.outputs()
    for k in range(n):
        drv.set(inputs(t, k))
        drv.step(t, h)
        t += h
        rows.append(drv.get(outs))
    return rows, t


ROLLBACK_CASES = {
    # model: (parameters, inputs(t, k), steps before the save point)
    "FlexibleSpacecraft": ({"omega_init[1]": 0.02, "eta_dot_init[2]": 0.05, "fault_scale": 1.0,
                            "disturbance_scale": 1.0, "h_max": 0.004},
                           lambda t, k: {"u[1]": 0.3 * np.sin(0.01 * k), "u[2]": -0.2}, 4500),  # into the faults
    "FAFEO": ({}, lambda t, k: {"omega[1]": 0.02 * np.cos(0.1 * t), "omega[2]": -0.03, "omega[3]": 0.01,
                                "u[1]": 0.5 * np.sin(t), "u[2]": 1.0, "u[3]": -0.2}, 300),
    "AISMC": ({}, lambda t, k: {"q[0]": 0.9, "q[1]": 0.3, "q[2]": 0.2, "q[3]": np.sqrt(1 - 0.81 - 0.13),
                                "omega[1]": 0.01 * np.sin(t), "q_d[0]": 1.0}, 200),
}


@pytest.mark.parametrize("name", sorted(ROLLBACK_CASES))
def test_rollback_is_exact(name, any_fmu_dir):
    """Save, step 10 times, restore, step again: identical outputs, bit for bit, also through
    serialisation to bytes."""
    fmi, folder = any_fmu_dir
    params, inputs, before = ROLLBACK_CASES[name]
    drv = Driver(folder / f"{name}.fmu", f"rb_{name}_{fmi}")
    try:
        drv.initialize(params)
        _, t = _steps(drv, 0.0, 0.01, before, inputs)
        state = drv.save()
        blob = drv.serialize(state)
        first, _ = _steps(drv, t, 0.01, 10, inputs)
        drv.restore(state)
        second, _ = _steps(drv, t, 0.01, 10, inputs)
        drv.restore(drv.deserialize(blob))
        third, _ = _steps(drv, t, 0.01, 10, inputs)
        assert first == second == third
        assert first[0] != first[-1]
    finally:
        drv.free()


def test_parameters_are_fixed_after_initialisation(any_fmu_dir):
    from fmpy.fmi1 import FMICallException

    fmi, folder = any_fmu_dir
    drv = Driver(folder / "PDController.fmu", f"ctrl_fixed_{fmi}")
    try:
        drv.initialize({"k_p": 3.0})
        assert drv.get(["k_p"]) == [3.0]
        with pytest.raises(FMICallException):
            drv.set({"k_p": 1.0})
    finally:
        drv.free()


def test_cli_validate(fmu_dir, capsys):
    from orchestrator.cli.main import main

    assert main(["validate", "--dir", str(fmu_dir)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) >= len(NAMES) and all(line.endswith(": valid") for line in out)


@pytest.mark.parametrize("name,stop", [("li2023_pd", 85.0), ("li2023_fasmc", 45.0)])
def test_fmi3_and_fmi2_give_identical_results(name, stop, tmp_path, fmu_dir, fmi3_dir, scenarios):
    text = (scenarios / f"{name}.toml").read_text().replace("stop = 200.0", f"stop = {stop}", 1)
    toml = write(tmp_path, text, f"{name}.toml")
    r2 = run_scenario(load(toml), exchange="ordered")
    s3 = load(toml, fmu_dir=fmi3_dir)
    assert all(read_model_description(str(i.fmu)).fmiVersion == "3.0" for i in s3.instances.values())
    r3 = run_scenario(s3, exchange="ordered")
    assert r2.complete and r3.complete, (r2.error, r3.error)
    assert r3.columns == r2.columns and np.array_equal(r3.time, r2.time)
    assert np.array_equal(r3.data, r2.data)
    assert np.abs(r2.vector("ctrl.u")).max() > 0.1  # a non-trivial run


def test_fmus_carry_their_runtime_requirements(any_fmu_dir):
    fmi, folder = any_fmu_dir
    for name in NAMES:
        with zipfile.ZipFile(folder / f"{name}.fmu") as z:
            req = z.read("resources/requirements.txt").decode().split()
            info = json.loads(z.read("resources/ftcsim_build.json"))
            md = z.read("modelDescription.xml").decode()
        assert any(r.startswith("numpy") for r in req), (name, req)
        assert not any(r.startswith(("pythonfmu", "plant", "fmpy", "cvxpy", "scipy")) for r in req), (name, req)
        assert info["python"] == ".".join(map(str, sys.version_info[:3]))
        assert info["fmi_version"] == f"{fmi}.0"
        assert f"Python {info['python']}" in md  # generationTool


def test_missing_module_is_named_with_the_fmu(tmp_path, fmu_dir, scenarios):
    """An FMU whose Python code imports a module the host lacks: the run fails with one
    message naming the module and the FMU (fresh process: the real module is loaded here)."""
    bad = tmp_path / "PDController.fmu"
    with zipfile.ZipFile(fmu_dir / "PDController.fmu") as zin, zipfile.ZipFile(bad, "w") as zout:
        script = f"resources/{zin.read('resources/slavemodule.txt').decode().strip()}.py"
        assert script in zin.namelist()
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == script:
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
