"""Kernel of plant/rigid_wheels.py (rigid spacecraft with N wheels, 001 (1)-(3), (5)): the RK4
step of ``RigidSpacecraftWheels.advance`` with the stage torques (fault onsets through the
one-sided rule of plant/timing.py), the same order of operations as the reference.

Arrays: ``x`` (6) = [nu, psi, gamma, omega]; ``us`` (n) the saturated command; ``e``, ``e_on``,
``bias``, ``bias_on`` (n); ``M`` (3, n); ``prm`` the named pack :data:`PARAMS` (:func:`params`: J11, J12,
J13, J22, J23, J33, dJ_amp (3), dJ_freq (3), Td_amp (3), Td_freq (3), nu_max, omega_max).
Returns (x after the step, k): k = -1, or the internal step after which the validity guard
failed (x is then the state after that step; the block raises its own message).

:func:`advance_momentum` is the same step with the wheel momenta as states (``wheel_momentum`` = 1,
``RigidSpacecraftWheels._advance_momentum``): ``x`` (6 + n) = [nu, psi, gamma, omega, h_w].
"""
from __future__ import annotations

import math

import numpy as np

from plant.jit import jit, pack
from plant.kernels.common import active, contains, happened, solve_sym3, window

_INERTIA = ("j11", "j12", "j13", "j22", "j23", "j33")  # kg.m2
PARAMS = (_INERTIA + tuple(f"{name}{i}" for name in ("dj_amp", "dj_freq", "td_amp", "td_freq") for i in (1, 2, 3))
          + ("nu_max", "omega_max"))
(J11, J12, J13, J22, J23, J33, DJ_AMP1, DJ_AMP2, DJ_AMP3, DJ_FREQ1, DJ_FREQ2, DJ_FREQ3, TD_AMP1, TD_AMP2, TD_AMP3,
 TD_FREQ1, TD_FREQ2, TD_FREQ3, NU_MAX, OMEGA_MAX) = range(len(PARAMS))


def params(J6, dj_amp, dj_freq, td_amp, td_freq, nu_max, omega_max):
    """The pack ``prm`` of :func:`advance` (:data:`PARAMS`): ``J6`` = (J11, J12, J13, J22, J23, J33) (kg.m2),
    the 3-vectors of the Delta J(t) and T_d(t) amplitudes and frequencies (001 section 4), the guards (rad, rad/s)."""
    values = dict(zip(_INERTIA, J6))
    for name, v in (("dj_amp", dj_amp), ("dj_freq", dj_freq), ("td_amp", td_amp), ("td_freq", td_freq)):
        values.update({f"{name}{i + 1}": x for i, x in enumerate(v)})
    return pack(PARAMS, {**values, "nu_max": nu_max, "omega_max": omega_max})


@jit
def _torque(us, e, e_on, bias, bias_on, M, tau, lo, hi, out):
    """out = M (E us + u_f) with the faults active at stage time tau (``_stage_torque``)."""
    n = us.shape[0]
    for i in range(3):
        out[i] = 0.0
    for j in range(n):
        ej = e[j] if active(e_on[j], tau, lo, hi) else 1.0
        fj = bias[j] if active(bias_on[j], tau, lo, hi) else 0.0
        uw = ej * us[j] + fj
        for i in range(3):
            out[i] += M[i, j] * uw


@jit
def _deriv(x, t, tau, prm, out):
    """out = [sigma', omega'] (reference ``_deriv``)."""
    nu, gamma = x[0], x[2]
    w1, w2, w3 = x[3], x[4], x[5]
    j11, j12, j13, j22, j23, j33 = prm[J11], prm[J12], prm[J13], prm[J22], prm[J23], prm[J33]
    j11 += prm[DJ_AMP1] * math.sin(prm[DJ_FREQ1] * t)
    j22 += prm[DJ_AMP2] * math.sin(prm[DJ_FREQ2] * t)
    j33 += prm[DJ_AMP3] * math.sin(prm[DJ_FREQ3] * t)
    h1 = j11 * w1 + j12 * w2 + j13 * w3
    h2 = j12 * w1 + j22 * w2 + j23 * w3
    h3 = j13 * w1 + j23 * w2 + j33 * w3
    b1 = -(w2 * h3 - w3 * h2) + tau[0] + prm[TD_AMP1] * math.sin(prm[TD_FREQ1] * t)
    b2 = -(w3 * h1 - w1 * h3) + tau[1] + prm[TD_AMP2] * math.sin(prm[TD_FREQ2] * t)
    b3 = -(w1 * h2 - w2 * h1) + tau[2] + prm[TD_AMP3] * math.sin(prm[TD_FREQ3] * t)
    sg, cg = math.sin(gamma), math.cos(gamma)
    c = w2 * cg - w3 * sg
    out[0] = w2 * sg + w3 * cg
    out[1] = c / math.cos(nu)
    out[2] = w1 - math.tan(nu) * c
    out[3], out[4], out[5] = solve_sym3(j11, j12, j13, j22, j23, j33, b1, b2, b3)


