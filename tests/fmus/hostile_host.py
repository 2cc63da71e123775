"""A hostile FMI host: every invalid call order and value, on our FMUs, FMI 2.0 and 3.0 (issue 37).

    python tests/fmus/hostile_host.py [--binary LIB] [--cases NAME,...] [--work DIR] FMU...

Loads each FMU's binary with ctypes (a Python host: ctypes releases the GIL around each call, as a
C host's thread would hold none) and runs the table :data:`CASES` on it. Every call is checked
against the status FMI requires; every error or fatal status a live instance returns must come with
a logged message of that status and category ``logStatusError`` / ``logStatusFatal``; every FMI 2
message must be a safe printf format (its ``%`` doubled). Prints one JSON line per FMU:
``{"fmu", "fmi", "checks", "failures"}``, and exits 0 after the last FMU. A crash ends the process
(the caller sees the signal), a hang runs into the caller's timeout: tests/fmus/test_hostile_host.py,
and under valgrind its long test. ``--binary LIB`` replaces each FMU's Linux binary (to measure
pythonfmu's stock library: run it with ``--cases`` one case at a time, it crashes).

The cases (each on fresh instances): NULL, foreign and freed instance handles given to every
function; double free; terminate without initialisation and other calls out of order; unknown
value references, outputs set, NULL arrays; NaN, infinite, negative and zero steps, NaN and
infinite times, time going backwards, an infinite step that must not hang; NaN and infinite inputs
and start times; calls after an error and after a fatal error (a ``MemoryError`` injected into the
slave's ``do_step``); reset and FMU state (get, set, serialize, deserialize, bad handles,
recovery after an error, rollback equal to the first run bit for bit); resource folders named
``a+b#c%d é`` reached through every URI form (every case runs in such a folder unless ``--folder``
names another); wrong GUID / token, NULL name, other FMU types;
functions the FMU does not support."""
# ruff: noqa: B023 (every lambda over a loop variable is called at once, by Host.call, inside its iteration)
from __future__ import annotations

import argparse
import ctypes as C
import json
import math
import re
import shutil
import sys
import tempfile
import time
import zipfile
from pathlib import Path

from fmpy import read_model_description

OK, WARNING, DISCARD, ERROR, FATAL = range(5)
ODD_FOLDER = "a+b#c%d é"  # every character a URI must escape, and a non-ASCII one
H = 1e-3  # the communication step of the cases (s)
NAN, INF = math.nan, math.inf

LOGGER2 = C.CFUNCTYPE(None, C.c_void_p, C.c_char_p, C.c_int, C.c_char_p, C.c_char_p)
LOGGER3 = C.CFUNCTYPE(None, C.c_void_p, C.c_int, C.c_char_p, C.c_char_p)
ALLOC = C.CFUNCTYPE(C.c_void_p, C.c_size_t, C.c_size_t)
FREE = C.CFUNCTYPE(None, C.c_void_p)
GENERIC = C.CFUNCTYPE(C.c_int, *(C.c_void_p,) * 10)  # any function, any pointer-sized arguments
_libc = C.CDLL(None)
_libc.calloc.restype = C.c_void_p
_libc.calloc.argtypes = [C.c_size_t, C.c_size_t]
_libc.free.argtypes = [C.c_void_p]


class CallbackStruct2(C.Structure):
    _fields_ = [("logger", LOGGER2), ("allocateMemory", ALLOC), ("freeMemory", FREE),
                ("stepFinished", C.c_void_p), ("componentEnvironment", C.c_void_p)]


class Failure(Exception):
    """A check that failed: the case stops, the next one runs."""


