"""A validated scenario -> components -> master -> RunResult, with FMUs freed on every path.

The scenario comes as :mod:`orchestrator.scenario` validated it (``orchestrator.scenario.checks.validate``):
each instance carries its modelDescription (FMU runs) or its block factory (in-process runs), the step
settings are resolved. Nothing is loaded or checked again here."""
from __future__ import annotations

import numpy as np

from orchestrator.common.interrupt import REQUEST
from orchestrator.common.watchdog import Hung, guarded, start_clock
from orchestrator.cosim.block import BlockComponent
from orchestrator.cosim.component import ComponentError
from orchestrator.cosim.fmu import fmu_component
from orchestrator.cosim.master import Master, RunResult
from orchestrator.cosim.policies import AdaptiveStep, MultirateStep
from orchestrator.cosim.sources import PiecewiseConstant
from orchestrator.scenario.model import Scenario
from orchestrator.scenario.physical import warn_implausible


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
                 after_setup=None, time_limit: float | None = None):
    """Run a validated scenario. FMU errors give a result with ``complete=False``. ``sample``:
    see :class:`orchestrator.cosim.plan.ExchangePlan` (Jacobi recording before or after the transfer).
    ``after_setup(components)``, if given, is called once every component is initialised
    (campaigns read the applied parameter values back there). ``time_limit``: s of wall time of
    the stepping (set-up excluded; None: unbounded): the run then ends incomplete with ``info["timed_out"]``
    (:mod:`orchestrator.common.watchdog`, which also stops a call hung past a signal)."""
    warn_implausible(scenario)  # a value no physical system has, run all the same (001's J): one line
    try:
        with guarded(time_limit) as watch:
            result = _run(scenario, exchange, progress, sample, after_setup)
    except Hung as e:  # a component call hung during set-up (the stepping loop handles its own)
        result = RunResult([], np.zeros(0), np.zeros((0, 0)), False, str(e), mode=scenario.mode)
    if watch.fired and not result.complete:  # an FMU reports Hung as its own error: the cause is the stop
        result.error = watch.fired
        result.interrupted = REQUEST.signum
        if not REQUEST:
            result.info["timed_out"] = True
    return result


def _run(scenario, exchange, progress, sample, after_setup):
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
        start_clock()  # the time limit counts from here (orchestrator/common/watchdog.py)
        result = master.run(scenario.start, scenario.stop, scenario.step, progress=progress, policy=policy)
        result.mode = mode
        return result
    finally:
        for comp in started:
            comp.terminate()
