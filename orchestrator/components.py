"""The two kinds of component the master drives through one interface.

``FMUComponent`` runs an FMI 2.0 co-simulation FMU through fmpy's ``FMU2Slave``;
``BlockComponent`` runs the same block in-process (no FMI), the reference path.

Interface used by the master:
  ``variables``           name -> ``VarInfo`` (value reference, causality, unit)
  ``feedthrough``         output name -> set of input names it depends on directly
  ``setup(t0, t1, params, inputs)``  instantiate, set parameters / input start values, initialise
  ``bind(out_names, out_buf, in_names, in_buf)`` tell the component where its outputs are read
                          into and where its inputs are written from (float64 numpy views)
  ``read()`` / ``write()``  copy all bound outputs into ``out_buf`` / bound inputs from ``in_buf``
  ``read_some(k)`` / ``write_some(k)``  the same for the k-th registered subset (see ``subset``)
  ``step(t, h)``           advance from t to t + h
  ``get_state()`` / ``set_state(s)``, ``terminate()`` (always safe to call, frees everything)
"""
from __future__ import annotations

import atexit
import ctypes
import re
import os
import shutil
import tempfile
from dataclasses import dataclass

import numpy as np

# Import the block packages from this installation before any FMU is loaded: a pythonfmu
# FMU puts its resources folder first on sys.path, and a package first imported from
# there would point into a temporary folder for the rest of the process.
import controller  # noqa: E402,F401
import estimator  # noqa: E402,F401
import fmus.adapter  # noqa: E402,F401
import plant  # noqa: E402,F401

from .errors import SimulationError


@dataclass(frozen=True)
class VarInfo:
    vr: int
    causality: str
    unit: str = ""
    start: float | None = None


_MISSING_MODULE = re.compile(r"No module named '([^']+)'")


class ComponentError(SimulationError):
    """An FMU call failed: names the instance, the call, the time and the status."""

    def __init__(self, instance, function, t, status, log="", origin=""):
        self.instance, self.function, self.t, self.status = instance, function, t, status
        label = {1: "fmi2Warning", 2: "fmi2Discard", 3: "fmi2Error", 4: "fmi2Fatal"}.get(status, str(status))
        where = f" ({origin})" if origin else ""
        msg = f"instance '{instance}'{where}: {function} returned {label} at t = {t:.6g} s"
        missing = _MISSING_MODULE.search(log or "")
        if missing:  # the FMU's Python code needs a package the host's Python lacks
            import sys

            self.missing_module = missing.group(1)
            msg = (f"instance '{instance}'{where}: the FMU's Python code cannot import module "
                   f"'{self.missing_module}': it is not installed in the Python running the FMUs "
                   f"({sys.executable}, Python {sys.version.split()[0]}); the FMU lists what it needs in "
                   f"resources/requirements.txt (pip install -r it, or `pythonfmu deploy -f FILE.fmu`)")
        if log:
            msg += f" -- FMU log: {log}"
        super().__init__(msg)


class _Subsets:
    """Index subsets of a component's bound outputs/inputs (for ordered propagation)."""

    def __init__(self):
        self.out_subsets: list[np.ndarray] = []
        self.in_subsets: list[np.ndarray] = []

    def subset(self, out_positions=None, in_positions=None) -> int:
        self.out_subsets.append(np.asarray(out_positions if out_positions is not None else [], dtype=np.intp))
        self.in_subsets.append(np.asarray(in_positions if in_positions is not None else [], dtype=np.intp))
        return len(self.out_subsets) - 1


_LOADED_LIBRARIES = []
_EXTRACTED: list[str] = []


@atexit.register
def _remove_extracted():
    for d in _EXTRACTED:
        shutil.rmtree(d, ignore_errors=True)


def release_fmu(fmu, free="fmi2FreeInstance") -> None:
    """fmi2Terminate + fmi2FreeInstance, never raising, and WITHOUT unloading the shared
    library: pythonfmu's library defines Python objects (its logger function) that the
    garbage collector may still visit after the instance is gone; unloading it (what
    fmpy's ``freeInstance`` does) makes a later collection crash the process."""
    calls = (lambda: fmu.terminate(), lambda: getattr(fmu, free)(fmu.component))
    for call in calls if getattr(fmu, "component", None) else ():  # NULL: instantiation failed
        try:
            call()
        except Exception:
            pass
    _LOADED_LIBRARIES.append(fmu.dll)


