"""The T-S fuzzy model of 000 (8)-(10) (plant/ts_fuzzy.py) against the nonlinear plant (6)-(7)."""
import numpy as np
import pytest

from papers.p000_li2023 import blocks as li2023
from papers.p000_li2023.parameters import LI2023, OMEGA_BOX
from plant.ts_fuzzy import fuzzy_model, memberships, rule_points


@pytest.fixture(scope="module")
def plant():
    p = li2023.flexible_spacecraft()
    p.initialize(0.0)
    return p


@pytest.fixture(scope="module")
def fm():
    return fuzzy_model(LI2023["J"], LI2023["delta"], LI2023["omega_n"], LI2023["zeta"], OMEGA_BOX)


def test_blended_model_equals_nonlinear_dynamics_inside_box(plant, fm):
    """sum_i b_i {A_i x + B tau + D_2i d2} equals omega' of the plant's own equations (6), and
    w' = A_d2 w + B_d2 omega, d2 = A_d1 w + B_d1 omega reproduce the modal equations (7)."""
    rng = np.random.default_rng(3)
    n = plant.n
    for _ in range(200):
        omega = rng.uniform(-OMEGA_BOX, OMEGA_BOX, 3)
        eta = rng.normal(0, 0.05, n)
        eta_dot = rng.normal(0, 0.05, n)
        tau = rng.normal(0, 2.0, 3)
        y = np.concatenate(([1.0, 0, 0, 0], omega, eta, eta_dot))
        dy = plant._deriv(y, tau)
        omega_dot, eta_ddot = dy[4:7], dy[7 + n :]
        b, A, D2 = fm.blend(omega)
        d2 = np.concatenate((eta, eta_dot))
        ts = A @ omega + fm.B @ tau + D2 @ d2  # 000 (10), Gamma = I, f = d1 = 0
        np.testing.assert_allclose(ts, omega_dot, rtol=1e-10, atol=1e-13)
        w = np.concatenate((eta, eta_dot + LI2023["delta"] @ omega))
        np.testing.assert_allclose(fm.Ad1 @ w + fm.Bd1 @ omega, d2, atol=1e-15)
        w_dot = np.concatenate((eta_dot, eta_ddot + LI2023["delta"] @ omega_dot))
        np.testing.assert_allclose(fm.Ad2 @ w + fm.Bd2 @ omega, w_dot, rtol=1e-10, atol=1e-13)


def test_memberships_partition_of_unity_and_saturation():
    rng = np.random.default_rng(4)
    for omega in rng.uniform(-1.5, 1.5, (500, 3)):
        b = memberships(omega, OMEGA_BOX)
        assert b.shape == (8,)
        assert np.all(b >= 0) and np.all(b <= 1)
        assert abs(b.sum() - 1.0) < 1e-14
        # b_i = prod_j M_{s_ij}(omega_j), written out independently with the rule signs
        plus = np.clip((omega + OMEGA_BOX) / (2 * OMEGA_BOX), 0, 1)
        ref = [np.prod([plus[j] if sgn > 0 else 1 - plus[j] for j, sgn in enumerate(signs)]) for signs in rule_points(OMEGA_BOX) / OMEGA_BOX]
        np.testing.assert_allclose(b, ref, atol=1e-16)
        # outside the box the memberships saturate: equal to those at the clipped point
        np.testing.assert_allclose(b, memberships(np.clip(omega, -OMEGA_BOX, OMEGA_BOX), OMEGA_BOX), atol=1e-16)
    # at each corner exactly one rule fires (000 section 5 order)
    for i, p in enumerate(rule_points(OMEGA_BOX)):
        np.testing.assert_array_equal(memberships(p, OMEGA_BOX), np.eye(8)[i])
        np.testing.assert_array_equal(memberships(2 * p, OMEGA_BOX), np.eye(8)[i])
    np.testing.assert_allclose(memberships(np.zeros(3), OMEGA_BOX), np.full(8, 0.125))


def test_blend_outside_box_is_the_corner_model(fm):
    b, A, D2 = fm.blend(np.array([2.0, 2.0, 2.0]))
    np.testing.assert_allclose(A, fm.A[0])
    np.testing.assert_allclose(D2, fm.D2[0])
