"""Issue 20, item 1: every FMU runs the code it carries, in a process that already imported ours.

Three FASMC FMUs (FMI 2.0) in one process: the shipped one; one rebuilt by `ftcsim build` from an
edited copy of the sources (FASMC's beta x 3 in controller/fasmc.py: the same FMU name, the same
parameters, other code); and a copy of the shipped FMU whose embedded controller raises in its
step (a hand-edited FMU: same slave module name as the shipped one). They used to run the shipped
code, bit for bit, through `ftcsim run`, a campaign and `compare`. Now each gives its own answer:
the rebuilt one equals the in-process FASMC with beta = 3 x 2.0 (an independent computation: the
installed code with the parameter), the raising one fails with its own message, and the campaign's
manifest records a different SHA-256 per FMU file."""
import json
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scenario_text import write

from orchestrator.api import run
from orchestrator.cli.main import main
from papers.p000_li2023.gains import BETA

pytestmark = [pytest.mark.fmu, pytest.mark.slow]

ROOT = Path(__file__).resolve().parents[2]
STOP = 1.0
RAISES = "edited copy: this FASMC's step raises"


@pytest.fixture(scope="module")
def three(tmp_path_factory, fmu_dir):
    """(shipped, rebuilt with beta x 3, raising copy) FASMC.fmu paths."""
    tmp = tmp_path_factory.mktemp("own_code")
    src = tmp / "src"
    for pkg in ("plant", "estimator", "controller", "diagnosis", "fmus", "papers", "arena"):
        shutil.copytree(ROOT / pkg, src / pkg, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    fasmc = src / "controller" / "fasmc.py"
    text = fasmc.read_text()
    assert text.count('self.beta = self.p("beta")') == 1
    fasmc.write_text(text.replace('self.beta = self.p("beta")', 'self.beta = 3.0 * self.p("beta")  # edited: beta x 3'))
    env = {"PYTHONPATH": str(src), "PATH": "/usr/bin:/bin", "HOME": str(tmp), "TMPDIR": str(tmp)}
    p = subprocess.run([sys.executable, "-c", "import sys; from fmus.build import build_fmu; from papers.registry import fmu_specs; "
                        "print(build_fmu(fmu_specs()['FASMC'], sys.argv[1], '2'))", str(tmp / "beta3")],
                       cwd=src, env=env, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-3000:]
    beta3 = Path(p.stdout.strip().splitlines()[-1])
    assert beta3.parent == tmp / "beta3"

    shipped = fmu_dir / "FASMC.fmu"
    raising = tmp / "raising" / "FASMC.fmu"
    raising.parent.mkdir()
    with zipfile.ZipFile(shipped) as zin, zipfile.ZipFile(raising, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "resources/controller/fasmc.py":
                data += (f"\n\ndef _raising_advance(self, t, h, u):\n    raise RuntimeError({RAISES!r})\n\n\n"
                         "FASMC.advance = _raising_advance\n").encode()
            zout.writestr(item, data)
    return shipped, beta3, raising


def _slave(fmu):
    with zipfile.ZipFile(fmu) as z:
        return z.read("resources/slavemodule.txt").decode().strip(), json.loads(z.read("resources/ftcsim_build.json"))


def test_the_three_fmus_carry_different_code(three):
    shipped, beta3, raising = three
    (s0, i0), (s1, i1), (s2, i2) = map(_slave, three)
    assert s1 != s0 and i1["code_sha256"] != i0["code_sha256"]  # rebuilt: named after its code
    assert s2 == s0  # the hand-edited copy keeps the shipped name: the harder case


def _scenario(tmp_path, fmu):
    text = (ROOT / "papers" / "p000_li2023" / "scenarios" / "li2023_fasmc.toml").read_text()
    text, n = re.subn(r'fmu = "FASMC"', f'fmu = "{Path(fmu).as_posix()}"', text)
    assert n == 1
    return write(tmp_path, text, f"{Path(fmu).parent.name}.toml")


def test_run_gives_each_fmu_its_own_answer_in_one_process(three, tmp_path, capsys):
    """`ftcsim run` (the command's main, three times in this process, after the shipped FMU ran
    and with our packages imported here) and the API, against the in-process FASMC with beta = 3."""
    shipped, beta3, raising = three
    out = {}
    for name, fmu in (("shipped", shipped), ("beta3", beta3), ("raising", raising)):
        rc = main(["run", str(_scenario(tmp_path, fmu)), "--out", str(tmp_path / name), "--quiet", "--no-plots"])
        out[name] = rc
        if rc == 0:
            out[name] = pd.read_parquet(tmp_path / name / "results.parquet")
    err = capsys.readouterr().err
    assert out["raising"] == 1 and RAISES in err  # its own code ran, and said so
    a, b = out["shipped"], out["beta3"]
    assert isinstance(a, pd.DataFrame) and isinstance(b, pd.DataFrame)
    u = [c for c in a.columns if c.startswith("ctrl.u[")]
    assert np.abs(a[u].to_numpy() - b[u].to_numpy()).max() > 1e-3  # beta x 3 changes the command
    reference = run("li2023_fasmc", mode="inprocess", stop=STOP, parameters={"ctrl.beta": 3.0 * BETA}).df
    ours = run(_scenario(tmp_path, beta3), stop=STOP).df
    scale = np.maximum(np.abs(reference.to_numpy()).max(axis=0), 1e-12)
    assert (np.abs(ours.to_numpy() - reference.to_numpy()) / scale).max() < 1e-9
    shipped_again = run(_scenario(tmp_path, shipped), stop=STOP).df  # and the shipped one is still itself
    nominal = run("li2023_fasmc", mode="inprocess", stop=STOP).df
    assert (np.abs(shipped_again.to_numpy() - nominal.to_numpy()) / scale).max() < 1e-9


def _campaign(tmp_path, three):
    shipped, beta3, raising = three
    text = f"""
[campaign]
name = "own_code"
scenario = "li2023_fasmc"
runs = 1
seed = 1
stop = {STOP}

[[variants]]
name = "shipped"
fmu = {{ctrl = "{shipped.as_posix()}"}}

[[variants]]
name = "beta3"
fmu = {{ctrl = "{beta3.as_posix()}"}}

[[variants]]
name = "raising"
fmu = {{ctrl = "{raising.as_posix()}"}}
"""
    return write(tmp_path, text, "own_code.toml")


def test_campaign_runs_each_fmu_and_records_its_sha256(three, tmp_path):
    from orchestrator.campaign.expand import file_digest

    rc = main(["campaign", str(_campaign(tmp_path, three)), "--out", str(tmp_path / "c"), "--workers", "0", "--quiet"])
    assert rc in (0, 1)
    summary = pd.read_parquet(tmp_path / "c" / "summary.parquet").set_index("variant")
    assert summary.loc["shipped", "status"] == "ok" and summary.loc["beta3", "status"] == "ok"
    assert summary.loc["raising", "status"] != "ok" and RAISES in summary.loc["raising", "error"]
    assert summary.loc["shipped", "control_energy"] != summary.loc["beta3", "control_energy"]
    manifest = json.loads((tmp_path / "c" / "manifest.json").read_text())
    digests = {Path(f["path"]): f["sha256"] for f in manifest["fmus"]}
    assert len({digests[p] for p in three}) == 3  # three files, three digests ...
    assert all(digests[p] == file_digest(p) for p in three)  # ... of the files that ran


def test_compare_ranks_the_rebuilt_controller_with_its_own_numbers(three, tmp_path):
    shipped, beta3, _ = three
    campaign = write(tmp_path, f"""
[campaign]
name = "base"
scenario = "li2023_fasmc"
runs = 1
seed = 1
stop = {STOP}

[[variants]]
name = "fasmc"
scenario = "li2023_fasmc"
""", "base.toml")
    rc = main(["compare", str(beta3), "--campaign", str(campaign), "--out", str(tmp_path / "cmp"), "--workers", "0",
               "--runs", "1", "--name", "beta3", "--quiet"])
    assert rc == 0
    summary = pd.read_parquet(tmp_path / "cmp" / "summary.parquet").set_index("variant")
    assert set(summary.index) == {"fasmc", "beta3"}
    assert (summary["status"] == "ok").all()
    assert summary.loc["fasmc", "control_energy"] != summary.loc["beta3", "control_energy"]
    alone = run(_scenario(tmp_path, beta3), stop=STOP).metrics["control_energy"]
    assert summary.loc["beta3", "control_energy"] == pytest.approx(alone, rel=1e-12)


def test_a_host_that_imports_the_slave_module_of_a_copy_gets_a_clear_refusal(three, tmp_path):
    """Another host (no ftcsim master in between): the shipped FASMC runs, then its hand-edited copy
    (same slave module name, other files) is instantiated. pythonfmu hands it the shipped class;
    the class refuses, naming both folders: fmi2Instantiate fails with that message."""
    from fmpy import read_model_description
    from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

    from orchestrator.common.archives import safe_extract

    shipped, _, raising = three
    log = []
    slaves = []
    for i, path in enumerate((shipped, raising)):
        md = read_model_description(str(path))
        unzip = safe_extract(path, tmp_path / f"x{i}")
        slaves.append(FMU2Slave(guid=md.guid, unzipDirectory=str(unzip), modelIdentifier="FASMC", instanceName=f"c{i}"))
    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(lambda env, inst, status, cat, msg: log.append(msg.decode()))
    from fmpy.fmi2 import defaultCallbacks

    cb.allocateMemory, cb.freeMemory = defaultCallbacks.allocateMemory, defaultCallbacks.freeMemory
    slaves[0].instantiate(callbacks=cb, loggingOn=True)
    with pytest.raises(Exception, match="Failed to instantiate"):  # fmpy's words for a NULL instance
        slaves[1].instantiate(callbacks=cb, loggingOn=True)
    assert any("differs from that of an FMU with the same slave module name" in m for m in log), log
    slaves[0].fmi2FreeInstance(slaves[0].component)  # never initialised: fmi2Terminate is not allowed (FMI 2.0 4.2.4)


def test_a_new_extraction_after_the_first_was_removed(any_fmu_dir):
    """The same FMU extracted, run, freed and its folder removed, three times in one process (what
    the test driver and campaign workers do): pythonfmu 0.7 executes the cached slave script
    again from the removed folder, and a private namespace must follow the new extraction."""
    from fmu_driver import Driver

    fmi, folder = any_fmu_dir
    first = None
    for i in range(3):
        drv = Driver(folder / "FlexibleSpacecraft.fmu", f"again{i}_{fmi}")
        try:
            drv.initialize({"omega_init[1]": 0.01})
            drv.step(0.0, 0.01)
            q = drv.get(["q[1]", "omega[1]"])
        finally:
            drv.free()  # also removes the extraction folder
        first = first or q
        assert q == first
