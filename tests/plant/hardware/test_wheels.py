"""Reaction wheels (plant/hardware/wheels.py) against closed-form solutions: the drive lag, friction
spin-down, the momentum limit, the torque bound, the gyroscopic torque and the momentum balance."""
import math

import numpy as np
import pytest

from plant.hardware.datasheets import WHEELS
from plant.hardware.wheels import ReactionWheels, torque_bound

M = np.array([[1.0, 0, 0, 1 / math.sqrt(3)], [0, 1.0, 0, 1 / math.sqrt(3)], [0, 0, 1.0, 1 / math.sqrt(3)]])


def _wheels(n=4, axes=3, **params):
    b = ReactionWheels(n, axes)
    if axes == 3:
        b.set_defaults({"M": M[:, :n]})
    b.set_parameters(params)
    b.initialize(0.0)
    return b


def _step(b, t, h, u):
    y = b.outputs_at(t, u)
    b.advance(t, h, u)
    return y


def _fields(b, y):
    n, a = b.n, b.a
    return {"tau": y[0:a], "u_wheel": y[a:a + n], "h": y[a + n:a + 2 * n], "speed": y[a + 2 * n:a + 3 * n],
            "h_body": y[a + 3 * n:2 * a + 3 * n], "saturated": y[2 * a + 3 * n:]}


def test_drive_lag_is_the_first_order_response():
    b = _wheels(time_constant=0.05, tau_max=0.2, h_max=100.0, I_w=0.1, gyroscopic=0.0)
    u = np.array([0.1, -0.05, 0.3, 0.0, 0, 0, 0])  # wheel 3 asks beyond tau_max: clipped to 0.2
    t, h = 0.0, 0.01
    for _ in range(30):
        b.advance(t, h, u)
        t += h
        y = _fields(b, b.outputs_at(t, u))
        ref = np.array([0.1, -0.05, 0.2, 0.0]) * (1 - math.exp(-t / 0.05))
        np.testing.assert_allclose(y["u_wheel"], ref, atol=1e-14)


def test_viscous_spin_down_is_exponential_and_coulomb_linear():
    I_w, cv = 0.02, 2e-4
    b = _wheels(n=3, I_w=I_w, viscous=cv, coulomb=0.0, h_max=50.0, gyroscopic=0.0, h_int=1e-3,
                **{"h_init[1]": 10.0, "h_init[2]": -5.0})
    t = 0.0
    for _ in range(100):
        b.advance(t, 0.1, np.zeros(6))
        t += 0.1
    ref = np.array([10.0, -5.0, 0.0]) * math.exp(-cv / I_w * t)
    np.testing.assert_allclose(b.hw, ref, rtol=1e-3)  # explicit Euler at 1 ms: O(dt cv / I_w) = 1e-5 per step
    cc = 5e-4
    c = _wheels(n=3, I_w=I_w, coulomb=cc, omega_eps=0.1, h_max=50.0, gyroscopic=0.0, **{"h_init[1]": 1.0})
    for k in range(10):
        c.advance(k * 0.1, 0.1, np.zeros(6))
    np.testing.assert_allclose(c.hw[0], 1.0 - cc * 1.0, atol=1e-12)  # speed stays far above omega_eps


def test_momentum_limit_holds_the_speed_and_delivers_no_torque():
    b = _wheels(n=3, tau_max=0.2, h_max=1.0, I_w=0.01, coulomb=5e-4, time_constant=0.01, gyroscopic=0.0)
    u = np.array([0.2, 0.0, 0.0, 0, 0, 0])  # body torque +0.2 on axis 1: h_1 decreases (h' = -u)
    t = 0.0
    rows = []
    for _ in range(800):
        rows.append(_fields(b, _step(b, t, 0.01, u)))
        t += 0.01
    h1 = np.array([r["h"][0] for r in rows])
    assert h1.min() >= -1.0 and abs(h1[-1] + 1.0) < 1e-12  # reached the limit and stays there
    last = rows[-1]
    assert last["saturated"][0] == 1.0 and last["u_wheel"][0] == 0.0
    # reversing the command leaves the limit at once
    _step(b, t, 0.01, -u)
    b2 = _fields(b, b.outputs_at(t + 0.01, -u))
    assert b2["saturated"][0] == 0.0 and b2["u_wheel"][0] < 0.0


