"""Kernels of the attitude controllers of paper 000 (controller/attitude.py, fasmc.py,
aismc.py, pd.py): the sliding terms and each law's outputs [sat(u), q_e0, q_ev, omega_e].
Same formulas as the reference ``sliding_terms``, ``FASMC.law``, ``AISMC.law`` /
``AISMC.advance`` and ``PDController.law`` (000 (4)-(5), (36), (39)-(40), (64), (69)-(71)).

The input vector is laid out as ``controller/base.py: attitude_inputs``: q [0:4], omega [4:7],
q_d [7:11], omega_d [11:14], omega_d_dot [14:17], f_hat [17:20], d2_hat [20:20+2n].
``prm`` is the named pack of each law (:data:`PD`, :data:`FASMC`, :data:`AISMC`, built by
:func:`params`): it always starts with [beta, omega_box, u_max, saturation_mode]; each law appends its own.
"""
from __future__ import annotations

import math

import numpy as np

from plant.jit import jit, pack
from plant.kernels.common import memberships8, saturate3

COMMON = ("beta", "omega_box", "u_max", "saturation_mode")
PD = COMMON + ("k_p", "k_d")
FASMC = COMMON + ("sigma_1", "sigma_2", "sigma_2p", "varsigma")
AISMC = COMMON + ("sigma", "sigma_p")
BETA, OMEGA_BOX, U_MAX, SATURATION_MODE = range(len(COMMON))
K_P, K_D = len(COMMON), len(COMMON) + 1  # PD
SIGMA_1, SIGMA_2, SIGMA_2P, VARSIGMA = range(len(COMMON), len(FASMC))  # FASMC
SIGMA, SIGMA_P = len(COMMON), len(COMMON) + 1  # AISMC


def params(law: tuple, **values):
    """The pack ``prm`` of ``law`` (:data:`PD`, :data:`FASMC` or :data:`AISMC`), by name."""
    return pack(law, values)


@jit
def _theta(a, qe0, e1, e2, e3, v0, v1, v2):
    """Theta_q v of 000 (5), as ``sliding_terms.theta``."""
    ev = e1 * v0 + e2 * v1 + e3 * v2
    c0 = e2 * v2 - e3 * v1
    c1 = e3 * v0 - e1 * v2
    c2 = e1 * v1 - e2 * v0
    return (a * v0 + 2.0 * e1 * ev - 2.0 * qe0 * c0,
            a * v1 + 2.0 * e2 * ev - 2.0 * qe0 * c1,
            a * v2 + 2.0 * e3 * ev - 2.0 * qe0 * c2)


@jit
def sliding_terms(u, beta, B, J, out):
    """out = [q_e0, q_ev (3), omega_e (3), s (3), g (3)] (reference ``sliding_terms``)."""
    q0, q1, q2, q3 = u[0], u[1], u[2], u[3]
    w0, w1, w2 = u[4], u[5], u[6]
    d0, d1, d2, d3 = u[7], u[8], u[9], u[10]
    qe0 = d1 * q1 + d2 * q2 + d3 * q3 + d0 * q0  # 000 (4)
    e1 = d0 * q1 - (d2 * q3 - d3 * q2) - d1 * q0
    e2 = d0 * q2 - (d3 * q1 - d1 * q3) - d2 * q0
    e3 = d0 * q3 - (d1 * q2 - d2 * q1) - d3 * q0
    a = qe0 * qe0 - (e1 * e1 + e2 * e2 + e3 * e3)
    tw0, tw1, tw2 = _theta(a, qe0, e1, e2, e3, u[11], u[12], u[13])
    we0, we1, we2 = w0 - tw0, w1 - tw1, w2 - tw2  # 000 (5)
    v0, v1, v2 = beta * e1 - tw0, beta * e2 - tw1, beta * e3 - tw2
    h0 = J[0, 0] * v0 + J[0, 1] * v1 + J[0, 2] * v2
    h1 = J[1, 0] * v0 + J[1, 1] * v1 + J[1, 2] * v2
    h2 = J[2, 0] * v0 + J[2, 1] * v1 + J[2, 2] * v2
    x0, x1, x2 = w1 * h2 - w2 * h1, w2 * h0 - w0 * h2, w0 * h1 - w1 * h0
    r0 = B[0, 0] * x0 + B[0, 1] * x1 + B[0, 2] * x2
    r1 = B[1, 0] * x0 + B[1, 1] * x1 + B[1, 2] * x2
    r2 = B[2, 0] * x0 + B[2, 1] * x1 + B[2, 2] * x2
    c10, c11, c12 = e2 * we2 - e3 * we1, e3 * we0 - e1 * we2, e1 * we1 - e2 * we0
    c20, c21, c22 = we1 * tw2 - we2 * tw1, we2 * tw0 - we0 * tw2, we0 * tw1 - we1 * tw0
    td0, td1, td2 = _theta(a, qe0, e1, e2, e3, u[14], u[15], u[16])
    out[0] = qe0
    out[1], out[2], out[3] = e1, e2, e3
    out[4], out[5], out[6] = we0, we1, we2
    out[7], out[8], out[9] = we0 + beta * e1, we1 + beta * e2, we2 + beta * e3  # 000 (39)
    out[10] = 0.5 * beta * (qe0 * we0 + c10) + r0 + c20 - td0  # 000 (36)
    out[11] = 0.5 * beta * (qe0 * we1 + c11) + r1 + c21 - td1
    out[12] = 0.5 * beta * (qe0 * we2 + c12) + r2 + c22 - td2


