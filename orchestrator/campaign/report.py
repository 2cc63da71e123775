"""``ftcsim campaign-report DIR [--out REPORT]``: what a campaign found, as report.md, report.html
(one self-contained page) and PNG plots.

From a campaign folder (``ftcsim campaign``), per group (a variant, or a variant at one grid point
of a ``[grid]`` sweep: the points are never pooled): for every metric the number of runs with a
value, mean with its 95 % confidence interval (Student t), standard deviation, median with its 95 %
percentile-bootstrap interval (scipy.stats.bootstrap), 5 % / 95 %
quantiles and extremes; the differences of every variant from the first one at the same grid point
on the same draws (paired, mean difference with its 95 % interval); the requirements of the
campaign file (``[requirements]``: a run passes when it finished and the metric exists and lies
within its bounds; the pass fraction with its 95 % Wilson interval, scipy.stats.binomtest); the worst runs of every
requirement (or of the first metrics) with their draw, seed and dispersed values, and the command
that replays one as an ordinary run; histograms of the metrics and, for the stored trajectories,
mean and 3-sigma envelopes over time per group.

A run that did not finish (``status`` other than ``ok``, or an ``error``) is listed as failed with
its error and takes no part in the statistics, differences and worst runs; it counts as not
passing a requirement. Groups or metrics without a value are left out. Units (the summary's Parquet
field metadata ``unit``, else :data:`UNITS`) are in the table headers. The report folder (default
``DIR/report``) follows :mod:`orchestrator.common.outputs` (kind ``campaign-report``;
``--overwrite`` replaces a previous one).
"""
from __future__ import annotations

import itertools
import math
import os
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import write_json_atomic
from orchestrator.common.outputs import is_result_folder
from orchestrator.common.parquet import read_folder, read_table
from orchestrator.common.reading import read_json
from orchestrator.results.html import plain_text, unit_tag
from orchestrator.results.report import Document, add_figures

KEY_METRICS = ("control_energy", "final_attitude_error", "settling_time", "final_rate_error", "max_abs_u")
ID_COLUMNS = ("run_id", "key", "variant", "group", "point", "draw", "seed", "status", "error", "wall_time_s", "cpu_time_s",
              "sim_time_s", "worker",
              "t_end", "steps", "step", "u_max")
WORST = 5
# units of the columns whose unit does not depend on the scenario, where the summary's Parquet
# fields carry none (a summary written before units were stored); UCUM spelling (plant/units.py)
UNITS = {"final_attitude_error": "rad", "max_attitude_error_last_10s": "rad", "final_q_ev_norm": "1",
         "max_q_ev_norm_last_10s": "1", "settling_time": "s", "real_time_factor": "1", "wall_time_s": "s",
         "cpu_time_s": "s", "sim_time_s": "s", "t_end": "s", "step": "s"}


def mean_ci(x, level=0.95):
    """(mean, half-width of the ``level`` confidence interval of the mean) of finite values."""
    from scipy import stats

    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) == 0:
        return None, None
    if len(x) == 1:
        return float(x[0]), None
    return float(x.mean()), float(stats.t.ppf(0.5 + level / 2, len(x) - 1) * x.std(ddof=1) / math.sqrt(len(x)))


def wilson(k: int, n: int, level: float = 0.95):
    """The ``level`` Wilson score interval of a proportion k / n (``scipy.stats.binomtest``); (None,
    None) for n = 0."""
    from scipy import stats

    if n == 0:
        return None, None
    ci = stats.binomtest(int(k), int(n)).proportion_ci(confidence_level=level, method="wilson")
    return float(ci.low), float(ci.high)


BOOTSTRAP_RESAMPLES = 2000
BOOTSTRAP_SEED = 2024  # fixed: a report of the same runs gives the same intervals


def median_ci(x, level: float = 0.95, resamples: int = BOOTSTRAP_RESAMPLES, seed: int = BOOTSTRAP_SEED):
    """(median, low, high) of the finite values of ``x``: the ``level`` percentile-bootstrap interval
    of the median (``scipy.stats.bootstrap``, ``resamples`` resamples from ``seed``); (median,
    median, median) when every value is the same, (None, None, None) without values, (median, None,
    None) for one value."""
    from scipy import stats

    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) == 0:
        return None, None, None
    med = float(np.median(x))
    if len(x) == 1:
        return med, None, None
    if np.ptp(x) == 0:
        return med, med, med
    r = stats.bootstrap((x,), np.median, n_resamples=resamples, confidence_level=level, method="percentile",
                        vectorized=True, rng=np.random.default_rng(seed))
    return med, float(r.confidence_interval.low), float(r.confidence_interval.high)