class Host:
    """One FMU, extracted, its binary loaded: FMI 2.0 or 3.0 calls with raw ctypes arguments."""

    def __init__(self, fmu: Path, work: Path, binary: str | None = None, folder: str = ODD_FOLDER):
        self.md = read_model_description(str(fmu))
        self.fmi = "3" if self.md.fmiVersion.startswith("3") else "2"
        self.model = self.md.coSimulation.modelIdentifier
        self.root = Path(tempfile.mkdtemp(prefix="host_", dir=work)) / folder / self.model
        zipfile.ZipFile(fmu).extractall(self.root)
        so = next(self.root.glob(f"binaries/*linux*/{self.model}.so"))
        if binary:
            shutil.copyfile(binary, so)
        self.lib = C.CDLL(str(so))
        self.token = (self.md.instantiationToken if self.fmi == "3" else self.md.guid).encode()
        self.resources = self.root / "resources"
        self.log: list[tuple[int, str, str]] = []  # (status, category, message) in call order
        self.bad_format: list[str] = []
        if self.fmi == "2":
            self._logger = LOGGER2(self._log2)
            self.callbacks = CallbackStruct2(self._logger, ALLOC(_libc.calloc), FREE(_libc.free), None, None)
        else:
            self._logger = LOGGER3(self._log3)
        variables = self.md.modelVariables
        self.inputs = [v.valueReference for v in variables if v.causality == "input"]
        self.outputs = [v.valueReference for v in variables if v.causality == "output"]
        self.parameters = [v.valueReference for v in variables if v.causality == "parameter"]
        self.all_vrs = [v.valueReference for v in variables]
        self.checks = 0
        self._sig = {}

    # -- logging -------------------------------------------------------------------------------------
    def _log2(self, env, name, status, category, message):
        text = (message or b"").decode("utf-8", "replace")
        if "%" in text.replace("%%", ""):
            self.bad_format.append(text)  # a printf-formatting host would read arguments that are not there
        self.log.append((status, (category or b"").decode(), text.replace("%%", "%")))

    def _log3(self, env, status, category, message):
        self.log.append((status, (category or b"").decode(), (message or b"").decode("utf-8", "replace")))

    # -- raw functions -------------------------------------------------------------------------------
    def fn(self, name: str, restype, *argtypes):
        key = (name, restype, argtypes)
        f = self._sig.get(key)
        if f is None:
            f = C.CFUNCTYPE(restype, *argtypes)(C.cast(getattr(self.lib, name), C.c_void_p).value)
            self._sig[key] = f
        return f

    def names(self) -> list[str]:
        """Every fmi2* / fmi3* function that takes an instance first."""
        import subprocess

        so = next(self.root.glob(f"binaries/*linux*/{self.model}.so"))
        out = subprocess.run(["nm", "-D", "--defined-only", str(so)], capture_output=True, text=True).stdout
        skip = {"GetTypesPlatform", "GetVersion", "Instantiate", "InstantiateCoSimulation", "InstantiateModelExchange",
                "InstantiateScheduledExecution"}
        names = sorted(p[2] for p in (line.split() for line in out.splitlines()) if len(p) == 3 and p[1] == "T")
        return [n for n in names if n.startswith(f"fmi{self.fmi}") and n[4:] not in skip]

    def generic(self, name: str, handle, *args) -> int:
        """``name(handle, args...)`` with pointer-sized arguments (a handle that is not an instance is
        refused before any other argument is read)."""
        f = self.fn(name, C.c_int, *(C.c_void_p,) * 10)
        padded = [handle, *args] + [None] * (10 - 1 - len(args))
        return f(*padded)

    # -- life cycle -------------------------------------------------------------------------------------
    def uri(self, form: str = "encoded") -> bytes:
        path = str(self.resources)
        if self.fmi == "3" and form == "encoded":
            return (path + "/").encode()
        encoded = self.resources.as_uri()[len("file://"):]
        return {"encoded": "file://" + encoded, "file:/": "file:" + encoded,
                "localhost": "file://localhost" + encoded,
                "lowercase": "file://" + re.sub("%[0-9A-F]{2}", lambda m: m.group(0).lower(), encoded),
                "raw": "file://" + path, "raw-trailing": "file://" + path + "/", "plain": path,
                "encoded-trailing": "file://" + encoded + "/"}[form].encode()

    def instantiate(self, location: bytes | None | int = -1, token: bytes | None | int = -1,
                    name: bytes | None = b"host", logging_on=False, fmu_type=1, callbacks=True):
        """A new instance (its handle, an int) or None (-1: this FMU's resources, GUID / token)."""
        location = self.uri() if location == -1 else location
        token = self.token if token == -1 else token
        if self.fmi == "2":
            f = self.fn("fmi2Instantiate", C.c_void_p, C.c_char_p, C.c_int, C.c_char_p, C.c_char_p,
                        C.POINTER(CallbackStruct2), C.c_int, C.c_int)
            return f(name, fmu_type, token, location, C.byref(self.callbacks) if callbacks else None, 0, int(logging_on))
        f = self.fn("fmi3InstantiateCoSimulation", C.c_void_p, C.c_char_p, C.c_char_p, C.c_char_p, C.c_bool, C.c_bool,
                    C.c_bool, C.c_bool, C.c_void_p, C.c_size_t, C.c_void_p, LOGGER3, C.c_void_p)
        return f(name, token, location, False, bool(logging_on), False, False, None, 0, None,
                 self._logger if callbacks else LOGGER3(), None)

    def free(self, c) -> None:
        self.fn(f"fmi{self.fmi}FreeInstance", None, C.c_void_p)(c)

    def setup(self, c, t0: float = 0.0) -> list[int]:
        """Statuses of: set up the experiment (FMI 2) and enter initialisation mode at ``t0``."""
        if self.fmi == "2":
            s1 = self.fn("fmi2SetupExperiment", C.c_int, C.c_void_p, C.c_int, C.c_double, C.c_double, C.c_int,
                         C.c_double)(c, 0, 0.0, t0, 0, 0.0)
            return [s1, self.fn("fmi2EnterInitializationMode", C.c_int, C.c_void_p)(c)]
        return [self.fn("fmi3EnterInitializationMode", C.c_int, C.c_void_p, C.c_bool, C.c_double, C.c_double,
                        C.c_bool, C.c_double)(c, False, 0.0, t0, False, 0.0)]

    def exit_init(self, c) -> int:
        return self.fn(f"fmi{self.fmi}ExitInitializationMode", C.c_int, C.c_void_p)(c)

    def step(self, c, t: float, h: float) -> int:
        if self.fmi == "2":
            return self.fn("fmi2DoStep", C.c_int, C.c_void_p, C.c_double, C.c_double, C.c_int)(c, t, h, 1)
        flags = [C.c_bool() for _ in range(3)]
        last = C.c_double()
        return self.fn("fmi3DoStep", C.c_int, C.c_void_p, C.c_double, C.c_double, C.c_bool, C.POINTER(C.c_bool),
                       C.POINTER(C.c_bool), C.POINTER(C.c_bool), C.POINTER(C.c_double))(
            c, t, h, True, *map(C.byref, flags), C.byref(last))

    def terminate(self, c) -> int:
        return self.fn(f"fmi{self.fmi}Terminate", C.c_int, C.c_void_p)(c)

    def reset(self, c) -> int:
        return self.fn(f"fmi{self.fmi}Reset", C.c_int, C.c_void_p)(c)

    def get(self, c, vrs, n=None, null_vr=False, null_values=False):
        """(status, values) of reading the Real / Float64 variables ``vrs``."""
        n = len(vrs) if n is None else n
        vr = None if null_vr else (C.c_uint32 * max(1, len(vrs)))(*vrs)
        out = None if null_values else (C.c_double * max(1, n))()
        if self.fmi == "2":
            s = self.fn("fmi2GetReal", C.c_int, C.c_void_p, C.c_void_p, C.c_size_t, C.c_void_p)(c, vr, n, out)
        else:
            s = self.fn("fmi3GetFloat64", C.c_int, C.c_void_p, C.c_void_p, C.c_size_t, C.c_void_p, C.c_size_t)(
                c, vr, n, out, n)
        return s, (list(out)[:n] if out is not None else None)

    def set(self, c, vrs, values, null_vr=False, null_values=False) -> int:
        n = len(vrs)
        vr = None if null_vr else (C.c_uint32 * max(1, n))(*vrs)
        vals = None if null_values else (C.c_double * max(1, n))(*values)
        if self.fmi == "2":
            return self.fn("fmi2SetReal", C.c_int, C.c_void_p, C.c_void_p, C.c_size_t, C.c_void_p)(c, vr, n, vals)
        return self.fn("fmi3SetFloat64", C.c_int, C.c_void_p, C.c_void_p, C.c_size_t, C.c_void_p, C.c_size_t)(
            c, vr, n, vals, n)

    def _state_name(self, what: str) -> str:
        return f"fmi{self.fmi}{what}FMU{'state' if self.fmi == '2' else 'State'}"

    def get_state(self, c, state: C.c_void_p | None = None):
        state = C.c_void_p() if state is None else state
        s = self.fn(self._state_name("Get"), C.c_int, C.c_void_p, C.POINTER(C.c_void_p))(c, C.byref(state))
        return s, state

    def set_state(self, c, state) -> int:
        return self.fn(self._state_name("Set"), C.c_int, C.c_void_p, C.c_void_p)(c, state)

    def free_state(self, c, state: C.c_void_p) -> int:
        return self.fn(self._state_name("Free"), C.c_int, C.c_void_p, C.POINTER(C.c_void_p))(c, C.byref(state))

    def serialize(self, c, state) -> tuple[int, bytes | None]:
        size = C.c_size_t()
        name = "fmi2SerializedFMUstateSize" if self.fmi == "2" else "fmi3SerializedFMUStateSize"
        s = self.fn(name, C.c_int, C.c_void_p, C.c_void_p, C.POINTER(C.c_size_t))(c, state, C.byref(size))
        if s != OK:
            return s, None
        buf = (C.c_ubyte * size.value)()
        name = "fmi2SerializeFMUstate" if self.fmi == "2" else "fmi3SerializeFMUState"
        s = self.fn(name, C.c_int, C.c_void_p, C.c_void_p, C.c_void_p, C.c_size_t)(c, state, buf, size.value)
        return s, bytes(buf)

    def deserialize(self, c, data: bytes):
        state = C.c_void_p(0x1234)  # an uninitialised variable of the host: never read
        buf = (C.c_ubyte * max(1, len(data)))(*data)
        name = "fmi2DeSerializeFMUstate" if self.fmi == "2" else "fmi3DeserializeFMUState"
        s = self.fn(name, C.c_int, C.c_void_p, C.c_void_p, C.c_size_t, C.POINTER(C.c_void_p))(
            c, buf, len(data), C.byref(state))
        return s, state

    def ready(self, t0: float = 0.0):
        """A new instance in step mode (checked)."""
        c = self.new()
        self.expect(self.setup(c, t0), [OK] * (2 if self.fmi == "2" else 1), "set up and enter initialisation")
        self.expect(self.exit_init(c), OK, "exit initialisation")
        return c

    def new(self, **kw):
        c = self.instantiate(**kw)
        if not c:
            raise Failure(f"instantiation failed: {self.log[-3:]}")
        return c

    # -- checks ---------------------------------------------------------------------------------------
    def expect(self, got, want, what: str) -> None:
        self.checks += 1
        if got != want:
            raise Failure(f"{what}: status {got}, FMI requires {want}; log: {self.log[-2:]}")

    def expect_logged(self, since: int, status: int, what: str, *words: str) -> None:
        """A message of ``status`` (category logStatusError / logStatusFatal) was logged since log entry
        ``since``, holding every one of ``words``."""
        self.checks += 1
        category = {ERROR: "logStatusError", FATAL: "logStatusFatal"}[status]
        new = [m for s, cat, m in self.log[since:] if s == status and cat == category]
        if not new or not all(any(w in m for m in new) for w in words):
            raise Failure(f"{what}: no {category} message with {words} logged; log: {self.log[since:][-3:]}")

    def call(self, status_want: int, what: str, thunk, *words: str):
        """Run ``thunk`` (a call on a live instance), check its status and, for an error, its message."""
        mark = len(self.log)
        got = thunk()
        status = got[0] if isinstance(got, tuple) else got
        self.expect(status, status_want, what)
        if status_want >= ERROR:
            self.expect_logged(mark, status_want, what, *words)
        return got


