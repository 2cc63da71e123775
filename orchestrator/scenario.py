"""Scenario files (TOML): loading and validation before anything runs.

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

Step policies (``orchestrator/policies.py``): ``fixed`` (the default) steps everyone with
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

import math
import os
import re
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from plant.block import split_name
from plant.units import BASE, canonical

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_FMU_DIR = ROOT / "build" / "fmus"
TOP_KEYS = ("scenario", "timing", "instances", "connections", "sources", "record", "metrics")
SCENARIO_KEYS = ("name", "description", "paper", "departures", "extends")
TIMING_KEYS = ("start", "stop", "step", "exchange", "step_policy", "rtol", "atol", "min_step", "max_step",
               "output_step", "safety", "error_variables", "record_announced")
ADAPTIVE_KEYS = ("rtol", "atol", "min_step", "max_step", "output_step", "safety", "error_variables")
STEP_POLICIES = ("fixed", "multirate", "adaptive")
INSTANCE_KEYS = ("fmu", "parameters", "parameter_set", "step", "announces")
METRIC_KEYS = {"attitude_error": "signal", "rate_error": "signal", "control": "signal", "u_max": "number"}
MAX_STEPS = 100_000_000
MAX_RESULT_BYTES = 4 * 2**30
MAX_EXTENDS = 8
INSTANCE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,63}$")
_REF = re.compile(r"^(?P<inst>[A-Za-z_][A-Za-z0-9_]*)\.(?P<var>.+)$")


@dataclass
class Interface:
    """What validation needs to know about a component: its variables by causality."""

    model_name: str
    causality: dict  # name -> 'input' | 'output' | 'parameter' | ...
    feedthrough: dict = field(default_factory=dict)  # output -> inputs it depends on directly
    units: dict = field(default_factory=dict)  # name -> unit string ("1" if none)
    unit_definitions: dict = field(default_factory=dict)  # unit -> canonical definition (plant/units.py)
    origin: str = ""  # the FMU file name, or "in-process"

    def names(self, causality):
        return [n for n, c in self.causality.items() if c == causality]


@dataclass
class Instance:
    name: str
    fmu: Path | None  # None: in-process only
    model_name: str
    interface: Interface
    parameters: dict = field(default_factory=dict)  # structured scalar name -> float
    step: float | None = None  # own communication step (multirate), s; None: the base step
    announces: list = field(default_factory=list)  # outputs giving the next instant to step to
    capabilities: dict = field(default_factory=dict)  # FMU flags (canGetAndSetFMUstate, ...); {}: in-process


@dataclass
class StepSettings:
    """``[timing]``'s step policy and its settings (module docstring). ``policy`` None: not
    given, resolved by :func:`check_step_policy`. Times in s."""

    policy: str | None = None
    rtol: float | None = None
    atol: float | None = None
    min_step: float | None = None
    max_step: float | None = None
    output_step: float | None = None
    safety: float | None = None
    error_variables: list = field(default_factory=list)  # [(inst, var)]; empty: the default
    record_announced: bool = False
    given: tuple = ()  # the [timing] keys the file set (for the messages)


@dataclass
class Source:
    name: str
    kind: str
    times: list
    values: np.ndarray
    targets: list  # [(inst, var)]


@dataclass
class Scenario:
    path: Path
    name: str
    description: str
    paper: str
    departures: list
    start: float
    stop: float
    step: float
    exchange: str
    instances: dict
    connections: list  # (src_inst, src_var, dst_inst, dst_var)
    sources: list
    record: list  # (inst, var)
    metrics: dict
    timing: StepSettings = field(default_factory=StepSettings)

    @property
    def n_steps(self) -> int:
        """Base steps (fixed and multirate: the communication steps)."""
        return int(round((self.stop - self.start) / self.step))

    @property
    def output_step(self) -> float:
        """The step of the recorded grid: ``output_step`` of an adaptive run, else ``step``."""
        return self.timing.output_step or self.step

    @property
    def step_policy(self) -> str:
        return self.timing.policy or "fixed"


# -- helpers -----------------------------------------------------------------------------------
def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def unknown_key(src, key, name, known) -> InputError:
    """The error for an unknown key ``name`` of table ``key``, with the closest known one."""
    import difflib

    close = difflib.get_close_matches(str(name), [str(k) for k in known], n=1)
    where = f"{key}.{name}" if key else str(name)
    hint = f"did you mean {close[0]!r}? " if close else ""
    what = "key" if key else "section"
    return InputError(src, where, f"unknown {what} ({hint}known: {', '.join(map(str, known))})")


def check_keys(src, key, table: dict, known) -> None:
    for k in table:
        if k not in known:
            raise unknown_key(src, key, k, known)


def _number(src, key, x, positive=False) -> float:
    if not _is_number(x):
        raise InputError(src, key, f"expected a number, got {type(x).__name__} {_short(x)}")
    try:
        x = float(x)
    except OverflowError:
        raise InputError(src, key, "number too large") from None
    if not math.isfinite(x):
        raise InputError(src, key, f"must be finite, got {x}")
    if positive and x <= 0:
        raise InputError(src, key, f"must be > 0, got {x:g}")
    return x


def _short(x, n=60) -> str:
    r = repr(x)
    return r if len(r) <= n else r[: n - 3] + "..."


def _table(src, key, x) -> dict:
    if x is None:
        raise InputError(src, key, "missing")
    if not isinstance(x, dict):
        raise InputError(src, key, f"expected a table, got {type(x).__name__}")
    return x


def _string(src, key, x) -> str:
    if not isinstance(x, str) or not x:
        raise InputError(src, key, f"expected a non-empty string, got {_short(x)}")
    return x


def expand(interface: Interface, name: str, causality=None) -> list[str]:
    """Scalar names behind ``name``: itself if scalar, ``name[...]`` elements in index
    order if it is a vector/matrix base name. Empty list if unknown."""
    if name in interface.causality:
        names = [name]
    else:
        items = [(split_name(n)[1], n) for n in interface.causality if split_name(n)[0] == name and "[" in n]
        names = [n for _, n in sorted(items)]
    if causality is not None:
        names = [n for n in names if interface.causality[n] == causality]
    return names


def _shape_of(names) -> tuple:
    idx = np.array([split_name(n)[1] for n in names])
    if idx.size == 0 or idx.ndim == 1:
        return ()
    return tuple(int(x) for x in (idx.max(axis=0) - idx.min(axis=0) + 1))


def _a(word: str) -> str:
    return f"{'an' if word[:1] in 'aeiou' else 'a'} {word}"


def summary(names, limit=12) -> str:
    """``q[0], q[1], .., omega[1..3]`` -> ``'q[0..3], omega[1..3]'`` (structured names grouped by base)."""
    groups = {}
    for n in names:
        base, idx = split_name(n)
        groups.setdefault(base, []).append(idx)
    parts = []
    for base, idx in groups.items():
        if idx == [()]:
            parts.append(base)
        elif all(len(i) == 1 for i in idx):
            lo, hi = min(i[0] for i in idx), max(i[0] for i in idx)
            parts.append(f"{base}[{lo}..{hi}]" if len(idx) == hi - lo + 1 else f"{base}[{len(idx)} elements]")
        else:  # a matrix or tensor: its shape
            shape = (max(i[d] for i in idx) - min(i[d] for i in idx) + 1 for d in range(len(idx[0])))
            parts.append(f"{base}[{'x'.join(map(str, shape))}]")
    more = f" and {len(parts) - limit} more" if len(parts) > limit else ""
    return ", ".join(parts[:limit]) + more if parts else "none"


def _instance_label(inst, itf) -> str:
    return f"instance '{inst}' ({itf.model_name}{', ' + itf.origin if itf.origin else ''})"


def _reference(src, key, ref, instances):
    """'inst.var' -> (inst, var) or InputError for a malformed reference or an unknown instance."""
    if not isinstance(ref, str):
        raise InputError(src, key, f"expected 'instance.variable', got {_short(ref)}")
    m = _REF.match(ref)
    if not m:
        raise InputError(src, key, f"{_short(ref)} is not of the form 'instance.variable'")
    if m["inst"] not in instances:
        raise InputError(src, key, f"unknown instance '{m['inst']}' (instances: {', '.join(instances)})")
    return m["inst"], m["var"]


def _end_problem(inst, var, itf, names, causality) -> str | None:
    """Why ``inst.var`` (scalar ``names``) cannot be used as ``causality``, or None."""
    if not names:
        hint = f"its {causality}s" if causality else "its inputs and outputs"
        pool = itf.names(causality) if causality else itf.names("input") + itf.names("output")
        return f"{_instance_label(inst, itf)} has no variable {_short(var)} ({hint}: {summary(pool)})"
    if causality is not None:
        bad = [n for n in names if itf.causality[n] != causality]
        if bad:
            return f"'{inst}.{bad[0]}' is {_a(itf.causality[bad[0]])}, expected {_a(causality)}"
    return None


def _resolve_ref(src, key, ref, instances, causality=None):
    """'inst.var' -> (inst, [scalar names])."""
    inst, var = _reference(src, key, ref, instances)
    itf = instances[inst].interface
    names = expand(itf, var)
    problem = _end_problem(inst, var, itf, names, causality)
    if problem:
        raise InputError(src, key, problem)
    return inst, names


def _connection(src, key, pair, instances):
    """A connection ``[from, to]`` -> (s_inst, s_names, d_inst, d_names, problems): the problems
    name both ends (a missing variable, causality, element counts, units)."""
    from plant.units import mismatch

    (s_inst, s_var), (d_inst, d_var) = (_reference(src, key, r, instances) for r in pair)
    s_itf, d_itf = instances[s_inst].interface, instances[d_inst].interface
    s_names, d_names = expand(s_itf, s_var), expand(d_itf, d_var)
    problems = [p for p in (_end_problem(s_inst, s_var, s_itf, s_names, "output"),
                            _end_problem(d_inst, d_var, d_itf, d_names, "input")) if p]
    if s_names and d_names and all(s_itf.causality[n] == "output" for n in s_names) and \
            all(d_itf.causality[n] == "output" for n in d_names):
        problems[-1] += " (an output wired to an output)"
    if not problems and len(s_names) != len(d_names):
        problems.append(f"{pair[0]} has {len(s_names)} elements, {pair[1]} has {len(d_names)}")
    if s_names and d_names and len(s_names) == len(d_names):
        units = {}
        for sn, dn in zip(s_names, d_names):
            su, du = s_itf.units.get(sn, "1"), d_itf.units.get(dn, "1")
            why = mismatch(su, s_itf.unit_definitions, du, d_itf.unit_definitions)
            if why:
                units.setdefault(why, []).append((sn, dn))
        for why, pairs in units.items():
            problems.append(f"unit mismatch, {why}: {s_inst}.{summary([a for a, _ in pairs])} ({s_itf.model_name} output) "
                            f"drives {d_inst}.{summary([b for _, b in pairs])} ({d_itf.model_name} input)")
    return s_inst, s_names, d_inst, d_names, problems


# -- interfaces ---------------------------------------------------------------------------------
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
    from fmpy import read_model_description

    from orchestrator.common.archives import check_members

    from .fmu_checks import load_problems

    if not path.is_file():
        raise InputError(src, key, f"FMU file not found: {path}")
    if not zipfile.is_zipfile(path):
        raise InputError(src, key, f"{path} is not an FMU (not a zip archive)")
    names = {i.filename for i in check_members(path, src, key)}  # also: not a zip -> InputError
    if "modelDescription.xml" not in names:
        raise InputError(src, key, f"{path} is not an FMU: no modelDescription.xml")
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


def block_interface(model_name: str) -> Interface:
    from fmus.catalog import block_factory

    b = block_factory(model_name)()
    c = {v.name: "input" for v in b.inputs}
    c.update({v.name: "output" for v in b.outputs})
    c.update({v.name: "parameter" for v in b.parameters})
    return Interface(model_name, c, {v.name: list(b.feedthrough.get(v.name, ())) for v in b.outputs},
                     units={v.name: v.unit for v in b.inputs + b.outputs + b.parameters}, origin="in-process")


# -- parameters ---------------------------------------------------------------------------------
def structured_parameter_set(name: str) -> dict:
    """A paper's parameter set (``papers/registry.py``) as structured scalar names (``J[1,2]``)."""
    from papers.paper import resolve
    from papers.registry import parameter_sets
    from plant.block import structured_values

    out = {}
    for base, value in resolve(parameter_sets()[name]).items():
        out.update(structured_values(base, value))
    return out


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
            out[name] = _number(src, k, value)
            continue
        try:
            arr = np.asarray(value, dtype=object)
        except Exception:
            raise InputError(src, k, f"expected an array of numbers, got {_short(value)}") from None
        flat = arr.ravel().tolist() if arr.ndim else [value]
        shape = _shape_of(names)
        want = shape if len(shape) > 1 else (len(names),)
        if arr.shape != want:
            raise InputError(src, k, f"expected shape {want} for {len(names)} elements, got {arr.shape}")
        for n, x in zip(names, flat):
            out[n] = _number(src, k, x)
    return out


