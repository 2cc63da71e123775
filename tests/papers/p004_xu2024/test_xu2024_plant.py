"""004 (5)-(6), (9) and section 4: the T-S model on x = [omega, q_v] and its triangular
memberships, the T-S plant block against scipy, the mode fault actuator, d(t)."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from papers.p004_xu2024 import parameters as P
from papers.p004_xu2024.blocks import disturbance, fault_actuator, flexible_plant, ts_plant
from plant.fuzzy import TriangularProduct
from plant.so3 import skew
from plant.ts_attitude import local_model


def _memberships(order="matched"):
    return TriangularProduct(P.MEMBERSHIP["z_half_width"], P.RULE_PEAKS[order], P.MEMBERSHIP["z_slope"])


def test_local_matrices_follow_the_kinematics():
    """A_1 = [[0, 0], [I/2, 0]]; at P2 the (2,1) block is 1/2 sqrt(1 - 3 0.55^2) I = 0.152069 I
    (0.04625 I as printed, without the root); the w block is -(J - d^T d)^-1 S(1) J; A_3 negates
    the w and q-q blocks; B = [(J - d^T d)^-1; 0]; J - d^T d matches the notes' value."""
    J, d = P.XU2024["J"], P.XU2024["delta"]
    A, B = local_model(J, d, P.OPERATING_POINTS)
    Jm = J - d.T @ d
    assert np.allclose(Jm[0], [303.961264, -3.593021, -9.697477], atol=1e-6)
    assert np.allclose(A[0][3:, :3], 0.5 * np.eye(3)) and np.abs(A[0][:3]).max() == 0 and np.abs(A[0][3:, 3:]).max() == 0
    assert np.allclose(A[1][3:, :3], 0.152069 * np.eye(3), atol=5e-7)
    assert np.allclose(local_model(J, d, P.OPERATING_POINTS, False)[0][1][3:, :3], 0.04625 * np.eye(3))
    assert np.allclose(A[1][:3, :3], -np.linalg.solve(Jm, skew(np.ones(3)) @ J))
    assert np.allclose(A[1][:3, :3][0], [0.04326, 0.810462, -0.586671], atol=2e-6)
    assert np.allclose(A[2][:3, :3], -A[1][:3, :3]) and np.allclose(A[2][3:, 3:], -A[1][3:, 3:])
    assert np.allclose(A[2][3:, :3], A[1][3:, :3])
    assert np.allclose(B, np.vstack([np.linalg.inv(Jm), np.zeros((3, 3))]))
    ev = np.linalg.eigvals(A[1])
    assert np.isclose(ev.real.max(), 0.0152, atol=1e-4) and np.isclose(np.abs(ev.imag).max(), 1.8312, atol=1e-4)


def test_local_model_matches_the_nonlinear_vector_field_at_the_points():
    """At each operating point x = P_i the T-S rule gives the nonlinear derivative exactly:
    A_i P_i = [-(J - d^T d)^-1 S(w) J w; 1/2 (q0 I + S(q)) w] (004 (1)-(5), u = d~ = 0)."""
    J, d = P.XU2024["J"], P.XU2024["delta"]
    A, _ = local_model(J, d, P.OPERATING_POINTS)
    Jm = J - d.T @ d
    for Ai, x in zip(A, P.OPERATING_POINTS):
        w, q = x[:3], x[3:]
        q0 = np.sqrt(1 - q @ q)
        f = np.concatenate([-np.linalg.solve(Jm, np.cross(w, J @ w)), 0.5 * (q0 * w + np.cross(q, w))])
        assert np.allclose(Ai @ x, f, atol=1e-12)