# -- the cases ------------------------------------------------------------------------------------------
def case_null_and_foreign_handles(h: Host):
    """Every function with a NULL handle and with a pointer that is no instance: fmiXError, nothing read."""
    foreign = (C.c_ubyte * 4096)()  # zeros: a struct of ours would start with a magic number
    for name in h.names():
        for handle in (None, C.addressof(foreign)):
            got = h.generic(name, handle)
            if not name.endswith("FreeInstance"):
                h.expect(got, ERROR, f"{name}({'NULL' if handle is None else 'foreign pointer'})")
    h.fn(f"fmi{h.fmi}FreeInstance", None, C.c_void_p)(None)
    h.expect(bytes(foreign), bytes(4096), "the foreign memory is untouched")


def case_double_free(h: Host):
    c = h.ready()
    h.free(c)
    h.free(c)  # double free: refused, nothing touched
    for name in h.names():
        if not name.endswith("FreeInstance"):
            h.expect(h.generic(name, c), ERROR, f"{name} on a freed instance")
    c2 = h.ready()  # the library still serves new instances
    h.expect(h.step(c2, 0.0, H), OK, "a step of a new instance after the double free")
    h.free(c2)


def case_order(h: Host):
    """Calls out of order: an error status, a message; after it only the recovery calls."""
    c = h.new()
    h.call(ERROR, "terminate without initialisation", lambda: h.terminate(c), "Terminate", "not allowed")
    h.call(ERROR, "a step after that error", lambda: h.step(c, 0.0, H), "refused", "not allowed")
    h.call(OK, "reset after the error", lambda: h.reset(c))
    h.expect(h.setup(c), [OK] * (2 if h.fmi == "2" else 1), "initialisation after the reset")
    h.expect(h.exit_init(c), OK, "exit initialisation after the reset")
    h.expect(h.step(c, 0.0, H), OK, "a step after the reset")
    h.free(c)
    c = h.new()
    h.call(ERROR, "a step before initialisation", lambda: h.step(c, 0.0, H), "DoStep")
    h.free(c)
    c = h.new()
    h.call(ERROR, "exit initialisation before entering it", lambda: h.exit_init(c), "ExitInitializationMode")
    h.free(c)
    c = h.ready()
    h.call(ERROR, "initialisation again in step mode", lambda: h.setup(c)[-1] if h.fmi == "3" else h.setup(c)[0],
           "not allowed")
    h.free(c)
    c = h.ready()
    h.expect(h.terminate(c), OK, "terminate")
    h.call(ERROR, "a step after terminate", lambda: h.step(c, 0.0, H), "DoStep")
    h.free(c)


