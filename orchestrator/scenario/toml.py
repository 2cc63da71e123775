"""Scenario files (TOML): reading (with ``extends``) and validation before anything runs.

Every problem raises ``InputError(file, key, problem)``; nothing is created before the
whole scenario has been checked against the FMUs' modelDescriptions (or, in-process,
the blocks' declarations). Format::

    [scenario]   name, description, paper, departures = ["...", ...],
                 extends = "other.toml" or "li2023_fasmc" (optional: start from that file,
                 which must lie in this file's folder or below it, or from a shipped
                 scenario by name; tables merge key by key, any other value replaces the base's)
    [timing]     start, stop, step, exchange = "ordered" | "jacobi",
                 step_policy = "fixed" | "multirate" | "adaptive"   (see "Step policies" below)
                 adaptive only: rtol, atol, min_step, max_step, output_step (s), safety,
                 error_variables = ["a.x", ...];  record_announced = true | false
                 time_limit = 600.0   (optional: s of wall time of the stepping; the run then
                                       stops incomplete, orchestrator/common/watchdog.py)
    [instances.NAME]  fmu = "ModelName" (from the FMU folder) or "path/to/file.fmu"
                      parameter_set = "li2023"          (optional: a paper's set, papers/registry.py)
                      step = 0.01                       (optional, multirate: this instance's
                                                         communication step, a whole multiple of
                                                         timing.step)
                      announces = ["t_next_sample"]     (optional: outputs giving the next instant
                                                         this instance must be stepped to)
    [instances.NAME.parameters]  scalar = 1.0, vector = [..], matrix = [[..], ..]
    connections = [["a.out", "b.in"], ...]              (vectors connect element-wise; names, causality
                                                         and units must match, see below)
    [sources.NAME] type = "piecewise_constant" | "constant", to = "b.in",
                   times = [..], values = [[..], ..]  (or value = [..] for constant)
    [record]     variables = ["a.x", ...]              (default: every output)
    [metrics]    attitude_error = "ctrl.q_e", rate_error = "ctrl.omega_e",
                 control = "ctrl.u", u_max = 5.0, plus the keys of the scenario's paper
                 (``KEYS`` of its metrics module, e.g. papers/p000_li2023/metrics.py)

Any instance can be a third-party FMU (``fmu = "path/to/X.fmu"``, FMI 2.0 or 3.0 co-simulation, Real
variables): interfaces are matched by name, causality and unit when connections and sources are
validated (an FMU's units come from its modelDescription, a block's from its declaration;
``plant/units.py``), and every connection that does not match is listed in one message
that names both ends (a missing variable with the instance's inputs or outputs, an output wired
to an output, N.m against rad/s). An extending file that changes an instance's ``fmu`` replaces
that instance's table as a whole (the base's parameters belong to the base's FMU).

Step policies (``orchestrator/cosim/policies.py``): ``fixed`` (the default) steps everyone with
``step``. ``multirate`` (the default as soon as an instance has its own ``step`` or
``announces``) keeps ``step`` as the base step: an instance with ``step = m * base`` is stepped
every m base steps and holds its inputs and outputs in between; announced instants shorten the
common step of the base-rate instances to land on them (``record_announced``: a row there too).
``adaptive`` chooses the steps by step doubling with rollback: ``step`` is the first step,
``output_step`` (default ``step``) the grid of the rows, on which every step lands;
``min_step`` (default output_step / 1000), ``max_step`` (default output_step), ``rtol``
(default 1e-6), ``atol`` (default 1e-8), ``safety`` (default 0.9) and ``error_variables``
(default: the recorded outputs that depend on no input, the states) steer it; every FMU must
declare canGetAndSetFMUstate and canHandleVariableCommunicationStepSize.

Every table refuses unknown keys (with the closest valid key suggested). Names become file
names and FMU instance names: instance names are identifiers (ASCII letters, digits, '_').
Limits checked before anything runs: at most ``MAX_STEPS`` communication steps and
``MAX_RESULT_BYTES`` of recorded data, ``extends`` at most ``MAX_EXTENDS`` deep.
"""
from __future__ import annotations

