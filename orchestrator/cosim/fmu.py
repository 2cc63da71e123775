"""Co-simulation FMUs as components: :class:`FMUComponent` runs an FMU through fmpy's raw
functions (zero-copy get/set into the master's buffers), with thin FMI 2.0 (:class:`FMU2Component`)
and FMI 3.0 (:class:`FMU3Component`) parts, as fmpy does with its ``_FMU`` base;
:func:`fmu_component` picks the part from the modelDescription. Also the life of what an FMU leaves
in the process: one extraction per FMU file, shared libraries never unloaded, FMI 3.0 instances
kept (see :func:`release_fmu`). The interface is :class:`orchestrator.cosim.component.Component`."""
from __future__ import annotations

import ctypes
import os
import sys
import tempfile

import numpy as np

from fmus.export_library import exit_safe
from orchestrator.common.archives import safe_extract
from orchestrator.common.errors import SimulationError
from orchestrator.common.process_exit import avoid_teardown
from orchestrator.common.tempdirs import owned_folder
from orchestrator.cosim.component import ComponentError, Subsets, VarInfo
from orchestrator.cosim.host import prepare_process

_URI_SAFE = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789/-_.~ ")


def extraction_root() -> str:
    """A folder to extract FMUs into whose path survives the trip through a file URI.

    fmpy hands an FMU its resource folder as a percent-encoded ``file://`` URI, and pythonfmu
    decodes only ``%20``: from a path with any other non-ASCII or reserved character (``/tmp/ü``)
    it reads a wrong folder and crashes the process. So FMUs go to the first of TMPDIR (the
    system temporary folder), /tmp, /var/tmp whose absolute path has plain characters only."""
    for cand in (tempfile.gettempdir(), "/tmp", "/var/tmp"):
        path = os.path.abspath(cand)
        if set(path) <= _URI_SAFE and os.path.isdir(path) and os.access(path, os.W_OK | os.X_OK):
            return path
    raise SimulationError(f"no writable temporary folder with a plain path (letters, digits, '/-_.~ ') to extract "
                          f"FMUs into: TMPDIR is {tempfile.gettempdir()!r}; set TMPDIR to such a folder")


_KEPT_LIBRARIES: dict = {}  # library file -> one ctypes handle, never unloaded
_ABANDONED: list = []  # instances that returned fmi2Fatal / fmi3Fatal: FMI allows no further call
_EXTRACTED: list[str] = []  # this process's FMU extraction folders (removed at exit: common/tempdirs.py)
_SHARED_EXTRACTIONS: dict = {}  # (FMU file, size, mtime) -> its extraction folder in this process


def shared_extraction(path, origin) -> str:
    """The folder an FMU file is extracted to, once per process and file version: every
    instance of it loads the same binary. An extraction per instance would map a new copy of the
    shared library per instance, never unloaded (see :func:`release_fmu`): about 1 MB of
    resident memory per instance and run, so a campaign's worker would grow without bound.
    Removed when the process ends."""
    st = os.stat(path)
    key = (os.path.abspath(path), st.st_size, st.st_mtime_ns)
    folder = _SHARED_EXTRACTIONS.get(key)
    if folder is None or not os.path.isdir(folder):
        # ASCII only: str.isalnum() is true for 'é', and a non-ASCII folder name takes the URI path of
        # extraction_root()'s docstring (pythonfmu read a wrong folder: segfault, issue 20)
        stem = "".join(ch if ch.isascii() and ch.isalnum() else "_" for ch in os.path.basename(str(path)))[:40]
        folder = owned_folder(f"{stem}_", extraction_root())  # removed at exit, or after a crash by the next ftcsim
        _EXTRACTED.append(folder)
        safe_extract(path, folder, origin)
        _SHARED_EXTRACTIONS[key] = folder
        if not exit_safe(folder):
            avoid_teardown(f"{os.path.basename(str(path))} carries pythonfmu's stock export library")
    return folder


def release_fmu(fmu, free="fmi2FreeInstance", fatal=False) -> None:
    """Terminate and free an instance, never raising, and WITHOUT unloading the shared
    library: pythonfmu's library defines Python objects (its logger function) that the
    garbage collector may still visit after the instance is gone; unloading it (what
    fmpy's ``freeInstance`` does) makes a later collection crash the process.

    ``fatal``: the instance returned fmi2Fatal / fmi3Fatal, after which FMI allows no call at
    all (pythonfmu has then released the instance's Python object, and freeing it releases it
    again): it is kept, never called. (Until the export library was corrected, FMI 3 instances
    were never freed: ``fmi3FreeInstance`` dropped the last reference that pythonfmu3's exit-time
    double release then wrote into; fmus/native/README.md.)"""
    component = getattr(fmu, "component", None)
    if fatal:
        _ABANDONED.append(fmu)
        return
    for call in (lambda: fmu.terminate(), lambda: getattr(fmu, free)(component)) if component else ():
        try:  # NULL component: instantiation failed
            call()
        except Exception:
            pass
    # one reference per library file is enough (an instance's CDLL holds ~50 kB of function objects)
    _KEPT_LIBRARIES.setdefault(getattr(fmu.dll, "_name", None) or id(fmu.dll), fmu.dll)


