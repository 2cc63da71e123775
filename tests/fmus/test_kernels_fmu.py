"""Kernels inside FMUs, in a fresh host process that loads the blocks from the FMU's extracted
resources (nothing of this installation imported): with numba the kernels run and their
compiled code is cached in FTCSIM_CACHE_DIR, never in the extracted FMU; with numba made
unimportable the block falls back to its numpy reference code. Either way the FMU's outputs
equal the same block driven in this process on the same path, bit for bit."""
import json
import os
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from plant import kernels
from plant.block import BlockSession

pytestmark = [pytest.mark.fmu, pytest.mark.slow]

T0, H, STEPS = 39.5, 0.01, 100  # across the 000 (66) fault onset at 40 s
PARAMS = {"fault_scale": 1.0, "disturbance_scale": 1.0, "omega_init[1]": 0.05}
U = [0.3, -0.2, 0.1]

HOST = r'''
import json, os, sys
if sys.argv[1] == "hide":  # a host Python without numba
    class NoNumba:
        def find_spec(self, name, path=None, target=None):
            if name == "numba" or name.startswith("numba."):
                raise ImportError("numba is not installed in this host (test)")
    sys.meta_path.insert(0, NoNumba())
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
fmu, params, u, t0, h, steps = sys.argv[2], json.loads(sys.argv[3]), json.loads(sys.argv[4]), *map(float, sys.argv[5:8])
md = read_model_description(fmu)
where = str(extract(fmu))
before = sorted(os.path.join(r, f) for r, _, fs in os.walk(where) for f in fs)
vr = {v.name: v.valueReference for v in md.modelVariables}
outs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
f = FMU2Slave(guid=md.guid, unzipDirectory=where, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="p")
f.instantiate()
f.setupExperiment(startTime=t0)
f.setReal([vr[k] for k in params], list(params.values()))
f.enterInitializationMode()
f.exitInitializationMode()
f.setReal([vr[f"u[{i + 1}]"] for i in range(3)], u)
rows = []
for k in range(int(steps)):
    f.doStep(currentCommunicationPoint=t0 + k * h, communicationStepSize=h)
    rows.append(f.getReal(outs))
f.terminate()
kern = next(m for n, m in sys.modules.items() if n.endswith(".plant.kernels"))  # the FMU's own (fmus/embedded.py)
after = sorted(os.path.join(r, fn) for r, _, fs in os.walk(where) for fn in fs)
print(json.dumps({"rows": rows, "enabled": kern.enabled(), "reason": kern.REASON, "kernels_file": kern.__file__,
                  "where": where, "new_files": sorted(f for f in set(after) - set(before) if not f.endswith(".pyc"))}), flush=True)
'''


def host_run(tmp_path, fmu, hide):
    """The host: this Python without ftcsim importable (-S skips site-packages' .pth files, the
    editable install; numpy, numba and fmpy come from PYTHONPATH), so the FMU runs its own copy
    (with ftcsim importable and the same files, it would use the installed modules: fmus/embedded.py)."""
    import sysconfig

    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.update(FTCSIM_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=sysconfig.get_paths()["purelib"])
    env.pop("FTCSIM_KERNELS", None)
    out = subprocess.run([sys.executable, "-S", "-c", HOST, "hide" if hide else "keep", str(fmu), json.dumps(PARAMS),
                          json.dumps(U), str(T0), str(H), str(STEPS)], capture_output=True, text=True, env=env,
                         cwd=str(tmp_path), timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def in_process(with_kernels):
    from papers.p000_li2023.blocks import flexible_spacecraft

    previous = kernels.set_enabled(with_kernels)
    try:
        b = flexible_spacecraft()
        b.set_parameters(PARAMS)
        b.initialize(T0)
    finally:
        kernels.set_enabled(previous)
    s = BlockSession(b)
    s.t = T0
    for i, x in enumerate(U):
        s.set_input(i, x)
    rows = []
    for k in range(STEPS):
        s.advance(T0 + k * H, H)
        rows.append(s.outputs().copy())
    return np.array(rows)


def test_fmu_requirements_list_numba(fmu_dir):
    with zipfile.ZipFile(fmu_dir / "FlexibleSpacecraft.fmu") as z:
        req = z.read("resources/requirements.txt").decode().split()
    assert any(r.startswith("numba") for r in req) and any(r.startswith("numpy") for r in req), req
    assert not any(r.startswith(("llvmlite", "scipy")) for r in req), req  # numba's own imports are not ours


def test_fmu_without_numba_runs_the_reference(tmp_path, fmu_dir):
    r = host_run(tmp_path, fmu_dir / "FlexibleSpacecraft.fmu", hide=True)
    assert r["kernels_file"].startswith(r["where"])  # the FMU's own copy of the code ran
    assert not r["enabled"] and "numba" in r["reason"]
    assert r["new_files"] == []
    assert np.array_equal(np.array(r["rows"]), in_process(with_kernels=False))


@pytest.mark.skipif(not kernels.enabled(), reason=f"kernels off: {kernels.REASON}")
def test_fmu_with_numba_runs_the_kernels_and_caches_outside(tmp_path, fmu_dir):
    r = host_run(tmp_path, fmu_dir / "FlexibleSpacecraft.fmu", hide=False)
    assert r["kernels_file"].startswith(r["where"]) and r["enabled"]
    assert r["new_files"] == []  # nothing written into the extracted FMU (but Python's own .pyc files)
    cached = [p for p in (tmp_path / "cache").rglob("*.nbi")]
    assert any("plant.kernels.flexible-" in str(p) for p in cached), cached
    assert np.array_equal(np.array(r["rows"]), in_process(with_kernels=True))
    # a second host with the cache now warm: loads, compiles nothing new, same numbers
    n_files = len(list((tmp_path / "cache").rglob("*")))
    r2 = host_run(tmp_path, fmu_dir / "FlexibleSpacecraft.fmu", hide=False)
    assert r2["rows"] == r["rows"] and len(list((tmp_path / "cache").rglob("*"))) == n_files
