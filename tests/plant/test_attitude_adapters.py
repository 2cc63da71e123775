"""Attitude adapters (plant/attitude_adapters.py) against rotation matrices formed independently by
scipy's Rotation: 001's 2-3-1 Euler angles are the intrinsic Y-Z-X sequence [psi, nu, gamma] of an
active rotation R (body -> inertial components), whose transpose is the frame rotation C (inertial
-> body) that both 001 (1) and 000 (3) use."""
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from plant.attitude_adapters import (
    AttitudeError,
    Euler231ToQuaternion,
    QuaternionToEuler231,
    quaternion_from_dcm,
)
from plant.so3 import rotation_matrix

RNG = np.random.default_rng(26)


def _scipy_C(sigma):
    nu, psi, gamma = sigma
    return Rotation.from_euler("YZX", [psi, nu, gamma]).as_matrix().T


def _sigmas(n=200, nu_max=math.radians(89.0)):
    return np.column_stack([RNG.uniform(-nu_max, nu_max, n), RNG.uniform(-math.pi, math.pi, n),
                            RNG.uniform(-math.pi, math.pi, n)])


def _run(block, u):
    block.initialize(0.0)
    return block.outputs_at(0.0, np.asarray(u, dtype=float))


def test_euler_to_quaternion_matches_rotation_matrices():
    b = Euler231ToQuaternion()
    b.initialize(0.0)
    for sigma in _sigmas():
        q = b.outputs_at(0.0, sigma)
        assert abs(np.linalg.norm(q) - 1.0) < 1e-14 and q[0] >= 0.0
        np.testing.assert_allclose(rotation_matrix(q), _scipy_C(sigma), atol=2e-15 * 8)
        # the same numbers as scipy's quaternion of the active rotation (scalar last), up to sign
        w = Rotation.from_euler("YZX", [sigma[1], sigma[0], sigma[2]]).as_quat()
        ref = np.array([w[3], w[0], w[1], w[2]])
        np.testing.assert_allclose(q, ref * math.copysign(1.0, ref[0]), atol=1e-14)


def test_quaternion_to_euler_matches_rotation_matrices():
    b = QuaternionToEuler231()
    b.initialize(0.0)
    for sigma in _sigmas():
        w = Rotation.from_euler("YZX", [sigma[1], sigma[0], sigma[2]]).as_quat()
        for sign in (1.0, -1.0):  # q and -q: the same attitude, the same angles
            q = sign * np.array([w[3], w[0], w[1], w[2]]) * 3.0  # any norm > 0
            out = b.outputs_at(0.0, q)
            np.testing.assert_allclose(out, sigma, atol=1e-10)
            np.testing.assert_allclose(_scipy_C(out), _scipy_C(sigma), atol=1e-13)


@pytest.mark.parametrize("nu", [math.pi / 2, -math.pi / 2])
def test_quaternion_to_euler_at_the_singularity_reproduces_the_attitude(nu):
    b = QuaternionToEuler231()
    b.initialize(0.0)
    for psi, gamma in RNG.uniform(-math.pi, math.pi, (20, 2)):
        C = _scipy_C((nu, psi, gamma))
        out = b.outputs_at(0.0, quaternion_from_dcm(C))
        assert abs(abs(out[0]) - math.pi / 2) < 1e-6
        np.testing.assert_allclose(_scipy_C(out), C, atol=1e-7)


def test_quaternion_from_dcm_covers_every_branch():
    # rotations by ~pi about each axis exercise the q1, q2, q3 branches of Shepperd's method
    for axis in np.vstack([np.eye(3), RNG.normal(size=(50, 3))]):
        for angle in (0.0, 1e-9, 1.0, math.pi - 1e-6, math.pi):
            R = Rotation.from_rotvec(axis / np.linalg.norm(axis) * angle)
            C = R.as_matrix().T
            q = quaternion_from_dcm(C)
            assert q[0] >= 0.0
            np.testing.assert_allclose(rotation_matrix(q), C, atol=1e-12)


def test_attitude_error_is_the_relative_rotation_and_rate_error():
    b = AttitudeError()
    b.initialize(0.0)
    for _ in range(200):
        Rq, Rd = Rotation.random(random_state=RNG), Rotation.random(random_state=RNG)
        q = np.roll(Rq.as_quat(), 1)  # scalar first; C(q) = R^T
        qd = np.roll(Rd.as_quat(), 1)
        w, wd = RNG.normal(size=3), RNG.normal(size=3)
        out = b.outputs_at(0.0, np.concatenate((q, w, qd, wd)))
        qe, we = out[0:4], out[4:7]
        Ce = Rq.as_matrix().T @ Rd.as_matrix()  # C(q) C(q_d)^T: body relative to the desired frame
        np.testing.assert_allclose(rotation_matrix(qe), Ce, atol=1e-13)
        assert qe[0] >= 0.0  # hemisphere = 1
        np.testing.assert_allclose(we, w - Ce @ wd, atol=1e-13)  # 000 (5)


def test_attitude_error_literal_hemisphere_keeps_000_sign():
    b = AttitudeError()
    b.set_parameter("hemisphere", 0.0)
    b.initialize(0.0)
    q = np.array([math.cos(2.0), 0.0, 0.0, math.sin(2.0)])  # 4 rad about z: q0 < 0
    out = b.outputs_at(0.0, np.concatenate((q, np.zeros(3), [1.0, 0, 0, 0], np.zeros(3))))
    np.testing.assert_allclose(out[0:4], q, atol=1e-15)
    b2 = AttitudeError()
    out2 = _run(b2, np.concatenate((q, np.zeros(3), [1.0, 0, 0, 0], np.zeros(3))))
    np.testing.assert_allclose(out2[0:4], -q, atol=1e-15)


def test_bad_quaternion_is_named():
    b = QuaternionToEuler231()
    b.initialize(0.0)
    with pytest.raises(ValueError, match="norm 0"):
        b.outputs_at(0.0, np.zeros(4))
    a = AttitudeError()
    a.set_parameter("hemisphere", 2.0)
    with pytest.raises(ValueError, match="hemisphere"):
        a.initialize(0.0)
