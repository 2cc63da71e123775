"""The arena's verdicts from its measured runs (pandas): outcome counts, metrics and ranks, accuracy
with realistic hardware, feasibility against the data-sheet wheels, paired comparisons, the
FDIR chains (displayed from ``arena/fdir.py``), the summary and the headline findings. One place computes every count the page
and the Parquet tables print.

Rules (stated on the page by :func:`rules`):

* a run's outcome is ``arena/measure.py``'s; ``failed`` runs produced nothing and are counted apart,
  never ranked; ``stopped`` runs are results: they do not fly and do not keep accuracy;
* a fault class outside the method's claims (``[methods.NAME] claims``, from its paper's fault model)
  is measured and shown as such ("outside the method's claims"), never counted in the summary's
  symbols; "none" is within every method's claims;
* a deterministic run (no fault, ideal hardware) is one run, shown as one point (n = 1, no interval);
* medians with percentile-bootstrap intervals; ranks per plant, hardware and fault class on the
  median attitude error after settling among the methods that fly in at least half of their runs;
* paired comparisons and significance: ``arena/stats.py``; the FDIR chains: ``arena/fdir.py``.
"""
from __future__ import annotations

import itertools
import math

import pandas as pd

from . import stats as S

OUTCOMES = ("flies", "not settled", "saturated", "diverged", "stopped", "failed")
FLY_SHARE = 0.5
PAIRED = ("attitude_error_rms_after", "final_attitude_error", "control_energy")
OUTSIDE = "outside the method's claims"
WITHIN = "within"
SYMBOLS = {"all": "✔", "some": "◐", "none": "✘", "absent": "·"}


def _rng(arena, *names):
    return S.generator(arena.seed, *names)


def _fmt(x, digits: int = 3) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—"
    return f"{x:.{digits}g}"


def _with_ci(v, lo, hi, digits: int = 3) -> str:
    """'v [lo, hi]' ('v' alone without an interval; '—' without a value)."""
    if v is None:
        return "—"
    if lo is None:
        return f"{_fmt(v, digits)} (n = 1)"
    return f"{_fmt(v, digits)} [{_fmt(lo, digits)}, {_fmt(hi, digits)}]"


def results(runs: pd.DataFrame) -> pd.DataFrame:
    """The runs that are results (every outcome but ``failed``)."""
    return runs[runs["outcome"] != "failed"]


# -- outcomes -------------------------------------------------------------------------------------------------
def outcome_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per plant, method, hardware and fault class: runs, outcome counts, not buildable (ideal)."""
    keys = ["plant", "method", "hardware", "fault"]
    rows = []
    for k, g in runs.groupby(keys, sort=True):
        r = dict(zip(keys, k))
        r["claims"] = WITHIN if bool(g["within_claims"].iloc[0]) else OUTSIDE
        r["runs"] = len(g)
        for o in OUTCOMES:
            r[o] = int((g["outcome"] == o).sum())
        r["not buildable"] = int((g["buildable"] == False).sum()) if k[2] == "ideal" else None  # noqa: E712
        r["deterministic"] = bool(g["deterministic"].iloc[0])
        rows.append(r)
    return pd.DataFrame(rows)


def stopped_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Stopped runs per cell, hardware and fault class: how many of the runs, when (median), why (the
    most frequent reason)."""
    keys = ["plant", "method", "hardware", "fault"]
    sizes = runs.groupby(keys).size()
    rows = []
    for k, g in runs[runs["outcome"] == "stopped"].groupby(keys, sort=True):
        reason = g["stop_reason"].fillna("").map(_short_reason).value_counts().index[0]
        rows.append({**dict(zip(keys, k)), "stopped": f"{len(g)}/{int(sizes[k])}",
                     "stop_time": float(g["stop_time"].median()), "reason": reason})
    return pd.DataFrame(rows)


def _short_reason(text: str, limit: int = 90) -> str:
    """The part of an FMU error that says what happened (after the last 'FMU log:'), shortened."""
    t = " ".join(str(text).split())
    if "FMU log:" in t:
        t = t.rsplit("FMU log:", 1)[1].strip()
    return t if len(t) <= limit else t[:limit - 1] + "…"