@jit
def advance(x0, t, h, steps, us, e, e_on, bias, bias_on, M, prm):
    lo, hi = window(t, h)
    dt = h / steps
    n = us.shape[0]
    switching = False
    for j in range(n):
        if contains(e_on[j], lo, hi) or contains(bias_on[j], lo, hi):
            switching = True
    ta, tb, tc = np.empty(3), np.empty(3), np.empty(3)
    if not switching:
        _torque(us, e, e_on, bias, bias_on, M, t, lo, hi, ta)
        tb[:] = ta
        tc[:] = ta
    x = x0.copy()
    xs = np.empty(6)
    k1, k2, k3, k4 = np.empty(6), np.empty(6), np.empty(6), np.empty(6)
    nu_max, omega_max = prm[NU_MAX], prm[OMEGA_MAX]
    for k in range(steps):
        tk = t + k * dt
        tm, t1 = tk + 0.5 * dt, tk + dt
        if switching:
            _torque(us, e, e_on, bias, bias_on, M, tk, lo, hi, ta)
            _torque(us, e, e_on, bias, bias_on, M, tm, lo, hi, tb)
            _torque(us, e, e_on, bias, bias_on, M, t1, lo, hi, tc)
        _deriv(x, tk, ta, prm, k1)
        for i in range(6):
            xs[i] = x[i] + 0.5 * dt * k1[i]
        _deriv(xs, tm, tb, prm, k2)
        for i in range(6):
            xs[i] = x[i] + 0.5 * dt * k2[i]
        _deriv(xs, tm, tb, prm, k3)
        for i in range(6):
            xs[i] = x[i] + dt * k3[i]
        _deriv(xs, t1, tc, prm, k4)
        for i in range(6):
            x[i] = x[i] + (dt / 6.0) * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i])
        w = max(abs(x[3]), abs(x[4]), abs(x[5]))
        finite = True
        for i in range(6):
            if not math.isfinite(x[i]):
                finite = False
        if not finite or abs(x[0]) > nu_max or w > omega_max:
            return x, k
    return x, -1


@jit
def _wheels(us, e, e_on, bias, bias_on, tau, lo, hi, out):
    """out = E us + u_f, the applied wheel torques with the faults active at stage time tau
    (reference ``_stage_wheels``)."""
    for j in range(us.shape[0]):
        ej = e[j] if active(e_on[j], tau, lo, hi) else 1.0
        fj = bias[j] if active(bias_on[j], tau, lo, hi) else 0.0
        out[j] = ej * us[j] + fj


