"""Sampled sensors and the zero-order hold (plant/hardware/sensors.py, sample_hold.py).

Noise statistics are checked against their definitions with bounds that hold for the fixed seeds
used (and, by the sample sizes, with a wide margin for any seed): the angle random walk through an
Allan deviation computed here from the samples (sigma_A(tau) = sigma_v / sqrt(tau) for white rate
noise), the rate random walk through the variance of the bias increments, the Gauss-Markov bias
through its stationary variance and lag-one correlation, the star tracker through its error
angles' standard deviations per axis."""
import math

import numpy as np
import pytest

from plant.hardware.datasheets import ARCSEC, DEG_PER_HOUR, DEG_PER_SQRT_HOUR, GYROS
from plant.hardware.sample_hold import ZeroOrderHold
from plant.hardware.sensors import AngleSensor, RateGyro, StarTracker, compose
from plant.so3 import rotation_matrix


def _sample(block, n, u, T):
    """n samples at the sample instants (communication step = sample period)."""
    ys, t = [], 0.0
    for k in range(n):
        t = k * T
        ys.append(block.outputs_at(t, u))
        block.advance(t, T, u)
    return np.array(ys)


def _gyro(n_axes=3, **p):
    b = RateGyro(n_axes)
    b.set_parameters(p)
    b.initialize(0.0)
    return b


def _allan(rate, T, m):
    """Overlapping Allan deviation of a rate series at tau = m T (from the integrated angle)."""
    theta = np.concatenate(([0.0], np.cumsum(rate) * T))
    d = theta[2 * m:] - 2 * theta[m:-m] + theta[:-2 * m]
    return math.sqrt(np.mean(d**2) / (2 * (m * T) ** 2))


def test_angle_random_walk_allan_deviation():
    arw, T = 0.15 * DEG_PER_SQRT_HOUR, 0.01
    y = _sample(_gyro(arw=arw, sample_period=T, seed=1), 40000, np.zeros(3), T)
    for axis in range(3):
        for m in (1, 10, 100):
            ratio = _allan(y[:, axis], T, m) * math.sqrt(m * T) / arw
            assert abs(ratio - 1.0) < (0.03 if m < 100 else 0.1), (axis, m, ratio)


def test_rate_random_walk_bias_increments():
    su, T = 1e-7, 0.1
    y = _sample(_gyro(rrw=su, sample_period=T, seed=2), 20000, np.zeros(3), T)
    bias = y[:, 3:6]  # ground truth: (beta_k + beta_k+1) / 2
    inc = np.diff(bias, axis=0)  # (w_k + w_k+1) / 2 sigma_u sqrt(T): variance sigma_u^2 T / 2
    ratio = inc.std(axis=0) / (su * math.sqrt(T / 2.0))
    assert np.all(np.abs(ratio - 1.0) < 0.03), ratio
    # and the measurement equals the true rate plus that bias (no ARW here; RRW's own noise term)
    noise = y[:, 0:3] - bias
    np.testing.assert_allclose(noise.std(axis=0) / (su * math.sqrt(T / 12.0)), 1.0, atol=0.03)


def test_bias_instability_gauss_markov():
    # tau = 5 T: phi = 0.82, about 3000 effective samples of 30000: the bounds are > 4 standard errors
    sb, tau, T = 0.5 * DEG_PER_HOUR, 5.0, 1.0
    y = _sample(_gyro(bi_sigma=sb, bi_tau=tau, sample_period=T, seed=3), 30000, np.zeros(3), T)
    g = y[:, 3:6]
    np.testing.assert_allclose(g.std(axis=0) / sb, 1.0, atol=0.06)  # stationary from the start
    phi = math.exp(-T / tau)
    lag1 = np.mean(g[1:] * g[:-1], axis=0) / np.mean(g * g, axis=0)
    np.testing.assert_allclose(lag1, phi, atol=0.015)


