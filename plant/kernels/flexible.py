"""Kernels of plant/flexible.py (FlexibleSpacecraft): the RK4 step with its stage torques, the
outputs at a communication point and the actuator path. Same formulas and switching rule as
the reference methods ``_deriv``, ``_stage_torque``, ``_constant_torque``, ``advance``,
``actuator`` and ``outputs_at`` (000 (2)-(3), (6)-(7), (66); 001 (5); plant/timing.py).

``prm`` is the named pack :data:`PARAMS` of the scalar parameters (:func:`params`, built in
``FlexibleSpacecraft.initialize``). :func:`advance_momentum` is the step with the wheel momenta as
states (``wheel_momentum`` = 1; reference ``_advance_reference`` with ``_deriv_momentum`` and
``_stage_wheels``): y = [q, omega, eta, eta_dot, h_w (3)].
"""
from __future__ import annotations

import math

import numpy as np

from plant.jit import jit, pack
from plant.kernels.common import (
    active,
    contains,
    disturbance,
    fault_at,
    fault_in_step,
    happened,
    rk4_combine,
    rk4_setup,
    rk4_stage,
    saturate3,
    window,
)

PARAMS = ("fault_scale", "fault_onset", "disturbance_scale", "effectiveness_onset", "bias_onset", "u_max",
          "saturation_mode")
FAULT_SCALE, FAULT_ONSET, DISTURBANCE_SCALE, E_ONSET, BIAS_ONSET, U_MAX, SATURATION_MODE = range(len(PARAMS))


def params(**values):
    """The pack ``prm`` of :func:`advance`, :func:`actuator` and :func:`outputs`, by name (:data:`PARAMS`)."""
    return pack(PARAMS, values)


@jit
def _deriv(y, torque, A, Bn, H, out, tmp):
    """out = dy/dt for the state y = [q (4), omega (3), eta (n), eta_dot (n)] and the total torque."""
    m = A.shape[0]
    h1 = 0.0
    h2 = 0.0
    h3 = 0.0
    for j in range(m):
        xj = y[4 + j]
        h1 += H[0, j] * xj
        h2 += H[1, j] * xj
        h3 += H[2, j] * xj
    w1, w2, w3 = y[4], y[5], y[6]
    tmp[0] = torque[0] - (w2 * h3 - w3 * h2)
    tmp[1] = torque[1] - (w3 * h1 - w1 * h3)
    tmp[2] = torque[2] - (w1 * h2 - w2 * h1)
    for i in range(m):
        s = 0.0
        for j in range(m):
            s += A[i, j] * y[4 + j]
        b = Bn[i, 0] * tmp[0] + Bn[i, 1] * tmp[1] + Bn[i, 2] * tmp[2]
        out[4 + i] = s + b
    q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
    out[0] = -0.5 * (q1 * w1 + q2 * w2 + q3 * w3)
    out[1] = 0.5 * (q0 * w1 + q2 * w3 - q3 * w2)
    out[2] = 0.5 * (q0 * w2 + q3 * w1 - q1 * w3)
    out[3] = 0.5 * (q0 * w3 + q1 * w2 - q2 * w1)


@jit
def _stage_torque(t, us, lo, hi, G, e, bias, prm, out):
    """Applied + disturbance torque at stage time t (reference ``_stage_torque``)."""
    fault_scale, fault_onset, dist_scale = prm[FAULT_SCALE], prm[FAULT_ONSET], prm[DISTURBANCE_SCALE]
    e_onset, bias_onset = prm[E_ONSET], prm[BIAS_ONSET]
    e_on = active(e_onset, t, lo, hi)
    b_on = active(bias_onset, t, lo, hi)
    f1, f2 = fault_in_step(t, fault_scale, fault_onset, lo, hi)
    v0 = (e[0] if e_on else 1.0) * us[0] + (bias[0] if b_on else 0.0) + f1
    v1 = (e[1] if e_on else 1.0) * us[1] + (bias[1] if b_on else 0.0) + f2
    v2 = (e[2] if e_on else 1.0) * us[2] + (bias[2] if b_on else 0.0) + 0.0
    for i in range(3):
        out[i] = G[i, 0] * v0 + G[i, 1] * v1 + G[i, 2] * v2
    if dist_scale != 0.0:
        d1, d2, d3 = disturbance(t, dist_scale)
        out[0] += d1
        out[1] += d2
        out[2] += d3


