"""A version-neutral handle on one FMU for the tests (fmpy's FMU2Slave or FMU3Slave)."""
import shutil
import tempfile

from fmpy import read_model_description

from orchestrator.common.archives import safe_extract
from orchestrator.cosim.fmu import release_fmu
from orchestrator.cosim.host import prepare_process


class Driver:
    def __init__(self, path, instance: str):
        prepare_process()  # as the master does before it loads an FMU
        self.md = read_model_description(str(path))
        self.v3 = self.md.fmiVersion.startswith("3")
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.unzip = unzip = safe_extract(path, tempfile.mkdtemp(prefix="ftcsim_test_"))
        kw = dict(guid=self.md.guid, unzipDirectory=str(unzip),
                  modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance)
        if self.v3:
            from fmpy.fmi3 import FMU3Slave

            self.fmu = FMU3Slave(**kw)
        else:
            from fmpy.fmi2 import FMU2Slave

            self.fmu = FMU2Slave(**kw)
        self.fmu.instantiate()
        if not self.v3:
            self.fmu.setupExperiment(startTime=0.0)

    def outputs(self):
        return [v.name for v in self.md.modelVariables if v.causality == "output"]

    def set(self, values: dict):
        vrs, xs = [self.vr[k] for k in values], [float(x) for x in values.values()]
        (self.fmu.setFloat64 if self.v3 else self.fmu.setReal)(vrs, xs)

    def get(self, names):
        return list((self.fmu.getFloat64 if self.v3 else self.fmu.getReal)([self.vr[n] for n in names]))

    def initialize(self, params=None):
        if params:
            self.set(params)
        if self.v3:
            self.fmu.enterInitializationMode(startTime=0.0)
        else:
            self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def step(self, t, h):
        self.fmu.doStep(t, h)

    def save(self):
        return self.fmu.getFMUState() if self.v3 else self.fmu.getFMUstate()

    def restore(self, state):
        (self.fmu.setFMUState if self.v3 else self.fmu.setFMUstate)(state)

    def serialize(self, state) -> bytes:
        return bytes(self.fmu.serializeFMUState(state) if self.v3 else self.fmu.serializeFMUstate(state))

    def deserialize(self, blob):
        return self.fmu.deserializeFMUState(blob) if self.v3 else self.fmu.deSerializeFMUstate(blob)

    def free(self):
        release_fmu(self.fmu, free="fmi3FreeInstance" if self.v3 else "fmi2FreeInstance")
        shutil.rmtree(self.unzip, ignore_errors=True)
