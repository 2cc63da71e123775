"""Attitude-representation adapters: blocks that let a method meet a plant it was not written for.

Conventions (those of the plants and methods they connect):

* Quaternions are scalar first, q = [q0, q_v], and describe the body frame relative to the
  inertial one through C(q) = (q0^2 - q_v^T q_v) I + 2 q_v q_v^T - 2 q0 q_v^x (``plant/so3.py``,
  the Theta_q of 000 (5)), which takes inertial components to body components. 000 (3) and 004 (1)
  integrate exactly this quaternion.
* 001's Euler angles sigma = [nu, psi, gamma] are the 2-3-1 sequence C(sigma) = R1(gamma) R3(nu)
  R2(psi) (``plant/euler231.py``), the same kind of matrix (inertial -> body components).
* Both families of plants output the body rate omega in body components (rad/s), so no rate
  conversion is needed between them; what differs is the attitude variable and the error a method
  regulates.

Blocks (all stateless, every output depends directly on the inputs it is computed from):

* :class:`Euler231ToQuaternion`: sigma -> q with C(q) = C(sigma), hemisphere q0 >= 0 (a 3-axis
  quaternion method on 001's Euler-angle plant);
* :class:`QuaternionToEuler231`: q -> sigma with C(sigma) = C(q), nu in [-90, 90] deg, psi and
  gamma in (-180, 180] deg (001's method on a quaternion plant). Near nu = +-90 deg the angles are
  singular (as in 001 (1)); the adapter keeps reproducing the attitude (at nu = +-90 deg exactly,
  psi = 0 and gamma carries the rotation about the common axis) and the method sees what its own
  kinematics imply;
* :class:`AttitudeError`: the error quaternion and rate error of 000 (4)-(5), q_e = q_d^* (x) q,
  omega_e = omega - C(q_e) omega_d, for a method that regulates an attitude to the identity
  (004's sampled fuzzy controller, whose T-S model is in x = [omega, q_v]; 001's FONTSM through
  :class:`QuaternionToEuler231`) on a scenario with a target attitude q_d. ``hemisphere`` = 1
  (default) returns the error with q_e0 >= 0 (the shorter rotation; q and -q are the same
  attitude), 0 as 000 (4) gives it.

The conversions are tested against rotation matrices formed independently (scipy's
``Rotation``) in tests/plant/test_attitude_adapters.py.
"""
from __future__ import annotations

import math

import numpy as np

from . import euler231
from .block import StatelessBlock, scalar, vector
from .so3 import rotation_matrix

__all__ = ["quaternion_from_dcm", "euler231_from_dcm", "quaternion_error", "error_rotation_times",
           "Euler231ToQuaternion", "QuaternionToEuler231", "AttitudeError"]


def quaternion_from_dcm(C) -> np.ndarray:
    """The unit quaternion q (scalar first, q0 >= 0) with ``rotation_matrix(q) == C`` for a
    proper orthogonal C (inertial -> body components). Shepperd's method: the largest of
    4 q0^2, 4 q_i^2 is formed from the trace and diagonal, the others from the off-diagonal
    sums/differences, so no division by a small number occurs."""
    C = np.asarray(C, dtype=float)
    c00, c01, c02 = C[0, 0], C[0, 1], C[0, 2]
    c10, c11, c12 = C[1, 0], C[1, 1], C[1, 2]
    c20, c21, c22 = C[2, 0], C[2, 1], C[2, 2]
    tr = c00 + c11 + c22
    # C = (q0^2 - |qv|^2) I + 2 qv qv^T - 2 q0 [qv x]: C_12 - C_21 = 4 q0 q3, C_20 - C_02 = 4 q0 q2, C_01 - C_10 = 4 q0 q3
    k = max((tr, 0), (c00, 1), (c11, 2), (c22, 3))[1]
    if k == 0:
        s = 2.0 * math.sqrt(max(1.0 + tr, 0.0))  # 4 q0
        q = (0.25 * s, (c12 - c21) / s, (c20 - c02) / s, (c01 - c10) / s)
    elif k == 1:
        s = 2.0 * math.sqrt(max(1.0 + c00 - c11 - c22, 0.0))  # 4 q1
        q = ((c12 - c21) / s, 0.25 * s, (c01 + c10) / s, (c02 + c20) / s)
    elif k == 2:
        s = 2.0 * math.sqrt(max(1.0 - c00 + c11 - c22, 0.0))  # 4 q2
        q = ((c20 - c02) / s, (c01 + c10) / s, 0.25 * s, (c12 + c21) / s)
    else:
        s = 2.0 * math.sqrt(max(1.0 - c00 - c11 + c22, 0.0))  # 4 q3
        q = ((c01 - c10) / s, (c02 + c20) / s, (c12 + c21) / s, 0.25 * s)
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    sign = -1.0 if q[0] < 0.0 else 1.0
    return np.array([sign * q[0] / n, sign * q[1] / n, sign * q[2] / n, sign * q[3] / n])


