"""The kinds of component the master drives through one interface (:class:`Component`).

``FMUComponent`` runs a co-simulation FMU through fmpy's raw functions, with thin FMI 2.0
(:class:`FMU2Component`) and FMI 3.0 (:class:`FMU3Component`) parts, as fmpy does with its
``_FMU`` base; :func:`fmu_component` picks the part from the modelDescription.
``BlockComponent`` runs the same block in-process (no FMI), the reference path. Every failure
is one neutral :class:`ComponentError` naming the instance, the call, the time and the status
in the FMI version's own words.

Interface used by the master:
  ``variables``           name -> ``VarInfo`` (value reference, causality, unit)
  ``feedthrough``         output name -> set of input names it depends on directly
  ``setup(t0, t1, params, inputs)``  instantiate, set parameters / input start values, initialise
  ``bind(out_names, out_buf, in_names, in_buf)`` tell the component where its outputs are read
                          into and where its inputs are written from (float64 numpy views)
  ``read()`` / ``write()``  copy all bound outputs into ``out_buf`` / bound inputs from ``in_buf``
  ``read_some(k)`` / ``write_some(k)``  the same for the k-th registered subset (see ``subset``)
  ``step(t, h)``           advance from t to t + h
  ``get_state()`` / ``set_state(s)`` / ``free_state(s)`` (rollback), ``terminate()`` (always safe
                          to call, frees everything)
  ``can_roll_back``, ``variable_step``  what the component declares it can do (FMUs: the
                          modelDescription's canGetAndSetFMUstate and
                          canHandleVariableCommunicationStepSize; in-process blocks: both)
  ``read_values(names)``   current values of Real variables (e.g. parameters after set-up), as
                          the FMU reports them (fmi2GetReal / fmi3GetFloat64) or the block holds them
"""
from __future__ import annotations

import atexit
import ctypes
import os
import re
import shutil
import tempfile
from dataclasses import dataclass
from typing import Protocol

import numpy as np

# Import the block packages from this installation before any FMU is loaded: a pythonfmu
# FMU puts its resources folder first on sys.path, and a package first imported from
# there would point into a temporary folder for the rest of the process.
import controller  # noqa: E402,F401
import estimator  # noqa: E402,F401
import fmus.adapter  # noqa: E402,F401
import papers  # noqa: E402,F401
import plant  # noqa: E402,F401

from .archives import safe_extract
from .errors import SimulationError


@dataclass(frozen=True)
class VarInfo:
    vr: int
    causality: str
    unit: str = ""
    start: float | None = None


_MISSING_MODULE = re.compile(r"No module named '([^']+)'")


STATUS_LABELS = {
    "2": {1: "fmi2Warning", 2: "fmi2Discard", 3: "fmi2Error", 4: "fmi2Fatal"},
    "3": {1: "fmi3Warning", 2: "fmi3Discard", 3: "fmi3Error", 4: "fmi3Fatal"},
}


class ComponentError(SimulationError):
    """A component call failed: names the instance, the call, the time and the status
    (labelled in the words of FMI version ``fmi``)."""

    def __init__(self, instance, function, t, status, log="", origin="", fmi="2"):
        self.instance, self.function, self.t, self.status = instance, function, t, status
        label = STATUS_LABELS.get(str(fmi), STATUS_LABELS["2"]).get(status, str(status))
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


class Component(Protocol):
    """What the master requires of a component (see the module docstring)."""

    name: str
    model_name: str
    variables: dict
    feedthrough: dict

    def setup(self, t0: float, t1: float, params: dict, inputs: dict) -> None: ...
    def bind(self, out_names, out_buf, in_names, in_buf) -> None: ...
    def subset(self, out_positions=None, in_positions=None) -> int: ...
    def read_some(self, k: int) -> None: ...
    def write_some(self, k: int) -> None: ...
    def step(self, t: float, h: float) -> None: ...
    def get_state(self): ...
    def set_state(self, state) -> None: ...
    def free_state(self, state) -> None: ...
    def terminate(self) -> None: ...


class _Subsets:
    """Index subsets of a component's bound outputs/inputs (for ordered propagation)."""

    def __init__(self):
        self.out_subsets: list[np.ndarray] = []
        self.in_subsets: list[np.ndarray] = []

    def subset(self, out_positions=None, in_positions=None) -> int:
        self.out_subsets.append(np.asarray(out_positions if out_positions is not None else [], dtype=np.intp))
        self.in_subsets.append(np.asarray(in_positions if in_positions is not None else [], dtype=np.intp))
        return len(self.out_subsets) - 1


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
_EXTRACTED: list[str] = []
_SHARED_EXTRACTIONS: dict = {}  # (FMU file, size, mtime) -> its extraction folder in this process


