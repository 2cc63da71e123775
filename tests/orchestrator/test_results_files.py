"""A run's files (issue 23 items 2-3, issue 20 item 2): Parquet by default (CSV on request) with
every signal's declared unit, read back by ``ftcsim.open`` into the Result ``ftcsim.run`` returned;
``record_step`` thins what is stored, never the metrics; a failed write publishes nothing and keeps
the previous result byte-identical; metrics.json records the SHA-256 of each FMU that ran."""
import hashlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from scenario_text import variant, write

import ftcsim
from orchestrator.cli.main import main
from orchestrator.common.parquet import read_table
from orchestrator.results.metrics import held_integral

ROOT = Path(__file__).resolve().parents[2]
SHORT = "li2023_pd"


def _same(a, b):
    """Two Results equal in time, values, units, metrics and info."""
    assert list(a.df.columns) == list(b.df.columns)
    assert np.array_equal(a.df.index.to_numpy(), b.df.index.to_numpy())
    assert np.array_equal(a.df.to_numpy(), b.df.to_numpy())
    assert a.units == b.units == a.df.attrs["units"] == b.df.attrs["units"]
    assert a.metrics == b.metrics and a.metric_units == b.metric_units and a.info == b.info
    assert a.complete == b.complete and a.error == b.error


@pytest.mark.parametrize("fmt", ["parquet", "csv"])
def test_open_returns_the_result_run_returned(fmt, tmp_path):
    out = tmp_path / "run"
    r = ftcsim.run(SHORT, mode="inprocess", stop=1.0, out=out, format=fmt)
    assert (out / f"results.{fmt}").is_file() and not (out / f"results.{'csv' if fmt == 'parquet' else 'parquet'}").exists()
    o = ftcsim.open(out)
    _same(r, o)
    assert r == o and not (r != o)
    assert len(r.df) == 101 and r.metrics["final_attitude_error"] > 0
    # settings are not metrics
    assert not {"scenario", "complete", "mode", "step_statistics", "signals"} & set(r.metrics)
    assert r.info["scenario"] == SHORT and r.info["complete"] is True and r.info["format"] == fmt


def test_csv_is_plain_for_pandas_with_a_units_sidecar(tmp_path):
    import pandas as pd

    r = ftcsim.run(SHORT, mode="inprocess", stop=0.5, out=tmp_path / "c", format="csv")
    # pandas parses floats exactly by default from 3.1 on; before (bsk 2.12.1 caps pandas at 3.0.3), on request
    exact = {} if tuple(int(x) for x in pd.__version__.split(".")[:2]) >= (3, 1) else {"float_precision": "round_trip"}
    df = pd.read_csv(tmp_path / "c" / "results.csv", **exact)
    assert list(df.columns) == ["time"] + list(r.df.columns) and len(df) == 51
    assert np.array_equal(df.drop(columns="time").to_numpy(), r.df.to_numpy())  # 17 digits: lossless
    units = pd.read_csv(tmp_path / "c" / "results.units.csv").set_index("signal")["unit"].to_dict()
    assert units == r.units


def test_units_are_the_fmus_declared_units(tmp_path, fmu_dir):
    """Each column's unit is the one its FMU's modelDescription declares (read here with fmpy),
    in the Parquet field metadata, Result.units and the DataFrame's attrs; metrics.json gives the
    SHA-256 of each FMU that ran."""
    from fmpy import read_model_description

    out = tmp_path / "fmu"
    r = ftcsim.run(SHORT, stop=0.2, out=out, fmu_dir=fmu_dir)
    schema = pq.read_schema(out / "results.parquet")
    seen = set()
    for inst in r.scenario.instances.values():
        md = read_model_description(str(inst.fmu))
        declared = {v.name: (v.unit or getattr(v.declaredType, "unit", None) or "1") for v in md.modelVariables}
        for col in r.df.columns:
            if col.startswith(inst.name + "."):
                unit = declared[col.split(".", 1)[1]]
                assert r.units[col] == unit and schema.field(col).metadata[b"unit"].decode() == unit, col
                seen.add(unit)
        digest = hashlib.sha256(Path(inst.fmu).read_bytes()).hexdigest()
        assert r.info["fmus"][inst.name] == {"file": Path(inst.fmu).name, "sha256": digest}
    assert {"rad/s", "N.m", "1"} <= seen  # rates, torques and quaternions were recorded
    assert schema.field("time").metadata[b"unit"] == b"s"
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["units"]["max_abs_u"] == "N.m" and doc["units"]["final_rate_error"] == "rad/s"
    assert doc["info"]["fmus"] == r.info["fmus"]
    assert read_table(out / "results.parquet").attrs["units"] == r.units


