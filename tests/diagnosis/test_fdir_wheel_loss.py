"""The shipped FDIR scenario on 001's craft (issue 34 acceptance): the wheel-loss run detects after the
onset, isolates the lost wheel, reconfigures, and beats the same run without FDIR by the stated
measure (RMS attitude error over the slew and settling time); the detector in the run computes what
its offline replay on the recorded f_hat computes; the shipped calibration file is what the shipped
campaign and scenario produce, and the scenarios apply it. Every wheel, the FMUs, and the calibrated
rate on fresh draws: make test-long (tests/conftest.py LONG)."""
import hashlib
import json

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from diagnosis.calibration import false_alarm_counts
from orchestrator import api
from orchestrator.api import InputError
from orchestrator.campaign.spec import load as load_campaign
from orchestrator.scenario.shipped import ROOT, block_factory, campaign_file, scenario_files
from papers.p001_zhang2019 import fdir_study
from papers.p001_zhang2019.fdir import CALIBRATION

CAL = json.loads(CALIBRATION.read_text())


@pytest.fixture(scope="module")
def wheel2():
    return {name: api.run(sc, mode="inprocess") for name, sc in (("fdir", fdir_study.SCENARIO), ("open", fdir_study.OPEN))}


def test_the_shipped_run_detects_isolates_reconfigures_and_beats_no_fdir(wheel2):
    f, o = (fdir_study.measures(wheel2[k], 20.0) for k in ("fdir", "open"))
    assert wheel2["fdir"].complete and wheel2["open"].complete
    assert 20.0 <= f["alarm_time_s"] < 30.5  # after the onset; at the latest just after the slew starts
    assert f["isolated_wheel"] == 2 and f["confidence"] > 0.99 and f["margin"] > 0.5
    assert f["reconfiguration_time_s"] == pytest.approx(f["alarm_time_s"] + 0.02)  # two samples: alarm, isolation
    assert o["reconfiguration_time_s"] is None  # the open chain: the same alarm, nothing reconfigured
    assert o["alarm_time_s"] == f["alarm_time_s"]
    assert f["rms_attitude_error_slew_rad"] < 0.95 * o["rms_attitude_error_slew_rad"]
    assert f["settling_time_s"] < o["settling_time_s"] - 2.0
    df = wheel2["fdir"].df
    assert df["det.alarm"][df.index < 20.0].max() == 0.0  # no alarm before the fault


def test_the_detector_computes_its_offline_replay_on_the_recorded_input(wheel2):
    """The statistic the block outputs at t_k+1 is the replay's at t_k (the sample taken in the step
    from t_k), from the same calibrated parameters: run and calibration see the same test."""
    df = wheel2["fdir"].df
    t = df.index.to_numpy()
    r = df[[f"est.f_hat[{i}]" for i in (1, 2, 3)]].to_numpy()
    det = block_factory("CusumDetector3")()
    det.set_parameters(wheel2["fdir"].scenario.instances["det"].parameters)
    det.initialize(0.0)
    stat, ev = det.replay(r[:-1], t[:-1])
    np.testing.assert_allclose(df["det.statistic"].to_numpy()[1:], stat, rtol=1e-12, atol=1e-9)
    assert t[np.flatnonzero(ev)[0]] == pytest.approx(df["det.alarm_time"].iloc[-1])


def test_the_shipped_calibration_comes_from_the_shipped_campaign_and_the_scenarios_apply_it():
    c = load_campaign(campaign_file("zhang2019_fdir_calibration"))
    assert CAL["kind"] == "fdir-calibration" and CAL["certified"] is True
    assert CAL["campaign"]["sha256"] == c.digest, "campaign changed: run the command in CAL['command'] again"
    scen = scenario_files()["zhang2019_fdir_wheel_loss_open"]
    assert CAL["campaign"]["scenario_sha256"] == hashlib.sha256(scen.read_bytes()).hexdigest(), \
        "scenario changed: run the command in CAL['command'] again"
    assert CAL["command"].startswith("ftcsim fdir calibrate campaigns/zhang2019_fdir_calibration.toml --detector det --rate 1 ")
    s, target = CAL["statistics"], CAL["target"]
    assert s["runs"] == c.runs and s["upper_bound_per_hour"] <= target["false_alarms_per_hour"]
    assert s["upper_bound_per_hour"] == pytest.approx(stats.chi2.ppf(target["level"], 2 * s["false_alarms"] + 2)
                                                      / (2 * s["exposure_hours"]))
    p = CAL["parameter_set"]
    for name in ("zhang2019_fdir_wheel_loss", "zhang2019_fdir_wheel_loss_open"):
        det = api.load(name, mode="inprocess").instances["det"].parameters
        assert det["h"] == p["h"] and [det[f"sigma[{i}]"] for i in (1, 2, 3)] == p["sigma"]
        assert [det[f"mu0[{i}]"] for i in (1, 2, 3)] == p["mu0"]
        for k in ("drift", "persistence", "t_enable", "sample_period"):
            assert det[k] == p[k] == c.bases[0].instances["det"].parameters[k], k
    assert p["h"] in [row["h"] for row in CAL["operating_curve"]]
    assert ROOT / "papers" / "p001_zhang2019" / CALIBRATION.name == CALIBRATION


