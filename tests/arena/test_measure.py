"""One run measured (arena/measure.py) and the calibrated detector (arena/detector.py), on trajectories
whose answers are known: the attitude error of 001's Euler angles against an independent per-row
computation, outcomes (stopped with its reason and time, failed, timeout), the time to band from the
last manoeuvre or the fault onset, the buildable verdict against the data-sheet wheels, alarms with
persistence, the conformal threshold and the leave-one-out count."""
import math

import numpy as np
import pandas as pd
import pytest

from arena import detector as D
from arena import measure as M
from arena.metrics import pointing_error_euler231
from orchestrator.results.metrics import attitude_error_rad
from plant.attitude_adapters import quaternion_from_dcm
from plant.euler231 import dcm
from plant.hardware.datasheets import WHEELS

SIG = {"attitude": "plant.theta", "rate": "plant.theta_dot", "delivered": "faults.u_f", "active": "faults.active"}


def test_attitude_error_of_euler_angles_is_the_rotation_angle():
    rng = np.random.default_rng(4)
    sigma = np.vstack([rng.uniform(-1.2, 1.2, (200, 3)), [[0.0, 0.0, 0.0], [1e-9, -2e-9, 3e-9], [0.3, 3.0, -2.9]]])
    q = M.euler231_quaternions(sigma)
    ref = np.array([quaternion_from_dcm(dcm(s)) for s in sigma])  # per row, the adapters' Shepperd
    assert np.allclose(np.abs(np.sum(q * ref, axis=1)), 1.0, atol=1e-12)  # the same rotation (q or -q)
    df = pd.DataFrame({"time": np.arange(len(sigma), dtype=float), **{f"plant.sigma[{i + 1}]": sigma[:, i] for i in range(3)}})
    err = M.attitude_error(df, {"attitude": "plant.sigma"}, None)
    mid = np.linalg.norm(sigma, axis=1) > 1e-3  # acos of the trace is accurate away from 0
    assert np.allclose(err[mid], pointing_error_euler231(sigma[mid]), atol=1e-9)
    assert err[-2] == pytest.approx(2.0 * np.linalg.norm(q[-2, 1:]), rel=1e-9) and err[-2] < 1e-8  # tiny angles too


def test_attitude_error_of_quaternions_against_a_switching_command():
    t = np.array([0.0, 1.0, 2.0])
    qd = [[1.0, 0, 0, 0], [math.cos(0.2), math.sin(0.2), 0, 0]]
    q = np.array([[1.0, 0, 0, 0], [1.0, 0, 0, 0], [math.cos(0.2), math.sin(0.2), 0, 0]])
    df = pd.DataFrame({"time": t, **{f"plant.q[{i}]": q[:, i] for i in range(4)}})
    err = M.attitude_error(df, {"attitude": "plant.q"}, {"times": [0.0, 1.0], "values": qd})
    assert err == pytest.approx([0.0, 0.4, 0.0], abs=1e-12)
    assert attitude_error_rad([0.0, 0.0, 1.0])[0] == pytest.approx(math.pi)


def _pitch(t, theta, u, active=None):
    d = {"time": t, "plant.theta[1]": theta, "plant.theta_dot[1]": np.gradient(theta, t), "faults.u_f[1]": u}
    if active is not None:
        d["faults.active"] = active
    return pd.DataFrame(d).rename(columns={"plant.theta[1]": "plant.theta", "plant.theta_dot[1]": "plant.theta_dot",
                                           "faults.u_f[1]": "faults.u_f"})


def _measure(df, **kw):
    args = dict(band=1e-3, status="ok", error=None, t_end=None, fault_class="none", onset=None, wheels=WHEELS)
    args.update(kw)
    return M.measure(df, SIG, **args)


def test_outcomes_stopped_failed_and_timeout():
    t = np.linspace(0.0, 0.2, 5)
    df = _pitch(t, 0.01 * np.ones(5), 0.1 * np.ones(5))
    m = _measure(df, status="failed", error="instance 'ctrl': ... FMU log: ValueError: singular", t_end=0.24)
    assert m["outcome"] == "stopped" and m["stop_time"] == 0.24 and "singular" in m["stop_reason"]
    assert m["peak_torque"] == pytest.approx(0.1)  # a stopped run carries its peaks over what ran
    assert _measure(None, status="failed", error="ImportError: x")["outcome"] == "failed"
    assert _measure(df, status="timeout", error="time limit")["outcome"] == "failed"