# -- metrics and ranks ------------------------------------------------------------------------------------------
def metrics_table(arena, runs: pd.DataFrame) -> pd.DataFrame:
    """Per plant, hardware, fault class and method: the flying runs' medians with bootstrap intervals
    (time to band, attitude error after settling), peak torque and momentum over every result, and
    the rank on the attitude error (module docstring)."""
    rows = []
    st = arena.statistics
    res = results(runs)
    for (plant, hw, fault), g in res.groupby(["plant", "hardware", "fault"], sort=True):
        entries = []
        for method, gm in g.groupby("method", sort=True):
            fly = gm[gm["outcome"] == "flies"]
            e = {"plant": plant, "hardware": hw, "fault": fault, "method": method,
                 "claims": WITHIN if bool(gm["within_claims"].iloc[0]) else OUTSIDE, "runs": len(gm),
                 "flies": len(fly), "fly_share": len(fly) / len(gm)}
            for m in ("time_to_band", "attitude_error_rms_after"):
                v, lo, hi = S.median_interval(fly[m].dropna().astype(float), resamples=st.bootstrap,
                                              confidence=st.confidence, rng=_rng(arena, plant, hw, fault, method, m))
                e[m], e[f"{m}_low"], e[f"{m}_high"] = v, lo, hi
            for m in ("peak_torque", "peak_momentum", "control_energy"):
                v = gm[m].dropna().astype(float)
                e[f"{m}_median"] = float(v.median()) if len(v) else None
            entries.append(e)
        ranked = sorted([e for e in entries if e["fly_share"] >= FLY_SHARE and e["attitude_error_rms_after"] is not None],
                        key=lambda e: e["attitude_error_rms_after"])
        for i, e in enumerate(ranked):
            e["rank"] = str(i + 1)
        for e in entries:
            e.setdefault("rank", "cannot fly" if e["fly_share"] < FLY_SHARE else "no value")
        rows += ranked + [e for e in entries if e not in ranked]
    return pd.DataFrame(rows)


def metrics_display(mt: pd.DataFrame) -> pd.DataFrame:
    """The metrics table as the page shows it (intervals as text)."""
    if mt.empty:
        return mt
    return pd.DataFrame({
        "method": mt["method"], "hardware": mt["hardware"], "fault": mt["fault"], "claims": mt["claims"],
        "rank": mt["rank"], "flies": [f"{a}/{b}" for a, b in zip(mt["flies"], mt["runs"])],
        "time to band [s]": [_with_ci(*x) for x in zip(mt["time_to_band"], mt["time_to_band_low"], mt["time_to_band_high"])],
        "attitude error after [rad]": [_with_ci(*x) for x in zip(mt["attitude_error_rms_after"],
                                                                  mt["attitude_error_rms_after_low"],
                                                                  mt["attitude_error_rms_after_high"])],
        "peak torque [N.m]": [_fmt(x) for x in mt["peak_torque_median"]],
        "peak momentum [N.m.s]": [_fmt(x) for x in mt["peak_momentum_median"]],
    })


# -- accuracy with realistic hardware --------------------------------------------------------------------------
def accuracy_table(arena, runs: pd.DataFrame) -> pd.DataFrame:
    """Does each method keep its paper's accuracy with realistic hardware? On its own plant (the
    paper's pair), over the fault classes within its claims: the realistic-hardware median attitude
    error after settling within ``accuracy_tolerance`` x the ideal median, and a settled share at
    least the ideal one minus 0.1. Stopped runs count as not settled."""
    rows = []
    own = results(runs)
    own = own[(own["gains"] == "own") & own["within_claims"]]
    for (method, plant), g in own.groupby(["method", "plant"], sort=True):
        r = {"method": method, "plant": plant, "tolerance": arena.accuracy_tolerance}
        for hw in ("ideal", "realistic"):
            gh = g[g["hardware"] == hw]
            fly = gh[gh["outcome"] == "flies"]["attitude_error_rms_after"].dropna()
            r[f"{hw}_runs"] = len(gh)
            r[f"{hw}_stopped"] = int((gh["outcome"] == "stopped").sum())
            r[f"{hw}_settled_share"] = len(fly) / len(gh) if len(gh) else None
            r[f"{hw}_median"] = float(fly.median()) if len(fly) else None
        i, x = r["ideal_median"], r["realistic_median"]
        if r["ideal_settled_share"] is None or r["realistic_settled_share"] is None:
            r["ratio"], r["keeps_accuracy"], r["verdict"] = None, None, "not flown with both hardware sets"
        elif i is None:
            r["ratio"], r["keeps_accuracy"], r["verdict"] = None, None, "no ideal-hardware accuracy to keep"
        else:
            r["ratio"] = None if x is None else (x / i if i > 0 else math.inf)
            r["keeps_accuracy"] = bool(x is not None and r["ratio"] <= arena.accuracy_tolerance
                                       and r["realistic_settled_share"] >= r["ideal_settled_share"] - 0.1)
            r["verdict"] = "keeps" if r["keeps_accuracy"] else (
                f"does not (stopped in {r['realistic_stopped']} of {r['realistic_runs']} runs)" if r["realistic_stopped"]
                else "does not")
        rows.append(r)
    return pd.DataFrame(rows)


