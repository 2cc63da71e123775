"""``ftcsim fdir calibrate`` end to end on a cheap fault-free residual (tests/diagnosis/noise_block.py:
AR(1) noise into a CUSUM, in-process): the offline replay counts exactly the alarms the block raises
in the loop on the same draws; on FRESH draws the calibrated threshold keeps the Wilks bound on the
share of runs that alarm; the threshold rule (no calibration draw alarms) and scipy's Poisson bound; the
uncertified case; the FDIR measures of diagnosis/metrics.py."""
import json

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from diagnosis.metrics import alarm_events, fdir_measures
from orchestrator import api
from papers.paper import FMUSpec

SCENARIO = """
connections = [["noise.y", "det.r"]]
[scenario]
name = "noise_cusum"
description = "fault-free AR(1) residual into a CUSUM"
[timing]
start = 0.0
stop = {stop}
step = 0.01
[instances.noise]
fmu = "NoiseTorque3"
[instances.det]
fmu = "CusumDetector3"
[instances.det.parameters]
drift = 0.5
persistence = 0.02
[record]
variables = ["noise.y", "det.n_alarms", "det.statistic"]
"""

CAMPAIGN = """
[campaign]
name = "{name}"
scenario = "noise.toml"
mode = "inprocess"
runs = {runs}
seed = {seed}
trajectories = ["noise.y"]
trajectory_step = 0.01
[dispersions."noise.seed"]
distribution = "integer"
low = 0
high = 1000000000
"""


@pytest.fixture
def noise(tmp_path, monkeypatch):
    import papers.registry as registry

    monkeypatch.setattr(registry, "GENERIC_FMUS", registry.GENERIC_FMUS + (
        FMUSpec("NoiseTorque3", "tests.diagnosis.noise_block:noise_torque_3", "test noise"),))
    (tmp_path / "noise.toml").write_text(SCENARIO.format(stop=15.0))
    return tmp_path


def _campaign(folder, name, runs, seed):
    path = folder / f"{name}.toml"
    path.write_text(CAMPAIGN.format(name=name, runs=runs, seed=seed))
    return path


def _in_loop_alarms(folder, cal, seeds, h=None) -> int:
    """The block in the loop with the calibration applied as a gains file (threshold ``h`` instead of
    the calibrated one if given), restarting after each alarm."""
    n = 0
    for s in seeds:
        extra = {} if h is None else {"det.h": float(h)}
        r = api.run(folder / "noise.toml", mode="inprocess", gains=[cal],
                    parameters={"noise.seed": float(s), "det.restart": 1.0, "det.latch": 0.0, **extra})
        n += int(r.df["det.n_alarms"].iloc[-1])
    return n


def test_calibrated_rate_holds_on_fresh_draws_and_the_replay_counts_what_the_loop_raises(noise):
    cal = noise / "cal.json"
    doc = api.fdir_calibrate(_campaign(noise, "calib", 20, 1), detector="det", rate_per_hour=120.0, level=0.95,
                             draws=noise / "draws", out=cal, workers=0)
    s = doc["statistics"]
    assert doc["certified"] and s["upper_bound_per_hour"] <= 120.0
    assert s["exposure_hours"] == pytest.approx(20 * 1500 * 0.01 / 3600)
    assert s["false_alarms"] == 0  # the rule: no calibration draw alarms at h ...
    curve = doc["operating_curve"]
    below = [c for c in curve if c["h"] < doc["parameter_set"]["h"]]
    assert below and all(c["false_alarms"] >= 1 for c in below)  # ... and none lower is alarm-free
    E = s["exposure_hours"]
    for c in curve:
        N = c["false_alarms"]
        assert c["upper_bound_per_hour"] == pytest.approx(stats.chi2.ppf(0.95, 2 * N + 2) / (2 * E))
    # the replay counts exactly what the block raises in the loop on the same draws (at a threshold where
    # it alarms, so the comparison can fail)
    seeds = pd.read_parquet(noise / "draws" / "summary.parquet")["noise.seed"]
    low = max((c for c in below if c["false_alarms"] >= 5), key=lambda c: c["h"])
    assert _in_loop_alarms(noise, cal, seeds, h=low["h"]) == low["false_alarms"]
    # fresh draws (another campaign seed): Wilks says a fresh run alarms with probability at most
    # 1 - 0.05^(1/20) = 0.139 (95 % confidence); 40 fresh runs may then hold at most 13 alarming runs
    # (binomial 99.9 %). A guard against gross errors only (a threshold at the median calibration peak
    # would make about half alarm); tests/arena/test_fdir.py has the test with power
    fresh = api.campaign(_campaign(noise, "fresh", 40, 99), noise / "fresh", workers=0)["noise.seed"]
    assert not set(fresh) & set(seeds)
    alarming = sum(_in_loop_alarms(noise, cal, [x]) > 0 for x in fresh)
    eps = 1 - 0.05 ** (1 / 20)
    assert alarming <= stats.binom.ppf(0.999, 40, eps), alarming
    assert json.loads(cal.read_text())["fmu_parameters"]["CusumDetector3"]["h"] == doc["parameter_set"]["h"]


def test_too_little_exposure_is_written_as_not_certified(noise, caplog):
    doc = api.fdir_calibrate(_campaign(noise, "short", 2, 5), detector="det", rate_per_hour=1.0, draws=noise / "d",
                             out=noise / "c.json", workers=0)
    assert not doc["certified"] and doc["statistics"]["false_alarms"] == 0
    assert "will not be certified (about 719 draws would be needed)" in caplog.text
    assert doc["statistics"]["hours_needed_for_target"] == pytest.approx(-np.log(0.05))


def test_fdir_measures_of_a_run():
    t = np.arange(0, 10, 0.1)
    alarm = ((t >= 2.0) & (t < 2.5)) | (t >= 6.3)
    iso = np.where(t >= 6.5, 3.0, 0.0)
    m = fdir_measures(t, alarm, onset=6.0, faulty_channel=3, isolated=iso, reconfigured=t >= 6.6, t_enable=1.0)
    assert m["false_alarms"] == 1 and m["exposure_hours"] == pytest.approx(5.0 / 3600)
    assert m["detection_delay_s"] == pytest.approx(0.3) and m["missed_detection"] is False
    assert m["isolation_correct"] is True and m["isolation_time_s"] == pytest.approx(6.5)
    assert m["time_to_reconfiguration_s"] == pytest.approx(0.6) and m["reconfigured_before_onset"] is False
    # a wheel dropped after the false alarm at 2 s: no time to reconfiguration is credited for the fault
    early = fdir_measures(t, alarm, onset=6.0, faulty_channel=3, isolated=iso, reconfigured=t >= 2.4, t_enable=1.0)
    assert early["time_to_reconfiguration_s"] is None and early["reconfigured_before_onset"] is True
    assert alarm_events(t, n_alarms=np.cumsum(t == 3.0) * 2).tolist() == [3.0, 3.0]
    free = fdir_measures(t, np.zeros_like(t))
    assert free["false_alarms"] == 0 and free["detection_delay_s"] is None and free["missed_detection"] is None