@jit
def advance(y0, t, h, steps, u, A, Bn, H, G, e, bias, prm):
    """The state after one communication step [t, t + h] with u held (reference ``advance``,
    without the omega_max guard, which the block applies)."""
    fault_scale, fault_onset, dist_scale = prm[FAULT_SCALE], prm[FAULT_ONSET], prm[DISTURBANCE_SCALE]
    e_onset, bias_onset = prm[E_ONSET], prm[BIAS_ONSET]
    s0, s1, s2 = saturate3(u[0], u[1], u[2], prm[U_MAX], int(prm[SATURATION_MODE]))
    us = np.array((s0, s1, s2))
    lo, hi = window(t, h)
    const = not (dist_scale != 0.0 or (fault_scale != 0.0 and active(fault_onset, t + h, lo, hi)))
    if const:
        const = not (contains(e_onset, lo, hi) or contains(bias_onset, lo, hi))
    n = y0.size
    dt, half, sixth, k1, k2, k3, k4, z = rk4_setup(h, steps, n)
    y = y0.copy()
    tmp = np.empty(3)
    tq0 = np.empty(3)
    tqm = np.empty(3)
    tq1 = np.empty(3)
    if const:
        _stage_torque(t, us, lo, hi, G, e, bias, prm, tq0)
        tqm[:] = tq0
        tq1[:] = tq0
    for k in range(steps):
        tk = t + k * dt
        if not const:
            _stage_torque(tk, us, lo, hi, G, e, bias, prm, tq0)
            _stage_torque(tk + 0.5 * dt, us, lo, hi, G, e, bias, prm, tqm)
            _stage_torque(tk + dt, us, lo, hi, G, e, bias, prm, tq1)
        _deriv(y, tq0, A, Bn, H, k1, tmp)
        rk4_stage(z, y, half, k1)
        _deriv(z, tqm, A, Bn, H, k2, tmp)
        rk4_stage(z, y, half, k2)
        _deriv(z, tqm, A, Bn, H, k3, tmp)
        rk4_stage(z, y, dt, k3)
        _deriv(z, tq1, A, Bn, H, k4, tmp)
        rk4_combine(y, sixth, k1, k2, k3, k4)
        nq = math.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3])
        for i in range(4):
            y[i] = y[i] / nq
    return y


@jit
def _stage_wheels(t, us, lo, hi, G, e, bias, prm, out, v):
    """v = E us + u_f + f (the wheel torques) and out = G v + u_d at stage time t (reference
    ``_stage_wheels``)."""
    fault_scale, fault_onset, dist_scale = prm[FAULT_SCALE], prm[FAULT_ONSET], prm[DISTURBANCE_SCALE]
    e_on = active(prm[E_ONSET], t, lo, hi)
    b_on = active(prm[BIAS_ONSET], t, lo, hi)
    f1, f2 = fault_in_step(t, fault_scale, fault_onset, lo, hi)
    v[0] = (e[0] if e_on else 1.0) * us[0] + (bias[0] if b_on else 0.0) + f1
    v[1] = (e[1] if e_on else 1.0) * us[1] + (bias[1] if b_on else 0.0) + f2
    v[2] = (e[2] if e_on else 1.0) * us[2] + (bias[2] if b_on else 0.0) + 0.0
    for i in range(3):
        out[i] = G[i, 0] * v[0] + G[i, 1] * v[1] + G[i, 2] * v[2]
    if dist_scale != 0.0:
        d1, d2, d3 = disturbance(t, dist_scale)
        out[0] += d1
        out[1] += d2
        out[2] += d3


@jit
def _deriv_momentum(y, torque, v, A, Bn, H, G, out, tmp):
    """out = dy/dt for y = [q, omega, eta, eta_dot, h_w] (reference ``_deriv_momentum``)."""
    m = A.shape[0]
    h1 = 0.0
    h2 = 0.0
    h3 = 0.0
    for j in range(m):
        xj = y[4 + j]
        h1 += H[0, j] * xj
        h2 += H[1, j] * xj
        h3 += H[2, j] * xj
    w0 = y[4 + m]
    w1_ = y[5 + m]
    w2_ = y[6 + m]
    h1 += G[0, 0] * w0 + G[0, 1] * w1_ + G[0, 2] * w2_
    h2 += G[1, 0] * w0 + G[1, 1] * w1_ + G[1, 2] * w2_
    h3 += G[2, 0] * w0 + G[2, 1] * w1_ + G[2, 2] * w2_
    w1, w2, w3 = y[4], y[5], y[6]
    tmp[0] = torque[0] - (w2 * h3 - w3 * h2)
    tmp[1] = torque[1] - (w3 * h1 - w1 * h3)
    tmp[2] = torque[2] - (w1 * h2 - w2 * h1)
    for i in range(m):
        s = 0.0
        for j in range(m):
            s += A[i, j] * y[4 + j]
        b = Bn[i, 0] * tmp[0] + Bn[i, 1] * tmp[1] + Bn[i, 2] * tmp[2]
        out[4 + i] = s + b
    q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
    out[0] = -0.5 * (q1 * w1 + q2 * w2 + q3 * w3)
    out[1] = 0.5 * (q0 * w1 + q2 * w3 - q3 * w2)
    out[2] = 0.5 * (q0 * w2 + q3 * w1 - q1 * w3)
    out[3] = 0.5 * (q0 * w3 + q1 * w2 - q2 * w1)
    out[4 + m] = -v[0]
    out[5 + m] = -v[1]
    out[6 + m] = -v[2]


