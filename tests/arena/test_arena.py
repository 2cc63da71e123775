"""``ftcsim arena`` end to end on a reduced arena (tests/arena/reduced.py: 3 cells x 2 hardware x 3
actuator-fault classes x 2 draws, 6 s, in-process; 33 runs: the three fault-free ideal runs are
deterministic, computed once; with two sensor-fault classes on the realistic cells that have the
sensor, 10 runs, and the wheel loss of fasmc_on_zhang2019 flown with its chain closed, 4 runs): the
leaderboard opens in headless Chromium with every image and table and passes the legibility checks
at 1400 x 900 (the summary on the first screen, no image scaled down, no table wider than the page,
no label outside its figure), the FDIR tables carry every chain, its calibration and the closed loop
whose replay equals the loop, the Parquet tables hold one row per run,
realistic wheels never exceed their torque bound at the plant, the accuracy verdict is the one
recomputed from the runs, draw k is the same random numbers in every cell, a rerun computes nothing,
and the FMUs through a Dask client give the same leaderboard as the blocks in process on a slice."""
import numpy as np
import pandas as pd
import pytest

from arena import leaderboard
from arena.app import measure_all
from arena.arenafile import load
from arena.plan import build
from orchestrator.api import read_table
from orchestrator.cli.main import main
from plant.hardware.datasheets import WHEELS
from plant.hardware.wheels import torque_bound
from tests.arena.reduced import ARENA, write

pytestmark = pytest.mark.slow
FAULTS = ARENA.replace('faults = ["none", "bias"]', 'faults = ["none", "bias", "lost", "gyro_bias", "st_outage"]')


@pytest.fixture(scope="module")
def arena_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("arena")
    path = write(folder, FAULTS)
    out = folder / "out"
    assert main(["arena", str(path), "--out", str(out), "--workers", "0", "--quiet"]) == 0
    return load(path), out


def test_tables_hold_one_row_per_run_with_units(arena_run):
    arena, out = arena_run
    runs = read_table(out / "tables" / "runs.parquet")
    act = runs[~runs["sensor_fault"]]
    assert len(act) == arena.n_runs - 3 == 33  # the deterministic fault-free ideal runs once per cell
    assert runs.loc[runs["deterministic"], "fault"].eq("none").all() and runs["deterministic"].sum() == 3
    keys = runs[["method", "plant", "hardware", "fault", "draw"]].drop_duplicates()
    assert len(keys) == len(runs) == 33 + 10  # gyro faults on 3 realistic cells, star-tracker ones on 2 (no pitch)
    sensor = runs[runs["sensor_fault"]]
    assert set(sensor["hardware"]) == {"realistic"} and not sensor["within_claims"].any()
    assert set(sensor.loc[sensor["plant"] == "hang2023", "fault"]) == {"gyro_bias"}
    assert runs.attrs["units"]["time_to_band"] == "s" and runs.attrs["units"]["attitude_error_rms_after"] == "rad"
    assert set(runs["outcome"]) <= {"flies", "not settled", "saturated", "diverged", "stopped"}  # no run failed
    assert runs["peak_torque"].notna().all() and runs["peak_momentum"].notna().all()
    assert runs.loc[runs["hardware"] == "ideal", "buildable"].notna().all()
    for name in ("summary", "outcomes", "metrics", "paired", "chains", "curves", "closed", "closed_runs",
                 "sensor_faults", "fdir_runs", "accuracy", "feasibility", "wheel_limit"):
        assert len(read_table(out / "tables" / f"{name}.parquet")) > 0, name


def test_every_chain_is_calibrated_and_the_closed_loop_replays_exactly(arena_run):
    arena, out = arena_run
    ch = read_table(out / "tables" / "chains.parquet")
    assert len(ch) == 2 * 3 and set(ch["detector"]) == {"cusum", "glr", "chi2"}  # fasmc's estimate x hardware
    assert ch["h"].notna().all() and not ch["certified"].any()  # 6 s missions: too few hours to certify anything
    assert ch.loc[ch["hardware"] == "ideal", "deterministic"].all() and not ch.loc[ch["hardware"] == "realistic",
                                                                                  "deterministic"].any()
    assert ch.loc[ch["hardware"] == "ideal", "meets_target"].isna().all()  # one deterministic run: undetermined
    assert (ch["false_alarms"] == 0).all()  # the rule: no calibration draw alarms at its threshold
    closed = read_table(out / "tables" / "closed.parquet")
    assert list(closed["hardware"]) == ["ideal", "realistic"] and (closed["runs"] == 2).all()
    assert (closed["replay_matches"] == closed["replayed"]).all() and closed["replayed"].sum() >= 2
    fr = read_table(out / "tables" / "fdir_runs.parquet")
    free = fr[(fr["fault"] == "none") & (fr["loop"] == "open")]
    for r in ch.itertuples():  # the chain's in-sample count is the sum of its fault-free runs' counts
        f = free[(free["cell"] == r.cell) & (free["hardware"] == r.hardware) & (free["detector"] == r.detector)]
        assert int(f["false_alarms"].sum()) == r.false_alarms and len(f) == r.fault_free_runs
    sf = read_table(out / "tables" / "sensor_faults.parquet")
    assert set(sf["fault"]) == {"gyro_bias", "st_outage"}


