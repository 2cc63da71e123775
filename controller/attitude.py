"""Attitude error and the nonlinear terms shared by the controllers of paper 000.

Quaternions are scalar first, q = [q0, q_v]. B = (J - delta^T delta)^-1 (000 (6)).
"""
import numpy as np


def skew(w) -> np.ndarray:
    """Cross-product matrix w^x, 000 (1)."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def quaternion_error(q, q_d):
    """000 (4): q_e0 = q_dv^T q_v + q_d0 q_0,  q_ev = q_d0 q_v - q_dv^x q_v - q_dv q_0."""
    q0, qv = q[0], q[1:4]
    qd0, qdv = q_d[0], q_d[1:4]
    qe0 = qdv @ qv + qd0 * q0
    qev = qd0 * qv - np.cross(qdv, qv) - qdv * q0
    return qe0, qev


def rate_error(qe0, qev, omega, omega_d):
    """000 (5): omega_e = omega - Theta_q omega_d, returns (omega_e, Theta_q)."""
    theta = (qe0 * qe0 - qev @ qev) * np.eye(3) + 2.0 * np.outer(qev, qev) - 2.0 * qe0 * skew(qev)
    return omega - theta @ omega_d, theta


def g_term(beta, qe0, qev, omega, omega_e, omega_d, omega_d_dot, theta, B, J):
    """Nonlinear term g(s) of 000 (36):
    g = 1/2 beta (q_e0 I + q_ev^x) w_e + B w^x J beta q_ev - [B w^x J - w_e^x] Theta w_d - Theta w_d'."""
    wx = skew(omega)
    BwJ = B @ wx @ J
    return (
        0.5 * beta * (qe0 * omega_e + np.cross(qev, omega_e))
        + beta * (BwJ @ qev)
        - (BwJ - skew(omega_e)) @ (theta @ omega_d)
        - theta @ omega_d_dot
    )


def d2_matrix(omega, delta, C, K, B):
    """D_2(omega) = B [delta^T K_eta, delta^T C_eta - omega^x delta^T] of 000 (9)."""
    return B @ np.hstack([delta.T @ K, delta.T @ C - skew(omega) @ delta.T])


def sliding_terms(q, omega, q_d, omega_d, omega_d_dot, beta, B, J):
    """Errors and sliding variable shared by the sliding-mode laws of 000:
    q_e (4), omega_e (5), s = omega_e + beta q_ev (39) and g(s) (36).
    Returns (q_e0, q_ev, omega_e, s, g)."""
    qe0, qev = quaternion_error(q, q_d)
    omega_e, theta = rate_error(qe0, qev, omega, omega_d)
    g = g_term(beta, qe0, qev, omega, omega_e, omega_d, omega_d_dot, theta, B, J)
    return qe0, qev, omega_e, omega_e + beta * qev, g