def euler231_from_dcm(C) -> np.ndarray:
    """[nu, psi, gamma] with ``euler231.dcm(sigma) == C`` (nu in [-90, 90] deg). At the singularity
    (|C_12| = 1, cos nu = 0: psi and gamma turn about the same axis) psi = 0 and gamma carries the
    whole rotation, gamma = atan2(C_23, C_33), so that C is still reproduced."""
    C = np.asarray(C, dtype=float)
    if abs(C[0, 1]) < 1.0 - 1e-12:
        return euler231.from_dcm(C)
    nu = math.copysign(0.5 * math.pi, C[0, 1])
    return np.array([nu, 0.0, math.atan2(C[1, 2], C[2, 2])])


def quaternion_error(q, q_d) -> tuple:
    """000 (4): q_e0 = q_dv^T q_v + q_d0 q0, q_ev = q_d0 q_v - q_dv^x q_v - q_dv q0, i.e. the
    quaternion with C(q_e) = C(q) C(q_d)^T (body frame relative to the desired frame)."""
    q0, q1, q2, q3 = (float(x) for x in q)
    d0, d1, d2, d3 = (float(x) for x in q_d)
    e0 = d1 * q1 + d2 * q2 + d3 * q3 + d0 * q0
    e1 = d0 * q1 - (d2 * q3 - d3 * q2) - d1 * q0
    e2 = d0 * q2 - (d3 * q1 - d1 * q3) - d2 * q0
    e3 = d0 * q3 - (d1 * q2 - d2 * q1) - d3 * q0
    return e0, e1, e2, e3


def error_rotation_times(qe, v) -> tuple:
    """C(q_e) v = (q_e0^2 - q_ev^T q_ev) v + 2 q_ev (q_ev^T v) - 2 q_e0 q_ev x v (000 (5) Theta_q)."""
    e0, e1, e2, e3 = qe
    a = e0 * e0 - (e1 * e1 + e2 * e2 + e3 * e3)
    ev = e1 * v[0] + e2 * v[1] + e3 * v[2]
    c = (e2 * v[2] - e3 * v[1], e3 * v[0] - e1 * v[2], e1 * v[1] - e2 * v[0])
    return (a * v[0] + 2.0 * e1 * ev - 2.0 * e0 * c[0],
            a * v[1] + 2.0 * e2 * ev - 2.0 * e0 * c[1],
            a * v[2] + 2.0 * e3 * ev - 2.0 * e0 * c[2])


def _unit(q, name: str) -> tuple:
    n = math.sqrt(sum(float(x) * float(x) for x in q))
    if not n > 0.0 or not math.isfinite(n):
        raise ValueError(f"{name}: quaternion of norm {n:g} cannot describe an attitude")
    return tuple(float(x) / n for x in q)