def _fmt(x, digits=4):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if isinstance(x, (bool, np.bool_)):
        return str(bool(x))
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    return f"{float(x):.{digits}g}"


def load_folder(folder: Path):
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(folder, "-", "campaign folder not found")
    if not is_result_folder(folder, "campaign"):
        raise InputError(folder, "-", "not a campaign folder of `ftcsim campaign` (no campaign marker)")
    for f in ("summary.parquet", "manifest.json"):
        if not os.path.lexists(folder / f):
            raise InputError(folder, f, "missing: rerun `ftcsim campaign` on this folder to write it")
    df = read_table(folder / "summary.parquet")  # the one reader (any file name, regular, bounded)
    man = read_json(folder / "manifest.json", "manifest.json", strict=False)
    if len(df) == 0:
        raise InputError(folder / "summary.parquet", "-", "no runs stored yet")
    return df, man


def metric_columns(df) -> list:
    """Numeric metric columns (not ids, parameters or execution records), key metrics first."""
    out = []
    for c in df.columns:
        if c in ID_COLUMNS or "." in c or c.startswith("requested:"):
            continue
        v = df[c]
        if v.dtype == bool or v.dtype == object and v.dropna().map(lambda x: isinstance(x, bool)).all():
            continue
        num = np.asarray(v.map(lambda x: np.nan if x is None else x), dtype=float) if v.dtype == object else \
            v.to_numpy(dtype=float, na_value=np.nan)
        if np.isfinite(num).any():
            out.append(c)
    return [m for m in KEY_METRICS if m in out] + [m for m in out if m not in KEY_METRICS]


def _values(df, col) -> np.ndarray:
    v = df[col]
    return np.array([np.nan if x is None else float(x) for x in v], dtype=float)


def units(folder: Path, df) -> dict:
    """{column: unit}: the summary's Parquet field metadata, else that of a stored run file (a
    summary rewritten by a tool that drops field metadata), else :data:`UNITS`."""
    found = dict(UNITS)
    for path in sorted((folder / "runs").glob("*.parquet"))[:1]:
        try:
            found.update(read_table(path).attrs.get("units", {}))
        except InputError:  # a damaged run file: the summary's units and UNITS
            pass
    found.update(df.attrs.get("units", {}))
    return found


def _point_labels(man) -> list[str]:
    """One label per grid point, in the campaign's point order ("k_d = 30, k_p = 2"; [] without a grid)."""
    grid = [(g["parameter"], g["values"]) for g in (man.get("grid") or []) if isinstance(g, dict)]
    if not grid:
        return []
    return [", ".join(f"{ref} = {_fmt(v) if not isinstance(v, list) else v}" for (ref, _), v in zip(grid, combo))
            for combo in itertools.product(*[vals for _, vals in grid])]


def with_groups(df, man):
    """``df`` with a ``group`` column (the variant, and the grid point when the campaign sweeps one)
    and an ``ok`` column (finished: status ok and no error)."""
    df = df.copy()
    labels = _point_labels(man)
    if labels and "point" in df.columns:
        def label(row):
            p = row["point"]
            at = labels[int(p)] if p is not None and 0 <= int(p) < len(labels) else f"point {p}"
            return f"{row['variant']} @ {at}"
        df["group"] = df.apply(label, axis=1)
    else:
        df["group"] = df["variant"].astype(str)
    status = df["status"] if "status" in df.columns else "ok"
    error = df["error"] if "error" in df.columns else None
    ok = (status == "ok") if not isinstance(status, str) else np.ones(len(df), bool)
    if error is not None:
        ok = ok & error.map(lambda e: e is None or (isinstance(e, float) and math.isnan(e)) or e == "")
    df["ok"] = np.asarray(ok, dtype=bool)
    return df


def _groups(df) -> list:
    return list(dict.fromkeys(df["group"]))


