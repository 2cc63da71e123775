"""A run that did not finish is never ranked, and nothing hangs forever (issue 20 items 3 and 4).

One controller FMU, FaultyPD (tests/orchestrator/blocks/faulty_block.py: the PD law of
docs/examples/pd_block.py that raises from ``raise_at`` or hangs from ``hang_at``), in place of
FASMC in li2023_fasmc (docs/examples/own_controller.toml): a crash at 1 s of 2 s is stored as
failed with its error, without metrics, and ranks nowhere (campaign and `ftcsim compare`); a step
that sleeps for an hour is stopped by the time limit and by SIGINT within 5 s (`ftcsim run` and
`ftcsim campaign`)."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from orchestrator import api
from orchestrator.campaign.run import run_campaign
from orchestrator.cli.main import main
from orchestrator.cosim.runner import run_scenario

ROOT = Path(__file__).resolve().parents[2]
BLOCKS = Path(__file__).resolve().parent / "blocks"
pytestmark = [pytest.mark.fmu, pytest.mark.slow]


@pytest.fixture(scope="module")
def faulty(tmp_path_factory, fmu_dir):
    """(folder, FaultyPD.fmu, scenario file using it) built once."""
    folder = tmp_path_factory.mktemp("faulty")
    fmu = folder / "FaultyPD.fmu"
    subprocess.run([sys.executable, "-c", "import sys; from fmus.build import build_block; "
                    "build_block('faulty_block:FaultyPD', out=sys.argv[1], paths=[sys.argv[2]])", str(fmu), str(BLOCKS)],
                   check=True, cwd=ROOT, timeout=300)
    text = (ROOT / "docs" / "examples" / "own_controller.toml").read_text()
    scenario = folder / "faulty.toml"
    scenario.write_text(text.replace('fmu = "MinimalPD.fmu"', f'fmu = "{fmu.as_posix()}"'))
    return folder, fmu, scenario


def _env(marker):
    env = dict(os.environ, FTCSIM_TEST_HANG_MARKER=str(marker), PYTHONPATH=str(ROOT))
    env.pop("FTCSIM_DEBUG", None)
    return env


def _stop_with_sigint(cmd, marker, cwd):
    """Start ``cmd``, wait until the block hangs (its marker file), send SIGINT: (exit status, s to stop, stderr)."""
    p = subprocess.Popen(cmd, cwd=cwd, env=_env(marker), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 240
        while not marker.exists() and p.poll() is None and time.monotonic() < deadline:
            time.sleep(0.1)
        assert marker.exists(), p.communicate(timeout=5)
        time.sleep(0.3)  # well inside the hour-long sleep
        t0 = time.monotonic()
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=30)
        return p.returncode, time.monotonic() - t0, err
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()


def test_a_hung_run_is_stopped_by_its_time_limit(faulty):
    _, _, scenario = faulty
    sc = api.load(str(scenario), stop=2.0, parameters={"ctrl.hang_at": 0.5})
    t0 = time.monotonic()
    raw = run_scenario(sc, time_limit=1.5)
    elapsed = time.monotonic() - t0
    assert not raw.complete and raw.info.get("timed_out") and raw.interrupted == 0
    assert "time limit of 1.5 s" in raw.error
    stepping = raw.wall_time  # the limit counts the stepping (set-up excluded); the hung step is cut 1 s after it
    assert 1.5 <= stepping < 1.5 + 5.0 and elapsed < 60, (stepping, elapsed)
    # the same limit from the scenario file ([timing] time_limit), through ftcsim.run
    limited = scenario.parent / "limited.toml"  # extends stays inside the scenario's folder
    limited.write_text(f'[scenario]\nextends = "{scenario.name}"\n[timing]\ntime_limit = 1.5\n'
                       "[instances.ctrl.parameters]\nhang_at = 0.5\n")
    r = api.run(str(limited), stop=2.0)
    assert r.raw.info.get("timed_out") and "time limit of 1.5 s" in r.raw.error and r.raw.wall_time < 6.5


def test_sigint_stops_a_run_hung_inside_an_fmu_call_within_5_s(faulty, tmp_path):
    _, _, scenario = faulty
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "orchestrator.cli", "run", str(scenario), "--out", str(out), "--quiet", "--no-plots"]
    text = scenario.read_text().replace("u_max = 5.0", "u_max = 5.0\nhang_at = 0.5")
    hanging = tmp_path / "hang.toml"
    hanging.write_text(text)
    cmd[4] = str(hanging)
    rc, took, err = _stop_with_sigint(cmd, tmp_path / "hangs", tmp_path)
    assert rc == 130 and took < 5.0, (rc, took, err)
    assert "interrupted by SIGINT" in err and "Traceback" not in err
    kept = pd.read_parquet(out / "results.parquet")  # the rows so far kept (parquet: the default format)
    assert (out / "INCOMPLETE").exists() and len(kept) > 0 and kept["time"].max() <= 0.5 + 1e-9


CAMPAIGN = """
[campaign]
scenario = "{scenario}"
runs = 1
stop = 2.0
time_limit = {limit}

