"""The leaderboard's statistics, from kept implementations (scipy.stats), with the arena's rules:

* an interval of a median (or of a share) is ``scipy.stats.bootstrap`` (percentile method, the
  arena's resamples and confidence, a generator seeded from the arena's seed and the entry's names);
  fewer than two values: no interval; a deterministic run is one value, shown as one point;
* a proportion (false alarms per run) has the Wilson score interval of
  ``scipy.stats.binomtest(k, n).proportion_ci(method="wilson")``;
* a paired comparison of two methods is the Wilcoxon signed-rank test (``scipy.stats.wilcoxon``,
  two-sided) of their differences on common draws; it can be "significant" only with at least
  ``min_pairs`` pairs, after Holm's step-down correction (:func:`holm`) across every comparison on
  the page at family-wise level ``alpha``; identical pairs (every difference 0) are never significant.
"""
from __future__ import annotations

import inspect
import math
import zlib

import numpy as np
from scipy import stats


def generator(seed: int, *names) -> np.random.Generator:
    """A generator per table entry, from the arena's seed and the entry's names (reproducible)."""
    return np.random.default_rng([int(seed)] + [zlib.crc32(str(k).encode()) for k in names])


_RNG_KW = "rng" if "rng" in inspect.signature(stats.bootstrap).parameters else "random_state"


def bootstrap_interval(x, statistic=np.median, *, resamples: int, confidence: float, rng) -> tuple:
    """(value, low, high) of ``statistic`` over ``x`` with its percentile-bootstrap interval
    (scipy.stats.bootstrap); (value, None, None) for one value, (None, None, None) for none."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return (None, None, None)
    value = float(statistic(x))
    if x.size < 2:
        return (value, None, None)
    if np.all(x == x[0]):
        return (value, value, value)
    res = stats.bootstrap((x,), statistic, n_resamples=int(resamples), confidence_level=confidence,
                          method="percentile", vectorized=True, axis=-1, **{_RNG_KW: rng})
    ci = res.confidence_interval
    return (value, float(ci.low), float(ci.high))


def median_interval(x, *, resamples: int, confidence: float, rng) -> tuple:
    return bootstrap_interval(x, np.median, resamples=resamples, confidence=confidence, rng=rng)


def share_interval(flags, *, resamples: int, confidence: float, rng) -> tuple:
    """(share, low, high) of true values with the bootstrap interval of the mean."""
    return bootstrap_interval(np.asarray(flags, dtype=float), np.mean, resamples=resamples, confidence=confidence,
                              rng=rng)


def wilson(k: int, n: int, confidence: float) -> tuple:
    """(k / n, low, high): the Wilson score interval of scipy.stats.binomtest; (None, None, None) for n = 0."""
    if n == 0:
        return (None, None, None)
    ci = stats.binomtest(int(k), int(n)).proportion_ci(confidence_level=confidence, method="wilson")
    return (k / n, float(ci.low), float(ci.high))


def wilcoxon_p(d) -> float | None:
    """Two-sided p-value of the Wilcoxon signed-rank test of paired differences ``d``; None when every
    difference is 0 (nothing to test: the pairs are identical)."""
    d = np.asarray(d, dtype=float)
    d = d[np.isfinite(d)]
    if d.size == 0 or np.all(d == 0):
        return None
    return float(stats.wilcoxon(d, zero_method="wilcox", alternative="two-sided").pvalue)


def holm(pvalues) -> list:
    """Holm's step-down adjusted p-values (same order; None stays None): the k-th smallest of m
    p-values becomes max over j <= k of min(1, (m - j + 1) p_(j)); reject where adjusted <= alpha."""
    idx = [i for i, p in enumerate(pvalues) if p is not None and not math.isnan(p)]
    m = len(idx)
    out = [None] * len(pvalues)
    running = 0.0
    for rank, i in enumerate(sorted(idx, key=lambda i: pvalues[i])):
        running = max(running, min(1.0, (m - rank) * pvalues[i]))
        out[i] = running
    return out
