"""The blocks' own refusals, before any FMU starts (see :mod:`orchestrator.scenario.physical`): a block's
``initialize`` is the declaration of what it accepts, so it is run in-process on the run's values, for
in-process instances and for FMUs that ``ftcsim build`` made from the catalog (the same block runs
inside them). One block per model is kept and initialised again for each check (never stepped);
verdicts are cached by values. Here, not in ``physical.py``, because it reaches the catalog
(``scenario/shipped.py``), which the engine (``cosim/runner.py`` imports ``physical``) must not."""
from __future__ import annotations

import re
import threading

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.scenario.physical import nominal_values


def check_block_initialisation(src, scenario) -> None:
    """Refuse values an instance's block would refuse at initialisation, naming the instance's parameter."""
    for name, inst in scenario.instances.items():
        if inst.model_description is None and inst.factory is None:
            continue
        refused = block_refuses(inst, nominal_values(inst), scenario.start)
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
