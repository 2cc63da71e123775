"""The sample clock the diagnosis blocks share (``plant/hardware/sampling.py``) and their announced instant."""
from __future__ import annotations

from plant.hardware.sampling import SampleClock

__all__ = ["SampleClock", "next_sample"]


def next_sample(clock: SampleClock, t: float) -> float:
    """The announced next sample instant after the communication point t (a sample due at t is taken
    in the step from t)."""
    return clock.t_next + clock.T if clock.due(t) else clock.t_next
