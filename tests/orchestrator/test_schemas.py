"""The JSON Schemas of the four file formats (issue 36): shipped as the declarations generate them, valid draft
2020-12, met by every shipped file, and refusing the same hostile cases as ftcsim's own checks; the cases only
ftcsim refuses (what a schema cannot say) are listed and asserted as such. Taplo, the engine of VS Code's Even
Better TOML, checks the shipped files with the repository's .taplo.toml."""
from __future__ import annotations

import copy
import json
import math
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from jsonschema import Draft202012Validator

from orchestrator.cli.main import main
from orchestrator.cli.schema import FORMATS, schema_text, shipped_file
from orchestrator.common.errors import InputError
from tests.arena.reduced import ARENA
from tests.arena.reduced import write as write_arena
from tests.schema_check import errors, validator

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = {  # format -> the shipped files of that format (globs from the repository root)
    "scenario": ("papers/*/scenarios/*.toml", "arena/scenarios/*.toml", "docs/examples/*.toml"),
    "campaign": ("campaigns/*.toml",),
    "arena": ("arena/*.toml",),
}
NO_DESIGN_FILE_SHIPS = "design"  # none ships: the designs' tests validate what they write (tests/schema_check.py)


def dotted(path) -> str:
    """A jsonschema error's path as ftcsim names keys: ``cells[0].truth``."""
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


# -- shipped as generated, valid, met by every shipped file ---------------------------------------------------------
@pytest.mark.parametrize("name", sorted(FORMATS))
def test_shipped_schema_is_what_the_declaration_generates(name):
    assert shipped_file(name).read_text() == schema_text(name), (
        f"{shipped_file(name)} differs from the declaration: `python -m orchestrator.tools.schemas` writes it again")
    Draft202012Validator.check_schema(json.loads(schema_text(name)))


def shipped_files():
    for name, globs in SHIPPED.items():
        for g in globs:
            for p in sorted(ROOT.glob(g)):
                yield pytest.param(name, p, id=str(p.relative_to(ROOT)))


@pytest.mark.parametrize("name,path", list(shipped_files()))
def test_every_shipped_file_meets_its_schema(name, path):
    found = errors(name, tomllib.loads(path.read_text()))
    assert not found, [(list(e.absolute_path), e.message[:200]) for e in found]


def test_every_format_has_shipped_files_or_says_why():
    assert set(SHIPPED) | {NO_DESIGN_FILE_SHIPS} == set(FORMATS)
    for name, globs in SHIPPED.items():
        assert any(next(ROOT.glob(g), None) for g in globs), name


def test_ftcsim_schema_prints_and_writes_the_shipped_schema(tmp_path, capsys):
    assert main(["schema", "arena"]) == 0
    assert capsys.readouterr().out == shipped_file("arena").read_text()
    out = tmp_path / "scenario.schema.json"
    assert main(["schema", "scenario", "--out", str(out)]) == 0
    assert out.read_text() == shipped_file("scenario").read_text()
    assert main(["schema", "scenario", "--out", str(out), "--overwrite"]) == 0  # its own file, replaced
    mine = tmp_path / "mine.json"
    mine.write_text("{}")
    assert main(["schema", "campaign", "--out", str(mine), "--overwrite"]) == 2  # a file it did not write: never
    assert mine.read_text() == "{}" and "not written by `ftcsim schema`" in capsys.readouterr().err


# -- the same hostile cases refused by the schema and by ftcsim --------------------------------------------------------
SCENARIO = (ROOT / "papers/p000_li2023/scenarios/li2023_pd.toml").read_text()  # a scenario that extends nothing
CAMPAIGN = ('[campaign]\nscenario = "li2023_pd"\nmode = "inprocess"\nruns = 2\nstop = 0.05\n\n'
            '[dispersions."plant.fault_scale"]\ndistribution = "uniform"\nlow = 0.2\nhigh = 1.5\n')
DESIGN = json.dumps({"written_by": "ftcsim design hang2023-tsfdo", "design": "hang2023-tsfdo",
                     "gains": {"L1": [[0.0, -10.0], [0.0, -5.0]]},
                     "fmu_parameters": {"Hang2023TSFDO": {"L1[1,1]": 0.0, "L1[1,2]": -10.0, "L1[2,1]": 0.0,
                                                          "L1[2,2]": -5.0}}})
