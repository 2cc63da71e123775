"""Euler angles of the 2-3-1 sequence used by 001 (1)-(2): sigma = [nu, psi, gamma] (rad).

001 calls nu the pitch, psi the yaw and gamma the roll angle. Its kinematics (1) are exactly
those of the frame rotation (inertial -> body)

    C(sigma) = R1(gamma) R3(nu) R2(psi)

i.e. psi about the y axis first, then nu about the new z axis, then gamma about the new x axis
(derived below and checked in tests/plant/test_euler231.py against an independent quaternion
integration). With R_i the elementary frame rotations, the body rate is

    omega = [gamma', 0, 0] + R1(gamma) [0, 0, nu'] + R1(gamma) R3(nu) [0, psi', 0]
          = G^-1(sigma) sigma',   G^-1 = [[0, sin nu, 1], [sin gamma, cos gamma cos nu, 0],
                                          [cos gamma, -sin gamma cos nu, 0]]

and sigma' = G(sigma) omega with (001 (2))

    G = [[0, sin gamma,              cos gamma            ],
         [0, cos gamma / cos nu,     -sin gamma / cos nu  ],
         [1, -tan nu cos gamma,      tan nu sin gamma     ]]

Reading: 001 prints the (2,3) entry as "-sin gamma cos nu"; (1) and the rotation above both give
-sin gamma / cos nu, which is what we use. det G = -1/cos nu: singular at nu = +-90 deg.
G(0) = [[0,0,1],[0,1,0],[1,0,0]] (a permutation): near sigma = 0, nu' ~ omega_3, psi' ~ omega_2,
gamma' ~ omega_1. ``AXIS_OF_ANGLE`` records that pairing (used by controller/fontsm.py).
"""
from __future__ import annotations

import math

import numpy as np

# G(0)^-1 = G(0): the body axis each angle rotates about near sigma = 0 (nu: 3, psi: 2, gamma: 1)
PAIRING = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])


def rates(sigma, omega) -> tuple:
    """sigma' = G(sigma) omega, 001 (1) (with the (2,3) entry read as -sin gamma / cos nu)."""
    nu, gamma = sigma[0], sigma[2]
    sg, cg = math.sin(gamma), math.cos(gamma)
    c = omega[1] * cg - omega[2] * sg
    return (omega[1] * sg + omega[2] * cg, c / math.cos(nu), omega[0] - math.tan(nu) * c)


def G(sigma) -> np.ndarray:
    """The kinematics matrix G(sigma) of 001 (2), (2,3) entry corrected (module docstring)."""
    nu, gamma = sigma[0], sigma[2]
    sg, cg, cn, tn = math.sin(gamma), math.cos(gamma), math.cos(nu), math.tan(nu)
    return np.array([[0.0, sg, cg], [0.0, cg / cn, -sg / cn], [1.0, -tn * cg, tn * sg]])


def G_inv(sigma) -> np.ndarray:
    """G(sigma)^-1 (defined everywhere, singular at nu = +-90 deg)."""
    nu, gamma = sigma[0], sigma[2]
    sg, cg, sn, cn = math.sin(gamma), math.cos(gamma), math.sin(nu), math.cos(nu)
    return np.array([[0.0, sn, 1.0], [sg, cg * cn, 0.0], [cg, -sg * cn, 0.0]])


def G_inv_dot(sigma, sigma_dot) -> np.ndarray:
    """d/dt G^-1(sigma) for the angle rates sigma_dot (analytic)."""
    nu, gamma = sigma[0], sigma[2]
    nd, gd = sigma_dot[0], sigma_dot[2]
    sg, cg, sn, cn = math.sin(gamma), math.cos(gamma), math.sin(nu), math.cos(nu)
    return np.array(
        [
            [0.0, cn * nd, 0.0],
            [cg * gd, -sg * cn * gd - cg * sn * nd, 0.0],
            [-sg * gd, -cg * cn * gd + sg * sn * nd, 0.0],
        ]
    )


def dcm(sigma) -> np.ndarray:
    """C(sigma) = R1(gamma) R3(nu) R2(psi): inertial components -> body components."""
    nu, psi, gamma = sigma
    sn, cn = math.sin(nu), math.cos(nu)
    sp, cp = math.sin(psi), math.cos(psi)
    sg, cg = math.sin(gamma), math.cos(gamma)
    return np.array(
        [
            [cn * cp, sn, -cn * sp],
            [-cg * sn * cp + sg * sp, cg * cn, cg * sn * sp + sg * cp],
            [sg * sn * cp + cg * sp, -sg * cn, -sg * sn * sp + cg * cp],
        ]
    )


def from_dcm(C) -> np.ndarray:
    """[nu, psi, gamma] of C = R1(gamma) R3(nu) R2(psi), with nu in [-90, 90] deg."""
    C = np.asarray(C, dtype=float)
    nu = math.asin(max(-1.0, min(1.0, C[0, 1])))
    psi = math.atan2(-C[0, 2], C[0, 0])
    gamma = math.atan2(-C[2, 1], C[1, 1])
    return np.array([nu, psi, gamma])
