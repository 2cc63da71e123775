"""What the sampled hardware blocks share: a sample clock and a seeded, rollback-safe noise stream.

:class:`SampleClock`: sample instants t_k = t0 + k T (formed from k, no drift). At a communication
point t the sample k is "due" when ``happened_at(t_k, t)`` (plant/timing.py): a block whose
sample instants lie on the communication grid samples exactly there, in every host. An instant
strictly inside a communication step cannot see the input there; the blocks then take the input
held over the step (zero-order hold of the input), and say so in their docstrings.

:class:`NormalStream`: standard normal draws from one PCG64 stream, in a fixed order (one call per
sample), whose state is part of the block's state as exact floats (``plant/markov.py``'s
encoding), so that a rollback or a rerun with the same seed gives the same noise bit for bit.
"""
from __future__ import annotations

import math

import numpy as np

from ..markov import PCG64_FLOATS, pcg64_state_from_floats, pcg64_state_to_floats
from ..timing import happened_at

__all__ = ["SampleClock", "NormalStream", "check_seed"]


def check_seed(x: float, who: str) -> int:
    if x != round(x) or x < 0 or not math.isfinite(x):
        raise ValueError(f"{who}: seed = {x:g} must be a non-negative integer")
    return int(round(x))


class SampleClock:
    """Sample instants t_k = t0 + k T; ``k`` is the next sample to take."""

    __slots__ = ("t0", "T", "k")

    def __init__(self, t0: float, period: float, who: str):
        if not period > 0 or not math.isfinite(period):
            raise ValueError(f"{who}: sample_period = {period:g} s must be > 0")
        self.t0, self.T, self.k = float(t0), float(period), 0

    @property
    def t_next(self) -> float:
        return self.t0 + self.k * self.T

    def due(self, t: float) -> bool:
        """Is sample k due at the communication point t?"""
        return happened_at(self.t_next, t)

    def inside(self, t: float, h: float) -> bool:
        """Is the next sample before the end of the step [t, t + h] (and not at its end point,
        which is the next communication point's)?"""
        return not happened_at(t + h, self.t_next)


class NormalStream:
    """Standard normal draws from a PCG64 stream; state as :data:`STATE_FLOATS` exact floats."""

    STATE_FLOATS = PCG64_FLOATS

    def __init__(self, seed: int):
        self._bg = np.random.PCG64(int(seed))
        self._rng = np.random.Generator(self._bg)

    def draw(self, n: int) -> np.ndarray:
        return self._rng.standard_normal(n)

    def get_state(self) -> list:
        return pcg64_state_to_floats(self._bg)

    def set_state(self, values) -> None:
        pcg64_state_from_floats(self._bg, values)
