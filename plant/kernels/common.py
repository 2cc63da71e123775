"""Scalar helpers shared by the kernels (compiled with them; see plant/kernels/__init__.py).

Each one is the kernel form of a reference function and follows its order of operations:

* :func:`window`, :func:`active`, :func:`happened` -- ``plant/timing.py`` (``StepWindow``,
  ``StepWindow.active``, ``happened_at``): the one-sided event rule, same tolerances;
* :func:`fault_in_step`, :func:`fault_at` -- ``plant/actuator.py: li2023_fault`` inside a
  step / at a communication point (000 (66));
* ``disturbance`` -- ``plant/actuator.py: li2023_disturbance`` (000 section 5), and
  ``solve_sym3``, ``min_eig_sym3`` -- ``plant/linalg3.py``: the reference functions themselves,
  compiled with :func:`~plant.kernels.jit`;
* :func:`saturate3` -- ``plant/actuator.py: saturate`` for a 3-vector;
* :func:`memberships8` -- ``plant/ts_fuzzy.py: memberships`` (000 (10), 8 corner rules);
* :func:`matvec` -- ``M @ x``, summed in index order;
* :func:`rk4_affine` -- fixed-step RK4 of z' = G z + g (``estimator/tsfdo.py``).
"""
from __future__ import annotations

import math

import numpy as np

from plant import actuator, linalg3
from plant.timing import POINT_TOL, STEP_TOL

from . import jit

_STEP_TOL, _POINT_TOL = STEP_TOL, POINT_TOL


@jit
def window(t, h):
    """(lo, hi) of ``StepWindow(t, h)``."""
    tol = _STEP_TOL * h
    return t + tol, t + h - tol


@jit
def active(T, tau, lo, hi):
    """``StepWindow.active(T, tau)`` for the window (lo, hi)."""
    if T <= lo:
        return True
    if T >= hi:
        return False
    return tau >= T


@jit
def contains(T, lo, hi):
    """``StepWindow.contains(T)``."""
    return lo < T and T < hi


@jit
def happened(T, t):
    """``happened_at(T, t)``."""
    return T <= t + _POINT_TOL * max(1.0, abs(t))


@jit
def _fault_values(t, scale, onset, s60, s30):
    tau = max(t - onset, 0.0)
    f1 = 0.5 * tau**0.2 * math.sin(0.2 * tau)
    if s60:
        f2 = 1.5
    elif s30:
        f2 = 0.0
    else:
        f2 = 1.0
    return scale * f1, scale * f2


@jit
def fault_in_step(t, scale, onset, lo, hi):
    """li2023_fault(t, scale, onset, window) -> (f1, f2) (f3 = 0), 000 (66)."""
    if scale == 0.0 or not active(onset, t, lo, hi):
        return 0.0, 0.0
    return _fault_values(t, scale, onset, active(onset + 60.0, t, lo, hi), active(onset + 30.0, t, lo, hi))


@jit
def fault_at(t, scale, onset):
    """li2023_fault(t, scale, onset) at a communication point -> (f1, f2) (f3 = 0)."""
    if scale == 0.0 or not happened(onset, t):
        return 0.0, 0.0
    return _fault_values(t, scale, onset, happened(onset + 60.0, t), happened(onset + 30.0, t))


# the reference functions themselves, compiled (plain float arithmetic, written once; the cache
# stamp of plant/kernels/__init__.py covers their files)
disturbance = jit(actuator.li2023_disturbance)  # (t, scale) -> (d1, d2, d3), N.m
solve_sym3 = jit(linalg3.solve_sym3)
min_eig_sym3 = jit(linalg3.min_eig_sym3)


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
def rk4_affine(G, g, z0, h, steps):
    """``steps`` classical RK4 steps of z' = G z + g (G, g constant) over h: the reference loop
    of ``estimator/tsfdo.py: TSFDO.advance``, same order of operations."""
    n = z0.size
    dt = h / steps
    half = 0.5 * dt
    sixth = dt / 6.0
    z = z0.copy()
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    w = np.empty(n)
    for _ in range(steps):
        matvec(G, z, k1)
        for i in range(n):
            k1[i] += g[i]
            w[i] = z[i] + half * k1[i]
        matvec(G, w, k2)
        for i in range(n):
            k2[i] += g[i]
            w[i] = z[i] + half * k2[i]
        matvec(G, w, k3)
        for i in range(n):
            k3[i] += g[i]
            w[i] = z[i] + dt * k3[i]
        matvec(G, w, k4)
        for i in range(n):
            k4[i] += g[i]
            z[i] = z[i] + sixth * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i])
    return z
