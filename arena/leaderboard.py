"""The arena's leaderboard: one self-contained page a person reads in one screen, the Parquet tables
behind it, and its figures (matplotlib, constrained layout).

The first screen: the summary (plant by method, one row per method and hardware set, verdict
symbols: ``arena/verdicts.py`` :func:`~arena.verdicts.cell_symbol`), its legend and one line per
headline finding. Everything else sits below in collapsible sections: the rules, the outcomes per
plant and fault class (with "outside the method's claims" beside a result the method's paper does
not claim), stopped runs, metrics and ranks, accuracy with realistic hardware, feasibility against
the data-sheet wheels, paired comparisons, detection, the cells and the figures.

Legibility: every figure is laid out with matplotlib's constrained layout and checked by
:func:`clipped_text` (every tick label, axis label, title and colorbar label inside the image) and
kept at most :data:`MAX_FIGURE_PX` pixels wide; tables keep to a few short columns.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from . import verdicts as V
from .measure import UNITS

DPI = 110
MAX_FIGURE_PX = 1000  # the page's column is 72rem (1152 px at 16 px/rem)
PAGE_ROWS = 60  # longer tables: the first rows on the page, every row in tables/*.parquet


# -- figures --------------------------------------------------------------------------------------------------------
def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def fly_figure(outcomes: pd.DataFrame):
    """Share of runs that fly: one row per method on a plant, one column per fault class and hardware;
    each cell says flies/runs, a dagger marks a class outside the method's claims."""
    plt = _plt()
    t = outcomes.assign(row=outcomes["method"] + " @ " + outcomes["plant"],
                        col=outcomes["fault"] + "\n" + outcomes["hardware"],
                        share=outcomes["flies"] / outcomes["runs"])
    piv = t.pivot_table(index="row", columns="col", values="share", aggfunc="first")
    nr, nc = piv.shape
    width = min((MAX_FIGURE_PX - 1) / DPI, 2.6 + 0.95 * nc)
    fig, ax = plt.subplots(figsize=(width, 1.1 + 0.3 * nr), layout="constrained", dpi=DPI)
    im = ax.imshow(piv.to_numpy(dtype=float), vmin=0, vmax=1, cmap="RdYlGn", aspect="auto")
    ax.set_xticks(range(nc), piv.columns, fontsize=7)
    ax.set_yticks(range(nr), piv.index, fontsize=7)
    lookup = t.set_index(["row", "col"])
    for i, r in enumerate(piv.index):
        for j, c in enumerate(piv.columns):
            if (r, c) not in lookup.index:
                continue
            e = lookup.loc[(r, c)]
            mark = "†" if e["claims"] == V.OUTSIDE else ""
            ax.text(j, i, f"{int(e['flies'])}/{int(e['runs'])}{mark}", ha="center", va="center", fontsize=6)
    fig.colorbar(im, ax=ax, label="share of runs that fly", shrink=0.6)
    ax.set_title("Which method flies which plant († outside the method's claims)", fontsize=9)
    return fig


def error_figure(runs: pd.DataFrame, plant: str):
    """Attitude error after settling of the runs that fly on one plant, per method and hardware."""
    plt = _plt()
    g = runs[(runs["plant"] == plant) & (runs["outcome"] == "flies") & runs["attitude_error_rms_after"].notna()]
    labels, data = [], []
    for (method, hw), gm in g.groupby(["method", "hardware"], sort=True):
        labels.append(f"{method}\n{hw}")
        data.append(gm["attitude_error_rms_after"].astype(float).to_numpy())
    width = min((MAX_FIGURE_PX - 1) / DPI, 2.0 + 0.9 * max(1, len(data)))
    fig, ax = plt.subplots(figsize=(width, 3.0), layout="constrained", dpi=DPI)
    if data:
        ax.boxplot(data, showfliers=True)
        ax.set_xticks(range(1, len(labels) + 1), labels, fontsize=7)
        if min(float(np.min(d)) for d in data) > 0:
            ax.set_yscale("log")
    else:
        ax.text(0.5, 0.5, "no run flies this plant", ha="center", va="center", transform=ax.transAxes)
        ax.set_xticks([])
    ax.set_ylabel("attitude error after settling (rad)", fontsize=8)
    ax.set_title(f"plant {plant}", fontsize=9)
    return fig