import functools
import os
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import parse_toml, read_utf8
from orchestrator.common.reading import check_regular, referenced
from orchestrator.scenario import declared as d
from orchestrator.scenario import shipped
from orchestrator.scenario.checks import STEP_POLICIES, check_timing, read_step_settings, validate
from orchestrator.scenario.interfaces import block_interface, fmu_capabilities, fmu_interface
from orchestrator.scenario.model import INSTANCE_NAME, Instance, Scenario, Source
from orchestrator.scenario.overrides import expand_parameters
from orchestrator.scenario.refs import REF, check_announces, connection, resolve_ref
from orchestrator.scenario.values import short

MAX_EXTENDS = 8
ELSEWHERE = (
    "instances: an FMU model name is built (or has an in-process block), a .fmu file exists and is an FMU; every "
    "parameter is one its FMU declares, of its shape, and within its physical range (a positive definite inertia, "
    "a proper fault model ...); a parameter_set's values apply to the parameters the FMU declares",
    "connections, sources, record, metrics and error_variables name variables of the instances with the right "
    "causality (an output drives an input, once), matching units and element counts; no algebraic loop",
    "timing: (stop - start) / step is a whole number of steps (at most 1e8); an instance's step is a whole multiple "
    "of timing.step; the adaptive keys need step_policy = 'adaptive', whose FMUs can roll back and vary their step; "
    "announces needs the multirate or adaptive policy; min_step <= max_step; the recorded data fit 4 GiB",
    "a source's times increase strictly, its values have one row per time of as many numbers as its target has "
    "elements",
    "metrics: a paper's keys belong to its scenarios (scenario.paper); a window's 'from' is before its 'to'",
    "extends names a file in this file's folder or below it, or a shipped scenario (no cycle, at most 8 deep); "
    "an instance whose fmu the extending file changes takes none of its base's parameters",
)


def _metric_rule(kinds: set) -> d.Rule:
    rules = {"signal": d.Text("a recorded signal 'instance.variable'", what="'instance.variable'"),
             "number": d.Number(), "time": d.Number("s"),
             "window": d.Interval("s, [from, to]", what="a time window [from, to] in s", strict=True)}
    return rules[next(iter(kinds))] if len(kinds) == 1 else d.Either(tuple(rules[k] for k in sorted(kinds)))