def case_value_references(h: Host):
    unknown = max(h.all_vrs) + 1000
    for what, thunk_of in (("get an unknown value reference", lambda c: h.get(c, [unknown])),
                           ("set an unknown value reference", lambda c: h.set(c, [unknown], [1.0])),
                           ("set an output", lambda c: h.set(c, [h.outputs[0]], [1.0])),
                           ("get with a NULL value-reference array", lambda c: h.get(c, [0, 1], null_vr=True)),
                           ("get into a NULL value array", lambda c: h.get(c, [h.outputs[0]], null_values=True)),
                           ("set from a NULL value array", lambda c: h.set(c, [h.outputs[0]], [0.0], null_values=True))):
        c = h.ready()
        h.call(ERROR, what, lambda: thunk_of(c))
        h.call(ERROR, f"a get after '{what}'", lambda: h.get(c, h.outputs[:1]), "refused")
        h.free(c)
    c = h.ready()
    h.expect(h.get(c, [], null_vr=True, null_values=True)[0], OK, "get nothing through NULL arrays")
    h.expect(h.get(c, h.outputs)[0], OK, "get every output")
    h.free(c)


def case_steps(h: Host):
    for t, step in ((0.0, NAN), (0.0, INF), (0.0, -INF), (0.0, -H), (0.0, 0.0), (NAN, H), (INF, H), (-INF, H)):
        c = h.ready()
        h.call(ERROR, f"a step from t = {t} by h = {step}", lambda: h.step(c, t, step), "step")
        h.call(ERROR, "a step after it", lambda: h.step(c, 0.0, H), "refused")
        h.free(c)
    c = h.ready()
    h.expect(h.step(c, 0.0, H), OK, "a step")
    h.call(ERROR, "the same step again (time going backwards)", lambda: h.step(c, 0.0, H), "backwards")
    h.free(c)
    c = h.ready(t0=5.0)
    h.call(ERROR, "a step before the start time", lambda: h.step(c, 0.0, H), "backwards")
    h.free(c)


