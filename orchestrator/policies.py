"""Step policies: when the master exchanges, steps and records.

A policy drives one run over an :class:`orchestrator.plan.ExchangePlan`: it chooses the
communication points, calls ``plan.exchange(t)``, steps every component, records rows into an
:class:`orchestrator.recorder.Recorder`, and stops early on a component error or a stop request
(``orchestrator/interrupt.py``). New policies (multirate, variable step) implement
:meth:`StepPolicy.run` and reuse the plan and the recorder as they are.

:class:`FixedStep`: one common step h for everyone, communication times on an integer
nanosecond grid (:func:`time_grid`), exactly libcosim's.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np


def time_grid(t0: float, h: float, n: int) -> np.ndarray:
    """Communication points t_0..t_n. When t0 and h are whole nanoseconds (every
    scenario we have), t_k = (t0_ns + k h_ns) / 1e9 from integer nanoseconds: the
    correctly rounded value of t0 + k h, and exactly the doubles libcosim passes to
    fmi2DoStep (it keeps time as int64 ns and steps with h_k = t_{k+1} - t_k). The run
    passes h_k = t_{k+1} - t_k too, so an FMU that adds t_k + h_k lands on t_{k+1}
    exactly. Otherwise t0 + k h in floating point."""
    t0_ns, h_ns = round(t0 * 1e9), round(h * 1e9)
    if h_ns > 0 and abs(h * 1e9 - h_ns) < 1e-6 and abs(t0 * 1e9 - t0_ns) < 1e-6 and abs(t0_ns) + n * h_ns < 2**53:
        return (t0_ns + h_ns * np.arange(n + 1, dtype=np.int64)) / 1e9
    return t0 + h * np.arange(n + 1)


@dataclass
class RunStats:
    """What a policy reports about its run (also written into metrics.json)."""

    steps: int = 0
    wall_time: float = 0.0
    error: str | None = None
    interrupted: int = 0
    extra: dict = field(default_factory=dict)


class StepPolicy:
    name = "base"

    def run(self, plan, t0: float, t1: float, recorder, progress=False) -> RunStats:  # pragma: no cover
        raise NotImplementedError


class FixedStep(StepPolicy):
    """One common communication step ``h`` (s) for every component."""

    name = "fixed"

    def __init__(self, h: float):
        self.h = float(h)

    def run(self, plan, t0, t1, recorder, progress=False) -> RunStats:
        from .components import ComponentError
        from .interrupt import REQUEST

        n = int(round((t1 - t0) / self.h))
        times = time_grid(t0, self.h, n)
        tlist = times.tolist()  # Python floats: numpy scalars are slow in block arithmetic
        hlist = np.diff(times).tolist()  # h_k = t_{k+1} - t_k, so that t_k + h_k == t_{k+1}
        plan.reset_sources()
        comps = list(plan.components.values())
        bar = _progress_bar(n) if progress else None
        stats = RunStats()
        done = 0
        t_wall = time.perf_counter()
        try:
            for k in range(n):
                t = tlist[k]
                plan.exchange(t, initial=(k == 0))
                plan.record_into(recorder.row(t))
                if REQUEST:
                    stats.error, stats.interrupted = f"interrupted by {REQUEST.name} at t = {t:.6g} s", REQUEST.signum
                    break
                for c in comps:
                    c.step(t, hlist[k])
                stats.steps = k + 1
                if bar is not None and not k & 1023:
                    bar.update(k - done)
                    done = k
            else:
                plan.exchange(tlist[n], initial=(n == 0))
                plan.record_into(recorder.row(tlist[n]))
        except ComponentError as e:
            stats.error = str(e)
        finally:
            if bar is not None:
                bar.close()
        stats.wall_time = time.perf_counter() - t_wall
        return stats


def _progress_bar(n):
    from tqdm import tqdm

    return tqdm(total=n, delay=2.0, unit="step", leave=False, mininterval=0.5)
