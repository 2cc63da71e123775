"""Parameter values over a loaded scenario: structured expansion of scalars, vectors and matrices, and the
gains files of ``ftcsim design``."""
from __future__ import annotations

import dataclasses
import difflib
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import load_json_object
from orchestrator.scenario.checks import check_timing, validate
from orchestrator.scenario.model import Interface, Scenario
from orchestrator.scenario.physical import nominal_values  # noqa: F401 (its home was here)
from orchestrator.scenario.refs import expand, shape_of
from orchestrator.scenario.values import hint, number, short


def expand_parameters(src, key, itf: Interface, values: dict, full_key=False) -> dict:
    """{'J': [[..]], 'k_p': 20} -> {'J[1,1]': .., 'k_p': 20.0}, checked against ``itf``; errors name
    ``key.name`` (``key`` alone with ``full_key``)."""
    out = {}
    for name, value in values.items():
        k = key if full_key else f"{key}.{name}"
        names = expand(itf, name)
        if not names:
            params = itf.names("parameter")
            raise InputError(src, k, f"{itf.model_name} has no parameter '{name}'"
                             + hint(name, sorted({n.split("[")[0] for n in params}) + params))
        bad = [n for n in names if itf.causality[n] != "parameter"]
        if bad:
            raise InputError(src, k, f"'{bad[0]}' is {itf.causality[bad[0]]}, not a parameter")
        if len(names) == 1 and names[0] == name:
            out[name] = number(src, k, value)
            continue
        try:
            arr = np.asarray(value, dtype=object)
        except Exception:
            raise InputError(src, k, f"expected an array of numbers, got {short(value)}") from None
        flat = arr.ravel().tolist() if arr.ndim else [value]
        shape = shape_of(names)
        want = shape if len(shape) > 1 else (len(names),)
        if arr.shape != want:
            raise InputError(src, k, f"expected shape {want} for {len(names)} elements, got {arr.shape}")
        for n, x in zip(names, flat):
            out[n] = number(src, k, x)
    return out


def read_gains(scenario: Scenario, gains_path) -> dict:
    """The parameter values a design file (``ftcsim design ... --out FILE``) sets in ``scenario``:
    ``{instance: {structured name: value}}``.

    The file's ``fmu_parameters`` maps FMU model names to structured parameter values; they apply to
    every instance of that model (an ``InputError`` if no instance uses any of them)."""
    src = str(gains_path)
    if not Path(gains_path).exists():
        raise InputError(src, "-", "gains file not found")
    doc = load_json_object(gains_path, "gains file")
    if "fmu_parameters" not in doc:
        close = difflib.get_close_matches("fmu_parameters", list(doc), n=1)
        raise InputError(src, "fmu_parameters", "missing" + (f" (is {close[0]!r} a typo of it?)" if close else
                                                              ": not a gains file of `ftcsim design`"))
    per_model = doc["fmu_parameters"]
    if not isinstance(per_model, dict):
        raise InputError(src, "fmu_parameters", "not an object {model: {parameter: value}}")
    changed = {}
    from orchestrator.scenario.shipped import catalog  # the models ftcsim builds (papers.registry)

    known = list(dict.fromkeys([*(i.model_name for i in scenario.instances.values()), *catalog()]))
    for model, values in per_model.items():
        if model not in known:  # a misspelt model would be ignored, and its gains never applied
            raise InputError(src, f"fmu_parameters.{model}", f"no FMU model {model!r}{hint(model, known)} (the "
                             f"scenario's: {', '.join(dict.fromkeys(i.model_name for i in scenario.instances.values()))})")
        if not isinstance(values, dict):
            raise InputError(src, f"fmu_parameters.{model}", "expected an object {parameter: value}")
        for inst in scenario.instances.values():
            if inst.model_name == model:
                changed.setdefault(inst.name, {}).update(
                    expand_parameters(src, f"fmu_parameters.{model}", inst.interface, values))
    if not changed:
        raise InputError(src, "fmu_parameters", f"no instance in {scenario.path} uses any of the models {list(per_model)}")
    return changed


