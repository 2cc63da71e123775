"""The leaderboard's statistics and verdicts on runs whose answers are known: a run that failed never
ranks, a method that cannot fly ranks as such after every method that flies, a stopped run counts as
not keeping accuracy, the bootstrap interval of the median against the normal theory, paired
differences on common draws with Holm's correction and the minimum number of pairs, Wilson against
its closed form, the summary's symbols and the outside-claims marking."""

import numpy as np
import pandas as pd
import pytest

from arena import stats as S
from arena import verdicts as V
from arena.arenafile import Detection, Statistics
from arena.metrics import false_alarm_rate


class _Arena:
    seed, accuracy_tolerance = 3, 2.0
    statistics = Statistics(bootstrap=500, confidence=0.95, alpha=0.05, min_pairs=10)
    detection = Detection()


def _runs(method, outcomes, values, fault="bias", hardware="ideal", gains="redesigned", within=True, plant="p"):
    n = len(outcomes)
    return pd.DataFrame({"method": method, "method_label": method, "plant": plant, "gains": gains, "hardware": hardware,
                         "fault": fault, "draw": range(n), "outcome": outcomes, "within_claims": within,
                         "deterministic": False, "buildable": True, "stop_reason": None, "stop_time": np.nan,
                         "attitude_error_rms_after": values, "final_attitude_error": values, "control_energy": values,
                         "time_to_band": values, "peak_torque": 1.0, "peak_momentum": 1.0})


def test_failed_runs_never_rank_and_a_method_that_cannot_fly_ranks_last():
    good = _runs("good", ["flies"] * 4 + ["failed"] * 6, [1.0, 2.0, 3.0, 4.0] + [0.0] * 6)
    worse = _runs("worse", ["flies"] * 10, np.linspace(5.0, 6.0, 10))
    grounded = _runs("grounded", ["saturated"] * 7 + ["flies"] * 3, [1e-9] * 10)  # tiny numbers, but cannot fly
    stopped = _runs("stopped", ["stopped"] * 10, [np.nan] * 10)
    mt = V.metrics_table(_Arena(), pd.concat([good, worse, grounded, stopped], ignore_index=True)).set_index("method")
    assert mt.loc["good", "rank"] == "1" and mt.loc["worse", "rank"] == "2"
    assert mt.loc["grounded", "rank"] == "cannot fly" and mt.loc["stopped", "rank"] == "cannot fly"
    assert mt.loc["good", "runs"] == 4 and mt.loc["good", "attitude_error_rms_after"] == pytest.approx(2.5)  # failed left out
    assert mt.loc["grounded", "fly_share"] == pytest.approx(0.3) and mt.loc["stopped", "runs"] == 10
    assert list(mt.index) == ["good", "worse", "grounded", "stopped"]


def test_bootstrap_interval_of_the_median_against_the_normal_theory():
    rng = np.random.default_rng(0)
    x = rng.normal(10.0, 1.0, 400)
    med, lo, hi = S.median_interval(x, resamples=1000, confidence=0.95, rng=np.random.default_rng(1))
    assert lo < med < hi and med == pytest.approx(np.median(x))
    # the standard error of the median of a normal sample: 1.2533 sigma / sqrt(n); 95 % -> +-1.96 of it
    assert (hi - lo) / 2 == pytest.approx(1.96 * 1.2533 / np.sqrt(400), rel=0.35)
    assert S.median_interval([], resamples=100, confidence=0.95, rng=rng) == (None, None, None)
    assert S.median_interval([3.0], resamples=100, confidence=0.95, rng=rng) == (3.0, None, None)  # one point


def test_wilson_is_the_closed_form():
    for k, n in ((0, 20), (1, 20), (7, 9), (20, 20)):
        share, lo, hi = S.wilson(k, n, 0.95)
        ref = false_alarm_rate([True] * k + [False] * (n - k))  # the hand-written closed form (z = 1.96)
        assert share == pytest.approx(ref["rate"]) and lo == pytest.approx(ref["low"], abs=1e-6)
        assert hi == pytest.approx(ref["high"], abs=1e-6)


