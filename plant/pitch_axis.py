"""Single-axis (pitch) flexible spacecraft with two bending modes, 002 (1)-(2), (8).

002 (1):  J theta'' + F eta'' = u^F,   eta'' + C_m eta' + Lambda eta + F^T theta'' = 0,
solved for the accelerations (002 (2)):
          (J - F F^T) theta'' = F (C_m eta' + Lambda eta) + u^F,
          eta'' = -C_m eta' - Lambda eta - F^T theta''.
C_m = diag(2 xi_i w_i), Lambda = diag(w_i^2); F is the 1 x 2 rigid-elastic coupling row.
Actuator: u^F = omega u with the effectiveness factor omega in [0, 1] (002 (3)).

Two views:
* :func:`rigid_model`: 002 (8), x = [theta, theta'], A = [[0, 1], [0, 0]],
  B = [0; (J - F F^T)^-1], C = I; the vibration torque w = F (C_m eta' + Lambda eta) enters
  through B as a disturbance. The LMI design of 002 Theorem 2 uses this model.
* :func:`flexible_model`: the full 6-state model, z = [theta, theta', eta_1, eta_2, eta_1', eta_2'],
  used by :func:`simulate` to compute the simulated cost J_c of 002 (11).

Parameter sets (numpy only, SI) are the papers' own: ``papers/p002_zhang2014/parameters.py``
and ``papers/p003_hang2023/parameters.py``; a set is a dict with ``J`` (kg m^2), ``F`` (coupling
row), ``omega`` (rad/s) and ``xi`` (1).
"""
from __future__ import annotations

import numpy as np


def effective_inertia(J, F) -> float:
    """J - F F^T, 002 (2)."""
    F = np.asarray(F, float).reshape(-1)
    return float(J - F @ F)


def rigid_model(J, F):
    """(A, B, C) of 002 (8) with x = [theta, theta']."""
    A = np.array([[0.0, 1.0], [0.0, 0.0]])
    B = np.array([[0.0], [1.0 / effective_inertia(J, F)]])
    return A, B, np.eye(2)


def modal(omega, xi):
    """C_m = diag(2 xi_i w_i), Lambda = diag(w_i^2), 002 (1)."""
    omega, xi = np.asarray(omega, float), np.asarray(xi, float)
    return np.diag(2.0 * xi * omega), np.diag(omega**2)


def flexible_model(J, F, omega, xi):
    """(A, B, Cw) of the full model, z = [theta, theta', eta, eta']; w = Cw z is the vibration torque."""
    F = np.asarray(F, float).reshape(1, -1)
    n = F.shape[1]
    Cm, Lam = modal(omega, xi)
    je = effective_inertia(J, F.ravel())
    A = np.zeros((2 + 2 * n, 2 + 2 * n))
    B = np.zeros((2 + 2 * n, 1))
    A[0, 1] = 1.0
    A[2 : 2 + n, 2 + n :] = np.eye(n)
    # theta'' = (u + F (Cm eta' + Lam eta)) / je
    row_th = np.zeros(2 + 2 * n)
    row_th[2 : 2 + n] = (F @ Lam).ravel() / je
    row_th[2 + n :] = (F @ Cm).ravel() / je
    A[1] = row_th
    B[1, 0] = 1.0 / je
    # eta'' = -Cm eta' - Lam eta - F^T theta''
    A[2 + n :, 2 : 2 + n] = -Lam - F.T @ row_th[2 : 2 + n].reshape(1, -1)
    A[2 + n :, 2 + n :] = -Cm - F.T @ row_th[2 + n :].reshape(1, -1)
    B[2 + n :, 0] = -F.ravel() / je
    Cw = np.zeros((1, 2 + 2 * n))
    Cw[0, 2 : 2 + n] = (F @ Lam).ravel()
    Cw[0, 2 + n :] = (F @ Cm).ravel()
    return A, B, Cw


def closed_loop_cost(K, effectiveness, params, Z, R, flexible: bool = True):
    """(A_cl, Q) of the loop u = K [theta, theta'] with torque omega*u: z' = A_cl z, and the
    cost density z^T Q z = x^T Z x + u^T omega R omega u of 002 (11) (x = [theta, theta'])."""
    K = np.asarray(K, float).reshape(1, 2)
    om = float(effectiveness)
    if flexible:
        A, B, _ = flexible_model(params["J"], params["F"], params["omega"], params["xi"])
    else:
        A, B, _ = rigid_model(params["J"], params["F"])
    n = A.shape[0]
    Kz = np.zeros((1, n))
    Kz[0, :2] = K
    Q = np.zeros((n, n))
    Q[:2, :2] = np.asarray(Z, float) + om * om * K.T @ np.asarray(R, float) @ K
    return A + om * B @ Kz, Q


def simulate(K, effectiveness, x0, params, Z, R, t_final: float = 300.0, h: float = 0.01,
             flexible: bool = True):
    """Closed loop u = K [theta, theta'], torque omega*u, fixed-step RK4 from rest modes.

    Returns a dict with ``t``, ``z`` (states), ``u`` and ``J_c`` = int_0^t_final
    x^T Z x + u^T omega R omega u dt (002 (11)), integrated as an extra RK4 state.
    ``flexible=False`` simulates the rigid design model (8) with w = 0.
    """
    K = np.asarray(K, float).reshape(1, 2)
    Acl, Q = closed_loop_cost(K, effectiveness, params, Z, R, flexible)
    n = Acl.shape[0]

    def f(y):
        z = y[:n]
        return np.concatenate([Acl @ z, [z @ Q @ z]])

    steps = int(round(t_final / h))
    y = np.zeros(n + 1)
    y[:2] = x0
    zs = np.empty((steps + 1, n))
    zs[0] = y[:n]
    for k in range(steps):
        k1 = f(y)
        k2 = f(y + 0.5 * h * k1)
        k3 = f(y + 0.5 * h * k2)
        k4 = f(y + h * k3)
        y = y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        zs[k + 1] = y[:n]
    t = np.arange(steps + 1) * h
    return {"t": t, "z": zs, "u": (zs[:, :2] @ K.T).ravel(), "J_c": float(y[n])}
