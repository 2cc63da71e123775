"""Offline replay of a detector over recorded inputs: the false alarms of fault-free runs, the
detection delays of faulty runs, both over a range of thresholds (the operating curve), and the
threshold search of the calibration (``ftcsim fdir calibrate``, ``orchestrator/campaign/calibrate.py``,
docs/fdir.md). numpy only; the statistics run in the detector's own kernels (``ChangeDetector.replay``),
so the replay computes exactly what the block computes in a run (``tests/diagnosis``: a run's recorded
statistic against its replay).

A run is ``(t, r)``: the detector's sample instants (s, its ``sample_period`` apart) and the input
vectors there (K, n). Counting rule for false alarms: the test restarts after each alarm decision
(``restart`` 1, ``latch`` 0: B&N's repeated test), so a run of length T gives a count of alarms and
the false-alarm rate is (sum of counts) / (sum of exposures). The exposure of a run is its number
of samples at or after ``t_enable`` times the sample period.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["normalisation", "exposure_hours", "false_alarm_counts", "detection_delays", "threshold_search",
           "parameter_set", "COUNTING"]

COUNTING = {"restart": 1.0, "latch": 0.0}  # the detector settings under which false alarms are counted


def _enabled(t: np.ndarray, t_enable: float) -> np.ndarray:
    return t_enable <= t + 1e-9 * np.maximum(1.0, np.abs(t))


def normalisation(runs, t_enable: float = 0.0) -> tuple:
    """(mu0, sigma) per channel: mean and standard deviation (ddof 1) of every sample at or after
    ``t_enable`` of every run. A channel without variation is a ``ValueError`` naming it."""
    x = np.concatenate([np.asarray(r, dtype=float)[_enabled(np.asarray(t), t_enable)] for t, r in runs])
    if len(x) < 2:
        raise ValueError(f"{len(x)} samples at or after t_enable = {t_enable:g} s: nothing to normalise with")
    mu0, sigma = x.mean(axis=0), x.std(axis=0, ddof=1)
    flat = [i + 1 for i in range(x.shape[1]) if not sigma[i] > 0]
    if flat:
        raise ValueError(f"channel {flat[0]} is constant over the {len(x)} fault-free samples: its scale cannot be estimated")
    return mu0, sigma


def exposure_hours(runs, period: float, t_enable: float = 0.0) -> np.ndarray:
    """Per run: samples at or after ``t_enable`` times the sample period, in hours."""
    return np.array([np.count_nonzero(_enabled(np.asarray(t), t_enable)) * period / 3600.0 for t, _ in runs])


def false_alarm_counts(detector, runs, h: float) -> np.ndarray:
    """Alarm decisions per run at threshold ``h`` under the counting rule (module docstring).
    ``detector``: an initialised :class:`~diagnosis.detectors.ChangeDetector` (its parameters are
    used, ``h``, ``restart`` and ``latch`` replaced)."""
    detector.set_decision(h, **COUNTING)
    return np.array([int(detector.replay(r, t)[1].sum()) for t, r in runs])


def detection_delays(detector, runs, onsets, h: float) -> tuple:
    """For faulty runs with fault onsets ``onsets`` (s): (delay (s, nan if missed), false alarms
    before the onset) per run at threshold ``h``; the delay is from the onset to the first alarm
    decision at or after it (the detector as configured, ``latch`` and ``restart`` as given)."""
    detector.set_decision(h)
    delays, early = [], []
    for (t, r), onset in zip(runs, onsets):
        t = np.asarray(t, dtype=float)
        _, ev = detector.replay(r, t)
        after = t >= onset - 1e-9 * max(1.0, abs(onset))
        hit = np.flatnonzero((ev > 0) & after)
        delays.append(float(t[hit[0]] - onset) if len(hit) else math.nan)
        early.append(int(((ev > 0) & ~after).sum()))
    return np.array(delays), np.array(early)


def threshold_search(count, bound, target: float, h_max: float, h_min: float, points: int = 48,
                     iterations: int = 40) -> tuple:
    """The smallest threshold h in [h_min, h_max] whose false-alarm count N(h) (``count(h)``) has
    ``bound(N) <= target``, and the operating curve [(h, N)] of the grid it looked at.

    ``count`` is non-increasing in h in practice (restart after each alarm makes it not strictly so):
    a log-spaced grid of ``points`` thresholds finds the first passing grid point, then bisection
    between it and the grid point below refines h to a relative 1e-9 or ``iterations`` halvings, and
    the result is checked once more. Returns (h, N(h), curve); h is None if even ``h_max`` fails."""
    grid = np.geomspace(max(h_min, 1e-12), h_max, points)
    curve = [(float(h), int(count(h))) for h in grid]
    ok = [i for i, (_, n) in enumerate(curve) if bound(n) <= target]
    if not ok:
        return None, None, curve
    i = ok[0]
    hi, n_hi = curve[i]
    lo = curve[i - 1][0] if i > 0 else 0.0
    for _ in range(iterations):
        if hi - lo <= 1e-9 * hi:
            break
        mid = 0.5 * (lo + hi)
        n = int(count(mid))
        if bound(n) <= target:
            hi, n_hi = mid, n
        else:
            lo = mid
    return hi, n_hi, sorted(set(curve) | {(hi, n_hi)})


def parameter_set(path) -> dict:
    """The parameter set a calibration file (``ftcsim fdir calibrate --out FILE``) holds: base name ->
    value (numbers and lists), what a scenario's ``parameter_set = NAME`` applies. A file that is not
    a calibration is a ``ValueError`` naming it."""
    import json
    from pathlib import Path

    p = Path(path)
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise ValueError(f"{p}: cannot read the calibration file ({e}); `ftcsim fdir calibrate` writes it") from None
    if not isinstance(doc, dict) or doc.get("kind") != "fdir-calibration" or not isinstance(doc.get("parameter_set"), dict):
        raise ValueError(f"{p}: not a calibration file of `ftcsim fdir calibrate` (kind, parameter_set)")
    return {k: (np.asarray(v, dtype=float) if isinstance(v, list) else float(v)) for k, v in doc["parameter_set"].items()}
