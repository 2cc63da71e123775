"""The campaign report (orchestrator/campaign/report.py): grid points kept apart, no empty rows,
failed runs listed with their error and never ranked, units in the headers, Markdown tables that
parse as tables, and report.html checked in headless Chromium."""
import json

import numpy as np
import pandas as pd
import pytest
from markdown_it import MarkdownIt

from orchestrator.campaign.report import make_report
from orchestrator.campaign.run import run_campaign
from orchestrator.campaign.store import SUMMARY
from tests.browser import Browser, require_browser
from tests.unit_spelling import misspelt, misspelt_units

CAMPAIGN = """
[campaign]
scenario = "li2023_pd"
mode = "inprocess"
runs = 2
seed = 5
stop = 0.3
trajectories = ["ctrl.q_e"]
trajectory_step = 0.1

[dispersions."plant.fault_scale"]
distribution = "uniform"
low = 0.2
high = 1.5

[[variants]]
name = "pd"

[[variants]]
name = "stiff"
[variants.parameters]
"ctrl.k_p" = 40.0

[grid]
"ctrl.k_d" = [30.0, 90.0]

[requirements]
control_energy = { max = 1e9 }
"""


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """A finished campaign (2 variants x 2 grid points x 2 draws, in-process, 0.3 s) whose run 1 is
    then marked failed with a control energy that would rank it best and worst."""
    tmp = tmp_path_factory.mktemp("campaign")
    (tmp / "c.toml").write_text(CAMPAIGN, encoding="utf-8")
    out = tmp / "out"
    run_campaign(tmp / "c.toml", out, workers=0)
    df = pd.read_parquet(out / SUMMARY)
    clean = df.copy()
    df["error"] = df["error"].astype(object)
    df.loc[df.run_id == 1, ["status", "error", "control_energy"]] = ["failed", "diverged | at 0.1 s", 1e12]
    df.to_parquet(out / SUMMARY, index=False)
    rep = tmp / "rep"
    rep.mkdir()
    return clean, make_report(out, rep), rep


def _tables(md: str) -> list:
    """[(header cells, [row cells])] of every table markdown-it finds in ``md``."""
    tables, cur, row = [], None, None
    for t in MarkdownIt("commonmark").enable("table").parse(md):
        if t.type == "table_open":
            cur = []
        elif t.type == "tr_open":
            row = []
        elif t.type == "inline" and row is not None:
            row.append(t.content)
        elif t.type == "tr_close":
            cur.append(row)
            row = None
        elif t.type == "table_close":
            tables.append((cur[0], cur[1:]))
    return tables


def test_grid_points_are_groups_and_failed_runs_are_not_statistics(campaign):
    clean, data, _ = campaign
    energy = {(r["group"]): r for r in data["statistics"] if r["metric"] == "control_energy"}
    assert sorted(energy) == ["pd @ ctrl.k_d = 30", "pd @ ctrl.k_d = 90", "stiff @ ctrl.k_d = 30", "stiff @ ctrl.k_d = 90"]
    for (variant, point), g in clean.groupby(["variant", "point"]):
        x = g.loc[g.run_id != 1, "control_energy"].to_numpy(float)  # run 1 failed: left out
        row = energy[f"{variant} @ ctrl.k_d = {[30, 90][point]}"]
        assert row["n"] == len(x) and row["mean"] == pytest.approx(x.mean()) and row["max"] == x.max()
    assert all(r["n"] > 0 for r in data["statistics"])  # no empty rows
    # the gain changes the energy: pooling the points would have hidden a real difference
    assert energy["pd @ ctrl.k_d = 30"]["mean"] != pytest.approx(energy["pd @ ctrl.k_d = 90"]["mean"], rel=1e-3)
    assert data["failed"] == [1]
    assert all(1 not in ids for ids in data["worst"].values())
    pairs = {r["group"]: r for r in data["paired"] if r["metric"] == "control_energy"}
    assert pairs["stiff @ ctrl.k_d = 30"]["reference"] == "pd @ ctrl.k_d = 30"
    assert pairs["stiff @ ctrl.k_d = 30"]["pairs"] == 1 and pairs["stiff @ ctrl.k_d = 90"]["pairs"] == 2  # run 1 failed
    req = {r["group"]: r for r in data["requirements"] if r["requirement"] == "control_energy"}
    assert req["pd @ ctrl.k_d = 30"]["passed"] == 1 and req["pd @ ctrl.k_d = 30"]["failed"] == 1


def test_markdown_stays_valid_with_units_and_the_failure_listed(campaign):
    _, data, rep = campaign
    md = (rep / "report.md").read_text(encoding="utf-8")
    tables = _tables(md)
    assert tables and all(len(r) == len(head) for head, rows in tables for r in rows)
    heads = [h for head, _ in tables for h in head]
    # units in the file spelling in report.md (N2.m2.s; report.html spells N²·m²·s, below)
    assert "mean ± 95 % CI [N2.m2.s]" in heads and "std [rad/s]" in heads and "median [95 % CI] [N2.m2.s]" in heads
    assert "²" not in md and "·" not in md
    assert misspelt(md, page=False) == [] and misspelt((rep / "report.html").read_text(encoding="utf-8"), page=True) == []
    assert misspelt_units(json.loads((rep / "report.json").read_text())["units"]) == []
    failed = next(rows for head, rows in tables if head[-1] == "error")
    assert failed == [["1", "pd @ ctrl.k_d = 30", "1", "failed", "diverged | at 0.1 s"]]
    for p in data["plots"]:
        assert f"]({p})" in md
    assert json.loads((rep / "report.json").read_text())["failed"] == [1]


def test_campaign_report_page_in_headless_chromium(campaign):
    require_browser()
    _, data, rep = campaign
    with Browser() as b:
        seen = b.check(rep / "report.html")
    assert seen.console_errors == []
    assert seen.broken_images == [] and seen.images == len(data["plots"]) == 2
    assert "control_energy [N²·m²·s]" in seen.tables


def test_a_campaign_whose_runs_all_failed_still_reports(tmp_path, campaign):
    """Every run failed: no statistics, no plots, every run listed."""
    clean, _, _ = campaign
    folder = tmp_path / "out"
    src = next(iter(campaign[2].parent.glob("out")))
    import shutil

    shutil.copytree(src, folder)
    df = clean.copy()
    df["status"], df["error"] = "failed", "x"
    df.to_parquet(folder / SUMMARY, index=False)
    (tmp_path / "rep").mkdir()
    data = make_report(folder, tmp_path / "rep")
    assert data["statistics"] == [] and data["plots"] == [] and data["failed"] == list(np.arange(8))
