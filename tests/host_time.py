"""A step policy that forms time the way OMSimulator and Ecos do, for the tests (issue 24).

``t += h`` in floating point, and the last step clipped to the stop time: ``h_k = min(h, t1 - t)``
while ``t < t1``. After many steps ``t`` has drifted by rounding, so the last step is a few ulps
longer or shorter than h, or (when ``t`` lands just below ``t1``) an extra sliver of a step; a
stop time off the grid gives a last step shorter than h. Drives the master like any policy."""
from __future__ import annotations

import time

from orchestrator.api import load
from orchestrator.cosim.component import ComponentError
from orchestrator.cosim.master import Master
from orchestrator.cosim.policies import RunStats, StepPolicy
from orchestrator.cosim.runner import make_components


class AccumulatingStep(StepPolicy):
    """Communication times by ``t += h``, the last step clipped to ``t1``; records every point."""

    name = "accumulating"

    def __init__(self, h: float):
        self.h = float(h)
        self.steps: list[tuple[float, float]] = []  # (t, h) of every step taken

    def expected_rows(self, t0, t1):
        return int(round((t1 - t0) / self.h)) + 2

    def run(self, plan, t0, t1, recorder, progress=False) -> RunStats:
        comps = list(plan.components.values())
        plan.reset_sources()
        stats = RunStats()
        start = time.perf_counter()
        t = t0
        k = 0
        try:
            while t < t1:
                plan.exchange(t, initial=(k == 0))
                plan.record_into(recorder.row(t))
                h = min(self.h, t1 - t)
                for c in comps:
                    c.step(t, h)
                self.steps.append((t, h))
                t += h
                k += 1
            plan.exchange(t, initial=(k == 0))
            plan.record_into(recorder.row(t))
        except ComponentError as e:
            stats.error = str(e)
        stats.steps = k
        stats.wall_time = time.perf_counter() - start
        return stats


def run_accumulating(scenario, stop: float, mode: str = "inprocess", h: float | None = None):
    """(result, policy): the shipped ``scenario`` run to ``stop`` by :class:`AccumulatingStep`."""
    sc = load(scenario, mode=mode, stop=stop)
    policy = AccumulatingStep(h or sc.step)
    comps = make_components(sc)
    master = Master(comps, sc.connections, [], sc.record, exchange=sc.exchange, origin=str(sc.path))
    try:
        for name, comp in comps.items():
            comp.setup(sc.start, sc.stop, sc.instances[name].parameters, {})
        return master.run(sc.start, sc.stop, policy=policy), policy
    finally:
        for comp in comps.values():
            comp.terminate()
