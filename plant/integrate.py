"""The fixed-step RK4 the blocks integrate with (numpy reference paths).

A block moves its state across a communication step h in ``steps`` equal internal steps
dt <= ``h_max`` (its parameter :func:`h_max_parameter`; :func:`substeps`), each a classical RK4 step (:func:`rk4_step`). The
floating-point operations are those every block wrote out before: the same order, so the
same bits.
"""
from __future__ import annotations

import math

from .block import scalar

__all__ = ["h_max_parameter", "substeps", "rk4_step"]


def h_max_parameter(default: float) -> list:
    """The parameter ``h_max`` (s, start ``default``): the largest internal RK4 step."""
    return scalar("h_max", default, "s", "largest internal RK4 step")


def substeps(h: float, h_max: float) -> tuple[int, float]:
    """(steps, dt): the fewest equal internal steps dt = h / steps <= h_max (s) over a
    communication step h (s), at least one."""
    steps = max(1, math.ceil(h / h_max - 1e-9))
    return steps, h / steps


def rk4_step(f, y, dt: float, a0=None, am=None, a1=None):
    """One classical RK4 step of y' = f(y, a) over dt (s), for a numpy array y.

    ``a0``, ``am``, ``a1``: what f needs at the start, the midpoint (stages 2 and 3) and the end
    of the step (e.g. the torque at those times); None for an f that ignores it."""
    k1 = f(y, a0)
    k2 = f(y + (0.5 * dt) * k1, am)
    k3 = f(y + (0.5 * dt) * k2, am)
    k4 = f(y + dt * k3, a1)
    return y + (dt / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
