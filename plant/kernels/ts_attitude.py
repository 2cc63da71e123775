"""Kernels of plant/ts_attitude.py (TSAttitudePlant, 004 (6)) and of the triangular product
memberships of plant/fuzzy.py (TriangularProduct.weights): same arithmetic as the reference
(per-variable triangles on the clipped premise, products, normalisation, the mean fallback
on the degenerate set), then the RK4 step of x' = sum_i h_i(x) A_i x + B u with u held."""
from __future__ import annotations

import numpy as np

from . import jit


@jit
def triangular_weights(z, b, s, rows, tol, out):
    """out = TriangularProduct.weights(z): ``rows`` (n_rules, d) int = rule_peak + 1."""
    R, d = rows.shape
    per = np.empty((d, 3))
    for j in range(d):
        x = z[j]
        bj = b[j]
        x = bj if x > bj else (-bj if x < -bj else x)
        sx = s[j] * x
        if sx >= 0.0:
            per[j, 0] = 0.0
            per[j, 1] = 1.0 - sx if sx < 1.0 else 0.0
            per[j, 2] = sx if sx < 1.0 else 1.0
        else:
            per[j, 0] = -sx if sx > -1.0 else 1.0
            per[j, 1] = 1.0 + sx if sx > -1.0 else 0.0
            per[j, 2] = 0.0
    total = 0.0
    for i in range(R):
        v = 1.0
        for j in range(d):
            v *= per[j, rows[i, j]]
        out[i] = v
        total += v
    if total >= tol:
        for i in range(R):
            out[i] = out[i] / total
        return
    m = 0.0
    for i in range(R):
        a = 0.0
        for j in range(d):
            a += per[j, rows[i, j]]
        out[i] = a / d
        m += out[i]
    for i in range(R):
        out[i] = out[i] / m if m > 0.0 else 1.0 / R


@jit
def _deriv(x, A, bu, b, s, rows, tol, h, out):
    triangular_weights(x, b, s, rows, tol, h)
    R, n, _ = A.shape
    for k in range(n):
        acc = 0.0
        for i in range(R):
            ax = 0.0
            for j in range(n):
                ax += A[i, k, j] * x[j]
            acc += h[i] * ax
        out[k] = acc + bu[k]


@jit
def advance(x0, u, h, steps, A, B, b, s, rows, tol):
    """The state after [t, t + h] with u held (reference ``TSAttitudePlant.advance`` without its guard)."""
    n = x0.size
    bu = np.zeros(n)
    for k in range(n):
        acc = 0.0
        for j in range(u.size):
            acc += B[k, j] * u[j]
        bu[k] = acc
    dt = h / steps
    half = 0.5 * dt
    sixth = dt / 6.0
    x = x0.copy()
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    w = np.empty(n)
    hw = np.empty(A.shape[0])
    for _ in range(steps):
        _deriv(x, A, bu, b, s, rows, tol, hw, k1)
        for i in range(n):
            w[i] = x[i] + half * k1[i]
        _deriv(w, A, bu, b, s, rows, tol, hw, k2)
        for i in range(n):
            w[i] = x[i] + half * k2[i]
        _deriv(w, A, bu, b, s, rows, tol, hw, k3)
        for i in range(n):
            w[i] = x[i] + dt * k3[i]
        _deriv(w, A, bu, b, s, rows, tol, hw, k4)
        for i in range(n):
            x[i] = x[i] + sixth * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i])
    return x
