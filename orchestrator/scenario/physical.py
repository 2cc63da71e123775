"""Parameter values as a run uses them, and their physical meaning checked before any FMU starts.

:func:`check_physical` applies two checks to every instance's values (the FMU's or block's start
values with the scenario's, the design files' and the overrides' on top):

* ``plant/physical.py``'s rules, declared per parameter by base name and unit (one set for every
  block family and for third-party FMUs using the same names: an inertia tensor symmetric and
  positive definite, frequencies, limits and time constants > 0, damping >= 0, fractions in [0, 1]);
* the block's own declaration of what it accepts: its ``initialize`` (the checks it makes inside
  the FMU, where a refusal would only be an FMI error after the folder was created) is run
  in-process (:mod:`orchestrator.scenario.block_checks`, beside this module so that the engine, which
  imports this one, reaches no catalog) on the run's values, for every instance whose block ftcsim has
  (in-process runs, and FMUs that ``ftcsim build`` made from the catalog). So every value a block
  would refuse at initialisation (an integer parameter out of its range, a Markov initial mode that
  does not exist, a duty cycle above one, a singular distribution matrix) is refused before any
  FMU starts, by the same code that would refuse it there.

It runs in :func:`orchestrator.scenario.checks.validate`, which every path passes (scenario files, SSP
packages, ``--set`` and API overrides, campaign variants, grid points and draws, ``compare``, the
arena): a meaningless value is one ``InputError`` naming the file (or option) and the parameter,
exit 2, nothing written. A value a model runs with although no physical system has it
(``plant.physical.implausible``: an inertia breaking the triangle inequality, as paper 001's) is one
warning line (logger ``ftcsim.scenario``: ``ftcsim: warning: ...`` on the command line) naming the file
and the parameter, once per distinct value and process, when a run of the scenario starts (:func:`warn_implausible`, called
by ``cosim/runner.py``: the values the run uses, after every override); the run goes on.
"""
from __future__ import annotations

import logging

import numpy as np

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
    """Refuse values no physical system has (``plant/physical.py``), naming the instance's parameter (the
    blocks' own refusals: :mod:`orchestrator.scenario.block_checks`)."""
    for name, inst in scenario.instances.items():
        if inst.model_description is None and inst.factory is None:
            continue  # nothing declares its start values
        values = nominal_values(inst)
        with np.errstate(all="ignore"):  # values that overflow are judged, not warned about
            found = problems(values, inst.interface.units)
        if found:
            base, problem = found[0]
            raise InputError(src, f"instances.{name}.parameters.{base}", f"{inst.model_name}: {problem}")


_WARNED: set = set()


def warn_implausible(scenario) -> list[str]:
    """Log one warning line per value no physical system has but the model runs with
    (``plant.physical.implausible``), naming the scenario file and the first instance's parameter (and
    the others with the same value), once per distinct problem and process (a campaign's or an arena's
    runs share it: the first file is named, the others with the same value are not repeated); returns
    the lines of this call."""
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
    for problem, text in zip(doubtful, lines):
        if problem not in _WARNED:
            _WARNED.add(problem)
            log.warning("warning: %s", text)
    return lines