@pytest.mark.parametrize("wheel", [1, 3, 4])
def test_every_wheel_is_isolated_and_fdir_helps(wheel, tmp_path):
    rep = fdir_study.run_study(tmp_path / "study", wheel=wheel)
    v = rep["verdict"]
    assert v["detected"] and v["isolated_right_wheel"] and v["reconfigured"] and v["improved"], v
    assert not v["false_alarm_without_fault"]
    assert (tmp_path / "study" / "report.md").is_file()
    assert (tmp_path / "study" / "fdir_wheel_loss.png").stat().st_size > 10_000


@pytest.mark.parametrize("fmi", ["2", "3"])
def test_the_fdir_chain_through_fmus_matches_in_process(fmi, fmu_dir, fmi3_dir, wheel2):
    folder = fmu_dir if fmi == "2" else fmi3_dir
    r = api.run(fdir_study.SCENARIO, mode="fmu", fmu_dir=folder)
    f, g = fdir_study.measures(r, 20.0), fdir_study.measures(wheel2["fdir"], 20.0)
    assert f["isolated_wheel"] == 2 and f["alarm_time_s"] == pytest.approx(g["alarm_time_s"])
    assert f["reconfiguration_time_s"] == pytest.approx(g["reconfiguration_time_s"])
    np.testing.assert_allclose(r.df["ctrl.q_e[1]"].to_numpy(), wheel2["fdir"].df["ctrl.q_e[1]"].to_numpy(), atol=1e-9)


def test_the_shipped_threshold_keeps_its_rate_on_fresh_fault_free_draws(tmp_path):
    """Fresh draws (another campaign seed) of the calibration campaign: the number of them that raise
    an alarm at the shipped threshold stays within the binomial spread of Wilks' bound for 200 draws,
    1 - 0.05^(1/200) = 0.0149 per run (95 % confidence)."""
    text = campaign_file("zhang2019_fdir_calibration").read_text().replace("seed = 34", "seed = 3434")
    text = text.replace("runs = 200", "runs = 40")
    path = tmp_path / "fresh.toml"
    path.write_text(text)
    summary = api.campaign(path, tmp_path / "fresh")
    assert (summary["status"] == "ok").all()
    det = block_factory("CusumDetector3")()
    det.set_parameters(api.load(fdir_study.OPEN, mode="inprocess").instances["det"].parameters)
    det.initialize(0.0)
    runs = []
    for _, row in summary.iterrows():
        tr = pd.read_parquet(api.trajectory_file(tmp_path / "fresh", row))
        keep = tr["time"].to_numpy() < 60.0 - 1e-9
        runs.append((tr["time"].to_numpy()[keep], tr[[f"est.f_hat[{i}]" for i in (1, 2, 3)]].to_numpy()[keep]))
    alarming = int((false_alarm_counts(det, runs, CAL["parameter_set"]["h"]) > 0).sum())
    eps = 1 - (1 - CAL["target"]["level"]) ** (1 / CAL["statistics"]["runs"])
    assert alarming <= stats.binom.ppf(0.999, len(runs), eps), (alarming, eps)


def test_the_study_never_writes_into_a_folder_it_did_not_create(tmp_path, capsys, monkeypatch):
    """A foreign folder (the user's) is refused before any run, its files untouched; a previous study is
    replaced only with --overwrite (checked before anything runs: no run is made here)."""
    mine = tmp_path / "notes"
    mine.mkdir()
    (mine / "report.md").write_text("my own notes\n")
    monkeypatch.setattr(fdir_study, "_study", lambda *a: pytest.fail("ran before the folder was checked"))
    assert fdir_study.main(["--out", str(mine)]) == 2
    assert "--out" in capsys.readouterr().err and (mine / "report.md").read_text() == "my own notes\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes"]  # no lock or staging folder left
    study = tmp_path / "study"
    monkeypatch.setattr(fdir_study, "_study", lambda out, *a: (out / "report.md").write_text("x") and {})
    fdir_study.run_study(study)
    with pytest.raises(InputError, match="overwrite"):
        fdir_study.run_study(study)
    fdir_study.run_study(study, overwrite=True)
    assert (study / "report.md").read_text() == "x"
