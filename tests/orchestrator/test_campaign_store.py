"""The campaign store (orchestrator/campaign/store.py, schema.py): stable typed Parquet whatever the
outcomes (issue 25 item 4) and a store that verifies what it reads (issue 20 item 5). In-process
blocks, runs of 0.3 s, in this process (workers=0)."""
import json
import shutil

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from orchestrator.campaign.run import run_campaign
from orchestrator.campaign.store import MANIFEST, SUMMARY
from orchestrator.cli.main import main
from orchestrator.common.parquet import read_table

TWO_METHODS = """
[campaign]
scenario = "li2023_pd"
mode = "inprocess"
runs = 2
seed = 3
stop = 0.3
trajectories = ["ctrl.q_e"]
trajectory_step = 0.1

[dispersions."plant.fault_scale"]
distribution = "uniform"
low = 0.2
high = 1.5

[settling]
signal = "ctrl.q_e"
level = {level}

[[variants]]
name = "pd"
[[variants]]
name = "fasmc"
scenario = "li2023_fasmc"
"""


def campaign(tmp_path, name, level):
    p = tmp_path / f"{name}.toml"
    p.write_text(TWO_METHODS.format(level=level), encoding="utf-8")
    out = tmp_path / name
    o = run_campaign(p, out, workers=0)
    assert o.stored == 4
    return out


