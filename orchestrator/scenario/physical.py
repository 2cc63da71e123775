"""Parameter values as a run uses them, and their physical meaning checked before any FMU starts.

:func:`check_physical` applies ``plant/physical.py``'s rules (one set for every block family: an
inertia tensor symmetric and positive definite, frequencies, limits and time constants > 0,
damping >= 0, fractions in [0, 1]) to every instance's values (the FMU's or block's start values
with the scenario's, the design files' and the overrides' on top). It runs in
:func:`orchestrator.scenario.checks.validate`, which every path passes (scenario files, SSP packages,
``--set`` and API overrides, campaign variants and draws, ``compare``): a meaningless value is one
``InputError`` naming the file and the parameter, exit 2, nothing written. A value a model runs
with although no physical system has it (``plant.physical.implausible``: an inertia breaking the
triangle inequality, as paper 001's) is one warning line (logger ``ftcsim.scenario``: ``ftcsim:
warning: ...`` on the command line) naming the file and the parameter, once per process, when a run of
the scenario starts (:func:`warn_implausible`, called by ``cosim/runner.py``: the values the run uses,
after every override); the run goes on.
"""
from __future__ import annotations

import logging

from orchestrator.common.errors import InputError
from plant.physical import implausible, problems

log = logging.getLogger("ftcsim.scenario")

_STARTS: dict = {}


def nominal_values(inst) -> dict:
    """Every parameter value of an instance as the run would use it without further overrides: the
    scenario's (and overrides') values over the FMU's (or block's) start values."""
    k = str(inst.fmu) if inst.fmu is not None else inst.model_name
    if k not in _STARTS:
        if inst.model_description is not None:
            _STARTS[k] = {v.name: float(v.start) for v in inst.model_description.modelVariables
                          if v.causality == "parameter" and v.start is not None and v.type in ("Real", "Float64")}
        else:
            block = inst.factory()
            _STARTS[k] = {v.name: float(x) for v, x in zip(block.parameters, block.param_values)}
    return {**_STARTS[k], **inst.parameters}


def check_physical(src, scenario) -> None:
    """Refuse values no physical system has (``plant/physical.py``), naming the instance's parameter."""
    for name, inst in scenario.instances.items():
        if inst.model_description is None and inst.factory is None:
            continue  # nothing declares its start values
        found = problems(nominal_values(inst), inst.interface.units)
        if found:
            base, problem = found[0]
            raise InputError(src, f"instances.{name}.parameters.{base}", f"{inst.model_name}: {problem}")


_WARNED: set = set()


def warn_implausible(scenario) -> list[str]:
    """Log one warning line per value no physical system has but the model runs with
    (``plant.physical.implausible``), naming the scenario file and the first instance's parameter (and
    the others with the same value), once per distinct line and process (a campaign's runs share it);
    returns the lines of this call."""
    doubtful = {}  # problem -> [(instance, parameter, model)]
    for name, inst in scenario.instances.items():
        if inst.model_description is None and inst.factory is None:
            continue
        for base, problem in implausible(nominal_values(inst), inst.interface.units):
            doubtful.setdefault(problem, []).append((name, base, inst.model_name))
    lines = []
    for problem, where in doubtful.items():
        name, base, model = where[0]
        also = f" (the same value in {', '.join(f'{n}.{b}' for n, b, _ in where[1:])})" if where[1:] else ""
        lines.append(f"{scenario.path}: instances.{name}.parameters.{base}: {model}: {problem}{also}; the run goes "
                     "on with it (kept for the reproduction of a paper that prints it, as 001 does)")
    for text in lines:
        if text not in _WARNED:
            _WARNED.add(text)
            log.warning("warning: %s", text)
    return lines
