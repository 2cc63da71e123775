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

import os
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import parse_toml, read_utf8
from orchestrator.common.outputs import safe_name
from orchestrator.common.reading import check_regular, referenced
from orchestrator.scenario import shipped
from orchestrator.scenario.checks import STEP_POLICIES, check_timing, read_step_settings, validate
from orchestrator.scenario.interfaces import block_interface, fmu_capabilities, fmu_interface
from orchestrator.scenario.model import INSTANCE_NAME, Instance, Scenario, Source
from orchestrator.scenario.overrides import expand_parameters
from orchestrator.scenario.refs import check_announces, connection, resolve_ref
from orchestrator.scenario.values import check_keys, number, seconds, short, string, table, unknown_key

TOP_KEYS = ("scenario", "timing", "instances", "connections", "sources", "record", "metrics")
SCENARIO_KEYS = ("name", "description", "paper", "departures", "extends")
TIMING_KEYS = ("start", "stop", "step", "exchange", "step_policy", "rtol", "atol", "min_step", "max_step",
               "output_step", "safety", "error_variables", "record_announced", "time_limit")
INSTANCE_KEYS = ("fmu", "parameters", "parameter_set", "step", "announces")
MAX_EXTENDS = 8


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
    for k in doc:
        if k not in TOP_KEYS:
            raise unknown_key(src, "", k, TOP_KEYS)
    fmu_dir = shipped.fmu_folder(fmu_dir)

    meta = table(src, "scenario", doc.get("scenario", {}))
    check_keys(src, "scenario", meta, SCENARIO_KEYS)
    departures = meta.get("departures", [])
    if not isinstance(departures, list) or not all(isinstance(d, str) for d in departures):
        raise InputError(src, "scenario.departures", "expected a list of strings")
    for k in ("description", "paper"):
        if k in meta and not isinstance(meta[k], str):
            raise InputError(src, f"scenario.{k}", f"expected a string, got {short(meta[k])}")
    scenario_name = meta.get("name", path.stem)
    safe_name(scenario_name, src, "scenario.name")  # it becomes a folder name under results/

    timing = table(src, "timing", doc.get("timing"))
    check_keys(src, "timing", timing, TIMING_KEYS)
    for k in ("stop", "step"):
        if k not in timing:
            raise InputError(src, f"timing.{k}", "missing")
    start = number(src, "timing.start", timing.get("start", 0.0))
    stop = number(src, "timing.stop", timing["stop"])
    step = number(src, "timing.step", timing["step"], positive=True)
    check_timing(src, start, stop, step)
    exchange = timing.get("exchange", "ordered")
    if exchange not in ("ordered", "jacobi"):
        raise InputError(src, "timing.exchange", f"must be 'ordered' or 'jacobi', not {short(exchange)}")
    if "step_policy" in timing and timing["step_policy"] not in STEP_POLICIES:
        read_step_settings(src, {"step_policy": timing["step_policy"]}, {})  # the message, before the instances
    time_limit = seconds(src, "timing.time_limit", timing["time_limit"]) if "time_limit" in timing \
        else None  # s of wall time (orchestrator/common/watchdog.py)

    inst_doc = table(src, "instances", doc.get("instances"))
    if not inst_doc:
        raise InputError(src, "instances", "no instances defined")
    instances = {}
    for name, spec in inst_doc.items():
        key = f"instances.{name}"
        if not INSTANCE_NAME.match(name):
            raise InputError(src, key, f"instance name {short(name)} must be an identifier (ASCII letters, digits, "
                                       "'_', not starting with a digit, at most 64 characters)")
        spec = table(src, key, spec)
        check_keys(src, key, spec, INSTANCE_KEYS)
        fmu = string(src, f"{key}.fmu", spec.get("fmu"))
        if fmu.endswith(".fmu"):
            fmu_path = (path.parent / fmu).resolve()
        else:
            fmu_path = fmu_dir / f"{fmu}.fmu"
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
            sets = shipped.parameter_sets()
            ps = spec["parameter_set"]
            if not isinstance(ps, str) or ps not in sets:
                raise InputError(src, f"{key}.parameter_set", f"unknown set {short(ps)} (known: {', '.join(sets)})")
            params.update({k: v for k, v in shipped.structured_parameter_set(ps).items() if k in itf.causality})
        params.update(expand_parameters(src, f"{key}.parameters", itf, table(src, f"{key}.parameters", spec.get("parameters", {}))))
        own_step = number(src, f"{key}.step", spec["step"], positive=True) if "step" in spec else None
        announces = check_announces(src, f"{key}.announces", spec.get("announces", []), itf)
        instances[name] = Instance(name, fmu_path, itf.model_name, itf, params, own_step, announces, caps, md, factory)

    # connections
    conns_doc = doc.get("connections", [])
    if not isinstance(conns_doc, list):
        raise InputError(src, "connections", "expected a list of [\"from.output\", \"to.input\"] pairs")
    connections, driven, unmatched = [], {}, []
    for k, pair in enumerate(conns_doc):
        key = f"connections[{k}]"
        if not (isinstance(pair, list) and len(pair) == 2):
            raise InputError(src, key, f"expected [\"from.output\", \"to.input\"], got {pair!r}")
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
    for name, spec in table(src, "sources", doc.get("sources", {})).items():
        key = f"sources.{name}"
        spec = table(src, key, spec)
        kind = spec.get("type", "piecewise_constant")
        if kind not in ("piecewise_constant", "constant"):
            raise InputError(src, f"{key}.type", f"unknown source type {short(kind)} (known: piecewise_constant, constant)")
        check_keys(src, key, spec, ("type", "to", "value") if kind == "constant" else ("type", "to", "times", "values"))
        d_inst, d_names = resolve_ref(src, f"{key}.to", spec.get("to"), instances, "input")
        if kind == "constant":
            times, values = [start], [spec.get("value")]
        else:
            times, values = spec.get("times"), spec.get("values")
            if not isinstance(times, list) or not times:
                raise InputError(src, f"{key}.times", "expected a non-empty list of times")
            times = [number(src, f"{key}.times", t) for t in times]
            if any(b <= a for a, b in zip(times, times[1:])):
                raise InputError(src, f"{key}.times", "times must be strictly increasing")
            if not isinstance(values, list) or len(values) != len(times):
                raise InputError(src, f"{key}.values", f"expected {len(times)} values, one per time")
        rows = []
        for j, v in enumerate(values):
            vk = f"{key}.values[{j}]" if kind != "constant" else f"{key}.value"
            v = v if isinstance(v, list) else [v]
            if len(v) != len(d_names):
                raise InputError(src, vk, f"expected {len(d_names)} numbers for {spec.get('to')}, got {len(v)}")
            rows.append([number(src, vk, x) for x in v])
        for dn in d_names:
            if (d_inst, dn) in driven:
                raise InputError(src, f"{key}.to", f"{d_inst}.{dn} is already driven by {driven[(d_inst, dn)]}")
            driven[(d_inst, dn)] = key
        sources.append(Source(name, kind, times, np.array(rows), [(d_inst, dn) for dn in d_names]))

    # record
    rec_doc = table(src, "record", doc.get("record", {}))
    check_keys(src, "record", rec_doc, ("variables",))
    record = []
    if "variables" in rec_doc:
        if not isinstance(rec_doc["variables"], list):
            raise InputError(src, "record.variables", "expected a list of 'instance.variable'")
        for j, ref in enumerate(rec_doc["variables"]):
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

    metrics = table(src, "metrics", doc.get("metrics", {}))
    paper_id = str(meta.get("paper", ""))
    known = shipped.metric_keys(paper_id)
    for k, v in metrics.items():
        key = f"metrics.{k}"
        kind = known.get(k)
        if kind is None:
            raise unknown_key(src, "metrics", k, list(known))
        if kind == "signal":
            inst, names = resolve_ref(src, key, v, instances)
            for nm in names:
                if (inst, nm) not in record:
                    record.append((inst, nm))
        elif kind == "number":
            number(src, key, v)
        elif kind == "time":
            metrics[k] = number(src, key, v)
        elif kind == "window":
            if not (isinstance(v, list) and len(v) == 2):
                raise InputError(src, key, f"expected a time window [from, to] in s, got {short(v)}")
            a, b = (number(src, key, x) for x in v)
            if not a < b:
                raise InputError(src, key, f"window [{a:g}, {b:g}]: 'from' must be before 'to'")
            metrics[k] = [a, b]
    record = list(dict.fromkeys(record))
    settings = read_step_settings(src, timing, instances)

    sc = Scenario(
        path=path,
        name=scenario_name,
        description=str(meta.get("description", "")),
        paper=paper_id,
        departures=departures,
        start=start,
        stop=stop,
        step=step,
        exchange=exchange,
        instances=instances,
        connections=connections,
        sources=sources,
        record=record,
        metrics=metrics,
        timing=settings,
        time_limit=time_limit,
    )
    return validate(src, sc)