def case_inputs(h: Host):
    targets = [("input", vr) for vr in h.inputs[:1]] + [("parameter", vr) for vr in h.parameters[:1]]
    for kind, vr in targets:
        for x in (NAN, INF, -INF):
            c = h.new() if kind == "parameter" else h.ready()
            h.call(ERROR, f"{kind} {vr} = {x}", lambda: h.set(c, [vr], [x]), "not a finite number")
            h.call(ERROR, "a step after it", lambda: h.step(c, 0.0, H), "refused")
            h.free(c)
    c = h.new()
    got = h.setup(c, NAN)
    h.expect(got[0], ERROR, "start time NaN")
    h.free(c)


def case_after_error(h: Host):
    c = h.ready()
    mark = len(h.log)
    h.expect(h.step(c, 0.0, NAN), ERROR, "a NaN step")
    first = [m for s, _, m in h.log[mark:] if s == ERROR][0]
    cause = first.split(": ", 1)[1][:40]  # the refusals quote the error
    h.call(ERROR, "get after an error", lambda: h.get(c, h.outputs[:1]), "refused", cause)
    h.call(ERROR, "set after an error", lambda: h.set(c, h.inputs[:1] or h.parameters[:1], [0.0]), "refused")
    h.call(ERROR, "step after an error", lambda: h.step(c, 0.0, H), "refused")
    h.call(ERROR, "terminate after an error", lambda: h.terminate(c), "refused")
    h.call(ERROR, "get the FMU state after an error", lambda: h.get_state(c), "refused")
    h.free(c)


