"""SSP 1.0 packages: ``ftcsim export-ssp`` and ``ftcsim run FILE.ssp``.

Export writes one ``.ssp`` (a zip) that another SSP tool can run as it is:

* ``resources/<Model>.fmu``: every FMU the scenario uses (one file per model and set of
  parameter values, shared by the instances that have both) and, for the scenario's sources,
  ``PiecewiseConstantSource.fmu``. Our FMUs are packed as configured copies whose
  modelDescription start values are the instance's parameter values (fmus/configure.py; they
  start from those), so a tool that applies no parameter set (Ecos's plain ``init()``) runs the
  scenario too; other FMUs as they are;
* ``resources/<instance>.ssv``: one SSV parameter set per instance with parameters, bound
  to its component by an ``ssd:ParameterBinding``;
* ``SystemStructure.ssd``: components with their input/output connectors (type and unit),
  the scalar connections, the unit definitions, and a ``DefaultExperiment`` with start
  and stop time and the step as the Open Simulation Platform annotation
  (``com.opensimulationplatform`` / ``osp:FixedStepAlgorithm baseStepSize``), which is
  how libcosim reads the step: SSP 1.0 itself has no step size;
* per component with a communication step of its own (``[instances.NAME] step``, multirate),
  libcosim's step-size hint: an OSP annotation ``osp:StepSizeHint value=...`` on the
  ``ssd:Component``, from which libcosim's fixed-step algorithm takes the decimation factor
  (hint / base step). libcosim transfers a connection only at multiples of the lcm of the two
  factors; that equals our sampled-data rule (a component reads the held outputs at each of its
  own points) whenever one factor of each connection divides the other (as in every nested
  multirate loop), which ``tests/orchestrator/test_libcosim.py`` checks;
* inside ``ssd:System`` (its ``ssd:Annotations``, OpenModelica's first): the
  ``org.openmodelica`` fixed-step master and step that OMSimulator's command line needs, and
  an ``org.ftcsim.scenario`` annotation carrying what SSP has no place for: the scenario's
  description, paper, departures, exchange scheme, record list, metrics and step policy
  (``ftcsim:StepPolicy``, JSON: policy, adaptive settings, announced outputs). Other tools
  ignore it (libcosim runs an adaptive package with its fixed step); ``ftcsim run FILE.ssp``
  uses it to give the same results (columns, metrics) as the TOML run (packages with it at the
  SSD root, the old layout, are still read);
* every SSV parameter set is named ``default`` (:data:`PARAMETER_SET`): Ecos applies SSV values
  only under a set name (``--parameterSet default``, ``init(parameter_set="default")``; the
  same values as the configured FMUs' start values).

Sources (``[sources.NAME]``): SSP has no signal generators. Each source becomes an
instance of the ``PiecewiseConstantSource`` FMU (``plant/signals.py``, built with the
others) connected to the source's targets, so the package is self-contained and runs
in any SSP tool. Its semantics equal the master's sources exactly (same segment rule),
so the ordered run of the package is identical to the TOML run; under Jacobi exchange
the master's sources already behave like such an FMU (see ``orchestrator/cosim/master.py``).
A source wider than 8 columns is split over several instances ``NAME_1, NAME_2, ...``;
more than 16 segments is refused.

Import (``load_ssp``) reads any SSP whose components are FMI co-simulation FMUs with
Real scalar connections (no linear transformations, no nested systems), validating the
SSD against the SSP 1.0 schema with fmpy's ``read_ssd``, and gives a ``Scenario`` that
``run_scenario`` runs like a TOML one.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import zipfile
from pathlib import Path, PurePosixPath

from lxml import etree

from fmus.configure import configured_fmu, honours_start_values
from orchestrator.common.archives import check_members, safe_extract
from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import parse_json_object
from orchestrator.common.outputs import OutputFile, safe_name
from orchestrator.common.tempdirs import owned_folder
from orchestrator.scenario import shipped
from orchestrator.scenario.checks import check_timing, read_step_settings, validate
from orchestrator.scenario.interfaces import block_interface, fmu_capabilities, fmu_interface
from orchestrator.scenario.model import INSTANCE_NAME, Instance, Scenario, StepSettings
from orchestrator.scenario.refs import check_announces, connection, resolve_ref
from orchestrator.scenario.toml import TIMING_KEYS
from orchestrator.scenario.values import unknown_key
from plant.signals import MAX_SEGMENTS, MAX_WIDTH
from plant.units import mismatch

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
    "ftcsim": "https://github.com/ftcsim/ssp-annotations",
    "oms": "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd",
}
OSP_ANNOTATION = "com.opensimulationplatform"
FTCSIM_ANNOTATION = "org.ftcsim.scenario"
OMS_ANNOTATION = "org.openmodelica"
PARAMETER_SET = "default"  # the one ParameterSet name of every SSV we write (Ecos applies one named set)
SOURCE_MODEL = "PiecewiseConstantSource"
FMU_TYPE = "application/x-fmu-sharedlibrary"
SSV_TYPE = "application/x-ssp-parameter-set"


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def _el(parent, prefix, tag, **attrib):
    e = etree.SubElement(parent, _q(prefix, tag))
    for k, v in attrib.items():
        if v is not None:
            e.set(k, str(v))
    return e


def _num(x: float) -> str:
    """Shortest text that reads back as the same double."""
    return repr(float(x))


# -- export --------------------------------------------------------------------------------
def _units_of(md) -> dict:
    """unit name -> BaseUnit attributes, from an FMU's UnitDefinitions."""
    out = {}
    for u in getattr(md, "unitDefinitions", []) or []:
        bu = u.baseUnit
        attrs = {}
        if bu is not None:
            for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad"):
                v = getattr(bu, k, 0)
                if v:
                    attrs[k] = str(int(v))
            if getattr(bu, "factor", 1.0) != 1.0:
                attrs["factor"] = _num(bu.factor)
            if getattr(bu, "offset", 0.0) != 0.0:
                attrs["offset"] = _num(bu.offset)
        out[u.name] = attrs
    return out