[[variants]]
name = "pd"
[[variants]]
name = "crash"
parameters = {{ "ctrl.raise_at" = 1.0 }}
[[variants]]
name = "hang"
parameters = {{ "ctrl.hang_at" = 0.5 }}
"""


def test_a_crashed_run_is_failed_a_hung_one_timed_out_and_neither_is_ranked(faulty, tmp_path):
    _, _, scenario = faulty
    path = tmp_path / "c.toml"
    path.write_text(CAMPAIGN.format(scenario=scenario.as_posix(), limit=20.0))
    t0 = time.monotonic()
    o = run_campaign(path, tmp_path / "out", workers=0, time_limit=4.0)  # the command line's limit wins
    assert time.monotonic() - t0 < 120
    assert (o.stored, o.failed) == (3, 2)
    df = pd.read_parquet(tmp_path / "out" / "summary.parquet").set_index("variant")
    assert df["status"].to_dict() == {"pd": "ok", "crash": "failed", "hang": "timeout"}
    assert "controller crashed at t = 1 s" in df.loc["crash", "error"]
    assert "time limit of 4 s" in df.loc["hang", "error"] and pd.isna(df.loc["pd", "error"])
    # no metrics for a run that did not finish: the energy of its first second ranks nowhere
    for v in ("crash", "hang"):
        assert np.isnan(df.loc[v, ["control_energy", "final_attitude_error", "max_abs_u"]].to_numpy(float)).all()
    assert np.isfinite(df.loc["pd", "control_energy"]) and df.loc["crash", "t_end"] == pytest.approx(1.0)
    from orchestrator.campaign.report import make_report

    rep = tmp_path / "report"
    rep.mkdir()
    data = make_report(tmp_path / "out", rep)
    energy = {r["variant"]: r for r in data["statistics"] if r["metric"] == "control_energy"}
    # a variant without a finished run has no statistics row (the report drops empty rows); both are listed failed
    assert energy["pd"]["n"] == 1 and "crash" not in energy and "hang" not in energy
    ids = df["run_id"].to_dict()
    assert sorted(data["failed"]) == sorted([ids["crash"], ids["hang"]])
    assert all(ids["crash"] not in w and ids["hang"] not in w for w in data["worst"].values())


def test_sigint_stops_a_campaign_whose_run_hangs_within_5_s(faulty, tmp_path):
    _, _, scenario = faulty
    path = tmp_path / "c.toml"
    path.write_text(CAMPAIGN.format(scenario=scenario.as_posix(), limit=3600.0))
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "orchestrator.cli", "campaign", str(path), "--out", str(out), "--workers", "0",
           "--quiet"]
    rc, took, err = _stop_with_sigint(cmd, tmp_path / "hangs", tmp_path)
    assert rc == 130 and took < 5.0, (rc, took, err)
    assert "Traceback" not in err
    done = pd.read_parquet(out / "summary.parquet")  # the runs before the hung one are kept
    assert done["variant"].tolist() == ["pd", "crash"]


def test_compare_reports_a_controller_that_crashed_as_failed_and_unranked(faulty, tmp_path, capsys):
    folder, fmu, scenario = faulty
    text = scenario.read_text().replace("u_max = 5.0", "u_max = 5.0\nraise_at = 1.0")
    crashing = tmp_path / "crash.toml"
    crashing.write_text(text)
    out = tmp_path / "cmp"
    rc = main(["compare", str(fmu), "--scenario", str(crashing), "--out", str(out), "--runs", "1", "--stop", "2",
               "--workers", "0"])
    printed = capsys.readouterr().out
    assert rc == 0
    df = pd.read_parquet(out / "summary.parquet").set_index("variant")
    assert df.loc["faultypd", "status"] == "failed" and "controller crashed" in df.loc["faultypd", "error"]
    assert np.isnan(df.loc["faultypd", "control_energy"]) and (df.drop("faultypd")["status"] == "ok").all()
    row = [x for x in printed.splitlines() if x.startswith("faultypd")][0]
    assert set(row.split()[1:]) == {"-"}, printed  # no mean: unranked
    assert "1 not ok" in printed
