"""The interface of an instance, from an FMU's modelDescription or an in-process block's declaration:
variables by causality, direct feedthrough, units (with the FMU's own ``UnitDefinitions``) and the
co-simulation capabilities the step policies need."""
from __future__ import annotations

import os
import zipfile
from pathlib import Path

from orchestrator.common.archives import check_members
from orchestrator.common.errors import InputError
from orchestrator.common.reading import MAX_DATA_BYTES, check_regular
from orchestrator.scenario.fmu_checks import fmi_problem, load_problems
from orchestrator.scenario.model import Interface
from plant.units import BASE, canonical


def fmu_unit_definitions(md) -> dict:
    """Unit name -> canonical definition, from an fmpy model description's UnitDefinitions."""
    out = {}
    for u in getattr(md, "unitDefinitions", None) or []:
        b = u.baseUnit
        if b is not None:
            out[u.name] = canonical({k: getattr(b, k, 0) or 0 for k in BASE}
                                    | {"factor": b.factor if b.factor is not None else 1.0,
                                       "offset": b.offset if b.offset is not None else 0.0})
    return out


def variable_unit(v) -> str:
    """An fmpy variable's unit (its own, else its declared type's), ``"1"`` if none."""
    unit = getattr(v, "unit", None) or getattr(getattr(v, "declaredType", None), "unit", None)
    return unit or "1"


def fmu_interface(src, key, path: Path):
    """Read and check an FMU's modelDescription. Returns (Interface, modelDescription)."""
    from fmpy import read_model_description  # fmpy takes 0.3 s to import: not for `ftcsim scenarios`

    if not os.path.lexists(path):
        raise InputError(src, key, f"FMU file not found: {path}")
    check_regular(path, "FMU file", src, key, MAX_DATA_BYTES)  # a FIFO or a device is refused, never opened
    if not zipfile.is_zipfile(path):
        raise InputError(src, key, f"{path} is not an FMU (not a zip archive)")
    names = {i.filename for i in check_members(path, src, key)}  # also: not a zip -> InputError
    if "modelDescription.xml" not in names:
        raise InputError(src, key, f"{path} is not an FMU: no modelDescription.xml")
    version = fmi_problem(path)  # FMI 1.0, no fmiVersion, Model Exchange only: said before fmpy parses it
    if version:
        raise InputError(src, key, f"{path}: {version}")
    try:
        md = read_model_description(str(path), validate=False)
    except Exception as e:
        raise InputError(src, key, f"{path} has no readable modelDescription.xml: {' '.join(str(e).split())[:200]}") from None
    if md.fmiVersion not in ("2.0", "3.0") or md.coSimulation is None:
        raise InputError(src, key, f"{path} is not an FMI 2.0 or 3.0 co-simulation FMU (fmiVersion {md.fmiVersion})")
    problems = load_problems(path, md)
    if problems:
        raise InputError(src, key, f"{path} cannot be loaded: {problems[0]}")
    bad = [v.name for v in md.modelVariables if v.type not in ("Real", "Float64") and v.causality in ("input", "output")]
    if bad:
        raise InputError(src, key, f"{path}: only Real inputs/outputs are supported, not {bad[0]}")
    feed = {}
    for u in md.outputs:
        deps = u.dependencies  # None: depends on every input (FMI)
        if deps is None:
            deps = [v for v in md.modelVariables if v.causality == "input"]
        feed[u.variable.name] = [d.name for d in deps if d.causality == "input"]
    itf = Interface(md.modelName, {v.name: v.causality for v in md.modelVariables}, feed,
                    units={v.name: variable_unit(v) for v in md.modelVariables},
                    unit_definitions=fmu_unit_definitions(md), origin=path.name)
    return itf, md


def fmu_capabilities(md) -> dict:
    """The co-simulation flags the step policies need, from a modelDescription."""
    cs = md.coSimulation
    return {k: bool(getattr(cs, k, False)) for k in ("canGetAndSetFMUstate", "canHandleVariableCommunicationStepSize")}


def block_interface(model_name: str, factory) -> Interface:
    """The interface of the block a fresh ``factory()`` returns (``model_name``'s in-process block)."""
    b = factory()
    c = {v.name: "input" for v in b.inputs}
    c.update({v.name: "output" for v in b.outputs})
    c.update({v.name: "parameter" for v in b.parameters})
    return Interface(model_name, c, {v.name: list(b.feedthrough.get(v.name, ())) for v in b.outputs},
                     units={v.name: v.unit for v in b.inputs + b.outputs + b.parameters}, origin="in-process")
