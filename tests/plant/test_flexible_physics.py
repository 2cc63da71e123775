"""Plant physics: 000 (2)-(3) against conservation laws and an independent integrator."""
import numpy as np
from scipy.integrate import solve_ivp

from orchestrator.scenario.shipped import structured_parameter_set
from papers.p000_li2023 import blocks as li2023
from papers.p000_li2023.parameters import LI2023
from papers.p004_xu2024.parameters import XU2024
from plant.flexible import modal_matrices
from plant.so3 import rotation_matrix


def _plant(**params):
    p = li2023.flexible_spacecraft()
    p.set_parameters(
        {
            "q_init[0]": 0.8426149773176358, "q_init[1]": 0.3, "q_init[2]": 0.2, "q_init[3]": -0.4,
            "omega_init[1]": 0.02, "omega_init[2]": -0.03, "omega_init[3]": 0.01,
            "eta_init[1]": 0.01, "eta_init[3]": -0.02, "eta_dot_init[2]": 0.05, "eta_dot_init[4]": -0.03,
        }
    )
    p.set_parameters(params)
    p.initialize(0.0)
    return p


def test_angular_momentum_conserved_without_torque():
    """With no torque, R(q)^T (J w + delta^T eta') is constant (000 (2) has no other moment)."""
    p = _plant(h_max=0.001)
    h0 = p.angular_momentum_inertial()
    u = np.zeros(3)
    worst = 0.0
    for k in range(10000):  # 100 s at 10 ms
        p.advance(k * 0.01, 0.01, u)
        if k % 500 == 499:
            worst = max(worst, np.linalg.norm(p.angular_momentum_inertial() - h0) / np.linalg.norm(h0))
    assert worst < 1e-9, worst
    # the modes really moved: energy went back and forth between hub and appendages
    assert np.abs(p.y[7:]).max() > 1e-3


def test_quaternion_stays_unit():
    p = _plant(h_max=0.01)
    u = np.array([0.5, -0.3, 0.2])
    dev = 0.0
    for k in range(10000):
        p.advance(k * 0.01, 0.01, u)
        dev = max(dev, abs(np.linalg.norm(p.y[:4]) - 1.0))
    assert dev < 1e-12, dev


def _reference_rhs(J, delta, C, K, torque):
    """000 (2)-(3) written from the paper, independently of plant/flexible.py: the mass
    matrix [[J, delta^T], [delta, I]] multiplies [w', eta''] and is solved each call."""
    n = delta.shape[0]
    M = np.block([[J, delta.T], [delta, np.eye(n)]])

    def rhs(t, x):
        q, w, eta, eta_d = x[:4], x[4:7], x[7 : 7 + n], x[7 + n :]
        H = J @ w + delta.T @ eta_d
        rhs_w = -np.cross(w, H) + torque(t)
        rhs_e = -C @ eta_d - K @ eta
        acc = np.linalg.solve(M, np.concatenate([rhs_w, rhs_e]))
        q0, qv = q[0], q[1:]
        qd = np.concatenate([[-0.5 * qv @ w], 0.5 * (q0 * w + np.cross(qv, w))])
        return np.concatenate([qd, acc[:3], eta_d, acc[3:]])

    return rhs


def test_open_loop_torque_matches_solve_ivp():
    """Open-loop torque profile: RK4 plant vs scipy's DOP853 on the mass-matrix form, 1e-6 in omega."""
    p = _plant(h_max=0.002)
    C, K = modal_matrices(LI2023["omega_n"], LI2023["zeta"])
    cmd = lambda t: np.array([0.8 * np.sin(0.3 * t), -0.5, 0.4 * np.cos(0.7 * t)])  # noqa: E731
    h = 0.01
    ts = np.arange(0, 15.0 + h / 2, h)  # 15 s: the torque profile spins the craft up past 0.05 rad/s
    held = [None]  # the command is held over each step, as the co-simulation does
    rhs = _reference_rhs(LI2023["J"], LI2023["delta"], C, K, lambda t: held[0])
    x0 = p.y.copy()
    omegas = []
    for t in ts[:-1]:
        p.advance(t, h, cmd(t))
        omegas.append(p.y[4:7].copy())
    x = x0
    err = 0.0
    for k, t in enumerate(ts[:-1]):
        held[0] = cmd(t)
        sol = solve_ivp(rhs, (t, t + h), x, method="DOP853", rtol=1e-12, atol=1e-14)
        x = sol.y[:, -1]
        err = max(err, np.abs(x[4:7] - omegas[k]).max())
    assert err < 1e-6, err
    assert np.abs(omegas[-1]).max() > 0.05  # the torque did spin the craft up


def test_parameter_sets_are_distinct_and_complete():
    a, b = structured_parameter_set("li2023"), structured_parameter_set("xu2024")
    assert set(a) == set(b) and len(a) == 9 + 12 + 4 + 4
    assert a["omega_n[1]"] == 1.5362 and b["omega_n[1]"] == 0.7681
    assert a["delta[3,3]"] == 0.83674 and b["delta[3,3]"] == -0.83674
    for ps in (LI2023, XU2024):  # J - delta^T delta must be positive definite
        assert np.linalg.eigvalsh(ps["J"] - ps["delta"].T @ ps["delta"]).min() > 0


def test_rotation_matrix_is_orthonormal_and_matches_kinematics():
    q = np.array([0.8426149773176358, 0.3, 0.2, -0.4])
    R = rotation_matrix(q)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-14)
    assert np.isclose(np.linalg.det(R), 1.0)
