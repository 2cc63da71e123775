"""The arena's FDIR chains (arena/fdir.py): the offline replay of a chain over a run's stored estimate
equals the blocks in the loop on that run (and the comparison fails on a shifted record); the
calibration's leave-one-out check fails when a fault-free draw is an outlier; a run's measures (the
wheel named from the direction of the estimate, a sensor fault read as an actuator's); the sensor-fault
rewrite of a realistic loop; the arena file's sensor classes."""
import numpy as np
import pytest
import tomli_w

from arena import cells as C
from arena import fdir as F
from arena.arenafile import Detection, load
from arena.plan import build, sample_period
from orchestrator import api
from orchestrator.api import InputError
from plant.rigid_wheels import default_distribution
from tests.arena.reduced import ARENA, ROOT, write

SHIPPED = ROOT / "arena" / "ftc_arena.toml"


def test_the_replay_equals_the_chain_in_the_loop_on_a_run(tmp_path):
    """fasmc_on_zhang2019 (ideal) with its chain closed: wheel 3 lost at 6 s, a CUSUM and the isolation in
    the loop, the allocation dropping the named wheel; the replay over the stored rows decides the same."""
    a = load(SHIPPED, only=["fasmc_on_zhang2019"], faults=["none", "lost"])
    cell = a.cells[0]
    T = sample_period(a, 0.01)
    params = F.design(a.detection, "cusum", T, 5.0)
    det = {**params, "mu0": [0.0] * 3, "sigma": [0.05] * 3, "h": 300.0, "latch": 1.0, "restart": 0.0}
    doc = C.closed_loop_scenario(C.cell_scenario(a, cell, "ideal"), cell, "cusum", det,
                                 {"mu0": [0.0] * 3, "window": 0.5, "sample_period": T})
    doc["timing"]["stop"] = 10.0
    (tmp_path / "loop.toml").write_text(tomli_w.dumps(doc))
    r = api.run(tmp_path / "loop.toml", mode="inprocess",
                parameters={"faults.fault_class": 7.0, "faults.channel": 3.0, "faults.onset": 6.0})
    rows = r.df.iloc[::round(T / 0.01)]  # the rows a campaign stores (trajectory_step = T)
    t = rows.index.to_numpy()
    keep = t < 10.0 - 1e-9
    est = rows[[c for c in rows.columns if c.startswith("est.f_hat")]].to_numpy()
    cal = F.Calibration("cusum", 3, T, 5.0, params, mu0=np.zeros(3), sigma=np.full(3, 0.05), h=300.0)
    rep = F.chain_replay(cal, t[keep], est[keep], F.signatures(4, 3), 0.5)
    rec = {"chain_alarms": rows["det.n_alarms"].to_numpy(), "chain_isolated": rows["iso.isolated"].to_numpy()}
    assert F.replay_matches(rep, rec)
    first = t[np.flatnonzero(rep["events"])[0]]
    assert 6.0 < first < 8.0 and rep["isolated"].max() == 3  # detected after the onset, the lost wheel named
    assert rows["alloc.n_active"].iloc[-1] == 3 and float(rows["det.alarm_time"].iloc[-1]) == pytest.approx(first)
    # the comparison can fail: a record one row late, or another wheel named
    late = {k: np.concatenate(([0.0], v[:-1])) for k, v in rec.items()}
    assert not F.replay_matches(rep, late)
    assert not F.replay_matches({**rep, "isolated": np.where(rep["isolated"] > 0, 2.0, 0.0)}, rec)


def _ar1(n, K, seed, scale=1.0):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        e = rng.normal(size=(K, 3)) * scale
        x = np.zeros((K, 3))
        for k in range(1, K):
            x[k] = 0.9 * x[k - 1] + e[k]
        out.append((np.arange(K) * 0.05, x))
    return out


def test_the_leave_one_out_check_can_fail_and_an_ordinary_set_passes():
    det = Detection(detectors=("cusum",), false_alarms_per_hour=10.0)
    runs = _ar1(20, 4000, 5)  # 20 x 195 s after the start-up: 1.08 h, certifiable at 10 per hour
    cal = F.calibrate(det, "cusum", runs, 0.05, 5.0)
    assert cal.certified and cal.stats["upper_bound_per_hour"] <= 10.0 and cal.meets is True
    assert cal.loo["exposure_hours"] == pytest.approx(cal.stats["exposure_hours"])
    # one draw far noisier than the others: the threshold the others set alarms on it, again and again
    odd = runs[:19] + _ar1(1, 4000, 6, scale=4.0)
    bad = F.calibrate(det, "cusum", odd, 0.05, 5.0)
    assert bad.loo["false_alarms"] > 10 and bad.loo["fails"] and bad.meets is False
    # too few hours: the smallest threshold without an alarm, not certified
    short = F.calibrate(det, "cusum", runs[:3], 0.05, 5.0)
    assert not short.certified and short.stats["false_alarms"] == 0 and short.meets is False
    # the operating curve: lower thresholds, more alarms
    counts = [c[1] for c in sorted(cal.curve)]
    assert counts[0] > counts[-1] == 0


