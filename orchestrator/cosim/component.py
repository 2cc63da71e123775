"""The one interface the master drives (:class:`Component`) and what every kind of component shares:
the variable record, the neutral error, the registry of index subsets.

The kinds: :class:`orchestrator.cosim.fmu.FMUComponent` runs a co-simulation FMU through fmpy's raw
functions (thin FMI 2.0 and 3.0 parts, as fmpy does with its ``_FMU`` base);
:class:`orchestrator.cosim.block.BlockComponent` runs the same block in-process (no FMI), the
reference path. Every failure is one neutral :class:`ComponentError` naming the instance, the
call, the time and the status in the FMI version's own words.

The interface (every member is in :class:`Component`):
  ``name``, ``model_name``
  ``variables``            name -> ``VarInfo`` (value reference, causality, unit, start)
  ``feedthrough``          output name -> set of input names it depends on directly
  ``can_roll_back``, ``variable_step``  what the component declares it can do (FMUs: the
                           modelDescription's canGetAndSetFMUstate and
                           canHandleVariableCommunicationStepSize; in-process blocks: both)
  ``setup(t0, t1, params, inputs)``  instantiate, set parameters / input start values, initialise
  ``bind(out_names, out_buf, in_names, in_buf)``  where its outputs are read into and its inputs
                           written from (float64 numpy views of the plan's arrays)
  ``subset(out_positions, in_positions) -> k``  register a group of bound outputs or inputs
  ``prepare()``            once every subset is registered: build what read_some / write_some use
  ``read_some(k)`` / ``write_some(k)``  copy the k-th subset's outputs into ``out_buf`` / inputs
                           from ``in_buf``
  ``step(t, h)``           advance from t to t + h
  ``read_values(names)``   current values of Real variables (e.g. parameters after set-up), as
                           the FMU reports them (fmi2GetReal / fmi3GetFloat64) or the block holds them
  ``get_state()`` / ``set_state(s)`` / ``free_state(s)`` (rollback), ``terminate()`` (always safe
                           to call, frees everything)
"""
from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from orchestrator.common.errors import SimulationError


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
            self.missing_module = missing.group(1)
            msg = (f"instance '{instance}'{where}: the FMU's Python code cannot import module "
                   f"'{self.missing_module}': it is not installed in the Python running the FMUs "
                   f"({sys.executable}, Python {sys.version.split()[0]}); the FMU lists what it needs in "
                   f"resources/requirements.txt (pip install -r it, or `pythonfmu deploy -f FILE.fmu`)")
        if log:
            msg += f" -- FMU log: {log}"
        super().__init__(msg)


@runtime_checkable
class Component(Protocol):
    """Everything the exchange plan (``orchestrator/cosim/plan.py``), the step policies
    (``policies.py``), the runner and campaigns use of a component (see the module docstring).
    ``tests/orchestrator/test_component_protocol.py`` checks that both kinds have every member and
    that this list is complete."""

    name: str
    model_name: str
    variables: dict  # name -> VarInfo
    feedthrough: dict  # output name -> set of the input names it depends on directly
    can_roll_back: bool  # get_state / set_state work (FMU: canGetAndSetFMUstate)
    variable_step: bool  # step() takes any h (FMU: canHandleVariableCommunicationStepSize)

    def setup(self, t0: float, t1: float, params: dict, inputs: dict) -> None: ...
    def bind(self, out_names, out_buf, in_names, in_buf) -> None: ...
    def subset(self, out_positions=None, in_positions=None) -> int: ...
    def prepare(self) -> None: ...
    def read_some(self, k: int) -> None: ...
    def write_some(self, k: int) -> None: ...
    def step(self, t: float, h: float) -> None: ...
    def read_values(self, names) -> list: ...
    def get_state(self): ...
    def set_state(self, state) -> None: ...
    def free_state(self, state) -> None: ...
    def terminate(self) -> None: ...


class Subsets:
    """Index subsets of a component's bound outputs/inputs (for ordered propagation)."""

    def __init__(self):
        self.out_subsets: list[np.ndarray] = []
        self.in_subsets: list[np.ndarray] = []

    def subset(self, out_positions=None, in_positions=None) -> int:
        self.out_subsets.append(np.asarray(out_positions if out_positions is not None else [], dtype=np.intp))
        self.in_subsets.append(np.asarray(in_positions if in_positions is not None else [], dtype=np.intp))
        return len(self.out_subsets) - 1


def as_slice(positions):
    """Consecutive ascending indices as a slice (same elements), anything else unchanged."""
    p = np.asarray(positions, dtype=np.intp)
    if p.size and np.array_equal(p, np.arange(p[0], p[0] + p.size)):
        return slice(int(p[0]), int(p[0]) + p.size)
    return p
