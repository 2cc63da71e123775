"""The arena's metric set (arena/metrics.py) on trajectories whose metrics are computed by hand."""
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from arena import metrics as m

T = np.linspace(0.0, 10.0, 1001)  # 10 ms rows


def test_time_to_band_on_a_linear_decay_is_the_crossing():
    err = np.maximum(1.0 - 0.2 * T, 0.0)  # 1 rad -> 0 at 5 s
    assert m.time_to_band(T, err, 0.1) == pytest.approx(4.5, abs=1e-9)  # 1 - 0.2 t = 0.1
    assert m.time_to_band(T, err, 0.1, t_start=2.0) == pytest.approx(2.5, abs=1e-9)
    assert m.time_to_band(T, err, 2.0) == 0.0
    assert m.time_to_band(T, 1.0 + 0 * T, 0.1) is None  # never settles
    bump = err.copy()
    bump[T >= 8.0] = 0.2  # leaves the band again at 8 s: settles only if it comes back
    assert m.time_to_band(T, bump, 0.1) is None


def test_error_after_settling():
    err = np.where(T < 5.0, 1.0, 0.01 * np.sin(2 * math.pi * T))  # whole periods from 5 to 10 s
    s = m.error_after(T, err, 5.0)
    assert s["rms"] == pytest.approx(0.01 / math.sqrt(2), rel=1e-3)
    assert s["max"] == pytest.approx(0.01, rel=1e-6) and s["final"] == pytest.approx(0.0, abs=1e-12)
    assert m.error_after(T, err, None) == {"rms": None, "max": None, "final": None}
    w = np.column_stack([0 * T + 3e-4, 0 * T + 4e-4, 0 * T])  # norms 5e-4
    assert m.error_after(T, w, 0.0)["rms"] == pytest.approx(5e-4, rel=1e-12)


def test_torque_metrics_of_a_constant_and_a_square_command():
    u = np.column_stack([0 * T + 0.3, 0 * T - 0.4, 0 * T])  # ||u|| = 0.5
    assert m.peak_torque(u) == {"axis": pytest.approx(0.4), "norm": pytest.approx(0.5)}
    assert m.rms_torque(T, u) == pytest.approx(0.5, rel=1e-12)
    assert m.control_energy(T, u) == pytest.approx(0.25 * 10.0, rel=1e-12)  # int ||u||^2 over 10 s
    sq = np.where(T < 5.0, 1.0, 0.0)  # held: 1 on [0, 5)
    assert m.control_energy(T, sq) == pytest.approx(5.0, rel=1e-12)
    assert m.rms_torque(T, sq) == pytest.approx(math.sqrt(0.5), rel=1e-12)


def test_momentum_used_is_the_peak_of_the_torque_integral():
    tau = np.column_stack([np.where(T < 4.0, 0.2, -0.2), 0 * T, 0 * T])  # +0.8 N.m.s at 4 s, back to -0.4 at 10
    assert m.momentum_used(T, tau) == pytest.approx(0.8, rel=1e-9)
    h = np.column_stack([0.5 * np.sin(T), -1.2 + 0 * T])
    assert m.peak_wheel_momentum(h, h_max=12.0) == {"peak": pytest.approx(1.2), "fraction": pytest.approx(0.1)}


def test_estimate_error_and_detection():
    onset = 4.0
    f = np.where(T >= onset, 0.5, 0.0)
    f_hat = np.where(T >= onset, 0.5 * (1.0 - np.exp(-(T - onset) / 0.5)), 0.0)  # first-order estimate
    # the estimate crosses 0.1 N.m at onset + 0.5 ln(0.5 / 0.4); rows every 10 ms
    t_cross = onset + 0.5 * math.log(0.5 / 0.4)
    delay = m.detection_delay(T, f_hat, 0.1, onset)
    assert t_cross - onset <= delay < t_cross - onset + 0.01 + 1e-12
    assert m.detection_delay(T, f_hat, 0.6, onset) is None
    # RMS error over [4, 10]: sqrt(int 0.25 e^(-2 s / 0.5) ds / 6) = sqrt(0.25 * 0.25 (1 - e^-24) / 6)
    ref = math.sqrt(0.25 * 0.25 * (1 - math.exp(-24.0)) / 6.0)
    assert m.estimate_rms_error(T, f_hat, f, onset) == pytest.approx(ref, rel=2e-2)  # held sum vs integral


def test_false_alarms_and_their_rate():
    quiet = 0.05 * np.sin(T)
    assert not m.false_alarm(T, quiet, 0.1)
    spike = quiet.copy()
    spike[50] = 0.2  # at 0.5 s: inside a start-up window that is skipped
    assert m.false_alarm(T, spike, 0.1) and not m.false_alarm(T, spike, 0.1, t_from=1.0)
    r = m.false_alarm_rate([True] * 2 + [False] * 18)
    assert r["rate"] == 0.1 and r["draws"] == 20 and 0.0 < r["low"] < 0.1 < r["high"] < 0.35
    assert m.false_alarm_rate([])["rate"] is None


def test_pointing_errors_are_principal_angles():
    rng = np.random.default_rng(1)
    R = Rotation.random(50, random_state=rng)
    Rd = Rotation.random(random_state=rng)
    q = np.roll(R.as_quat(), 1, axis=1)
    qd = np.roll(Rd.as_quat(), 1)
    ref = (Rd.inv() * R).magnitude()  # angle of the relative rotation
    np.testing.assert_allclose(m.pointing_error_between(q, qd), ref, atol=1e-12)
    np.testing.assert_allclose(m.pointing_error_between(-q, qd), ref, atol=1e-12)
    qe = np.array([[math.cos(0.05), math.sin(0.05), 0, 0], [-math.cos(0.05), 0, 0, math.sin(0.05)]])
    np.testing.assert_allclose(m.pointing_error_quaternion(qe), [0.1, 0.1], atol=1e-15)
    sigma = np.array([[0.1, 0.0, 0.0], [0.0, -0.2, 0.0], [0.0, 0.0, 0.3]])  # one elementary rotation each
    np.testing.assert_allclose(m.pointing_error_euler231(sigma), [0.1, 0.2, 0.3], atol=1e-12)


def test_metric_set_of_one_run_is_json_safe():
    import json

    err = np.maximum(1.0 - 0.2 * T, 0.001)
    u = np.column_stack([0 * T + 0.3, 0 * T - 0.4, 0 * T])
    out = m.metric_set(T, pointing_error=err, rate_error=0 * T, torque=u, band=0.01, settle_margin=0.5,
                       fault=0 * T, fault_hat=0.05 + 0 * T, threshold=0.1, estimate_from=1.0)
    assert out["time_to_band"] == pytest.approx(4.95) and out["pointing_max_after"] == pytest.approx(0.001)
    assert out["false_alarm"] is False and out["estimate_rms_error"] == pytest.approx(0.05)
    json.dumps(out, allow_nan=False)
    never = m.metric_set(T, pointing_error=1 + 0 * T, rate_error=0 * T, torque=u, band=0.01)
    assert never["time_to_band"] is None and never["pointing_rms_after"] is None and not never["settled"]


def test_bad_times_are_refused():
    with pytest.raises(ValueError, match="increasing"):
        m.control_energy([0.0, 1.0, 1.0], [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="rows"):
        m.rms_torque(T, np.ones(5))
