"""Property-based: random mutations of a shipped campaign file (campaigns/li2023_methods.toml: values
of every type, unknown keys, hostile names, tables removed or renamed, in [campaign], the
dispersions, the variants) never crash `ftcsim campaign`. For every one: exit status 0, 1 or 2 only,
no traceback and no internal error, exactly one stderr line and no campaign folder on exit 2.
Each example computes run 0 only (``--run 0``), in-process, under a 5 s time limit per run."""
import copy
import tomllib
from pathlib import Path

import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_property import names, values

from orchestrator.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
BASE = tomllib.loads((ROOT / "campaigns" / "li2023_methods.toml").read_text(encoding="utf-8"))
BASE["campaign"].update(mode="inprocess", runs=2, stop=0.1)  # short runs when the mutation leaves them valid
BASE["campaign"].pop("description", None)


def _paths(node, prefix=()):
    """Every (path, value) under ``node``: keys of tables and items of lists of tables."""
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for k, v in items:
        yield prefix + (k,), v
        if isinstance(v, dict) or (isinstance(v, list) and v and all(isinstance(x, dict) for x in v)):
            yield from _paths(v, prefix + (k,))


@st.composite
def campaigns(draw):
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
        elif action == "add" and isinstance(parent[path[-1]], dict):
            parent[path[-1]][draw(names)] = draw(values)
        elif isinstance(parent, dict):
            parent[draw(names)] = parent.pop(path[-1])
    return doc


@settings(max_examples=40, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(doc=campaigns())
def test_random_campaign_files_give_a_result_or_one_line(doc, tmp_path_factory, capsys, fmu_dir):
    try:
        text = tomli_w.dumps(doc)
    except (TypeError, ValueError):
        return  # not representable in TOML
    work = tmp_path_factory.mktemp("propc")
    path = work / "c.toml"
    path.write_text(text, encoding="utf-8")
    out = work / "out"
    try:
        rc = main(["campaign", str(path), "--out", str(out), "--workers", "0", "--quiet", "--run", "0",
                   "--time-limit", "5"])
    except SystemExit as e:
        rc = e.code
    err = capsys.readouterr().err
    assert rc in (0, 1, 2), (rc, err, text)
    assert "Traceback" not in err and "internal error" not in err, (err, text)
    if rc == 2:
        assert len(err.strip().splitlines()) == 1 and not out.exists(), (err, text)