@jit
def _finish(cmd, st, prm):
    """[sat(cmd), q_e0, q_ev, omega_e] (reference ``AttitudeController.outputs_at``)."""
    out = np.empty(10)
    out[0], out[1], out[2] = saturate3(cmd[0], cmd[1], cmd[2], prm[U_MAX], int(prm[SATURATION_MODE]))
    for i in range(7):
        out[3 + i] = st[i]
    return out


@jit
def fasmc_outputs(u, B, J, Jm, rules, prm):
    """FASMC 000 (40)/(64); ``prm`` = [beta, omega_box, u_max, saturation_mode, sigma_1, sigma_2,
    sigma_2p, varsigma]; ``rules`` (8, 9 + 6n) = per rule [K_c^i, Jm D_2i] flattened."""
    beta, box = prm[BETA], prm[OMEGA_BOX]
    sigma_1, sigma_2, sigma_2p, varsigma = prm[SIGMA_1], prm[SIGMA_2], prm[SIGMA_2P], prm[VARSIGMA]
    st = np.empty(13)
    sliding_terms(u, beta, B, J, st)
    s0, s1, s2 = st[7], st[8], st[9]
    b = memberships8(u[4], u[5], u[6], box)
    R, ncol = rules.shape
    blend = np.zeros(ncol)
    for k in range(R):
        for j in range(ncol):
            blend[j] += b[k] * rules[k, j]
    v0 = blend[0] * s0 + blend[1] * s1 + blend[2] * s2  # 000 (40): v = sum_j b_j K_c^j s
    v1 = blend[3] * s0 + blend[4] * s1 + blend[5] * s2
    v2 = blend[6] * s0 + blend[7] * s1 + blend[8] * s2
    nv = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    if nv > varsigma:  # saturated virtual controller, ||v||_2 <= varsigma
        k = varsigma / nv
        v0, v1, v2 = v0 * k, v1 * k, v2 * k
    nd = (ncol - 9) // 3
    ns = math.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
    ksw = sigma_2 / (ns + sigma_2p)
    v = (v0, v1, v2)
    cmd = np.empty(3)
    for i in range(3):
        dd = 0.0
        for j in range(nd):
            dd += blend[9 + i * nd + j] * u[20 + j]  # sum_i b_i Gamma^+ B^- D_2i d2_hat
        jg = Jm[i, 0] * st[10] + Jm[i, 1] * st[11] + Jm[i, 2] * st[12]  # Gamma^+ B^- g(s)
        si = st[7 + i]
        cmd[i] = v[i] - u[17 + i] - dd - jg - sigma_1 * si - ksw * si  # 000 (40), (64)
    return _finish(cmd, st, prm)