def _slave_class(h: Host):
    """The FMU's slave class in this process (its module is imported by the first instantiation)."""
    name = (h.resources / "slavemodule.txt").read_text().split()[0]
    if name not in sys.modules:
        h.free(h.new())
    return getattr(sys.modules[name], h.model)


def case_after_fatal(h: Host):
    """A MemoryError in the slave (injected into its class in this process) is fatal: every later call
    is refused with fmiXFatal, none touches the instance; freeing it works."""
    c = h.ready()
    cls = _slave_class(h)

    def out_of_memory(self, *args):
        raise MemoryError("injected by tests/fmus/hostile_host.py")

    cls.do_step = out_of_memory
    try:
        h.call(FATAL, "a step that runs out of memory", lambda: h.step(c, 0.0, H), "MemoryError")
    finally:
        del cls.do_step
    for k, name in enumerate(n for n in h.names() if not n.endswith("FreeInstance")):
        mark = len(h.log)
        h.expect(h.generic(name, c), FATAL, f"{name} after a fatal error")
        # the first refusals quote the error, the later ones refer to it (a host that calls on and on)
        h.expect_logged(mark, FATAL, f"{name} after a fatal error", "refused", *(["MemoryError"] if k < 16 else []))
    h.free(c)


def case_fmu_state(h: Host):
    c = h.ready()
    for k in range(2):
        h.expect(h.step(c, k * H, H), OK, "a step")
    s1 = h.get_state(c)
    h.expect(s1[0], OK, "get the FMU state")
    s1 = s1[1]
    for k in range(2, 5):
        h.expect(h.step(c, k * H, H), OK, "a step")
    first = h.get(c, h.outputs)[1]
    h.expect(h.set_state(c, s1), OK, "set the FMU state (rollback)")
    for k in range(2, 5):
        h.expect(h.step(c, k * H, H), OK, "a step after the rollback")
    h.expect(h.get(c, h.outputs)[1], first, "outputs after the rollback equal those of the first run")
    status, data = h.serialize(c, s1)
    h.expect(status, OK, "serialize the FMU state")
    status, s2 = h.deserialize(c, data)
    h.expect(status, OK, "deserialize it")
    h.expect(h.set_state(c, s2), OK, "set the deserialized state")
    for k in range(2, 5):
        h.expect(h.step(c, k * H, H), OK, "a step from the deserialized state")
    h.expect(h.get(c, h.outputs)[1], first, "outputs from the deserialized state equal those of the first run")
    # recovery: an error, then the saved state
    h.expect(h.step(c, 5 * H, NAN), ERROR, "a NaN step")
    h.call(OK, "set the FMU state after an error (recovery)", lambda: h.set_state(c, s1))
    h.expect(h.step(c, 2 * H, H), OK, "a step after the recovery")
    h.expect(h.free_state(c, s2), OK, "free the deserialized state")
    h.expect(s2.value, None, "the freed state pointer is cleared")
    h.expect(h.free_state(c, C.c_void_p()), OK, "free a NULL state (ignored)")
    s1_copy = C.c_void_p(s1.value)
    h.expect(h.free_state(c, s1), OK, "free the state")
    h.call(ERROR, "free the same state again", lambda: h.free_state(c, s1_copy), "not an FMU state")
    h.free(c)
    foreign = (C.c_ubyte * 256)()
    for what, thunk_of in (("set a NULL state", lambda c: h.set_state(c, None)),
                           ("set a pointer that is no state", lambda c: h.set_state(c, C.addressof(foreign))),
                           ("deserialize bytes that are no state", lambda c: h.deserialize(c, b"not a state" * 4)),
                           ("deserialize nothing", lambda c: h.deserialize(c, b""))):
        c = h.ready()
        h.call(ERROR, what, lambda: thunk_of(c))
        h.free(c)
    a, b = h.ready(), h.ready()
    status, sa = h.get_state(a)
    h.call(ERROR, "set one instance's state on another", lambda: h.set_state(b, sa), "not an FMU state")
    h.free(a)  # frees its states
    h.free(b)


