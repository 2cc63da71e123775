"""``ftcsim params SCENARIO``: every instance's parameters with the value a run uses, the unit and the
description (from the FMU's modelDescription, or the block's declaration in-process), and the
``--set`` options that parse them (:func:`set_options`)."""
from __future__ import annotations

import json
import tomllib

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import strict_json
from orchestrator.common.reading import depth_of
from orchestrator.scenario.loading import load_scenario
from orchestrator.scenario.overrides import nominal_values
from orchestrator.scenario.values import hint
from plant.block import split_name

MAX_SET_DEPTH = 4  # a --set VALUE: a number, a vector, a matrix, a stack of matrices


def set_options(items) -> dict:
    """``["plant.fault_scale=0.5", "plant.J=[[1,0,0],[0,2,0],[0,0,3]]"]`` -> ``{"plant.fault_scale": 0.5,
    ...}``; each VALUE is a TOML literal (a number, an array, an array of arrays). Errors name ``--set``
    and the key."""
    out = {}
    for item in items or ():
        ref, eq, text = str(item).partition("=")
        ref = ref.strip()
        if not eq or "." not in ref or not text.strip():
            raise InputError("command line", f"--set {item}", "expected INSTANCE.PARAMETER=VALUE (e.g. "
                             "plant.fault_scale=0.5, plant.J=[[1,0,0],[0,2,0],[0,0,3]])")
        text = text.strip()
        if not text.isprintable():  # a line break would start a second TOML statement, silently dropped
            raise InputError("command line", f"--set {ref}", f"{text!r}: VALUE must be one line of printable text "
                             "(a TOML number or array)")
        try:
            doc = tomllib.loads(f"v = {text}")
        except tomllib.TOMLDecodeError as e:
            why = " ".join(str(e).split()).split(" (at line")[0]
            raise InputError("command line", f"--set {ref}", f"{text!r} is not a TOML number or array "
                             f"({why})") from None
        except RecursionError:  # tomllib recurses per nesting level
            doc = None
        if doc is None or depth_of(doc["v"]) > MAX_SET_DEPTH:
            raise InputError("command line", f"--set {ref}", f"arrays nested more than {MAX_SET_DEPTH} deep (a "
                             "parameter is a number, a vector or a matrix)")
        if set(doc) != {"v"}:
            raise InputError("command line", f"--set {ref}", f"{text!r} holds more than one value")
        value = doc["v"]
        if ref in out:
            raise InputError("command line", f"--set {ref}", "given twice")
        out[ref] = value
    return out


def descriptions(inst) -> dict:
    """Parameter name -> description of an instance (FMU modelDescription or block declaration)."""
    if inst.model_description is not None:
        return {v.name: v.description or "" for v in inst.model_description.modelVariables
                if v.causality == "parameter"}
    return {v.name: v.description for v in inst.factory().parameters}


def rows(scenario) -> list[dict]:
    """One row per parameter (vectors and matrices grouped under their base name): instance,
    parameter, value (a number or nested lists), unit, description."""
    out = []
    for name, inst in scenario.instances.items():
        values = nominal_values(inst)
        desc = descriptions(inst)
        groups = {}
        for p in inst.interface.names("parameter"):
            groups.setdefault(split_name(p)[0], []).append(p)
        for base, names in groups.items():
            if names == [base]:
                value = values.get(base)
            else:
                idx = np.array([split_name(n)[1] for n in names])
                shape = tuple(idx.max(axis=0) - idx.min(axis=0) + 1)
                arr = np.full(shape, np.nan)
                for n, ix in zip(names, idx):
                    arr[tuple(ix - idx.min(axis=0))] = values.get(n, np.nan)
                value = arr.tolist()
            out.append({"instance": name, "parameter": base, "value": value,
                        "unit": inst.interface.units.get(names[0], "1"), "description": desc.get(names[0], "")})
    return out


def _literal(value) -> str:
    """A value as the TOML literal ``--set`` takes."""
    if value is None:
        return "-"
    if isinstance(value, list):
        return "[" + ", ".join(_literal(v) for v in value) + "]"
    return "nan" if value != value else f"{value:.10g}"


def cmd_params(args) -> int:
    sc = load_scenario(args.scenario, mode=args.mode, fmu_dir=args.fmu_dir, gains=args.gains or (),
                       parameters=set_options(args.set), src="command line", option="--set")
    table = rows(sc)
    if args.instance:
        known = list(sc.instances)
        if args.instance not in known:
            raise InputError("command line", "--instance", f"no instance {args.instance!r} in {sc.name}"
                             f"{hint(args.instance, known)} (instances: {', '.join(known)})")
        table = [r for r in table if r["instance"] == args.instance]
    if args.json:
        # strict JSON: a missing element (NaN) of a sparse matrix is null; text is never rewritten
        print(json.dumps(strict_json(table), indent=1, allow_nan=False, default=str))
        return 0
    width = max((len(f"{r['instance']}.{r['parameter']}") for r in table), default=10)
    for r in table:
        value = _literal(r["value"])
        print(f"{r['instance'] + '.' + r['parameter']:{width}s}  {value:24s} {r['unit']:8s} {r['description']}")
    return 0


def register(sub) -> None:
    p = sub.add_parser("params", help="list a scenario's parameters: every instance's, with value, unit and "
                                      "description (the names `ftcsim run --set` takes)")
    p.add_argument("scenario", help="shipped scenario name, scenario file (.toml) or SSP package (.ssp)")
    p.add_argument("--instance", help="only this instance's parameters")
    p.add_argument("--mode", choices=["fmu", "inprocess"], default="fmu",
                   help="read the FMUs' modelDescriptions (default) or the in-process blocks' declarations")
    p.add_argument("--fmu-dir", help="folder of built FMUs (default build/fmus)")
    p.add_argument("--gains", action="append", help="design file (JSON) whose values to show; repeatable")
    p.add_argument("--set", action="append", metavar="INSTANCE.PARAM=VALUE",
                   help="show the values with this override (as `ftcsim run --set`); repeatable")
    p.add_argument("--json", action="store_true", help="a JSON list of rows instead of the table")
    p.set_defaults(func=cmd_params)