def test_a_runs_measures_name_the_wheel_and_a_sensor_fault_read_as_an_actuators():
    T, K = 0.05, 400
    t = np.arange(K) * T
    rng = np.random.default_rng(2)
    M = np.asarray(default_distribution(4), dtype=float)
    free = [(t, rng.normal(scale=0.01, size=(K, 3))) for _ in range(10)]
    cal = F.calibrate(Detection(detectors=("glr",)), "glr", free, T, 1.0, leave_one_out=False)
    est = rng.normal(scale=0.01, size=(K, 3))
    est[t >= 12.0] += 0.2 * M[:, 3]  # the skew wheel (4) fails at 12 s
    row = {"outcome": "flies", "mission": 20.0, "fault": "lost", "onset": 12.0, "stop_time": None,
           "sensor_fault": False, "channel": 4.0}
    m = F.run_measures(cal, row, t, est, M, 0.5)
    assert m["missed_detection"] is False and 0.0 < m["detection_delay_s"] < 0.5
    assert m["isolated_channel"] == 4 and m["isolation_correct"] is True
    assert m["isolation_time_s"] >= 12.0 + m["detection_delay_s"] + 0.5 - 1e-9  # after the isolation window
    sensor = F.run_measures(cal, {**row, "fault": "gyro_bias", "sensor_fault": True, "channel": 2.0}, t, est, M, 0.5)
    assert sensor["isolated_channel"] == 4 and sensor["isolation_correct"] is None  # an actuator named
    quiet = F.run_measures(cal, row, t, free[0][1], M, 0.5)
    assert quiet["missed_detection"] is True and quiet["isolated_channel"] is None
    stopped = F.run_measures(cal, {**row, "outcome": "stopped", "stop_time": 12.1}, t, est, M, 0.5)
    assert stopped is None  # stopped before the fault could show: neither detected nor missed


def test_sensor_fault_blocks_sit_between_each_sensor_and_its_readers():
    a = load(SHIPPED)
    by = {c.name: c for c in a.cells}
    three = C.cell_scenario(a, by["fasmc_on_zhang2019"], "realistic")
    doc = C.sensor_scenario(three, ["gyro_bias", "st_outage"])
    conns = doc["connections"]
    assert [b for x, b in conns if x == "gyro.omega_m"] == ["gf.omega_m"]
    assert [b for x, b in conns if x == "st.q_m"] == ["stf.q_m"]
    assert {x for x, b in conns if b in ("ctrl.omega", "est.omega")} == {"gf.omega_f"}
    assert doc["instances"]["gf"]["fmu"] == "GyroFault3" and doc["instances"]["stf"]["step"] == 0.2  # st_small: 5 Hz
    pitch = C.cell_scenario(a, by["asmftc_on_hang2023"], "realistic")
    assert C.sensor_classes(pitch, ["gyro_bias", "st_outage"]) == ["gyro_bias"]  # no star tracker on a pitch axis
    p = C.sensor_scenario(pitch, ["gyro_bias", "st_outage"])
    assert p["instances"]["gf"]["fmu"] == "GyroFault1" and "stf" not in p["instances"]
    assert p["instances"]["gf"]["step"] == 0.01  # the gyro's period, not the 0.5 ms loop
    assert C.sensor_instances(C.cell_scenario(a, by["asmftc_on_hang2023"], "ideal")) == {}


def test_the_plan_flies_sensor_classes_on_realistic_cells_and_closes_the_wheel_loss(tmp_path):
    text = ARENA.replace('faults = ["none", "bias"]', 'faults = ["none", "bias", "lost", "gyro_bias", "st_outage"]\n'
                                                        'sensor_draws = 1')
    arena = load(write(tmp_path, text))
    plans = {p.name: p for p in build(arena)}
    sensors = {n: {g.kind: g for g in p.groups}.get("sensors") for n, p in plans.items()}
    assert sensors["fasmc_on_zhang2019.realistic"].faults == ["gyro_bias", "st_outage"]
    assert sensors["hinf_on_hang2023.realistic"].faults == ["gyro_bias"] and sensors["hinf_on_hang2023.ideal"] is None
    assert sensors["fasmc_on_zhang2019.realistic"].runs == 1
    camp = plans["fasmc_on_zhang2019.realistic"].campaigns["sensors"]
    assert {"gf.onset", "gf.channel", "gyro.seed", "st.seed", "stf.onset"} <= set(camp["dispersions"])
    assert [p.name for p in plans.values() if p.reconfigures] == ["fasmc_on_zhang2019.ideal",
                                                                  "fasmc_on_zhang2019.realistic"]
    assert "fdir" in plans["fasmc_on_zhang2019.ideal"].parts  # its closed chain's design decides runs
    # --draws sets every class's draws
    assert {g.kind: g.runs for g in build(load(tmp_path / "reduced.toml", draws=3))[3].groups}["sensors"] == 3


@pytest.mark.parametrize("over,key", [({"hardware": ["ideal"], "faults": ["none", "gyro_bias"]}, "--faults"),
                                      ({"hardware": ["ideal"]}, "--hardware")])
def test_a_sensor_class_without_realistic_hardware_is_refused(tmp_path, over, key):
    text = ARENA.replace('faults = ["none", "bias"]', 'faults = ["none", "gyro_bias"]')
    with pytest.raises(InputError) as e:
        load(write(tmp_path, text), **over)
    assert e.value.key == key and "realistic hardware only" in e.value.problem
