"""The attitude error of runs and campaigns (issue 36): final_attitude_error and
max_attitude_error_last_10s in rad, the rotation angle of the error quaternion 2 asin ||q_ev||,
against scipy's rotation angle; the quaternion norm ||q_ev|| kept as final_q_ev_norm."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from orchestrator.results.metrics import attitude_error_rad, attitude_metrics


def test_the_angle_is_scipys_rotation_magnitude():
    rng = np.random.default_rng(36)
    q = rng.normal(size=(500, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[:3] = [[1, 0, 0, 0], [-1, 0, 0, 0], [0, 1, 0, 0]]  # zero, zero (the other cover), pi
    ours = attitude_error_rad(q[:, 1:])
    theirs = Rotation.from_quat(q[:, [1, 2, 3, 0]]).magnitude()  # scipy: scalar last
    assert ours == pytest.approx(theirs, abs=1e-7)  # asin loses digits near pi / 2 only
    assert ours[:3] == pytest.approx([0.0, 0.0, np.pi])


def test_a_small_error_is_twice_the_norm_and_a_norm_over_one_is_clipped():
    assert attitude_error_rad(np.array([3e-4, 0.0, -4e-4])) == pytest.approx(2 * 5e-4, rel=1e-7)
    assert attitude_error_rad(np.array([[1.0 + 1e-12, 0.0, 0.0]])) == pytest.approx([np.pi])


def test_run_metrics_keep_both_names():
    t = np.linspace(0.0, 20.0, 2001)
    angle = 0.1 * np.exp(-t / 5.0)  # rad, about axis (0, 0.6, 0.8)
    q = np.column_stack([np.cos(angle / 2), np.outer(np.sin(angle / 2), [0.0, 0.6, 0.8])])
    m = attitude_metrics(t, q)
    assert m["final_attitude_error"] == pytest.approx(angle[-1], rel=1e-9)
    assert m["max_attitude_error_last_10s"] == pytest.approx(angle[t >= 10.0].max(), rel=1e-9)
    assert m["final_q_ev_norm"] == pytest.approx(np.sin(angle[-1] / 2), rel=1e-9)
    theta = np.column_stack([-angle])  # a pitch angle (rad): its magnitude, no quaternion norm
    m = attitude_metrics(t, theta)
    assert m == {"final_attitude_error": pytest.approx(angle[-1]),
                 "max_attitude_error_last_10s": pytest.approx(angle[t >= 10.0].max())}
