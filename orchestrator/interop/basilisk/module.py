"""Any co-simulation FMU (ftcsim's estimators, FTC laws, fault blocks, sensors, plants, or any other
FMI 2.0 / 3.0 co-simulation FMU) as a Basilisk module: :class:`FMUModule`, a Basilisk ``SysModel`` that
runs the FMU through fmpy (the FMU component of ftcsim's master, ``orchestrator/cosim/fmu.py``).

Messages (every FMU variable is bound by its base name, ``q`` for ``q[0..3]``, to one port; units SI):

=============  =====================  ======================  ===================================================
port           input message          output message          conversion (orchestrator/interop/basilisk/conventions.py)
=============  =====================  ======================  ===================================================
``sc.q``       ``scStateInMsg``       ``scStateOutMsg``       SCStatesMsg sigma_BN (MRP) <-> q (scalar first)
``sc.sigma231````scStateInMsg``       ``scStateOutMsg``       sigma_BN <-> 001's [nu, psi, gamma] (2-3-1)
``sc.mrp``     ``scStateInMsg``       ``scStateOutMsg``       sigma_BN as it is
``sc.omega``   ``scStateInMsg``       ``scStateOutMsg``       omega_BN_B, rad/s
``nav.q``      ``attNavInMsg``        ``attNavOutMsg``        NavAttMsg sigma_BN <-> q (e.g. simpleNav's output)
``nav.omega``  ``attNavInMsg``        ``attNavOutMsg``        NavAttMsg omega_BN_B, rad/s
``imu.omega``  ``imuInMsg``           ``imuOutMsg``           IMUSensorMsg AngVelPlatform, rad/s (platform = body)
``st.q``       ``stInMsg``            ``stOutMsg``            STSensorMsg qInrtl2Case (scalar first; case = body)
``cmd.torque`` ``cmdTorqueInMsg``     ``cmdTorqueOutMsg``     CmdTorqueBodyMsg torqueRequestBody, N.m on the body
``rw.torque``  ``rwMotorTorqueInMsg`` ``rwMotorTorqueOutMsg`` ArrayMotorTorqueMsg motorTorque = -u_c (N.m; ftcsim's
                                                              u_c acts on the body, motorTorque on the wheel)
``rw.speed``   ``rwSpeedInMsg``       ``rwSpeedOutMsg``       RWSpeedMsg wheelSpeeds, rad/s relative to the body
=============  =====================  ======================  ===================================================

Without ``inputs`` / ``outputs``, ftcsim's names bind themselves: inputs ``q`` -> ``sc.q``, ``sigma`` ->
``sc.sigma231``, ``omega`` -> ``sc.omega``, ``u`` (3) -> ``cmd.torque``, ``u_c`` -> ``rw.torque``;
outputs ``u`` (3) -> ``cmd.torque``, ``u_c`` -> ``rw.torque``. An input bound to nothing keeps its start
value; :meth:`FMUModule.link` feeds an input from another module's output (an estimate to a law).

Time: the module steps its FMU by ``step`` (s), which must be the period of its task: every call comes
``step`` after the previous one, else :class:`BridgeError` names both. At each call (time t) it sets the
inputs read from the messages, publishes the outputs that depend directly on an input (the FMU's
``dependencies``: a law's u) as their values at t, steps the FMU to t + step, and publishes the outputs
that depend on no input (a state: an observer's estimate) as their values at t + step, which is what a
module reads at the next call. So, as in ftcsim's ordered exchange: give a module a higher priority
than the modules whose *direct* outputs it reads (the spacecraft before the law), and a lower one than
the modules whose *state* outputs it reads (the law before the observer whose estimate it uses, the
observer after the law whose command it is told). :meth:`FMUModule.link` checks that order at every call.
An FMU whose direct outputs a module needs before it can give the FMU its remaining inputs (000's FAFEO:
its estimate depends on the measured rate, and it is told the command the law computes from that
estimate) is split in two calls, ftcsim's ordered exchange: ``FMUModule(..., split=True)`` reads what
is there and publishes the direct outputs, ``module.late`` (added after the law) reads the rest and steps.
A command written at t acts on the spacecraft over [t, t + step] (Basilisk's reaction wheels read it
at the next call), as the zero-order hold of ftcsim's master.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from Basilisk.architecture import messaging, sysModel
from fmpy import read_model_description

from orchestrator.cosim.fmu import fmu_component
from orchestrator.scenario.shipped import fmu_folder
from plant.naming import split_name

from . import conventions as cv

__all__ = ["FMUModule", "BridgeError", "initialize", "execute", "PORTS"]


class BridgeError(RuntimeError):
    """A problem of an FMU module: its configuration, its place in the task, or a failed FMU call."""


def _quaternion(values) -> np.ndarray:
    q = np.asarray(values, dtype=float)
    return -q if q[0] < 0 else q


# port -> (message attribute stem, payload field, size (None: as the FMU variable), read conversion, write conversion)
PORTS = {
    "sc.q": ("scState", "sigma_BN", 4, cv.quaternion_from_mrp, cv.mrp_from_quaternion),
    "sc.sigma231": ("scState", "sigma_BN", 3, cv.euler231_from_mrp, cv.mrp_from_euler231),
    "sc.mrp": ("scState", "sigma_BN", 3, np.asarray, np.asarray),
    "sc.omega": ("scState", "omega_BN_B", 3, np.asarray, np.asarray),
    "nav.q": ("attNav", "sigma_BN", 4, cv.quaternion_from_mrp, cv.mrp_from_quaternion),
    "nav.omega": ("attNav", "omega_BN_B", 3, np.asarray, np.asarray),
    "imu.omega": ("imu", "AngVelPlatform", 3, np.asarray, np.asarray),
    "st.q": ("st", "qInrtl2Case", 4, _quaternion, _quaternion),
    "cmd.torque": ("cmdTorque", "torqueRequestBody", 3, np.asarray, np.asarray),
    "rw.torque": ("rwMotorTorque", "motorTorque", None, cv.body_torque, cv.motor_torque),
    "rw.speed": ("rwSpeed", "wheelSpeeds", None, np.asarray, np.asarray),
}
_MESSAGES = {"scState": "SCStatesMsg", "attNav": "NavAttMsg", "imu": "IMUSensorMsg", "st": "STSensorMsg",
             "cmdTorque": "CmdTorqueBodyMsg", "rwMotorTorque": "ArrayMotorTorqueMsg", "rwSpeed": "RWSpeedMsg"}
_ARRAY = {"motorTorque": 36, "wheelSpeeds": 36}  # fixed array sizes of those payload fields (MAX_EFF_CNT)
DEFAULT_INPUTS = {"q": "sc.q", "sigma": "sc.sigma231", "omega": "sc.omega", "u": "cmd.torque", "u_c": "rw.torque"}
DEFAULT_OUTPUTS = {"u": "cmd.torque", "u_c": "rw.torque"}

_LAST_ERROR: list = []  # the error an UpdateState raised (SWIG turns it into a RuntimeError): execute() re-raises it


def _reraising(call) -> None:
    _LAST_ERROR.clear()
    try:
        call()
    except RuntimeError:
        if _LAST_ERROR:
            raise _LAST_ERROR[-1] from None
        raise


def initialize(sim) -> None:
    """``sim.InitializeSimulation()``, re-raising an FMU module's :class:`BridgeError` as itself."""
    _reraising(sim.InitializeSimulation)


