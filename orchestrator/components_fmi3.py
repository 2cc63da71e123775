"""``FMU3Component``: an FMI 3.0 co-simulation FMU behind the interface of ``FMUComponent``.

Same life cycle and the same zero-copy get/set as the FMI 2.0 component
(``orchestrator/components.py``), through fmpy's ``FMU3Slave`` and its raw
``fmi3GetFloat64`` / ``fmi3SetFloat64`` / ``fmi3DoStep``. Only Float64 inputs and outputs
are exchanged (what our FMUs have; ``scenario.fmu_interface`` refuses others). The
master and the scenario code do not need to know which FMI version they drive:
``runner.make_components`` picks this class when the modelDescription says 3.0.
"""
from __future__ import annotations

import ctypes
import tempfile

from .components import _EXTRACTED, ComponentError, FMUComponent, VarInfo, release_fmu

_STATUS3 = {1: "fmi3Warning", 2: "fmi3Discard", 3: "fmi3Error", 4: "fmi3Fatal"}


class Component3Error(ComponentError):
    def __init__(self, instance, function, t, status, log="", origin=""):
        super().__init__(instance, function, t, status, log, origin)
        if status in _STATUS3:  # FMI 3 status names in the message
            label2 = {1: "fmi2Warning", 2: "fmi2Discard", 3: "fmi2Error", 4: "fmi2Fatal"}[status]
            self.args = (self.args[0].replace(f"returned {label2}", f"returned {_STATUS3[status]}", 1),)


class FMU3Component(FMUComponent):
    """One instance of an FMI 3.0 co-simulation FMU."""

    error = Component3Error
    GET, SET, DO_STEP = "fmi3GetFloat64", "fmi3SetFloat64", "fmi3DoStep"
    _value_array_length = True

    def __init__(self, name: str, fmu_path, model_description):
        super().__init__(name, fmu_path, model_description)
        self.variables = {
            v.name: VarInfo(
                v.valueReference,
                v.causality,
                getattr(v, "unit", "") or "",
                float(v.start) if v.start is not None and v.type == "Float64" else None,
            )
            for v in model_description.modelVariables
        }

    def setup(self, t0, t1, params: dict, inputs: dict):
        from fmpy import extract
        from fmpy.fmi3 import FMU3Slave

        self._unzip = tempfile.mkdtemp(prefix=f"ftcsim3_{self.name}_")
        extract(self.path, self._unzip)
        self._fmu = FMU3Slave(
            guid=self.md.guid,
            unzipDirectory=self._unzip,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=self.name,
        )
        log = self._log

        def logger(env, status, category, message):
            log.append(" ".join((message or b"").decode("utf-8", "replace").split()))

        f = self._fmu
        self._guard("fmi3InstantiateCoSimulation", t0, lambda: f.instantiate(loggingOn=True, logMessage=logger))
        values = {**params, **inputs}
        if values:
            vrs = [self.variables[n].vr for n in values]
            self._guard("fmi3SetFloat64", t0, lambda: f.setFloat64(vrs, [float(x) for x in values.values()]))
        self._guard("fmi3EnterInitializationMode", t0, lambda: f.enterInitializationMode(startTime=t0, stopTime=t1))
        self._guard("fmi3ExitInitializationMode", t0, f.exitInitializationMode)
        fn = f._functions
        self._get = fn["fmi3GetFloat64"]
        self._set = fn["fmi3SetFloat64"]
        self._do_step = fn["fmi3DoStep"]
        self._c = f.component
        # doStep's output arguments, allocated once
        self._event = ctypes.c_bool()
        self._terminate = ctypes.c_bool()
        self._early = ctypes.c_bool()
        self._last_t = ctypes.c_double()
        self._step_refs = (ctypes.byref(self._event), ctypes.byref(self._terminate),
                           ctypes.byref(self._early), ctypes.byref(self._last_t))
        self.t = t0

    def step(self, t: float, h: float):
        r = self._step_refs
        status = self._do_step(self._c, t, h, True, r[0], r[1], r[2], r[3])
        if status > 1:
            raise Component3Error(self.name, "fmi3DoStep", t, status, self.last_log(), self.origin)
        self.t = t + h

    def get_state(self):
        return self._fmu.getFMUState()

    def set_state(self, state):
        self._fmu.setFMUState(state)

    def terminate(self):
        """Terminate and free the instance; never raises."""
        f, self._fmu = self._fmu, None
        if f is not None:
            release_fmu(f, free="fmi3FreeInstance")
        if self._unzip:
            _EXTRACTED.append(self._unzip)
            self._unzip = None