@jit
def advance_momentum(y0, t, h, steps, u, A, Bn, H, G, e, bias, prm):
    """:func:`advance` with the wheel momenta as states (y0 = [q, omega, eta, eta_dot, h_w])."""
    s0, s1, s2 = saturate3(u[0], u[1], u[2], prm[U_MAX], int(prm[SATURATION_MODE]))
    us = np.array((s0, s1, s2))
    lo, hi = window(t, h)
    n = y0.size
    dt, half, sixth, k1, k2, k3, k4, z = rk4_setup(h, steps, n)
    y = y0.copy()
    tmp = np.empty(3)
    tq0, tqm, tq1 = np.empty(3), np.empty(3), np.empty(3)
    v0, vm, v1 = np.empty(3), np.empty(3), np.empty(3)
    for k in range(steps):
        tk = t + k * dt
        _stage_wheels(tk, us, lo, hi, G, e, bias, prm, tq0, v0)
        _stage_wheels(tk + 0.5 * dt, us, lo, hi, G, e, bias, prm, tqm, vm)
        _stage_wheels(tk + dt, us, lo, hi, G, e, bias, prm, tq1, v1)
        _deriv_momentum(y, tq0, v0, A, Bn, H, G, k1, tmp)
        rk4_stage(z, y, half, k1)
        _deriv_momentum(z, tqm, vm, A, Bn, H, G, k2, tmp)
        rk4_stage(z, y, half, k2)
        _deriv_momentum(z, tqm, vm, A, Bn, H, G, k3, tmp)
        rk4_stage(z, y, dt, k3)
        _deriv_momentum(z, tq1, v1, A, Bn, H, G, k4, tmp)
        rk4_combine(y, sixth, k1, k2, k3, k4)
        nq = math.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3])
        for i in range(4):
            y[i] = y[i] / nq
    return y


@jit
def actuator(t, u, G, e, bias, prm, out, k):
    """out[k:k+3] = applied torque, out[k+3:k+6] = f_eq at the communication point t
    (reference ``actuator``)."""
    fault_scale, fault_onset, e_onset, bias_onset = prm[FAULT_SCALE], prm[FAULT_ONSET], prm[E_ONSET], prm[BIAS_ONSET]
    s0, s1, s2 = saturate3(u[0], u[1], u[2], prm[U_MAX], int(prm[SATURATION_MODE]))
    e_on = happened(e_onset, t)
    b_on = happened(bias_onset, t)
    f1, f2 = fault_at(t, fault_scale, fault_onset)
    fe0 = ((e[0] if e_on else 1.0) - 1.0) * s0 + (bias[0] if b_on else 0.0) + f1
    fe1 = ((e[1] if e_on else 1.0) - 1.0) * s1 + (bias[1] if b_on else 0.0) + f2
    fe2 = ((e[2] if e_on else 1.0) - 1.0) * s2 + (bias[2] if b_on else 0.0) + 0.0
    v0, v1, v2 = s0 + fe0, s1 + fe1, s2 + fe2
    for i in range(3):
        out[k + i] = G[i, 0] * v0 + G[i, 1] * v1 + G[i, 2] * v2
    out[k + 3] = fe0
    out[k + 4] = fe1
    out[k + 5] = fe2


@jit
def outputs(t, y, u, G, e, bias, prm, dC, dK, dT):
    """[y, tau_applied, f_eq, d_vib, u_d] at the communication point t (reference ``outputs_at``)."""
    n = dC.shape[1]
    ny = y.size
    out = np.empty(ny + 12)
    out[:ny] = y
    actuator(t, u, G, e, bias, prm, out, ny)
    w1, w2, w3 = y[4], y[5], y[6]
    c0 = 0.0
    c1 = 0.0
    c2 = 0.0
    for j in range(n):
        c0 += dT[0, j] * y[7 + n + j]
        c1 += dT[1, j] * y[7 + n + j]
        c2 += dT[2, j] * y[7 + n + j]
    cr = (w2 * c2 - w3 * c1, w3 * c0 - w1 * c2, w1 * c1 - w2 * c0)
    for i in range(3):
        a = 0.0
        b = 0.0
        for j in range(n):
            a += dC[i, j] * y[7 + n + j]
            b += dK[i, j] * y[7 + j]
        out[ny + 6 + i] = a + b - cr[i]
    d1, d2, d3 = disturbance(t, prm[DISTURBANCE_SCALE])
    out[ny + 9] = d1
    out[ny + 10] = d2
    out[ny + 11] = d3
    return out
