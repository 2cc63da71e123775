"""Attitude error and the nonlinear terms shared by the controllers of paper 000.

Quaternions are scalar first, q = [q0, q_v]. B = (J - delta^T delta)^-1 (000 (6)).
Written matrix-free where it is cheap (these run every communication step).
"""
import numpy as np

from plant.so3 import cross, skew  # noqa: F401  (skew re-exported)


def quaternion_error(q, q_d):
    """000 (4): q_e0 = q_dv^T q_v + q_d0 q_0,  q_ev = q_d0 q_v - q_dv^x q_v - q_dv q_0."""
    q0, qv = q[0], q[1:4]
    qd0, qdv = q_d[0], q_d[1:4]
    qe0 = float(qdv @ qv) + qd0 * q0
    qev = qd0 * qv - cross(qdv, qv) - qdv * q0
    return qe0, qev


def theta_matrix(qe0, qev) -> np.ndarray:
    """Theta_q of 000 (5): (q_e0^2 - q_ev^T q_ev) I + 2 q_ev q_ev^T - 2 q_e0 q_ev^x."""
    return (qe0 * qe0 - qev @ qev) * np.eye(3) + 2.0 * np.outer(qev, qev) - 2.0 * qe0 * skew(qev)


def rate_error(qe0, qev, omega, omega_d):
    """000 (5): omega_e = omega - Theta_q omega_d. Returns (omega_e, Theta_q or None if omega_d = 0)."""
    if not omega_d.any():
        return omega.copy(), None
    theta = theta_matrix(qe0, qev)
    return omega - theta @ omega_d, theta


def g_term(beta, qe0, qev, omega, omega_e, omega_d, omega_d_dot, theta, B, J):
    """Nonlinear term g(s) of 000 (36):
    g = 1/2 beta (q_e0 I + q_ev^x) w_e + B w^x J beta q_ev - [B w^x J - w_e^x] Theta w_d - Theta w_d'.
    ``theta`` may be None when omega_d = 0 (then it is only needed for omega_d_dot)."""
    g = 0.5 * beta * (qe0 * omega_e + cross(qev, omega_e)) + beta * (B @ cross(omega, J @ qev))
    if theta is None and omega_d_dot.any():
        theta = theta_matrix(qe0, qev)
    if theta is not None:
        wd = theta @ omega_d
        g -= B @ cross(omega, J @ wd) - cross(omega_e, wd)
        g -= theta @ omega_d_dot
    return g


def vibration_torque(omega, d2, dK, dC, delta_T):
    """B^-1 D_2(omega) d2 = delta^T K eta + delta^T C eta_dot - omega x (delta^T eta_dot),
    with d2 = [eta; eta_dot] (000 (9)); the torque that (69)/(40) compensate."""
    n = dK.shape[1]
    eta, eta_dot = d2[:n], d2[n:]
    return dK @ eta + dC @ eta_dot - cross(omega, delta_T @ eta_dot)


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def sliding_terms(q, omega, q_d, omega_d, omega_d_dot, beta, B, J):
    """Errors and sliding variable shared by the sliding-mode laws of 000:
    q_e (4), omega_e (5), s = omega_e + beta q_ev (39) and g(s) (36), written out in scalars for the
    hot path (same formulas as ``quaternion_error``, ``rate_error`` and ``g_term``, tested equal):
        Theta v = (q_e0^2 - q_ev^T q_ev) v + 2 q_ev (q_ev^T v) - 2 q_e0 q_ev x v,
        g = 1/2 beta (q_e0 w_e + q_ev x w_e) + B (w x J (beta q_ev - Theta w_d)) + w_e x Theta w_d - Theta w_d'.
    Returns (q_e0, q_ev, omega_e, s, g) with arrays for q_ev, omega_e, s, g."""
    q0, q1, q2, q3 = float(q[0]), float(q[1]), float(q[2]), float(q[3])
    d0, d1, d2, d3 = float(q_d[0]), float(q_d[1]), float(q_d[2]), float(q_d[3])
    qe0 = d1 * q1 + d2 * q2 + d3 * q3 + d0 * q0  # 000 (4)
    e1 = d0 * q1 - (d2 * q3 - d3 * q2) - d1 * q0
    e2 = d0 * q2 - (d3 * q1 - d1 * q3) - d2 * q0
    e3 = d0 * q3 - (d1 * q2 - d2 * q1) - d3 * q0
    qev = (e1, e2, e3)
    a = qe0 * qe0 - (e1 * e1 + e2 * e2 + e3 * e3)

    def theta(v):
        ev = e1 * v[0] + e2 * v[1] + e3 * v[2]
        c = _cross(qev, v)
        return [a * v[i] + 2.0 * qev[i] * ev - 2.0 * qe0 * c[i] for i in range(3)]

    w = (float(omega[0]), float(omega[1]), float(omega[2]))
    tw = theta(omega_d)
    we = [w[i] - tw[i] for i in range(3)]  # 000 (5)
    s = np.array([we[i] + beta * qev[i] for i in range(3)])  # 000 (39)
    h = J @ np.array([beta * qev[i] - tw[i] for i in range(3)])
    r = B @ np.array(_cross(w, h))
    c1 = _cross(qev, we)
    c2 = _cross(we, tw)
    twd = theta(omega_d_dot)
    g = np.array([0.5 * beta * (qe0 * we[i] + c1[i]) + r[i] + c2[i] - twd[i] for i in range(3)])  # 000 (36)
    return qe0, np.array(qev), np.array(we), s, g