def case_reset(h: Host):
    c = h.ready()
    for k in range(3):
        h.expect(h.step(c, k * H, H), OK, "a step")
    first = h.get(c, h.outputs)[1]
    h.expect(h.reset(c), OK, "reset")
    h.expect(h.setup(c), [OK] * (2 if h.fmi == "2" else 1), "initialisation after the reset")
    h.expect(h.exit_init(c), OK, "exit initialisation after the reset")
    for k in range(3):
        h.expect(h.step(c, k * H, H), OK, "a step after the reset")
    h.expect(h.get(c, h.outputs)[1], first, "outputs after the reset equal those of the first run")
    h.free(c)


def case_resource_locations(h: Host):
    """The FMU sits in a folder named 'a+b#c%d é': every URI form reaches it."""
    forms = ["encoded", "file:/", "localhost", "lowercase", "raw", "raw-trailing", "encoded-trailing", "plain"]
    for form in forms if h.fmi == "2" else ["encoded", "plain", "raw", "file:/"]:
        c = h.instantiate(location=h.uri(form))
        h.checks += 1
        if not c:
            raise Failure(f"resource location {h.uri(form)!r} ({form}): no instance; log: {h.log[-2:]}")
        h.expect(h.setup(c)[-1], OK, f"initialisation through {form}")
        h.expect(h.exit_init(c), OK, f"exit initialisation through {form}")
        h.expect(h.step(c, 0.0, H), OK, f"a step through {form}")
        h.free(c)
    missing = str(h.resources.parent / "nowhere")
    bad = [b"file://otherhost" + str(h.resources).encode(), b"http://localhost/x", b"resources", b"",
           ("file://" + missing).encode(), b"file:///tmp/%zz%", None]
    for location in bad:
        mark = len(h.log)
        h.checks += 1
        c = h.instantiate(location=location)
        if c:
            h.free(c)
            raise Failure(f"resource location {location!r}: an instance")
        h.expect_logged(mark, ERROR, f"resource location {location!r}", "resource")


def case_identity(h: Host):
    for what, kw, words in (("a wrong GUID / token", dict(token=b"{not-this-fmu}"), ("not this FMU",)),
                            ("a NULL GUID / token", dict(token=None), ("NULL",)),
                            ("a NULL instance name", dict(name=None), ("name",))):
        mark = len(h.log)
        h.checks += 1
        c = h.instantiate(**kw)
        if c:
            h.free(c)
            raise Failure(f"{what}: an instance")
        h.expect_logged(mark, ERROR, what, *words)
    if h.fmi == "2":
        mark = len(h.log)
        h.expect(h.instantiate(fmu_type=0), None, "model exchange")
        h.expect_logged(mark, ERROR, "model exchange", "co-simulation")
    else:
        f = h.fn("fmi3InstantiateModelExchange", C.c_void_p, C.c_char_p, C.c_char_p, C.c_char_p, C.c_bool, C.c_bool,
                 C.c_void_p, LOGGER3)
        h.expect(f(b"me", h.token, h.uri(), False, False, None, h._logger), None, "model exchange")
    c = h.instantiate(callbacks=False)  # no logger (FMI 3 allows it; an FMI 2 host that omits it)
    h.checks += 1
    if not c:
        raise Failure("no instance without callbacks")
    h.expect(h.step(c, 0.0, H), ERROR, "a step before initialisation without a logger")
    h.free(c)


