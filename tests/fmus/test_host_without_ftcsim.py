"""FMUs in a host whose Python does not have ftcsim installed (OMSimulator, a C host): every FMU
embeds only the modules it imports, so several of them in one process must each find their own
modules even when another FMU imported the same package first (OMSimulator failed in
``findClass`` on the attitude source after the plant had imported ``plant``)."""
import os
import subprocess
import sys
import sysconfig

import pytest

pytestmark = pytest.mark.fmu

# plant first: it imports the package ``plant`` without plant/signals.py, which the source needs
ORDER = ["FlexibleSpacecraft", "PiecewiseConstantSource", "FAFEO", "FASMC", "RigidSpacecraftWheels", "FONTSM"]

_HOST = r"""
import importlib.util, sys, tempfile, zipfile
assert importlib.util.find_spec("plant") is None, "ftcsim is importable: the test would prove nothing"
from fmpy import read_model_description
v3 = sys.argv[1] == "3"
if v3:
    from fmpy.fmi3 import FMU3Slave as Slave
else:
    from fmpy.fmi2 import FMU2Slave as Slave
slaves = []
for path in sys.argv[2:]:
    md = read_model_description(path)
    unzip = tempfile.mkdtemp()
    zipfile.ZipFile(path).extractall(unzip)
    fmu = Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName=md.modelName)
    fmu.instantiate()
    if v3:
        fmu.enterInitializationMode(startTime=0.0)
    else:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.doStep(0.0, 0.001)  # FONTSM samples its fractional operators at its default 1 ms
    print("ok", md.modelName, flush=True)
    slaves.append(fmu)
for fmu in slaves:  # a host ends its instances before it exits (the FMUs' Python objects go first)
    fmu.terminate()
    fmu.freeInstance()
print("modules of plant from", len({m.__file__.rsplit("/plant/", 1)[0] for n, m in sys.modules.items()
                                    if n.startswith("plant.")}), "FMUs")
"""


def test_several_fmus_share_packages_in_a_host_without_ftcsim(any_fmu_dir, tmp_path):
    fmi, folder = any_fmu_dir
    site = sysconfig.get_paths()["purelib"]  # numpy and fmpy; -S skips its .pth files (ftcsim's editable install)
    # kernels off: each FMU runs its own copy of plant/kernels here (no ftcsim in this host), whose
    # numba cache is per copy; compiling them cold costs ~16 s and is not what this test is about
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")} | {"PYTHONPATH": site, "FTCSIM_KERNELS": "0"}
    p = subprocess.run([sys.executable, "-S", "-c", _HOST, fmi, *(str(folder / f"{n}.fmu") for n in ORDER)],
                       cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
    assert [line.split()[1] for line in p.stdout.splitlines() if line.startswith("ok ")] == ORDER
    assert "modules of plant from 1 FMUs" not in p.stdout  # the later FMUs' own copies were used