DEEP = "[" * 40 + "1.0" + "]" * 40  # beyond the reader's 32 levels
GOOD = {"scenario": SCENARIO, "campaign": CAMPAIGN, "arena": ARENA, "design": DESIGN}


def check(name: str, text: str, tmp_path: Path):
    """ftcsim's own check of a file of format ``name`` holding ``text`` (nothing runs)."""
    if name == "scenario":
        from orchestrator.scenario.toml import load

        p = tmp_path / "case.toml"
        p.write_text(text)
        return load(p, in_process=True)
    if name == "campaign":
        from orchestrator.campaign.spec import load

        p = tmp_path / "case.toml"
        p.write_text(text)
        return load(p)
    if name == "arena":
        from arena.arenafile import load

        return load(write_arena(tmp_path, text))
    from orchestrator.cli.design import load_json  # what `ftcsim verify --gains` reads

    p = tmp_path / "case.json"
    p.write_text(text)
    return load_json(p)


def document(name: str, text: str):
    """The document an editor validates: TOML as tomllib reads it; JSON as Python reads it (NaN, Infinity)."""
    return json.loads(text) if name == "design" else tomllib.loads(text)


def edit(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


HOSTILE = {  # (format, class) -> (the good file edited, the key ftcsim names)
    ("scenario", "unknown key"): (lambda t: edit(t, "step = 0.01", "step = 0.01\nstpo = 1.0"), "timing.stpo"),
    ("scenario", "wrong type"): (lambda t: edit(t, "step = 0.01", 'step = "0.01"'), "timing.step"),
    ("scenario", "NaN"): (lambda t: edit(t, "stop = 200.0", "stop = nan"), "timing.stop"),
    ("scenario", "inf"): (lambda t: edit(t, "k_p = 20.0", "k_p = -inf"), "instances.ctrl.parameters.k_p"),
    ("scenario", "out of range"): (lambda t: edit(t, "step = 0.01", "step = -0.01"), "timing.step"),
    ("scenario", "missing required key"): (lambda t: edit(t, "stop = 200.0\n", ""), "timing.stop"),
    ("scenario", "deep nesting"): (lambda t: edit(t, "k_p = 20.0", f"k_p = {DEEP}"), "-"),
    ("scenario", "arrays too deep"): (lambda t: edit(t, "k_p = 20.0", "k_p = [[[[[1.0]]]]]"),
                                      "instances.ctrl.parameters.k_p"),
    ("scenario", "wrong enum value"): (lambda t: edit(t, 'exchange = "ordered"', 'exchange = "gauss"'),
                                       "timing.exchange"),
    ("scenario", "bad name"): (lambda t: edit(t, "[instances.ctrl]", '[instances."ctrl-x"]').replace(
        "[instances.ctrl.parameters]", '[instances."ctrl-x".parameters]'), "instances.ctrl-x"),
    ("campaign", "unknown key"): (lambda t: edit(t, "runs = 2", "rnus = 2"), "campaign.rnus"),
    ("campaign", "wrong type"): (lambda t: edit(t, "runs = 2", 'runs = "2"'), "campaign.runs"),
    ("campaign", "NaN"): (lambda t: edit(t, "stop = 0.05", "stop = nan"), "campaign.stop"),
    ("campaign", "inf"): (lambda t: edit(t, "high = 1.5", "high = inf"), "dispersions.plant.fault_scale.high"),
    ("campaign", "out of range"): (lambda t: edit(t, "runs = 2", "runs = 0"), "campaign.runs"),
    ("campaign", "missing required key"): (lambda t: edit(t, 'scenario = "li2023_pd"\n', ""), "campaign.scenario"),
    ("campaign", "deep nesting"): (lambda t: edit(t, "low = 0.2", f"low = {DEEP}"), "-"),
    ("campaign", "arrays too deep"): (lambda t: edit(t, "low = 0.2", "low = [[[[[0.2]]]]]"),
                                      "dispersions.plant.fault_scale.low"),
    ("campaign", "wrong enum value"): (lambda t: edit(t, '"uniform"', '"gauss"'),
                                       "dispersions.plant.fault_scale.distribution"),
    ("campaign", "a key of another distribution"): (lambda t: edit(t, "low = 0.2", "mean = 0.2"),
                                                    "dispersions.plant.fault_scale.mean"),
    ("arena", "unknown key"): (lambda t: edit(t, "draws = 2", "drawz = 2"), "arena.drawz"),
    ("arena", "wrong type"): (lambda t: edit(t, "seed = 7", 'seed = "7"'), "arena.seed"),
    ("arena", "NaN"): (lambda t: edit(t, "stop = 6.0", "stop = nan"), "arena.stop"),
    ("arena", "inf"): (lambda t: edit(t, "band = 0.02", "band = inf"), "plants.hang2023.band"),
    ("arena", "out of range"): (lambda t: edit(t, "draws = 2", "draws = 0"), "arena.draws"),
    ("arena", "missing required key"): (lambda t: edit(t, "band = 0.02\n", ""), "plants.hang2023.band"),
    ("arena", "deep nesting"): (lambda t: edit(t, "onset = [1.0, 3.0]", f"onset = {DEEP}"), "file"),
    ("arena", "wrong enum value"): (lambda t: edit(t, 'mode = "inprocess"', 'mode = "cloud"'), "arena.mode"),
    ("arena", "a list value twice"): (lambda t: edit(t, 'faults = ["none", "bias"]', 'faults = ["bias", "bias"]'),
                                      "arena.faults"),
    ("arena", "a key that needs another"): (lambda t: edit(t, 'gains = "own"', 'gains = "own"\ntruth = "faults.fault"'),
                                            "cells[0].truth"),
    ("design", "wrong type"): (lambda t: edit(t, '"L1[1,1]": 0.0', '"L1[1,1]": "0.0"'),
                               "fmu_parameters.Hang2023TSFDO.L1[1,1]"),
    ("design", "a table that is not one"): (lambda t: edit(t, '"gains": {"L1": [[0.0, -10.0], [0.0, -5.0]]}',
                                                           '"gains": [1.0]'), "gains"),
    ("design", "NaN"): (lambda t: edit(t, "-10.0]", "NaN]"), "-"),  # strict JSON: refused as the file is read
    ("design", "inf"): (lambda t: edit(t, '"L1[1,2]": -10.0', '"L1[1,2]": -Infinity'), "-"),
    ("design", "deep nesting"): (lambda t: edit(t, '"L1[1,1]": 0.0', f'"L1[1,1]": {DEEP}'), "-"),
    ("design", "arrays too deep"): (lambda t: edit(t, '"L1[1,1]": 0.0', '"L1[1,1]": [[[[[0.0]]]]]'),
                                    "fmu_parameters.Hang2023TSFDO.L1[1,1]"),
    ("design", "a boolean for a number"): (lambda t: edit(t, "[[0.0, -10.0]", "[[true, -10.0]"), "gains.L1"),
}
# the classes a format has no case of, and why
NOT_APPLICABLE = {
    ("design", "unknown key"): "a design file's top level holds the design's own record (solver, versions ...): free; "
                               "its parameter names are checked against the scenario's FMUs (KNOWN_DIFFERENCES)",
    ("design", "out of range"): "no number of a design file has a range of its own (a parameter's is its FMU's)",
    ("design", "missing required key"): "verify reads files without fmu_parameters; run --gains needs them "
                                        "(KNOWN_DIFFERENCES)",
    ("design", "wrong enum value"): "design names the design verify checks, compared with the command's NAME",
    ("arena", "arrays too deep"): "an arena file has no array of numbers of free depth",
}
CLASSES = ("unknown key", "wrong type", "NaN", "inf", "out of range", "missing required key", "deep nesting",
           "wrong enum value")


def test_every_format_has_a_case_of_every_hostile_class():
    for name in FORMATS:
        for klass in CLASSES:
            assert (name, klass) in HOSTILE or (name, klass) in NOT_APPLICABLE, (name, klass)


@pytest.mark.parametrize("name", sorted(FORMATS))
def test_the_good_files_of_the_table_pass_both(name, tmp_path):
    assert not errors(name, document(name, GOOD[name]))
    check(name, GOOD[name], tmp_path)


@pytest.mark.parametrize("name,klass", sorted(HOSTILE))
def test_schema_and_checker_refuse_the_same_hostile_case(name, klass, tmp_path):
    make, key = HOSTILE[(name, klass)]
    text = make(GOOD[name])
    try:
        doc = document(name, text)
    except RecursionError:  # tomllib recurses per level; an editor's parser does not
        doc = None
    if doc is not None:
        found = errors(name, doc)
        assert found, f"the {name} schema accepts the {klass} case"
        if key not in ("-", "file"):  # where the schema refuses lies on the path to the key ftcsim names
            paths = [dotted(e.absolute_path) for e in found]
            assert any(key == p or key.startswith(p + ".") or key.startswith(p + "[") or not p for p in paths), paths
    with pytest.raises(InputError) as e:
        check(name, text, tmp_path)
    assert e.value.key == key, str(e.value)


# ftcsim refuses, the schema cannot: each case (format, the good file edited, the key ftcsim names, why) is asserted
# both ways, so that a schema that learns the rule, or a checker that forgets it, fails here
KNOWN_DIFFERENCES = {
    "a whole number written as a float": (
        "campaign", lambda t: edit(t, "runs = 2", "runs = 2.0"), "campaign.runs",
        "JSON Schema's integer holds 2.0; ftcsim takes whole numbers as TOML integers only"),
    "a run of no whole number of steps": (
        "scenario", lambda t: edit(t, "step = 0.01", "step = 0.03"), "timing.step", "(stop - start) / step"),
    "a parameter the FMU does not declare": (
        "scenario", lambda t: edit(t, "k_p = 20.0", "k_pp = 20.0"), "instances.ctrl.parameters.k_pp",
        "parameters are the FMU's (its modelDescription or block declaration)"),
    "a connection to an unknown instance": (
        "scenario", lambda t: edit(t, '["plant.q", "ctrl.q"]', '["plnt.q", "ctrl.q"]'), "connections[0]",
        "a reference into the file's own instances"),
    "another paper's metric key": (
        "scenario", lambda t: edit(t, 'control = "ctrl.u"', 'control = "ctrl.u"\nfit_until = 10.0'), "metrics.fit_until",
        "the schema lists every paper's keys; a scenario uses its own paper's"),
    "a uniform high below its low": (
        "campaign", lambda t: edit(t, "high = 1.5", "high = 0.1"), "dispersions.plant.fault_scale.high",
        "one key against another"),
    "a dispersed parameter the scenario lacks": (
        "campaign", lambda t: edit(t, '"plant.fault_scale"', '"plant.fault_scal"'), "dispersions.plant.fault_scal",
        "a reference into the base scenario"),
    "a range whose high is below its low": (
        "arena", lambda t: edit(t, "onset = [1.0, 3.0]", "onset = [3.0, 1.0]"), "dispersions.onset",
        "one element against the other"),
    "a cell of an unknown method": (
        "arena", lambda t: edit(t, 'method = "hinf"\nplant', 'method = "hinff"\nplant'), "cells[0].method",
        "a reference into the file's own tables"),
    "realistic hardware without a gyro": (
        "arena", lambda t: edit(t, 'gyro = "gyro_stim300"\nattitude_sensor = "angle_small"',
                                'attitude_sensor = "angle_small"'), "plants.hang2023.gyro",
        "required only when arena.hardware lists realistic"),
    "a design for another design": (
        "design", lambda t: t, "design", "verify NAME compares design with its NAME"),
    "a parameter the FMU does not declare (run --gains)": (
        "design", lambda t: edit(t, '"L1[1,1]"', '"L9[1,1]"'), "fmu_parameters.Hang2023TSFDO.L9[1,1]",
        "parameters are the scenario's FMU's"),
    "no fmu_parameters (run --gains)": (
        "design", lambda t: re.sub(r', "fmu_parameters": .*\}\}', "}", t), "fmu_parameters",
        "verify reads such a file; run --gains needs them"),
}


def check_known(case, name, text, tmp_path):
    if name == "design" and case == "a design for another design":
        from types import SimpleNamespace

        from orchestrator.cli.design import run_verify

        p = tmp_path / "d.json"
        p.write_text(text)
        return run_verify(SimpleNamespace(name="li2023-observer", gains=str(p)))
    if name == "design":  # what `ftcsim run --gains` reads, over 003's scenario with the TSFDO
        from orchestrator.scenario.overrides import read_gains
        from orchestrator.scenario.toml import load

        p = tmp_path / "d.json"
        p.write_text(text)
        return read_gains(load(ROOT / "papers/p003_hang2023/scenarios/hang2023_asmftc_f04.toml", in_process=True), p)
    return check(name, text, tmp_path)


@pytest.mark.parametrize("case", sorted(KNOWN_DIFFERENCES))
def test_what_only_ftcsim_refuses(case, tmp_path):
    name, make, key, why = KNOWN_DIFFERENCES[case]
    text = make(GOOD[name])
    assert not errors(name, document(name, text)), f"the {name} schema now refuses {case!r}: move it to HOSTILE"
    with pytest.raises(InputError) as e:
        check_known(case, name, text, tmp_path)
    assert e.value.key == key, str(e.value)


def test_what_only_ftcsim_checks_is_said_in_each_schema():
    """The cross-field rules are written in each schema's description, for the editor's hover."""
    for name in FORMATS:
        text = json.loads(shipped_file(name).read_text())["description"]
        assert "Checked by ftcsim, not by this schema:\n- " in text, name


# -- Taplo (VS Code's Even Better TOML) with the repository's .taplo.toml ----------------------------------------------
def taplo() -> str:
    exe = shutil.which("taplo") or str(Path(sys.executable).parent / "taplo")
    if not Path(exe).is_file():
        pytest.skip("taplo is not installed (pip install taplo: the test extra has it)")
    return exe


def test_taplo_checks_the_shipped_files_with_the_shipped_schemas():
    files = [str(p.relative_to(ROOT)) for _, globs in SHIPPED.items() for g in globs for p in sorted(ROOT.glob(g))]
    r = subprocess.run([taplo(), "check", "--colors", "never", "--no-auto-config", "--config", ".taplo.toml", *files], cwd=ROOT,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and "error: " not in r.stderr, r.stderr[-2000:]


@pytest.mark.parametrize("name,klass,where", [
    ("scenario", "NaN", "papers/p000_li2023/scenarios"), ("campaign", "out of range", "campaigns"),
    ("arena", "wrong enum value", "arena"), ("scenario", "unknown key", "arena/scenarios")])
def test_taplo_refuses_a_hostile_file_in_a_shipped_folder(name, klass, where, tmp_path):
    """The .taplo.toml rules give each shipped folder its schema: a hostile file there is refused by Taplo (a
    TOML nan reaches the schema as null, which is not a number)."""
    folder = tmp_path / where
    folder.mkdir(parents=True)
    shutil.copy(ROOT / ".taplo.toml", tmp_path)
    shutil.copytree(ROOT / "orchestrator" / "schemas", tmp_path / "orchestrator" / "schemas")
    (folder / "hostile.toml").write_text(HOSTILE[(name, klass)][0](GOOD[name]))
    r = subprocess.run([taplo(), "check", "--colors", "never", f"{where}/hostile.toml"], cwd=tmp_path, capture_output=True, text=True,
                       timeout=60)
    assert r.returncode != 0 and "error: " in r.stderr, r.stderr[-2000:]  # (its log lines come and go)


def test_finite_refuses_nan_and_infinities_in_python_too():
    """$defs/finite: the bounds refuse the infinities, the `not` clause refuses NaN (jsonschema, Python)."""
    v = Draft202012Validator({"$defs": json.loads(shipped_file("arena").read_text())["$defs"],
                              "$ref": "#/$defs/finite"})
    assert [v.is_valid(x) for x in (0.0, -1e308, 1.5, 7, math.nan, math.inf, -math.inf, "1")] == \
        [True, True, True, True, False, False, False, False]


# -- every key of rich documents, mutated: the declaration and its schema agree ---------------------------------------
def _rich_scenario() -> dict:
    doc = tomllib.loads(SCENARIO)
    doc["instances"]["plant"]["parameters"] = {"q_init": [0.8, 0.3, 0.2, -0.4], "fault_onset": 40.0}  # one of each
    doc["instances"]["ctrl"]["parameters"] = {"k_p": 20.0}
    doc["timing"].update(step_policy="adaptive", rtol=1e-6, atol=1e-8, min_step=1e-4, max_step=0.01, output_step=0.01,
                         safety=0.9, error_variables=["plant.q"], record_announced=False, time_limit=60.0)
    doc["instances"]["ctrl"].update(step=0.02, announces=["u"])
    doc["sources"]["hold"] = {"type": "constant", "to": "ctrl.omega_d", "value": [0.0, 0.0, 0.0]}
    return doc  # no extends: the declaration checks a document with its base merged in


def _rich_design() -> dict:
    return {**json.loads(DESIGN), "source": "003 Theorem 1", "settings": {"W": [1.0], "objective": "max"},
            "performance": {"alpha": 0.8, "error_abscissa": [-1.0, -2.0]}, "cases": [{"K": [[1.0, 2.0]], "j": 0.75}],
            "solver": "CLARABEL"}


RICH_CAMPAIGN = CAMPAIGN.replace("runs = 2", """runs = 2
name = "rich"
description = "every key"
seed = 3
fmu_dir = "fmus"
start = 0.0
step = 0.01
gains = ["a.json"]
trajectories = ["ctrl.q_e"]
trajectory_step = 0.05
time_limit = 60.0""") + """shared = false
apply = "scale"

[dispersions."plant.q_init"]
distribution = "normal"
mean = [0.8, 0.3, 0.2, -0.4]
std = 0.01

[dispersions."ctrl.k_p"]
distribution = "choice"
values = [10.0, 20.0]
weights = [1.0, 2.0]

[dispersions."faults.seed"]
distribution = "integer"
low = 0
high = 10

[parameters]
"plant.fault_onset" = 30.0

[grid]
"ctrl.k_d" = [40.0, 60.0]

[[variants]]
name = "pd"
scenario = "li2023_pd"
gains = ["b.json"]
fmu = { ctrl = "PDController" }
parameters = { "ctrl.beta" = 2.0 }

[settling]
signal = "ctrl.q_e"
level = 0.01
from = 1.0

[requirements]
final_attitude_error = { max = 1e-3, min = 0.0 }
"""
RICH = {  # format -> a document with every key of its format, each of them mutated
    "scenario": _rich_scenario, "campaign": lambda: tomllib.loads(RICH_CAMPAIGN), "arena": lambda: tomllib.loads(ARENA),
    "design": _rich_design,
}
VALUES = ("x", "", math.nan, math.inf, True, 0, -1, 2.0, 1e300, [], {}, [[[[[1.0]]]]])
DECLARED_ONLY = {  # what the declaration checks that JSON Schema cannot say: a fragment of the message -> why
    "expected a whole number, got float": "JSON Schema's integer holds 2.0 and 1e300 (KNOWN_DIFFERENCES)",
    " < low ": "an interval's high against its low",
}
UNKNOWN = "zz_unknown"


def _paths(node, path=()):
    """Every value's path (into lists: their first element only)."""
    if path:
        yield path
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, path + (k,))
    elif isinstance(node, list) and node:
        yield from _paths(node[0], path + (0,))


def _mutants(doc):
    for path in _paths(doc):
        *head, last = path
        for value in VALUES + ("delete",):
            new = copy.deepcopy(doc)
            parent = new
            for p in head:
                parent = parent[p]
            if value == "delete":
                if isinstance(parent, dict):
                    del parent[last]
                    yield path, value, new
                continue
            parent[last] = value
            yield path, value, new
        target = doc
        for p in path:
            target = target[p]
        if isinstance(target, dict):
            new = copy.deepcopy(doc)
            node = new
            for p in path:
                node = node[p]
            node[UNKNOWN] = 1.0
            yield path, UNKNOWN, new


@pytest.mark.parametrize("name", sorted(FORMATS))
def test_the_declaration_and_its_schema_agree_on_every_key(name):
    """Every key of rich documents replaced by a string, an empty string, NaN, inf, a boolean, 0, -1, 2.0, 1e300,
    an empty array and table, arrays nested 5 deep, or deleted, and an unknown key added to every table: the
    declaration (what ftcsim checks first) refuses exactly what the schema generated from it refuses, but for
    DECLARED_ONLY."""
    fmt, v = FORMATS[name](), validator(name)  # the scenario format of every paper's metrics, as its schema
    mismatches, n = [], 0
    doc = RICH[name]()
    assert v.is_valid(doc)
    fmt.check("doc", doc)
    for path, value, new in _mutants(doc):
        n += 1
        try:
            fmt.check("doc", new)
            ours = None
        except InputError as e:
            ours = e.problem
        theirs = v.is_valid(new)
        if theirs == (ours is None) or (theirs and any(fragment in ours for fragment in DECLARED_ONLY)):
            continue
        mismatches.append((dotted(path), value, ours or "accepted", "schema accepts" if theirs else "schema refuses"))
    assert not mismatches, mismatches[:40]
    assert n > 300, n