# -- feasibility ------------------------------------------------------------------------------------------------
def feasibility_table(runs: pd.DataFrame, wheels: dict) -> pd.DataFrame:
    """Ideal hardware, per cell: runs whose peak torque and momentum no data-sheet wheel delivers,
    the largest peaks, and the smallest wheel that would fly every run."""
    from .measure import buildable

    rows = []
    ideal = results(runs)
    ideal = ideal[ideal["hardware"] == "ideal"]
    for (plant, method), g in ideal.groupby(["plant", "method"], sort=True):
        pt, pm = g["peak_torque"].dropna(), g["peak_momentum"].dropna()
        worst = buildable(float(pt.max()), float(pm.max()), wheels) if len(pt) and len(pm) else None
        rows.append({"plant": plant, "method": method, "runs": len(g),
                     "not_buildable": int((g["buildable"] == False).sum()),  # noqa: E712
                     "peak_torque_max": float(pt.max()) if len(pt) else None,
                     "peak_momentum_max": float(pm.max()) if len(pm) else None,
                     "wheel_for_every_run": worst or "none in the catalog"})
    return pd.DataFrame(rows)


def wheel_limit_table(arena, runs: pd.DataFrame) -> pd.DataFrame:
    """Realistic hardware: the largest wheel torque at the plant against the wheels' bound
    tau_max + c_c + c_v h_max / I_w (plant/hardware/wheels.py)."""
    from plant.hardware.datasheets import WHEELS
    from plant.hardware.wheels import torque_bound

    rows = []
    real = runs[(runs["hardware"] == "realistic") & runs["peak_torque"].notna()]
    for (plant, method), g in real.groupby(["plant", "method"], sort=True):
        name = arena.plants[plant].hardware["wheels"]
        p = WHEELS[name]
        bound = torque_bound(p["tau_max"], p["coulomb"], p["viscous"], p["h_max"], p["I_w"])
        peak = float(g["peak_torque"].max())
        rows.append({"plant": plant, "method": method, "wheels": name, "runs": len(g), "peak_wheel_torque": peak,
                     "bound": bound, "within": bool(peak <= bound + 1e-12)})
    return pd.DataFrame(rows)


# -- paired comparisons -------------------------------------------------------------------------------------------
def paired_table(arena, runs: pd.DataFrame) -> pd.DataFrame:
    """Two methods on the same plant, hardware and fault class, on the draws where both ran to the end
    and the metric is defined for both: median of A - B with its bootstrap interval, the share of
    draws where A is lower, the Wilcoxon p-value and its Holm adjustment over every comparison with
    at least ``min_pairs`` pairs; significant when that adjusted p <= alpha. Deterministic runs are
    one pair (never significant)."""
    st = arena.statistics
    rows = []
    done = runs[~runs["outcome"].isin(["failed", "stopped"])]
    for (plant, hw, fault), g in done.groupby(["plant", "hardware", "fault"], sort=True):
        g = g.drop_duplicates(["method", "draw"])
        table = {m: g.pivot(index="draw", columns="method", values=m).astype(float) for m in PAIRED}
        for a, b in itertools.combinations(sorted(g["method"].unique()), 2):
            for metric in PAIRED:
                d = (table[metric][a] - table[metric][b]).dropna().to_numpy()  # common draws, both defined
                med, lo, hi = S.median_interval(d, resamples=st.bootstrap, confidence=st.confidence,
                                                rng=_rng(arena, plant, hw, fault, a, b, metric))
                p = S.wilcoxon_p(d) if len(d) >= st.min_pairs else None
                rows.append({"plant": plant, "hardware": hw, "fault": fault, "metric": metric, "a": a, "b": b,
                             "pairs": len(d), "median_diff": med, "ci_low": lo, "ci_high": hi,
                             "a_lower_share": float((d < 0).mean()) if len(d) else None, "p": p})
    out = pd.DataFrame(rows)
    if out.empty:
        return out
    out["p_holm"] = S.holm(list(out["p"]))
    out["significant"] = [bool(p is not None and not (isinstance(p, float) and math.isnan(p)) and p <= st.alpha)
                          for p in out["p_holm"]]
    out["family"] = int(out["p"].notna().sum())
    return out


