"""Kernel of controller/fontsm.py (backstepping + FONTSM, 001 (23)-(36)): the law of
``FONTSM._compute`` for c = 0 (omega_d = 0, the scenarios' reading), the same formulas and
order of operations. The Grünwald-Letnikov past sums stay in controller/fractional.py (numpy's
BLAS dot products over the memory: faster than a loop compiled without reassociation) and come
in as ``p1``, ``p2``; c > 0 keeps the reference code.

Arrays: ``u`` the inputs [sigma (3), omega (3), e_hat (n), uf_hat (n), sigma_d (3)];
``prm`` = the named pack :data:`PARAMS` (:func:`params`): pairing (1/0), strict_start (1/0),
started (k > 0, 1/0), h, r, phi, e_min, e_max;
``g`` (10, 3) = [hp1, hp2, beta_1, beta_2, a, b, eps_1, eps_2, A_prev, B_prev]; ``J`` (3, 3),
``M`` (3, n), ``ups`` (3). Returns [u_c (n), s, z1 (as printed), z2, f1, f2, A, B, lambda_min].
"""
from __future__ import annotations

import math

import numpy as np

from plant.jit import jit, pack
from plant.kernels.common import min_eig_sym3, solve_sym3

PARAMS = ("pairing", "strict_start", "started", "h", "r", "phi", "e_min", "e_max")
PAIRING, STRICT_START, STARTED, H, R, PHI, E_MIN, E_MAX = range(len(PARAMS))


def params(**values):
    """The pack ``prm`` of :func:`law`, by name (:data:`PARAMS`)."""
    return pack(PARAMS, values)


@jit
def _sig(x, p):
    """``controller/fontsm.py: sig``."""
    if x == 0.0:
        return 0.0
    return math.copysign(abs(x) ** p, x)


@jit
def law(u, p1, p2, prm, g, J, M, ups):
    n = M.shape[1]
    out = np.empty(n + 22)
    pairing, strict, started = prm[PAIRING] == 1.0, prm[STRICT_START] == 1.0, prm[STARTED] == 1.0
    h, r, phi, e_min, e_max = prm[H], prm[R], prm[PHI], prm[E_MIN], prm[E_MAX]
    z1p = np.empty(3)
    for i in range(3):
        z1p[i] = u[i] - u[6 + 2 * n + i]  # 001 (23)
    z1 = np.empty(3)
    if pairing:
        z1[0], z1[1], z1[2] = z1p[2], z1p[1], z1p[0]
    else:
        z1[:] = z1p
    w1, w2, w3 = u[3], u[4], u[5]
    z2 = np.empty(3)
    for i in range(3):
        z2[i] = u[3 + i] - 0.0  # omega_d = 0 (c = 0), 001 (23)
    f1, f2, A, B, s, ucm = np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    for i in range(3):
        f1[i] = _sig(z1[i], g[2, i])
        f2[i] = _sig(z1[i], g[3, i])
        A[i] = g[0, i] * (f1[i] + p1[i])  # GL D^alpha_1 f1
        B[i] = g[1, i] * (f2[i] + p2[i])  # GL I^(1 - alpha_2) f2
    for i in range(3):
        if started:
            dA = (A[i] - g[8, i]) / h  # D^(alpha_1 + 1) f1, 001 (22)
            dB = (B[i] - g[9, i]) / h
        elif strict:
            dA, dB = A[i] / h, B[i] / h
        else:
            dA = dB = 0.0
        s[i] = z2[i] + g[4, i] * A[i] + g[5, i] * B[i]  # 001 (30)
        if phi > 0:
            sw = max(-1.0, min(1.0, s[i] / phi))
        else:
            sw = float((s[i] > 0) - (s[i] < 0))
        srt = _sig(s[i], r)
        ucm[i] = -g[4, i] * dA - g[5, i] * dB - g[6, i] * sw - g[7, i] * srt + 0.0  # 001 (35), omega_d' = 0
    h1 = J[0, 0] * w1 + J[0, 1] * w2 + J[0, 2] * w3
    h2 = J[1, 0] * w1 + J[1, 1] * w2 + J[1, 2] * w3
    h3 = J[2, 0] * w1 + J[2, 1] * w2 + J[2, 2] * w3
    gyro = (w2 * h3 - w3 * h2, w3 * h1 - w1 * h3, w1 * h2 - w2 * h1)
    v = np.empty(3)
    for i in range(3):
        muf = 0.0
        for j in range(n):
            muf += M[i, j] * u[6 + n + j]
        rest = gyro[i] - muf - ups[i]
        v[i] = rest + J[i, 0] * ucm[0] + J[i, 1] * ucm[1] + J[i, 2] * ucm[2]  # 001 (34)
    e = np.empty(n)
    for j in range(n):
        e[j] = min(max(u[6 + j], e_min), e_max)
    Q = np.zeros((3, 3))
    for i in range(3):
        for k in range(3):
            acc = 0.0
            for j in range(n):
                acc += M[i, j] * e[j] ** 3 * M[k, j]
            Q[i, k] = acc  # M E_hat^3 M^T
    q11, q12, q13, q22, q23, q33 = Q[0, 0], Q[0, 1], Q[0, 2], Q[1, 1], Q[1, 2], Q[2, 2]
    lam = min_eig_sym3(q11, q12, q13, q22, q23, q33)
    y1, y2, y3 = solve_sym3(q11, q12, q13, q22, q23, q33, v[0], v[1], v[2])
    for j in range(n):
        out[j] = e[j] ** 2 * (M[0, j] * y1 + M[1, j] * y2 + M[2, j] * y3)  # 001 (33)
    for i in range(3):
        out[n + i] = s[i]
        out[n + 3 + i] = z1p[i]
        out[n + 6 + i] = z2[i]
        out[n + 9 + i] = f1[i]
        out[n + 12 + i] = f2[i]
        out[n + 15 + i] = A[i]
        out[n + 18 + i] = B[i]
    out[n + 21] = lam
    return out
