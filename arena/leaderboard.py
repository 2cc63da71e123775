"""The arena's leaderboard: tables (pandas) and figures (matplotlib) from the measured runs, the
Parquet files behind them and one self-contained HTML page.

Statistics (stated on the page):

* a metric of a method on a plant is the median over the runs that fly (``arena/measure.py``
  outcomes), with a 95 % percentile-bootstrap confidence interval of the median (``bootstrap``
  resamples of the runs, generator seeded with the arena's seed);
* rankings are per plant, hardware and metric, over every fault class but "none"; a method that
  flies in fewer than half of its runs there ranks as "cannot fly", after every method that flies,
  whatever its median; a run that failed (no result) is left out and counted;
* paired comparisons: two methods on the same plant, hardware and fault class, on the draws where
  both ran to the end and the metric is defined for both (draw k is the same random numbers for
  both; the error after settling exists only for runs that settle): the median of the differences
  A - B with its bootstrap interval, and how often A is lower;
* false alarms: over the fault-free draws, the share of runs whose estimate crosses the cell's
  threshold, with the Wilson 95 % interval (``arena.metrics.false_alarm_rate``);
* accuracy kept with realistic hardware: on the method's own plant (the paper's pair), the median
  pointing error after settling with realistic hardware is within ``accuracy_tolerance`` x the
  ideal-hardware median and the method settles in at least as large a share of runs (minus 0.1).
"""
from __future__ import annotations

import itertools
import math

import numpy as np
import pandas as pd

from .measure import UNITS
from .metrics import false_alarm_rate

RANKED = ("time_to_band", "pointing_rms_after", "rate_rms_after", "peak_torque_axis", "rms_torque", "control_energy",
          "momentum_used", "estimate_rms_error", "detection_delay")
PAIRED = ("pointing_rms_after", "final_pointing_error", "control_energy")
FLY_SHARE = 0.5
OUTCOMES = ("flies", "not settled", "saturated", "diverged", "stopped", "failed")


def bootstrap_median(x, resamples: int, rng) -> tuple:
    """(median, low, high): the 95 % percentile bootstrap interval of the median of ``x``."""
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return (None, None, None)
    med = float(np.median(x))
    if x.size == 1:
        return (med, med, med)
    idx = rng.integers(0, x.size, size=(resamples, x.size))
    meds = np.median(x[idx], axis=1)
    return (med, float(np.quantile(meds, 0.025)), float(np.quantile(meds, 0.975)))


def _rng(arena, *key):
    """A generator per table entry, from the arena's seed and the entry's names (reproducible)."""
    import zlib

    return np.random.default_rng([arena.seed] + [zlib.crc32(str(k).encode()) for k in key])