# -- FDIR chains ---------------------------------------------------------------------------------------------------
def _target_verdict(r) -> str:
    if r["h"] is None or (isinstance(r["h"], float) and math.isnan(r["h"])):
        return r["reason"] or "no threshold"
    if r["deterministic"]:
        return "1 deterministic run: no rate"
    if not r["certified"]:
        return "not certified (too few hours)"
    return "yes (by the rule)"


def chains_display(ch: pd.DataFrame) -> pd.DataFrame:
    """The FDIR chains, ranked within each plant and hardware set (arena/fdir.py)."""
    if ch.empty:
        return ch
    ch = ch.sort_values(["plant", "hardware", "rank"], key=lambda c: c.map(lambda v: 99 if v is None else v)
                        if c.name == "rank" else c, kind="stable")
    return pd.DataFrame({
        "plant": ch["plant"], "hardware": ch["hardware"], "rank": [_fmt(x) if x is not None else "—" for x in ch["rank"]],
        "chain": ch["chain"],
        f"first false alarms per hour, at most ({_fmt(ch['level'].iloc[0] * 100, 3)} %)": [
            "—" if d else _fmt(b) for b, d in zip(ch["upper_bound_per_hour"], ch["deterministic"])],
        "meets target": [_target_verdict(r) for _, r in ch.iterrows()],
        "missed": [_with_ci(*x, digits=2) for x in zip(ch["missed_share"], ch["missed_low"], ch["missed_high"])],
        "delay [s]": [_with_ci(*x) for x in zip(ch["delay_median"], ch["delay_low"], ch["delay_high"])],
        "isolation": ["—" if k is None or (isinstance(k, float) and math.isnan(k)) else f"{int(k)}/{int(n)} ({what})"
                      for k, n, what in zip(ch["isolation_correct"], ch["isolated_runs"], ch["isolation"])],
    })


def calibration_display(ch: pd.DataFrame) -> pd.DataFrame:
    """Each chain's threshold and the statistics behind it."""
    if ch.empty:
        return ch
    return pd.DataFrame({
        "chain": ch["chain"], "plant": ch["plant"], "hardware": ch["hardware"],
        "h (normalised statistic)": [_fmt(x) for x in ch["h"]],
        "fault-free runs": [f"{n}" + (f" (+{k} stopped)" if k else "") for n, k in zip(ch["fault_free_runs"],
                                                                                   ch["fault_free_stopped"])],
        "hours": [_fmt(x, 2) for x in ch["exposure_hours"]],
        "alarms": [("—" if n is None or (isinstance(n, float) and math.isnan(n)) else int(n)) for n in ch["false_alarms"]],
        "upper bound [/h]": [_fmt(x) for x in ch["upper_bound_per_hour"]],
        "certified": ["yes" if c else "no" for c in ch["certified"]],
    })


def closed_display(cl: pd.DataFrame) -> pd.DataFrame:
    if cl.empty:
        return cl
    return pd.DataFrame({
        "cell": cl["cell"], "hardware": cl["hardware"], "chain": cl["detector"].map(str.upper) + " + isolation + allocation",
        "detected": [f"{d}/{n}" for d, n in zip(cl["detected"], cl["runs"])],
        "isolated right": [f"{k}/{n}" for k, n in zip(cl["isolated_right"], cl["isolated"])],
        "delay [s]": [_fmt(x) for x in cl["delay_median"]],
        "to reconfiguration [s]": [_fmt(x) for x in cl["reconfiguration_median"]],
        "flies: FDIR / none": [f"{a}/{n} / {b}/{n}" for a, b, n in zip(cl["flies_fdir"], cl["flies_open"], cl["pairs"])],
        "error after settling [rad]: FDIR / none": [f"{_fmt(a)} / {_fmt(b)}" for a, b in zip(cl["error_fdir"],
                                                                                           cl["error_open"])],
        "Wilcoxon p": [_fmt(x, 2) for x in cl["p"]],
        "replay = loop": [f"{k}/{n}" for k, n in zip(cl["replay_matches"], cl["replayed"])],
    })


