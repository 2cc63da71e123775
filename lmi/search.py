"""One-dimensional searches over a design scalar (kappa of 002, the decay rate of 003, ...).

``grid_then_golden``: evaluate ``f`` on a grid (ascending, positive), then refine the best
interior point by golden-section search in log space between its neighbours. Every value
tried is returned, so a design can record its whole search.
"""
from __future__ import annotations

import math

import numpy as np

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def golden_section_log(f, lo: float, hi: float, iterations: int):
    """Minimise ``f`` over [lo, hi] (lo > 0) by golden-section search on log(x).
    Returns (x_best, f_best, [(x, f(x)), ...])."""
    a, b = math.log(lo), math.log(hi)
    c, d = b - GOLDEN * (b - a), a + GOLDEN * (b - a)
    fc, fd = f(math.exp(c)), f(math.exp(d))
    seen = [(math.exp(c), fc), (math.exp(d), fd)]
    for _ in range(iterations):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - GOLDEN * (b - a)
            fc = f(math.exp(c))
            seen.append((math.exp(c), fc))
        else:
            a, c, fc = c, d, fd
            d = a + GOLDEN * (b - a)
            fd = f(math.exp(d))
            seen.append((math.exp(d), fd))
    x, fx = min(seen, key=lambda p: p[1])
    return x, fx, seen


def grid_then_golden(f, grid, iterations: int = 8):
    """Minimise ``f`` (may return ``inf`` where infeasible) over the positive ``grid``, refined
    by :func:`golden_section_log` between the neighbours of the best interior grid point.
    Returns (x_best, f_best, [(x, f(x)), ...]); ``f_best`` is ``inf`` if nothing was finite."""
    grid = [float(x) for x in grid]
    vals = [f(x) for x in grid]
    seen = list(zip(grid, vals))
    i = int(np.argmin(vals))
    best = (grid[i], vals[i])
    if math.isfinite(vals[i]) and 0 < i < len(grid) - 1 and iterations:
        x, fx, more = golden_section_log(f, grid[i - 1], grid[i + 1], iterations)
        seen += more
        if fx < best[1]:
            best = (x, fx)
    return best[0], best[1], seen