def test_record_step_thins_the_rows_not_the_metrics(tmp_path):
    full = ftcsim.run(SHORT, mode="inprocess", stop=1.05)
    thin = ftcsim.run(SHORT, mode="inprocess", stop=1.05, record_step=0.1, out=tmp_path / "t")
    t = full.df.index.to_numpy()
    kept = thin.df.index.to_numpy()
    assert np.allclose(kept[:-1], np.arange(11) * 0.1, atol=1e-12) and kept[-1] == t[-1] == 1.05  # the last row too
    rows = [int(np.argmin(np.abs(t - x))) for x in kept]
    assert np.array_equal(thin.df.to_numpy(), full.df.to_numpy()[rows])  # the same rows, bit for bit
    assert thin.metrics == full.metrics  # from every step
    u = full.df[[f"ctrl.u[{i}]" for i in (1, 2, 3)]].to_numpy()
    assert thin.metrics["control_energy"] == pytest.approx(held_integral(t, np.sum(u ** 2, axis=1)), rel=1e-12)
    _same(thin, ftcsim.open(tmp_path / "t"))
    assert thin != full  # other rows


def test_command_line_record_step_format_and_short_out(tmp_path):
    """`ftcsim run -o DIR --record-step S --format csv` gives the API's rows and units; a --step finer
    than the file's records on the file's step (the metrics from every step) unless --record-step
    asks for more."""
    scen = str(write(tmp_path, variant({"stop = 200.0": "stop = 2.0"})))
    assert main(["run", scen, "--mode", "inprocess", "-o", str(tmp_path / "cli"), "--no-plots", "--quiet",
                 "--record-step", "0.05", "--format", "csv"]) == 0
    api = ftcsim.run(scen, mode="inprocess", record_step=0.05)
    cli = ftcsim.open(tmp_path / "cli")
    assert len(cli.df) == 41 and np.array_equal(cli.df.to_numpy(), api.df.to_numpy()) and cli.units == api.units
    assert main(["run", scen, "--mode", "inprocess", "-o", str(tmp_path / "fine"), "--no-plots", "--quiet",
                 "--step", "0.005"]) == 0
    fine = ftcsim.open(tmp_path / "fine")
    every = ftcsim.run(scen, mode="inprocess", step=0.005)
    assert fine.info["step"] == 0.005 and fine.info["record_step"] == 0.01 and len(fine.df) == 201
    assert len(every.df) == 401 and fine.metrics == every.metrics


def test_plot_labels_axes_with_units(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    r = ftcsim.run(SHORT, mode="inprocess", stop=0.3)
    fig = r.plot(["plant.omega", "ctrl.u"])
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["plant.omega [rad/s]", "ctrl.u [N.m]"]
    assert fig.axes[-1].get_xlabel() == "time [s]"
    html = r._repr_html_()
    assert SHORT in html and "final_attitude_error" in html and "<table>" in html
    r.to_parquet(tmp_path / "x.parquet")
    back = read_table(tmp_path / "x.parquet")
    assert back.attrs["units"]["plant.omega[1]"] == "rad/s"
    assert np.array_equal(back.drop(columns="time").to_numpy(), r.df.to_numpy())


WRITE_UNDER_LIMIT = r"""
import resource, sys
from orchestrator.cli.main import main
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.parametrize("fmt", ["parquet", "csv"])
def test_failed_write_keeps_the_previous_result_byte_identical(fmt, tmp_path):
    scen = str(write(tmp_path, variant({"stop = 200.0": "stop = 20.0"})))
    out = tmp_path / "r"
    assert main(["run", scen, "--mode", "inprocess", "-o", str(out), "--quiet", "--record-step", "1", "--no-plots",
                 "--format", fmt]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    # every step now (2001 rows): a results file above the limit, metrics.json and the marker below it
    p = subprocess.run([sys.executable, "-c", WRITE_UNDER_LIMIT, "100000", "run", scen, "--mode", "inprocess",
                        "-o", str(out), "--quiet", "--overwrite", "--format", fmt],
                       cwd=ROOT, capture_output=True, text=True, timeout=300)
    err = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(err) == 1, p.stderr  # an OSError of the output: exit 2 (issue 35)
    assert f"cannot write results.{fmt}" in err[0] and "previous result there is unchanged" in err[0], err[0]
    assert {q.name: q.read_bytes() for q in out.iterdir()} == before
    assert sorted(q.name for q in tmp_path.iterdir()) == ["case.toml", "r"]  # no staging folder, no lock left