@jit
def _deriv_momentum(x, t, uw, M, prm, out):
    """out = [sigma', omega', h_w'] with the wheel momenta x[6:] (reference ``_deriv_momentum``)."""
    n = uw.shape[0]
    nu, gamma = x[0], x[2]
    w1, w2, w3 = x[3], x[4], x[5]
    g1 = 0.0
    g2 = 0.0
    g3 = 0.0
    t1 = 0.0
    t2 = 0.0
    t3 = 0.0
    for j in range(n):
        g1 += M[0, j] * x[6 + j]
        g2 += M[1, j] * x[6 + j]
        g3 += M[2, j] * x[6 + j]
    for j in range(n):
        t1 += M[0, j] * uw[j]
        t2 += M[1, j] * uw[j]
        t3 += M[2, j] * uw[j]
    j11, j12, j13, j22, j23, j33 = prm[J11], prm[J12], prm[J13], prm[J22], prm[J23], prm[J33]
    j11 += prm[DJ_AMP1] * math.sin(prm[DJ_FREQ1] * t)
    j22 += prm[DJ_AMP2] * math.sin(prm[DJ_FREQ2] * t)
    j33 += prm[DJ_AMP3] * math.sin(prm[DJ_FREQ3] * t)
    h1 = j11 * w1 + j12 * w2 + j13 * w3 + g1
    h2 = j12 * w1 + j22 * w2 + j23 * w3 + g2
    h3 = j13 * w1 + j23 * w2 + j33 * w3 + g3
    b1 = -(w2 * h3 - w3 * h2) + t1 + prm[TD_AMP1] * math.sin(prm[TD_FREQ1] * t)
    b2 = -(w3 * h1 - w1 * h3) + t2 + prm[TD_AMP2] * math.sin(prm[TD_FREQ2] * t)
    b3 = -(w1 * h2 - w2 * h1) + t3 + prm[TD_AMP3] * math.sin(prm[TD_FREQ3] * t)
    sg, cg = math.sin(gamma), math.cos(gamma)
    c = w2 * cg - w3 * sg
    out[0] = w2 * sg + w3 * cg
    out[1] = c / math.cos(nu)
    out[2] = w1 - math.tan(nu) * c
    out[3], out[4], out[5] = solve_sym3(j11, j12, j13, j22, j23, j33, b1, b2, b3)
    for j in range(n):
        out[6 + j] = -uw[j]


@jit
def advance_momentum(x0, t, h, steps, us, e, e_on, bias, bias_on, M, prm):
    """:func:`advance` with the wheel momenta as states, x = [sigma, omega, h_w] (6 + n)."""
    lo, hi = window(t, h)
    dt = h / steps
    n = us.shape[0]
    m = x0.shape[0]
    ua, ub, uc = np.empty(n), np.empty(n), np.empty(n)
    x = x0.copy()
    xs = np.empty(m)
    k1, k2, k3, k4 = np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    nu_max, omega_max = prm[NU_MAX], prm[OMEGA_MAX]
    for k in range(steps):
        tk = t + k * dt
        tm, t1 = tk + 0.5 * dt, tk + dt
        _wheels(us, e, e_on, bias, bias_on, tk, lo, hi, ua)
        _wheels(us, e, e_on, bias, bias_on, tm, lo, hi, ub)
        _wheels(us, e, e_on, bias, bias_on, t1, lo, hi, uc)
        _deriv_momentum(x, tk, ua, M, prm, k1)
        for i in range(m):
            xs[i] = x[i] + 0.5 * dt * k1[i]
        _deriv_momentum(xs, tm, ub, M, prm, k2)
        for i in range(m):
            xs[i] = x[i] + 0.5 * dt * k2[i]
        _deriv_momentum(xs, tm, ub, M, prm, k3)
        for i in range(m):
            xs[i] = x[i] + dt * k3[i]
        _deriv_momentum(xs, t1, uc, M, prm, k4)
        for i in range(m):
            x[i] = x[i] + (dt / 6.0) * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i])
        w = max(abs(x[3]), abs(x[4]), abs(x[5]))
        finite = True
        for i in range(m):
            if not math.isfinite(x[i]):
                finite = False
        if not finite or abs(x[0]) > nu_max or w > omega_max:
            return x, k
    return x, -1


@jit
def actuator(t, u, n, u_max, e, e_on, bias, bias_on, M):
    """[u_wheel (n), tau_applied (3), fault_torque (3), e (n), u_f (n)] at the point t for the
    command u[:n] (reference ``_actuator_outputs``: saturation, faults from the right at t)."""
    out = np.empty(3 * n + 6)
    for i in range(6):
        out[n + i] = 0.0
    for j in range(n):
        us = u[j]
        if u_max > 0:
            us = min(max(us, -u_max), u_max)
        ej = e[j] if happened(e_on[j], t) else 1.0
        fj = bias[j] if happened(bias_on[j], t) else 0.0
        uw = ej * us + fj
        fw = (ej - 1.0) * us + fj
        out[j] = uw
        out[n + 6 + j] = ej
        out[2 * n + 6 + j] = fj
        for i in range(3):
            out[n + i] += M[i, j] * uw
            out[n + 3 + i] += M[i, j] * fw
    return out
