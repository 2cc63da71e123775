"""The arena's FDIR chains (arena/fdir.py): the offline replay of a chain over a run's stored estimate
equals the blocks in the loop on that run (and the comparison fails on a shifted record); the
calibration's threshold sits above every fault-free peak and fresh draws keep its Wilks bound; a run's measures (the
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


def test_the_calibration_puts_h_above_every_fault_free_peak_and_certifies_by_the_hours():
    det = Detection(detectors=("cusum",), false_alarms_per_hour=10.0)
    runs = _ar1(20, 4000, 5)  # 20 x 195 s after the start-up: 1.08 h, certifiable at 10 per hour
    cal = F.calibrate(det, "cusum", runs, 0.05, 5.0)
    assert cal.certified and cal.stats["false_alarms"] == 0 and cal.meets is True
    assert cal.stats["upper_bound_per_hour"] == pytest.approx(-np.log(0.05) / cal.stats["exposure_hours"])
    b = cal.block()
    b.set_decision(cal.h * (1 - 1e-9), latch=0.0, restart=1.0)  # a hair lower: the largest peak's draw alarms
    assert sum(F.false_alarm_counts(b, [r], cal.h * (1 - 1e-9))[0] for r in runs) >= 1
    # too few hours: a threshold, not certified, not meeting the target
    short = F.calibrate(det, "cusum", runs[:3], 0.05, 5.0)
    assert not short.certified and short.stats["false_alarms"] == 0 and short.meets is False
    # one deterministic run (ideal hardware): a threshold, "meets" undetermined
    one = F.calibrate(det, "cusum", runs[:1], 0.05, 5.0, drawn=False)
    assert one.h is not None and one.meets is None
    # the operating curve: lower thresholds, more alarms
    counts = [c[1] for c in sorted(cal.curve)]
    assert counts[0] > counts[-1] == 0


def test_fresh_draws_alarm_no_more_often_than_the_wilks_bound_allows():
    """The guarantee by construction, tested on fresh draws: 60 calibrations on 20 fault-free draws
    each, every threshold tried on 20 fresh draws of the same process. Above the largest of n = 20
    exchangeable peaks a fresh draw alarms with probability 1/(n + 1) on average (the count of 20 is
    beta-binomial(20, 1, 20): mean share 1/21, standard deviation of the mean over 60 calibrations
    0.0084); the mean share stays within 4 of those of 1/21. A threshold two draws lower (the
    third-largest peak, share 3/21) fails the same bound. The draws are i.i.d. without a per-draw bias,
    so the O(1/n) optimism of a normalisation taken from the same draws is not probed here."""
    from scipy import stats

    from diagnosis.calibration import persisted_peaks

    det = Detection(detectors=("cusum",), false_alarms_per_hour=10.0)
    shares, lower = [], []
    for k in range(60):
        calib = _ar1(20, 300, 1000 + k)
        cal = F.calibrate(det, "cusum", calib, 0.05, 1.0)
        b = cal.block()
        peaks = persisted_peaks(b, _ar1(20, 300, 5000 + k))
        shares.append(float(np.mean(peaks >= cal.h)))
        lower.append(float(np.mean(peaks >= np.sort(persisted_peaks(b, calib))[-3])))
    d = stats.betabinom(20, 1, 20)
    bound = 1 / 21 + 4 * d.std() / 20 / np.sqrt(60)
    assert np.mean(shares) <= bound < np.mean(lower), (np.mean(shares), bound, np.mean(lower))


def test_a_runs_measures_name_the_wheel_and_a_sensor_fault_read_as_an_actuators():
    T, K = 0.05, 400
    t = np.arange(K) * T
    rng = np.random.default_rng(2)
    M = np.asarray(default_distribution(4), dtype=float)
    free = [(t, rng.normal(scale=0.01, size=(K, 3))) for _ in range(10)]
    cal = F.calibrate(Detection(detectors=("glr",)), "glr", free, T, 1.0)
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


def test_a_run_too_short_for_a_decision_is_neither_detected_nor_missed_and_nan_tails_are_cut():
    T = 0.05
    t = np.arange(0, 20.25, T)  # the last sample at 20.2 s
    free = [(t, np.random.default_rng(s).normal(scale=0.01, size=(len(t), 3))) for s in range(5)]
    cal = F.calibrate(Detection(detectors=("cusum",), persistence=0.2), "cusum", free, T, 1.0)
    m = 1 + int(np.ceil(0.2 / T - 1e-9))  # 5 samples from the onset on
    assert F.decidable(cal, t, 20.2 - (m - 1) * T) and not F.decidable(cal, t, 20.2 - (m - 2) * T)
    row = {"outcome": "stopped", "mission": 60.0, "fault": "lost", "onset": 20.01, "stop_time": 20.22,
           "sensor_fault": False, "channel": 2.0}
    big = free[2][1].copy()
    big[t >= 19.9 - 1e-9] += 5.0  # far above any threshold from 19.9 s: it would alarm given the samples
    assert F.run_measures(cal, row, t, big, None, 0.5) is None  # 20.05 .. 20.2: 4 samples, no decision possible
    ok = F.run_measures(cal, {**row, "onset": 19.9}, t, big, None, 0.5)
    assert ok is not None and ok["missed_detection"] is False
    # a fault-free draw whose estimate turns non-finite is kept up to its last finite sample
    r = free[0][1].copy()
    r[200:] = np.nan
    kept = F.fault_free_runs([(0, t, r), (1, t, free[1][1])], 60.0)
    assert len(kept) == 2 and len(kept[0][0]) == 200 and np.isfinite(kept[0][1]).all()
