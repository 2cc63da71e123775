"""The conventions of ftcsim and Basilisk, mapped (numpy only: importable without bsk).

==========================  ==========================================  ==========================================
quantity                    ftcsim                                      Basilisk
==========================  ==========================================  ==========================================
attitude                    q = [q0, q1, q2, q3], scalar first, body     MRP sigma_BN (|sigma| <= 1, shadow set
                            w.r.t. inertial (000 (3))                   switched); EP beta = q
001's Euler angles          [nu, psi, gamma], 2-3-1 sequence            ``euler2312C([psi, nu, gamma])``
body rate                   omega, body components, rad/s               omega_BN_B
wheel command               u_c,j: torque of wheel j ON THE BODY         motorTorque_j: torque ON THE WHEEL
                                                                        (u_c,j = -motorTorque_j)
craft inertia               J: without the wheels' spin inertia          IHubPntBc_B = J + sum_j I_w g_j g_j^T
                            about their axes                            (balanced wheels add no inertia)
wheel speed / momentum      h_w,j = I_w (g_j^T omega + Omega_j),         Omega_j relative to the body
                            inertial (plant h_w; ReactionWheels h)
flexible mode i (000)       eta_i, row delta_i of delta, omega_n,i,      one hinged panel: mass 0, hinge axis
                            zeta_i                                      delta_i / |delta_i|, inertia |delta_i|^2
                                                                        about it, k = |delta_i|^2 omega_n,i^2,
                                                                        c = 2 zeta_i omega_n,i |delta_i|^2,
                                                                        theta = eta_i / |delta_i|
==========================  ==========================================  ==========================================

Derivation of the last rows: with balanced wheels Basilisk's hub equation is
(I_hub - sum I_w g g^T) omega' = -omega x I_hub omega - sum g (u_m + u_f) - sum I_w Omega omega x g
(reactionWheelStateEffector.cpp, ``updateContributions``), which with h = I_w (g^T omega + Omega) is
ftcsim's J omega' = -omega x (J omega + G h) + G u, h' = -u, for J = I_hub - sum I_w g g^T and
u = -(u_m + u_f). A massless panel of inertia I about its hinge axis a (hingedRigidBodyStateEffector
with d = 0, IPntS_S = diag(0, I, 0)) has I (a^T omega' + theta'') = -k theta - c theta', i.e. 000 (2)'s
eta'' + C eta' + K eta = -delta_i omega' with eta = sqrt(I) theta, delta_i = sqrt(I) a; the hub then
carries J - delta^T delta (000 (1)).
"""
from __future__ import annotations

import numpy as np

from plant.attitude_adapters import euler231_from_dcm, quaternion_from_dcm
from plant.euler231 import dcm as euler231_dcm
from plant.so3 import rotation_matrix

__all__ = ["mrp_to_dcm", "dcm_to_mrp", "mrp_from_quaternion", "quaternion_from_mrp", "euler231_from_mrp",
           "mrp_from_euler231", "body_torque", "motor_torque", "hub_inertia", "craft_inertia", "inertial_momentum",
           "relative_speed", "panels_from_modes", "hinge_dcm", "quaternion_dcm"]


def mrp_to_dcm(sigma) -> np.ndarray:
    """[BN] of the MRP sigma (Schaub & Junkins, Analytical Mechanics of Space Systems, (3.153))."""
    s = np.asarray(sigma, dtype=float)
    s2 = float(s @ s)
    sx = np.array([[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]])
    return np.eye(3) + (8.0 * sx @ sx - 4.0 * (1.0 - s2) * sx) / (1.0 + s2) ** 2


def mrp_from_quaternion(q) -> np.ndarray:
    """The MRP (|sigma| <= 1) of the unit quaternion q (scalar first): sigma = q_v / (1 + q0), q0 >= 0."""
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q)
    if q[0] < 0.0:
        q = -q
    return q[1:4] / (1.0 + q[0])


def quaternion_from_mrp(sigma) -> np.ndarray:
    """The unit quaternion (scalar first, q0 >= 0) of the MRP sigma: q0 = (1 - s^2) / (1 + s^2),
    q_v = 2 sigma / (1 + s^2) (the shadow set when |sigma| > 1, so that q0 >= 0)."""
    s = np.asarray(sigma, dtype=float)
    s2 = float(s @ s)
    q = np.concatenate(([(1.0 - s2) / (1.0 + s2)], 2.0 * s / (1.0 + s2)))
    return -q if q[0] < 0.0 else q


def dcm_to_mrp(C) -> np.ndarray:
    """The MRP (|sigma| <= 1) of the rotation matrix C = [BN]."""
    return mrp_from_quaternion(quaternion_from_dcm(C))