@functools.cache
def scenario_format(paper: str | None = None) -> d.Format:
    """The declaration of scenario files (the module docstring): their checks and their JSON Schema. The
    ``[metrics]`` keys are ``paper``'s (None: every paper's, for the schema)."""
    ref = d.Text(pattern=REF.pattern.strip("^$"), what="'instance.variable'",
                 rule_text="is not of the form 'instance.variable'")
    positive = {k: d.Number(f"s, adaptive policy only (default: {default})", positive=True) for k, default in (
        ("min_step", "output_step / 1000"), ("max_step", "output_step"), ("output_step", "step"))}
    timing = d.Table({
        "start": d.Number("s", default=0.0), "stop": d.Number("s"), "step": d.Number("s, the (base) communication step",
                                                                                      positive=True),
        "exchange": d.Choice(("ordered", "jacobi"), default="ordered", description="ordered: outputs passed on in the "
                             "topological order of the connections; jacobi: every output read first, then every input "
                             "set (orchestrator/cosim/plan.py)"),
        "step_policy": d.Choice(STEP_POLICIES, what="policy", description="default: fixed, or multirate as soon as an "
                                "instance has a step or announces instants"),
        "rtol": d.Number("adaptive policy only (default: 1e-6)", positive=True),
        "atol": d.Number("adaptive policy only (default: 1e-8)", lower=0.0), **positive,
        "safety": d.Number("adaptive policy only (default: 0.9)", positive=True, upper=1.0),
        "error_variables": d.ListOf(ref, "adaptive policy only: the outputs whose error the step control watches "
                                    "(default: the recorded states)", min_items=1,
                                    what="a non-empty list of 'instance.output'"),
        "record_announced": d.Flag("a row at every announced instant too"),
        "time_limit": d.Seconds("s of wall time of the stepping; the run then stops incomplete"),
    }, complete=("stop", "step"))
    instance = d.Table({
        "fmu": d.Text("an FMU model name (from the FMU folder) or a .fmu file relative to this file",
                      examples=tuple(shipped.catalog())),
        "parameter_set": d.Choice(tuple(shipped.parameter_sets()), what="set", description="a paper's parameter set"),
        "parameters": d.Table(extra=d.Values(), description="parameter = value: a number, a vector, a matrix ..."),
        "step": d.Number("s, multirate: this instance's communication step, a whole multiple of timing.step",
                         positive=True),
        "announces": d.ListOf(d.Text(), "outputs giving the next instant this instance must be stepped to (s)",
                              what="a list of output names", single=True),
    }, complete=("fmu",))
    source = {"type": d.Choice(("piecewise_constant", "constant"), default="piecewise_constant"),
              "to": d.Text("the input driven ('instance.input')", what="'instance.variable'")}
    keys = shipped.metric_keys(paper) if paper is not None else \
        {k: v for p in shipped.papers() for k, v in shipped.metric_keys(p.id).items()}
    kinds = {}
    for p in ([paper] if paper is not None else [p.id for p in shipped.papers()]):
        for k, v in shipped.metric_keys(p).items():
            kinds.setdefault(k, set()).add(v)
    root = d.Table({
        "scenario": d.Table({
            "name": d.Name("names the run folder (default: the file's stem)"),
            "description": d.Text(empty=True), "paper": d.Text("the paper's id (000 ...)", empty=True),
            "departures": d.ListOf(d.Text(empty=True), "where the scenario departs from the paper",
                                   what="a list of strings"),
            "extends": d.Text("a scenario file in this file's folder (or below) or a shipped scenario name: tables "
                              "merge key by key, other values replace the base's")}),
        "timing": timing,
        "instances": d.Table(extra=instance, names=d.Text(pattern=INSTANCE_NAME.pattern.strip("^$"), rule_text=(
            "is not an instance name: an identifier (ASCII letters, digits, '_', not starting with a digit, at most 64 "
            "characters)")), min_items=1, empty="no instances defined"),
        "connections": d.ListOf(d.ListOf(ref, what='["from.output", "to.input"]', min_items=2, max_items=2, index=False),
                                "vectors connect element-wise", what='a list of ["from.output", "to.input"] pairs'),
        "sources": d.Table(extra=d.Union("type", {
            "piecewise_constant": d.Table({**source, "times": d.ListOf(d.Number(), "s", min_items=1, index=False,
                                                                       what="a non-empty list of times"),
                                           "values": d.ListOf(d.Values(depth=1), "one row per time")},
                                          required=("to", "times", "values")),
            "constant": d.Table({**source, "value": d.Values(depth=1)}, required=("to", "value"))},
            what="source type", default_variant="piecewise_constant")),
        "record": d.Table({"variables": d.ListOf(ref, "default: every output", what="a list of 'instance.variable'")}),
        "metrics": d.Table({k: _metric_rule(kinds[k]) for k in keys},
                           description="the run's metric signals and settings, plus the keys of the scenario's paper "
                                       "(KEYS of its metrics module)"),
    }, complete=("timing", "instances"))
    return d.Format("scenario", "ftcsim scenario file", root, "A scenario: FMUs (or blocks), their wiring, sources, "
                    "timing and metrics (`ftcsim run`, README.md).", extends=("scenario", "extends"), elsewhere=ELSEWHERE)


