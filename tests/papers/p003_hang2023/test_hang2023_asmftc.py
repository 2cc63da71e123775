"""ASMFTC (controller/asmftc.py): the law against 003 (3.9)-(3.15), (3.21) written out, the readings
tested in closed loop (plant + TSFDO + ASMFTC, published L1, 0.5 ms, fault 0.4 at 20 s), bad input.

Closed-loop evidence for the readings (60 s runs, papers/p003_hang2023/README.md); asserted here on
2.5 s windows, where each reading already shows its behaviour:
* e = theta - theta_d (default) vs the literal e = theta_d - theta: the latter diverges (1.4 s);
* Phi = (1 + lambda_hat) delta (default) vs (lambda_hat - 1) delta: with the leaky laws (3.19)-(3.20)
  the latter drifts away (theta grows past theta(0)); with (3.10) + (3.11) + (3.13) both converge
  (the latter only by 5 s: 60 s runs in the README).
"""
import math

import numpy as np
import pytest

from papers.p003_hang2023 import blocks


def _ctrl(**p):
    c = blocks.controller()
    c.set_parameters(p)
    c.initialize(0.0)
    return c


def test_law_matches_the_equations():
    c = _ctrl(switching=1, gamma3=1.0, f_hat_init=0.02, lambda_hat_init=1.3)
    th, thd, d0 = 0.05, -0.03, 0.11
    y = c.outputs_at(0.0, np.array([th, thd, 0.0, 0.0, d0]))
    J1 = 6.14 - (1.27806**2 + 0.91758**2)
    N, r = 5.0, 5.0 / 3.0
    sgn = lambda x, a: math.copysign(abs(x) ** a, x)  # noqa: E731
    s = th + N * sgn(thd, r)  # (3.9)
    ueq = (3.0 / 5.0) * J1 / N * sgn(thd, 2 - r)
    delta = abs(ueq) + abs(d0) + 0.02 + 0.5  # (3.15)
    Phi = (1 + 1.3) * delta  # (3.12), reading (1 + lambda_hat) delta
    u = -ueq - d0 - 0.02 - Phi * s / (abs(s) + 1.0)  # (3.21)
    assert y[0] == pytest.approx(u, rel=1e-14) and y[1] == pytest.approx(s, rel=1e-14)
    assert y[6] == pytest.approx(Phi, rel=1e-14) and y[7] == pytest.approx(delta, rel=1e-14)
    c0 = _ctrl(switching=0, phi_form=0, f_hat_init=0.02, lambda_hat_init=1.3)
    y0 = c0.outputs_at(0.0, np.array([th, thd, 0.0, 0.0, d0]))
    assert y0[0] == pytest.approx(-ueq - d0 - 0.02 - 0.3 * delta * math.copysign(1.0, s), rel=1e-14)  # (3.10)
    # adaptive laws over one step (3.19)-(3.20): f_hat' = -f_hat + r beta |e'|^(r-1) N s, lambda' = -lambda + alpha delta |s|
    c.advance(0.0, 1e-4, np.array([th, thd, 0.0, 0.0, d0]))
    fdot = -0.02 + r * abs(thd) ** (r - 1) * N * s
    ldot = -1.3 + delta * abs(s)
    assert (c.f_hat - 0.02) / 1e-4 == pytest.approx(fdot, rel=1e-3)
    assert (c.lam - 1.3) / 1e-4 == pytest.approx(ldot, rel=1e-3)


def _loop(T=2.5, h=5e-4, **ctrl):
    p, o, c = blocks.plant(), blocks.observer(), blocks.controller()
    c.set_parameters(ctrl)
    for b in (p, o, c):
        b.initialize(0.0)
    u = np.zeros(1)
    oin, cin = np.zeros(3), np.zeros(5)
    th = []
    for k in range(int(round(T / h))):
        t = k * h
        y = p.outputs_at(t, u)
        oin[:2] = cin[:2] = y[:2]
        cin[4] = o.outputs_at(t, oin)[0]
        u = c.outputs_at(t, cin)[:1]
        oin[2] = u[0]
        p.advance(t, h, u)
        o.advance(t, h, oin)
        c.advance(t, h, cin)
        th.append(p.z[0])
    return np.array(th)


@pytest.mark.slow
def test_error_sign_reading():
    th = _loop(switching=0, leakage=0)  # (3.10), (3.11), (3.13), e = theta - theta_d
    assert abs(th[-1]) < 1e-4 and np.abs(th[-500:]).max() < 1e-3  # 3e-5 at 2.5 s, < 1e-6 from 10 s on
    with pytest.raises(FloatingPointError, match="diverged"):
        _loop(switching=0, leakage=0, error_sign=-1)  # literal e = theta_d - theta


@pytest.mark.slow
def test_phi_reading():
    assert _loop(switching=0, leakage=1, phi_form=0)[-1] > 0.2  # (3.19)-(3.20): drifts away (0.4 rad at 5 s)
    assert _loop(switching=1, leakage=1, phi_form=0)[-1] > 0.09  # (3.21): away from 0, past theta(0) = 0.08
    default = _loop()  # (3.21), (3.19)-(3.20), (1 + lambda) delta: creeps towards 0
    assert 0.06 < default[-1] < 0.08 and np.all(np.diff(default[2000:]) < 0)


@pytest.mark.parametrize("name, value, match", [
    ("k1", 4.0, r"k1 must be a positive odd integer"),
    ("k2", 5.0, r"1 < k1/k2 < 2 is required \(003 \(3.9\)\), got k1/k2 = 1"),
    ("k1", 7.0, r"1 < k1/k2 < 2 is required \(003 \(3.9\)\), got k1/k2 = 2.33"),
    ("N", 0.0, r"N must be > 0"),
    ("J", 2.0, r"J1 = J - F F\^T = -0.475\d* kg.m2 must be > 0"),
    ("gamma3", 0.0, r"gamma3 must be > 0 with switching = 1"),
    ("phi_form", 2, r"phi_form must be one of \(0, 1\)"),
    ("error_sign", 0, r"error_sign must be one of \(1, -1\)"),
])
def test_bad_controller_parameters(name, value, match):
    c = blocks.controller()
    c.set_parameter(name, value)
    with pytest.raises(ValueError, match=match):
        c.initialize(0.0)


def test_rollback_is_exact():
    c = _ctrl()
    x = np.array([0.05, -0.01, 0.0, 0.0, 0.2])
    c.advance(0.0, 5e-4, x)
    s = c.get_state()
    a = [c.advance(5e-4 * k, 5e-4, x) or c.outputs_at(0, x).tolist() for k in range(5)]
    c.set_state(s)
    b = [c.advance(5e-4 * k, 5e-4, x) or c.outputs_at(0, x).tolist() for k in range(5)]
    assert a == b and a[0] != a[-1]