def parameter_values(scenario: Scenario, parameters: dict, src="api", option="parameters") -> dict:
    """``{"instance.parameter": value}`` (arrays for vector and matrix parameters, structured names
    such as ``"plant.J[1,1]"`` too) as ``{instance: {structured name: value}}``, checked. Errors name
    ``option`` (``parameters`` in the API, ``--set`` on the command line) and the reference."""
    out = {}
    sep = " " if option.startswith("-") else "."
    for ref, value in parameters.items():
        inst, _, name = str(ref).partition(".")
        if inst not in scenario.instances or not name:
            raise InputError(src, f"{option}{sep}{ref}", f"expected 'instance.parameter' with an instance of "
                             f"{', '.join(scenario.instances)}" + hint(inst, scenario.instances))
        i = scenario.instances[inst]
        key = f"{option}{sep}{inst}" if option == "parameters" else f"{option}{sep}{ref}"
        out.setdefault(inst, {}).update(expand_parameters(src, key, i.interface, {name: value}, full_key=option != "parameters"))
    return out


def with_overrides(scenario: Scenario, *, start=None, stop=None, parameters=None, gains=(), src="api",
                   option="parameters") -> Scenario:
    """A new validated scenario: ``scenario`` with another start and stop time (s), the parameter values of the
    design files ``gains`` (in order) and then ``parameters`` (``{"instance.parameter": value}``, or
    ``{instance: {structured name: value}}``). ``scenario`` itself is left as it is. Problems are
    ``InputError(src, key, problem)``."""
    if parameters is not None and not isinstance(parameters, Mapping):
        raise InputError(src, option, f"expected {{'instance.parameter': value}}, got {type(parameters).__name__}")
    if gains is not None and not isinstance(gains, (str, Path, list, tuple)):
        raise InputError(src, "gains", f"expected a design file or a list of them, got {type(gains).__name__}")
    flag = option.startswith("--")
    t0 = scenario.start if start is None else number(src, "--start" if flag else "start", start)
    t1 = scenario.stop if stop is None else number(src, "--stop" if flag else "stop", stop)
    if start is not None or stop is not None:
        try:
            check_timing(src, t0, t1, scenario.step, key="run", blame="stop" if stop is not None else "start")
        except InputError as e:
            if not option.startswith("--"):
                raise
            raise InputError(src, f"--{e.key.rpartition('.')[2]}", e.problem) from None  # the command line's option
    values = {name: dict(inst.parameters) for name, inst in scenario.instances.items()}
    origin = {}  # (instance, base name) -> (source, key) of the value given here: a problem is named there
    for j, g in enumerate([gains] if isinstance(gains, (str, Path)) else gains or ()):
        if not isinstance(g, (str, Path)):
            raise InputError(src, f"gains[{j}]", f"expected a design file (a path), got {type(g).__name__}")
        for inst, p in read_gains(scenario, g).items():
            values[inst].update(p)
            model = scenario.instances[inst].model_name
            origin.update({(inst, n.split("[")[0]): (str(g), f"fmu_parameters.{model}.{n.split('[')[0]}") for n in p})
    parameters = parameters or {}
    if all(isinstance(v, dict) for v in parameters.values()) and set(parameters) <= set(scenario.instances) \
            and parameters:
        per_instance = {inst: dict(p) for inst, p in parameters.items()}
    else:
        per_instance = parameter_values(scenario, parameters, src, option)
    sep = " " if option.startswith("-") else "."
    for inst, p in per_instance.items():
        values[inst].update(p)
        origin.update({(inst, n.split("[")[0]): (src, f"{option}{sep}{inst}.{n.split('[')[0]}") for n in p})
    instances = {name: dataclasses.replace(inst, parameters=values[name]) for name, inst in scenario.instances.items()}
    try:
        return validate(scenario.path, dataclasses.replace(scenario, start=t0, stop=t1, instances=instances))
    except InputError as e:  # a value given here (--set, parameters=, a design file) is named where it was given
        inst, _, base = e.key.removeprefix("instances.").partition(".parameters.")
        if not e.key.startswith("instances."):
            raise
        if (inst, base) not in origin:  # a problem of several parameters (J - delta^T delta): one given here
            base = next((b for i, b in origin if i == inst and re.search(rf"\b{re.escape(b)}\b", e.problem)), base)
        if (inst, base) in origin:
            raise InputError(*origin[(inst, base)], e.problem) from None
        raise