# -- main loader -----------------------------------------------------------------------------
def _merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
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
    from orchestrator.common.jsonio import parse_toml, read_utf8

    doc = parse_toml(src, read_utf8(path, "scenario file"))
    meta = doc.get("scenario", {})
    base = meta.get("extends") if isinstance(meta, dict) else None
    if base is None:
        return doc
    if not isinstance(base, str) or not base:
        raise InputError(src, "scenario.extends", f"expected a file name or a shipped scenario name, got {_short(base)}")
    if len(_seen) >= MAX_EXTENDS:
        raise InputError(src, "scenario.extends", f"extends chain deeper than {MAX_EXTENDS}")
    if not base.endswith(".toml") and "/" not in base:
        from papers.registry import scenario_files

        shipped = scenario_files()
        if base not in shipped:
            raise InputError(src, "scenario.extends", f"no shipped scenario {base!r} (`ftcsim scenarios` lists them)")
        base_path = shipped[base].resolve()
    else:
        folder = path.parent.resolve()
        base_path = (folder / base).resolve()
        if not base_path.is_relative_to(folder):
            raise InputError(src, "scenario.extends", f"{base!r} lies outside the scenario's folder {folder}; refused")
    if base_path in _seen or base_path == path.resolve():
        raise InputError(src, "scenario.extends", f"circular extends through {base}")
    if not base_path.is_file():
        raise InputError(src, "scenario.extends", f"base scenario not found: {base_path}")
    merged = _merge(_without_replaced_instances(read_document(base_path, _seen + (path.resolve(),)), doc), doc)
    merged["scenario"].pop("extends", None)
    return merged