def _source_instances(scenario: Scenario, fmu_dir: Path):
    """Scenario sources -> [(instance name, {param: value}, [(column, inst, var)])]."""
    out = []
    taken = set(scenario.instances)
    for s in scenario.sources:
        n_seg, width = s.values.shape
        if len(s.times) > MAX_SEGMENTS:
            raise InputError(scenario.path, f"sources.{s.name}.times",
                             f"{len(s.times)} segments; an SSP export holds at most {MAX_SEGMENTS} per source")
        chunks = [list(range(j, min(j + MAX_WIDTH, width))) for j in range(0, width, MAX_WIDTH)]
        for c, cols in enumerate(chunks):
            name = s.name if len(chunks) == 1 else f"{s.name}_{c + 1}"
            if name in taken:
                raise InputError(scenario.path, f"sources.{s.name}",
                                 f"cannot export: an instance named '{name}' already exists")
            taken.add(name)
            params = {"n_segments": float(len(s.times))}
            for k, t in enumerate(s.times):
                params[f"times[{k + 1}]"] = float(t)
            for k in range(n_seg):
                for i, col in enumerate(cols):
                    params[f"values[{k + 1},{i + 1}]"] = float(s.values[k, col])
            wires = [(f"y[{i + 1}]",) + tuple(s.targets[col]) for i, col in enumerate(cols)]
            out.append((name, params, wires))
    return out


def _ssv(name: str, params: dict, units_of_param: dict, unit_defs: dict) -> bytes:
    root = etree.Element(_q("ssv", "ParameterSet"), nsmap={"ssv": NS["ssv"], "ssc": NS["ssc"]})
    root.set("version", "1.0")
    root.set("name", name)
    ps = _el(root, "ssv", "Parameters")
    used = set()
    for pname, value in params.items():
        p = _el(ps, "ssv", "Parameter", name=pname)
        unit = units_of_param.get(pname) or None
        if unit is not None and unit not in unit_defs:
            unit = None
        _el(p, "ssv", "Real", value=_num(value), unit=unit)
        if unit:
            used.add(unit)
    if used:
        units = _el(root, "ssv", "Units")
        for u in sorted(used):
            _el(_el(units, "ssc", "Unit", name=u), "ssc", "BaseUnit", **unit_defs[u])
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)


