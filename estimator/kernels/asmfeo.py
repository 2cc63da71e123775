"""Kernel of estimator/asmfeo.py (ASMFEO, 001 (12), (14), (15)): the RK4 step with the held
innovation (``ASMFEO._advance_held_innovation``, sampling_mode 1), the same formulas and order
of operations. sampling_mode 0 keeps the reference code.

Arrays: ``x`` = [omega_hat (3), e_hat (n), uf_hat (n), K]; ``wt`` (3) the held innovation;
``u_c`` (n) the command applied over the step; ``u_law`` (n) the command of the effectiveness law
(14) (``u_c`` or the previous one, ``command_pairing``); ``J``, ``Ji`` (3, 3); ``B`` = J^-1 M (3, n); ``Lam`` (3); ``prm``: the
named pack :data:`PARAMS` (lambda_1, lambda_2, lambda_3, ||J^-1||, epsilon, mu).
"""
from __future__ import annotations

import math

import numpy as np

from plant.jit import jit, pack

PARAMS = ("l1", "l2", "l3", "ji_norm", "eps", "mu")  # the observer's gains (001 (14)-(15)), ||J^-1||
L1, L2, L3, JI_NORM, EPS, MU = range(len(PARAMS))


def params(**values):
    """The pack ``prm`` of :func:`advance_held`, by name (:data:`PARAMS`)."""
    return pack(PARAMS, values)


@jit
def _f(tau, w1, w2, w3, K, J, Ji, lin, d, s, kd_up, mu, out):
    h1 = J[0, 0] * w1 + J[0, 1] * w2 + J[0, 2] * w3
    h2 = J[1, 0] * w1 + J[1, 1] * w2 + J[1, 2] * w3
    h3 = J[2, 0] * w1 + J[2, 1] * w2 + J[2, 2] * w3
    g1, g2, g3 = w2 * h3 - w3 * h2, w3 * h1 - w1 * h3, w1 * h2 - w2 * h1
    for i in range(3):
        out[i] = lin[i] + tau * d[i] - (Ji[i, 0] * g1 + Ji[i, 1] * g2 + Ji[i, 2] * g3) + K * s[i]  # 001 (12)
    out[3] = kd_up if K > mu else mu  # 001 (15)


@jit
def advance_held(x, wt, u_c, u_law, steps, dt, J, Ji, B, Lam, prm):
    n = u_c.shape[0]
    l1, l2, l3, ji_norm, eps, mu = prm[L1], prm[L2], prm[L3], prm[JI_NORM], prm[EPS], prm[MU]
    g = np.empty(n)
    for j in range(n):  # B^T omega~
        g[j] = B[0, j] * wt[0] + B[1, j] * wt[1] + B[2, j] * wt[2]
    e_dot, uf_dot = np.empty(n), np.empty(n)
    for j in range(n):  # 001 (14), constant over the step
        e_dot[j] = l1 * u_law[j] * g[j]
        uf_dot[j] = l2 * g[j]
    d, lin, s = np.empty(3), np.empty(3), np.empty(3)
    for i in range(3):
        a = 0.0
        b = 0.0
        for j in range(n):
            a += B[i, j] * (u_c[j] * e_dot[j] + uf_dot[j])
            b += B[i, j] * (u_c[j] * x[3 + j] + x[3 + n + j])
        d[i] = a
        lin[i] = Lam[i] * wt[i] + b
    sg = np.empty(3)
    for i in range(3):
        sg[i] = 1.0 if wt[i] > 0 else (-1.0 if wt[i] < 0 else (0.0 if wt[i] == 0 else wt[i]))
    for i in range(3):
        s[i] = Ji[i, 0] * sg[0] + Ji[i, 1] * sg[1] + Ji[i, 2] * sg[2]
    nw = math.sqrt(wt[0] * wt[0] + wt[1] * wt[1] + wt[2] * wt[2])
    kd_up = l3 * ji_norm * nw * (1.0 if nw > eps else (-1.0 if nw < eps else 0.0))
    w1, w2, w3, K = x[0], x[1], x[2], x[3 + 2 * n]
    a, b, c, e = np.empty(4), np.empty(4), np.empty(4), np.empty(4)
    for k in range(steps):
        t0 = k * dt
        _f(t0, w1, w2, w3, K, J, Ji, lin, d, s, kd_up, mu, a)
        _f(t0 + 0.5 * dt, w1 + 0.5 * dt * a[0], w2 + 0.5 * dt * a[1], w3 + 0.5 * dt * a[2], K + 0.5 * dt * a[3],
           J, Ji, lin, d, s, kd_up, mu, b)
        _f(t0 + 0.5 * dt, w1 + 0.5 * dt * b[0], w2 + 0.5 * dt * b[1], w3 + 0.5 * dt * b[2], K + 0.5 * dt * b[3],
           J, Ji, lin, d, s, kd_up, mu, c)
        _f(t0 + dt, w1 + dt * c[0], w2 + dt * c[1], w3 + dt * c[2], K + dt * c[3], J, Ji, lin, d, s, kd_up, mu, e)
        q = dt / 6.0
        w1 += q * (a[0] + 2.0 * (b[0] + c[0]) + e[0])
        w2 += q * (a[1] + 2.0 * (b[1] + c[1]) + e[1])
        w3 += q * (a[2] + 2.0 * (b[2] + c[2]) + e[2])
        K += q * (a[3] + 2.0 * (b[3] + c[3]) + e[3])
    H = steps * dt
    out = np.empty(4 + 2 * n)
    out[0], out[1], out[2] = w1, w2, w3
    for j in range(n):
        out[3 + j] = x[3 + j] + H * e_dot[j]
        out[3 + n + j] = x[3 + n + j] + H * uf_dot[j]
    out[3 + 2 * n] = K
    return out
