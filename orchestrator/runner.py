"""Scenario -> components -> master -> RunResult, with FMUs freed on every path."""
from __future__ import annotations

import os

from orchestrator.common.errors import InputError
from orchestrator.scenario.interfaces import fmu_interface
from orchestrator.scenario.model import Scenario

from .components import BlockComponent, ComponentError, fmu_component
from .master import Master
from .sources import PiecewiseConstant

_CHECKED: dict = {}  # (FMU file, size, mtime) -> its checked modelDescription, for processes that run many


def _model_description(scenario, name, path):
    st = os.stat(path)
    key = (os.path.abspath(path), st.st_size, st.st_mtime_ns)
    if key not in _CHECKED:
        if len(_CHECKED) > 256:
            _CHECKED.clear()
        _CHECKED[key] = fmu_interface(scenario.path, f"instances.{name}.fmu", path)[1]
    return _CHECKED[key]


def make_components(scenario: Scenario, mode: str = "fmu") -> dict:
    comps = {}
    for name, inst in scenario.instances.items():
        if mode == "fmu":
            md = _model_description(scenario, name, inst.fmu)
            comps[name] = fmu_component(name, inst.fmu, md)
        elif mode == "inprocess":
            from orchestrator.scenario.shipped import block_factory

            comps[name] = BlockComponent(name, block_factory(inst.model_name)())
        else:
            raise InputError("command line", "--mode", f"unknown mode {mode!r} (fmu, inprocess)")
    return comps


def make_policy(scenario: Scenario):
    """The step policy of a validated scenario (``[timing] step_policy``); None for the fixed
    step (``Master.run``'s default, the path pinned by the li2023 checksums)."""
    from orchestrator.scenario.checks import check_step_policy, multiple

    from .policies import AdaptiveStep, MultirateStep

    check_step_policy(scenario.path, scenario)
    st = scenario.timing
    announced = [(name, var) for name, inst in scenario.instances.items() for var in inst.announces]
    if st.policy == "fixed":
        return None
    if st.policy == "multirate":
        multiples = {name: multiple(inst.step, scenario.step) for name, inst in scenario.instances.items()
                     if inst.step is not None}
        return MultirateStep(scenario.step, multiples, announced, st.record_announced)
    return AdaptiveStep(scenario.step, st.output_step, st.rtol, st.atol, st.min_step, st.max_step, st.error_variables,
                        st.safety, announced, st.record_announced)


def run_scenario(scenario: Scenario, mode: str = "fmu", exchange: str | None = None, progress: bool = False,
                 sample: str = "before", after_setup=None):
    """Run a validated scenario. FMU errors give a result with ``complete=False``. ``sample``:
    see :class:`orchestrator.plan.ExchangePlan` (Jacobi recording before or after the transfer).
    ``after_setup(components)``, if given, is called once every component is initialised
    (campaigns read the applied parameter values back there)."""
    policy = make_policy(scenario)
    comps = make_components(scenario, mode)
    sources = [PiecewiseConstant(s.name, s.times, s.values, s.targets) for s in scenario.sources]
    master = Master(
        comps,
        scenario.connections,
        sources,
        scenario.record,
        exchange=exchange or scenario.exchange,
        origin=str(scenario.path),
        sample=sample,
        watch=policy.watch if policy is not None else (),
    )
    started = []
    try:
        for name, comp in comps.items():
            inst = scenario.instances[name]
            started.append(comp)
            try:
                comp.setup(scenario.start, scenario.stop, inst.parameters, {})
            except ComponentError as e:
                import numpy as np

                from .master import RunResult

                return RunResult(master.columns, np.zeros(0), np.zeros((0, len(master.columns))), False, str(e), mode=mode)
        if after_setup is not None:
            after_setup(comps)
        result = master.run(scenario.start, scenario.stop, scenario.step, progress=progress, policy=policy)
        result.mode = mode
        return result
    finally:
        for comp in started:
            comp.terminate()
