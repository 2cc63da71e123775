"""Parameter values over a loaded scenario: structured expansion of scalars, vectors and matrices, and the
gains files of ``ftcsim design``."""
from __future__ import annotations

import difflib
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import load_json_object
from orchestrator.scenario.model import Interface, Scenario
from orchestrator.scenario.refs import expand, shape_of
from orchestrator.scenario.values import number, short


def expand_parameters(src, key, itf: Interface, values: dict) -> dict:
    """{'J': [[..]], 'k_p': 20} -> {'J[1,1]': .., 'k_p': 20.0}, checked against ``itf``."""
    out = {}
    for name, value in values.items():
        k = f"{key}.{name}"
        names = expand(itf, name)
        if not names:
            raise InputError(src, k, f"{itf.model_name} has no parameter '{name}'")
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


def apply_gains(scenario: Scenario, gains_path) -> list[str]:
    """Override parameters from a design file (``ftcsim design ... --out FILE``).

    The file's ``fmu_parameters`` maps FMU model names to structured parameter values;
    they apply to every instance of that model. Returns the instances changed."""
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
    changed = []
    for model, values in per_model.items():
        if not isinstance(values, dict):
            raise InputError(src, f"fmu_parameters.{model}", "expected an object {parameter: value}")
        for inst in scenario.instances.values():
            if inst.model_name == model:
                inst.parameters.update(expand_parameters(src, f"fmu_parameters.{model}", inst.interface, values))
                changed.append(inst.name)
    if not changed:
        raise InputError(src, "fmu_parameters", f"no instance in {scenario.path} uses any of the models {list(per_model)}")
    return changed