def merge_tables(base: dict, over: dict) -> dict:
    """``over`` on ``base``, table by table (deep); any other value of ``over`` (numbers, strings,
    arrays, arrays of tables) replaces the base's. What ``extends`` does in scenario and campaign files."""
    out = dict(base)
    for k, v in over.items():
        out[k] = merge_tables(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def _without_replaced_instances(base: dict, over: dict) -> dict:
    """``base`` with the tables of the instances whose ``fmu`` ``over`` changes emptied (in place
    in the order), so that ``over``'s table replaces them: a base's parameters and parameter set
    belong to the base's FMU."""
    b, o = base.get("instances"), over.get("instances")
    if not (isinstance(b, dict) and isinstance(o, dict)):
        return base
    instances = {name: ({} if isinstance(o.get(name), dict) and "fmu" in o[name] and isinstance(table, dict)
                        and o[name]["fmu"] != table.get("fmu") else table) for name, table in b.items()}
    return {**base, "instances": instances}


def read_document(path: Path, _seen=()) -> dict:
    """Parse a scenario file, resolving ``[scenario] extends``: a file in this file's folder (or
    below it), or a shipped scenario by name. Depth at most ``MAX_EXTENDS``, no cycles."""
    src = str(path)
    doc = parse_toml(src, read_utf8(path, "scenario file"))
    meta = doc.get("scenario", {})
    base = meta.get("extends") if isinstance(meta, dict) else None
    if base is None:
        return doc
    if not isinstance(base, str) or not base:
        raise InputError(src, "scenario.extends", f"expected a file name or a shipped scenario name, got {short(base)}")
    if len(_seen) >= MAX_EXTENDS:
        raise InputError(src, "scenario.extends", f"extends chain deeper than {MAX_EXTENDS}")
    if not base.endswith(".toml") and "/" not in base:
        files = shipped.scenario_files()
        if base not in files:
            raise InputError(src, "scenario.extends", f"no shipped scenario {base!r} (`ftcsim scenarios` lists them)")
        base_path = files[base].resolve()
    else:  # in this file's folder, also once symbolic links are followed; NUL bytes refused
        base_path = referenced(path.parent, base, src, "scenario.extends", "base scenario", whose="scenario's")
    here = Path(os.path.realpath(path))
    if base_path in _seen or base_path == here:
        raise InputError(src, "scenario.extends", f"circular extends through {base}")
    check_regular(base_path, "base scenario", src, "scenario.extends")
    merged = merge_tables(_without_replaced_instances(read_document(base_path, _seen + (here,)), doc), doc)
    merged["scenario"].pop("extends", None)
    return merged


def describe(path: Path) -> tuple[str, str]:
    """(paper, description) of a scenario file without validating it (for ``ftcsim scenarios``)."""
    try:
        meta = read_document(path).get("scenario", {})
    except InputError as e:
        return "?", f"(unreadable: {e.problem})"
    return str(meta.get("paper", "")), str(meta.get("description", ""))


def load(path, fmu_dir=None, in_process=False, step=None) -> Scenario:
    """Load and validate a scenario file. ``in_process``: resolve instances to blocks;
    ``step``: override the communication step of [timing]."""
    path = Path(path)
    src = str(path)
    doc = read_document(path)
    if step is not None:
        doc.setdefault("timing", {})["step"] = step
    meta = doc.get("scenario", {})
    paper = meta.get("paper") if isinstance(meta, dict) and isinstance(meta.get("paper"), str) else ""
    given, doc = doc, scenario_format(paper).check(src, doc)  # every key, type and range; below, what needs the FMUs
    fmu_dir = shipped.fmu_folder(fmu_dir)
    meta, timing = doc.get("scenario", {}), doc["timing"]
    start, stop, step = timing["start"], timing["stop"], timing["step"]
    check_timing(src, start, stop, step)

    instances = {}
    for name, spec in doc["instances"].items():
        key = f"instances.{name}"
        fmu = spec["fmu"]
        fmu_path = (path.parent / fmu).resolve() if fmu.endswith(".fmu") else fmu_dir / f"{fmu}.fmu"
        if in_process:
            model = fmu if not fmu.endswith(".fmu") else None
            if model is None and fmu_path.is_file():
                model = fmu_interface(src, f"{key}.fmu", fmu_path)[0].model_name
            factory = shipped.block_factory(model, src, f"{key}.fmu", fmu)
            itf, fmu_path, caps, md = block_interface(model, factory), None, {}, None
        else:
            if not fmu.endswith(".fmu") and not fmu_path.is_file():
                raise InputError(src, f"{key}.fmu", f"FMU file not found: {fmu_path} (run `ftcsim build` first)")
            itf, md = fmu_interface(src, f"{key}.fmu", fmu_path)
            caps, factory = fmu_capabilities(md), None
        params = {}
        if "parameter_set" in spec:
            params.update({k: v for k, v in shipped.structured_parameter_set(spec["parameter_set"]).items()
                           if k in itf.causality})
        params.update(expand_parameters(src, f"{key}.parameters", itf, spec.get("parameters", {})))
        announces = check_announces(src, f"{key}.announces", spec.get("announces", []), itf)
        instances[name] = Instance(name, fmu_path, itf.model_name, itf, params, spec.get("step"), announces, caps, md,
                                   factory)

    # connections
    connections, driven, unmatched = [], {}, []
    for k, pair in enumerate(doc.get("connections", [])):
        key = f"connections[{k}]"
        s_inst, s_names, d_inst, d_names, problems = connection(src, key, pair, instances)
        if problems:
            twice = [f"{d_inst}.{dn} is already driven by {driven[(d_inst, dn)]}" for dn in d_names if (d_inst, dn) in driven]
            unmatched.append((k, f"{pair[0]} -> {pair[1]}: {'; '.join(problems + twice[:1])}"))
            continue
        for sn, dn in zip(s_names, d_names):
            if (d_inst, dn) in driven:
                raise InputError(src, key, f"{d_inst}.{dn} is already driven by {driven[(d_inst, dn)]}")
            driven[(d_inst, dn)] = key
            connections.append((s_inst, sn, d_inst, dn))
    if len(unmatched) == 1:
        raise InputError(src, f"connections[{unmatched[0][0]}]", unmatched[0][1])
    if unmatched:
        raise InputError(src, "connections", f"{len(unmatched)} connections do not match: "
                         + " | ".join(f"[{k}] {text}" for k, text in unmatched))

    # sources
    sources = []
    for name, spec in doc.get("sources", {}).items():
        key = f"sources.{name}"
        kind = spec["type"]
        d_inst, d_names = resolve_ref(src, f"{key}.to", spec["to"], instances, "input")
        if kind == "constant":
            times, values = [start], [spec["value"]]
        else:
            times, values = spec["times"], spec["values"]
            if any(b <= a for a, b in zip(times, times[1:])):
                raise InputError(src, f"{key}.times", "times must be strictly increasing")
            if len(values) != len(times):
                raise InputError(src, f"{key}.values", f"expected {len(times)} values, one per time")
        rows = []
        for j, v in enumerate(values):
            vk = f"{key}.values[{j}]" if kind != "constant" else f"{key}.value"
            v = v if isinstance(v, list) else [v]
            if len(v) != len(d_names):
                raise InputError(src, vk, f"expected {len(d_names)} numbers for {spec['to']}, got {len(v)}")
            rows.append([float(x) for x in v])
        for dn in d_names:
            if (d_inst, dn) in driven:
                raise InputError(src, f"{key}.to", f"{d_inst}.{dn} is already driven by {driven[(d_inst, dn)]}")
            driven[(d_inst, dn)] = key
        sources.append(Source(name, kind, times, np.array(rows), [(d_inst, dn) for dn in d_names]))

    # record
    record = []
    if "variables" in doc.get("record", {}):
        for j, ref in enumerate(doc["record"]["variables"]):
            inst, names = resolve_ref(src, f"record.variables[{j}]", ref, instances)
            for nm in names:
                c = instances[inst].interface.causality[nm]
                if c == "input" and (inst, nm) not in driven:
                    raise InputError(src, f"record.variables[{j}]", f"input {inst}.{nm} is not driven by anything")
                if c not in ("input", "output"):
                    raise InputError(src, f"record.variables[{j}]", f"{inst}.{nm} is a {c}; only inputs and outputs are recorded")
                record.append((inst, nm))
    else:
        for inst in instances.values():
            record += [(inst.name, nm) for nm in inst.interface.names("output")]

    known = shipped.metric_keys(paper)  # a "number" as written (it is hashed into the run keys), times as floats
    metrics = {k: given["metrics"][k] if known[k] == "number" else v for k, v in doc.get("metrics", {}).items()}
    for k, v in metrics.items():
        if known[k] == "signal":
            inst, names = resolve_ref(src, f"metrics.{k}", v, instances)
            record += [(inst, nm) for nm in names]
    record = list(dict.fromkeys(record))
    settings = read_step_settings(src, timing, instances)

    sc = Scenario(
        path=path,
        name=meta.get("name", path.stem),
        description=meta.get("description", ""),
        paper=paper,
        departures=meta.get("departures", []),
        start=start,
        stop=stop,
        step=step,
        exchange=timing["exchange"],
        instances=instances,
        connections=connections,
        sources=sources,
        record=record,
        metrics=metrics,
        timing=settings,
        time_limit=timing.get("time_limit"),
    )
    return validate(src, sc)