def build_ssd(scenario: Scenario, fmu_dir=None):
    """The SSD (as bytes), the SSV files and the FMU files of a scenario's package:
    ``(ssd_bytes, {member: bytes}, {member: fmu path or the bytes of a configured copy})``."""
    fmu_dir = shipped.fmu_folder(fmu_dir)
    # components: (name, fmu path, model description, parameters)
    comps = []
    for name, inst in scenario.instances.items():
        if inst.fmu is None:
            raise InputError(scenario.path, f"instances.{name}", "in-process instances cannot be exported; load with FMUs")
        _, md = fmu_interface(scenario.path, f"instances.{name}.fmu", Path(inst.fmu))
        comps.append((name, Path(inst.fmu), md, dict(inst.parameters)))
    connections = [(s, sv, d, dv) for s, sv, d, dv in scenario.connections]
    sources = _source_instances(scenario, fmu_dir)
    if sources:
        src_fmu = fmu_dir / f"{SOURCE_MODEL}.fmu"
        if not src_fmu.is_file():
            raise InputError("command line", "--fmu-dir",
                             f"{src_fmu} not found: the scenario has sources, run `ftcsim build {SOURCE_MODEL}` first")
        _, src_md = fmu_interface(str(src_fmu), "-", src_fmu)
        for name, params, wires in sources:
            comps.append((name, src_fmu, src_md, params))
            connections += [(name, y, inst, var) for y, inst, var in wires]

    # one resource per FMU file and parameter values: ours configured with them (fmus/configure.py)

    fmu_members, member_of, source_of, honours = {}, {}, {}, {}
    for name, path, md, params in comps:
        file = str(path.resolve())
        if file not in honours:
            honours[file] = honours_start_values(path)
        key = (file, tuple(sorted(params.items())) if honours[file] else ())
        if key not in member_of:
            member = f"resources/{md.modelName}.fmu"
            k = 2
            while member in fmu_members:
                member = f"resources/{md.modelName}_{k}.fmu"
                k += 1
            fmu_members[member] = configured_fmu(path, params) if key[1] else path
            member_of[key] = member
        source_of[name] = member_of[key]

    unit_defs = {}
    for _, _, md, _ in comps:
        unit_defs.update(_units_of(md))

    root = etree.Element(
        _q("ssd", "SystemStructureDescription"),
        nsmap={k: NS[k] for k in ("ssd", "ssc", "ssv", "osp", "ftcsim", "oms")},
    )
    root.set("version", "1.0")
    root.set("name", scenario.name)
    root.set("generationTool", "ftcsim export-ssp")
    system = _el(root, "ssd", "System", name=scenario.name, description=scenario.description or None)
    elements = _el(system, "ssd", "Elements")
    ssv_members = {}
    for name, _path, md, params in comps:
        comp = _el(elements, "ssd", "Component", name=name, type=FMU_TYPE,
                   source=source_of[name], implementation="CoSimulation")
        conns = _el(comp, "ssd", "Connectors")
        for v in md.modelVariables:
            if v.causality not in ("input", "output"):
                continue
            c = _el(conns, "ssd", "Connector", name=v.name, kind=v.causality)
            unit = getattr(v, "unit", None) or (getattr(v.declaredType, "unit", None) if getattr(v, "declaredType", None) else None)
            _el(c, "ssc", "Real", unit=unit if unit in unit_defs else None)
        if params:
            member = f"resources/{name}.ssv"
            units_of_param = {v.name: getattr(v, "unit", None) for v in md.modelVariables}
            ssv_members[member] = _ssv(PARAMETER_SET, params, units_of_param, unit_defs)
            bindings = _el(comp, "ssd", "ParameterBindings")
            _el(bindings, "ssd", "ParameterBinding", type=SSV_TYPE, source=member)
        inst = scenario.instances.get(name)
        if inst is not None and inst.step is not None:  # libcosim's decimation (step-size hint)
            ann = _el(_el(comp, "ssd", "Annotations"), "ssc", "Annotation", type=OSP_ANNOTATION)
            _el(ann, "osp", "StepSizeHint", value=_num(inst.step))
    if connections:
        cs = _el(system, "ssd", "Connections")
        for s, sv, d, dv in connections:
            _el(cs, "ssd", "Connection", startElement=s, startConnector=sv, endElement=d, endConnector=dv)
    # the System's annotations (the last child of ssd:System): OpenModelica's simulation
    # information first (OMSimulator's command line needs its master and step), then what SSP has
    # no place for; OMSimulator refuses annotations at the root ("wrong xml schema detected")
    annotations = _el(system, "ssd", "Annotations")
    oms = _el(_el(_el(annotations, "ssc", "Annotation", type=OMS_ANNOTATION), "oms", "Annotations"),
              "oms", "SimulationInformation")
    _el(oms, "oms", "FixedStepMaster", description="oms-ma", stepSize=_num(scenario.step),
        absoluteTolerance="0.0001", relativeTolerance="0.0001")
    ann = _el(annotations, "ssc", "Annotation", type=FTCSIM_ANNOTATION)
    sc = _el(ann, "ftcsim", "Scenario", name=scenario.name, paper=scenario.paper or None,
             step=_num(scenario.step), exchange=scenario.exchange)
    if scenario.description:
        _el(sc, "ftcsim", "Description").text = scenario.description
    for d in scenario.departures:
        _el(sc, "ftcsim", "Departure").text = d
    for inst, var in scenario.record:
        _el(sc, "ftcsim", "Record", variable=f"{inst}.{var}")
    if scenario.metrics:
        _el(sc, "ftcsim", "Metrics").text = json.dumps(scenario.metrics)
    policy = _policy_annotation(scenario)
    if policy:
        _el(sc, "ftcsim", "StepPolicy").text = json.dumps(policy)
    if unit_defs:
        units = _el(root, "ssd", "Units")
        for u in sorted(unit_defs):
            _el(_el(units, "ssc", "Unit", name=u), "ssc", "BaseUnit", **unit_defs[u])
    exp = _el(root, "ssd", "DefaultExperiment", startTime=_num(scenario.start), stopTime=_num(scenario.stop))
    ann = _el(_el(exp, "ssd", "Annotations"), "ssc", "Annotation", type=OSP_ANNOTATION)
    _el(_el(ann, "osp", "Algorithm"), "osp", "FixedStepAlgorithm", baseStepSize=_num(scenario.step))
    ssd = etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)
    return ssd, ssv_members, fmu_members


