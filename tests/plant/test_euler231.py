"""The 2-3-1 Euler kinematics of 001 (1)-(2) (plant/euler231.py) against rotation matrices and an
independent quaternion integration."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from plant import euler231

RNG = np.random.default_rng(11)


def _rot(axis, a):
    """Elementary frame rotation R_axis(a) (inertial -> rotated frame)."""
    c, s = math.cos(a), math.sin(a)
    if axis == 1:
        return np.array([[1, 0, 0], [0, c, s], [0, -s, c]])
    if axis == 2:
        return np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])
    return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])


def _quat_dcm(q):
    """Body-from-inertial DCM of a scalar-first unit quaternion (independent of plant/so3.py)."""
    q0, q1, q2, q3 = q / np.linalg.norm(q)
    return np.array(
        [
            [q0**2 + q1**2 - q2**2 - q3**2, 2 * (q1 * q2 + q0 * q3), 2 * (q1 * q3 - q0 * q2)],
            [2 * (q1 * q2 - q0 * q3), q0**2 - q1**2 + q2**2 - q3**2, 2 * (q2 * q3 + q0 * q1)],
            [2 * (q1 * q3 + q0 * q2), 2 * (q2 * q3 - q0 * q1), q0**2 - q1**2 - q2**2 + q3**2],
        ]
    )


def _quat_from_dcm(C):
    q0 = 0.5 * math.sqrt(max(0.0, 1.0 + np.trace(C)))
    return np.array([q0, (C[1, 2] - C[2, 1]) / (4 * q0), (C[2, 0] - C[0, 2]) / (4 * q0), (C[0, 1] - C[1, 0]) / (4 * q0)])


@pytest.mark.parametrize("k", range(20))
def test_dcm_is_the_2_3_1_sequence_and_inverts(k):
    sigma = RNG.uniform([-1.4, -3.0, -3.0], [1.4, 3.0, 3.0])
    nu, psi, gamma = sigma
    C = _rot(1, gamma) @ _rot(3, nu) @ _rot(2, psi)
    assert np.allclose(euler231.dcm(sigma), C, atol=1e-15)
    assert np.allclose(euler231.from_dcm(C), sigma, atol=1e-12)
    assert np.allclose(euler231.G(sigma) @ euler231.G_inv(sigma), np.eye(3), atol=1e-12)
    assert math.isclose(np.linalg.det(euler231.G(sigma)), -1.0 / math.cos(nu), rel_tol=1e-12)


@pytest.mark.parametrize("k", range(10))
def test_rates_match_the_rotation_kinematics(k):
    """C' = -omega^x C for the body rate omega: G must map omega to the angle rates that give it."""
    sigma = RNG.uniform([-1.3, -3.0, -3.0], [1.3, 3.0, 3.0])
    omega = RNG.normal(size=3)
    sd = np.array(euler231.rates(sigma, omega))
    assert np.allclose(sd, euler231.G(sigma) @ omega, atol=1e-14)
    eps = 1e-6
    C_dot = (euler231.dcm(sigma + eps * sd) - euler231.dcm(sigma - eps * sd)) / (2 * eps)
    W = np.array([[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]])
    assert np.allclose(C_dot, -W @ euler231.dcm(sigma), atol=1e-8)
    # the printed (2,3) entry -sin(gamma) cos(nu) would not: it breaks this identity
    G_printed = euler231.G(sigma)
    G_printed[1, 2] = -math.sin(sigma[2]) * math.cos(sigma[0])
    sd_p = G_printed @ omega
    C_dot_p = (euler231.dcm(sigma + eps * sd_p) - euler231.dcm(sigma - eps * sd_p)) / (2 * eps)
    assert not np.allclose(C_dot_p, -W @ euler231.dcm(sigma), atol=1e-3)


def test_G_inv_dot_is_the_derivative_of_G_inv():
    sigma = np.array([0.3, -0.7, 1.1])
    sd = np.array([0.2, -0.4, 0.9])
    eps = 1e-6
    num = (euler231.G_inv(sigma + eps * sd) - euler231.G_inv(sigma - eps * sd)) / (2 * eps)
    assert np.allclose(euler231.G_inv_dot(sigma, sd), num, atol=1e-9)


def test_euler_integration_matches_quaternion_integration_over_60_s():
    """sigma' = G(sigma) omega(t) and q' = 1/2 Omega(omega(t)) q for the same prescribed omega(t),
    both with DOP853 at rtol 1e-13; the quaternion converted to [nu, psi, gamma] agrees to 1e-9 rad
    over 60 s. omega(t) keeps |nu| < 70 deg (away from the singularity)."""

    def omega(t):
        return np.array([0.3 * math.sin(0.4 * t) + 0.1, 0.2 * math.cos(0.3 * t), -0.15 * math.sin(0.7 * t + 0.3)])

    sigma0 = np.array([-0.6, 0.5, 0.5])
    q0 = _quat_from_dcm(euler231.dcm(sigma0))

    def f_sigma(t, s):
        return euler231.rates(s, omega(t))

    def f_q(t, q):
        w1, w2, w3 = omega(t)
        Om = 0.5 * np.array([[0, -w1, -w2, -w3], [w1, 0, w3, -w2], [w2, -w3, 0, w1], [w3, w2, -w1, 0]])
        return Om @ q

    ts = np.linspace(0, 60, 601)
    a = solve_ivp(f_sigma, (0, 60), sigma0, method="DOP853", rtol=1e-13, atol=1e-14, t_eval=ts)
    b = solve_ivp(f_q, (0, 60), q0, method="DOP853", rtol=1e-13, atol=1e-14, t_eval=ts)
    assert np.allclose(_quat_dcm(q0), euler231.dcm(sigma0), atol=1e-14)
    worst = 0.0
    for k in range(len(ts)):
        s_q = euler231.from_dcm(_quat_dcm(b.y[:, k]))
        d = a.y[:, k] - s_q
        d[1:] = (d[1:] + math.pi) % (2 * math.pi) - math.pi  # psi, gamma wrap
        worst = max(worst, float(np.abs(d).max()))
    assert np.abs(a.y[0]).max() < math.radians(70)
    assert np.ptp(a.y[1]) > 1.0 and np.ptp(a.y[2]) > 1.0  # a real motion, not a small wobble
    assert worst < 1e-9, worst