def _drop_repeated_sys_path_entries() -> None:
    """pythonfmu puts the FMU's resources folder at the front of sys.path at every instantiation:
    with a shared extraction the same folder again and again (a slower import system, a list
    that grows by one entry per run). Keep the first occurrence of each extraction folder."""
    seen = set()
    keep = []
    for entry in sys.path:
        if isinstance(entry, str) and entry.startswith(tuple(_EXTRACTED)) if _EXTRACTED else False:
            if entry in seen:
                continue
            seen.add(entry)
        keep.append(entry)
    if len(keep) != len(sys.path):
        sys.path[:] = keep


def forget_other_slave_module(unzip: str) -> None:
    """pythonfmu imports an FMU's slave script by its module name (resources/slavemodule.txt), and
    Python gives back a module of that name imported before: from another FMU file with the same
    name (a copy of an FMU with edited files) it would be that FMU's class and code. Such a module
    is dropped, so that this FMU's own script is imported (fmus/embedded.py, issue 20)."""
    resources = os.path.join(os.path.abspath(unzip), "resources")
    try:
        with open(os.path.join(resources, "slavemodule.txt"), encoding="utf-8") as f:
            name = f.readline().strip()
    except OSError:
        return
    module = sys.modules.get(name)
    if module is not None and os.path.dirname(os.path.abspath(getattr(module, "__file__", "") or "")) != resources:
        del sys.modules[name]


# ---------------------------------------------------------------------------------------
class FMUComponent(Subsets):
    """One instance of a co-simulation FMU, called through raw fmpy functions (zero-copy
    get/set into the master's buffers). Subclasses give the version-specific parts."""

    fmi = "2"
    GET = SET = DO_STEP = ""
    REAL_TYPE = "Real"
    _value_array_length = False  # fmi3Get/SetFloat64 take the length of the value array too

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
                float(v.start) if v.start is not None and v.type == self.REAL_TYPE else None,
            )
            for v in model_description.modelVariables
        }
        self.feedthrough = {}
        for u in model_description.outputs:
            deps = u.dependencies
            # No dependencies attribute in the XML means "depends on all inputs" (FMI spec).
            if deps is None:
                deps = [v for v in model_description.modelVariables if v.causality == "input"]
            self.feedthrough[u.variable.name] = {d.name for d in deps if d.causality == "input"}
        self._fmu = None
        self._unzip = None
        self._fatal = False
        self._log: list[str] = []
        self.t = 0.0
        cs = model_description.coSimulation
        self.can_roll_back = bool(getattr(cs, "canGetAndSetFMUstate", False))
        self.variable_step = bool(getattr(cs, "canHandleVariableCommunicationStepSize", False))

    def error(self, function, t, status, log=None) -> ComponentError:
        if status >= 4:  # fmi2Fatal / fmi3Fatal: no further call to this instance (release_fmu)
            self._fatal = True
        return ComponentError(self.name, function, t, status, self.last_log() if log is None else log,
                              self.origin, self.fmi)

    # -- life cycle --------------------------------------------------------------------
    def setup(self, t0, t1, params: dict, inputs: dict):
        prepare_process()  # before the first FMU puts its resources folder on sys.path
        self._unzip = shared_extraction(self.path, self.path)
        forget_other_slave_module(self._unzip)
        self._fmu = self._slave_class()(
            guid=self.md.guid,
            unzipDirectory=self._unzip,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=self.name,
        )
        try:
            self._initialize(t0, t1, {**params, **inputs})
        finally:
            _drop_repeated_sys_path_entries()
        fn = self._fmu._functions
        self._get, self._set, self._do_step = fn[self.GET], fn[self.SET], fn[self.DO_STEP]
        self._c = self._fmu.component
        self.t = t0

    def _set_start_values(self, t0, values: dict, setter):
        """Parameters and input start values before initialisation, through fmpy's ``setter``."""
        if values:
            vrs = [self.variables[n].vr for n in values]
            self._guard(self.SET, t0, lambda: setter(vrs, [float(x) for x in values.values()]))

    def _record_log(self, message: bytes):
        self._log.append(" ".join((message or b"").decode("utf-8", "replace").split()))

    def _guard(self, function, t, call):
        from fmpy.fmi1 import FMICallException

        try:
            return call()
        except FMICallException as e:
            raise self.error(function, t, e.status) from None
        except Exception as e:  # fmpy raises a plain Exception when instantiation fails
            raise self.error(function, t, 3, self.last_log() or str(e)) from None

    def last_log(self) -> str:
        return " | ".join(self._log[-3:])

    def bind(self, out_names, out_buf, in_names, in_buf):
        self._out_names, self._in_names = list(out_names), list(in_names)
        self._out_buf, self._in_buf = out_buf, in_buf
        self._out_vr = np.array([self.variables[n].vr for n in out_names], dtype=np.uint32)
        self._in_vr = np.array([self.variables[n].vr for n in in_names], dtype=np.uint32)

    def prepare(self):
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
            raise self.error(self.GET, self.t, status)
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
            raise self.error(self.SET, self.t, status)

    def read_values(self, names) -> list[float]:
        """The values of the Real variables ``names`` as the FMU reports them now."""
        vrs = [self.variables[n].vr for n in names]
        getter = getattr(self._fmu, self.GET_VALUES)
        return [float(x) for x in self._guard(self.GET, self.t, lambda: getter(vrs))] if vrs else []

    def step(self, t: float, h: float):
        status = self._do_step(self._c, t, h, *self._step_args)
        if status > 1:
            raise self.error(self.DO_STEP, t, status)
        self.t = t + h

    def get_state(self):
        return self._guard(self.GET_STATE_FN, self.t, getattr(self._fmu, self.GET_STATE))

    def set_state(self, state):
        self._guard(self.SET_STATE_FN, self.t, lambda: getattr(self._fmu, self.SET_STATE)(state))

    def free_state(self, state):
        self._guard(self.FREE_STATE_FN, self.t, lambda: getattr(self._fmu, self.FREE_STATE)(state))

    def terminate(self):
        """Terminate and free the instance; never raises."""
        f, self._fmu = self._fmu, None
        if f is not None:
            release_fmu(f, free=f"fmi{self.fmi}FreeInstance", fatal=self._fatal)
        # the extraction folder is shared by every instance of this FMU file in the process
        # (shared_extraction) and removed when the process ends
        self._unzip = None