def test_torque_never_exceeds_the_wheel_bound():
    p = WHEELS["wheels_hr12_12"]
    b = _wheels(gyroscopic=0.0, **p)
    bound = torque_bound(p["tau_max"], p["coulomb"], p["viscous"], p["h_max"], p["I_w"])
    rng = np.random.default_rng(3)
    t, worst = 0.0, 0.0
    for k in range(3000):
        if k % 40 == 0:  # commands held 0.4 s, often far beyond tau_max, some reversing a braking wheel
            u = np.concatenate((rng.normal(0.0, 1.0, 4) * rng.choice([0.05, 0.3, 10.0]), np.zeros(3)))
        y = _fields(b, _step(b, t, 0.01, u))
        worst = max(worst, float(np.abs(y["u_wheel"]).max()))
        t += 0.01
    assert worst <= bound + 1e-15
    assert worst > p["tau_max"] * 0.9  # the loop did drive the wheels hard


def test_gyroscopic_torque_of_the_stored_momentum():
    b = _wheels(I_w=0.01, h_max=10.0, **{"h_init[1]": 2.0, "h_init[4]": -1.0})
    w = np.array([0.1, -0.2, 0.3])
    y = _fields(b, b.outputs_at(0.0, np.concatenate((np.zeros(4), w))))
    hb = M @ np.array([2.0, 0.0, 0.0, -1.0])
    np.testing.assert_allclose(y["h_body"], hb, atol=1e-15)
    np.testing.assert_allclose(y["tau"], -np.cross(w, hb), atol=1e-15)  # u_b = 0 (no command, no friction)


def test_momentum_balance_body_impulse_equals_minus_stored_momentum():
    b = _wheels(gyroscopic=0.0, time_constant=0.05, tau_max=0.2, h_max=50.0, I_w=0.02, h_int=0.001)
    u = np.concatenate((np.array([0.15, -0.1, 0.05, 0.1]), np.zeros(3)))
    t, h, impulse = 0.0, 0.001, np.zeros(3)
    for _ in range(2000):
        y = _fields(b, _step(b, t, h, u))
        impulse += y["tau"] * h
        t += h
    stored = M @ b.hw
    np.testing.assert_allclose(impulse, -stored, rtol=0, atol=2e-4)  # the held output lags by one step


def test_pitch_axis_wheel_is_scalar_named():
    b = ReactionWheels(1, 1)
    assert [v.name for v in b.inputs] == ["u_c"] and b.outputs[0].name == "tau"
    b.set_parameters({"gyroscopic": 0.0})
    b.initialize(0.0)
    with pytest.raises(ValueError, match="gyroscopic"):
        c = ReactionWheels(1, 1)
        c.set_parameters({"gyroscopic": 1.0})
        c.initialize(0.0)


def test_bad_parameters_are_named():
    with pytest.raises(ValueError, match="h_init"):
        _wheels(h_max=1.0, **{"h_init[2]": 2.0})
    with pytest.raises(ValueError, match="time_constant"):
        _wheels(time_constant=0.0)


def test_one_pitch_wheel_outputs_are_the_general_path_bit_for_bit():
    """ReactionWheels(1, 1) computes its outputs in Python floats: the same numbers as the numpy path of
    wheel_torques and M @ (...) over states across the speed range, at the momentum limit and at rest."""
    rng = np.random.default_rng(0)
    for _ in range(500):
        w = ReactionWheels(1, 1)
        p = dict(WHEELS["wheels_hr12_12"], viscous=float(rng.choice([0.0, 1e-4])))
        p["M[1,1]"] = float(rng.choice([1.0, -1.0, 0.7]))
        w.set_parameters(p)
        w.initialize(0.0)
        w.hw = np.array([float(rng.choice([rng.uniform(-12, 12), 12.0, -12.0, 0.0, 1e-3]))])
        w.um = np.array([rng.uniform(-0.3, 0.3)])
        ub, cut = w.wheel_torques(w.hw, w.um)
        ref = np.concatenate((w.M @ ub, ub, w.hw, w.hw / w.Iw, w.M @ w.hw, cut.astype(float)))
        assert np.array_equal(w.outputs_at(0.0, np.array([0.1])), ref)
