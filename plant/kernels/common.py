"""Scalar helpers shared by the kernels (compiled with them; see plant/jit.py).

Each one is the kernel form of a reference function and follows its order of operations:

* ``window``, ``active``, ``contains``, ``happened`` -- ``plant/timing.py`` (``step_bounds``,
  ``event_active``, ``event_inside``, ``happened_at``): the one-sided event rule, the reference
  functions themselves, compiled;
* :func:`fault_in_step`, :func:`fault_at` -- ``plant/actuator.py: li2023_fault`` inside a
  step / at a communication point (000 (66)), around ``li2023_fault_values`` compiled;
* ``disturbance`` -- ``plant/actuator.py: li2023_disturbance`` (000 section 5), and
  ``solve_sym3``, ``min_eig_sym3`` -- ``plant/linalg3.py``: the reference functions themselves,
  compiled with :func:`~plant.kernels.jit`;
* :func:`saturate3` -- ``plant/actuator.py: saturate`` for a 3-vector;
* :func:`memberships8` -- ``plant/ts_fuzzy.py: memberships`` (000 (10), 8 corner rules);
* :func:`matvec` -- ``M @ x``, summed in index order;
* :func:`rk4_setup`, :func:`rk4_stage`, :func:`rk4_combine` -- the pieces of the classical RK4
  step the kernels share (same order of operations as the references' loops);
* :func:`rk4_affine` -- fixed-step RK4 of z' = G z + g (``estimator/tsfdo.py``).
"""
from __future__ import annotations

import numpy as np

from plant import actuator, linalg3, timing
from plant.jit import jit

# the reference functions themselves, compiled (plain float arithmetic, written once; the cache
# stamp of plant/jit.py covers their files)
window = jit(timing.step_bounds)  # (t, h) -> (lo, hi)
active = jit(timing.event_active)  # (T, tau, lo, hi)
contains = jit(timing.event_inside)  # (T, lo, hi)
happened = jit(timing.happened_at)  # (T, t)
_fault_values = jit(actuator.li2023_fault_values)  # (t, scale, onset, after_60, after_30) -> (f1, f2)
disturbance = jit(actuator.li2023_disturbance)  # (t, scale) -> (d1, d2, d3), N.m
solve_sym3 = jit(linalg3.solve_sym3)
min_eig_sym3 = jit(linalg3.min_eig_sym3)


@jit
def fault_in_step(t, scale, onset, lo, hi):
    """li2023_fault(t, scale, onset, window) -> (f1, f2) (f3 = 0), 000 (66)."""
    if scale == 0.0 or not active(onset, t, lo, hi):
        return 0.0, 0.0
    after_60 = active(onset + 60.0, t, lo, hi)
    return _fault_values(t, scale, onset, after_60, not after_60 and active(onset + 30.0, t, lo, hi))


@jit
def fault_at(t, scale, onset):
    """li2023_fault(t, scale, onset) at a communication point -> (f1, f2) (f3 = 0)."""
    if scale == 0.0 or not happened(onset, t):
        return 0.0, 0.0
    after_60 = happened(onset + 60.0, t)
    return _fault_values(t, scale, onset, after_60, not after_60 and happened(onset + 30.0, t))


@jit
def saturate3(u0, u1, u2, u_max, mode):
    """saturate(u, u_max, mode) for a 3-vector: per axis (mode 0) or onto the 1-norm ball (1)."""
    if mode == 1:
        n1 = abs(u0) + abs(u1) + abs(u2)
        if n1 > u_max:
            k = u_max / n1
            return u0 * k, u1 * k, u2 * k
        return u0, u1, u2
    return min(max(u0, -u_max), u_max), min(max(u1, -u_max), u_max), min(max(u2, -u_max), u_max)


@jit
def memberships8(w0, w1, w2, box):
    """The 8 normalised firing strengths of plant/ts_fuzzy.py (first axis slowest)."""
    p0 = min(max((w0 + box) / (2.0 * box), 0.0), 1.0)
    p1 = min(max((w1 + box) / (2.0 * box), 0.0), 1.0)
    p2 = min(max((w2 + box) / (2.0 * box), 0.0), 1.0)
    a = (p0, 1.0 - p0)
    b = (p1, 1.0 - p1)
    c = (p2, 1.0 - p2)
    out = np.empty(8)
    k = 0
    for i in range(2):
        for j in range(2):
            for m in range(2):
                out[k] = a[i] * b[j] * c[m]
                k += 1
    return out


@jit
def matvec(M, x, out):
    """out = M @ x (summed in index order)."""
    for i in range(M.shape[0]):
        s = 0.0
        for j in range(M.shape[1]):
            s += M[i, j] * x[j]
        out[i] = s
    return out


@jit
def rk4_setup(h, steps, n):
    """(dt, dt / 2, dt / 6) of ``steps`` RK4 steps over h, and scratch of size n for the four
    slopes and a stage point: (dt, half, sixth, k1, k2, k3, k4, w)."""
    dt = h / steps
    return dt, 0.5 * dt, dt / 6.0, np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)


@jit
def rk4_stage(w, x, c, k):
    """w = x + c k (an RK4 stage point, c = dt / 2 or dt)."""
    for i in range(x.size):
        w[i] = x[i] + c * k[i]


@jit
def rk4_combine(x, sixth, k1, k2, k3, k4):
    """x = x + dt / 6 (k1 + 2 (k2 + k3) + k4), in place."""
    for i in range(x.size):
        x[i] = x[i] + sixth * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i])


@jit
def _affine_slope(G, x, g, k):
    """k = G x + g."""
    matvec(G, x, k)
    for i in range(k.size):
        k[i] += g[i]


@jit
def rk4_affine(G, g, z0, h, steps):
    """``steps`` classical RK4 steps of z' = G z + g (G, g constant) over h: the reference loop
    of ``estimator/tsfdo.py: TSFDO.advance``, same order of operations."""
    dt, half, sixth, k1, k2, k3, k4, w = rk4_setup(h, steps, z0.size)
    z = z0.copy()
    for _ in range(steps):
        _affine_slope(G, z, g, k1)
        rk4_stage(w, z, half, k1)
        _affine_slope(G, w, g, k2)
        rk4_stage(w, z, half, k2)
        _affine_slope(G, w, g, k3)
        rk4_stage(w, z, dt, k3)
        _affine_slope(G, w, g, k4)
        rk4_combine(z, sixth, k1, k2, k3, k4)
    return z