def execute(sim) -> None:
    """``sim.ExecuteSimulation()``, re-raising an FMU module's :class:`BridgeError` as itself (SWIG reports
    an exception in a Python module as "SWIG director method error")."""
    _reraising(sim.ExecuteSimulation)


def resolve_fmu(fmu) -> Path:
    """An FMU file, or the model name of one of ftcsim's built FMUs (``FAFEO``: ``build/fmus/FAFEO.fmu``,
    or ``$FTCSIM_FMU_DIR``)."""
    p = Path(fmu)
    if p.suffix != ".fmu" and os.sep not in str(fmu):
        p = fmu_folder() / f"{fmu}.fmu"
    if not p.is_file():
        raise BridgeError(f"{fmu}: FMU file not found ({p}; `ftcsim build` writes ftcsim's FMUs)")
    return p


class FMUModule(sysModel.SysModel):
    """One co-simulation FMU as a Basilisk module (see the module docstring for the ports and time).

    Parameters
    ----------
    fmu : str or Path
        The FMU file, or the model name of one of ftcsim's FMUs (``"FAFEO"``).
    step : float
        The FMU's communication step, s: the period of the task the module is added to.
    parameters : dict, optional
        Parameter values by structured name (``"K_p[1,1]"``) or base name with an array (``"J": J``).
    inputs, outputs : dict, optional
        FMU variable base name -> port (``{"q": "st.q", "omega": "imu.omega"}``); ``None``: ftcsim's names
        bind themselves (module docstring); ``{}``: none.
    name : str, optional
        The instance and ``ModelTag`` (default: the FMU's model name).
    """

    def __init__(self, fmu, step: float, parameters: dict | None = None, inputs: dict | None = None,
                 outputs: dict | None = None, name: str | None = None, split: bool = False):
        super().__init__()
        path = resolve_fmu(fmu)
        md = read_model_description(str(path))
        if md.coSimulation is None:
            raise BridgeError(f"{path.name}: not a co-simulation FMU (model exchange only)")
        self.name = self.ModelTag = name or md.modelName
        if not (isinstance(step, (int, float)) and np.isfinite(step) and step > 0):
            raise BridgeError(f"{self.name}: step = {step!r}: the task period in s, > 0")
        self.step = float(step)
        self.step_ns = int(round(self.step * 1e9))
        self.path, self.md = path, md
        self.component = fmu_component(self.name, path, md)
        self.names = {}  # base name -> [structured names in index order] (Real / Float64 only)
        for v in md.modelVariables:
            if v.type in ("Real", "Float64"):
                self.names.setdefault(split_name(v.name)[0], []).append(v)
        for base, vs in self.names.items():
            vs.sort(key=lambda v: split_name(v.name)[1])
            self.names[base] = [v.name for v in vs]
        self.causality = {v.name: v.causality for v in md.modelVariables}
        self.parameters = self._expand_parameters(parameters or {})
        self.inputs = self._bind(inputs, "input", DEFAULT_INPUTS)
        self.outputs = self._bind(outputs, "output", DEFAULT_OUTPUTS)
        self.links = {}  # input base -> (module, output base)
        self.held = {}  # input base -> value held (hold())
        for stem, cls in _MESSAGES.items():  # every port's messages exist, bound or not (Basilisk's style)
            setattr(self, f"{stem}InMsg", getattr(messaging, cls + "Reader")())
            setattr(self, f"{stem}OutMsg", getattr(messaging, cls)())
        self.values: dict[str, np.ndarray] = {}  # output base -> value last published
        self.valid_at: dict[str, int] = {}  # output base -> time (ns) its published value is for
        self.feedthrough = {base: any(self.component.feedthrough.get(n) for n in self.names[base])
                            for base in self.names if self._causality(base) == "output"}
        self.current: dict[str, np.ndarray] = {}  # output base -> value at the time of the last call
        self._payloads = {}  # message stem -> its payload, kept: ports publishing at different times share it
        self._last = None
        self._started = False
        self._pending, self._deferred = None, []
        self.late = _Late(self) if split else None

    # -- configuration -------------------------------------------------------------------------
    def _causality(self, base: str) -> str:
        return self.causality[self.names[base][0]]

    def _expand_parameters(self, given: dict) -> dict:
        out = {}
        for key, value in given.items():
            if key in self.causality:
                names, values = [key], [value]
            elif key in self.names and len(self.names[key]) == np.size(value):
                names, values = self.names[key], np.ravel(np.asarray(value, dtype=float)).tolist()
            else:
                raise BridgeError(f"{self.name}: parameters.{key}: no such parameter of {self.md.modelName} "
                                  "(or not as many elements)")
            for n, x in zip(names, values):
                if self.causality[n] != "parameter":
                    raise BridgeError(f"{self.name}: parameters.{key}: {n} is an {self.causality[n]}, not a parameter")
                if not np.isfinite(float(x)):
                    raise BridgeError(f"{self.name}: parameters.{n} = {x!r} is not a finite number")
                out[n] = float(x)
        return out

    def _bind(self, given, causality: str, defaults: dict) -> dict:
        """FMU base name -> port, checked (the port exists, the sizes agree, the causality fits)."""
        explicit = given is not None
        given = dict(defaults if given is None else given)
        out = {}
        for base, port in given.items():
            if port not in PORTS:
                raise BridgeError(f"{self.name}: {causality}s.{base}: unknown port {port!r} (ports: {', '.join(PORTS)})")
            if base not in self.names or self._causality(base) != causality:
                if explicit:
                    raise BridgeError(f"{self.name}: {causality}s.{base}: {self.md.modelName} has no {causality} {base}")
                continue
            size = PORTS[port][2]
            n = len(self.names[base])
            if size is not None and n != size or size is None and n > _ARRAY[PORTS[port][1]]:
                if explicit:
                    raise BridgeError(f"{self.name}: {causality}s.{base}: {n} elements, port {port} carries "
                                      f"{size if size is not None else 'at most ' + str(_ARRAY[PORTS[port][1]])}")
                continue
            out[base] = port
        return out

    def hold(self, values: dict) -> None:
        """Hold inputs bound to no port at these values (base name -> value; a target attitude ``q_d``), from
        the next Reset on."""
        for base, value in values.items():
            if base not in self.names or self._causality(base) != "input":
                raise BridgeError(f"{self.name}: hold: {self.md.modelName} has no input {base}")
            if base in self.inputs or base in self.links:
                raise BridgeError(f"{self.name}: hold: input {base} is bound to {self.inputs.get(base) or 'a link'}")
            x = np.ravel(np.asarray(value, dtype=float))
            if x.size != len(self.names[base]) or not np.all(np.isfinite(x)):
                raise BridgeError(f"{self.name}: hold: {base} needs {len(self.names[base])} finite numbers, got {value!r}")
            self.held[base] = x

    def link(self, input_base: str, source: FMUModule, output_base: str | None = None) -> None:
        """Feed this module's input ``input_base`` from ``source``'s output ``output_base`` (the same name by
        default), checking at every call that the value read is the source's value at this time."""
        output_base = output_base or input_base
        if input_base not in self.names or self._causality(input_base) != "input":
            raise BridgeError(f"{self.name}: link: {self.md.modelName} has no input {input_base}")
        if output_base not in source.names or source._causality(output_base) != "output":
            raise BridgeError(f"{self.name}: link: {source.name} has no output {output_base}")
        if len(self.names[input_base]) != len(source.names[output_base]):
            raise BridgeError(f"{self.name}: link {source.name}.{output_base} -> {input_base}: "
                              f"{len(source.names[output_base])} elements into {len(self.names[input_base])}")
        self.inputs.pop(input_base, None)
        self.links[input_base] = (source, output_base)

    # -- Basilisk --------------------------------------------------------------------------------
    def Reset(self, CurrentSimNanos):
        try:
            self._reset(CurrentSimNanos)
        except Exception as e:
            raise self._fail(e, "Reset", CurrentSimNanos) from None

    def UpdateState(self, CurrentSimNanos):
        try:
            self._update(CurrentSimNanos)
        except Exception as e:
            raise self._fail(e, "UpdateState", CurrentSimNanos) from None

    def _fail(self, e, where, t_ns) -> BridgeError:
        err = e if isinstance(e, BridgeError) else BridgeError(f"{self.name} ({self.path.name}) at t = {t_ns * 1e-9:.9g} s, "
                                                               f"{where}: {' '.join(str(e).split())}")
        _LAST_ERROR.append(err)
        return err

    def _reset(self, t_ns: int) -> None:
        for base, port in self.inputs.items():
            reader = getattr(self, PORTS[port][0] + "InMsg")
            if not reader.isLinked():
                raise BridgeError(f"{self.name}: input {base} is bound to {port}, but {PORTS[port][0]}InMsg is subscribed "
                                  f"to no message (subscribeTo one, or pass inputs={{...}} without {base})")
        if self._started:
            self.component.terminate()
        self.t0_ns = t_ns
        held = {n: float(x) for b, v in self.held.items() for n, x in zip(self.names[b], v)}
        self.component.setup(t_ns * 1e-9, None, self.parameters, held)
        self._started = True
        self.in_names = [n for b in self.names if self._causality(b) == "input" for n in self.names[b]]
        self.out_names = [n for b in self.names if self._causality(b) == "output" for n in self.names[b]]
        self._in = np.array([self.component.variables[n].start or 0.0 for n in self.in_names])
        for base, x in self.held.items():
            self._in[[self.in_names.index(n) for n in self.names[base]]] = x
        self._out = np.zeros(len(self.out_names))
        self.component.bind(self.out_names, self._out, self.in_names, self._in)
        self._all = self.component.subset(np.arange(len(self.out_names)), np.arange(len(self.in_names)))
        ft = [i for i, n in enumerate(self.out_names) if self.feedthrough[split_name(n)[0]]]
        st = [i for i, n in enumerate(self.out_names) if not self.feedthrough[split_name(n)[0]]]
        self._ft = self.component.subset(ft, [])  # read before the step: the outputs of the inputs just set
        self._st = self.component.subset(st, [])  # read after it: the states at the next call
        self.component.prepare()
        self._in_pos = {b: [self.in_names.index(n) for n in self.names[b]] for b in self.names if self._causality(b) == "input"}
        self._out_pos = {b: [self.out_names.index(n) for n in self.names[b]] for b in self.names if self._causality(b) == "output"}
        self.component.read_some(self._all)
        self._last, self._pending = None, None
        self.values, self.valid_at = {}, {}
        self._publish(t_ns, t_ns, state=True)

    def _link_error(self, base: str, t_ns: int) -> BridgeError:
        source, out_base = self.links[base]
        at = source.valid_at.get(out_base)
        if source.feedthrough[out_base]:
            hint = (f"{out_base} depends on {source.name}'s inputs, so {source.name} must run first at each call (give it "
                    f"a higher priority than {self.name}"
                    + ("" if self.late else f", or build {self.name} with split=True and add {self.name}.late to the task "
                                            f"after {source.name}") + ")")
        else:
            hint = (f"{out_base} is a state of {source.name}, published after its step, so {self.name} must run first at "
                    f"each call (give {self.name} a higher priority than {source.name})")
        return BridgeError(f"{self.name}: input {base} reads {source.name}.{out_base}, whose value is for t = "
                           f"{'(none yet)' if at is None else f'{at * 1e-9:.9g} s'}, not for this call's t = "
                           f"{t_ns * 1e-9:.9g} s: " + hint)

    def _update(self, t_ns: int) -> None:
        """The call (the first of two with ``split``): inputs, outputs of direct feedthrough; the step."""
        if self._last is not None and t_ns - self._last != self.step_ns:
            raise BridgeError(f"{self.name}: called at t = {t_ns * 1e-9:.9g} s, {(t_ns - self._last) * 1e-9:.9g} s after its "
                              f"previous call, but its FMU steps by step = {self.step:g} s: add it to a task of period "
                              f"{self.step:g} s (macros.sec2nano({self.step:g}))")
        if self._last is None and t_ns != self.t0_ns:
            raise BridgeError(f"{self.name}: first called at t = {t_ns * 1e-9:.9g} s, but its FMU started at "
                              f"{self.t0_ns * 1e-9:.9g} s (a task with a first start time?)")
        if self.late is not None and self._pending is not None:
            raise BridgeError(f"{self.name}: {self.name}.late did not run after the call at {self._pending * 1e-9:.9g} s: "
                              f"add {self.name}.late to the same task, with a lower priority")
        self._last = t_ns
        for base, port in self.inputs.items():
            stem, field, _, read, _ = PORTS[port]
            payload = getattr(self, stem + "InMsg")()
            n = len(self._in_pos[base])
            value = np.asarray(read(np.asarray(getattr(payload, field), dtype=float)[: n if PORTS[port][2] is None else None]))
            self._in[self._in_pos[base]] = value
        deferred = []
        for base, (source, out_base) in self.links.items():
            if source.valid_at.get(out_base) == t_ns:
                self._in[self._in_pos[base]] = source.values[out_base]
            elif self.late is not None:
                deferred.append(base)  # its source runs after this call: read at the late call
            else:
                raise self._link_error(base, t_ns)
        self.component.write_some(self._all)
        self.component.read_some(self._ft)
        waiting = {n for b in deferred for n in self.names[b]}
        self._publish(t_ns, t_ns, state=False, skip={b for b in self.feedthrough if self.feedthrough[b]
                                                      and any(self.component.feedthrough.get(n, set()) & waiting
                                                              for n in self.names[b])})
        if self.late is not None:
            self._pending, self._deferred = t_ns, deferred
            return
        self._finish(t_ns)

    def _late_update(self, t_ns: int) -> None:
        """The second call of a split module: the inputs whose sources ran in between, then the step."""
        if self._pending != t_ns:
            raise BridgeError(f"{self.name}.late: called at t = {t_ns * 1e-9:.9g} s without {self.name}'s call at that time "
                              f"before it (add {self.name} with a higher priority, {self.name}.late with a lower one)")
        for base in self._deferred:
            source, out_base = self.links[base]
            if source.valid_at.get(out_base) != t_ns:
                raise self._link_error(base, t_ns)
            self._in[self._in_pos[base]] = source.values[out_base]
        if self._deferred:
            self.component.write_some(self._all)
            self.component.read_some(self._ft)
            self._publish(t_ns, t_ns, state=False)
        self._pending = None
        self._finish(t_ns)

    def _finish(self, t_ns: int) -> None:
        self.current = {b: v for b, v in self.values.items()}  # every output's value at t (records, value())
        self.component.step(t_ns * 1e-9, self.step)
        self.component.read_some(self._st)
        self._publish(t_ns + self.step_ns, t_ns + self.step_ns, state=True)

    def _publish(self, t_ns: int, valid_ns: int, state: bool, skip=()) -> None:
        """Publish the outputs that depend on no input (``state``) or on some input (not ``state``),
        except ``skip`` (outputs that depend on an input not read yet)."""
        payloads = {}
        for base, pos in self._out_pos.items():
            if self.feedthrough[base] == state or base in skip:
                continue
            value = self._out[pos].copy()
            self.values[base], self.valid_at[base] = value, valid_ns
            port = self.outputs.get(base)
            if port is None:
                continue
            stem, field, size, _, write = PORTS[port]
            payload = payloads[stem] = self._payloads.setdefault(stem, getattr(messaging, _MESSAGES[stem] + "Payload")())
            x = np.asarray(write(value), dtype=float)
            if size is None:
                x = np.concatenate((x, np.zeros(_ARRAY[field] - x.size)))
            setattr(payload, field, x.tolist())
        for stem, payload in payloads.items():
            getattr(self, stem + "OutMsg").write(payload, t_ns, self.moduleID)

    def value(self, base: str) -> np.ndarray:
        """The value of output ``base`` at the time of the last call (a state output's published value is
        already the next call's: ``values``, ``valid_at``)."""
        return self.current[base]

    def __del__(self):
        try:
            if self._started:
                self.component.terminate()
        except Exception:
            pass


class _Late(sysModel.SysModel):
    """The second call of a split :class:`FMUModule` (``module.late``): add it to the same task with a
    lower priority than the modules whose outputs the FMU's remaining inputs read."""

    def __init__(self, module: FMUModule):
        super().__init__()
        self.module = module
        self.ModelTag = f"{module.name}.late"

    def UpdateState(self, CurrentSimNanos):
        try:
            self.module._late_update(CurrentSimNanos)
        except Exception as e:
            raise self.module._fail(e, "late UpdateState", CurrentSimNanos) from None