@atexit.register
def _remove_extracted():
    for d in _EXTRACTED:
        shutil.rmtree(d, ignore_errors=True)


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
        stem = "".join(ch if ch.isalnum() else "_" for ch in os.path.basename(str(path)))[:40]
        folder = tempfile.mkdtemp(prefix=f"ftcsim_{stem}_", dir=extraction_root())
        _EXTRACTED.append(folder)
        safe_extract(path, folder, origin)
        _SHARED_EXTRACTIONS[key] = folder
        from fmus.export_library import exit_safe

        from .process_exit import avoid_teardown

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
    import sys

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
    import sys

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
class FMUComponent(_Subsets):
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


# ---------------------------------------------------------------------------------------
def _as_slice(positions):
    """Consecutive ascending indices as a slice (same elements), anything else unchanged."""
    p = np.asarray(positions, dtype=np.intp)
    if p.size and np.array_equal(p, np.arange(p[0], p[0] + p.size)):
        return slice(int(p[0]), int(p[0]) + p.size)
    return p


class BlockComponent(_Subsets):
    """The same block run in-process, without FMI: the reference path. It drives the block
    through the same :class:`plant.block.BlockSession` as the FMU adapters."""

    def __init__(self, name: str, block):
        super().__init__()
        self.name = name
        self.block = block
        self.model_name = block.model_name
        self.origin = f"in-process {self.model_name}"
        vr = 0
        self.variables = {}
        for causality, group in (("input", block.inputs), ("output", block.outputs), ("parameter", block.parameters)):
            for v in group:
                self.variables[v.name] = VarInfo(vr, causality, v.unit, v.start)
                vr += 1
        self.feedthrough = {v.name: set(block.feedthrough.get(v.name, ())) for v in block.outputs}
        self.t = 0.0
        self.session = None
        self.can_roll_back = self.variable_step = True

    def _fail(self, function, t, e):
        return ComponentError(self.name, function, t, 3, f"{type(e).__name__}: {e}", self.origin)

    def setup(self, t0, t1, params: dict, inputs: dict):
        from plant.block import BlockSession

        try:
            self.block.set_parameters(params)
            self.block.initialize(t0)
        except Exception as e:
            raise self._fail("initialize", t0, e) from None
        self.session = BlockSession(self.block)
        self.session.t = self.t = t0
        for n, x in inputs.items():
            self.session.set_input(self.block.input_index[n], x)

    def bind(self, out_names, out_buf, in_names, in_buf):
        self._out_pos = np.array([self.block.output_index[n] for n in out_names], dtype=np.intp)
        self._in_pos = np.array([self.block.input_index[n] for n in in_names], dtype=np.intp)
        self._out_buf, self._in_buf = out_buf, in_buf

    def _prepare_subsets(self):
        # consecutive positions become slices (a view copy instead of fancy indexing); the input
        # subsets carry, computed once, whether an output depends on them (BlockSession)
        self._out_calls = [(_as_slice(p), _as_slice(self._out_pos[p]), p.size) for p in self.out_subsets]
        from plant.block import input_affects, input_positions

        affects = input_affects(self.block)
        self._in_calls = [(_as_slice(p), input_positions(self._in_pos[p], affects), p.size) for p in self.in_subsets]

    def read_some(self, k: int):
        pos, src, n = self._out_calls[k]
        if n == 0:
            return
        try:
            y = self.session.outputs()
        except Exception as e:
            raise self._fail("outputs_at", self.t, e) from None
        self._out_buf[pos] = y[src]

    def write_some(self, k: int):
        pos, dst, n = self._in_calls[k]
        if n == 0:
            return
        self.session.set_inputs(dst, self._in_buf[pos])

    def step(self, t: float, h: float):
        try:
            self.session.advance(t, h)
        except Exception as e:
            raise self._fail("advance", t, e) from None
        self.t = t + h

    def read_values(self, names) -> list[float]:
        """The values the block holds for the parameters ``names``."""
        return [self.block.p(n) for n in names]

    def get_state(self):
        return self.session.get_state()

    def set_state(self, state):
        try:
            self.session.set_state(state)
        except Exception as e:
            raise self._fail("set_state", self.t, e) from None
        self.t = self.session.t

    def free_state(self, state):
        pass

    def terminate(self):
        pass
