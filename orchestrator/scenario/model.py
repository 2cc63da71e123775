"""What a run is: the validated scenario and its parts (plain data, no checks, no files).

A :class:`Scenario` comes out of :mod:`orchestrator.scenario.toml` or :mod:`orchestrator.scenario.ssp`
with every check done once (:func:`orchestrator.scenario.checks.validate`); it carries what the engine
(``orchestrator.cosim``) needs: each instance's modelDescription (read once, at load) or its block
factory (in-process runs), the resolved step policy and multiples. The dataclasses are frozen: a
change is a new scenario (:func:`orchestrator.scenario.overrides.with_overrides`, validated again),
never an edit of a validated one. (Their dicts and lists are not copied: do not edit them either.)
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

INSTANCE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,63}$")


@dataclass(frozen=True)
class Interface:
    """What validation needs to know about a component: its variables by causality."""

    model_name: str
    causality: dict  # name -> 'input' | 'output' | 'parameter' | ...
    feedthrough: dict = field(default_factory=dict)  # output -> inputs it depends on directly
    units: dict = field(default_factory=dict)  # name -> unit string ("1" if none)
    unit_definitions: dict = field(default_factory=dict)  # unit -> canonical definition (plant/units.py)
    origin: str = ""  # the FMU file name, or "in-process"

    def names(self, causality):
        return [n for n, c in self.causality.items() if c == causality]


@dataclass(frozen=True)
class Instance:
    name: str
    fmu: Path | None  # None: in-process only
    model_name: str
    interface: Interface
    parameters: dict = field(default_factory=dict)  # structured scalar name -> float
    step: float | None = None  # own communication step (multirate), s; None: the base step
    announces: list = field(default_factory=list)  # outputs giving the next instant to step to
    capabilities: dict = field(default_factory=dict)  # FMU flags (canGetAndSetFMUstate, ...); {}: in-process
    model_description: object = None  # the FMU's (fmpy), read and checked once at load; None in-process
    factory: object = None  # in-process: the callable returning a fresh block; None for an FMU


@dataclass(frozen=True)
class StepSettings:
    """``[timing]``'s step policy and its settings (``orchestrator/scenario/toml.py``). ``policy`` None:
    not given; :func:`orchestrator.scenario.checks.check_step_policy` returns them resolved (policy,
    adaptive defaults, ``multiples``). Times in s."""

    policy: str | None = None
    rtol: float | None = None
    atol: float | None = None
    min_step: float | None = None
    max_step: float | None = None
    output_step: float | None = None
    safety: float | None = None
    error_variables: list = field(default_factory=list)  # [(inst, var)]; empty: the default
    record_announced: bool = False
    given: tuple = ()  # the [timing] keys the file set (for the messages)
    multiples: dict = field(default_factory=dict)  # resolved: instance -> its step / the base step (whole number)


@dataclass(frozen=True)
class Source:
    name: str
    kind: str
    times: list
    values: np.ndarray
    targets: list  # [(inst, var)]


@dataclass(frozen=True)
class Scenario:
    path: Path
    name: str
    description: str
    paper: str
    departures: list
    start: float
    stop: float
    step: float
    exchange: str
    instances: dict
    connections: list  # (src_inst, src_var, dst_inst, dst_var)
    sources: list
    record: list  # (inst, var)
    metrics: dict
    timing: StepSettings = field(default_factory=StepSettings)
    time_limit: float | None = None  # s of wall time of the stepping ([timing] time_limit; None: none)

    @property
    def n_steps(self) -> int:
        """Base steps (fixed and multirate: the communication steps)."""
        return int(round((self.stop - self.start) / self.step))

    @property
    def output_step(self) -> float:
        """The step of the recorded grid: ``output_step`` of an adaptive run, else ``step``."""
        return self.timing.output_step or self.step

    @property
    def mode(self) -> str:
        """``"inprocess"`` when every instance is a block run in-process, else ``"fmu"``."""
        return "inprocess" if all(i.fmu is None for i in self.instances.values()) else "fmu"

    @property
    def step_policy(self) -> str:
        return self.timing.policy or "fixed"