@jit
def aismc_outputs(u, B, J, Jm, Kc3, integral, prm):
    """AISMC 000 (70)-(71); ``prm`` = [beta, omega_box, u_max, saturation_mode, sigma, sigma_p]."""
    beta, box, sigma, sigma_p = prm[BETA], prm[OMEGA_BOX], prm[SIGMA], prm[SIGMA_P]
    st = np.empty(13)
    sliding_terms(u, beta, B, J, st)
    s0, s1, s2 = st[7], st[8], st[9]
    b = memberships8(u[4], u[5], u[6], box)
    S0, S1, S2 = s0 - integral[0], s1 - integral[1], s2 - integral[2]  # 000 (71)
    dm = math.sqrt(S0 * S0 + S1 * S1 + S2 * S2)
    bk = 0.0
    for k in range(Kc3.shape[0]):
        a0 = Kc3[k, 0, 0] * s0 + Kc3[k, 0, 1] * s1 + Kc3[k, 0, 2] * s2
        a1 = Kc3[k, 1, 0] * s0 + Kc3[k, 1, 1] * s1 + Kc3[k, 1, 2] * s2
        a2 = Kc3[k, 2, 0] * s0 + Kc3[k, 2, 1] * s1 + Kc3[k, 2, 2] * s2
        bk += b[k] * math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)  # ||K_c^i s||_2
    gain = bk + sigma + dm
    kk = gain / (math.sqrt(s0 * s0 + s1 * s1 + s2 * s2) + sigma_p)
    cmd = np.empty(3)
    for i in range(3):
        cmd[i] = -kk * st[7 + i] - (Jm[i, 0] * st[10] + Jm[i, 1] * st[11] + Jm[i, 2] * st[12])  # 000 (70)
    return _finish(cmd, st, prm)


@jit
def aismc_integral(u, h, B, J, Kc3, integral, prm):
    """I(t + h) = I(t) + h (A(clip(omega)) + B sum_i b_i K_c^i) s (reference ``AISMC.advance``)."""
    beta, box = prm[BETA], prm[OMEGA_BOX]
    st = np.empty(13)
    sliding_terms(u, beta, B, J, st)
    b = memberships8(u[4], u[5], u[6], box)
    w0 = min(max(u[4], -box), box)
    w1 = min(max(u[5], -box), box)
    w2 = min(max(u[6], -box), box)
    W = np.array(((0.0, -w2, w1), (w2, 0.0, -w0), (-w1, w0, 0.0)))
    Kcb = np.zeros((3, 3))
    for k in range(Kc3.shape[0]):
        for i in range(3):
            for j in range(3):
                Kcb[i, j] += b[k] * Kc3[k, i, j]
    BW = np.zeros((3, 3))
    M = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            BW[i, j] = -B[i, 0] * W[0, j] - B[i, 1] * W[1, j] - B[i, 2] * W[2, j]
    for i in range(3):
        for j in range(3):
            M[i, j] = (BW[i, 0] * J[0, j] + BW[i, 1] * J[1, j] + BW[i, 2] * J[2, j]
                       + (B[i, 0] * Kcb[0, j] + B[i, 1] * Kcb[1, j] + B[i, 2] * Kcb[2, j]))
    out = np.empty(3)
    for i in range(3):
        out[i] = integral[i] + h * (M[i, 0] * st[7] + M[i, 1] * st[8] + M[i, 2] * st[9])
    return out


@jit
def pd_outputs(u, B, J, Jm, dK, dC, dT, prm):
    """PD with feed-forward 000 (69); ``prm`` = [beta, omega_box, u_max, saturation_mode, k_p, k_d]."""
    beta, box, kp, kd = prm[BETA], prm[OMEGA_BOX], prm[K_P], prm[K_D]
    st = np.empty(13)
    sliding_terms(u, beta, B, J, st)
    n = dK.shape[1]
    cmd = np.empty(3)
    for i in range(3):
        cmd[i] = -kp * st[1 + i] - kd * st[4 + i] - u[17 + i] - (Jm[i, 0] * st[10] + Jm[i, 1] * st[11] + Jm[i, 2] * st[12])
    nonzero = False
    for j in range(2 * n):
        if u[20 + j] != 0.0:
            nonzero = True
    if nonzero:  # B^+ D_2(clip(omega)) d2_hat = dK eta + dC eta_dot - w x (delta^T eta_dot)
        w0 = min(max(u[4], -box), box)
        w1 = min(max(u[5], -box), box)
        w2 = min(max(u[6], -box), box)
        t = np.zeros(3)
        for i in range(3):
            for j in range(n):
                t[i] += dT[i, j] * u[20 + n + j]
        cr = (w1 * t[2] - w2 * t[1], w2 * t[0] - w0 * t[2], w0 * t[1] - w1 * t[0])
        for i in range(3):
            a = 0.0
            c = 0.0
            for j in range(n):
                a += dK[i, j] * u[20 + j]
                c += dC[i, j] * u[20 + n + j]
            cmd[i] -= a + c - cr[i]
    return _finish(cmd, st, prm)