def _policy_annotation(scenario: Scenario) -> dict:
    """The step-policy settings the file gave (the rest follows from the defaults) and the
    announced outputs, as JSON-safe values; {} for a plain fixed-step scenario."""
    st = scenario.timing
    out = {}
    for k in st.given:
        if k == "step_policy":
            out[k] = st.policy
        elif k == "error_variables":
            out[k] = [f"{i}.{v}" for i, v in st.error_variables]
        else:
            out[k] = getattr(st, k)
    announces = {n: list(i.announces) for n, i in scenario.instances.items() if i.announces}
    if announces:
        out["announces"] = announces
    return out


def export_ssp(scenario: Scenario, out, fmu_dir=None, overwrite: bool = False) -> Path:
    """Write ``scenario`` as an SSP package at ``out`` (atomically: complete or nothing).
    An existing file at ``out`` is replaced only with ``overwrite``."""
    target = OutputFile(out, "an SSP package", written_by_ftcsim, overwrite, suffix=".ssp").check()
    try:
        ssd, ssvs, fmus = build_ssd(scenario, fmu_dir)
    except BaseException:
        target.release()
        raise

    def write(tmp):
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("SystemStructure.ssd", ssd)
            for member, data in ssvs.items():
                z.writestr(member, data)
            for member, src in fmus.items():  # FMUs are zips already: stored
                if isinstance(src, bytes):
                    z.writestr(member, src, compress_type=zipfile.ZIP_STORED)
                else:
                    z.write(src, member, compress_type=zipfile.ZIP_STORED)
        validate_ssp(tmp)

    target.write(write)  # complete or nothing; an existing package replaced only if ftcsim wrote it
    return Path(out)


def written_by_ftcsim(path) -> bool:
    """True if ``path`` is an SSP package ``ftcsim export-ssp`` wrote (its SSD says so)."""
    try:
        with zipfile.ZipFile(path) as z:
            head = z.read("SystemStructure.ssd")[:4096]
    except (OSError, KeyError, zipfile.BadZipFile, ValueError):
        return False
    return b'generationTool="ftcsim export-ssp"' in head


def validate_ssp(path) -> None:
    """Parse the package with fmpy's SSP reader, which validates the SSD (and every
    referenced SSV) against the SSP 1.0 schemas. Raises ``InputError`` on a problem."""
    from fmpy.ssp.ssd import read_ssd

    try:
        read_ssd(str(path), validate=True)
    except Exception as e:
        raise InputError(str(path), "SystemStructure.ssd", " ".join(str(e).split())) from None