def sensors_display(sn: pd.DataFrame) -> pd.DataFrame:
    if sn.empty:
        return sn
    return pd.DataFrame({
        "cell": sn["cell"], "sensor fault": sn["fault"], "flies": [f"{k}/{n}" for k, n in zip(sn["flies"], sn["runs"])],
        "alarms after the onset": [("—" if a is None or (isinstance(a, float) and math.isnan(a)) else f"{int(a)}/{n}")
                                   for a, n in zip(sn["alarmed"], sn["scored"])],
        "delay [s]": [_fmt(x) for x in sn["delay_median"]],
        "named an actuator": [("—" if a is None or (isinstance(a, float) and math.isnan(a)) else f"{int(a)}/{n}")
                              for a, n in zip(sn["named_actuator"], sn["scored"])],
    })


# -- the summary and the headlines -------------------------------------------------------------------------------
def cell_symbol(g: pd.DataFrame) -> str:
    """The summary's text of one method on one plant with one hardware set (module docstring of the page)."""
    if g.empty:
        return SYMBOLS["absent"]
    res = results(g)
    within = res[res["within_claims"]]
    outside = res[~res["within_claims"]]
    n, k = len(within), int((within["outcome"] == "flies").sum())
    sym = SYMBOLS["none"] if n == 0 or k == 0 else SYMBOLS["all"] if k == n else SYMBOLS["some"]
    text = f"{sym} {k}/{n}" if n else "— 0/0"
    stopped = int((res["outcome"] == "stopped").sum())
    if stopped:
        text += f" ■{stopped}"
    nb = int((res["buildable"] == False).sum())  # noqa: E712
    if nb:
        text += f" ⊘{nb}"
    if len(outside):
        text += f" (†{int((outside['outcome'] == 'flies').sum())}/{len(outside)})"
    return text


def summary_table(arena, runs: pd.DataFrame) -> pd.DataFrame:
    """Plant by method: one row per method and hardware, one column per plant (:func:`cell_symbol`)."""
    plants = list(arena.plants)
    used = [p for p in plants if (runs["plant"] == p).any()]
    rows = []
    for m in arena.methods:
        if not (runs["method"] == m).any():
            continue
        for hw in arena.hardware:
            r = {"method": arena.methods[m].label, "hardware": hw}
            for p in used:
                g = runs[(runs["method"] == m) & (runs["plant"] == p) & (runs["hardware"] == hw)]
                r[p] = cell_symbol(g)
            rows.append(r)
    return pd.DataFrame(rows)


def legend(arena) -> str:
    return (f"{SYMBOLS['all']} every run within the method's claims flies; {SYMBOLS['some']} some do; "
            f"{SYMBOLS['none']} none does; k/n: runs that fly / runs within its claims (a deterministic fault-free "
            f"run counts once); ■k: k runs stopped (an FMU stopped them: counted as not flying); ⊘k: k runs no "
            f"data-sheet wheel could deliver (ideal hardware); (†k/n): runs {OUTSIDE} that fly; "
            f"{SYMBOLS['absent']} not flown.")