class FMU2Component(FMUComponent):
    """FMI 2.0: fmi2GetReal / fmi2SetReal / fmi2DoStep, setup experiment then initialisation."""

    fmi = "2"
    GET, SET, DO_STEP = "fmi2GetReal", "fmi2SetReal", "fmi2DoStep"
    GET_STATE, SET_STATE, FREE_STATE = "getFMUstate", "setFMUstate", "freeFMUstate"
    GET_STATE_FN, SET_STATE_FN, FREE_STATE_FN = "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate"
    GET_VALUES = "getReal"
    REAL_TYPE = "Real"
    _step_args = (1,)  # noSetFMUStatePriorToCurrentPoint

    def _slave_class(self):
        from fmpy.fmi2 import FMU2Slave

        return FMU2Slave

    def _initialize(self, t0, t1, values):
        from fmpy.fmi2 import defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

        def logger(env, instance, status, category, message):
            self._record_log(message)

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = defaultCallbacks.allocateMemory
        cb.freeMemory = defaultCallbacks.freeMemory
        self._callbacks = cb  # keep alive
        f = self._fmu
        self._guard("fmi2Instantiate", t0, lambda: f.instantiate(callbacks=cb, loggingOn=True))
        self._guard("fmi2SetupExperiment", t0, lambda: f.setupExperiment(startTime=t0, stopTime=t1))
        self._set_start_values(t0, values, f.setReal)
        self._guard("fmi2EnterInitializationMode", t0, f.enterInitializationMode)
        self._guard("fmi2ExitInitializationMode", t0, f.exitInitializationMode)



class FMU3Component(FMUComponent):
    """FMI 3.0: fmi3GetFloat64 / fmi3SetFloat64 / fmi3DoStep (Float64 variables only, what our
    FMUs have; ``scenario.fmu_interface`` refuses others)."""

    fmi = "3"
    GET, SET, DO_STEP = "fmi3GetFloat64", "fmi3SetFloat64", "fmi3DoStep"
    GET_STATE, SET_STATE, FREE_STATE = "getFMUState", "setFMUState", "freeFMUState"
    GET_STATE_FN, SET_STATE_FN, FREE_STATE_FN = "fmi3GetFMUState", "fmi3SetFMUState", "fmi3FreeFMUState"
    GET_VALUES = "getFloat64"
    REAL_TYPE = "Float64"
    _value_array_length = True

    def _slave_class(self):
        from fmpy.fmi3 import FMU3Slave

        return FMU3Slave

    def _initialize(self, t0, t1, values):
        def logger(env, status, category, message):
            self._record_log(message)

        f = self._fmu
        self._guard("fmi3InstantiateCoSimulation", t0, lambda: f.instantiate(loggingOn=True, logMessage=logger))
        self._set_start_values(t0, values, f.setFloat64)
        self._guard("fmi3EnterInitializationMode", t0, lambda: f.enterInitializationMode(startTime=t0, stopTime=t1))
        self._guard("fmi3ExitInitializationMode", t0, f.exitInitializationMode)
        # doStep's output arguments (event, terminate, early return, last time), allocated once
        self._flags = [ctypes.c_bool(), ctypes.c_bool(), ctypes.c_bool(), ctypes.c_double()]
        self._step_args = (True, *(ctypes.byref(x) for x in self._flags))


def fmu_component(name: str, fmu_path, model_description) -> FMUComponent:
    """The FMI 2.0 or 3.0 component for an FMU, by its modelDescription's fmiVersion."""
    cls = FMU3Component if model_description.fmiVersion.startswith("3.") else FMU2Component
    return cls(name, fmu_path, model_description)