def outcome_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per plant, hardware, fault class and method: runs, outcome counts, share that flies."""
    keys = ["plant", "hardware", "fault", "method"]
    rows = []
    for k, g in runs.groupby(keys, sort=True):
        ok = g[g["outcome"] != "failed"]
        r = dict(zip(keys, k))
        r["method_label"] = g["method_label"].iloc[0]
        r["gains"] = g["gains"].iloc[0]
        r["runs"] = len(g)
        for o in OUTCOMES:
            r[o] = int((g["outcome"] == o).sum())
        r["fly_share"] = float((ok["outcome"] == "flies").mean()) if len(ok) else None
        for m in ("time_to_band", "pointing_rms_after", "peak_torque_axis", "control_energy"):
            v = ok.loc[ok["outcome"] == "flies", m].dropna()
            r[f"{m}_median"] = float(v.median()) if len(v) else None
        rows.append(r)
    return pd.DataFrame(rows)


def ranking_table(arena, runs: pd.DataFrame) -> pd.DataFrame:
    """Per plant, hardware and metric: each method's median [95 % CI] over its flying runs (fault
    classes but "none"), its share of flying runs and its rank ("cannot fly" after the others)."""
    rows = []
    faulty = runs[(runs["fault"] != "none") & (runs["outcome"] != "failed")]
    for (plant, hw), g in faulty.groupby(["plant", "hardware"], sort=True):
        for metric in RANKED:
            entries = []
            for method, gm in g.groupby("method", sort=True):
                fly = gm[gm["outcome"] == "flies"]
                v = fly[metric].dropna().astype(float)
                share = len(fly) / len(gm)
                if metric in ("estimate_rms_error", "detection_delay") and gm[metric].isna().all():
                    continue  # the method has no estimate
                med, lo, hi = bootstrap_median(v, arena.bootstrap, _rng(arena, plant, hw, metric, method))
                entries.append({"plant": plant, "hardware": hw, "metric": metric, "method": method,
                                "method_label": gm["method_label"].iloc[0], "gains": gm["gains"].iloc[0],
                                "runs": len(gm), "n": len(v), "fly_share": share, "median": med, "ci_low": lo,
                                "ci_high": hi, "cannot_fly": share < FLY_SHARE})
            flying = sorted([e for e in entries if not e["cannot_fly"] and e["median"] is not None],
                            key=lambda e: e["median"])
            for i, e in enumerate(flying):
                e["rank"] = str(i + 1)
            rest = [e for e in entries if e not in flying]
            for e in rest:  # cannot fly; or flies but the metric is undefined in every flying run
                e["rank"] = "cannot fly" if e["cannot_fly"] else "no value"
            rows += flying + rest
    return pd.DataFrame(rows)


def paired_table(arena, runs: pd.DataFrame) -> pd.DataFrame:
    """Method pairs on common draws (module docstring)."""
    rows = []
    done = runs[~runs["outcome"].isin(["failed", "stopped"])]
    for (plant, hw, fault), g in done.groupby(["plant", "hardware", "fault"], sort=True):
        methods = sorted(g["method"].unique())
        for a, b in itertools.combinations(methods, 2):
            ga, gb = g[g["method"] == a].set_index("draw"), g[g["method"] == b].set_index("draw")
            common = sorted(set(ga.index) & set(gb.index))
            for metric in PAIRED:
                d = (ga.loc[common, metric].astype(float) - gb.loc[common, metric].astype(float)).dropna()
                med, lo, hi = bootstrap_median(d.to_numpy(), arena.bootstrap, _rng(arena, plant, hw, fault, a, b, metric))
                rows.append({"plant": plant, "hardware": hw, "fault": fault, "metric": metric, "a": a, "b": b,
                             "pairs": len(d), "median_diff": med, "ci_low": lo, "ci_high": hi,
                             "a_lower_share": float((d < 0).mean()) if len(d) else None,
                             "significant": bool(lo is not None and (lo > 0 or hi < 0))})
    return pd.DataFrame(rows)


def false_alarm_table(runs: pd.DataFrame) -> pd.DataFrame:
    rows = []
    free = runs[(runs["fault"] == "none") & runs["false_alarm"].notna() & (runs["outcome"] != "failed")]
    for (plant, hw, method), g in free.groupby(["plant", "hardware", "method"], sort=True):
        r = false_alarm_rate(g["false_alarm"].astype(bool).tolist())
        rows.append({"plant": plant, "hardware": hw, "method": method, "draws": r["draws"], "rate": r["rate"],
                     "ci_low": r["low"], "ci_high": r["high"]})
    return pd.DataFrame(rows)


def accuracy_table(arena, runs: pd.DataFrame) -> pd.DataFrame:
    """Does each method keep its paper's accuracy with realistic hardware? (module docstring)"""
    rows = []
    own = runs[(runs["gains"] == "own") & (runs["outcome"] != "failed")]
    for (method, plant), g in own.groupby(["method", "plant"], sort=True):
        r = {"method": method, "plant": plant, "tolerance": arena.accuracy_tolerance}
        for hw in ("ideal", "realistic"):
            gh = g[g["hardware"] == hw]
            fly = gh[gh["outcome"] == "flies"]["pointing_rms_after"].dropna()
            r[f"{hw}_settled_share"] = len(fly) / len(gh) if len(gh) else None
            r[f"{hw}_pointing_median"] = float(fly.median()) if len(fly) else None
        i, x = r["ideal_pointing_median"], r["realistic_pointing_median"]
        if r["ideal_settled_share"] is None or r["realistic_settled_share"] is None:
            r["ratio"], r["keeps_accuracy"] = None, None
        elif i is None:
            r["ratio"], r["keeps_accuracy"] = None, None  # no ideal accuracy to keep
        else:
            r["ratio"] = None if x is None else x / i if i > 0 else math.inf
            r["keeps_accuracy"] = bool(x is not None and r["ratio"] <= arena.accuracy_tolerance
                                       and r["realistic_settled_share"] >= r["ideal_settled_share"] - 0.1)
        rows.append(r)
    return pd.DataFrame(rows)


