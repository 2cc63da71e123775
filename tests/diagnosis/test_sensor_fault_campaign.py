"""Every sensor-fault class of the catalog runs in the shipped campaign (issue 34 item 5), short: the
ground truth each stores is the fault it is (bias magnitude, drift rate x time, stuck = frozen -
measured, outage invalid, frozen valid with a growing angle), and the fault-free variant has none."""
import numpy as np
import pandas as pd
import pytest

from orchestrator import api
from orchestrator.campaign.spec import load
from orchestrator.scenario.shipped import campaign_file


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    out = tmp_path_factory.mktemp("sensor") / "c"
    c = load(campaign_file("zhang2019_fdir_sensor_faults"), runs=1, stop=6.0)
    summary = api.campaign(c, out, workers=0)
    return out, summary


def _traj(out, summary, variant):
    row = summary[summary["variant"] == variant].iloc[0]
    assert row["status"] == "ok", row["error"]
    df = pd.read_parquet(api.trajectory_file(out, row))
    return df.set_index("time")


def test_every_class_runs_and_logs_its_ground_truth(campaign):
    out, summary = campaign
    assert sorted(summary["variant"]) == sorted(["none", "gyro_bias_step", "gyro_drift_ramp", "gyro_stuck",
                                                 "star_tracker_outage", "star_tracker_frozen"])
    assert (summary["status"] == "ok").all()
    none = _traj(out, summary, "none")
    assert none[["gf.fault[1]", "gf.fault[2]", "gf.fault[3]", "stf.fault_angle", "gf.active", "stf.active"]].abs().max().max() == 0.0
    bias = _traj(out, summary, "gyro_bias_step")
    after = bias.index >= 2.0 - 1e-9
    np.testing.assert_allclose(bias["gf.fault[1]"][after], 0.002)
    assert (bias["gf.fault[1]"][~after] == 0).all() and (bias["gf.fault[2]"] == 0).all()
    drift = _traj(out, summary, "gyro_drift_ramp")
    t = drift.index.to_numpy()
    np.testing.assert_allclose(drift["gf.fault[2]"], np.where(t >= 2.0 - 1e-9, 2e-4 * (t - 2.0), 0.0), atol=1e-15)
    stuck = _traj(out, summary, "gyro_stuck")
    assert (stuck["gf.active"][stuck.index >= 2.0 - 1e-9] == 1.0).all()
    assert stuck["gf.fault[1]"].abs().iloc[-1] > 1e-3  # the craft moves, the stuck gyro does not
    outage = _traj(out, summary, "star_tracker_outage")
    on = (outage.index >= 2.0 - 1e-9)
    assert (outage["stf.valid"][on] == 0.0).all() and (outage["stf.valid"][~on] == 1.0).all()
    frozen = _traj(out, summary, "star_tracker_frozen")
    assert (frozen["stf.valid"] == 1.0).all() and frozen["stf.active"].iloc[-1] == 1.0
    angle = frozen["stf.fault_angle"][frozen.index >= 2.5].to_numpy()
    assert angle[-1] > 1e-3 and np.all(np.diff(angle) > -1e-6)  # the acquisition moves the craft away from the frozen attitude
    assert summary.set_index("variant").loc["gyro_stuck", "final_attitude_error"] > \
        summary.set_index("variant").loc["none", "final_attitude_error"]
