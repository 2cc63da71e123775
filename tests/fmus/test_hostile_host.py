"""Issue 37: a hostile host cannot crash our FMUs' host, FMI 2.0 and 3.0.

tests/fmus/hostile_host.py runs its table of invalid call orders and values (NULL, foreign and freed
instances, double free, calls out of order, unknown value references, NaN / infinite / negative / zero
steps, NaN inputs and times, calls after an error and after a fatal error, reset and FMU state,
resource folders named 'a+b#c%d é' through every URI form, wrong GUIDs) on FMUs in a subprocess: it
must end with status 0 (no crash), within its timeout (no hang), every status the one FMI requires,
every error logged. tests/fmus/c_host.c does the same from a C program whose Python the FMU starts.

``make test`` runs three FMUs per FMI version and the C host (seconds); ``make test-long`` runs every
FMU, and the table under valgrind (0 invalid accesses; about 40 s per FMU under valgrind)."""
import json
import os
import shutil
import subprocess
import sys
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from fmpy import read_model_description

from fmus.export_library import fmi_include
from fmus.host_env import host_environment

pytestmark = [pytest.mark.fmu]

HERE = Path(__file__).resolve().parent
HARNESS = HERE / "hostile_host.py"
FAST = ("PDController", "FlexibleSpacecraft", "Xu2024MarkovFaults")  # a controller, the plant of the NaN crash, the hang
# under valgrind in make test-long: one FMU of every kind (controller, estimator, plant, sensor, source, fault, glue)
VALGRIND = ("PDController", "ASMFEO", "FlexibleSpacecraft", "RateGyro3", "PiecewiseConstantSource",
            "Xu2024MarkovFaults", "ZeroOrderHold4", "Hang2023ASMFTC")


def _env(tmp_path):
    # the kernels (numba) are not what is tested, and slow to load under valgrind
    return dict(os.environ, FTCSIM_KERNELS="0", TMPDIR=str(tmp_path))


def run_harness(fmus, tmp_path, timeout, valgrind_log=None):
    """(completed process, one result dict per FMU) of the harness on ``fmus``, under valgrind if a log
    file is given."""
    cmd = [sys.executable, str(HARNESS), "--work", str(tmp_path), *map(str, fmus)]
    env = _env(tmp_path)
    if valgrind_log:
        cmd = ["valgrind", f"--log-file={valgrind_log}", "--leak-check=no", "--num-callers=16", *cmd]
        env["PYTHONMALLOC"] = "malloc"  # valgrind sees every Python allocation
    done = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
    results = [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]
    return done, results


def _assert_clean(done, results, fmus):
    assert done.returncode == 0, f"the host crashed (status {done.returncode}): {done.stderr[-1500:]}"
    assert [r["fmu"] for r in results] == [Path(f).name for f in fmus]
    failures = {f"{r['fmu']} (FMI {r['fmi']})": r["failures"] for r in results if r["failures"]}
    assert not failures, failures
    assert all(r["checks"] > 300 for r in results), [(r["fmu"], r["checks"]) for r in results]


def test_hostile_host_on_three_fmus(any_fmu_dir, tmp_path):
    fmi, folder = any_fmu_dir
    fmus = [folder / f"{name}.fmu" for name in FAST]
    done, results = run_harness(fmus, tmp_path, timeout=180)
    _assert_clean(done, results, fmus)


def test_hostile_host_on_every_fmu(any_fmu_dir, tmp_path):
    fmi, folder = any_fmu_dir
    fmus = sorted(folder.glob("*.fmu"))
    assert len(fmus) >= 30
    half = len(fmus) // 2
    with ThreadPoolExecutor(2) as pool:
        runs = list(pool.map(lambda part: run_harness(part, tmp_path, timeout=900), (fmus[:half], fmus[half:])))
    for part, (done, results) in zip((fmus[:half], fmus[half:]), runs):
        _assert_clean(done, results, part)


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed (apt install valgrind)")
def test_hostile_host_under_valgrind(any_fmu_dir, tmp_path):
    """The whole table under valgrind: no invalid read, write or free anywhere (ld.so's known
    strncmp over-read during dlopen aside: tests/fmus/valgrind_exit.py)."""
    from valgrind_exit import summarise

    fmi, folder = any_fmu_dir
    groups = [[folder / f"{n}.fmu" for n in VALGRIND[k::2]] for k in range(2)]
    logs = [tmp_path / f"valgrind{k}.log" for k in range(2)]
    with ThreadPoolExecutor(2) as pool:
        runs = list(pool.map(lambda k: run_harness(groups[k], tmp_path, 3600, logs[k]), range(2)))
    for group, log, (done, results) in zip(groups, logs, runs):
        _assert_clean(done, results, group)
        found = summarise(log.read_text(), done.returncode)
        assert found["at_exit"] == found["in_fmu"] == found["other"] == [], found


