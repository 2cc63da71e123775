"""Offline replay of a detector over recorded inputs: the false alarms of fault-free runs, the
detection delays of faulty runs, both over a range of thresholds (the operating curve), and the
threshold rule of the calibration (``ftcsim fdir calibrate``, ``orchestrator/campaign/calibrate.py``,
and the arena's FDIR scoring, ``arena/fdir.py``: one rule, :func:`certify`; docs/fdir.md). numpy (scipy.stats
for the Poisson bounds, imported where used); the statistics run in the detector's own kernels
(``ChangeDetector.replay``), so the replay computes exactly what the block computes in a run
(``tests/diagnosis``: a run's recorded statistic against its replay).

A run is ``(t, r)``: the detector's sample instants (s, its ``sample_period`` apart) and the input
vectors there (K, n). Counting rule for false alarms: the test restarts after each alarm decision
(``restart`` 1, ``latch`` 0: B&N's repeated test), so a run of length T gives a count of alarms and
the false-alarm rate is (sum of counts) / (sum of exposures). The exposure of a run is its number
of samples at or after ``t_enable`` times the sample period.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["normalisation", "exposure_hours", "false_alarm_counts", "detection_delays",
           "parameter_set", "COUNTING", "statistic", "persisted_levels", "persisted_peaks", "first_alarms", "upper_bound",
           "rate_statistics", "certify", "allowed_alarms", "NEVER"]

NEVER = 1e300  # a threshold no statistic reaches: the replay then gives the statistic alone (no decision acts)

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


def false_alarm_counts(detector, runs, h: float, peaks=None) -> np.ndarray:
    """Alarm decisions per run at threshold ``h`` under the counting rule (module docstring).
    ``detector``: an initialised :class:`~diagnosis.detectors.ChangeDetector` (its parameters are
    used, ``h``, ``restart`` and ``latch`` replaced). ``peaks``: the runs' :func:`persisted_peaks`,
    if known: a run whose peak is below ``h`` raises no alarm (its first decision is the one without
    restart) and is not replayed."""
    detector.set_decision(h, **COUNTING)
    return np.array([0 if peaks is not None and peaks[i] < h else int(detector.replay(r, t)[1].sum())
                     for i, (t, r) in enumerate(runs)])


def statistic(detector, t, r) -> np.ndarray:
    """The decision statistic of a run (K,) from a fresh state, with no decision acting on it (no
    restart): the same at every threshold; 0 at the samples before ``t_enable`` (ignored)."""
    detector.set_decision(NEVER, restart=0.0)
    return detector.replay(r, t)[0]


def persisted_levels(detector, t, s) -> np.ndarray:
    """L_k, the largest threshold the statistic ``s`` has met at the last m samples (m the persistence
    in samples, ``detector.prm["persist"]``), counting the samples at or after ``t_enable`` only (-inf
    before m of them). With restart 0 the block decides an alarm at sample k at threshold h exactly
    when L_k >= h > L_k-1 (its run of exceeding samples reaches m there): the decisions at every
    threshold from one replay (:func:`first_alarms`)."""
    t = np.asarray(t, dtype=float)
    s = np.asarray(s, dtype=float)
    m = int(detector.prm["persist"])
    on = np.flatnonzero(_enabled(t, detector.prm["t_enable"]))
    out = np.full(len(t), -np.inf)
    if len(on) >= m:
        x = s[on]
        from numpy.lib.stride_tricks import sliding_window_view

        out[on[m - 1:]] = sliding_window_view(x, m).min(axis=1) if m > 1 else x
    return out


def persisted_peaks(detector, runs) -> np.ndarray:
    """Per run, max_k L_k (:func:`persisted_levels`): at any threshold above it the run raises no
    alarm; at or below it, at least one (-inf: fewer than m enabled samples)."""
    return np.array([float(persisted_levels(detector, t, statistic(detector, t, r)).max(initial=-np.inf))
                     for t, r in runs])


def first_alarms(detector, runs, starts, thresholds) -> np.ndarray:
    """(runs, thresholds): the instant (s) of the first alarm decision at or after ``starts[i]`` of
    run i at each threshold (nan: none), for the detector as configured with ``restart`` 0 (the first
    decision at or after an instant does not depend on ``latch``). From one replay per run
    (:func:`persisted_levels`), equal to :func:`detection_delays` + onset at each threshold (tested)."""
    h = np.asarray(thresholds, dtype=float)
    out = np.full((len(runs), len(h)), np.nan)
    for i, ((t, r), start) in enumerate(zip(runs, starts)):
        t = np.asarray(t, dtype=float)
        L = persisted_levels(detector, t, statistic(detector, t, r))
        prev = np.concatenate(([-np.inf], L[:-1]))
        k0 = int(np.searchsorted(t, start - 1e-9 * max(1.0, abs(start))))
        if k0 >= len(t):
            continue  # no sample at or after the start
        L, prev = L[k0:, None], prev[k0:, None]
        event = (L >= h[None, :]) & (prev < h[None, :])
        hit = event.any(axis=0)
        out[i, hit] = t[k0 + event.argmax(axis=0)[hit]]
    return out


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


def upper_bound(N: int, E: float, level: float) -> float:
    """One-sided upper confidence bound at ``level`` on a Poisson rate with N events over E hours:
    chi2.ppf(level, 2N + 2) / (2E) (Garwood 1936; scipy.stats); inf for E = 0."""
    from scipy import stats

    return float(stats.chi2.ppf(level, 2 * int(N) + 2) / (2.0 * E)) if E > 0 else math.inf


def rate_statistics(counts, exposures, level: float, bootstrap_runs: int = 10) -> dict:
    """The false-alarm rate of per-run ``counts`` over ``exposures`` (hours): rate per hour, its
    two-sided Garwood interval at ``level``, the one-sided upper bound at ``level`` and, from
    ``bootstrap_runs`` runs and one alarm on, a bootstrap interval over runs (scipy.stats.bootstrap;
    alarms that cluster within runs make the Poisson interval too narrow: ``interval_per_hour`` is
    the union of both), and the dispersion index of the counts."""
    from scipy import stats

    counts, exposures = np.asarray(counts, dtype=float), np.asarray(exposures, dtype=float)
    N, E = int(counts.sum()), float(exposures.sum())
    a = 1.0 - level
    lo = 0.0 if N == 0 else float(stats.chi2.ppf(a / 2, 2 * N) / (2 * E))
    hi = float(stats.chi2.ppf(1 - a / 2, 2 * N + 2) / (2 * E))
    out = {"false_alarms": N, "exposure_hours": E, "rate_per_hour": N / E, "poisson_interval_per_hour": [lo, hi],
           "upper_bound_per_hour": upper_bound(N, E, level), "bootstrap_interval_per_hour": None,
           "dispersion_index": None}
    if N > 0 and len(counts) > 1:
        expected = N / E * exposures
        keep = expected > 0
        out["dispersion_index"] = float(((counts[keep] - expected[keep]) ** 2 / expected[keep]).sum() / (len(counts) - 1))
    if N > 0 and len(counts) >= bootstrap_runs:
        res = stats.bootstrap((counts, exposures), lambda n, e, axis=-1: n.sum(axis) / e.sum(axis),
                              paired=True, vectorized=True, confidence_level=level, method="percentile",
                              n_resamples=4999, random_state=np.random.default_rng(20240934))
        out["bootstrap_interval_per_hour"] = [float(res.confidence_interval.low), float(res.confidence_interval.high)]
    b = out["bootstrap_interval_per_hour"] or [lo, hi]
    out["interval_per_hour"] = [min(lo, b[0]), max(hi, b[1])]
    return out


def allowed_alarms(E: float, rate: float, level: float) -> int:
    """The most false alarms N over E hours whose upper bound at ``level`` is at most ``rate`` per
    hour (-1: not even N = 0, too few hours)."""
    N = -1
    while upper_bound(N + 1, E, level) <= rate:
        N += 1
    return N


def certify(detector, runs, exposures, rate: float, level: float, curve_points: int = 32) -> dict:
    """The calibration rule (docs/fdir.md): h is the smallest threshold at which none of the fault-free
    ``runs`` raises an alarm (just above the largest persisted peak, :func:`persisted_peaks`), and it is
    certified for ``rate`` false alarms per hour at ``level`` when -ln(1 - level) / E <= ``rate``
    (E: the runs' exposure, hours). ``detector``: initialised, with its normalisation.

    Why this bound holds although h is chosen from the same runs: the runs are exchangeable draws, so
    the largest of their n peaks is an upper tolerance limit (Wilks, order statistics): the probability
    that a new draw's peak exceeds it, i.e. that a new fault-free run of the same exposure e = E / n
    raises an alarm (a first alarm), is at most 1 - (1 - level)^(1/n) with confidence ``level``,
    whatever the peaks' distribution; per hour at most -ln(1 - level) / (n e) = -ln(1 - level) / E (a
    few per cent looser), the one-sided Poisson bound for no alarm. Approximate in two ways: the
    detector's normalisation (mu0, sigma) comes from the same runs, so a fresh run is not exactly
    exchangeable with them (optimistic by O(1/n); exact for a normalisation fixed beforehand), and
    unequal exposures make the per-hour figure an average. A threshold set lower, allowing N > 0 alarms
    and bounding their count, would be chosen on the very counts it bounds (a selection the Poisson
    bound does not account for): the rule never allows an alarm in the calibration draws. The bound is
    a property of the rule, not a test: fresh draws test it (``tests/diagnosis``, ``tests/arena/test_fdir.py``).

    Returns ``h``, ``certified``, ``counts`` (per run at h: zeros), ``curve`` [(h, N)]: ``curve_points``
    log-spaced thresholds from a thousandth of the largest peak up and h (an operating curve of the
    fault-free runs under the counting rule), ``peaks``."""
    E = float(np.sum(exposures))
    peaks = persisted_peaks(detector, runs)
    certified = allowed_alarms(E, rate, level) >= 0
    finite = peaks[np.isfinite(peaks)]
    top = float(finite.max()) if len(finite) else 0.0
    h = float(np.nextafter(max(top, 0.0), math.inf)) if top > 0 else 1e-300
    counts = false_alarm_counts(detector, runs, h, peaks)
    curve = []
    if curve_points and top > 0:
        curve = [(float(x), int(false_alarm_counts(detector, runs, float(x), peaks).sum()))
                 for x in np.geomspace(top * 1e-3, top, curve_points)]
    curve = sorted(set(curve) | {(h, int(counts.sum()))})
    return {"h": h, "certified": bool(certified), "counts": counts, "curve": curve, "peaks": peaks}


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
