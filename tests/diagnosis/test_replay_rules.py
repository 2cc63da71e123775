"""The offline replay's shortcuts (diagnosis/calibration.py) against the block itself: the first alarm
at every threshold from one replay equals the block's replay at each threshold; the persisted peak is
the threshold where a run's alarms stop; skipping the runs below their peak changes no count; the
threshold rule (certify) on runs whose alarm counts are known by construction."""
import math

import numpy as np
import pytest
from scipy import stats

from diagnosis.calibration import (
    certify,
    detection_delays,
    false_alarm_counts,
    first_alarms,
    persisted_peaks,
    rate_statistics,
    statistic,
    upper_bound,
)
from diagnosis.detectors import Chi2Detector, CusumDetector, GlrDetector

T = 0.05


def _block(cls, **params):
    b = cls(3)
    b.set_parameters({"sample_period": T, **params})
    b.initialize(0.0)
    return b


def _runs(n, K, seed, step_at=None, size=0.0):
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        x = np.zeros((K, 3))
        e = rng.normal(size=(K, 3))
        for k in range(1, K):  # AR(1): an estimate is not white
            x[k] = 0.9 * x[k - 1] + e[k]
        t = np.arange(K) * T
        if step_at is not None:
            x[t >= step_at[i], i % 3] += size
        out.append((t, x))
    return out


DETECTORS = [(CusumDetector, {"drift": 0.5}), (GlrDetector, {"window": 0.5}), (Chi2Detector, {"window": 0.5, "form": 1.0})]


@pytest.mark.parametrize("cls,extra", DETECTORS, ids=["cusum", "glr", "chi2"])
def test_first_alarms_from_one_replay_equal_the_blocks_decisions(cls, extra):
    b = _block(cls, persistence=0.2, t_enable=1.0, latch=1.0, **extra)
    onsets = [4.0, 6.0, 7.5, 3.0, 5.0, 9.0]
    runs = _runs(6, 400, 3, onsets, 4.0)
    s = [statistic(b, t, r) for t, r in runs]
    grid = np.quantile(np.concatenate(s), [0.5, 0.8, 0.9, 0.95, 0.99, 0.999]) * [1, 1, 1, 1, 1, 1.0001]
    fast = first_alarms(b, runs, onsets, grid)
    seen = 0
    for j, h in enumerate(grid):
        delays, _ = detection_delays(b, runs, onsets, h)  # the block, replayed at h
        for i, d in enumerate(delays):
            if math.isnan(d):
                assert math.isnan(fast[i, j]), (i, h)
            else:
                seen += 1
                assert fast[i, j] == pytest.approx(onsets[i] + d, abs=1e-12), (i, h)
    assert 0 < seen < fast.size  # some thresholds alarm, some miss: the comparison can fail both ways


@pytest.mark.parametrize("cls,extra", DETECTORS, ids=["cusum", "glr", "chi2"])
def test_the_persisted_peak_is_where_the_alarms_stop_and_skipping_changes_no_count(cls, extra):
    b = _block(cls, persistence=0.15, t_enable=0.5, **extra)
    runs = _runs(5, 300, 8)
    peaks = persisted_peaks(b, runs)
    for i, (t, r) in enumerate(runs):
        assert false_alarm_counts(b, [(t, r)], peaks[i] * (1 + 1e-9))[0] == 0
        assert false_alarm_counts(b, [(t, r)], peaks[i])[0] >= 1
    for h in np.quantile(peaks, [0.0, 0.5, 1.0]) * 0.999:
        assert false_alarm_counts(b, runs, h, peaks).tolist() == false_alarm_counts(b, runs, h).tolist()


def test_certify_is_the_smallest_threshold_without_an_alarm_and_certified_by_the_hours():
    b = _block(CusumDetector, drift=0.5, persistence=0.1)
    runs = _runs(20, 2000, 11)
    exposures = np.array([len(t) * T / 3600 for t, _ in runs])  # t_enable 0: every sample
    E = exposures.sum()
    rate = 40.0
    assert upper_bound(0, E, 0.95) <= rate  # certifiable: 0.56 h
    out = certify(b, runs, exposures, rate, 0.95)
    assert out["certified"] and int(out["counts"].sum()) == 0  # no calibration draw alarms at h
    below = false_alarm_counts(b, runs, out["h"] * (1 - 1e-9))
    assert below.sum() >= 1  # a hair lower, the draw holding the largest peak alarms: the smallest such h
    assert out["h"] == pytest.approx(max(out["peaks"]), rel=1e-12) and out["h"] > max(out["peaks"])
    # the rate is not what decides h: a looser target gives the same threshold (no alarm is ever allowed)
    assert certify(b, runs, exposures, 1000.0, 0.95)["h"] == out["h"]
    # too few hours: the same threshold, not certified
    few = certify(b, runs[:2], exposures[:2], rate, 0.95)
    assert not few["certified"] and few["counts"].sum() == 0
    assert few["h"] == pytest.approx(max(few["peaks"]), rel=1e-8) and few["h"] >= max(few["peaks"])


def test_rate_statistics_are_garwoods_interval():
    s = rate_statistics([3, 0, 1], [0.5, 0.5, 1.0], 0.9, bootstrap_runs=10)
    assert s["rate_per_hour"] == 2.0 and s["false_alarms"] == 4  # 4 alarms in 2 h
    lo, hi = s["poisson_interval_per_hour"]  # P(X <= 4 | hi E) = P(X >= 4 | lo E) = 0.05
    assert stats.poisson.cdf(4, hi * 2.0) == pytest.approx(0.05) and stats.poisson.sf(3, lo * 2.0) == pytest.approx(0.05)
    assert stats.poisson.cdf(4, s["upper_bound_per_hour"] * 2.0) == pytest.approx(0.1)
    assert s["bootstrap_interval_per_hour"] is None and s["interval_per_hour"] == [lo, hi]
