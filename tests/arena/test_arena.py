"""``ftcsim arena`` end to end on a reduced arena (tests/arena/reduced.py: 3 cells x 2 hardware x 2
fault classes x 2 draws, 6 s, in-process): the leaderboard opens in headless Chromium with every
image and table, the Parquet tables hold one row per run, realistic wheels never exceed their
torque bound at the plant, the accuracy verdict is the one recomputed from the runs, and draw k is
the same random numbers in every cell."""
import numpy as np
import pandas as pd
import pytest

from arena.arenafile import load
from arena.leaderboard import build, sections
from orchestrator.api import read_table
from orchestrator.cli.main import main
from plant.hardware.datasheets import WHEELS
from plant.hardware.wheels import torque_bound
from tests.arena.reduced import write

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def arena_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("arena")
    path = write(folder)
    out = folder / "out"
    assert main(["arena", str(path), "--out", str(out), "--workers", "0", "--quiet"]) == 0
    return load(path), out


def test_tables_hold_one_row_per_run_with_units(arena_run):
    arena, out = arena_run
    runs = read_table(out / "tables" / "runs.parquet")
    assert len(runs) == arena.n_runs == 24
    keys = runs[["method", "plant", "hardware", "fault", "draw"]].drop_duplicates()
    assert len(keys) == 24
    assert runs.attrs["units"]["time_to_band"] == "s" and runs.attrs["units"]["pointing_rms_after"] == "rad"
    assert set(runs["outcome"]) <= {"flies", "not settled", "saturated", "diverged", "stopped"}  # no run failed
    for name in ("outcomes", "ranking", "paired", "false_alarms", "accuracy", "wheel_limit"):
        assert len(read_table(out / "tables" / f"{name}.parquet")) > 0, name


def test_leaderboard_opens_in_headless_chromium_with_every_image_and_table(arena_run):
    from tests.browser import open_page, require_browser

    require_browser()
    arena, out = arena_run
    runs = read_table(out / "tables" / "runs.parquet")
    lb = build(arena, runs)
    items = [i for _, _, its in sections(arena, lb) for i in its]
    seen = open_page(out / "leaderboard.html")
    assert seen.console_errors == [] and seen.broken_images == []
    assert seen.images == sum(k == "figure" for k, _, _ in items) == 3  # who flies what, one per plant
    assert len(seen.tables) == sum(k == "table" for k, _, _ in items)
    captions = " ".join(seen.tables)
    for name in ("cells", "accuracy", "wheel_limit", "paired", "false_alarms", "ranking hang2023 ideal time_to_band",
                 "ranking zhang2019 realistic control_energy", "outcomes zhang2019 bias"):
        assert name in captions, name


def test_realistic_wheels_never_exceed_their_bound_at_the_plant(arena_run):
    arena, out = arena_run
    checked = 0
    for folder in sorted((out / "cells").glob("*.realistic")):
        plant = folder.name.split("_on_")[1].split(".")[0]
        p = WHEELS[arena.plants[plant].hardware["wheels"]]
        bound = torque_bound(p["tau_max"], p["coulomb"], p["viscous"], p["h_max"], p["I_w"])
        df = pd.read_parquet(folder / "run" / "trajectories")
        u = df[[c for c in df.columns if c.startswith("wheels.u_wheel")]].to_numpy()
        assert np.abs(u).max() <= bound + 1e-12, folder.name
        assert np.abs(u).max() > 0.9 * p["tau_max"], folder.name  # the methods ask more: the limit acts
        checked += 1
    assert checked == 3
    wl = read_table(out / "tables" / "wheel_limit.parquet")
    assert wl["within"].all() and len(wl) == 3


def test_accuracy_verdict_is_the_one_recomputed_from_the_runs(arena_run):
    arena, out = arena_run
    runs = read_table(out / "tables" / "runs.parquet")
    own = runs[(runs["method"] == "hinf") & (runs["outcome"] != "failed")]
    med, share = {}, {}
    for hw in ("ideal", "realistic"):
        g = own[own["hardware"] == hw]
        fly = g.loc[g["outcome"] == "flies", "pointing_rms_after"].dropna()
        med[hw], share[hw] = (float(np.median(fly)) if len(fly) else None), len(fly) / len(g)
    assert med["ideal"] is not None  # the reference pair settles with ideal hardware
    keeps = (med["realistic"] is not None and med["realistic"] / med["ideal"] <= arena.accuracy_tolerance
             and share["realistic"] >= share["ideal"] - 0.1)
    acc = read_table(out / "tables" / "accuracy.parquet")
    row = acc[acc["method"] == "hinf"].iloc[0]
    assert bool(row["keeps_accuracy"]) == keeps
    text = (out / "leaderboard.html").read_text()
    verdict = ("Keep their paper&#39;s accuracy with realistic hardware: hinf." if keeps
               else "Do not: hinf.")
    assert verdict in text.replace("'", "&#39;")


def test_draw_k_is_the_same_numbers_in_every_cell(arena_run):
    _, out = arena_run
    runs = read_table(out / "tables" / "runs.parquet")
    faulty = runs[runs["fault"] == "bias"]
    for (hw, draw), g in faulty.groupby(["hardware", "draw"]):
        assert g["onset"].nunique() == 1 and g["loss"].nunique() == 1, (hw, draw)
    assert faulty.groupby("draw")["onset"].first().nunique() == 2  # two draws, two onsets
    # the paired comparisons pair the same draws
    paired = read_table(out / "tables" / "paired.parquet")
    assert set(paired["a"]) | set(paired["b"]) == {"fasmc", "pd"}


def test_rerun_resumes_and_computes_nothing(arena_run, capsys):
    arena, out = arena_run
    before = (out / "tables" / "runs.parquet").stat().st_mtime_ns
    stored = sorted(p.name for p in out.glob("cells/*/run/runs/*.parquet"))
    assert main(["arena", str(arena.path), "--out", str(out), "--workers", "0", "--quiet"]) == 0
    assert sorted(p.name for p in out.glob("cells/*/run/runs/*.parquet")) == stored
    assert (out / "tables" / "runs.parquet").stat().st_mtime_ns >= before
