"""Kernels of estimator/fafeo.py (FAFEO, 000 (16)-(17) in the PI form (22)): the RK4 step with
the projections and the outputs. Same formulas as the reference ``FAFEO.advance`` and
``FAFEO.outputs_at`` (after priming, which the block does itself).

Arrays: ``Mr`` (8, rows, m) and ``Cr`` (8, rows, 3) are the per-rule affine maps of
``FAFEO.initialize`` (rows = m + 3 + 2n: z', unclipped f_hat, unprojected d2_hat); ``B`` (3, 3);
``prm``: the named pack :data:`PARAMS` (:func:`params`).
"""
from __future__ import annotations

import numpy as np

from plant.jit import jit, pack
from plant.kernels.common import memberships8, rk4_combine, rk4_setup, rk4_stage

PARAMS = ("omega_box", "f_min", "f_max", "d_max", "hold_innovation")  # rad/s, N.m, N.m, -, 1/0
OMEGA_BOX, F_MIN, F_MAX, D_MAX, HOLD_INNOVATION = range(len(PARAMS))


def params(**values):
    """The pack ``prm`` of :func:`advance` and :func:`outputs`, by name (:data:`PARAMS`)."""
    return pack(PARAMS, values)


@jit
def _deriv(z, M, c, B, m, f_min, f_max, out, r, f):
    """out = z' (reference ``deriv`` inside ``FAFEO.advance``); r is scratch of size rows."""
    rows = M.shape[0]
    for i in range(rows):
        s = 0.0
        for j in range(m):
            s += M[i, j] * z[j]
        r[i] = s + c[i]
    for i in range(m):
        out[i] = r[i]
    lo_hit = False
    hi_hit = False
    for i in range(3):
        if r[m + i] < f_min:
            lo_hit = True
        if r[m + i] > f_max:
            hi_hit = True
    if lo_hit or hi_hit:
        # Proj of 000 (17): clipped f_hat in x_hat', conditional integration of zeta_f
        for i in range(3):
            f[i] = min(max(r[m + i], f_min), f_max) - r[m + i]
        for i in range(3):
            out[i] += B[i, 0] * f[0] + B[i, 1] * f[1] + B[i, 2] * f[2]
        for i in range(3):
            fu = r[m + i]
            dz = out[3 + i]
            if (fu > f_max and dz > 0.0) or (fu < f_min and dz < 0.0):
                out[3 + i] = 0.0


@jit
def advance(x, y, u, h, steps, Mr, Cr, B, prm):
    """The observer state after [t, t + h] with the inputs held (reference ``FAFEO.advance``)."""
    box, f_min, f_max, d_max = prm[OMEGA_BOX], prm[F_MIN], prm[F_MAX], prm[D_MAX]
    hold = prm[HOLD_INNOVATION] != 0.0
    R, rows, m = Mr.shape
    b = memberships8(y[0], y[1], y[2], box)
    M = np.zeros((rows, m))
    C = np.zeros((rows, 3))
    for k in range(R):
        bk = b[k]
        for i in range(rows):
            for j in range(m):
                M[i, j] += bk * Mr[k, i, j]
            for j in range(3):
                C[i, j] += bk * Cr[k, i, j]
    c = np.empty(rows)
    if hold:  # e_y = y - x_hat sampled at t and held: y replaced by x_hat(tau) + e_y(t)
        e0, e1, e2 = y[0] - x[0], y[1] - x[1], y[2] - x[2]
        for i in range(rows):
            for j in range(3):
                M[i, j] += C[i, j]
            c[i] = C[i, 0] * e0 + C[i, 1] * e1 + C[i, 2] * e2
    else:
        for i in range(rows):
            c[i] = C[i, 0] * y[0] + C[i, 1] * y[1] + C[i, 2] * y[2]
    for i in range(3):
        c[i] += B[i, 0] * u[3] + B[i, 1] * u[4] + B[i, 2] * u[5]  # B Gamma u, Gamma = I
    dt, half, sixth, k1, k2, k3, k4, w = rk4_setup(h, steps, m)
    z = x.copy()
    r = np.empty(rows)
    f = np.empty(3)
    nd = rows - m - 3
    d2u = np.empty(nd)
    for _ in range(steps):
        _deriv(z, M, c, B, m, f_min, f_max, k1, r, f)
        rk4_stage(w, z, half, k1)
        _deriv(w, M, c, B, m, f_min, f_max, k2, r, f)
        rk4_stage(w, z, half, k2)
        _deriv(w, M, c, B, m, f_min, f_max, k3, r, f)
        rk4_stage(w, z, dt, k3)
        _deriv(w, M, c, B, m, f_min, f_max, k4, r, f)
        rk4_combine(z, sixth, k1, k2, k3, k4)
        # ||d2_hat||_1 <= d_max (000 (17)): project the estimator state back onto the ball
        n1 = 0.0
        for i in range(nd):
            s = 0.0
            for j in range(m):
                s += M[m + 3 + i, j] * z[j]
            d2u[i] = s + c[m + 3 + i]
            n1 += abs(d2u[i])
        if n1 > d_max:
            k = d_max / n1 - 1.0
            for i in range(nd):
                z[6 + i] += d2u[i] * k
    return z


@jit
def outputs(x, u, Lout, Pout, prm):
    """[omega_hat, f_hat, d2_hat] of a primed observer (reference ``FAFEO.outputs_at``)."""
    f_min, f_max, d_max = prm[F_MIN], prm[F_MAX], prm[D_MAX]
    rows, m = Lout.shape
    out = np.empty(3 + rows)
    r = np.empty(rows)
    for i in range(rows):
        s = 0.0
        for j in range(m):
            s += Lout[i, j] * x[j]
        r[i] = s + (Pout[i, 0] * u[0] + Pout[i, 1] * u[1] + Pout[i, 2] * u[2])
    out[0], out[1], out[2] = x[0], x[1], x[2]
    for i in range(3):
        out[3 + i] = min(max(r[i], f_min), f_max)  # Proj of 000 (17)
    n1 = 0.0
    for i in range(3, rows):
        n1 += abs(r[i])
    k = d_max / n1 if n1 > d_max else 1.0
    for i in range(3, rows):
        out[3 + i] = r[i] * k if n1 > d_max else r[i]
    return out