def statistics(df, metrics) -> list:
    """Per metric and group, over the finished runs: n with a value of all finished runs, mean with
    its 95 % CI half-width, std, median, 5 / 95 % quantiles, extremes. Rows without a value are left out."""
    rows = []
    good = df[df["ok"]]
    for m in metrics:
        for grp in _groups(df):
            g = good[good["group"] == grp]
            x = _values(g, m)
            f = x[np.isfinite(x)]
            if len(f) == 0:
                continue
            mean, half = mean_ci(f)
            med, med_lo, med_hi = median_ci(f)
            rows.append({"metric": m, "group": grp, "variant": g["variant"].iloc[0],
                         "point": None if g["point"].iloc[0] is None else int(g["point"].iloc[0]),
                         "n": len(f), "of": len(x), "mean": mean, "ci95": half,
                         "std": float(f.std(ddof=1)) if len(f) > 1 else None, "median": med,
                         "median_ci_low": med_lo, "median_ci_high": med_hi,
                         "p5": float(np.quantile(f, 0.05)), "p95": float(np.quantile(f, 0.95)),
                         "min": float(f.min()), "max": float(f.max())})
    return rows


def paired(df, metrics) -> list:
    """Differences of every variant from the first variant at the same grid point, on the same
    draw; finished runs on both sides only."""
    variants = list(dict.fromkeys(df["variant"]))
    if len(variants) < 2:
        return []
    good = df[df["ok"]]
    ref = good[good["variant"] == variants[0]].set_index(["point", "draw"])
    rows = []
    for grp in _groups(df):
        g = good[good["group"] == grp]
        if g.empty or g["variant"].iloc[0] == variants[0]:
            continue
        g = g.set_index(["point", "draw"])
        common = ref.index.intersection(g.index)
        ref_group = ref.loc[common, "group"].iloc[0] if len(common) else variants[0]
        for m in metrics:
            d = _values(g.loc[common], m) - _values(ref.loc[common], m)
            n = int(np.isfinite(d).sum())
            if n == 0:
                continue
            mean, half = mean_ci(d)
            rows.append({"metric": m, "group": grp, "variant": str(g["variant"].iloc[0]), "reference": ref_group,
                         "pairs": n, "mean_difference": mean, "ci95": half})
    return rows


def requirements(df, reqs) -> tuple[dict, list]:
    """Per-run pass (bool array per metric and 'all'; a failed run never passes) and per-group pass
    fractions with their 95 % Wilson intervals."""
    passes = {}
    ok_run = df["ok"].to_numpy(bool)
    for m, b in reqs.items():
        x = _values(df, m) if m in df.columns else np.full(len(df), np.nan)
        ok = np.isfinite(x) & ok_run
        if "max" in b:
            ok &= x <= b["max"]
        if "min" in b:
            ok &= x >= b["min"]
        passes[m] = ok
    if passes:
        passes["all"] = np.logical_and.reduce(list(passes.values()))
    rows = []
    for m, ok in passes.items():
        for grp in _groups(df):
            sel = (df["group"] == grp).to_numpy()
            k, n = int(ok[sel].sum()), int(sel.sum())
            lo, hi = wilson(k, n)
            rows.append({"requirement": m, "group": grp, "variant": str(df.loc[sel, "variant"].iloc[0]), "passed": k,
                         "runs": n, "failed": int((sel & ~ok_run).sum()), "fraction": k / n if n else None,
                         "ci_low": lo, "ci_high": hi})
    return passes, rows


