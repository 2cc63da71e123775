"""Scenario -> components -> master -> RunResult, with FMUs freed on every path."""
from __future__ import annotations

from .components import BlockComponent, ComponentError, fmu_component
from .errors import InputError
from .master import Master
from .scenario import Scenario, fmu_interface
from .sources import PiecewiseConstant


def make_components(scenario: Scenario, mode: str = "fmu") -> dict:
    comps = {}
    for name, inst in scenario.instances.items():
        if mode == "fmu":
            _, md = fmu_interface(scenario.path, f"instances.{name}.fmu", inst.fmu)
            comps[name] = fmu_component(name, inst.fmu, md)
        elif mode == "inprocess":
            from fmus.catalog import block_factory

            comps[name] = BlockComponent(name, block_factory(inst.model_name)())
        else:
            raise InputError("command line", "--mode", f"unknown mode {mode!r} (fmu, inprocess)")
    return comps


def run_scenario(scenario: Scenario, mode: str = "fmu", exchange: str | None = None, progress: bool = False,
                 sample: str = "before"):
    """Run a validated scenario. FMU errors give a result with ``complete=False``. ``sample``:
    see :class:`orchestrator.plan.ExchangePlan` (Jacobi recording before or after the transfer)."""
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
        result = master.run(scenario.start, scenario.stop, scenario.step, progress=progress)
        result.mode = mode
        return result
    finally:
        for comp in started:
            comp.terminate()
