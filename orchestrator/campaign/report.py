"""``ftcsim campaign-report DIR [--out REPORT]``: what a campaign found, as report.md and PNG plots.

From a campaign folder (``ftcsim campaign``): for every metric and variant the number of runs
with a value, mean with its 95 % confidence interval (Student t), standard deviation,
median, 5 % / 95 % quantiles and extremes; the variants' differences from the first variant on
the same draws (paired: matched by grid point and draw, mean difference with its 95 % interval);
the requirements of the campaign file (``[requirements]``: a run passes when the metric exists
and lies within its bounds; the pass fraction with its 95 % Wilson interval); the worst runs of
every requirement (or of the first metrics) with their draw, seed and dispersed values, and the
command that replays one as an ordinary run; histograms of the metrics and, for the stored
trajectories, mean and 3-sigma envelopes over time per variant. Runs that failed are listed
with their error. The report folder (default ``DIR/report``) follows
:mod:`orchestrator.common.outputs` (kind ``campaign-report``; ``--overwrite`` replaces a previous one).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import write_json_atomic
from orchestrator.common.outputs import is_result_folder

KEY_METRICS = ("control_energy", "final_attitude_error", "settling_time", "final_rate_error", "max_abs_u")
ID_COLUMNS = ("run_id", "key", "variant", "point", "draw", "seed", "status", "error", "wall_time_s", "cpu_time_s",
              "sim_time_s", "worker",
              "t_end", "steps", "step", "u_max")
WORST = 5


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


def wilson(k: int, n: int, z=1.959963984540054):
    """95 % Wilson score interval of a proportion k / n."""
    if n == 0:
        return None, None
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return max(0.0, c - h), min(1.0, c + h)


def _fmt(x, digits=4):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if isinstance(x, (bool, np.bool_)):
        return str(bool(x))
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    return f"{float(x):.{digits}g}"


def load_folder(folder: Path):
    import pandas as pd

    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(folder, "-", "campaign folder not found")
    if not is_result_folder(folder, "campaign"):
        raise InputError(folder, "-", "not a campaign folder of `ftcsim campaign` (no campaign marker)")
    for f in ("summary.parquet", "manifest.json"):
        if not (folder / f).is_file():
            raise InputError(folder, f, "missing: rerun `ftcsim campaign` on this folder to write it")
    try:
        df = pd.read_parquet(folder / "summary.parquet")
    except Exception as e:
        raise InputError(folder / "summary.parquet", "-", f"unreadable: {' '.join(str(e).split())[:200]}") from None
    try:
        man = json.loads((folder / "manifest.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise InputError(folder / "manifest.json", "-", f"unreadable: {e}") from None
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


def statistics(df, metrics) -> list:
    rows = []
    for m in metrics:
        for var, g in df.groupby("variant", sort=False):
            x = _values(g, m)
            f = x[np.isfinite(x)]
            mean, half = mean_ci(f)
            rows.append({"metric": m, "variant": var, "n": len(f), "of": len(x), "mean": mean, "ci95": half,
                         "std": float(f.std(ddof=1)) if len(f) > 1 else None,
                         "median": float(np.median(f)) if len(f) else None,
                         "p5": float(np.quantile(f, 0.05)) if len(f) else None,
                         "p95": float(np.quantile(f, 0.95)) if len(f) else None,
                         "min": float(f.min()) if len(f) else None, "max": float(f.max()) if len(f) else None})
    return rows


def paired(df, metrics) -> list:
    """Differences of every variant from the first on the same (point, draw)."""
    variants = list(dict.fromkeys(df["variant"]))
    if len(variants) < 2:
        return []
    ref = df[df["variant"] == variants[0]].set_index(["point", "draw"])
    rows = []
    for var in variants[1:]:
        g = df[df["variant"] == var].set_index(["point", "draw"])
        common = ref.index.intersection(g.index)
        for m in metrics:
            d = _values(g.loc[common], m) - _values(ref.loc[common], m)
            mean, half = mean_ci(d)
            rows.append({"metric": m, "variant": var, "reference": variants[0], "pairs": int(np.isfinite(d).sum()),
                         "mean_difference": mean, "ci95": half})
    return rows


def requirements(df, reqs) -> tuple[dict, list]:
    """Per-run pass (bool array per metric and 'all') and per-variant pass fractions."""
    passes = {}
    for m, b in reqs.items():
        x = _values(df, m) if m in df.columns else np.full(len(df), np.nan)
        ok = np.isfinite(x)
        if "max" in b:
            ok &= x <= b["max"]
        if "min" in b:
            ok &= x >= b["min"]
        passes[m] = ok
    if passes:
        passes["all"] = np.logical_and.reduce(list(passes.values()))
    rows = []
    for m, ok in passes.items():
        for var in dict.fromkeys(df["variant"]):
            sel = (df["variant"] == var).to_numpy()
            k, n = int(ok[sel].sum()), int(sel.sum())
            lo, hi = wilson(k, n)
            rows.append({"requirement": m, "variant": var, "passed": k, "runs": n, "fraction": k / n if n else None,
                         "ci_low": lo, "ci_high": hi})
    return passes, rows


def _plots(df, man, folder: Path, out: Path, metrics) -> list:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = []
    variants = list(dict.fromkeys(df["variant"]))
    shown = metrics[:6]
    if shown:
        fig, axes = plt.subplots(len(shown), 1, figsize=(7, 2.2 * len(shown) + 0.4), squeeze=False)
        for ax, m in zip(axes[:, 0], shown):
            for var in variants:
                x = _values(df[df["variant"] == var], m)
                x = x[np.isfinite(x)]
                if len(x):
                    ax.hist(x, bins=min(30, max(5, len(x) // 4)), alpha=0.5, label=f"{var} (n={len(x)})")
            ax.set_xlabel(m)
            ax.set_ylabel("runs")
            ax.legend(fontsize=7)
            ax.grid(True, lw=0.3)
        fig.suptitle(f"{man.get('campaign', '')}: metric distributions")
        fig.tight_layout()
        fig.savefig(out / "metrics.png", dpi=110)
        plt.close(fig)
        files.append("metrics.png")
    traj = folder / "trajectories"
    signals = man.get("trajectories") or []
    if signals and traj.is_dir():
        import pandas as pd

        try:
            tr = pd.read_parquet(traj)
        except Exception:
            return files
        tr["run_id"] = tr["run_id"].astype(int)
        tr = tr.merge(df[["run_id", "variant"]], on="run_id")
        cols = [s for s in signals if s in tr.columns]
        fig, axes = plt.subplots(len(cols), 1, figsize=(8, 1.9 * len(cols) + 0.6), sharex=True, squeeze=False)
        for ax, col in zip(axes[:, 0], cols):
            for var in variants:
                g = tr[tr["variant"] == var].pivot_table(index="time", columns="run_id", values=col)
                if g.empty:
                    continue
                mu, sd = g.mean(axis=1), g.std(axis=1, ddof=1).fillna(0.0)
                line = ax.plot(g.index, mu, lw=1.0, label=f"{var} mean")[0]
                ax.fill_between(g.index, mu - 3 * sd, mu + 3 * sd, color=line.get_color(), alpha=0.2,
                                label=f"{var} mean +/- 3 sigma")
            ax.set_ylabel(col, fontsize=7)
            ax.grid(True, lw=0.3)
        axes[0, 0].legend(fontsize=6, ncol=2)
        axes[-1, 0].set_xlabel("time [s]")
        fig.suptitle(f"{man.get('campaign', '')}: trajectories, mean and 3-sigma envelope per variant")
        fig.tight_layout()
        fig.savefig(out / "envelopes.png", dpi=110)
        plt.close(fig)
        files.append("envelopes.png")
    return files


def make_report(folder, out) -> dict:
    """Write report.md, report.json and the plots of campaign folder ``folder`` into ``out``
    (a folder that exists). Returns the report's data."""
    folder, out = Path(folder), Path(out)
    df, man = load_folder(folder)
    metrics = metric_columns(df)
    stats = statistics(df, metrics)
    pairs = paired(df, metrics)
    passes, req_rows = requirements(df, man.get("requirements") or {})
    failed = df[df["status"] != "ok"]
    dispersed = [c for c in df.columns if "." in c and not c.startswith("requested:")]
    worst_of = [m for m in (man.get("requirements") or {}) if m in df.columns] or metrics[:3]
    worst = {}
    for m in worst_of:
        x = _values(df, m)
        bound = (man.get("requirements") or {}).get(m, {})
        larger_is_worse = "max" in bound or "min" not in bound
        order = np.argsort(np.where(np.isfinite(x), -x if larger_is_worse else x, -np.inf), kind="stable")
        worst[m] = [int(i) for i in order[:WORST]]
    plots = _plots(df, man, folder, out, metrics)

    L = [f"# Campaign {man.get('campaign', folder.name)}", ""]
    if man.get("description"):
        L += [man["description"], ""]
    L += [f"{len(df)} of {man.get('runs', len(df))} runs stored ({man.get('status', '?')}); "
          f"{len(failed)} not ok. Draws: {man.get('draws')} per variant and grid point, seed {man.get('seed')}, "
          f"mode {man.get('mode')}. Folder: `{folder}`.", ""]
    L += ["Dispersions: " + (", ".join(f"`{d['parameter']}` ({d['distribution']}, {d['apply']})"
                                       for d in man.get("dispersions", [])) or "none") + ".", ""]
    L += ["## Metrics per variant", "", "Mean with the half-width of its 95 % confidence interval (Student t); "
          "n = runs with a value (e.g. runs that settled) of all runs.", "",
          "| metric | variant | n | mean +/- 95 % CI | std | median | 5 % | 95 % | min | max |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for r in stats:
        ci = f"{_fmt(r['mean'])} +/- {_fmt(r['ci95'], 2)}" if r["ci95"] is not None else _fmt(r["mean"])
        L.append(f"| {r['metric']} | {r['variant']} | {r['n']}/{r['of']} | {ci} | {_fmt(r['std'])} | "
                 f"{_fmt(r['median'])} | {_fmt(r['p5'])} | {_fmt(r['p95'])} | {_fmt(r['min'])} | {_fmt(r['max'])} |")
    if pairs:
        L += ["", f"## Differences from {pairs[0]['reference']} on the same draws", "",
              "Paired by grid point and draw; a 95 % interval that excludes 0 is a difference the campaign resolves.",
              "", "| metric | variant | pairs | mean difference +/- 95 % CI |", "|---|---|---|---|"]
        for r in pairs:
            ci = f"{_fmt(r['mean_difference'])} +/- {_fmt(r['ci95'], 2)}" if r["ci95"] is not None else \
                _fmt(r["mean_difference"])
            L.append(f"| {r['metric']} | {r['variant']} - {r['reference']} | {r['pairs']} | {ci} |")
    if req_rows:
        L += ["", "## Requirements", "", "A run passes when the metric exists and lies within the bounds "
              "(" + "; ".join(f"{m}: " + ", ".join(f"{k} {v:g}" for k, v in b.items())
                              for m, b in man["requirements"].items()) + "). Pass fraction with its 95 % Wilson "
              "interval.", "", "| requirement | variant | passed | fraction [95 % CI] |", "|---|---|---|---|"]
        for r in req_rows:
            L.append(f"| {r['requirement']} | {r['variant']} | {r['passed']}/{r['runs']} | {_fmt(r['fraction'], 3)} "
                     f"[{_fmt(r['ci_low'], 3)}, {_fmt(r['ci_high'], 3)}] |")
    camp = man.get("campaign_file", "CAMPAIGN.toml")
    for m, idx in worst.items():
        L += ["", f"## Worst runs by {m}", "", "| run | variant | draw | seed | " + m + " | "
              + " | ".join(dispersed[:6]) + " |", "|---" * (5 + len(dispersed[:6])) + "|"]
        for i in idx:
            r = df.iloc[i]
            L.append(f"| {int(r['run_id'])} | {r['variant']} | {int(r['draw'])} | {int(r['seed'])} | {_fmt(r[m])} | "
                     + " | ".join(_fmt(r[c]) for c in dispersed[:6]) + " |")
        if idx:
            L += ["", f"Replay one as an ordinary run: `ftcsim campaign {camp} --replay "
                      f"{int(df.iloc[idx[0]]['run_id'])} --out DIR`."]
    if len(failed):
        L += ["", "## Runs not ok", "", "| run | variant | draw | status | error |", "|---|---|---|---|---|"]
        for _, r in failed.head(50).iterrows():
            L.append(f"| {int(r['run_id'])} | {r['variant']} | {int(r['draw'])} | {r['status']} | "
                     f"{str(r['error'])[:200].replace('|', '/')} |")
    if plots:
        L += ["", "## Plots", ""] + [f"![{p}]({p})" for p in plots]
    (out / "report.md").write_text("\n".join(L) + "\n", encoding="utf-8")
    data = {"campaign": man.get("campaign"), "runs": len(df), "statistics": stats, "paired": pairs,
            "requirements": req_rows, "worst": {m: [int(df.iloc[i]["run_id"]) for i in idx] for m, idx in worst.items()},
            "failed": [int(x) for x in failed["run_id"]], "plots": plots}
    write_json_atomic(out / "report.json", data)
    return data
