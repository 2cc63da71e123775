"""Fault isolation (diagnosis/isolation.py) on known fault directions: every wheel of 001's layout,
either sign, noise; the shares against their closed form; a dedicated residual bank; the decision
window, the confidence floor, reset and the ``healthy`` output; timing."""
import math

import numpy as np
import pytest

from diagnosis.factories import fault_isolation_4
from diagnosis.isolation import FaultIsolation, shares
from plant.rigid_wheels import default_distribution

M = default_distribution(4)
RNG = np.random.default_rng(3)


def _iso(**params):
    b = fault_isolation_4()
    b.set_parameters(params)
    b.initialize(0.0)
    return b


def _names(b):
    return [v.name for v in b.outputs]


def _run(b, f, alarm, t0=0.0, T=0.01):
    for k, (x, a) in enumerate(zip(f, alarm)):
        b.advance(t0 + k * T, T, np.concatenate((x, [a, 0.0])))
    return dict(zip(_names(b), b.outputs_at(t0 + len(f) * T, np.zeros(5))))


@pytest.mark.parametrize("wheel", [1, 2, 3, 4])
def test_isolates_each_wheel_from_its_spin_axis_whatever_the_sign(wheel):
    """f = c_k m_j + noise (c_k changing sign, the command a lost wheel no longer delivers): named j;
    confidence near 1; margin 1 - cos^2 of the nearest other axis (2/3 for 001's layout)."""
    c = np.sin(np.linspace(0.3, 6.0, 40)) * 0.5
    f = c[:, None] * M[:, wheel - 1] + 1e-3 * RNG.normal(size=(40, 3))
    b = _iso(window=0.3)
    y = _run(b, f, np.ones(40))
    assert y["isolated"] == wheel
    assert y["confidence"] > 0.999
    assert y["margin"] == pytest.approx(2.0 / 3.0, abs=0.01)
    assert y["isolation_time"] == pytest.approx(0.3)
    assert [y[f"healthy[{j}]"] for j in range(1, 5)] == [0.0 if j == wheel else 1.0 for j in range(1, 5)]


def test_shares_are_the_squared_cosines():
    for _ in range(20):
        x = RNG.normal(size=3)
        s = shares(M, x[None, :])
        cos2 = (M.T @ x) ** 2 / (np.linalg.norm(M, axis=0) ** 2 * (x @ x))
        np.testing.assert_allclose(s, cos2, rtol=1e-13)
    assert shares(M, np.zeros((2, 3))).tolist() == [0.0] * 4


def test_a_dedicated_residual_bank_is_the_identity_signature():
    """S = I: the residual carrying the energy is named (001's ASMFEO residuals 1 - e_hat_j)."""
    b = FaultIsolation(4, 4, "1")
    b.initialize(0.0)
    r = np.zeros((10, 4))
    r[:, 2] = 0.4
    r += 0.01 * RNG.normal(size=r.shape)
    assert _run(b, r, np.ones(10))["isolated"] == 3


def test_waits_for_the_alarm_and_decides_after_the_window_then_latches_until_reset():
    b = _iso(window=0.05)
    f = np.outer(np.ones(20), M[:, 0])
    alarm = np.r_[np.zeros(5), np.ones(15)]
    names = _names(b)
    for k in range(20):
        y = b.outputs_at(k * 0.01, np.zeros(5))
        if k <= 10:  # alarm sampled at 0.05 s; window 0.05 s: decided at the 0.10 s sample, shown from 0.11 s
            assert y[names.index("isolated")] == 0.0, k
        b.advance(k * 0.01, 0.01, np.concatenate((f[k], [alarm[k], 0.0])))
        if k == 10:
            assert b.outputs_at(0.11, np.zeros(5))[names.index("isolation_time")] == pytest.approx(0.10)
    b.advance(0.2, 0.01, np.concatenate((M[:, 3], [1.0, 0.0])))  # latched: a new direction changes nothing
    assert b.outputs_at(0.21, np.zeros(5))[names.index("isolated")] == 1.0
    b.advance(0.21, 0.01, np.concatenate((M[:, 3], [1.0, 1.0])))  # reset
    y = b.outputs_at(0.22, np.zeros(5))
    assert y[names.index("isolated")] == 0.0 and y[names.index("isolation_time")] == -1.0


def test_min_confidence_withholds_an_ambiguous_direction():
    """(m_1 - m_2)/sqrt 2: share 1/2 on wheels 1 and 2, 0 on the skew wheel 4: not named with
    min_confidence 0.9; named with 0, confidence 1/2, margin 0."""
    x = (M[:, 0] - M[:, 1]) / math.sqrt(2.0)
    assert _run(_iso(min_confidence=0.9), np.tile(x, (10, 1)), np.ones(10))["isolated"] == 0.0
    y = _run(_iso(), np.tile(x, (10, 1)), np.ones(10))
    assert y["isolated"] in (1.0, 2.0) and y["confidence"] == pytest.approx(0.5) and y["margin"] == pytest.approx(0.0)


def test_state_round_trip_and_bad_signatures():
    b = _iso(window=0.1)
    f = RNG.normal(size=(8, 3))
    _run(b, f, np.ones(8))
    s = b.get_state()
    y = b.outputs_at(0.08, np.zeros(5))
    _run(b, f, np.ones(8), t0=0.08)
    b.set_state(s)
    np.testing.assert_array_equal(b.outputs_at(0.08, np.zeros(5)), y)
    bad = fault_isolation_4()
    bad.set_parameters({"S[1,2]": 0.0, "S[2,2]": 0.0, "S[3,2]": 0.0})
    with pytest.raises(ValueError, match=r"S\[:,2\] is zero"):
        bad.initialize(0.0)


def test_a_controller_with_a_fault_mode_reads_healthy_001_fontsm_drops_the_wheel():
    """001's FONTSM allocation 001 (33), u_c = E^2 M^T (J^-1 M E^3 M^T)^-1 v: with e_hat = the
    isolation's ``healthy`` (0 for wheel 3) wheel 3 gets nothing and the other three deliver what the
    four would (M E u_c equal with and without the isolation, E = diag(healthy))."""
    from papers.p001_zhang2019.blocks import controller

    c = controller()
    c.initialize(0.0)
    b = _iso()
    _run(b, np.tile(M[:, 2], (3, 1)), np.ones(3))
    y = dict(zip(_names(b), b.outputs_at(0.03, np.zeros(5))))
    healthy = np.array([y[f"healthy[{j}]"] for j in range(1, 5)])
    assert healthy.tolist() == [1.0, 1.0, 0.0, 1.0]
    x = np.concatenate(([0.1, -0.2, 0.05], [0.01, 0.02, -0.01]))
    u4 = c.outputs_at(0.0, np.concatenate((x, np.ones(4), np.zeros(4), np.zeros(3))))[0:4]
    u3 = c.outputs_at(0.0, np.concatenate((x, healthy, np.zeros(4), np.zeros(3))))[0:4]
    assert u3[2] == 0.0 and u4[2] != 0.0
    np.testing.assert_allclose(M @ (healthy * u3), M @ u4, rtol=1e-10)
