"""The arena's own fault detector: a threshold on an estimator's output with a persistence window,
calibrated on the fault-free draws (numpy only). A small, replaceable piece: the decision layer of
``diagnosis/`` (CUSUM, GLR, chi-square windows) will supersede it; until then the arena's detection
figures come from a detector that is at least calibrated.

Statistic: s(t) = ||estimate(t) - nominal|| from the estimator's start-up time ``t_from`` on.
Alarm: s stays above the threshold h over a whole window of ``persistence`` seconds; the alarm time
is the end of the first such window (:func:`first_alarm`). The largest h a run's statistic exceeds
for a whole window is its persisted peak (:func:`persisted_peak`): h raises an alarm in the run iff
h < that peak.

Calibration (:func:`calibrate`), per cell and hardware, from the persisted peaks m_1..m_n of its n
fault-free runs, each monitored for T seconds, for a target of ``rate`` false alarms per hour:
the per-run false-alarm probability of that rate is a = 1 - exp(-rate T / 3600) (alarms as a
Poisson process); the threshold is h = (1 + margin) m_(k), m_(k) the k-th smallest peak with
k = ceil((n + 1)(1 - a)): a new fault-free run exceeds m_(k) with probability at most a when the runs
are exchangeable (the conformal quantile). With fewer runs than that needs (k > n, n + 1 < 1 / a) the
largest peak is taken and ``extrapolated`` says so: the guarantee then rests on the margin alone.

False alarms are counted on the fault-free runs, each with the threshold calibrated on the *other*
fault-free runs (leave-one-out: out of sample, so a count that could not fail is never reported as
a result); a single fault-free run (deterministic: ideal hardware) is calibrated and counted on
itself, which cannot fail: ``in_sample``.
"""
from __future__ import annotations

import math

import numpy as np


def _window(t, persistence: float) -> int:
    """Samples spanning ``persistence`` seconds (at least 1)."""
    if len(t) < 2 or persistence <= 0:
        return 1
    dt = float(np.median(np.diff(t)))
    return max(1, int(math.ceil(persistence / dt - 1e-9)) + 1)


def _running_min(x, w: int) -> np.ndarray:
    """min of x over the w samples ending at each index (first w - 1 indices: -inf)."""
    if w <= 1:
        return x.copy()
    if x.size < w:
        return np.full(x.size, -np.inf)
    from numpy.lib.stride_tricks import sliding_window_view

    out = np.full(x.size, -np.inf)
    out[w - 1:] = sliding_window_view(x, w).min(axis=1)
    return out


def persisted_levels(t, s, persistence: float, t_from: float = 0.0) -> np.ndarray:
    """At each sample, the largest level s has stayed above over the last ``persistence`` s, counting
    samples at or after ``t_from`` only (-inf before a whole window has passed; NaN counts as inf:
    a non-finite estimate is an alarm)."""
    t = np.asarray(t, float)
    s = np.where(np.isfinite(s), np.asarray(s, float), np.inf)
    s = np.where(t >= t_from, s, -np.inf)
    return _running_min(s, _window(t, persistence))


def persisted_peak(t, s, persistence: float, t_from: float = 0.0) -> float:
    """The largest threshold the statistic exceeds for a whole window after ``t_from``
    (-inf if the run is shorter than a window)."""
    lv = persisted_levels(t, s, persistence, t_from)
    return float(lv.max()) if lv.size else -math.inf


def first_alarm(t, s, h: float, persistence: float, t_from: float = 0.0):
    """Time (s) of the first alarm with threshold ``h`` at or after ``t_from`` (the window counted
    from there), or None."""
    lv = persisted_levels(t, s, persistence, t_from)
    k = np.nonzero(lv > h)[0]
    return float(np.asarray(t, float)[k[0]]) if k.size else None


def per_run_probability(rate_per_hour: float, seconds: float) -> float:
    """False-alarm probability per run of ``seconds`` for a Poisson rate (per hour)."""
    return -math.expm1(-rate_per_hour * seconds / 3600.0)


def rate_per_hour(p: float, seconds: float) -> float:
    """The Poisson rate (per hour) whose per-run probability over ``seconds`` is ``p``."""
    if p >= 1.0:
        return math.inf
    return -math.log1p(-p) * 3600.0 / seconds


def calibrate(peaks, seconds: float, rate: float, margin: float) -> dict:
    """Threshold from fault-free persisted peaks (module docstring): ``threshold``, ``quantile`` (the
    order statistic used), ``k``, ``n``, ``per_run`` (a), ``extrapolated``."""
    m = np.sort(np.asarray([p for p in peaks if np.isfinite(p) or p == math.inf], dtype=float))
    n = m.size
    a = per_run_probability(rate, seconds)
    if n == 0:
        return {"threshold": None, "quantile": None, "k": None, "n": 0, "per_run": a, "extrapolated": True}
    k = math.ceil((n + 1) * (1.0 - a))
    extrapolated = k > n
    q = float(m[min(k, n) - 1])
    return {"threshold": max(q, 0.0) * (1.0 + margin), "quantile": q, "k": min(k, n), "n": n, "per_run": a,
            "extrapolated": extrapolated}


def leave_one_out_alarms(peaks, seconds: float, rate: float, margin: float) -> list:
    """For each fault-free run, whether it alarms with the threshold calibrated on the others
    (a list of bools); one run: calibrated on itself (in sample, cannot alarm)."""
    peaks = list(peaks)
    if len(peaks) <= 1:
        return [False] * len(peaks)
    out = []
    for i, p in enumerate(peaks):
        h = calibrate(peaks[:i] + peaks[i + 1:], seconds, rate, margin)["threshold"]
        out.append(bool(h is not None and p > h))
    return out
