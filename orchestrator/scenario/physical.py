"""Parameter values as a run uses them, and their physical meaning checked before any FMU starts.

:func:`check_physical` applies two checks to every instance's values (the FMU's or block's start
values with the scenario's, the design files' and the overrides' on top):

* ``plant/physical.py``'s rules, declared per parameter by base name and unit (one set for every
  block family and for third-party FMUs using the same names: an inertia tensor symmetric and
  positive definite, frequencies, limits and time constants > 0, damping >= 0, fractions in [0, 1]);
* the block's own declaration of what it accepts: its ``initialize`` (the checks it makes inside
  the FMU, where a refusal would only be an FMI error after the folder was created) is run here,
  in-process, on a fresh block with the run's values, for every instance whose block ftcsim has
  (in-process runs, and FMUs that ``ftcsim build`` made from the catalog). So every value a block
  would refuse at initialisation (an integer parameter out of its range, a Markov initial mode that
  does not exist, a duty cycle above one, a singular distribution matrix) is refused before any
  FMU starts, by the same code that would refuse it there.

It runs in :func:`orchestrator.scenario.checks.validate`, which every path passes (scenario files, SSP
packages, ``--set`` and API overrides, campaign variants, grid points and draws, ``compare``, the
arena): a meaningless value is one ``InputError`` naming the file (or option) and the parameter,
exit 2, nothing written.
"""
from __future__ import annotations

import re
import threading

import numpy as np

from orchestrator.common.errors import InputError
from plant.physical import problems

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
    """Refuse values no physical system has (``plant/physical.py``) and values the instance's block
    would refuse at initialisation (see the module docstring), naming the instance's parameter."""
    for name, inst in scenario.instances.items():
        if inst.model_description is None and inst.factory is None:
            continue  # nothing declares its start values
        values = nominal_values(inst)
        with np.errstate(all="ignore"):  # values that overflow are judged, not warned about
            found = problems(values, inst.interface.units)
        if found:
            base, problem = found[0]
            raise InputError(src, f"instances.{name}.parameters.{base}", f"{inst.model_name}: {problem}")
        refused = block_refuses(inst, values, scenario.start)
        if refused:
            base, problem = refused
            while problem.startswith(f"{inst.model_name}: "):  # the block's own prefix, said once
                problem = problem[len(inst.model_name) + 2:]
            raise InputError(src, f"instances.{name}.parameters.{base}", f"{inst.model_name} refuses these values at "
                                                                         f"initialisation: {problem}")


def _factory_of(inst):
    """The in-process block factory of an instance: its own (in-process runs), or the catalog's for an
    FMU that ``ftcsim build`` made (the same block runs inside it); None for any other FMU."""
    if inst.factory is not None:
        return inst.factory
    md = inst.model_description
    if md is None or not str(getattr(md, "generationTool", "") or "").startswith("ftcsim build"):
        return None
    from orchestrator.scenario.shipped import block_factory  # the catalog (papers.registry), only here

    try:
        return block_factory(md.modelName)
    except InputError:  # a block built with `ftcsim build --block`: not in the catalog
        return None


def block_refuses(inst, values: dict, t0: float) -> tuple[str, str] | None:
    """(parameter, problem) if the instance's block refuses ``values`` at ``initialize(t0)``, else None
    (also when ftcsim has no block for the instance)."""
    factory = _factory_of(inst)
    if factory is None:
        return None
    key = (id(factory), t0, tuple(sorted(values.items())))
    if key in _VERDICTS:
        return _VERDICTS[key]
    if id(factory) not in _BLOCKS:  # one block per factory, initialised again for each check (never run)
        block = factory()
        _BLOCKS[id(factory)] = (factory, block, {v.name for v in block.parameters})
    _, block, declared = _BLOCKS[id(factory)]
    verdict = None
    if set(values) <= declared:  # else another block under the same model name: not ours to judge
        with _LOCK:  # the shared block, one check at a time
            verdict = _initialise(block, values, t0, declared)
    if len(_VERDICTS) > 4096:
        _VERDICTS.clear()
    _VERDICTS[key] = verdict
    return verdict


def _initialise(block, values, t0, declared):
    try:
        for n, x in values.items():
            block.set_parameter(n, x)
        with np.errstate(all="ignore"):
            block.initialize(t0)
    except (ValueError, ArithmeticError, KeyError, IndexError, np.linalg.LinAlgError) as e:
        problem = " ".join(str(e).split()) or type(e).__name__
        return _parameter_named(problem, declared), problem
    return None


_BLOCKS: dict = {}  # id(factory) -> (factory kept alive, a block of it, its parameter names)
_VERDICTS: dict = {}  # (factory, t0, values) -> verdict of block_refuses
_LOCK = threading.Lock()


def _parameter_named(problem: str, declared) -> str:
    """The declared parameter (base name) a block's message names first, else ``"-"``."""
    bases = sorted({d.split("[")[0] for d in declared}, key=len, reverse=True)
    found = [(m.start(), b) for b in bases for m in [re.search(rf"(?<![\w.]){re.escape(b)}(?![\w])", problem)] if m]
    return min(found)[1] if found else "-"
