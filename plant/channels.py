"""Declarations of N actuator / sensor channels that connect to the papers' blocks as they are named."""
from __future__ import annotations

import numpy as np

from .block import scalar, vector

__all__ = ["channels"]


def channels(base: str, n: int, unit: str, description: str, start=None) -> list:
    """``base`` (a scalar) for one channel, ``base[1..n]`` otherwise: a one-channel (pitch-axis)
    instance connects to the scalar ``u``, ``theta``, ``theta_dot`` of 002/003's blocks, a 3- or
    4-channel one element-wise to the vectors of 000/001/004's."""
    if n == 1:
        return scalar(base, 0.0 if start is None else float(np.ravel(start)[0]), unit, description)
    return vector(base, n, unit, description, start)