def wheel_limit_table(arena, runs: pd.DataFrame) -> pd.DataFrame:
    """Realistic cells: the largest wheel torque at the plant against the wheels' bound
    tau_max + c_c + c_v h_max / I_w (``plant/hardware/wheels.py``)."""
    from plant.hardware.datasheets import WHEELS
    from plant.hardware.wheels import torque_bound

    rows = []
    real = runs[(runs["hardware"] == "realistic") & runs["wheel_peak_torque"].notna()]
    for (plant, method), g in real.groupby(["plant", "method"], sort=True):
        p = WHEELS[arena.plants[plant].hardware["wheels"]]
        bound = torque_bound(p["tau_max"], p["coulomb"], p["viscous"], p["h_max"], p["I_w"])
        peak = float(g["wheel_peak_torque"].max())
        rows.append({"plant": plant, "method": method, "wheels": arena.plants[plant].hardware["wheels"], "runs": len(g),
                     "peak_wheel_torque": peak, "bound": bound, "within": bool(peak <= bound + 1e-12)})
    return pd.DataFrame(rows)


# -- figures --------------------------------------------------------------------------------------------------
def fly_figure(outcomes: pd.DataFrame):
    """Share of flying runs: one row per method on a plant, one column per fault class and hardware."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = outcomes.assign(row=outcomes["method"] + " @ " + outcomes["plant"],
                        col=outcomes["fault"] + "\n" + outcomes["hardware"])
    piv = t.pivot_table(index="row", columns="col", values="fly_share", aggfunc="first")
    fig, ax = plt.subplots(figsize=(1.0 + 0.75 * piv.shape[1], 0.6 + 0.32 * piv.shape[0]))
    im = ax.imshow(piv.to_numpy(dtype=float), vmin=0, vmax=1, cmap="RdYlGn", aspect="auto")
    ax.set_xticks(range(piv.shape[1]), piv.columns, fontsize=7)
    ax.set_yticks(range(piv.shape[0]), piv.index, fontsize=7)
    fig.colorbar(im, ax=ax, label="share of runs that fly")
    ax.set_title("Which method flies which plant")
    return fig


def pointing_figure(runs: pd.DataFrame, plant: str):
    """Pointing error after settling of the flying runs, per method and hardware, on one plant."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    g = runs[(runs["plant"] == plant) & (runs["outcome"] == "flies") & runs["pointing_rms_after"].notna()]
    labels, data = [], []
    for (method, hw), gm in g.groupby(["method", "hardware"], sort=True):
        labels.append(f"{method}\n{hw}")
        data.append(gm["pointing_rms_after"].astype(float).to_numpy())
    fig, ax = plt.subplots(figsize=(1.2 + 0.8 * max(1, len(data)), 2.8))
    if data:
        ax.boxplot(data, showfliers=True)
        ax.set_xticks(range(1, len(labels) + 1), labels, fontsize=7)
        ax.set_yscale("log")
    else:
        ax.text(0.5, 0.5, "no method flies this plant", ha="center", va="center", transform=ax.transAxes)
    ax.set_ylabel("pointing RMS after settling (rad)")
    ax.set_title(f"plant {plant}")
    return fig


# -- the page -------------------------------------------------------------------------------------------------
def build(arena, runs: pd.DataFrame) -> dict:
    """Every table and figure of the leaderboard."""
    outcomes = outcome_table(runs)
    tables = {"runs": runs, "outcomes": outcomes, "ranking": ranking_table(arena, runs),
              "paired": paired_table(arena, runs), "false_alarms": false_alarm_table(runs),
              "accuracy": accuracy_table(arena, runs), "wheel_limit": wheel_limit_table(arena, runs)}
    figures = {"flies": fly_figure(outcomes)} if len(outcomes) else {}
    for plant in sorted(runs["plant"].unique()):
        figures[f"pointing_{plant}"] = pointing_figure(runs, plant)
    return {"tables": tables, "figures": figures}


def page(arena, lb: dict):
    """The page (``orchestrator.results.html.Page``): self-contained, figures as data URIs."""
    from orchestrator.results.html import Page

    pg = Page(f"{arena.name}: leaderboard")
    for title, text, items in sections(arena, lb):
        pg.add_heading(title)
        for p in text:
            if p:
                pg.add_text(p)
        for kind, name, obj in items:
            if kind == "table":
                pg.add_table(obj, caption=name, units={k: v for k, v in UNITS.items() if k in obj.columns})
            else:
                pg.add_figure(obj, caption=name)
    return pg


