"""Property-based: random scenario files (values of every type, unknown keys, hostile names, tables
removed or renamed) never crash the command line. For every one: exit status 0, 1 or 2 only, no
traceback and no internal error, exactly one stderr line on exit 2, nothing created or removed
outside --out, no temporary folder left behind, and a strict-JSON metrics.json when it ran."""
import copy
import json
import tempfile
import tomllib

import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scenario_text import PD

from orchestrator.cli.main import main

BASE = tomllib.loads(PD)
BASE["timing"]["stop"] = 0.3  # keep every valid example short

names = st.one_of(
    st.sampled_from(["name", "stop", "step", "start", "fmu", "k_p", "parameters", "to", "times", "values",
                     "variables", "control", "u_max", "extends", "paper", "exchange", "parameter_set",
                     "../x", "a/b", "", " ", "é", "q[0]", "x" * 70, "plant", "ctrl"]),
    st.text(max_size=8),
)
scalars = st.one_of(
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([0.0, -1.0, 0.01, 0.02, 0.1, 0.3, 1.0, 2.0, 1e300, -1e-300, 5e-324]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["", "x", "../../etc", "/abs/path", "PDController", "FlexibleSpacecraft", "li2023", "xu2024",
                     "plant.q", "ctrl.u", "ctrl.k_p", "plant.omega[1]", "ordered", "jacobi", "li2023_fasmc",
                     "Broken.fmu", "\x01", "日本"]),
    st.text(max_size=10),
)
values = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.dictionaries(names, inner, max_size=3)), max_leaves=8)


def _paths(doc, prefix=()):
    """Every (path, value) of the document (tables and their keys)."""
    for k, v in doc.items():
        yield prefix + (k,), v
        if isinstance(v, dict):
            yield from _paths(v, prefix + (k,))


@st.composite
def scenarios(draw):
    doc = copy.deepcopy(BASE)
    for _ in range(draw(st.integers(1, 4))):
        paths = list(_paths(doc))
        if not paths:
            break
        path, _ = draw(st.sampled_from(paths))
        parent = doc
        for k in path[:-1]:
            parent = parent[k]
        action = draw(st.sampled_from(["replace", "replace", "delete", "add", "rename"]))
        if action == "replace":
            parent[path[-1]] = draw(values)
        elif action == "delete":
            del parent[path[-1]]
        elif action == "add":
            target = parent[path[-1]] if isinstance(parent[path[-1]], dict) else parent
            target[draw(names)] = draw(values)
        else:
            parent[draw(names)] = parent.pop(path[-1])
    return doc


def _snapshot(folder, skip):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if skip not in p.parts)


def _check(doc, tmp_path_factory, capsys, mode):
    work = tmp_path_factory.mktemp("prop")
    tmpdir = work / "tmp"
    tmpdir.mkdir()
    try:
        text = tomli_w.dumps(doc)
    except (TypeError, ValueError):
        return  # not representable in TOML (e.g. an empty key path): nothing to test
    scen = work / "case.toml"
    scen.write_text(text, encoding="utf-8")
    out = work / "out"
    before = _snapshot(work, "out")
    saved = tempfile.tempdir
    tempfile.tempdir = str(tmpdir)
    try:
        try:
            rc = main(["run", str(scen), "--out", str(out), "--quiet", "--no-plots", "--mode", mode])
        except SystemExit as e:
            rc = e.code
    finally:
        tempfile.tempdir = saved
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert rc in (0, 1, 2), (rc, err, text)
    assert "Traceback" not in err and "internal error" not in err, (err, text)
    if rc == 2:
        assert len(lines) == 1 and not out.exists(), (lines, text)
    assert _snapshot(work, "out") == before, text  # nothing outside --out created or removed
    assert list(tmpdir.iterdir()) == [], text
    if rc == 0:
        json.loads((out / "metrics.json").read_text(), parse_constant=lambda c: pytest.fail(f"{c} in metrics.json"))


@settings(max_examples=120, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(doc=scenarios())
def test_random_scenarios_in_process(doc, tmp_path_factory, capsys, fmu_dir):
    _check(doc, tmp_path_factory, capsys, "inprocess")


@pytest.mark.fmu
@settings(max_examples=25, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(doc=scenarios())
def test_random_scenarios_with_fmus(doc, tmp_path_factory, capsys, fmu_dir):
    _check(doc, tmp_path_factory, capsys, "fmu")