def test_leaderboard_is_legible_in_headless_chromium(arena_run):
    from tests.browser import legibility, open_page, require_browser

    require_browser()
    arena, out = arena_run
    seen = open_page(out / "leaderboard.html")
    assert seen.console_errors == [] and seen.broken_images == []
    assert seen.images == 4  # who flies what, one per plant, the operating curves (realistic hardware)
    captions = " ".join(seen.tables)
    for name in ("Summary", "outcomes on zhang2019", "metrics on hang2023", "accuracy kept", "FDIR chains",
                 "calibration of each chain", "chain closed", "sensor faults", "cells"):
        assert name in captions, name
    view = legibility(out / "leaderboard.html", 1400, 900)
    assert view.wide_images == [] and view.wide_tables == [], (view.wide_images, view.wide_tables)
    assert view.page_width <= view.width
    assert view.first["caption"].startswith("Summary") and view.first["bottom"] <= 900  # on the first screen
    lb = leaderboard.build(arena, measure_all(arena, build(arena), out))
    try:
        assert lb["clipped"] and all(v == [] for v in lb["clipped"].values()), lb["clipped"]
    finally:
        import matplotlib.pyplot as plt

        for f in lb["figures"].values():
            plt.close(f)


def test_realistic_wheels_never_exceed_their_bound_at_the_plant(arena_run):
    arena, out = arena_run
    checked = 0
    for folder in sorted((out / "cells").glob("*.realistic")):
        plant = folder.name.split("_on_")[1].split(".")[0]
        p = WHEELS[arena.plants[plant].hardware["wheels"]]
        bound = torque_bound(p["tau_max"], p["coulomb"], p["viscous"], p["h_max"], p["I_w"])
        df = pd.read_parquet(folder / "draws" / "trajectories")
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
    own = runs[(runs["method"] == "hinf") & (runs["outcome"] != "failed") & runs["within_claims"]]
    med, share = {}, {}
    for hw in ("ideal", "realistic"):
        g = own[own["hardware"] == hw]
        fly = g.loc[g["outcome"] == "flies", "attitude_error_rms_after"].dropna()
        med[hw], share[hw] = (float(np.median(fly)) if len(fly) else None), len(fly) / len(g)
    assert med["ideal"] is not None  # the reference pair settles with ideal hardware
    keeps = (med["realistic"] is not None and med["realistic"] / med["ideal"] <= arena.accuracy_tolerance
             and share["realistic"] >= share["ideal"] - 0.1)
    acc = read_table(out / "tables" / "accuracy.parquet")
    assert bool(acc[acc["method"] == "hinf"].iloc[0]["keeps_accuracy"]) == keeps
    text = (out / "leaderboard.html").read_text()
    assert ("Keep their paper&#x27;s accuracy with realistic hardware: " + ("hinf" if keeps else "none")) in text


def test_draw_k_is_the_same_numbers_in_every_cell(arena_run):
    _, out = arena_run
    runs = read_table(out / "tables" / "runs.parquet")
    faulty = runs[runs["fault"] == "bias"]
    sensor = runs[runs["fault"] == "gyro_bias"]  # sensor-fault draw k has fault-free draw k's noise
    free = runs[(runs["fault"] == "none") & (runs["hardware"] == "realistic")]
    assert sensor.groupby("draw")["onset"].nunique().eq(1).all() and sensor["onset"].nunique() == 2
    assert set(sensor["draw"]) == set(free["draw"])
    for (hw, draw), g in faulty.groupby(["hardware", "draw"]):
        assert g["onset"].nunique() == 1 and g["loss"].nunique() == 1, (hw, draw)
    assert faulty.groupby("draw")["onset"].first().nunique() == 2  # two draws, two onsets
    paired = read_table(out / "tables" / "paired.parquet")
    assert set(paired["a"]) | set(paired["b"]) == {"fasmc", "pd"}


def test_rerun_resumes_and_computes_nothing(arena_run):
    arena, out = arena_run
    stored = sorted(p.name for p in out.glob("cells/*/*/runs/*.parquet"))
    before = {p: p.stat().st_mtime_ns for p in out.glob("cells/*/*/runs/*.parquet")}
    assert main(["arena", str(arena.path), "--out", str(out), "--workers", "0", "--quiet"]) == 0
    assert sorted(p.name for p in out.glob("cells/*/*/runs/*.parquet")) == stored
    assert all(p.stat().st_mtime_ns == t for p, t in before.items())


def test_fmus_through_a_dask_client_give_the_same_leaderboard_as_the_blocks(tmp_path, fmu_dir):
    """The same slice in process without Dask and with the FMUs on a LocalCluster through ``client=``."""
    from distributed import Client, LocalCluster

    from arena.app import run_arena

    path = write(tmp_path)
    slice_ = dict(only=["hinf_on_hang2023", "fasmc_on_zhang2019"], stop=2.0, draws=2,
                  faults=["none", "bias", "lost", "gyro_bias"])
    run_arena(path, tmp_path / "blocks", workers=0, **slice_)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        run_arena(path, tmp_path / "fmus", client=client, mode="fmu", **slice_)
    for name in ("summary", "outcomes", "metrics", "feasibility", "chains", "closed", "sensor_faults"):
        a = read_table(tmp_path / "blocks" / "tables" / f"{name}.parquet")
        b = read_table(tmp_path / "fmus" / "tables" / f"{name}.parquet")
        pd.testing.assert_frame_equal(a, b, check_exact=False, rtol=1e-9, atol=1e-12)
