"""The arena as one plan (arena/plan.py) and its folder (arena/app.py), without running anything:
deterministic runs planned once, each cell's digest covering what decides its runs, a changed input
refused (naming the cell and what changed) or recomputed with --overwrite, never mixed in."""
import json

import pytest

from arena import app
from arena import plan as P
from arena.arenafile import load
from orchestrator.api import InputError
from tests.arena.reduced import write


@pytest.fixture
def reduced(tmp_path):
    path = write(tmp_path)
    return path, load(path)


def test_deterministic_runs_are_planned_once(reduced):
    _, arena = reduced
    plans = P.build(arena)
    assert len(plans) == 6
    for p in plans:
        kinds = {g.kind: g for g in p.groups}
        if p.hardware == "ideal":  # no fault, no sensor noise: no drawn number reaches the run
            assert kinds["single"].faults == ["none"] and kinds["single"].runs == 1
            assert kinds["draws"].faults == ["bias"] and kinds["draws"].runs == 2
            assert "dispersions" not in p.campaigns["single"] and "dispersions" in p.campaigns["draws"]
        else:  # sensor noise: the fault-free runs are draws too
            assert list(kinds) == ["draws"] and kinds["draws"].faults == ["none", "bias"]
            assert {"gyro.seed", "faults.onset"} <= set(p.campaigns["draws"]["dispersions"])
        assert p.scenario["timing"]["stop"] == arena.mission(p.cell) == 6.0  # the arena's stop cut
    assert sum(g.runs * len(g.faults) for p in plans for g in p.groups) == arena.n_runs - 3


def test_a_cell_whose_inputs_changed_is_refused_or_recomputed(reduced, tmp_path):
    path, arena = reduced
    plans = P.build(arena)
    out = tmp_path / "out"
    assert app.check_folder(arena, plans, out, overwrite=False) == []
    app.publish(arena, plans, out, [])
    assert app.check_folder(arena, plans, out, overwrite=False) == []  # the same inputs: resumed
    record = json.loads((out / "cells" / "hinf_on_hang2023.ideal" / "cell.json").read_text())
    assert record["digest"] == plans[0].digest and set(record["parts"]) == {"scenario", "campaigns", "mode", "models"}
    # the cell's scenario file changes: its two cells are refused, naming what changed
    scen = tmp_path / "scenarios" / "arena_hinf_on_hang2023.toml"
    scen.write_text(scen.read_text().replace("theta_init = 0.08", "theta_init = 0.07"))
    changed = P.build(load(path))
    with pytest.raises(InputError) as e:
        app.check_folder(arena, changed, out, overwrite=False)
    assert e.value.key == "--out" and "hinf_on_hang2023" in e.value.problem and "its scenario" in e.value.problem
    assert "--overwrite" in e.value.problem
    again = app.check_folder(arena, changed, out, overwrite=True)
    assert sorted(p.name for p in again) == ["hinf_on_hang2023.ideal", "hinf_on_hang2023.realistic"]
    # more draws: the campaigns change; another mode: the models change
    with pytest.raises(InputError, match="draws, seed"):
        app.check_folder(arena, P.build(load(path, draws=3)), out, overwrite=False)
    with pytest.raises(InputError, match="the mode"):
        app.check_folder(arena, P.build(load(path, mode="fmu")), out, overwrite=False)


def test_folders_that_are_not_an_arena_are_refused(reduced, tmp_path):
    _, arena = reduced
    plans = P.build(arena)
    out = tmp_path / "out"
    out.mkdir()
    (out / "precious.txt").write_text("mine")
    with pytest.raises(InputError, match="not an arena folder"):
        app.check_folder(arena, plans, out, overwrite=True)
    link = tmp_path / "link"
    link.symlink_to(out)
    with pytest.raises(InputError, match="symbolic link"):
        app.check_folder(arena, plans, link, overwrite=True)
    old = tmp_path / "old"
    old.mkdir()
    (old / "arena.json").write_text(json.dumps({"arena": "x", "arena_sha256": "0"}))  # issue 26's folders
    with pytest.raises(InputError, match="another ftcsim version"):
        app.check_folder(arena, plans, old, overwrite=True)
