"""A validated scenario -> components -> master -> RunResult, with FMUs freed on every path.

The scenario comes as :mod:`orchestrator.scenario` validated it (``orchestrator.scenario.checks.validate``):
each instance carries its modelDescription (FMU runs) or its block factory (in-process runs), the step
settings are resolved. Nothing is loaded or checked again here."""
from __future__ import annotations

import numpy as np

from orchestrator.cosim.block import BlockComponent
from orchestrator.cosim.component import ComponentError
from orchestrator.cosim.fmu import fmu_component
from orchestrator.cosim.master import Master, RunResult
from orchestrator.cosim.policies import AdaptiveStep, MultirateStep
from orchestrator.cosim.sources import PiecewiseConstant
from orchestrator.scenario.model import Scenario


def make_components(scenario: Scenario) -> dict:
    """One component per instance: the FMU through fmpy, or the block in-process."""
    return {name: (fmu_component(name, inst.fmu, inst.model_description) if inst.fmu is not None
                   else BlockComponent(name, inst.factory()))
            for name, inst in scenario.instances.items()}


def make_policy(scenario: Scenario):
    """The step policy of a validated scenario (``[timing] step_policy``); None for the fixed
    step (``Master.run``'s default, the path pinned by the li2023 checksums)."""
    st = scenario.timing
    announced = [(name, var) for name, inst in scenario.instances.items() for var in inst.announces]
    if st.policy == "fixed":
        return None
    if st.policy == "multirate":
        return MultirateStep(scenario.step, dict(st.multiples), announced, st.record_announced)
    return AdaptiveStep(scenario.step, st.output_step, st.rtol, st.atol, st.min_step, st.max_step, st.error_variables,
                        st.safety, announced, st.record_announced)


def run_scenario(scenario: Scenario, exchange: str | None = None, progress: bool = False, sample: str = "before",
                 after_setup=None):
    """Run a validated scenario. FMU errors give a result with ``complete=False``. ``sample``:
    see :class:`orchestrator.cosim.plan.ExchangePlan` (Jacobi recording before or after the transfer).
    ``after_setup(components)``, if given, is called once every component is initialised
    (campaigns read the applied parameter values back there)."""
    policy = make_policy(scenario)
    mode = scenario.mode
    comps = make_components(scenario)
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
                return RunResult(master.columns, np.zeros(0), np.zeros((0, len(master.columns))), False, str(e), mode=mode)
        if after_setup is not None:
            after_setup(comps)
        result = master.run(scenario.start, scenario.stop, scenario.step, progress=progress, policy=policy)
        result.mode = mode
        return result
    finally:
        for comp in started:
            comp.terminate()