def check_timing(src, start: float, stop: float, step: float, key="timing") -> int:
    """Number of steps of [start, stop] with ``step``; refuses what cannot run."""
    if stop <= start:
        raise InputError(src, f"{key}.stop", f"stop ({stop:g}) must be after start ({start:g})")
    n = (stop - start) / step
    if n > MAX_STEPS:
        raise InputError(src, f"{key}.step", f"(stop - start) / step = {n:.3g} steps, more than the {MAX_STEPS:.0e} "
                                             "a run may take; use a larger step or a shorter run")
    if abs(n - round(n)) > 1e-9 * max(1.0, n):
        raise InputError(src, f"{key}.step", f"(stop - start) / step = {n:g} is not a whole number of steps")
    return int(round(n))


def check_run_size(scenario) -> None:
    """Refuse, before any FMU starts, a run whose recorded data would not fit the limit."""
    check_timing(scenario.path, scenario.start, scenario.stop, scenario.step)
    check_step_policy(scenario.path, scenario)
    rows = int(round((scenario.stop - scenario.start) / scenario.output_step)) + 1
    size = rows * (len(scenario.record) + 1) * 8
    if size > MAX_RESULT_BYTES:
        raise InputError(scenario.path, "record", f"{rows} rows x {len(scenario.record) + 1} columns would take "
                         f"{size / 2**30:.1f} GiB (at most {MAX_RESULT_BYTES / 2**30:.0f} GiB): record fewer variables "
                         "or use a larger step")