def headlines(arena, runs: pd.DataFrame, tables: dict) -> list:
    """One line per headline finding, computed from the tables."""
    lines = []
    n_res = len(results(runs))
    n_failed = int((runs["outcome"] == "failed").sum())
    lines.append(f"{len(runs)} runs stored ({n_res} results, {n_failed} failed without a result) for "
                 f"{len(arena.cells)} cells x {len(arena.hardware)} hardware x {len(arena.faults)} fault classes x "
                 f"{arena.draws} draws.")
    if arena.overrides:
        cut = f"missions cut to {arena.stop:g} s (not the papers' missions); " if "stop" in arena.overrides else ""
        lines.append(f"A slice: {cut}overrides {', '.join(f'{k} = {v}' for k, v in arena.overrides.items())}.")
    acc = tables["accuracy"]
    if len(acc):
        verdict = {r.method: (None if r.keeps_accuracy is None or pd.isna(r.keeps_accuracy) else bool(r.keeps_accuracy))
                   for r in acc.itertuples()}
        keep = [m for m, v in verdict.items() if v is True]
        lose = [r.method + (f" (stopped in {r.realistic_stopped}/{r.realistic_runs})" if r.realistic_stopped else "")
                for r in acc.itertuples() if verdict[r.method] is False]
        none = [m for m, v in verdict.items() if v is None]
        lines.append(f"Keep their paper's accuracy with realistic hardware: {', '.join(keep) or 'none'}; do not: "
                     f"{', '.join(lose) or 'none'}" + (f"; no ideal accuracy to keep: {', '.join(none)}" if none else "")
                     + ".")
    stopped = runs[runs["outcome"] == "stopped"]
    if len(stopped):
        parts = []
        keys = ["method", "plant", "hardware"]
        sizes = runs.groupby(keys).size()
        for k, g in sorted(stopped.groupby(keys), key=lambda kg: -len(kg[1]))[:3]:
            reason = g["stop_reason"].fillna("").map(lambda x: _short_reason(x, 60)).value_counts().index[0]
            parts.append(f"{k[0]} on {k[1]} {k[2]} {len(g)}/{int(sizes[k])} at {_fmt(float(g['stop_time'].median()))} s "
                         f"({reason})")
        n_more = stopped.groupby(keys).ngroups - len(parts)
        lines.append("Stopped (results: counted as not flying): " + "; ".join(parts)
                     + (f"; {n_more} more in the details" if n_more > 0 else "") + ".")
    ideal = results(runs)
    ideal = ideal[ideal["hardware"] == "ideal"]
    if len(ideal):
        nb = ideal[ideal["buildable"] == False]  # noqa: E712
        if len(nb):
            worst = nb.groupby("method")["peak_torque"].max().sort_values(ascending=False).head(3)
            lines.append(f"Not buildable: {len(nb)} of {len(ideal)} ideal-hardware runs exceed every data-sheet wheel "
                         "(torque or momentum); largest peaks " + ", ".join(f"{m} {_fmt(v)} N.m" for m, v in worst.items())
                         + ".")
        else:
            lines.append(f"Every ideal-hardware run ({len(ideal)}) is within a data-sheet wheel's torque and momentum.")
    mt = tables["metrics"]
    if len(mt):
        best = []
        for plant, g in mt[(mt["rank"] == "1") & (mt["hardware"] == "ideal") & (mt["claims"] == WITHIN)].groupby(
                "plant", sort=True):
            counts = g["method"].value_counts()
            best.append(f"{plant}: {', '.join(f'{m} ({c})' for m, c in counts.items())}")
        if best:
            lines.append("Most accurate after settling, ideal hardware (rank 1 in how many fault classes within its "
                         "claims): " + "; ".join(best) + ".")
    pt = tables["paired"]
    if len(pt):
        sig = int(pt["significant"].sum())
        lines.append(f"Paired comparisons: {sig} significant of {int(pt['p'].notna().sum())} with at least "
                     f"{arena.statistics.min_pairs} paired draws (Holm, family-wise {arena.statistics.alpha:g}); "
                     f"{int(pt['p'].isna().sum())} have too few pairs or identical pairs.")
    ch = tables["chains"]
    if len(ch):
        det = arena.detection
        random = ch[~ch["deterministic"].astype(bool) & ch["h"].notna()]
        meets = int((random["meets_target"] == True).sum())  # noqa: E712
        best = []
        for (plant, hw), g in ch[ch["rank"].map(lambda v: v == 1)].groupby(["plant", "hardware"], sort=True):
            r = g.iloc[0]
            if hw == "realistic":
                if r["missed_share"] is not None and float(r["missed_share"]) < 1.0:
                    best.append(f"{plant}: {r['chain']} (missed {_fmt(r['missed_share'], 2)}, delay "
                                f"{_fmt(r['delay_median'])} s)")
                else:  # rank 1 of chains that all miss every fault is no best chain
                    best.append(f"{plant}: no chain detects an actuator fault")
        no_free = ch[ch["h"].isna()]
        lines.append(f"FDIR chains (detector x estimator, {', '.join(det.detectors)}): {meets} of {len(random)} with "
                     f"drawn fault-free runs certified for at most {det.false_alarms_per_hour:g} first false alarms per "
                     f"hour at {det.level:.0%} (a property of the calibration rule, not a test)"
                     + (f"; {len(no_free)} without a fault-free run flown" if len(no_free) else "")
                     + ("; best per plant, realistic hardware: " + "; ".join(best) if best else "") + ".")
    cl = tables["closed"]
    if len(cl):
        parts = [f"{r.cell} {r.hardware}: flies {r.flies_fdir}/{r.pairs} with FDIR, {r.flies_open}/{r.pairs} without"
                 for r in cl.itertuples()]
        lines.append("Wheel loss with the chain closed (detect, isolate, drop the wheel): " + "; ".join(parts) + ".")
    oc = tables["outcomes"]
    if len(oc):
        out = oc[oc["claims"] == OUTSIDE]
        if len(out):
            by = out.groupby("method")["fault"].agg(lambda s: ", ".join(sorted(set(s))))
            lines.append(f"Measured {OUTSIDE} (shown, not counted in the symbols): "
                         + "; ".join(f"{m} under {f}" for m, f in by.items()) + ".")
    return lines