# -- a C host -------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def c_host(tmp_path_factory):
    cc = shutil.which(os.environ.get("CC") or "cc")
    assert cc, "no C compiler: the FMU build needs one too"
    exe = tmp_path_factory.mktemp("c_host") / "c_host"
    subprocess.run([cc, "-Wall", "-Werror", f"-I{fmi_include('2')}", "-o", str(exe), str(HERE / "c_host.c"), "-ldl",
                    "-lm"], check=True)
    return exe


def _odd_extraction(fmu: Path, tmp_path: Path) -> Path:
    folder = tmp_path / "a+b#c%d é" / fmu.stem
    zipfile.ZipFile(fmu).extractall(folder)
    return folder


def test_a_c_host_whose_python_the_fmu_starts(any_fmu_dir, tmp_path, c_host):
    """The non-Python host path: the library starts the interpreter; NULL instance, wrong token, NaN step,
    refused get, recovery, reset, double free, exit through main's return."""
    fmi, folder = any_fmu_dir
    fmu = folder / "PDController.fmu"
    md = read_model_description(str(fmu))
    root = _odd_extraction(fmu, tmp_path)
    binary = next(root.glob("binaries/*linux*/PDController.so"))
    output = next(v.valueReference for v in md.modelVariables if v.causality == "output")
    location = (root / "resources").as_uri() if fmi == "2" else f"{root / 'resources'}/"
    token = md.guid if fmi == "2" else md.instantiationToken
    done = subprocess.run([str(c_host), fmi, str(binary), token, location, str(output)], capture_output=True,
                          text=True, env={**_env(tmp_path), **host_environment()}, timeout=120)
    assert done.returncode == 0, done.stdout[-1500:] + done.stderr[-1500:]
    assert done.stdout.rstrip().splitlines()[-1].startswith("ok ")
    assert "time must be a finite number" in done.stdout  # the adapter's message reached the C logger
    assert "refused: this instance had an error" in done.stdout


# -- fmpy from a temporary folder with every character a URI escapes ---------------------------------------------
_SIMULATE = """
import json, sys, tempfile
from fmpy import simulate_fmu
print(tempfile.gettempdir())  # where fmpy extracts each FMU
failed = {}
for fmu in sys.argv[1:]:
    try:
        result = simulate_fmu(fmu, stop_time=0.01, step_size=1e-3, output_interval=1e-3)
        assert len(result) == 11 and result["time"][-1] == 0.01, result["time"]
    except Exception as e:
        failed[fmu] = repr(e)[:300]
print(json.dumps(failed))
"""


def test_fmpy_simulates_every_fmu_with_tmpdir_named_like_a_uri_trap(any_fmu_dir, tmp_path):
    """fmpy extracts into TMPDIR and hands the FMU a percent-encoded file URI: pythonfmu's library
    decoded only %20 and crashed on 'a+b#c%d é'; ours decodes every escape (RFC 3986)."""
    fmi, folder = any_fmu_dir
    tmpdir = tmp_path / "a+b#c%d é"
    tmpdir.mkdir()
    fmus = sorted(map(str, folder.glob("*.fmu")))
    done = subprocess.run([sys.executable, "-c", _SIMULATE, *fmus], capture_output=True, text=True, timeout=900,
                          env={**_env(tmp_path), "TMPDIR": str(tmpdir)})
    assert done.returncode == 0, done.stderr[-2000:]
    where, failed = done.stdout.splitlines()[-2:]
    assert where == str(tmpdir)
    assert json.loads(failed) == {}