def _multiple(x: float, base: float) -> int | None:
    """x / base if it is a whole number >= 1 (to 1e-9 relative), else None."""
    m = x / base
    k = int(round(m))
    return k if k >= 1 and abs(m - k) <= 1e-9 * m else None


def read_step_settings(src, timing: dict, instances: dict) -> StepSettings:
    """The step-policy keys of a [timing] table, each checked on its own (the checks between
    keys and against the instances are :func:`check_step_policy`'s)."""
    st = StepSettings(given=tuple(k for k in timing if k in ADAPTIVE_KEYS + ("step_policy", "record_announced")))
    if "step_policy" in timing:
        p = timing["step_policy"]
        if p not in STEP_POLICIES:
            import difflib

            close = difflib.get_close_matches(str(p), STEP_POLICIES, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise InputError(src, "timing.step_policy", f"unknown policy {_short(p)} ({hint}known: {', '.join(STEP_POLICIES)})")
        st.policy = p
    for k in ("rtol", "min_step", "max_step", "output_step", "safety"):
        if k in timing:
            setattr(st, k, _number(src, f"timing.{k}", timing[k], positive=True))
    if "atol" in timing:
        st.atol = _number(src, "timing.atol", timing["atol"])
        if st.atol < 0:
            raise InputError(src, "timing.atol", f"must be >= 0, got {st.atol:g}")
    if st.safety is not None and st.safety > 1:
        raise InputError(src, "timing.safety", f"must be in (0, 1], got {st.safety:g}")
    if "record_announced" in timing:
        if not isinstance(timing["record_announced"], bool):
            raise InputError(src, "timing.record_announced", f"expected true or false, got {_short(timing['record_announced'])}")
        st.record_announced = timing["record_announced"]
    if "error_variables" in timing:
        refs = timing["error_variables"]
        if not isinstance(refs, list) or not refs:
            raise InputError(src, "timing.error_variables", "expected a non-empty list of 'instance.output'")
        for j, ref in enumerate(refs):
            inst, names = _resolve_ref(src, f"timing.error_variables[{j}]", ref, instances, "output")
            st.error_variables += [(inst, n) for n in names]
        st.error_variables = list(dict.fromkeys(st.error_variables))
    return st


def check_step_policy(src, sc) -> None:
    """Check the step policy against the timing and the instances (at load, and again after
    start/stop/step overrides); resolves the policy and the adaptive defaults in place."""
    st = sc.timing
    given_policy = st.policy if "step_policy" in st.given else None
    own = {n: i for n, i in sc.instances.items() if i.step is not None and _multiple(i.step, sc.step) != 1}
    announcers = {n: i for n, i in sc.instances.items() if i.announces}
    policy = given_policy or ("multirate" if own or announcers else "fixed")
    for name, inst in sc.instances.items():
        key = f"instances.{name}.step"
        if inst.step is None:
            continue
        m = _multiple(inst.step, sc.step)
        if m is None:
            raise InputError(src, key, f"{inst.step:g} s is not a whole multiple of the base step timing.step = "
                                       f"{sc.step:g} s (an instance's step is m times the base step, m = 1, 2, ...)")
        if m != 1 and policy != "multirate":
            raise InputError(src, key, f"an instance step of its own ({inst.step:g} s, base {sc.step:g} s) needs "
                                       f"timing.step_policy = 'multirate', not {policy!r}")
        if sc.n_steps % m:
            raise InputError(src, key, f"the run ({sc.stop - sc.start:g} s) is not a whole number of this instance's "
                                       f"steps of {inst.step:g} s")
    for name, inst in announcers.items():
        key = f"instances.{name}.announces"
        if policy == "fixed":
            raise InputError(src, key, "announced instants need timing.step_policy = 'multirate' or 'adaptive', "
                                       "not 'fixed' (a fixed step cannot land on them)")
        if name in own:
            raise InputError(src, key, f"an instance that announces instants runs at the base step: remove its step "
                                       f"({inst.step:g} s) or its announcements")
    if st.record_announced and not announcers:
        raise InputError(src, "timing.record_announced", "no instance announces instants (instances.NAME.announces)")
    if policy != "adaptive":
        for k in ADAPTIVE_KEYS:
            if k in st.given:
                raise InputError(src, f"timing.{k}", f"only used with step_policy = 'adaptive' (this scenario's "
                                                     f"policy is {policy!r})")
    else:
        for name, inst in sc.instances.items():
            caps = inst.capabilities
            for flag, what in (("canGetAndSetFMUstate", "get and set its state (rollback)"),
                               ("canHandleVariableCommunicationStepSize", "vary its communication step")):
                if caps and not caps.get(flag, False):
                    raise InputError(src, f"instances.{name}.fmu", f"{Path(inst.fmu).name} cannot {what}: its "
                                     f"modelDescription has {flag} = false, and step_policy = 'adaptive' needs it")
        st.output_step = st.output_step if "output_step" in st.given else sc.step
        n = (sc.stop - sc.start) / st.output_step
        if abs(n - round(n)) > 1e-9 * max(1.0, n):
            raise InputError(src, "timing.output_step", f"(stop - start) / output_step = {n:g} is not a whole number "
                                                        "of output intervals")
        st.max_step = st.max_step if "max_step" in st.given else st.output_step
        st.min_step = st.min_step if "min_step" in st.given else min(st.output_step * 1e-3, st.max_step)
        if st.min_step > st.max_step:
            raise InputError(src, "timing.min_step", f"min_step = {st.min_step:g} s is larger than max_step = "
                                                     f"{st.max_step:g} s")
        if st.rtol is None:
            st.rtol = 1e-6
        if st.atol is None:
            st.atol = 1e-8
        if st.safety is None:
            st.safety = 0.9
        if not st.error_variables:
            st.error_variables = [(i, v) for i, v in sc.record if sc.instances[i].interface.causality.get(v) == "output"
                                  and not sc.instances[i].interface.feedthrough.get(v)]
            if not st.error_variables:
                raise InputError(src, "timing.error_variables", "no recorded output is a state (every one depends on "
                                 "an input): name the outputs whose error the step control watches")
    if policy == "multirate" or announcers:
        for name, inst in sc.instances.items():
            caps = inst.capabilities
            if announcers and name not in own and caps and not caps.get("canHandleVariableCommunicationStepSize", False):
                raise InputError(src, f"instances.{name}.fmu", f"{Path(inst.fmu).name} cannot vary its communication "
                                 "step (canHandleVariableCommunicationStepSize = false): landing on announced instants "
                                 "shortens the steps of every base-rate instance")
    st.policy = policy


def describe(path: Path) -> tuple[str, str]:
    """(paper, description) of a scenario file without validating it (for ``ftcsim scenarios``)."""
    try:
        meta = read_document(path).get("scenario", {})
    except InputError as e:
        return "?", f"(unreadable: {e.problem})"
    return str(meta.get("paper", "")), str(meta.get("description", ""))


def metric_keys(paper_id: str) -> dict:
    """[metrics] keys a scenario of ``paper_id`` may use: generic ones and its paper's ``KEYS``."""
    keys = dict(METRIC_KEYS)
    try:
        from papers.paper import resolve
        from papers.registry import paper

        p = paper(paper_id)
    except KeyError:
        return keys
    if p.metrics:
        keys.update(getattr(resolve(p.metrics.partition(":")[0]), "KEYS", {}))
    return keys


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
    fmu_dir = Path(fmu_dir or os.environ.get("FTCSIM_FMU_DIR") or DEFAULT_FMU_DIR)

    meta = _table(src, "scenario", doc.get("scenario", {}))
    check_keys(src, "scenario", meta, SCENARIO_KEYS)
    departures = meta.get("departures", [])
    if not isinstance(departures, list) or not all(isinstance(d, str) for d in departures):
        raise InputError(src, "scenario.departures", "expected a list of strings")
    for k in ("description", "paper"):
        if k in meta and not isinstance(meta[k], str):
            raise InputError(src, f"scenario.{k}", f"expected a string, got {_short(meta[k])}")
    scenario_name = meta.get("name", path.stem)
    from orchestrator.common.outputs import safe_name

    safe_name(scenario_name, src, "scenario.name")  # it becomes a folder name under results/

    timing = _table(src, "timing", doc.get("timing"))
    check_keys(src, "timing", timing, TIMING_KEYS)
    for k in ("stop", "step"):
        if k not in timing:
            raise InputError(src, f"timing.{k}", "missing")
    start = _number(src, "timing.start", timing.get("start", 0.0))
    stop = _number(src, "timing.stop", timing["stop"])
    step = _number(src, "timing.step", timing["step"], positive=True)
    check_timing(src, start, stop, step)
    exchange = timing.get("exchange", "ordered")
    if exchange not in ("ordered", "jacobi"):
        raise InputError(src, "timing.exchange", f"must be 'ordered' or 'jacobi', not {_short(exchange)}")
    if "step_policy" in timing and timing["step_policy"] not in STEP_POLICIES:
        read_step_settings(src, {"step_policy": timing["step_policy"]}, {})  # the message, before the instances

    inst_doc = _table(src, "instances", doc.get("instances"))
    if not inst_doc:
        raise InputError(src, "instances", "no instances defined")
    instances = {}
    for name, spec in inst_doc.items():
        key = f"instances.{name}"
        if not INSTANCE_NAME.match(name):
            raise InputError(src, key, f"instance name {_short(name)} must be an identifier (ASCII letters, digits, "
                                       "'_', not starting with a digit, at most 64 characters)")
        spec = _table(src, key, spec)
        check_keys(src, key, spec, INSTANCE_KEYS)
        fmu = _string(src, f"{key}.fmu", spec.get("fmu"))
        if fmu.endswith(".fmu"):
            fmu_path = (path.parent / fmu).resolve()
        else:
            fmu_path = fmu_dir / f"{fmu}.fmu"
        if in_process:
            from fmus.catalog import catalog

            CATALOG = catalog()

            model = fmu if not fmu.endswith(".fmu") else None
            if model is None and fmu_path.is_file():
                model = fmu_interface(src, f"{key}.fmu", fmu_path)[0].model_name
            if model not in CATALOG:
                raise InputError(src, f"{key}.fmu", f"'{fmu}' has no in-process block (known: {', '.join(CATALOG)})")
            itf, fmu_path, caps = block_interface(model), None, {}
        else:
            if not fmu.endswith(".fmu") and not fmu_path.is_file():
                raise InputError(src, f"{key}.fmu", f"FMU file not found: {fmu_path} (run `ftcsim build` first)")
            itf, md = fmu_interface(src, f"{key}.fmu", fmu_path)
            caps = fmu_capabilities(md)
        params = {}
        if "parameter_set" in spec:
            from papers.registry import parameter_sets

            sets = parameter_sets()
            ps = spec["parameter_set"]
            if not isinstance(ps, str) or ps not in sets:
                raise InputError(src, f"{key}.parameter_set", f"unknown set {_short(ps)} (known: {', '.join(sets)})")
            params.update({k: v for k, v in structured_parameter_set(ps).items() if k in itf.causality})
        params.update(expand_parameters(src, f"{key}.parameters", itf, _table(src, f"{key}.parameters", spec.get("parameters", {}))))
        own_step = _number(src, f"{key}.step", spec["step"], positive=True) if "step" in spec else None
        announces = _announces(src, f"{key}.announces", spec.get("announces", []), itf)
        instances[name] = Instance(name, fmu_path, itf.model_name, itf, params, own_step, announces, caps)

    # connections
    conns_doc = doc.get("connections", [])
    if not isinstance(conns_doc, list):
        raise InputError(src, "connections", "expected a list of [\"from.output\", \"to.input\"] pairs")
    connections, driven, unmatched = [], {}, []
    for k, pair in enumerate(conns_doc):
        key = f"connections[{k}]"
        if not (isinstance(pair, list) and len(pair) == 2):
            raise InputError(src, key, f"expected [\"from.output\", \"to.input\"], got {pair!r}")
        s_inst, s_names, d_inst, d_names, problems = _connection(src, key, pair, instances)
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
    for name, spec in _table(src, "sources", doc.get("sources", {})).items():
        key = f"sources.{name}"
        spec = _table(src, key, spec)
        kind = spec.get("type", "piecewise_constant")
        if kind not in ("piecewise_constant", "constant"):
            raise InputError(src, f"{key}.type", f"unknown source type {_short(kind)} (known: piecewise_constant, constant)")
        check_keys(src, key, spec, ("type", "to", "value") if kind == "constant" else ("type", "to", "times", "values"))
        d_inst, d_names = _resolve_ref(src, f"{key}.to", spec.get("to"), instances, "input")
        if kind == "constant":
            times, values = [start], [spec.get("value")]
        else:
            times, values = spec.get("times"), spec.get("values")
            if not isinstance(times, list) or not times:
                raise InputError(src, f"{key}.times", "expected a non-empty list of times")
            times = [_number(src, f"{key}.times", t) for t in times]
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
            rows.append([_number(src, vk, x) for x in v])
        for dn in d_names:
            if (d_inst, dn) in driven:
                raise InputError(src, f"{key}.to", f"{d_inst}.{dn} is already driven by {driven[(d_inst, dn)]}")
            driven[(d_inst, dn)] = key
        sources.append(Source(name, kind, times, np.array(rows), [(d_inst, dn) for dn in d_names]))

    # record
    rec_doc = _table(src, "record", doc.get("record", {}))
    check_keys(src, "record", rec_doc, ("variables",))
    record = []
    if "variables" in rec_doc:
        if not isinstance(rec_doc["variables"], list):
            raise InputError(src, "record.variables", "expected a list of 'instance.variable'")
        for j, ref in enumerate(rec_doc["variables"]):
            inst, names = _resolve_ref(src, f"record.variables[{j}]", ref, instances)
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

    metrics = _table(src, "metrics", doc.get("metrics", {}))
    paper_id = str(meta.get("paper", ""))
    known = metric_keys(paper_id)
    for k, v in metrics.items():
        key = f"metrics.{k}"
        kind = known.get(k)
        if kind is None:
            raise unknown_key(src, "metrics", k, list(known))
        if kind == "signal":
            inst, names = _resolve_ref(src, key, v, instances)
            for nm in names:
                if (inst, nm) not in record:
                    record.append((inst, nm))
        elif kind == "number":
            _number(src, key, v)
        elif kind == "time":
            metrics[k] = _number(src, key, v)
        elif kind == "window":
            if not (isinstance(v, list) and len(v) == 2):
                raise InputError(src, key, f"expected a time window [from, to] in s, got {_short(v)}")
            a, b = (_number(src, key, x) for x in v)
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
    )
    check_step_policy(src, sc)
    return sc


def _announces(src, key, names, itf: Interface) -> list[str]:
    """``announces = ["t_next_sample"]``: outputs of the instance holding its next instant (s)."""
    if isinstance(names, str):
        names = [names]
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise InputError(src, key, f"expected a list of output names, got {_short(names)}")
    for n in names:
        c = itf.causality.get(n)
        if c != "output":
            what = "no such variable" if c is None else f"it is {'an' if c[0] in 'aeiou' else 'a'} {c}"
            raise InputError(src, key, f"{n!r} is not an output of {itf.model_name} ({what}); announced instants "
                                       "are outputs holding the next time to step to (s)")
    return list(dict.fromkeys(names))


def apply_gains(scenario: Scenario, gains_path) -> list[str]:
    """Override parameters from a design file (``ftcsim design ... --out FILE``).

    The file's ``fmu_parameters`` maps FMU model names to structured parameter values;
    they apply to every instance of that model. Returns the instances changed."""
    from .design_commands import load_json

    src = str(gains_path)
    if not Path(gains_path).exists():
        raise InputError(src, "-", "gains file not found")
    doc = load_json(gains_path)
    if "fmu_parameters" not in doc:
        import difflib

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
