"""Signal generator blocks: a scenario's reference signals as a component of their own.

``PiecewiseConstantSource`` is the block behind the ``PiecewiseConstantSource`` FMU that
``ftcsim export-ssp`` puts into an SSP package for every ``[sources.NAME]`` of a scenario:
SSP 1.0 has no signal generators, and an FMU keeps the package self-contained, so any SSP
tool (libcosim, OMSimulator, ...) runs the same reference signals as our master.

Semantics are those of ``orchestrator.cosim.sources.PiecewiseConstant``: segment k holds
``values[k, :]`` from ``times[k]`` (inclusive) until ``times[k+1]`` (exclusive); before
``times[1]`` the first segment holds. The segment at t is found with the same relative
tolerance of 1e-12 on t, so that a switch time that falls on a communication point is
taken at that point in both.

Fixed capacity (an FMU's interface is fixed when it is built): up to ``MAX_SEGMENTS``
segments and ``MAX_WIDTH`` outputs. Wider sources use several instances (the exporter
splits the columns); ``n_segments`` says how many of the ``times`` are used.

Inputs:  none
Outputs: y[1..MAX_WIDTH] (unit "1": the exporter connects them to the targets as they are)
Parameters: n_segments, times[1..MAX_SEGMENTS] (s), values[k,i] (k segment, i output)
"""
from __future__ import annotations

import bisect

import numpy as np

from .block import StatelessBlock, Variable, scalar, vector

MAX_SEGMENTS = 16
MAX_WIDTH = 8


class PiecewiseConstantSource(StatelessBlock):
    model_name = "PiecewiseConstantSource"
    description = "Piecewise-constant signal source (scenario sources as an FMU)"

    def __init__(self):
        params = (
            scalar("n_segments", 1, "1", "number of segments in use (1..16)")
            + vector("times", MAX_SEGMENTS, "s", "start time of each segment (strictly increasing)",
                     [float(k) for k in range(MAX_SEGMENTS)])
            + [Variable(f"values[{k + 1},{i + 1}]", "1", "value of output i in segment k")
               for k in range(MAX_SEGMENTS) for i in range(MAX_WIDTH)]
        )
        super().__init__([], vector("y", MAX_WIDTH, "1", "source output"), params, {})
        self._times = [0.0]
        self._values = np.zeros((1, MAX_WIDTH))

    def initialize(self, t0: float) -> None:
        n = int(round(self.p("n_segments")))
        if not 1 <= n <= MAX_SEGMENTS:
            raise ValueError(f"{self.model_name}: n_segments = {n} outside 1..{MAX_SEGMENTS}")
        times = self.p_vector("times")[:n].tolist()
        if any(b <= a for a, b in zip(times, times[1:])):
            raise ValueError(f"{self.model_name}: times must be strictly increasing, got {times}")
        self._times = times
        self._values = self.p_matrix("values")[:n].copy()

    def segment(self, t: float) -> int:
        return max(0, bisect.bisect_right(self._times, t + 1e-12 * max(1.0, abs(t))) - 1)

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        return self._values[self.segment(t)].copy()