# ---------------------------------------------------------------------------------------
class FMUComponent(_Subsets):
    """One instance of an FMI 2.0 co-simulation FMU, called through raw fmpy functions."""

    error = ComponentError
    GET, SET, DO_STEP = "fmi2GetReal", "fmi2SetReal", "fmi2DoStep"
    # fmi3Get/SetFloat64 take the length of the value array as one more argument
    _value_array_length = False

    def __init__(self, name: str, fmu_path, model_description):
        super().__init__()
        self.name = name
        self.path = str(fmu_path)
        self.md = model_description
        self.model_name = model_description.modelName
        self.origin = os.path.basename(self.path)
        self.variables = {
            v.name: VarInfo(
                v.valueReference,
                v.causality,
                getattr(v, "unit", "") or "",
                float(v.start) if v.start is not None and v.type == "Real" else None,
            )
            for v in model_description.modelVariables
        }
        self.feedthrough = {}
        for u in model_description.outputs:
            deps = u.dependencies
            # No dependencies attribute in the XML means "depends on all inputs" (FMI 2.0 spec).
            if deps is None:
                deps = [v for v in model_description.modelVariables if v.causality == "input"]
            self.feedthrough[u.variable.name] = {d.name for d in deps if d.causality == "input"}
        self._fmu = None
        self._unzip = None
        self._log: list[str] = []
        self.t = 0.0

    # -- life cycle --------------------------------------------------------------------
    def setup(self, t0, t1, params: dict, inputs: dict):
        from fmpy import extract
        from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
        from fmpy.fmi2 import defaultCallbacks

        self._unzip = tempfile.mkdtemp(prefix=f"ftcsim_{self.name}_")
        extract(self.path, self._unzip)
        self._fmu = FMU2Slave(
            guid=self.md.guid,
            unzipDirectory=self._unzip,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=self.name,
        )
        log = self._log

        def logger(env, instance, status, category, message):
            log.append(" ".join(message.decode("utf-8", "replace").split()))

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = defaultCallbacks.allocateMemory
        cb.freeMemory = defaultCallbacks.freeMemory
        self._callbacks = cb  # keep alive
        self._guard("fmi2Instantiate", t0, lambda: self._fmu.instantiate(callbacks=cb, loggingOn=True))
        f = self._fmu
        self._guard("fmi2SetupExperiment", t0, lambda: f.setupExperiment(startTime=t0, stopTime=t1))
        values = {**params, **inputs}
        if values:
            vrs = [self.variables[n].vr for n in values]
            self._guard("fmi2SetReal", t0, lambda: f.setReal(vrs, [float(x) for x in values.values()]))
        self._guard("fmi2EnterInitializationMode", t0, f.enterInitializationMode)
        self._guard("fmi2ExitInitializationMode", t0, f.exitInitializationMode)
        fn = f._functions
        self._get = fn["fmi2GetReal"]
        self._set = fn["fmi2SetReal"]
        self._do_step = fn["fmi2DoStep"]
        self._c = f.component
        self.t = t0

    def _guard(self, function, t, call):
        from fmpy.fmi1 import FMICallException

        try:
            return call()
        except FMICallException as e:
            raise self.error(self.name, function, t, e.status, self.last_log(), self.origin) from None
        except Exception as e:  # fmpy raises a plain Exception when instantiation fails
            raise self.error(self.name, function, t, 3, self.last_log() or str(e), self.origin) from None

    def last_log(self) -> str:
        return " | ".join(self._log[-3:])

    def bind(self, out_names, out_buf, in_names, in_buf):
        self._out_names, self._in_names = list(out_names), list(in_names)
        self._out_buf, self._in_buf = out_buf, in_buf
        self._out_vr = np.array([self.variables[n].vr for n in out_names], dtype=np.uint32)
        self._in_vr = np.array([self.variables[n].vr for n in in_names], dtype=np.uint32)

    def _prepare_subsets(self):
        """ctypes arrays for every subset: value references and pointers into the buffers."""
        dbl = ctypes.POINTER(ctypes.c_double)

        def mk(vr_all, buf, positions):
            pos = np.asarray(positions, dtype=np.intp)
            vrs = np.ascontiguousarray(vr_all[pos], dtype=np.uint32)
            vr_ptr = vrs.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32))
            if pos.size and np.all(np.diff(pos) == 1):
                # contiguous: the FMU reads/writes straight into the bound buffer
                return (vr_ptr, vrs), pos.size, ctypes.cast(buf.ctypes.data + int(pos[0]) * 8, dbl), None
            tmp = np.zeros(pos.size)
            return (vr_ptr, vrs), pos.size, tmp.ctypes.data_as(dbl), (tmp, pos)

        self._out_calls = [mk(self._out_vr, self._out_buf, p) for p in self.out_subsets]
        self._in_calls = [mk(self._in_vr, self._in_buf, p) for p in self.in_subsets]

    def read_some(self, k: int):
        (vr, _keep), n, ptr, scatter = self._out_calls[k]
        if n == 0:
            return
        status = self._get(self._c, vr, n, ptr, n) if self._value_array_length else self._get(self._c, vr, n, ptr)
        if status > 1:
            raise self.error(self.name, self.GET, self.t, status, self.last_log(), self.origin)
        if scatter is not None:
            tmp, pos = scatter
            self._out_buf[pos] = tmp

    def write_some(self, k: int):
        (vr, _keep), n, ptr, scatter = self._in_calls[k]
        if n == 0:
            return
        if scatter is not None:
            tmp, pos = scatter
            tmp[:] = self._in_buf[pos]
        status = self._set(self._c, vr, n, ptr, n) if self._value_array_length else self._set(self._c, vr, n, ptr)
        if status > 1:
            raise self.error(self.name, self.SET, self.t, status, self.last_log(), self.origin)

    def step(self, t: float, h: float):
        status = self._do_step(self._c, t, h, 1)
        if status > 1:
            raise ComponentError(self.name, "fmi2DoStep", t, status, self.last_log(), self.origin)
        self.t = t + h

    def get_state(self):
        return self._fmu.getFMUstate()

    def set_state(self, state):
        self._fmu.setFMUstate(state)

    def terminate(self):
        """Terminate and free the instance; never raises."""
        f, self._fmu = self._fmu, None
        if f is not None:
            release_fmu(f)
        if self._unzip:
            _EXTRACTED.append(self._unzip)  # removed at exit: modules may still refer to it
            self._unzip = None


