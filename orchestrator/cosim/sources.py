"""Signal sources that feed component inputs from the scenario.

``PiecewiseConstant``: values[k] holds from times[k] (inclusive) until times[k+1]
(exclusive), e.g. 000 Table 1's desired attitudes. ``Constant`` is the one-segment case.
"""
from __future__ import annotations

import bisect

import numpy as np


class PiecewiseConstant:
    def __init__(self, name: str, times, values, targets):
        self.name = name
        self.times = [float(t) for t in times]
        self.values = np.atleast_2d(np.asarray(values, dtype=float))
        self.targets = list(targets)  # [(instance, variable)], one per column
        self._segment = None

    @property
    def width(self) -> int:
        return self.values.shape[1]

    def segment(self, t: float) -> int:
        """Index of the segment in force at t (the first one before times[0])."""
        return max(0, bisect.bisect_right(self.times, t + 1e-12 * max(1.0, abs(t))) - 1)

    def update(self, t: float, out: np.ndarray) -> bool:
        """Write the value at t into ``out``; True if it changed since the last call."""
        k = self.segment(t)
        if k == self._segment:
            return False
        self._segment = k
        out[:] = self.values[k]
        return True

    def reset(self):
        self._segment = None

    def value(self, t: float) -> np.ndarray:
        return self.values[self.segment(t)]