def test_measurement_is_the_true_rate_plus_noise_held_between_samples():
    b = _gyro(n_axes=1, sample_period=0.1, **{k: v for k, v in GYROS["gyro_stim300"].items() if k != "sample_period"})
    t, h, rows = 0.0, 0.01, []
    for k in range(100):
        w = np.array([0.01 * math.sin(k * 0.1)])
        rows.append((t, b.outputs_at(t, w)[0], w[0]))
        b.advance(t, h, w)
        t = round(t + h, 12)
    meas = np.array([r[1] for r in rows])
    for k in range(100):  # held for the 10 points of each sample
        assert meas[k] == meas[10 * (k // 10)]
    err = meas[::10] - np.array([r[2] for r in rows])[::10]
    assert np.abs(err).max() < 5 * 0.15 * DEG_PER_SQRT_HOUR / math.sqrt(0.1)  # ARW over a 0.1 s sample


def test_same_seed_same_noise_other_seed_other_noise_and_rollback():
    p = dict(arw=1e-4, rrw=1e-6, bi_sigma=1e-5, bi_tau=10.0, sample_period=0.02)
    a = _sample(_gyro(seed=5, **p), 200, np.zeros(3), 0.02)
    b = _sample(_gyro(seed=5, **p), 200, np.zeros(3), 0.02)
    c = _sample(_gyro(seed=6, **p), 200, np.zeros(3), 0.02)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    g = _gyro(seed=5, **p)
    _sample(g, 100, np.zeros(3), 0.02)
    saved = g.get_state()
    first = [g.outputs_at(2.0 + k * 0.02, np.zeros(3)).tolist() for k in range(1)]
    run1 = _sample_from(g, 2.0, 50)
    g.set_state(saved)
    run2 = _sample_from(g, 2.0, 50)
    assert run1 == run2 and first[0] == run1[0]


def _sample_from(g, t0, n, T=0.02):
    out = []
    for k in range(n):
        t = t0 + k * T
        out.append(g.outputs_at(t, np.zeros(3)).tolist())
        g.advance(t, T, np.zeros(3))
    return out


def test_samples_inside_a_step_use_the_held_input():
    b = _gyro(sample_period=0.01, seed=1)
    b.advance(0.0, 0.1, np.zeros(3))  # ten sample instants inside one communication step
    assert b.clock.k == 10 and b.outputs_at(0.1, np.zeros(3))[-1] == pytest.approx(0.11)


def test_star_tracker_noise_per_axis():
    sc, sr = 6 * ARCSEC, 40 * ARCSEC
    b = StarTracker()
    b.set_parameters({"sigma_cross": sc, "sigma_roll": sr, "boresight": 2, "sample_period": 0.2, "seed": 4})
    b.initialize(0.0)
    q = np.array([0.9, 0.3, -0.2, 0.25])
    q /= np.linalg.norm(q)
    y = _sample(b, 10000, q, 0.2)
    qm = y[:, 0:4]
    assert np.all(np.abs(np.linalg.norm(qm, axis=1) - 1.0) < 1e-14) and np.all(qm @ q > 0)
    ang = np.array([b.error_angles(q, row) for row in qm])
    np.testing.assert_allclose(ang.std(axis=0) / np.array([sc, sr, sc]), 1.0, atol=0.03)
    np.testing.assert_allclose(ang.mean(axis=0), 0.0, atol=4 * sr / math.sqrt(10000))


def test_star_tracker_bias_is_a_fixed_rotation():
    b = StarTracker()
    b.set_parameters({"bias[1]": 1e-3, "bias[3]": -2e-3})
    b.initialize(0.0)
    q = np.array([1.0, 0.0, 0.0, 0.0])
    qm = b.outputs_at(0.0, q)[0:4]
    np.testing.assert_allclose(b.error_angles(q, qm), [1e-3, 0.0, -2e-3], rtol=0, atol=1e-15)


def test_compose_multiplies_rotation_matrices():
    rng = np.random.default_rng(0)
    for _ in range(50):
        p, q = rng.normal(size=4), rng.normal(size=4)
        p, q = p / np.linalg.norm(p), q / np.linalg.norm(q)
        np.testing.assert_allclose(rotation_matrix(compose(p, q)), rotation_matrix(p) @ rotation_matrix(q), atol=1e-14)


def test_angle_sensor():
    b = AngleSensor(1)
    b.set_parameters({"sigma": 1e-4, "bias": 2e-4, "sample_period": 0.2, "seed": 9})
    b.initialize(0.0)
    y = _sample(b, 20000, np.array([0.05]), 0.2)[:, 0] - 0.05
    assert abs(y.mean() - 2e-4) < 4 * 1e-4 / math.sqrt(20000) and abs(y.std() / 1e-4 - 1) < 0.03


def test_zero_order_hold():
    b = ZeroOrderHold(3)
    b.set_parameters({"sample_period": 0.1})
    b.initialize(0.0)
    t, outs = 0.0, []
    for k in range(50):
        u = np.array([k, -k, 2.0 * k], dtype=float)
        outs.append(b.outputs_at(t, u))
        b.advance(t, 0.01, u)
        t = round(t + 0.01, 12)
    for k, y in enumerate(outs):
        ks = 10 * (k // 10)  # the sample taken at the last instant t_ks = ks * 10 ms
        np.testing.assert_array_equal(y[0:3], [ks, -ks, 2.0 * ks])
        assert y[3] == pytest.approx(0.1 * (k // 10 + 1))