def test_time_to_band_counts_from_the_last_manoeuvre_or_the_onset():
    t = np.arange(0.0, 100.0, 0.05)
    theta = np.where(t < 30.0, 0.0, 0.1 * np.exp(-(t - 30.0)))  # a disturbance at 30 s, decaying
    u = 0.01 * np.exp(-t / 50.0)  # not at its peak: not saturated
    m = _measure(_pitch(t, theta, u, active=(t >= 30.0).astype(float)), fault_class="bias", onset=30.0)
    assert m["onset"] == 30.0 and m["settle_from"] == 30.0
    assert m["time_to_band"] == pytest.approx(math.log(100.0), abs=0.06)  # 0.1 e^-x = 1e-3
    assert m["outcome"] == "flies"
    m = _measure(_pitch(t, theta, u), manoeuvres=[20.0, 50.0])  # a later manoeuvre: counted from there
    assert m["settle_from"] == 50.0 and m["time_to_band"] == 0.0
    markov = _measure(_pitch(t, theta, u, active=(t >= 42.0).astype(float)), fault_class="markov")
    assert markov["onset"] == pytest.approx(42.0)  # the first active sample: the chain decides


def test_buildable_against_the_data_sheet_wheels():
    assert M.buildable(0.1, 10.0, WHEELS) == "wheels_hr12_12"
    assert M.buildable(0.2, 60.0, WHEELS) == "wheels_hr16_100"
    assert M.buildable(0.21, 1.0, WHEELS) is None and M.buildable(0.1, 101.0, WHEELS) is None
    t = np.arange(0.0, 10.0, 0.5)
    assert M.held_momentum(t, np.ones((len(t), 2)) * [1.0, -2.0]) == pytest.approx([9.5, 19.0])


def test_persistence_alarm_and_conformal_threshold():
    t = np.arange(0.0, 20.0, 0.05)
    s = np.where((t >= 10.0) & (t < 10.5), 1.0, 0.0) + np.where(t >= 15.0, 2.0, 0.0)
    assert D.first_alarm(t, s, 0.5, persistence=1.0) == pytest.approx(16.0)  # the 0.5 s blip is not persistent
    assert D.first_alarm(t, s, 0.5, persistence=0.2) == pytest.approx(10.2)
    assert D.first_alarm(t, s, 0.5, persistence=1.0, t_from=15.5) == pytest.approx(16.5)  # counted from t_from
    assert D.persisted_peak(t, s, 1.0) == pytest.approx(2.0) and D.persisted_peak(t, np.minimum(s, 1.0), 0.6) == 1.0
    peaks = list(np.arange(1.0, 21.0))  # 20 fault-free runs
    cal = D.calibrate(peaks, 3600.0 * 0.1, rate=0.5, margin=0.0)  # a = 1 - exp(-0.05) = 0.0488: k = ceil(21 x 0.951) = 20
    assert cal["k"] == 20 and not cal["extrapolated"] and cal["threshold"] == 20.0
    cal = D.calibrate(peaks, 3600.0, rate=1.5, margin=0.0)  # a = 0.777: k = ceil(21 x 0.223) = 5
    assert cal["k"] == 5 and cal["threshold"] == 5.0
    cal = D.calibrate(peaks, 60.0, rate=1.0, margin=0.2)  # a = 0.0165 needs 60 runs: the largest, x 1.2
    assert cal["extrapolated"] and cal["threshold"] == pytest.approx(24.0)
    loo = D.leave_one_out_alarms([1.0, 1.0, 1.0, 5.0], 60.0, 1.0, 0.2)
    assert loo == [False, False, False, True]  # the outlier exceeds 1.2 x the others' largest
    assert D.leave_one_out_alarms([3.0], 60.0, 1.0, 0.2) == [False]  # one run: in sample


def test_a_scalar_estimate_gives_a_scalar_statistic():
    t = np.arange(0.0, 10.0, 0.05)
    df = _pitch(t, 1e-4 * np.ones_like(t), 0.01 * np.exp(-t))
    df["est.d0_hat"] = np.where(t >= 6.0, 0.3, 0.01)
    df["faults.fault"] = 0.0
    sig = {**SIG, "estimate": "est.d0_hat", "truth": "faults.fault"}
    m = M.measure(df, sig, band=1e-3, status="ok", error=None, t_end=None, fault_class="none", onset=None,
                  wheels=WHEELS, nominal=0.0, estimate_from=1.0)
    ts, s = m["statistic"]
    assert s.shape == t.shape and D.persisted_peak(ts, s, 1.0, 1.0) == pytest.approx(0.3)
    assert m["estimate_rms_error"] > 0