# -- import --------------------------------------------------------------------------------
def _float_attr(src, key, e, name, default=None):
    v = e.get(name)
    if v is None:
        if default is None:
            raise InputError(src, key, f"missing attribute {name}")
        return default
    try:
        x = float(v)
    except ValueError:
        raise InputError(src, key, f"{name}={v[:40]!r} is not a number") from None
    if not math.isfinite(x):
        raise InputError(src, key, f"{name}={v!r} must be finite")
    return x


def _member(src, key, ref, names) -> str:
    """A package member named by ``ref`` (a component or parameter-binding source): a relative
    path that stays inside the package and exists in it."""
    if not isinstance(ref, str) or not ref:
        raise InputError(src, key, "missing source")
    p = PurePosixPath(ref)
    if p.is_absolute() or ".." in p.parts or "\\" in ref or ":" in ref.split("/")[0] or ref.startswith("~"):
        raise InputError(src, key, f"source {ref!r} points outside the package; refused")
    norm = str(p)
    if norm not in names:
        raise InputError(src, key, f"source {ref!r} is not in the package")
    return norm


def _parameter_set(src, key, ps) -> dict:
    """{name: (value, unit or None)} of an ssv:ParameterSet; a name given twice is refused (the last
    one silently winning would hide a typo or a tampered file)."""
    out = {}
    for p in ps.findall("ssv:Parameters/ssv:Parameter", NS):
        real = p.find("ssv:Real", NS)
        name = p.get("name")
        if real is None:
            raise InputError(src, f"{key}/{name}", "only Real parameters are supported")
        if name in out:
            raise InputError(src, f"{key}/{name}", "parameter given twice in one parameter set")
        out[name] = (_float_attr(src, f"{key}/{name}", real, "value"), real.get("unit"))
    return out


def _add_parameters(src, key, params: dict, where: dict, found: dict, itf) -> None:
    """Add the parameters ``found`` of one binding (``key``) to ``params``: refuse a parameter another
    binding set already and a declared unit that does not match the FMU's (as scenario files'
    connections are checked: ``plant/units.py``)."""
    for name, (value, unit) in found.items():
        if name in params:
            raise InputError(src, f"{key}/{name}", f"parameter set twice (also in {where[name]})")
        own = itf.units.get(name)
        if unit is not None and own is not None:
            why = mismatch(unit, {}, own, itf.unit_definitions)
            if why:
                raise InputError(src, f"{key}/{name}", f"unit mismatch, {why}: the package gives {unit!r}, "
                                                       f"{itf.model_name} declares {own!r}")
        params[name], where[name] = value, key


