"""Recording: rows of recorded values at the communication points a step policy chooses.

:class:`Recorder` grows in chunks (a variable-step or interrupted run does not know its row
count in advance, and a fixed-size array would be wasted memory for a run that stops early);
``row()`` hands out the next row to fill in place (no allocation per row), ``result()`` returns
the time vector and the data matrix of the rows filled so far.
"""
from __future__ import annotations

import numpy as np


class Recorder:
    def __init__(self, columns, chunk_rows: int = 4096, expected_rows: int | None = None):
        self.columns = list(columns)
        self._width = len(self.columns)
        self._chunk = max(16, int(min(expected_rows or chunk_rows, 1 << 20)))
        self._chunks: list[np.ndarray] = []
        self._times: list[np.ndarray] = []
        self._used = 0  # rows used in the last chunk
        self.rows = 0

    def row(self, t: float) -> np.ndarray:
        """The next row (filled with NaN) for time t; write the recorded values into it."""
        if not self._chunks or self._used == len(self._times[-1]):
            n = self._chunk if self._chunks else self._chunk
            self._chunks.append(np.full((n, self._width), np.nan))
            self._times.append(np.empty(n))
            self._used = 0
        k = self._used
        self._times[-1][k] = t
        self._used += 1
        self.rows += 1
        return self._chunks[-1][k]

    def result(self) -> tuple[np.ndarray, np.ndarray]:
        """(time (rows,), data (rows, columns)) of every row filled so far."""
        if not self._chunks:
            return np.zeros(0), np.zeros((0, self._width))
        times = [t for t in self._times[:-1]] + [self._times[-1][: self._used]]
        data = [d for d in self._chunks[:-1]] + [self._chunks[-1][: self._used]]
        if len(data) == 1:
            return times[0].copy(), data[0].copy()
        return np.concatenate(times), np.concatenate(data)
