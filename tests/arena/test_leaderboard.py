"""The leaderboard's statistics on runs whose answers are known: a run that failed never ranks, a
method that cannot fly ranks as such after every method that flies, the bootstrap interval of the
median holds the median, paired differences are taken on common draws, the false-alarm rate."""
import numpy as np
import pandas as pd
import pytest

from arena import leaderboard as L


class _Arena:
    seed, bootstrap, accuracy_tolerance = 3, 500, 2.0


def _runs(method, outcomes, values, fault="bias", hardware="ideal", gains="redesigned"):
    return pd.DataFrame({"method": method, "method_label": method, "plant": "p", "gains": gains, "hardware": hardware,
                         "fault": fault, "draw": range(len(outcomes)), "outcome": outcomes,
                         "pointing_rms_after": values, "control_energy": values, "false_alarm": None,
                         **{m: values for m in ("time_to_band", "rate_rms_after", "peak_torque_axis", "rms_torque",
                                                 "momentum_used")},
                         "estimate_rms_error": np.nan, "detection_delay": np.nan})


def test_failed_runs_never_rank_and_a_method_that_cannot_fly_ranks_last():
    good = _runs("good", ["flies"] * 4 + ["failed"] * 6, [1.0, 2.0, 3.0, 4.0] + [0.0] * 6)
    worse = _runs("worse", ["flies"] * 10, np.linspace(5.0, 6.0, 10))
    grounded = _runs("grounded", ["saturated"] * 7 + ["flies"] * 3, [1e-9] * 10)  # tiny numbers, but cannot fly
    rk = L.ranking_table(_Arena(), pd.concat([good, worse, grounded], ignore_index=True))
    r = rk[rk["metric"] == "pointing_rms_after"].set_index("method")
    assert r.loc["good", "rank"] == "1" and r.loc["worse", "rank"] == "2" and r.loc["grounded", "rank"] == "cannot fly"
    assert r.loc["good", "runs"] == 4 and r.loc["good", "median"] == pytest.approx(2.5)  # the failed six left out
    assert r.loc["grounded", "fly_share"] == pytest.approx(0.3)
    assert list(r.index) == ["good", "worse", "grounded"]


def test_bootstrap_interval_of_the_median():
    rng = np.random.default_rng(0)
    x = rng.normal(10.0, 1.0, 400)
    med, lo, hi = L.bootstrap_median(x, 1000, np.random.default_rng(1))
    assert lo < med < hi and med == pytest.approx(np.median(x))
    # the standard error of the median of a normal sample: 1.2533 sigma / sqrt(n); 95 % -> +-1.96 of it
    half = 1.96 * 1.2533 / np.sqrt(400)
    assert (hi - lo) / 2 == pytest.approx(half, rel=0.35)
    assert L.bootstrap_median([], 100, rng) == (None, None, None)


def test_paired_differences_use_common_draws_only():
    a = _runs("a", ["flies"] * 5, [1.0, 2.0, 3.0, 4.0, 5.0])
    b = _runs("b", ["flies", "flies", "flies", "stopped", "flies"], [2.0, 3.0, 4.0, 0.0, 7.0])
    b.loc[2, "pointing_rms_after"] = np.nan  # did not settle: no error after settling
    b["final_pointing_error"] = b["pointing_rms_after"]
    a["final_pointing_error"] = a["pointing_rms_after"]
    p = L.paired_table(_Arena(), pd.concat([a, b], ignore_index=True))
    row = p[p["metric"] == "pointing_rms_after"].iloc[0]
    assert row["pairs"] == 3  # draw 3: b stopped; draw 2: b has no error after settling
    assert row["median_diff"] == pytest.approx(-1.0) and row["a_lower_share"] == 1.0
    assert p[p["metric"] == "control_energy"].iloc[0]["pairs"] == 4


def test_false_alarm_rate_over_fault_free_draws():
    r = _runs("m", ["flies"] * 10, [1.0] * 10, fault="none")
    r["false_alarm"] = [True, False, False, False, False, False, False, False, False, False]
    fa = L.false_alarm_table(r)
    assert fa.iloc[0]["rate"] == pytest.approx(0.1) and fa.iloc[0]["draws"] == 10
    assert 0.0 < fa.iloc[0]["ci_low"] < 0.1 < fa.iloc[0]["ci_high"]


def test_accuracy_verdict():
    ideal = _runs("m", ["flies"] * 4, [1e-4] * 4, gains="own")
    kept = _runs("m", ["flies"] * 4, [1.5e-4] * 4, hardware="realistic", gains="own")
    lost = _runs("m", ["flies"] * 4, [3e-4] * 4, hardware="realistic", gains="own")
    assert bool(L.accuracy_table(_Arena(), pd.concat([ideal, kept])).iloc[0]["keeps_accuracy"])
    assert not bool(L.accuracy_table(_Arena(), pd.concat([ideal, lost])).iloc[0]["keeps_accuracy"])
    grounded = _runs("m", ["saturated"] * 4, [np.nan] * 4, hardware="realistic", gains="own")
    assert not bool(L.accuracy_table(_Arena(), pd.concat([ideal, grounded])).iloc[0]["keeps_accuracy"])