def load_ssp(path, in_process=False, step=None) -> Scenario:
    """Read and check an SSP package; returns a ``Scenario`` whose FMUs are the package's.
    ``step``: override the package's communication step."""
    path = Path(path)
    src = str(path)
    if not path.is_file():
        raise InputError(src, "-", "SSP file not found")
    if not zipfile.is_zipfile(path):
        raise InputError(src, "-", "not an SSP package (not a zip archive)")
    names = {i.filename for i in check_members(path, src)}  # hostile entries refused before anything
    if "SystemStructure.ssd" not in names:
        raise InputError(src, "SystemStructure.ssd", "missing from the package")
    validate_ssp(path)
    tmp = owned_folder("ssp_")
    safe_extract(path, tmp, src)
    try:
        root = etree.parse(os.path.join(tmp, "SystemStructure.ssd"),
                           etree.XMLParser(resolve_entities=False, no_network=True)).getroot()
    except etree.XMLSyntaxError as e:
        raise InputError(src, "SystemStructure.ssd", f"not well-formed XML: {e}") from None
    system = root.find("ssd:System", NS)
    if system.find("ssd:Elements/ssd:System", NS) is not None:
        raise InputError(src, "ssd:System", "nested systems are not supported")

    # experiment
    exp = root.find("ssd:DefaultExperiment", NS)
    if exp is None:
        raise InputError(src, "ssd:DefaultExperiment", "missing: start, stop and step are needed")
    start = _float_attr(src, "ssd:DefaultExperiment", exp, "startTime", 0.0)
    if exp.get("stopTime") is None:
        raise InputError(src, "ssd:DefaultExperiment", "missing stopTime")
    stop = _float_attr(src, "ssd:DefaultExperiment", exp, "stopTime")
    ours = system.find(f"ssd:Annotations/ssc:Annotation[@type='{FTCSIM_ANNOTATION}']/ftcsim:Scenario", NS)
    if ours is None:  # packages written before the annotation moved into the System
        ours = root.find(f"ssd:Annotations/ssc:Annotation[@type='{FTCSIM_ANNOTATION}']/ftcsim:Scenario", NS)
    fixed = exp.find(f"ssd:Annotations/ssc:Annotation[@type='{OSP_ANNOTATION}']/osp:Algorithm/osp:FixedStepAlgorithm", NS)
    if step is not None:
        step = float(step)
        if not (math.isfinite(step) and step > 0):
            raise InputError("command line", "--step", f"must be a finite number > 0, got {step}")
    elif fixed is not None:
        step = _float_attr(src, "osp:FixedStepAlgorithm", fixed, "baseStepSize")
    elif ours is not None and ours.get("step"):
        step = _float_attr(src, "ftcsim:Scenario", ours, "step")
    elif (oms := system.find(f"ssd:Annotations/ssc:Annotation[@type='{OMS_ANNOTATION}']/oms:Annotations/"
                             "oms:SimulationInformation/oms:FixedStepMaster", NS)) is not None:
        step = _float_attr(src, "oms:FixedStepMaster", oms, "stepSize")
    else:
        raise InputError(src, "ssd:DefaultExperiment", "no step size: add the OSP annotation "
                         "<osp:FixedStepAlgorithm baseStepSize=...> (type com.opensimulationplatform)")
    if not step > 0:
        raise InputError(src, "osp:FixedStepAlgorithm", f"baseStepSize must be > 0, got {step}")
    check_timing(src, start, stop, step, key="ssd:DefaultExperiment")

    # components
    instances = {}
    for comp in system.findall("ssd:Elements/ssd:Component", NS):
        name = comp.get("name") or ""
        key = f"Component[{name[:40]}]"
        if not INSTANCE_NAME.match(name):
            raise InputError(src, key, "component name must be an identifier (ASCII letters, digits, '_', not "
                                       "starting with a digit, at most 64 characters): it names files and FMU instances")
        if name in instances:
            raise InputError(src, key, "two components with this name")
        ctype = comp.get("type", FMU_TYPE)
        if ctype != FMU_TYPE:
            raise InputError(src, key, f"component type {ctype!r} is not supported (only FMUs)")
        fmu_path = Path(tmp) / _member(src, key, comp.get("source"), names)
        itf, md = fmu_interface(src, key, fmu_path)
        params, where = {}, {}
        for b in comp.findall("ssd:ParameterBindings/ssd:ParameterBinding", NS):
            if b.get("source"):
                ssv_path = Path(tmp) / _member(src, f"{key}/ParameterBinding", b.get("source"), names)
                try:
                    ps = etree.parse(str(ssv_path), etree.XMLParser(resolve_entities=False, no_network=True)).getroot()
                except etree.XMLSyntaxError as e:
                    raise InputError(src, f"{key}/{b.get('source')}", f"not well-formed XML: {e}") from None
                _add_parameters(src, f"{key}/{b.get('source')}", params, where,
                                _parameter_set(src, f"{key}/{b.get('source')}", ps), itf)
            for ps in b.findall("ssd:ParameterValues/ssv:ParameterSet", NS):
                _add_parameters(src, f"{key}/ParameterValues", params, where,
                                _parameter_set(src, f"{key}/ParameterValues", ps), itf)
        for pname in params:
            c = itf.causality.get(pname)
            if c not in ("parameter", "input"):
                raise InputError(src, key, f"parameter {pname!r}: {md.modelName} has no such parameter"
                                 + ("" if c is None else f" ({pname} is {c})"))
        hint = comp.find(f"ssd:Annotations/ssc:Annotation[@type='{OSP_ANNOTATION}']/osp:StepSizeHint", NS)
        own_step = None
        if hint is not None:
            own_step = _float_attr(src, f"{key}/osp:StepSizeHint", hint, "value")
            if not own_step > 0:
                raise InputError(src, f"{key}/osp:StepSizeHint", f"value must be > 0, got {own_step:g}")
        caps, factory = fmu_capabilities(md), None
        if in_process:
            factory = shipped.block_factory(md.modelName, src, key)
            itf, fmu_path, caps, md = block_interface(md.modelName, factory), None, {}, None
        instances[name] = Instance(name, fmu_path, itf.model_name, itf, params, own_step, [], caps, md, factory)
    if not instances:
        raise InputError(src, "ssd:Elements", "no components")

    connections, driven = [], {}
    for c in system.findall("ssd:Connections/ssd:Connection", NS):
        a, av, b, bv = (c.get(k) for k in ("startElement", "startConnector", "endElement", "endConnector"))
        key = f"Connection[{a}.{av} -> {b}.{bv}]"
        if a is None or b is None:
            raise InputError(src, key, "connections to the system's own connectors are not supported")
        if len(c):
            raise InputError(src, key, "transformations on connections are not supported")
        s_inst, s_names = resolve_ref(src, key, f"{a}.{av}", instances, "output")
        d_inst, d_names = resolve_ref(src, key, f"{b}.{bv}", instances, "input")
        if s_names != [av] or d_names != [bv]:
            raise InputError(src, key, "connections must be between scalar variables")
        problems = connection(src, key, [f"{a}.{av}", f"{b}.{bv}"], instances)[4]  # units, as scenario files
        if problems:
            raise InputError(src, key, "; ".join(problems))
        if (b, bv) in driven:
            raise InputError(src, key, f"{b}.{bv} is already driven by {driven[(b, bv)]}")
        driven[(b, bv)] = key
        connections.append((a, av, b, bv))

    record, metrics, meta = [], {}, {}
    if ours is not None:
        for r in ours.findall("ftcsim:Record", NS):
            inst, names = resolve_ref(src, "ftcsim:Record", r.get("variable"), instances)
            record += [(inst, nm) for nm in names]
        m = ours.find("ftcsim:Metrics", NS)
        if m is not None and m.text:
            metrics = parse_json_object(src, "ftcsim:Metrics", m.text)
        d = ours.find("ftcsim:Description", NS)
        meta = dict(
            name=ours.get("name"),
            paper=ours.get("paper", ""),
            description=d.text if d is not None else "",
            departures=[x.text or "" for x in ours.findall("ftcsim:Departure", NS)],
            exchange=ours.get("exchange", "ordered"),
        )
    if not record:
        for inst in instances.values():
            if inst.model_name != SOURCE_MODEL:
                record += [(inst.name, nm) for nm in inst.interface.names("output")]
    if meta.get("exchange") not in (None, "ordered", "jacobi"):
        raise InputError(src, "ftcsim:Scenario", f"exchange must be 'ordered' or 'jacobi', not {meta['exchange']!r}")
    timing = StepSettings()
    policy_el = ours.find("ftcsim:StepPolicy", NS) if ours is not None else None
    if policy_el is not None and policy_el.text:
        doc = parse_json_object(src, "ftcsim:StepPolicy", policy_el.text)
        announces = doc.pop("announces", {})
        if not isinstance(announces, dict):
            raise InputError(src, "ftcsim:StepPolicy", "announces: expected an object {instance: [outputs]}")
        for k in doc:
            if k not in TIMING_KEYS:
                raise unknown_key(src, "ftcsim:StepPolicy", k, TIMING_KEYS)
        timing = read_step_settings(src, doc, instances)
        for inst, names in announces.items():
            if inst not in instances:
                raise InputError(src, "ftcsim:StepPolicy", f"announces: unknown instance {inst!r}")
            instances[inst] = dataclasses.replace(instances[inst], announces=check_announces(
                src, f"ftcsim:StepPolicy announces.{inst}", names, instances[inst].interface))
    name = meta.get("name") or root.get("name") or path.stem
    safe_name(name, src, "ftcsim:Scenario name" if meta.get("name") else "ssd:SystemStructureDescription name")
    sc = Scenario(
        path=path,
        name=name,
        description=meta.get("description") or system.get("description") or "",
        paper=meta.get("paper", ""),
        departures=meta.get("departures", []),
        start=start,
        stop=stop,
        step=step,
        exchange=meta.get("exchange", "ordered"),
        instances=instances,
        connections=connections,
        sources=[],
        record=list(dict.fromkeys(record)),
        metrics=metrics,
        timing=timing,
    )
    return validate(src, sc)