@pytest.fixture(scope="module")
def settled_and_not(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("schemas")
    # |q_ev| starts near 0.6 (li2023 initial attitude): a band of 10 holds from the start, one of 1e-9 never
    return campaign(tmp, "all", 10.0), campaign(tmp, "none", 1e-9)


def test_outcomes_do_not_change_the_schema_and_variants_share_their_columns(settled_and_not):
    a, b = settled_and_not
    sa, sb = pd.read_parquet(a / SUMMARY), pd.read_parquet(b / SUMMARY)
    assert sa["settling_time"].notna().all() and sb["settling_time"].isna().all()  # the outcomes differ ...
    schema_a, schema_b = pq.read_schema(a / SUMMARY), pq.read_schema(b / SUMMARY)
    assert schema_a.equals(schema_b, check_metadata=True)  # ... the schema does not
    assert schema_a.field("settling_time").type == pa.float64()
    assert schema_a.field("error").type == pa.string() and schema_a.field("status").type == pa.string()
    for name in ("run_id", "point", "draw", "seed"):
        assert schema_a.field(name).type == pa.int64(), name
    # every run file of both campaigns and both variants: one schema (FASMC's observer metrics are nulls for PD)
    files = sorted((a / "runs").glob("*.parquet")) + sorted((b / "runs").glob("*.parquet"))
    assert len(files) == 8 and all(pq.read_schema(f).equals(schema_a, check_metadata=True) for f in files)
    assert sa.loc[sa.variant == "pd", "observer_error_final"].isna().all()
    assert np.isfinite(sa.loc[sa.variant == "fasmc", "observer_error_final"]).all()
    # units travel in the field metadata
    units = read_table(a / SUMMARY).attrs["units"]
    assert units["settling_time"] == "s" and units["wall_time_s"] == "s" and units["plant.fault_scale"] == "1"
    assert units["requested:plant.fault_scale"] == "1"


def test_polars_and_duckdb_read_the_run_files_and_trajectories_by_glob(settled_and_not):
    polars = pytest.importorskip("polars")
    duckdb = pytest.importorskip("duckdb")
    a, _ = settled_and_not
    runs = polars.read_parquet(str(a / "runs" / "*.parquet"))
    assert sorted(runs["run_id"].to_list()) == [0, 1, 2, 3] and runs.schema["run_id"] == polars.Int64
    con = duckdb.connect()
    got = con.execute(f"select run_id, variant, settling_time from read_parquet('{a}/runs/*.parquet', "
                      "hive_partitioning=true) order by run_id").fetchall()
    assert [r[0] for r in got] == [0, 1, 2, 3] and [r[1] for r in got] == ["pd", "pd", "fasmc", "fasmc"]
    tr = con.execute(f"select run_id, count(*) from read_parquet('{a}/trajectories/*.parquet', "
                     "hive_partitioning=true) group by run_id order by run_id").fetchall()
    assert tr == [(0, 4), (1, 4), (2, 4), (3, 4)]  # 0, 0.1, 0.2, 0.3 s
    # pandas: integer run ids, in numeric order (not a category ordered 0, 1, 10, 100)
    t = pd.read_parquet(a / "trajectories")
    assert t["run_id"].dtype == np.int64 and read_table(a / "trajectories").attrs["units"]["time"] == "s"


@pytest.fixture
def stored_campaign(settled_and_not, tmp_path):
    """A copy of a finished campaign (and its file), to damage."""
    src, _ = settled_and_not
    out = tmp_path / "c"
    shutil.copytree(src, out)
    return out


def _resume(out, capsys):
    """Rerun the campaign of ``out``: (exit status, the lines on stderr: with --quiet, its warnings).
    The ``ftcsim`` loggers write to stderr and do not propagate (cli.main.configure_logging)."""
    capsys.readouterr()
    rc = main(["campaign", str(out / "campaign.toml"), "--out", str(out), "--workers", "0", "--quiet"])
    return rc, capsys.readouterr().err.splitlines()


def test_a_swapped_run_file_is_detected_and_recomputed(stored_campaign, capsys):
    out = stored_campaign
    before = pd.read_parquet(out / SUMMARY)
    f0, f1 = sorted((out / "runs").glob("*.parquet"))[:2]
    b0, b1 = f0.read_bytes(), f1.read_bytes()
    f0.write_bytes(b1)
    f1.write_bytes(b0)
    rc, lines = _resume(out, capsys)
    assert rc == 0 and len(lines) == 2 and all("\n" not in x for x in lines), lines
    assert f"runs/{f0.name}: damaged run file (holds run 1" in lines[0] and lines[0].endswith("recomputing")
    after = pd.read_parquet(out / SUMMARY)
    assert after["run_id"].tolist() == [0, 1, 2, 3]
    cols = [c for c in before.columns if c not in ("wall_time_s", "cpu_time_s", "sim_time_s", "worker")]
    pd.testing.assert_frame_equal(after[cols], before[cols])  # recomputed: the same results


def test_a_truncated_run_file_is_detected_and_recomputed(stored_campaign, capsys):
    out = stored_campaign
    f = sorted((out / "runs").glob("*.parquet"))[2]
    f.write_bytes(f.read_bytes()[: f.stat().st_size // 2])
    rc, lines = _resume(out, capsys)
    assert rc == 0 and len(lines) == 1 and f"runs/{f.name}: damaged run file (unreadable" in lines[0], lines
    assert pd.read_parquet(out / SUMMARY)["run_id"].tolist() == [0, 1, 2, 3]
    assert pq.read_table(f).num_rows == 1


def test_a_damaged_manifest_is_rebuilt_from_the_campaign_copy(stored_campaign, capsys):
    out = stored_campaign
    (out / MANIFEST).write_text('{"campaign": "li', encoding="utf-8")  # cut mid-write
    rc, lines = _resume(out, capsys)
    assert rc == 0 and len(lines) == 1 and "manifest.json: damaged; rebuilt from" in lines[0], lines
    man = json.loads((out / MANIFEST).read_text())
    assert man["status"] == "complete" and man["stored_runs"] == 4 and "rebuilt" in man


def test_a_damaged_manifest_with_another_campaign_file_is_refused_in_one_line(stored_campaign, capsys):
    out = stored_campaign
    (out / MANIFEST).write_text("[]", encoding="utf-8")
    other = out.parent / "other.toml"
    other.write_text(TWO_METHODS.format(level=0.5), encoding="utf-8")
    files = {p.name: p.read_bytes() for p in (out / "runs").iterdir()}
    rc = main(["campaign", str(other), "--out", str(out), "--workers", "0", "--quiet"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err
    assert f"{out / MANIFEST}: -: damaged" in err and "--overwrite" in err
    assert {p.name: p.read_bytes() for p in (out / "runs").iterdir()} == files  # nothing touched
