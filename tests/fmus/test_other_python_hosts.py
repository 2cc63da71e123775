"""Issue 37: fmuloader and PathSim (pathsim-fmi) run our FMUs, FMI 2.0 and 3.0, and agree with fmpy.

PDController, its attitude input set to q = (0.9, 0.1, 0.2, 0.3) normalised (the other inputs at their
start values), 10 steps of 10 ms: the torque command equals fmpy's bit for bit. fmuloader binds every
FMI 2.0 function, model exchange included (our library has them, refused), and hands the FMU an
unencoded file URI (our library reads such a path as written). PathSim feeds 0 to an input left open,
so every input gets a constant source. Each host in its own process (docs/external-tools.md)."""
import json
import os
import subprocess
import sys

import pytest

pytestmark = [pytest.mark.fmu, pytest.mark.slow]

_RUN = """
import json, sys
import numpy as np
from fmpy import read_model_description, simulate_fmu

host, fmu = sys.argv[1:]
md = read_model_description(fmu)
fmi = "3" if md.fmiVersion.startswith("3") else "2"
vr = {v.name: v.valueReference for v in md.modelVariables}
q = np.array([0.9, 0.1, 0.2, 0.3]) / np.linalg.norm([0.9, 0.1, 0.2, 0.3])
ins, outs = [f"q[{i}]" for i in range(4)], ["u[1]", "u[2]", "u[3]"]
start = dict(zip(ins, q))
if host == "fmpy":
    r = simulate_fmu(fmu, stop_time=0.1, step_size=0.01, output_interval=0.01, start_values=start, output=outs)
    u = [r[o][-1] for o in outs]
elif host == "fmuloader":
    if fmi == "2":
        from fmuloader.fmi2 import Fmi2Slave, Fmi2Type
        s = Fmi2Slave(fmu, model_identifier=md.coSimulation.modelIdentifier)
        s.instantiate("pd", Fmi2Type.CO_SIMULATION, guid=md.guid)
        s.setup_experiment(start_time=0.0)
        s.enter_initialization_mode()
    else:
        from fmuloader.fmi3 import Fmi3Slave
        s = Fmi3Slave(fmu, model_identifier=md.coSimulation.modelIdentifier)
        s.instantiate_co_simulation("pd", instantiation_token=md.instantiationToken)
        s.enter_initialization_mode(start_time=0.0)
    s.exit_initialization_mode()
    (s.set_real if fmi == "2" else s.set_float64)([vr[n] for n in ins], list(q))
    for k in range(10):
        s.do_step(k * 0.01, 0.01)
    u = (s.get_real if fmi == "2" else s.get_float64)([vr[o] for o in outs])
    s.terminate()
    s.free_instance()
else:
    from pathsim import Connection, Simulation
    from pathsim.blocks import Constant
    from pathsim_fmi import CoSimulationFMU
    block = CoSimulationFMU(fmu, instance_name="pd", start_values=start, dt=0.01)
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    sources = [Constant(float(start.get(v.name, v.start))) for v in inputs]
    sim = Simulation([*sources, block], [Connection(s, block[k]) for k, s in enumerate(sources)], dt=0.01, log=False)
    sim.run(0.1)
    names = [v.name for v in md.modelVariables if v.causality == "output"]
    u = [float(block.outputs.to_array()[names.index(o)]) for o in outs]
print(json.dumps([float(x) for x in u]))
"""


def _run(host, fmu, tmp_path):
    done = subprocess.run([sys.executable, "-c", _RUN, host, str(fmu)], capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, FTCSIM_KERNELS="0", TMPDIR=str(tmp_path)))
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.splitlines()[-1])


@pytest.mark.parametrize("host", ["fmuloader", "pathsim"])
def test_another_python_host_runs_our_fmu_like_fmpy(any_fmu_dir, tmp_path, host):
    fmi, folder = any_fmu_dir
    fmu = folder / "PDController.fmu"
    reference = _run("fmpy", fmu, tmp_path)
    assert max(map(abs, reference)) > 1.0  # a real command, not the zeros of a broken wiring
    assert _run(host, fmu, tmp_path) == reference
