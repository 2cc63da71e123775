"""The arena's scenario files (arena/scenarios): cross-paper pairs that run end to end, in-process and
as FMUs (identical results), over a short horizon; the realistic-hardware ones keep every wheel's
torque within its bound at the plant over a whole run."""
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import ftcsim
from arena.survey import measure
from plant.hardware.datasheets import WHEELS
from plant.hardware.wheels import torque_bound

ROOT = Path(__file__).resolve().parents[2]
FOLDER = ROOT / "arena" / "scenarios"
FILES = sorted(FOLDER.glob("*.toml"))
SHORT = 0.3  # s: 30 communication steps

# the paper each FMU belongs to: a pair is cross-paper when its method's paper differs from its plant's
PLANT_PAPER = {"FlexibleSpacecraft": "000", "Xu2024FlexiblePlant": "004", "RigidSpacecraftWheels": "001",
               "Zhang2014Plant": "002", "Hang2023Plant": "003"}
METHOD_PAPER = {"FAFEO": "000", "FASMC": "000", "AISMC": "000", "PDController": "000", "ASMFEO": "001",
                "FONTSM": "001", "Zhang2014Hinf": "002", "Hang2023TSFDO": "003", "Hang2023ASMFTC": "003",
                "Xu2024SampledFTC": "004"}


def _papers(path):
    doc = tomllib.loads(path.read_text())
    fmus = [i["fmu"] for i in doc["instances"].values()]
    plant = {PLANT_PAPER[f] for f in fmus if f in PLANT_PAPER}
    method = {METHOD_PAPER[f] for f in fmus if f in METHOD_PAPER}
    return plant, method


def test_at_least_six_cross_paper_pairs_with_the_fault_catalog():
    cross, own = [], []
    for f in FILES:
        plant, method = _papers(f)
        assert len(plant) == 1 and len(method) == 1, f.name  # one plant, one method's paper
        text = f.read_text()
        assert "FaultCatalog" in text, f.name
        (cross if plant != method else own).append(f.stem)
    assert len(cross) >= 6, cross
    # the papers' own pairs with the catalog's faults, one per paper: the arena's references
    assert sorted(_papers(FOLDER / f"{n}.toml")[0].pop() for n in own) == ["000", "001", "002", "003", "004"], own


@pytest.mark.fmu
@pytest.mark.parametrize("path", FILES, ids=[f.stem for f in FILES])
def test_runs_in_process_and_as_fmus_with_identical_results(path, fmu_dir):
    a = ftcsim.run(str(path), stop=SHORT, mode="inprocess")
    b = ftcsim.run(str(path), stop=SHORT, mode="fmu", fmu_dir=fmu_dir)
    assert a.complete and b.complete, (a.error, b.error)
    assert list(a.df.columns) == list(b.df.columns)
    assert np.array_equal(a.df.index.to_numpy(), b.df.index.to_numpy())
    assert np.array_equal(a.df.to_numpy(), b.df.to_numpy())
    cmd = [c for c in a.df.columns if c.startswith(("ctrl.u", "wheels.u_wheel", "wheel.tau"))]
    assert np.abs(a.df[cmd].to_numpy()).max() > 1e-3  # the loop acts
    m = measure(a, path.stem)
    assert m["peak_torque_axis"] > 0 and m["control_energy"] > 0


@pytest.mark.fmu
def test_ftcsim_run_command_on_an_arena_file(tmp_path, fmu_dir):
    """The command line, FMU mode, on a copy with a short horizon: results written, exit 0."""
    text = (FOLDER / "arena_hinf_on_hang2023.toml").read_text().replace("stop = 60.0", "stop = 0.5", 1)
    f = tmp_path / "arena_hinf_short.toml"
    f.write_text(text)
    p = subprocess.run([sys.executable, "-m", "orchestrator.cli", "run", str(f), "--out", str(tmp_path / "out"),
                        "--quiet", "--no-plots", "--fmu-dir", str(fmu_dir)], capture_output=True, text=True, cwd=ROOT,
                       timeout=300)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "out" / "results.parquet").is_file() and (tmp_path / "out" / "metrics.json").is_file()


@pytest.mark.parametrize("name,stop,wheels", [("arena_hinf_on_hang2023_realistic", 60.0, "wheels_hr12_12"),
                                              ("arena_fasmc_on_zhang2019_realistic", 40.0, "wheels_hr12_50")])
def test_realistic_wheels_never_exceed_their_torque_bound_at_the_plant(name, stop, wheels):
    r = ftcsim.run(str(FOLDER / f"{name}.toml"), stop=stop, mode="inprocess")
    assert r.complete, r.error
    p = WHEELS[wheels]
    bound = torque_bound(p["tau_max"], p["coulomb"], p["viscous"], p["h_max"], p["I_w"])
    cols = [c for c in r.df.columns if c.startswith(("wheels.u_wheel", "wheel.tau"))]
    peak = np.abs(r.df[cols].to_numpy()).max()
    assert peak <= bound + 1e-12
    assert peak > 0.9 * p["tau_max"]  # the method asks more than the wheels give: the limit is what acts
    cmd = [c for c in r.df.columns if c.startswith("ctrl.u")]
    assert np.abs(r.df[cmd].to_numpy()).max() > 2.0 * p["tau_max"]