def test_holm_by_hand():
    p = [0.01, 0.04, 0.03, 0.005, None]
    # sorted 0.005, 0.01, 0.03, 0.04 -> 4 x 0.005 = 0.02, 3 x 0.01 = 0.03, 2 x 0.03 = 0.06, max(0.06, 1 x 0.04) = 0.06
    assert S.holm(p) == pytest.approx([0.03, 0.06, 0.06, 0.02, None])
    assert S.holm([0.9, 0.8]) == [1.0, 1.0]


def test_paired_differences_use_common_draws_and_need_enough_pairs():
    a = _runs("a", ["flies"] * 12, np.arange(1.0, 13.0))
    b = _runs("b", ["flies"] * 10 + ["stopped", "flies"], np.arange(1.0, 13.0) + 1.0)
    b.loc[2, "attitude_error_rms_after"] = np.nan  # did not settle in draw 2: no error after settling
    p = V.paired_table(_Arena(), pd.concat([a, b], ignore_index=True)).set_index("metric")
    row = p.loc["attitude_error_rms_after"]
    assert row["pairs"] == 10  # draw 10: b stopped; draw 2: b has no error after settling
    assert row["median_diff"] == pytest.approx(-1.0) and row["a_lower_share"] == 1.0
    assert row["p"] == pytest.approx(0.001953125)  # every difference -1: the exact two-sided signed-rank p, 2 / 2^10
    assert p.loc["control_energy", "pairs"] == 11
    # Holm over the family: three comparisons with p; the smallest x 3 <= 0.05
    assert row["family"] == 3 and bool(row["significant"])
    few = V.paired_table(_Arena(), pd.concat([a.head(9), b.head(9)], ignore_index=True))
    assert few["p"].isna().all() and not few["significant"].any()  # 9 pairs < min_pairs: never significant
    same = V.paired_table(_Arena(), pd.concat([a, a.assign(method="c")], ignore_index=True))
    assert same["p"].isna().all() and not same["significant"].any()  # identical pairs: nothing to test


def test_accuracy_verdict_counts_stopped_runs_as_not_keeping():
    ideal = _runs("m", ["flies"] * 4, [1e-4] * 4, gains="own")
    kept = _runs("m", ["flies"] * 4, [1.5e-4] * 4, hardware="realistic", gains="own")
    lost = _runs("m", ["flies"] * 4, [3e-4] * 4, hardware="realistic", gains="own")
    stopped = _runs("m", ["stopped"] * 4, [np.nan] * 4, hardware="realistic", gains="own")
    assert bool(V.accuracy_table(_Arena(), pd.concat([ideal, kept])).iloc[0]["keeps_accuracy"])
    assert not bool(V.accuracy_table(_Arena(), pd.concat([ideal, lost])).iloc[0]["keeps_accuracy"])
    r = V.accuracy_table(_Arena(), pd.concat([ideal, stopped])).iloc[0]
    assert not bool(r["keeps_accuracy"]) and r["verdict"] == "does not (stopped in 4 of 4 runs)"
    # outside its claims, a class does not enter the verdict
    outside = _runs("m", ["stopped"] * 4, [np.nan] * 4, hardware="realistic", gains="own", fault="lost", within=False)
    assert bool(V.accuracy_table(_Arena(), pd.concat([ideal, kept, outside])).iloc[0]["keeps_accuracy"])


def test_summary_symbols_count_within_claims_and_mark_the_rest():
    within = _runs("m", ["flies"] * 3 + ["stopped"], [1.0] * 4)
    within.loc[0, "buildable"] = False
    outside = _runs("m", ["not settled", "flies"], [1.0] * 2, fault="lost", within=False)
    assert V.cell_symbol(pd.concat([within, outside])) == "◐ 3/4 ■1 ⊘1 (†1/2)"
    assert V.cell_symbol(_runs("m", ["flies"] * 2, [1.0] * 2)) == "✔ 2/2"
    assert V.cell_symbol(_runs("m", ["stopped"] * 2, [np.nan] * 2)) == "✘ 0/2 ■2"
    assert V.cell_symbol(_runs("m", ["failed"] * 2, [np.nan] * 2)) == "— 0/0"
    oc = V.outcome_table(pd.concat([within, outside]))
    assert list(oc["claims"]) == ["within", "outside the method's claims"]