# ---------------------------------------------------------------------------------------
class BlockComponent(_Subsets):
    """The same block run in-process, without FMI: the reference path."""

    def __init__(self, name: str, block):
        super().__init__()
        self.name = name
        self.block = block
        self.model_name = block.model_name
        vr = 0
        self.variables = {}
        for causality, group in (("input", block.inputs), ("output", block.outputs), ("parameter", block.parameters)):
            for v in group:
                self.variables[v.name] = VarInfo(vr, causality, v.unit, v.start)
                vr += 1
        self.feedthrough = {v.name: set(block.feedthrough.get(v.name, ())) for v in block.outputs}
        self.t = 0.0

    def setup(self, t0, t1, params: dict, inputs: dict):
        self.block.set_parameters(params)
        self._u = self.block.default_inputs()
        for n, x in inputs.items():
            self._u[self.block.input_index[n]] = x
        try:
            self.block.initialize(t0)
        except Exception as e:
            raise ComponentError(self.name, "initialize", t0, 3, f"{type(e).__name__}: {e}", f"in-process {self.model_name}") from None
        self.t = t0
        self._dirty = True

    def bind(self, out_names, out_buf, in_names, in_buf):
        self._out_pos = np.array([self.block.output_index[n] for n in out_names], dtype=np.intp)
        self._in_pos = np.array([self.block.input_index[n] for n in in_names], dtype=np.intp)
        self._out_buf, self._in_buf = out_buf, in_buf

    def _prepare_subsets(self):
        self._out_calls = [(p, self._out_pos[p]) for p in self.out_subsets]
        self._in_calls = [(p, self._in_pos[p]) for p in self.in_subsets]

    def read_some(self, k: int):
        pos, src = self._out_calls[k]
        if pos.size == 0:
            return
        if self._dirty:
            self._y = self.block.outputs_at(self.t, self._u)
            self._dirty = False
        self._out_buf[pos] = self._y[src]

    def write_some(self, k: int):
        pos, dst = self._in_calls[k]
        if pos.size == 0:
            return
        self._u[dst] = self._in_buf[pos]
        self._dirty = True

    def step(self, t: float, h: float):
        try:
            self.block.advance(t, h, self._u)
        except Exception as e:
            raise ComponentError(self.name, "advance", t, 3, f"{type(e).__name__}: {e}", f"in-process {self.model_name}") from None
        self.t = t + h
        self._dirty = True

    def get_state(self):
        return (self.t, self._u.copy(), list(self.block.get_state()))

    def set_state(self, state):
        self.t, u, x = state
        self._u = u.copy()
        self.block.set_state(x)
        self._dirty = True

    def terminate(self):
        pass