def curves_figure(curves: pd.DataFrame, hardware: str = "realistic"):
    """Each chain's operating curve on ``hardware``: median detection delay of the faulty runs against
    the false-alarm rate of the fault-free draws (in sample), one point per threshold; the calibrated
    threshold ringed. One panel per plant."""
    plt = _plt()
    c = curves[(curves["hardware"] == hardware) & curves["delay_median"].notna()]
    plants = list(dict.fromkeys(c["plant"]))
    cols = min(3, max(1, len(plants)))
    rows = max(1, -(-len(plants) // cols))
    width = min((MAX_FIGURE_PX - 1) / DPI, 3.2 * cols + 0.6)
    fig, axes = plt.subplots(rows, cols, figsize=(width, 2.7 * rows + 0.5), layout="constrained", dpi=DPI, squeeze=False)
    for ax in axes.ravel()[len(plants):]:
        ax.set_visible(False)
    for ax, plant in zip(axes.ravel(), plants):
        g = c[c["plant"] == plant]
        for (method, det), k in g.groupby(["method", "detector"], sort=True):
            k = k.sort_values("h")
            line, = ax.plot(k["rate_per_hour"], k["delay_median"], marker=".", ms=4, lw=1, label=f"{method} {det}")
            cal = k[k["calibrated"]]
            ax.plot(cal["rate_per_hour"], cal["delay_median"], "o", mfc="none", ms=8, color=line.get_color())
        ax.set_xscale("symlog", linthresh=1.0)
        if (g["delay_median"] > 0).all():
            ax.set_yscale("log")
        ax.set_xlabel("false alarms per hour", fontsize=7)
        ax.set_ylabel("median delay (s)", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.set_title(f"{plant} ({hardware})", fontsize=8)
        ax.legend(fontsize=6, loc="best")
    if not plants:
        axes[0, 0].set_visible(True)
        axes[0, 0].text(0.5, 0.5, "no operating curve", ha="center", va="center", transform=axes[0, 0].transAxes)
    fig.suptitle("Operating curves (ringed: the calibrated threshold)", fontsize=8)
    return fig


def clipped_text(fig) -> list:
    """What of ``fig`` is drawn partly outside the image after the layout (tick labels, axis labels,
    titles, colorbars, annotations: everything an Axes draws, and the figure's own texts):
    [(what, reason)]; [] when every label is inside. Ticks outside an axis's view are not drawn and
    not counted (matplotlib's tight boxes)."""
    from matplotlib.text import Text

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    W, H = fig.bbox.width, fig.bbox.height
    out = []

    def outside(bb) -> bool:
        return bb.x0 < -0.5 or bb.y0 < -0.5 or bb.x1 > W + 0.5 or bb.y1 > H + 0.5

    for ax in fig.axes:
        bb = ax.get_tightbbox(renderer)
        if bb is not None and outside(bb):
            name = ax.get_title() or ax.get_ylabel() or ax.get_label() or "axes"
            out.append((name, f"drawn over [{bb.x0:.0f}, {bb.x1:.0f}] x [{bb.y0:.0f}, {bb.y1:.0f}] px, "
                              f"outside {W:.0f} x {H:.0f} px"))
    for t in fig.texts + [x for x in (getattr(fig, "_suptitle", None), getattr(fig, "_supxlabel", None),
                                      getattr(fig, "_supylabel", None)) if isinstance(x, Text)]:
        if t.get_visible() and t.get_text().strip() and outside(t.get_window_extent(renderer)):
            out.append((t.get_text(), "outside the image"))
    if W > MAX_FIGURE_PX + 0.5:
        out.append(("(figure)", f"{W:.0f} px wide: more than {MAX_FIGURE_PX} px"))
    return out


# -- tables and the page ---------------------------------------------------------------------------------------------
def build(arena, measured) -> dict:
    """Every table and figure of the leaderboard from the measured runs (``arena.app.Measured``):
    {"tables": {name: DataFrame}, "figures": {name: Figure}, "headlines": [line], "clipped": {figure:
    [(text, reason)]}}."""
    from plant.hardware.datasheets import WHEELS

    from . import fdir as F

    runs = measured.runs
    fd = F.score(arena, measured)
    tables = {"runs": runs, "outcomes": V.outcome_table(runs), "stopped": V.stopped_table(runs),
              "metrics": V.metrics_table(arena, runs), "accuracy": V.accuracy_table(arena, runs),
              "feasibility": V.feasibility_table(runs, WHEELS), "wheel_limit": V.wheel_limit_table(arena, runs),
              "paired": V.paired_table(arena, runs), "chains": fd["chains"], "fdir_runs": fd["runs"],
              "curves": fd["curves"], "closed": fd["closed"], "closed_runs": measured.closed,
              "sensor_faults": fd["sensors"], "summary": V.summary_table(arena, runs)}
    figures = {}
    if len(tables["outcomes"]):
        figures["flies"] = fly_figure(tables["outcomes"])
    if len(tables["curves"]):  # realistic hardware: the fault-free draws give a rate (ideal: one deterministic run)
        if ((tables["curves"]["hardware"] == "realistic") & tables["curves"]["delay_median"].notna()).any():
            figures["curves_realistic"] = curves_figure(tables["curves"], "realistic")
    for plant in [p for p in arena.plants if (runs["plant"] == p).any()]:
        figures[f"error_{plant}"] = error_figure(runs, plant)
    clipped = {name: clipped_text(fig) for name, fig in figures.items()}
    return {"tables": tables, "figures": figures, "headlines": V.headlines(arena, runs, tables), "clipped": clipped}


def _head(df: pd.DataFrame, rows: int = PAGE_ROWS) -> tuple:
    return df.head(rows), (f"The first {rows} of {len(df)} rows; every row in tables/" if len(df) > rows else "")


def sections(arena, lb: dict) -> list:
    """[(title, [paragraph], [("table" | "figure", caption, object)])] of the collapsible sections."""
    t, f = lb["tables"], lb["figures"]
    out = [("How to read this page", V.rules(arena), [])]
    oc = t["outcomes"]
    items = []
    for plant, g in oc.groupby("plant", sort=False) if len(oc) else []:
        d = g.drop(columns=["plant", "deterministic"]).rename(columns={"not settled": "not settled"})
        items.append(("table", f"outcomes on {plant} ({arena.plants[plant].mission:g} s mission"
                      + (f", cut to {arena.stop:g} s" if arena.stop is not None else "") + ")", d))
    out.append(("Outcomes by plant, method, hardware and fault class",
                ["runs: the draws computed (a deterministic fault-free run with ideal hardware is 1 run); not buildable: "
                 "ideal-hardware runs no data-sheet wheel could fly."], items))
    if len(t["stopped"]):
        out.append(("Stopped runs (results: counted as not flying)", [], [("table", "stopped runs: median stop time [s] "
                                                                          "and the most frequent reason", t["stopped"])]))
    mt = t["metrics"]
    items = []
    for plant, g in mt.groupby("plant", sort=False) if len(mt) else []:
        items.append(("table", f"metrics on {plant}: medians over the runs that fly [{arena.statistics.confidence:.0%} "
                               "bootstrap interval]; rank on the attitude error after settling", V.metrics_display(g)))
    out.append(("Metrics and ranks", ["Lower is better for every metric. Peak torque and momentum: medians over every "
                                      "result (per actuator channel)."], items))
    ch = t["chains"]
    if len(ch):
        det = arena.detection
        items = [("table", "FDIR chains (estimator + detector + isolation), ranked per plant and hardware",
                  V.chains_display(ch)),
                 ("table", "calibration of each chain on its cell's fault-free draws", V.calibration_display(ch))]
        if len(t["closed"]):
            items.append(("table", "wheel loss with the chain closed (reconfiguration) against the same draws without it",
                          V.closed_display(t["closed"])))
        if len(t["sensor_faults"]):
            items.append(("table", f"sensor faults (realistic hardware), with the {det.detectors[0]} chain",
                          V.sensors_display(t["sensor_faults"])))
        items += [("figure", f"operating curves, {k[7:]} hardware: median detection delay of the actuator-fault runs "
                             "against the false-alarm rate of the fault-free draws (in sample), one point per threshold",
                   f[k]) for k in ("curves_realistic",) if k in f]
        rank_note = ("Rank within a plant and hardware set: fewer missed detections, then shorter median delay, better "
                     "isolation (certification is the cell's, the same for all its chains). Delay, missed and isolation over the "
                     "actuator-fault runs; false alarms over the fault-free draws.")
        drawn = ch[~ch["deterministic"].astype(bool) & ch["exposure_hours"].notna()]
        floor = ""
        if len(drawn):
            r = drawn.loc[drawn["exposure_hours"].astype(float).idxmin()]
            least = float(r["exposure_hours"])
            floor = (f" The least fault-free flight of a chain with drawn runs is {least:.2g} h ({r['cell']}, "
                     f"{int(r['fault_free_runs'])} draws): no rate below {-math.log1p(-det.level) / least:.3g} per hour can "
                     "be certified from it; the operating curves show what a lower threshold gains in delay and costs in false "
                     "alarms (in sample, restart counts: not a bound).")
        out.append(("FDIR chains: detection, isolation, reconfiguration", [
            f"Target: at most {det.false_alarms_per_hour:g} first false alarms per hour, certified at {det.level:.0%} by "
            "the threshold above every fault-free peak of the cell's own draws (Wilks; How to read this page has the "
            "rule: a property of the rule, approximate, not a test)." + floor, rank_note], items))
    acc = t["accuracy"]
    if len(acc):
        d = acc[["method", "plant", "ideal_median", "realistic_median", "ratio", "ideal_settled_share",
                 "realistic_settled_share", "verdict"]]
        out.append(("Accuracy with realistic hardware (the papers' own pairs)", [
            f"Realistic-hardware median attitude error after settling within {arena.accuracy_tolerance:g} x the ideal one, "
            "and a settled share at least the ideal one minus 0.1, over the fault classes within the method's claims; "
            "stopped runs count as not settled."], [("table", "accuracy kept with realistic hardware", d)]))
    fe = t["feasibility"]
    items = [("table", "ideal hardware against the data-sheet wheels", fe)] if len(fe) else []
    if len(t["wheel_limit"]):
        items.append(("table", "realistic wheels: largest torque at the plant against the bound tau_max + c_c + "
                               "c_v h_max / I_w", t["wheel_limit"]))
    out.append(("Feasibility: torque and momentum", [], items))
    pt = t["paired"]
    if len(pt):
        shown = pt[pt["significant"]] if pt["significant"].any() else pt[pt["p"].notna()]
        d, note = _head(shown[["plant", "hardware", "fault", "metric", "a", "b", "pairs", "median_diff", "p", "p_holm",
                               "significant"]])
        out.append(("Paired comparisons on common draws", [
            f"{len(pt)} comparisons; {int(pt['p'].notna().sum())} with at least {arena.statistics.min_pairs} pairs form "
            f"Holm's family; shown: {'the significant ones' if pt['significant'].any() else 'those of the family'}. "
            "median_diff = median of A - B (negative: A lower).", note],
            [("table", "paired comparisons (Wilcoxon signed-rank, Holm-adjusted)", d)]))
    cells = pd.DataFrame([{"cell": c.name, "label": arena.methods[c.method].label, "gains": c.gains,
                           "claims": ", ".join(arena.methods[c.method].claims) or "none",
                           "source": arena.methods[c.method].claims_source} for c in arena.cells])
    out.append(("Cells and the methods' claims", ["gains: own = the paper's pair; redesigned = the method's design "
                                                  "re-run on the plant's model and verified; published = the published "
                                                  "gains as a robustness case."], [("table", "cells", cells)]))
    figs = [("figure", "share of runs that fly", f["flies"])] if "flies" in f else []
    figs += [("figure", f"attitude error after settling on {k[6:]}", v) for k, v in f.items() if k.startswith("error_")]
    out.append(("Figures", [], figs))
    return out


def page(arena, lb: dict):
    """The page (``orchestrator.results.html.Page``): self-contained, figures as data URIs."""
    from orchestrator.results.html import Page

    pg = Page(f"{arena.name}: leaderboard")
    pg.add_table(lb["tables"]["summary"], caption="Summary: which method flies which plant (within its claims)")
    pg.add_text(V.legend(arena), small=True)
    pg.add_items(lb["headlines"])
    for title, text, items in sections(arena, lb):
        with pg.details(title):
            for p in text:
                if p:
                    pg.add_text(p)
            for kind, caption, obj in items:
                if kind == "table":
                    pg.add_table(obj, caption=caption, units={k: v for k, v in UNITS.items() if k in obj.columns})
                else:
                    pg.add_figure(obj, caption=caption)
    return pg


def write(arena, measured, out, write_table):
    """Tables (Parquet, atomically through ``write_table``) and ``leaderboard.html`` into ``out``."""
    plt = _plt()
    lb = build(arena, measured)
    (out / "tables").mkdir(exist_ok=True)
    try:
        for name, df in lb["tables"].items():
            if df is None or (df.empty and name in ("closed", "closed_runs", "sensor_faults", "curves", "fdir_runs")):
                continue
            write_table(out / "tables" / f"{name}.parquet", _storable(df), units=UNITS if name == "runs" else None)
        return page(arena, lb).write(out / "leaderboard.html")
    finally:
        for fig in lb["figures"].values():
            plt.close(fig)


def _storable(df: pd.DataFrame) -> pd.DataFrame:
    """Object columns with mixed None / bool / number as strings or floats Parquet can hold."""
    d = df.copy()
    for c in d.columns:
        if d[c].dtype == object:
            vals = [v for v in d[c] if v is not None and not (isinstance(v, float) and np.isnan(v))]
            if vals and all(isinstance(v, (bool, np.bool_)) for v in vals):
                d[c] = d[c].map(lambda v: None if v is None or (isinstance(v, float) and np.isnan(v)) else bool(v))
            elif vals and all(isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool)
                              for v in vals):
                d[c] = pd.to_numeric(d[c], errors="coerce")
    return d
