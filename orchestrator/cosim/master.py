"""The co-simulation master: an exchange plan, a step policy and a recorder, put together.

* :mod:`orchestrator.cosim.plan` decides who reads and writes what at a communication point
  (ordered or Jacobi exchange, algebraic loops refused), built once;
* :mod:`orchestrator.cosim.policies` decides when to exchange and step (fixed, multirate, adaptive);
* :mod:`orchestrator.cosim.recorder` keeps the rows.

``Master(...).run(t0, t1, h)`` runs with the fixed-step policy; ``run(t0, t1,
policy=...)`` with any other (build the Master with ``watch=policy.watch``: the outputs the
policy reads besides the recorded ones). Components must be set up (instantiated and
initialised) before ``run``; on an error the rows recorded so far are returned with
``complete=False``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from orchestrator.cosim.plan import AlgebraicLoopError, ExchangePlan, feedthrough_levels  # noqa: F401 (re-exported)
from orchestrator.cosim.policies import AdaptiveStep, FixedStep, MultirateStep, time_grid  # noqa: F401 (re-exported)
from orchestrator.cosim.recorder import Recorder


@dataclass
class RunResult:
    columns: list[str]
    time: np.ndarray
    data: np.ndarray  # (rows, len(columns))
    complete: bool
    error: str | None = None
    wall_time: float = 0.0
    steps: int = 0
    exchange: str = "ordered"
    mode: str = "fmu"
    info: dict = field(default_factory=dict)
    interrupted: int = 0  # the signal number that stopped the run (0: none)

    def column(self, name: str) -> np.ndarray:
        return self.data[:, self.columns.index(name)]

    def vector(self, base: str) -> np.ndarray:
        """All columns ``base[...]`` in index order, as (rows, n); a scalar signal ``base`` as (rows, 1)."""
        cols = [i for i, c in enumerate(self.columns) if c == base or c.startswith(base + "[")]
        return self.data[:, cols]


class Master:
    """Build once from components + wiring, then ``run``."""

    def __init__(self, components: dict, connections, sources=(), record=(), exchange="ordered", origin="scenario",
                 sample="before", watch=()):
        self.plan = ExchangePlan(components, connections, sources, record, exchange, origin, sample, watch=watch)
        self.components = components
        self.columns = self.plan.columns
        self.exchange = exchange

    def run(self, t0, t1, h=None, progress=False, policy=None) -> RunResult:
        policy = policy or FixedStep(h)
        if hasattr(policy, "expected_rows"):
            expected = policy.expected_rows(t0, t1)
        else:
            expected = int(round((t1 - t0) / policy.h)) + 1 if hasattr(policy, "h") else None
        recorder = Recorder(self.columns, expected_rows=expected)
        stats = policy.run(self.plan, t0, t1, recorder, progress=progress)
        times, data = recorder.result()
        return RunResult(columns=self.columns, time=times, data=data, complete=stats.error is None,
                         error=stats.error, wall_time=stats.wall_time, steps=stats.steps, exchange=self.exchange,
                         info={"policy": policy.name, **stats.extra}, interrupted=stats.interrupted)
