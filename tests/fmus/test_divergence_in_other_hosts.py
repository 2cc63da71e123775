"""Issue 37: the diverging package in other hosts ends without a crash, with our message.

``hang2023_asmftc_sign_f04`` diverges under any Jacobi master: the plant's step raises
(``|theta_dot| ... exceeds theta_dot_max``) at t = 0.018 s. With pythonfmu's stock library the
Python instance was released after that fatal error and the next call wrote into freed memory
(libcosim segfaulted at exit, Ecos during the run). With ours:

* libcosim (FMI 2.0 only) stops at the failed step with our message: its error names the plant's
  ``fmi2DoStep`` and the block's reason; the process ends with the runner's status 1;
* Ecos (FMI 2.0 and 3.0, in-process and its command line) ignores the status of a step
  (``fmi_model_instance::step`` drops ``slave::step``'s result) and logs an FMU's messages at debug
  level: it runs on to its stop time while the plant refuses every later call with our message, and
  exits 0. The plant's outputs stay at their last good values (Ecos keeps its buffers).

Minutes (two exports, three engines): make test-long."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fmus.host_env import host_environment

pytestmark = [pytest.mark.fmu, pytest.mark.engines]

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = "hang2023_asmftc_sign_f04"
REASON = "exceeds theta_dot_max"  # Hang2023Plant's message (plant/pitch_axis.py) when the loop diverges


@pytest.fixture(scope="module")
def packages(tmp_path_factory, fmu_dir, fmi3_dir):
    out = tmp_path_factory.mktemp("diverging")
    made = {}
    for fmi, folder in (("2", fmu_dir), ("3", fmi3_dir)):
        made[fmi] = out / f"f04_fmi{fmi}.ssp"
        subprocess.run([str(Path(sys.executable).with_name("ftcsim")), "export-ssp", SCENARIO, "--fmu-dir", str(folder),
                        "--out", str(made[fmi]), "-q"], check=True, cwd=ROOT, timeout=300)
    return made


def _env(tmp_path):
    return dict(os.environ, FTCSIM_KERNELS="0", TMPDIR=str(tmp_path))


def test_libcosim_stops_at_the_failed_step_with_our_message(packages, tmp_path):
    done = subprocess.run([sys.executable, "-m", "orchestrator.interop.engines", "libcosim", str(packages["2"]), "--out",
                           str(tmp_path / "x.npz")], capture_output=True, text=True, env=_env(tmp_path), cwd=ROOT,
                          timeout=600)
    assert done.returncode == 1, (done.returncode, done.stderr[-2000:])  # the runner's error, not a signal
    assert "step failed" in done.stderr and "fmi2DoStep: FloatingPointError: Hang2023Plant" in done.stderr
    assert REASON in done.stderr


_ECOS = """
import sys
import numpy as np
from orchestrator.interop.engines import _preload_tbb
_preload_tbb()
from ecospy import EcosSimulation
from ecospy.lib import EcosLib
EcosLib.set_log_level("debug")  # Ecos logs an FMU's messages at debug level
sim = EcosSimulation(step_size=0.0005, ssp_path=sys.argv[1])
sim.init(0.0)
rows = []
for k in range(100):  # 0.05 s: the plant fails at 0.018 s
    sim.step(1)
    rows.append((sim.get_time(), sim.get_real("plant::theta"), sim.get_real("plant::theta_dot")))
sim.terminate()
np.save(sys.argv[2], np.array(rows))
print("ecos ran to", rows[-1][0])
"""


@pytest.mark.parametrize("fmi", ["2", "3"])
def test_ecos_runs_on_without_a_crash_and_logs_our_message(packages, tmp_path, fmi):
    rows = tmp_path / "rows.npy"
    done = subprocess.run([sys.executable, "-c", _ECOS, str(packages[fmi]), str(rows)], capture_output=True, text=True,
                          env=_env(tmp_path), cwd=ROOT, timeout=600)
    out = done.stdout + done.stderr
    assert done.returncode == 0, (done.returncode, out[-2000:])
    assert f"fmi{fmi}DoStep: FloatingPointError: Hang2023Plant" in out and REASON in out
    assert f"fmi{fmi}DoStep: refused: this instance had an error" in out
    t, theta, rate = np.load(rows).T
    failed = np.flatnonzero(t > 0.018 + 1e-9)[0]
    assert abs(t[-1] - 0.05) < 1e-9  # Ecos went on to its stop time
    assert np.all(theta[failed + 1:] == theta[failed + 1]) and np.all(rate[failed + 1:] == rate[failed + 1])


@pytest.mark.parametrize("level", ["debug", None])
@pytest.mark.parametrize("fmi", ["2", "3"])
def test_the_ecos_command_line_runs_on_and_logs_our_message(packages, tmp_path, fmi, level):
    import importlib.util

    ecos = tmp_path / "ecos"
    shutil.copyfile(Path(importlib.util.find_spec("ecospy").origin).parent / "binaries" / "ecos", ecos)
    ecos.chmod(0o755)
    env = {**_env(tmp_path), **host_environment(), "LD_LIBRARY_PATH": str(Path(sys.prefix) / "lib")}
    done = subprocess.run([str(ecos), "simulate", "--path", str(packages[fmi]), "--stepSize", "0.0005", "--stopTime",
                           "0.05", *(["--logLevel", level] if level else []), "--noCsv"], capture_output=True, text=True, env=env,
                          cwd=tmp_path, timeout=600)
    out = done.stdout + done.stderr
    assert done.returncode == 0, (done.returncode, out[-2000:])
    assert f"fmi{fmi}DoStep: FloatingPointError: Hang2023Plant" in out and REASON in out
    # Ecos is not a Python program: the FMU started Python, so the first error of the instance is also one line
    # on stderr, at any log level (at Ecos's default level the FMU's log messages are not shown)
    echoed = [line for line in done.stderr.splitlines() if line.startswith("[ftcsim FMU ")]
    assert len(echoed) == 1 and "error: " in echoed[0] and REASON in echoed[0], done.stderr[-2000:]