class Euler231ToQuaternion(StatelessBlock):
    """sigma = [nu, psi, gamma] (2-3-1, 001 (1)) -> q with C(q) = C(sigma), q0 >= 0."""

    model_name = "Euler231ToQuaternion"
    description = "Attitude adapter: 001's 2-3-1 Euler angles -> unit quaternion (scalar first, q0 >= 0)"

    def __init__(self):
        super().__init__(vector("sigma", 3, "rad", "Euler angles [nu, psi, gamma] of the 2-3-1 sequence"),
                         vector("q", 4, "1", "attitude quaternion, scalar first, q0 >= 0", first=0), [],
                         {f"q[{i}]": [f"sigma[{j}]" for j in (1, 2, 3)] for i in range(4)})

    def initialize(self, t0: float) -> None:
        pass

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        return quaternion_from_dcm(euler231.dcm(u[0:3]))


class QuaternionToEuler231(StatelessBlock):
    """q (scalar first, any norm > 0) -> sigma = [nu, psi, gamma] with C(sigma) = C(q)."""

    model_name = "QuaternionToEuler231"
    description = "Attitude adapter: unit quaternion (scalar first) -> 001's 2-3-1 Euler angles [nu, psi, gamma]"

    def __init__(self):
        super().__init__(vector("q", 4, "1", "attitude quaternion, scalar first", [1, 0, 0, 0], first=0),
                         vector("sigma", 3, "rad", "Euler angles [nu, psi, gamma] of the 2-3-1 sequence"), [],
                         {f"sigma[{i}]": [f"q[{j}]" for j in range(4)] for i in (1, 2, 3)})

    def initialize(self, t0: float) -> None:
        pass

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        return euler231_from_dcm(rotation_matrix(np.array(_unit(u[0:4], "QuaternionToEuler231 input q"))))


class AttitudeError(StatelessBlock):
    """q_e = q_d^* (x) q and omega_e = omega - C(q_e) omega_d of 000 (4)-(5)."""

    model_name = "AttitudeError"
    description = "Attitude adapter: error quaternion and rate error of 000 (4)-(5) w.r.t. a desired attitude"

    def __init__(self):
        inputs = (vector("q", 4, "1", "attitude quaternion, scalar first", [1, 0, 0, 0], first=0)
                  + vector("omega", 3, "rad/s", "body rate")
                  + vector("q_d", 4, "1", "desired attitude quaternion, scalar first", [1, 0, 0, 0], first=0)
                  + vector("omega_d", 3, "rad/s", "desired body rate (desired-frame components)"))
        outputs = (vector("q_e", 4, "1", "error quaternion 000 (4), scalar first", first=0)
                   + vector("omega_e", 3, "rad/s", "rate error 000 (5)"))
        params = scalar("hemisphere", 1.0, "1", "1: q_e0 >= 0 (shorter rotation), 0: 000 (4) as it is")
        qs = [f"q[{i}]" for i in range(4)] + [f"q_d[{i}]" for i in range(4)]
        feed = {f"q_e[{i}]": qs for i in range(4)}
        feed.update({f"omega_e[{i}]": qs + [f"omega[{i}]"] + [f"omega_d[{j}]" for j in (1, 2, 3)] for i in (1, 2, 3)})
        super().__init__(inputs, outputs, params, feed)
        self.flip = True

    def initialize(self, t0: float) -> None:
        h = self.p("hemisphere")
        if h not in (0.0, 1.0):
            raise ValueError(f"{self.model_name}: hemisphere = {h:g} must be 0 or 1")
        self.flip = h == 1.0

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        qe = quaternion_error(_unit(u[0:4], "AttitudeError input q"), _unit(u[7:11], "AttitudeError input q_d"))
        if self.flip and qe[0] < 0.0:  # -q_e is the same attitude error, the shorter rotation
            qe = (-qe[0], -qe[1], -qe[2], -qe[3])
        w = u[4:7]
        cw = error_rotation_times(qe, u[11:14])  # C(-q) = C(q): the flip leaves omega_e unchanged
        return np.array([qe[0], qe[1], qe[2], qe[3], w[0] - cw[0], w[1] - cw[1], w[2] - cw[2]])
