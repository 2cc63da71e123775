"""Kernels of plant/ts_attitude.py (TSAttitudePlant, 004 (6)) and of the triangular product
memberships of plant/fuzzy.py (TriangularProduct.weights): same arithmetic as the reference
(per-variable triangles on the clipped premise, products, normalisation, the mean fallback
on the degenerate set), then the RK4 step of x' = sum_i h_i(x) A_i x + B u with u held."""
from __future__ import annotations

import numpy as np

from plant.jit import jit
from plant.kernels.common import rk4_combine, rk4_setup, rk4_stage


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
    dt, half, sixth, k1, k2, k3, k4, w = rk4_setup(h, steps, n)
    x = x0.copy()
    hw = np.empty(A.shape[0])
    for _ in range(steps):
        _deriv(x, A, bu, b, s, rows, tol, hw, k1)
        rk4_stage(w, x, half, k1)
        _deriv(w, A, bu, b, s, rows, tol, hw, k2)
        rk4_stage(w, x, half, k2)
        _deriv(w, A, bu, b, s, rows, tol, hw, k3)
        rk4_stage(w, x, dt, k3)
        _deriv(w, A, bu, b, s, rows, tol, hw, k4)
        rk4_combine(x, sixth, k1, k2, k3, k4)
    return x
