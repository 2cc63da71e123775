"""Sensor faults (plant/sensor_faults.py): gyro bias step, drift ramp, stuck; star-tracker outage and
frozen output; each against its definition at communication points, with the ground truth it logs,
the announced events, the end of a fault of finite duration and rollback."""
import math

import numpy as np
import pytest

from plant.hardware.sensors import compose, small_rotation
from plant.sensor_faults import GyroFault, StarTrackerFault, gyro_fault_3, rotation_angle, star_tracker_fault


def _gyro(**p):
    b = gyro_fault_3()
    b.set_parameters(p)
    b.initialize(0.0)
    return b


def _out(b, t, u):
    return dict(zip([v.name for v in b.outputs], b.outputs_at(t, np.asarray(u, dtype=float))))


W = np.array([0.01, -0.02, 0.03])


def test_gyro_bias_step_on_one_axis_from_its_onset():
    b = _gyro(fault_class=1, channel=2, onset=5.0, magnitude=0.002)
    before, after = _out(b, 4.99, W), _out(b, 5.0, W)
    assert [before[f"omega_f[{i}]"] for i in (1, 2, 3)] == W.tolist() and before["active"] == 0.0
    assert after["omega_f[2]"] == pytest.approx(W[1] + 0.002) and after["omega_f[1]"] == W[0]
    assert after["fault[2]"] == pytest.approx(0.002) and after["active"] == 1.0
    assert before["t_next_event"] == 5.0 and after["t_next_event"] == 1e300


def test_gyro_drift_ramp_grows_with_time_and_ends_after_its_duration():
    b = _gyro(fault_class=2, onset=10.0, rate=1e-4, duration=20.0)
    y = _out(b, 25.0, W)
    assert [y[f"fault[{i}]"] for i in (1, 2, 3)] == pytest.approx([1.5e-3] * 3)
    assert y["t_next_event"] == 30.0
    end = _out(b, 30.0, W)
    assert end["active"] == 0.0 and end["fault[1]"] == 0.0


def test_gyro_stuck_holds_the_measurement_of_the_onset_point():
    b = _gyro(fault_class=3, channel=0, onset=1.0)
    for k in range(10):
        t = 0.5 + 0.1 * k
        w = W * (1 + k)
        y = _out(b, t, w)
        if t >= 1.0 - 1e-12:
            np.testing.assert_allclose([y[f"omega_f[{i}]"] for i in (1, 2, 3)], W * 6)  # the 1.0 s point's value
            np.testing.assert_allclose([y[f"fault[{i}]"] for i in (1, 2, 3)], W * 6 - w)
        b.advance(t, 0.1, w)
    s = b.get_state()
    b2 = _gyro(fault_class=3, channel=0, onset=1.0)
    b2.set_state(s)
    assert _out(b2, 2.0, W) == _out(b, 2.0, W)
    assert _gyro(fault_class=3, stuck_mode=1, magnitude=0.5, onset=0.0).outputs_at(0.0, W)[0] == 0.5


def test_star_tracker_outage_flags_and_holds_frozen_does_not_flag():
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    for cls, valid in ((1, 0.0), (2, 1.0)):
        b = star_tracker_fault()
        b.set_parameters({"fault_class": cls, "onset": 2.0, "duration": 3.0})
        b.initialize(0.0)
        qs = [compose(small_rotation([0.0, 0.0, 0.01 * k]), q0) for k in range(80)]
        for k, q in enumerate(qs):
            t = 0.1 * k
            y = _out(b, t, q)
            qf = np.array([y[f"q_f[{i}]"] for i in range(4)])
            if 2.0 - 1e-9 <= t < 5.0 - 1e-9:
                np.testing.assert_allclose(qf, qs[20])
                assert y["valid"] == valid and y["active"] == 1.0
                assert y["fault_angle"] == pytest.approx(0.01 * (k - 20), abs=1e-12)
            else:
                np.testing.assert_allclose(qf, q)
                assert y["valid"] == 1.0 and y["fault_angle"] == 0.0 and y["active"] == 0.0
            b.advance(t, 0.1, q)


def test_rotation_angle_and_bad_parameters():
    q = compose(small_rotation([0.1, -0.2, 0.3]), np.array([0.5, 0.5, 0.5, 0.5]))
    assert rotation_angle(q, [0.5, 0.5, 0.5, 0.5]) == pytest.approx(math.sqrt(0.14), rel=1e-12)
    assert rotation_angle(-q, q) == pytest.approx(0.0, abs=1e-7)
    for cls, p, match in ((GyroFault, {"fault_class": 4}, "fault_class"), (GyroFault, {"channel": 4}, "channel"),
                          (StarTrackerFault, {"duration": -1.0}, "duration"), (GyroFault, {"stuck_mode": 2}, "stuck_mode")):
        b = cls() if cls is StarTrackerFault else cls(3)
        b.set_parameters(p)
        with pytest.raises(ValueError, match=match):
            b.initialize(0.0)