def _plots(df, man, folder: Path, out: Path, metrics, unit) -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = []
    good = df[df["ok"]]
    groups = _groups(good)
    shown = metrics[:6]
    if shown and len(good):
        fig, axes = plt.subplots(len(shown), 1, figsize=(7, 2.2 * len(shown) + 0.4), squeeze=False)
        for ax, m in zip(axes[:, 0], shown):
            for grp in groups:
                x = _values(good[good["group"] == grp], m)
                x = x[np.isfinite(x)]
                if len(x):
                    ax.hist(x, bins=min(30, max(5, len(x) // 4)), alpha=0.5, label=f"{grp} (n={len(x)})")
            ax.set_xlabel(f"{m} [{unit[m]}]" if unit.get(m) else m)
            ax.set_ylabel("runs")
            ax.legend(fontsize=7)
            ax.grid(True, lw=0.3)
        fig.suptitle(f"{man.get('campaign', '')}: metric distributions (finished runs)")
        fig.tight_layout()
        plain_text(fig).savefig(out / "metrics.png", dpi=110)  # metric names and units as plain text
        plt.close(fig)
        files.append("metrics.png")
    traj = folder / "trajectories"
    signals = man.get("trajectories") or []
    if signals and traj.is_dir() and len(good):

        try:
            tr = read_folder(traj)
        except InputError:
            return files
        tr["run_id"] = tr["run_id"].astype(int)
        tr = tr.merge(good[["run_id", "group"]], on="run_id")
        cols = [s for s in signals if s in tr.columns]
        if not cols or tr.empty:
            return files
        fig, axes = plt.subplots(len(cols), 1, figsize=(8, 1.9 * len(cols) + 0.6), sharex=True, squeeze=False)
        for ax, col in zip(axes[:, 0], cols):
            for grp in groups:
                g = tr[tr["group"] == grp].pivot_table(index="time", columns="run_id", values=col)
                if g.empty:
                    continue
                mu, sd = g.mean(axis=1), g.std(axis=1, ddof=1).fillna(0.0)
                line = ax.plot(g.index, mu, lw=1.0, label=f"{grp} mean")[0]
                ax.fill_between(g.index, mu - 3 * sd, mu + 3 * sd, color=line.get_color(), alpha=0.2,
                                label=f"{grp} mean +/- 3 sigma")
            ax.set_ylabel(col, fontsize=7)
            ax.grid(True, lw=0.3)
        axes[0, 0].legend(fontsize=6, ncol=2)
        axes[-1, 0].set_xlabel("time [s]")
        fig.suptitle(f"{man.get('campaign', '')}: trajectories, mean and 3-sigma envelope per group")
        fig.tight_layout()
        plain_text(fig).savefig(out / "envelopes.png", dpi=110)
        plt.close(fig)
        files.append("envelopes.png")
    return files


def _ci(mean, half) -> str:
    return _fmt(mean) if half is None else f"{_fmt(mean)} ± {_fmt(half, 2)}"


def _median_ci(r) -> str:
    if r.get("median_ci_low") is None:
        return _fmt(r["median"])
    return f"{_fmt(r['median'])} [{_fmt(r['median_ci_low'], 3)}, {_fmt(r['median_ci_high'], 3)}]"


def make_report(folder, out) -> dict:
    """Write report.md, report.html, report.json and the plots of campaign folder ``folder`` into
    ``out`` (a folder that exists). Returns the report's data."""
    import pandas as pd

    folder, out = Path(folder), Path(out)
    df, man = load_folder(folder)
    df = with_groups(df, man)
    unit = units(folder, df)
    good_idx = np.flatnonzero(df["ok"].to_numpy(bool))
    metrics = metric_columns(df.iloc[good_idx]) if len(good_idx) else []
    stats = statistics(df, metrics)
    pairs = paired(df, metrics)
    reqs = man.get("requirements") or {}
    passes, req_rows = requirements(df, reqs)
    failed = df[~df["ok"]]
    dispersed = [c for c in df.columns if "." in c and not c.startswith("requested:")]
    worst_of = [m for m in reqs if m in df.columns] or metrics[:3]
    worst = {}
    for m in worst_of:
        x = _values(df, m)
        x[~df["ok"].to_numpy(bool)] = np.nan  # a failed run is not ranked
        bound = reqs.get(m, {})
        larger_is_worse = "max" in bound or "min" not in bound
        finite = np.flatnonzero(np.isfinite(x))
        order = finite[np.argsort(-x[finite] if larger_is_worse else x[finite], kind="stable")]
        worst[m] = [int(i) for i in order[:WORST]]
    plots = _plots(df, man, folder, out, metrics, unit)

    def u(col, label=None):
        return f"{label or col} [{unit_tag(unit[col])}]" if unit.get(col) else (label or col)

    doc = Document(f"Campaign {man.get('campaign', folder.name)}", out)
    intro = []
    if man.get("description"):
        intro.append(str(man["description"]))
    grid = man.get("grid") or []
    intro.append(f"{len(df)} of {man.get('runs', len(df))} runs stored ({man.get('status', '?')}); {len(failed)} failed "
                 f"(not in the statistics). Draws: {man.get('draws')} per variant and grid point, seed {man.get('seed')}, "
                 f"mode {man.get('mode')}. Folder: `{folder}`.")
    intro.append("Dispersions: " + (", ".join(f"`{d['parameter']}` ({d['distribution']}, {d['apply']})"
                                              for d in man.get("dispersions", [])) or "none") + "."
                 + (" Grid: " + "; ".join(f"`{g['parameter']}` over {g['values']}" for g in grid)
                    + " (one group per variant and grid point)." if grid else ""))
    doc.text("\n\n".join(intro))
    if stats:
        doc.heading("Metrics per group")
        doc.text("Over the finished runs: mean with the half-width of its 95 % confidence interval (Student t); "
                 f"median with its 95 % percentile-bootstrap interval ({BOOTSTRAP_RESAMPLES} resamples, seed "
                 f"{BOOTSTRAP_SEED}); n = runs with a value (e.g. runs that settled) of the finished runs.")
        for m in metrics:
            rs = [r for r in stats if r["metric"] == m]
            if not rs:
                continue
            un = unit.get(m)
            cols = {"mean ± 95 % CI": "mean", "std": "std", "median [95 % CI]": "median", "5 %": "p5", "95 %": "p95",
                    "min": "min", "max": "max"}
            t = pd.DataFrame([{"metric": m, "group": r["group"], "n": f"{r['n']}/{r['of']}",
                               "mean ± 95 % CI": _ci(r["mean"], r["ci95"]),
                               **{k: r[v] for k, v in cols.items() if v not in ("mean", "median")},
                               "median [95 % CI]": _median_ci(r)} for r in rs])
            t = t[["metric", "group", "n", *cols]]
            doc.table(t, caption=u(m), units={c: un for c in cols} if un else None)
    if pairs:
        doc.heading("Differences from the first variant on the same draws")
        doc.text("Paired by grid point and draw (finished runs on both sides); a 95 % interval that excludes 0 is a "
                 "difference the campaign resolves.")
        for m in metrics:
            rs = [r for r in pairs if r["metric"] == m]
            if rs:
                t = pd.DataFrame([{"metric": m, "group": f"{r['group']} - {r['reference']}", "pairs": r["pairs"],
                                   "mean difference ± 95 % CI": _ci(r["mean_difference"], r["ci95"])} for r in rs])
                doc.table(t, caption=u(m), units={"mean difference ± 95 % CI": unit[m]} if unit.get(m) else None)
    if req_rows:
        doc.heading("Requirements")
        doc.text("A run passes when it finished and the metric exists and lies within the bounds ("
                 + "; ".join(f"{u(m)}: " + ", ".join(f"{k} {v:g}" for k, v in b.items()) for m, b in reqs.items())
                 + "). Pass fraction of all runs of the group (failed runs count as not passing) with its 95 % "
                 "Wilson interval.")
        doc.table(pd.DataFrame([{"requirement": r["requirement"], "group": r["group"], "passed": f"{r['passed']}/{r['runs']}",
                                 "failed runs": r["failed"], "fraction": r["fraction"], "95 % CI low": r["ci_low"],
                                 "95 % CI high": r["ci_high"]} for r in req_rows]), digits=3)
    camp = man.get("campaign_file", "CAMPAIGN.toml")
    for m, idx in worst.items():
        if not idx:
            continue
        doc.heading(f"Worst runs by {m}")
        t = pd.DataFrame([{"run": int(df.iloc[i]["run_id"]), "group": df.iloc[i]["group"], "draw": int(df.iloc[i]["draw"]),
                           "seed": int(df.iloc[i]["seed"]), m: df.iloc[i][m], **{c: df.iloc[i][c] for c in dispersed[:6]}}
                          for i in idx])
        doc.table(t, units={c: unit[c] for c in [m, *dispersed[:6]] if unit.get(c)})
        doc.text(f"Replay one as an ordinary run: `ftcsim campaign {camp} --replay {int(df.iloc[idx[0]]['run_id'])} --out DIR`.")
    if len(failed):
        doc.heading("Failed runs")
        doc.text(f"{len(failed)} run(s) did not finish; they are not in the statistics, differences or worst runs"
                 + (" (the first 50 shown)." if len(failed) > 50 else "."))
        t = pd.DataFrame([{"run": int(r["run_id"]), "group": r["group"], "draw": int(r["draw"]), "status": r.get("status"),
                           "error": " ".join(str(r.get("error") or "").split())[:300]} for _, r in failed.head(50).iterrows()])
        doc.table(t, failed_rows=[True] * len(t))
    add_figures(doc, plots, "Plots")
    doc.write()
    data = {"campaign": man.get("campaign"), "runs": len(df), "statistics": stats, "paired": pairs,
            "requirements": req_rows, "worst": {m: [int(df.iloc[i]["run_id"]) for i in idx] for m, idx in worst.items()},
            "failed": [int(x) for x in failed["run_id"]], "plots": plots, "units": {m: unit.get(m) for m in metrics}}
    write_json_atomic(out / "report.json", data)
    return data