def test_stopped_runs_carry_their_reason_and_time():
    r = _runs("m", ["stopped", "stopped", "flies"], [np.nan, np.nan, 1.0])
    r["stop_reason"] = ["instance 'ctrl' ... FMU log: ValueError: singular allocation (33)"] * 2 + [None]
    r["stop_time"] = [0.24, 0.26, np.nan]
    st = V.stopped_table(r).iloc[0]
    assert st["stopped"] == "2/3" and st["stop_time"] == pytest.approx(0.25)
    assert st["reason"] == "ValueError: singular allocation (33)"


def test_figures_keep_every_label_inside_and_the_check_can_fail():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from arena import leaderboard as L

    rows = []
    for m in ("fasmc", "aismc", "pd", "fontsm", "sftc", "hinf", "asmftc"):
        for p in ("li2023", "xu2024", "zhang2019"):
            for f in ("none", "loe_step", "bias", "lost"):
                for hw in ("ideal", "realistic"):
                    rows.append({"method": m, "plant": p, "fault": f, "hardware": hw, "flies": 3, "runs": 20,
                                 "claims": V.OUTSIDE if f == "lost" else V.WITHIN})
    runs = pd.concat([_runs(m, ["flies"] * 20, np.geomspace(1e-6, 1e-2, 20), hardware=hw, plant="zhang2019")
                      for m in ("fasmc", "aismc", "pd", "fontsm", "sftc") for hw in ("ideal", "realistic")])
    figs = [L.fly_figure(pd.DataFrame(rows)), L.error_figure(runs, "zhang2019"), L.error_figure(runs, "none")]
    try:
        for fig in figs:
            assert L.clipped_text(fig) == []
            assert fig.bbox.width <= L.MAX_FIGURE_PX
        bad, ax = plt.subplots(figsize=(3, 2), dpi=110)  # no constrained layout: a long label is cut
        ax.set_ylabel("a label far too long for this little figure " * 2)
        assert L.clipped_text(bad) and L.clipped_text(bad)[0][0].startswith("a label")
        figs.append(bad)
    finally:
        for fig in figs:
            plt.close(fig)


def test_no_chain_is_named_best_for_a_plant_where_every_chain_misses_every_fault():
    """Rank 1 among chains that all miss every actuator fault is not a best chain: the headline says so."""
    from collections import defaultdict
    from types import SimpleNamespace

    from arena import verdicts as V
    from arena.arenafile import Detection

    arena = SimpleNamespace(cells=[1], hardware=["realistic"], faults=["none", "bias"], draws=2, overrides={},
                            detection=Detection(detectors=("cusum", "glr")), statistics=None)
    runs = pd.DataFrame({"outcome": ["flies"] * 2, "method": ["m"] * 2, "plant": ["p"] * 2,
                         "hardware": ["realistic"] * 2, "fault": ["none", "bias"]})
    chains = pd.DataFrame({"plant": ["p", "p", "q"], "hardware": ["realistic"] * 3, "rank": [1, 2, 1],
                           "chain": ["A + CUSUM", "A + GLR", "B + CUSUM"], "missed_share": [1.0, 1.0, 0.25],
                           "delay_median": [None, None, 3.0], "deterministic": [False] * 3, "h": [1.0] * 3,
                           "meets_target": [True] * 3})
    tables = defaultdict(pd.DataFrame, {"chains": chains})
    line = next(x for x in V.headlines(arena, runs, tables) if x.startswith("FDIR chains"))
    assert "p: no chain detects an actuator fault" in line and "A + CUSUM" not in line
    assert "q: B + CUSUM (missed 0.25, delay 3 s)" in line
