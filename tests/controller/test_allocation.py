"""Torque allocation (controller/allocation.py) against least squares computed independently:
numpy.linalg.lstsq (the minimum-norm solution of M x = u) and the KKT system of the weighted
problem min sum w_j x_j^2 s.t. M x = u."""
import numpy as np
import pytest

from controller.allocation import TorqueAllocation, WheelsToBody, allocation_matrix
from papers.p001_zhang2019.parameters import ZHANG2019

M = ZHANG2019["M"]
RNG = np.random.default_rng(7)


def _kkt(M, w, u):
    n = M.shape[1]
    K = np.block([[np.diag(w), M.T], [M, np.zeros((3, 3))]])
    return np.linalg.solve(K, np.concatenate((np.zeros(n), u)))[:n]


def test_pseudo_inverse_is_the_minimum_norm_least_squares_solution():
    A = allocation_matrix(M)
    for u in RNG.normal(size=(50, 3)):
        x = A @ u
        ref = np.linalg.lstsq(M, u, rcond=None)[0]
        np.testing.assert_allclose(x, ref, atol=1e-13)
        np.testing.assert_allclose(M @ x, u, atol=1e-13)


def test_weighted_pseudo_inverse_solves_the_weighted_problem():
    for _ in range(20):
        Mr = RNG.normal(size=(3, 5))
        w = RNG.uniform(0.2, 5.0, 5)
        A = allocation_matrix(Mr, w)
        for u in RNG.normal(size=(5, 3)):
            np.testing.assert_allclose(A @ u, _kkt(Mr, w, u), atol=1e-11)


@pytest.mark.parametrize("dropped", [0, 1, 2, 3])
def test_a_dropped_wheel_gets_nothing_and_the_others_still_deliver_u(dropped):
    A = allocation_matrix(M, dropped=(dropped,))
    keep = [j for j in range(4) if j != dropped]
    for u in RNG.normal(size=(20, 3)):
        x = A @ u
        assert x[dropped] == 0.0
        np.testing.assert_allclose(M @ x, u, atol=1e-12)  # three independent wheels remain
        np.testing.assert_allclose(x[keep], np.linalg.lstsq(M[:, keep], u, rcond=None)[0], atol=1e-12)


def test_two_wheels_left_is_the_least_squares_best_effort():
    A = allocation_matrix(M, dropped=(0, 3))
    for u in RNG.normal(size=(10, 3)):
        x = A @ u
        ref = np.linalg.lstsq(M[:, [1, 2]], u, rcond=None)[0]
        np.testing.assert_allclose(x[[1, 2]], ref, atol=1e-12)
        assert x[0] == x[3] == 0.0


def _alloc(**params):
    b = TorqueAllocation(4)
    b.set_defaults({"M": M})
    b.set_parameters(params)
    b.initialize(0.0)
    return b


def test_block_drops_the_failed_wheel_from_its_onset():
    b = _alloc(failed_wheel=2, failed_onset=5.0)
    u = np.array([0.3, -0.2, 0.1])
    inp = np.concatenate((u, np.ones(4), [0.0]))
    before, after = b.outputs_at(4.99, inp), b.outputs_at(5.0, inp)
    np.testing.assert_allclose(before[0:4], np.linalg.pinv(M) @ u, atol=1e-14)
    assert after[1] == 0.0 and after[-1] == 3.0 and before[-1] == 4.0
    np.testing.assert_allclose(after[4:7], u, atol=1e-13)  # tau_alloc = M u_c
    np.testing.assert_allclose(after[[0, 2, 3]], np.linalg.lstsq(M[:, [0, 2, 3]], u, rcond=None)[0], atol=1e-13)


def test_block_drops_wheels_the_estimate_says_are_dead():
    b = _alloc(e_drop=0.2)
    u = np.array([0.1, 0.2, 0.3])
    out = b.outputs_at(0.0, np.concatenate((u, [1.0, 1.0, 0.05, 1.0], [0.0])))
    assert out[2] == 0.0 and out[-1] == 3.0
    np.testing.assert_allclose(M @ out[0:4], u, atol=1e-13)


@pytest.mark.parametrize("wheel", [1, 2, 3, 4])
def test_block_drops_the_wheel_the_isolation_names_when_it_names_it(wheel):
    """issue 34: input ``isolated`` = j drops wheel j at that communication point (the remaining three
    deliver u, against lstsq), 0 drops nothing; a value naming no wheel is an error naming it."""
    b = _alloc()
    u = np.array([0.2, -0.4, 0.3])
    none = b.outputs_at(1.0, np.concatenate((u, np.ones(4), [0.0])))
    np.testing.assert_allclose(none[0:4], np.linalg.pinv(M) @ u, atol=1e-14)
    named = b.outputs_at(1.0, np.concatenate((u, np.ones(4), [float(wheel)])))
    keep = [j for j in range(4) if j != wheel - 1]
    assert named[wheel - 1] == 0.0 and named[-1] == 3.0 and none[-1] == 4.0
    np.testing.assert_allclose(named[keep], np.linalg.lstsq(M[:, keep], u, rcond=None)[0], atol=1e-13)
    np.testing.assert_allclose(named[4:7], u, atol=1e-13)
    for bad in (5.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="input isolated"):
            b.outputs_at(1.0, np.concatenate((u, np.ones(4), [bad])))


def test_wheels_to_body_maps_torques_and_faults():
    b = WheelsToBody(4)
    b.set_defaults({"M": M})
    b.initialize(0.0)
    uw, f = RNG.normal(size=4), RNG.normal(size=4)
    out = b.outputs_at(0.0, np.concatenate((uw, f)))
    np.testing.assert_allclose(out[0:3], M @ uw, atol=1e-15)
    np.testing.assert_allclose(out[3:6], M @ f, atol=1e-15)


def test_bad_parameters_are_named():
    with pytest.raises(ValueError, match="failed_wheel"):
        _alloc(failed_wheel=5)
    with pytest.raises(ValueError, match="weights"):
        _alloc(**{"w[2]": 0.0})
    b = TorqueAllocation(4)
    b.set_defaults({"M": np.zeros((3, 4))})
    with pytest.raises(ValueError, match="column 1 is zero"):
        b.initialize(0.0)
