"""Roll an FMI 2.0 controller FMU back with fmpy and check that it replays bit for bit
(docs/own-controller.md, section 3). Usage: python docs/examples/rollback_check.py MinimalPD.fmu"""
import shutil
import sys

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

path = sys.argv[1]
md = read_model_description(path)
vr = {v.name: v.valueReference for v in md.modelVariables}
u = [vr[f"u[{i}]"] for i in (1, 2, 3)]
folder = extract(path)
fmu = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName="ctrl")
fmu.instantiate()
fmu.setupExperiment(startTime=0.0)
fmu.enterInitializationMode()
fmu.exitInitializationMode()

fmu.setReal([vr["q[1]"], vr["omega[2]"]], [0.1, 0.01])
fmu.doStep(0.0, 0.01)
saved, before = fmu.getFMUstate(), fmu.getReal(u)
fmu.setReal([vr["f_hat[1]"]], [0.3])
fmu.doStep(0.01, 0.01)
print("after a new input and a step:", fmu.getReal(u))
fmu.setFMUstate(saved)
print("restored:", fmu.getReal(u), "identical to the saved point:", fmu.getReal(u) == before)
blob = fmu.serializeFMUstate(saved)
fmu.setFMUstate(fmu.deSerializeFMUstate(blob))
print("through", len(blob), "serialised bytes:", fmu.getReal(u) == before)
fmu.freeFMUstate(saved)
fmu.terminate()
fmu.freeInstance()
shutil.rmtree(folder, ignore_errors=True)