def test_triangular_memberships():
    """Peaks at the operating points (matched reading), partition of unity, clipping outside
    the domain, the printed x(0) in the degenerate set (fallback), and the literal pairing."""
    m = _memberships()
    for i, x in enumerate(P.OPERATING_POINTS):
        assert np.allclose(m.weights(x), np.eye(3)[i], atol=1e-3)  # 1.818 * 0.55 = 0.9999
    rng = np.random.default_rng(0)
    Z = rng.uniform(-1.5, 1.5, (500, 6))
    W = m.weights_batch(Z)
    assert np.allclose(W.sum(axis=1), 1.0) and W.min() >= 0
    assert np.array_equal(W, np.array([m.weights(z) for z in Z]))
    z = np.array([0.2, 0.3, 0.1, 0.1, 0.05, 0.2])
    assert np.array_equal(m.weights(z), m.weights(np.where(z > 0, z, z)))
    assert np.array_equal(m.weights(np.array([3.0, 0.5, 0.5, 0.3, 0.3, 0.9])),
                          m.weights(np.array([1.0, 0.5, 0.5, 0.3, 0.3, 0.55])))
    x0 = P.X0_PRINTED
    assert m.degenerate(x0) and np.isclose(m.weights(x0).sum(), 1.0)
    assert np.allclose(m.weights(x0), [5.0e-05, 0.499983, 0.499967], atol=1e-6)
    mixed = np.array([0.2, -0.1, 0.3, 0.1, 0.1, -0.2])  # components of both signs: only rule 1
    assert np.array_equal(m.weights(mixed), [1.0, 0.0, 0.0])
    lit = _memberships("literal")
    assert np.allclose(lit.weights(P.OPERATING_POINTS[1]), [0, 0, 1], atol=1e-3)  # rule 2 fires at P3 side


def test_ts_plant_block_matches_scipy():
    """The T-S plant block (RK4, 1 ms) against solve_ivp of x' = sum h_i(x) A_i x + B u
    (same memberships) for a constant torque, from a state inside the domain, 1.5 s."""
    b = ts_plant()
    x0 = np.array([0.3, 0.25, 0.2, 0.1, 0.15, 0.05])
    b.set_defaults({"x_init": x0})
    b.initialize(0.0)
    u = np.array([2.0, -1.0, 0.5])
    for k in range(1500):
        b.advance(k * 1e-3, 1e-3, u)
    A, B = local_model(P.XU2024["J"], P.XU2024["delta"], P.OPERATING_POINTS)
    m = _memberships()
    sol = solve_ivp(lambda t, x: np.tensordot(m.weights(x), A, axes=1) @ x + B @ u, (0, 1.5), x0,
                    method="DOP853", rtol=1e-12, atol=1e-14)
    assert np.abs(b.get_state() - sol.y[:, -1]).max() < 1e-8
    y = b.outputs_at(1.5, u)
    assert np.isclose(y[3], np.sqrt(1 - sol.y[3:, -1] @ sol.y[3:, -1]))


def test_fault_actuator_applies_each_mode():
    """004 (9): tau = F_r u + G_r v + d with Cases I-III (v = 0.1 N.m ours)."""
    b = fault_actuator()
    b.initialize(0.0)
    u, d = np.array([10.0, -20.0, 30.0]), np.array([0.1, 0.2, -0.3])
    for r, (F, Gv) in enumerate([(1, 0), (np.array([0.7, 0.8, 0.6]), 0), (1, 0.1)], start=1):
        y = b.outputs_at(0.0, np.concatenate([u, [float(r)], d]))
        assert np.allclose(y[3:6], F * u + Gv) and np.allclose(y[:3], F * u + Gv + d)
        assert np.allclose(y[6:9], F * u + Gv - u)
    with pytest.raises(ValueError, match="input mode = 2.5 is not one of the modes 1..3"):
        b.outputs_at(0.0, np.concatenate([u, [2.5], d]))
    b.set_parameter("F[2,3]", 1.2)
    with pytest.raises(ValueError, match=r"F\[2,3\] = 1.2 outside \[0, 1\]"):
        b.initialize(0.0)


def test_disturbance_as_printed():
    b = disturbance()
    b.initialize(0.0)
    t = 7.3
    d = b.outputs_at(t, np.zeros(0))
    ref = [-0.2 + 0.1 * np.cos(0.06 * t) - 0.1 * np.cos(0.8 * t), 0.2 + 0.2 * np.sin(0.6 * t) - 0.1 * np.cos(0.4 * t),
           -0.2 + 0.15 * np.sin(0.5 * t) - 0.1 * np.sin(0.8 * t)]
    assert np.allclose(d, ref, rtol=0, atol=1e-15)
    assert np.isclose(b.energy(0.0, 10.0), 1.2966, atol=1e-4)  # the notes' int_0^10 ||d||^2


def test_flexible_plant_has_004_set_and_unit_quaternion():
    b = flexible_plant()
    b.initialize(0.0)
    y = b.outputs_at(0.0, np.zeros(3))
    assert np.allclose(y[:4], np.array([1, -2, 1, -2]) / np.sqrt(10)) and np.allclose(y[4:7], [2, -1.5, 1])
    assert np.allclose(b.p_matrix("delta"), P.XU2024["delta"]) and np.allclose(b.p_vector("omega_n"), P.XU2024["omega_n"])
    assert b.p("u_max") >= 1e6