def sections(arena, lb: dict) -> list:
    """[(title, [paragraph, ...], [("table" | "figure", name, object), ...])] of the page."""
    t, f = lb["tables"], lb["figures"]
    runs = t["runs"]
    n_failed = int((runs["outcome"] == "failed").sum())
    cannot = runs[~runs["outcome"].isin(["flies", "failed"])]
    out = [("The arena", [
        arena.description or "",
        f"{len(runs)} runs stored of {arena.n_runs} planned: {len(arena.cells)} cells (a method on a plant) x "
        f"{len(arena.hardware)} hardware ({', '.join(arena.hardware)}) x {len(arena.faults)} fault classes "
        f"({', '.join(arena.faults)}) x {arena.draws} draws; seed {arena.seed}, common to every cell: draw k is the same "
        "random numbers (fault onset, size, channel, Markov path, sensor noise) for every method.",
        f"{n_failed} runs failed (no result: never ranked, listed in tables/runs.parquet with their error); "
        f"{len(cannot)} runs did not fly (stopped, diverged, saturated or not settled): results, ranked as such.",
        "Statistics: medians over the runs that fly with 95 % percentile-bootstrap intervals of the median "
        f"({arena.bootstrap} resamples); a method flying fewer than {FLY_SHARE:.0%} of its runs on a plant ranks as "
        "'cannot fly'. Paired comparisons use the draws where both methods fly. False-alarm rates over the fault-free "
        "draws carry Wilson 95 % intervals. The Parquet tables behind this page are in tables/.",
    ], [("figure", "share of runs that fly, per method on a plant, fault class and hardware", f["flies"])]
        if "flies" in f else [])]
    cells = pd.DataFrame([{"method": c.method, "label": arena.methods[c.method].label,
                           "paper": arena.methods[c.method].paper, "plant": c.plant, "gains": c.gains,
                           "scenario": c.scenario.name} for c in arena.cells])
    out.append(("Cells", ["gains: own = the paper's own pair; redesigned = the method's design re-run on the target "
                          "plant's model and verified (arena/gains.py); published = the published gains flown as a "
                          "robustness case (no design applies)."], [("table", "cells", cells)]))
    acc = t["accuracy"]
    if len(acc):
        keep = ", ".join(acc.loc[acc["keeps_accuracy"] == True, "method"]) or "none"  # noqa: E712
        lose = ", ".join(acc.loc[acc["keeps_accuracy"] == False, "method"]) or "none"  # noqa: E712
        out.append(("Accuracy with realistic hardware", [
            f"Keep their paper's accuracy with realistic hardware: {keep}. Do not: {lose}.",
            f"Computed on each method's own plant: the median pointing error after settling with realistic hardware "
            f"within {arena.accuracy_tolerance:g} x the ideal-hardware median, and a settled share at least the ideal "
            "one minus 0.1 (no value: the method does not settle with ideal hardware either)."],
            [("table", "accuracy", acc)]))
    if len(t["wheel_limit"]):
        out.append(("Wheel torque at the plant", ["With realistic wheels, the largest per-wheel torque over every "
                                                  "run against the wheel's bound tau_max + c_c + c_v h_max / I_w."],
                    [("table", "wheel_limit", t["wheel_limit"])]))
    rk = t["ranking"]
    for (plant, hw), g in rk.groupby(["plant", "hardware"], sort=True) if len(rk) else []:
        items = []
        for metric, gm in g.groupby("metric", sort=False):
            items.append(("table", f"ranking {plant} {hw} {metric}",
                          gm[["rank", "method", "gains", "runs", "fly_share", "n", "median", "ci_low", "ci_high"]]))
        out.append((f"Rankings: plant {plant}, {hw} hardware", ["Lower is better for every metric; fault classes "
                                                                  "but 'none' pooled."], items))
    oc = t["outcomes"]
    for (plant, fault), g in oc.groupby(["plant", "fault"], sort=True) if len(oc) else []:
        out.append((f"Plant {plant}, fault class {fault}", [], [("table", f"outcomes {plant} {fault}", g.drop(
            columns=["plant", "fault"]))]))
    for name in [k for k in f if k.startswith("pointing_")]:
        out.append((f"Pointing error, plant {name[9:]}", [], [("figure", f"pointing error after settling, {name[9:]}",
                                                               f[name])]))
    if len(t["paired"]):
        out.append(("Paired comparisons on common draws", ["median of A - B over the draws where both ran to the end "
                                                           "and the metric is defined for both, with its bootstrap "
                                                           "interval; significant: the interval excludes 0."],
                    [("table", "paired", t["paired"])]))
    if len(t["false_alarms"]):
        out.append(("False alarms over the fault-free draws", [], [("table", "false_alarms", t["false_alarms"])]))
    return out


def write(arena, runs: pd.DataFrame, out, write_table, units=None):
    """Tables (Parquet, atomically through ``write_table``) and ``leaderboard.html`` into ``out``."""
    import matplotlib.pyplot as plt

    lb = build(arena, runs)
    (out / "tables").mkdir(exist_ok=True)
    for name, df in lb["tables"].items():
        write_table(out / "tables" / f"{name}.parquet", df, units=units if name == "runs" else None)
    try:
        return page(arena, lb).write(out / "leaderboard.html")
    finally:
        for fig in lb["figures"].values():
            plt.close(fig)