def rules(arena) -> list:
    """The rules of the page, as paragraphs."""
    st, det = arena.statistics, arena.detection
    return [
        "Outcomes: flies (inside the plant's band at the end, not saturated, not diverged), not settled, saturated "
        "(at the actuators' peak for 95 % of the run), diverged (non-finite, or the rate ends above twice its initial "
        "norm), stopped (an FMU stopped the run: a result, with its reason and time; it counts as not flying and not "
        "keeping accuracy), failed (no result: nothing stored, or the wall-time limit; never ranked).",
        "Attitude error: 2 asin ||q_ev|| of the error quaternion of the true attitude against the command (|theta| on the "
        "pitch axis); time to band from the later of the last manoeuvre and the fault onset; the error after settling "
        "from 1 s after entering the band for good.",
        f"Claims: each method's paper claims some fault classes (the Cells table, with the source); a result {OUTSIDE} "
        "is shown beside the measurement and never counted in the summary's symbols.",
        "Feasibility: a run is not buildable when no wheel of the data-sheet catalog (plant/hardware/datasheets.py) "
        "delivers its peak torque and stores its peak momentum on every channel (ideal hardware; realistic wheels are "
        "data-sheet wheels).",
        "A deterministic run (no fault, ideal hardware: no drawn number reaches it) is computed once and shown as one "
        "point (n = 1, no interval).",
        f"Statistics: medians over the runs that fly with {st.confidence:.0%} percentile-bootstrap intervals "
        f"(scipy.stats.bootstrap, {st.bootstrap} resamples); ranks on the median attitude error after settling among "
        f"methods that fly in at least {FLY_SHARE:.0%} of their runs. A paired comparison is significant only with at "
        f"least {st.min_pairs} paired draws and a Holm-adjusted Wilcoxon signed-rank p-value at most {st.alpha:g}, Holm "
        "across every comparison on this page.",
        f"FDIR chains (arena/fdir.py, diagnosis/): every estimator's estimate goes through each detector "
        f"({', '.join(det.detectors)}; persistence {det.persistence:g} s, CUSUM drift {det.drift:g} sigma, GLR and "
        f"chi-square window {det.window:g} s) replayed offline over the stored run (the same blocks; exact: the decision "
        "feeds nothing back), and the isolation where the fault channel is defined (the direction of the estimate "
        "against the wheels' axes or the body axes). Thresholds from the cell's own fault-free draws: the smallest at "
        "which no draw raises an alarm (just above the largest of their n persisted peaks), certified when "
        f"-ln(1 - {det.level:g}) / E is at most {det.false_alarms_per_hour:g} per hour (E the draws' hours): the largest "
        "of n exchangeable peaks is a Wilks tolerance limit, so a new fault-free run alarms with probability at most "
        f"1 - {1 - det.level:g}^(1/n) at {det.level:.0%} confidence, whatever the distribution of the peaks (approximate: "
        "the normalisation comes from the same draws). That is a property of the rule, not a test that could fail here "
        "(no fresh fault-free draws are flown; tests/ check it on fresh draws); it bounds first alarms per run, not the "
        "restart counts of the operating curves (in sample). With too few hours (a slice, or the one deterministic "
        "ideal-hardware run) the threshold is "
        "not certified. Chains are ranked per plant and hardware by missed detections, median delay, isolation "
        "(certification is the cell's, the same for its chains). A wheel loss is also flown with the first "
        "detector's chain closed where the cell has "
        "a wheel allocation (the isolated wheel is dropped): that is the only run whose trajectory the chain changes.",
        "Sensor faults (gyro bias, drift, stuck; star-tracker outage, frozen output) fly with realistic hardware only, "
        "where the sensor exists. No method's paper claims them, and no chain here has a sensor channel: a sensor fault "
        "is scored by the FTC outcome, by the alarms it raises, and by how often the chain names an actuator for it.",
    ]