def case_unsupported(h: Host):
    names = (["fmi2GetDirectionalDerivative", "fmi2CancelStep", "fmi2GetRealOutputDerivatives"] if h.fmi == "2"
             else ["fmi3EnterEventMode", "fmi3GetDirectionalDerivative", "fmi3SetTime", "fmi3GetClock"])
    for name in names:
        c = h.ready()
        h.call(ERROR, name, lambda: h.generic(name, c), "not supported")
        h.free(c)


def case_logging(h: Host):
    """Errors reach the host with loggingOn false; nothing is logged for a good run without debug logging."""
    c = h.ready()
    mark = len(h.log)
    for k in range(3):
        h.expect(h.step(c, k * H, H), OK, "a step")
    h.expect(h.log[mark:], [], "no message during a good run without debug logging")
    h.free(c)


def case_slave_messages(h: Host):
    """What the slave logs reaches the host in order, before the error of the same call; debug (OK) messages
    only with loggingOn (injected into the slave's class in this process)."""
    cls = _slave_class(h)
    original = cls.do_step

    def noisy(self, t, dt):
        self.log("a debug note from the slave", 0, "logAll")
        return original(self, t, dt)

    def failing(self, t, dt):
        self.log("a warning before the failure", 1, "logStatusWarning")
        raise ValueError("injected failure")

    try:
        cls.do_step = noisy
        for logging_on in (False, True):
            c = h.new(logging_on=logging_on)
            h.expect(h.setup(c)[-1], OK, "initialisation")
            h.expect(h.exit_init(c), OK, "exit initialisation")
            mark = len(h.log)
            h.expect(h.step(c, 0.0, H), OK, "a step that logs a debug note")
            got = [m for s, _, m in h.log[mark:] if s == OK]
            h.expect(got, ["a debug note from the slave"] if logging_on else [], f"debug notes with loggingOn={logging_on}")
            h.free(c)
        cls.do_step = failing
        c = h.ready()
        mark = len(h.log)
        h.expect(h.step(c, 0.0, H), ERROR, "a step that logs, then raises")
        got = [(s, "warning" if "a warning before the failure" in m else "error" if "ValueError: injected failure" in m
                else m) for s, _, m in h.log[mark:]]
        h.expect(got, [(WARNING, "warning"), (ERROR, "error")], "the slave's warning, then the error")
        h.free(c)
    finally:
        del cls.do_step


CASES = {name[5:]: f for name, f in sorted(globals().items()) if name.startswith("case_")}


def run(fmu: Path, work: Path, binary: str | None, cases, folder: str = ODD_FOLDER) -> dict:
    h = Host(fmu, work, binary, folder)
    failures, seconds = [], {}
    for name in cases:
        start = time.perf_counter()
        try:
            CASES[name](h)
        except Failure as e:
            failures.append(f"{name}: {e}")
        seconds[name] = round(time.perf_counter() - start, 3)
    if h.bad_format:
        failures.append(f"FMI 2 messages with a bare '%': {h.bad_format[:2]}")
    return {"fmu": fmu.name, "fmi": h.fmi, "checks": h.checks, "failures": failures, "seconds": seconds}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--work")
    ap.add_argument("--folder", default=ODD_FOLDER, help="the folder the FMUs are extracted into (a plain name to "
                    "measure a library that cannot decode URIs on the other cases)")
    ap.add_argument("fmus", nargs="+")
    args = ap.parse_args()
    cases = [c for c in args.cases.split(",") if c]
    unknown = sorted(set(cases) - set(CASES))
    if unknown:
        ap.error(f"unknown cases {unknown}; known: {', '.join(CASES)}")
    work = Path(args.work or tempfile.mkdtemp(prefix="hostile_"))
    for fmu in args.fmus:
        print(json.dumps(run(Path(fmu), work, args.binary, cases, args.folder)), flush=True)
    if not args.work:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