def euler231_from_mrp(sigma) -> np.ndarray:
    """001's [nu, psi, gamma] (2-3-1, plant/euler231.py) of the MRP sigma_BN."""
    return euler231_from_dcm(mrp_to_dcm(sigma))


def mrp_from_euler231(angles) -> np.ndarray:
    """The MRP sigma_BN of 001's [nu, psi, gamma]; Basilisk's ``euler2312C([psi, nu, gamma])`` is the same matrix."""
    return dcm_to_mrp(euler231_dcm(angles))


def body_torque(motor_torque) -> np.ndarray:
    """ftcsim's u_c (torque of each wheel on the body, N.m) of Basilisk's motorTorque (on the wheel)."""
    return -np.asarray(motor_torque, dtype=float)


def motor_torque(u_c) -> np.ndarray:
    """Basilisk's motorTorque (N.m, on the wheel) of ftcsim's u_c (on the body)."""
    return -np.asarray(u_c, dtype=float)


def _axes(G) -> np.ndarray:
    G = np.asarray(G, dtype=float)
    if G.ndim != 2 or G.shape[0] != 3:
        raise ValueError(f"M: a 3 x N matrix of spin axes is needed, got shape {G.shape}")
    norms = np.linalg.norm(G, axis=0)
    if np.any(np.abs(norms - 1.0) > 1e-9):
        raise ValueError(f"M: the spin axes must be unit vectors (column norms {np.array2string(norms, precision=6)})")
    return G


def hub_inertia(J, G, I_w) -> np.ndarray:
    """Basilisk's ``IHubPntBc_B`` (kg.m2) for ftcsim's craft inertia J, unit spin axes G (3 x N) and wheel
    spin inertias I_w (scalar or N): J + sum_j I_w,j g_j g_j^T."""
    G = _axes(G)
    Iw = np.broadcast_to(np.asarray(I_w, dtype=float), (G.shape[1],))
    return np.asarray(J, dtype=float) + (G * Iw) @ G.T


def craft_inertia(I_hub, G, I_w) -> np.ndarray:
    """ftcsim's J of Basilisk's ``IHubPntBc_B``: I_hub - sum_j I_w,j g_j g_j^T."""
    G = _axes(G)
    Iw = np.broadcast_to(np.asarray(I_w, dtype=float), (G.shape[1],))
    return np.asarray(I_hub, dtype=float) - (G * Iw) @ G.T


def inertial_momentum(speed, omega, G, I_w) -> np.ndarray:
    """ftcsim's h_w (N.m.s) of Basilisk's relative wheel speeds Omega (rad/s) at body rate omega."""
    G = _axes(G)
    return np.asarray(I_w, dtype=float) * (G.T @ np.asarray(omega, dtype=float) + np.asarray(speed, dtype=float))


def relative_speed(h_w, omega, G, I_w) -> np.ndarray:
    """Basilisk's Omega (rad/s, relative to the body) of ftcsim's inertial h_w (N.m.s)."""
    G = _axes(G)
    return np.asarray(h_w, dtype=float) / np.asarray(I_w, dtype=float) - G.T @ np.asarray(omega, dtype=float)


def panels_from_modes(delta, omega_n, zeta) -> list[dict]:
    """000's flexible modes (delta: n x 3 coupling, 1; natural frequencies omega_n, rad/s; damping
    ratios zeta) as n massless hinged panels, one per mode (see the module docstring): for each a dict
    of ``axis`` (unit hinge axis, body), ``inertia`` (kg.m2 about it), ``k`` (N.m/rad), ``c`` (N.m.s/rad)
    and ``scale`` (eta_i = scale theta_i). A zero row (an uncoupled mode) has no panel equivalent."""
    delta = np.atleast_2d(np.asarray(delta, dtype=float))
    out = []
    for i, row in enumerate(delta):
        n = float(np.linalg.norm(row))
        if n == 0.0:
            raise ValueError(f"delta: row {i + 1} is zero: a mode that does not couple to the hub is no hinged panel")
        I = n * n
        wn, z = float(omega_n[i]), float(zeta[i])
        out.append({"axis": row / n, "inertia": I, "k": I * wn * wn, "c": 2.0 * z * wn * I, "scale": n})
    return out


def hinge_dcm(axis) -> np.ndarray:
    """A hinge frame [HB] (rows h1, h2, h3 in body components) whose second axis, the hinge axis of
    Basilisk's hinged panel, is ``axis``."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    ref = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    h1 = np.cross(a, ref)
    h1 /= np.linalg.norm(h1)
    h3 = np.cross(h1, a)
    return np.vstack([h1, a, h3])


def quaternion_dcm(q) -> np.ndarray:
    """[BN] of ftcsim's quaternion q (scalar first): plant/so3.py's rotation matrix."""
    return rotation_matrix(np.asarray(q, dtype=float))
