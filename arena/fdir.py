"""The arena's FDIR chains (issue 34 item 6): every estimator's decision chain (a change detector of
``diagnosis/``, the isolation where the fault channel is defined, the reconfiguration where the cell
has a wheel allocation) calibrated on the cell's own fault-free draws and scored on its runs.

Where the chain runs. A detector and an isolation feed nothing back into the loop until something
reads their decision, so they are replayed offline over each run's stored estimate with the SAME
blocks (``ChangeDetector.replay`` and ``FaultIsolation.sample`` of ``diagnosis/``), sampling the stored
rows: the trajectory step rounded to whole communication steps (:func:`arena.plan.sample_period`).
That is exact for detection and isolation, costs no simulation, and lets every detector and any
threshold be tried on the same runs (the operating curves). Only where the decision changes the
trajectory is the chain closed in the loop: a cell with a wheel allocation the isolation can tell
(:func:`arena.cells.reconfigures`) flies its wheel-loss class a second time with the first listed
detector and the isolation in the loop and ``iso.isolated -> alloc.isolated`` (:func:`closed_loop_items`,
after the first pass: its thresholds come from the cell's stored fault-free draws). The replay of each
closed run is compared with what the blocks decided in it (:func:`replay_matches`; also a test).

Calibration of a chain (a cell and hardware set, one detector): the fault-free draws flown to the end
(a run an FMU stopped exposes no detector; an estimate that turns non-finite is kept up to its last
finite sample), their estimate at or after the estimator's start-up (``estimate_from``) normalised by
its mean and standard deviation, and the rule of ``diagnosis.calibration.certify`` (the one ``ftcsim
fdir calibrate`` applies): the smallest threshold at which no draw raises an alarm, certified for the
target when -ln(1 - level) / E <= target (Wilks: the largest of n exchangeable peaks bounds a new
draw's alarm probability at 1 - (1 - level)^(1/n) with confidence ``level``, so at most
-ln(1 - level) / E first false alarms per hour; approximate, as the normalisation comes from the same
draws). The guarantee is a property of the rule, stated as such on the page, not a check that could
fail here (no fresh fault-free draws are flown; a leave-one-out count under this rule is one draw of
n by construction). Certification depends on the cell's fault-free hours only, the same for every
detector of a cell, so it does not rank chains. With ideal hardware the fault-free run is one
deterministic run (no rate: nothing drawn reaches it), and "meets" is undetermined.

Per run (:func:`run_measures`, ``diagnosis.metrics.fdir_measures``): the alarms of a fault-free draw
(counting rule); for a faulty run the chain as flown (latched, no restart): detection delay from the
onset, missed detection, the isolated channel and whether it is the faulty one (actuator classes; a
channel named in a sensor-fault run names an actuator for a sensor fault), the time to
reconfiguration (closed loop only). A run without the m = 1 + ceil(persistence / T) samples at or
after the onset that an alarm needs (stopped, or cut by a slice) is neither detected nor missed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from diagnosis.calibration import certify, exposure_hours, false_alarm_counts, first_alarms, normalisation, rate_statistics, upper_bound
from diagnosis.detectors import Chi2Detector, CusumDetector, GlrDetector
from diagnosis.isolation import FaultIsolation
from diagnosis.metrics import fdir_measures

from . import stats as S

DETECTOR_CLASSES = {"cusum": CusumDetector, "glr": GlrDetector, "chi2": Chi2Detector}
LABELS = {"cusum": "CUSUM", "glr": "GLR", "chi2": "chi2"}
CURVE_POINTS = 15  # thresholds of an operating curve (log-spaced, h/30 .. 3 h), and h itself


# -- the blocks ------------------------------------------------------------------------------------------------------
def design(detection, name: str, T: float, t_enable: float) -> dict:
    """The detector's design parameters in the arena (``[detection]``): persistence, drift (CUSUM) or
    window (GLR, chi-square in its mean form), t_enable, the sample period T."""
    p = {"persistence": detection.persistence, "t_enable": float(t_enable), "sample_period": float(T)}
    if name == "cusum":
        p["drift"] = detection.drift
    else:
        p["window"] = detection.window
    if name == "chi2":
        p["form"] = 1.0
    return p


def vector_parameters(base: str, x) -> dict:
    x = np.atleast_1d(np.asarray(x, dtype=float))
    return {base: float(x[0])} if len(x) == 1 else {f"{base}[{i + 1}]": float(v) for i, v in enumerate(x)}


def detector(name: str, n: int, params: dict, mu0=None, sigma=None):
    """An initialised detector block of ``diagnosis/`` (n channels) with ``params`` and the normalisation."""
    b = DETECTOR_CLASSES[name](n, "1")
    values = dict(params)
    if mu0 is not None:
        values.update(vector_parameters("mu0", mu0))
        values.update(vector_parameters("sigma", sigma))
    b.set_parameters(values)
    b.initialize(0.0)
    return b


def isolation(signatures, mu0, window: float, T: float) -> FaultIsolation:
    m, N = signatures.shape
    iso = FaultIsolation(m, N, "1", signatures)
    iso.set_parameters({**vector_parameters("mu0", mu0), "window": float(window), "sample_period": float(T)})
    iso.initialize(0.0)
    return iso


def signatures(channels: int, width: int):
    """S of the isolation (``arena.cells.isolation_signatures``), or None."""
    if channels == 4 and width == 3:
        from plant.rigid_wheels import default_distribution

        return np.asarray(default_distribution(4), dtype=float)
    if channels == width and channels > 1:
        return np.eye(channels)
    return None


# -- calibration -----------------------------------------------------------------------------------------------------
@dataclass
class Calibration:
    """One chain's threshold and the statistics behind it (module docstring)."""

    detector: str
    n: int
    T: float
    t_enable: float
    params: dict
    runs: int = 0
    mu0: np.ndarray | None = None
    sigma: np.ndarray | None = None
    h: float | None = None
    certified: bool = False
    stats: dict = field(default_factory=dict)  # in sample: diagnosis.calibration.rate_statistics
    curve: list = field(default_factory=list)  # operating curve [(h, N, rate, bound)] of the fault-free draws
    reason: str | None = None  # why there is no threshold
    drawn: bool = True  # False: the fault-free run is one deterministic run (ideal hardware)

    def block(self):
        return detector(self.detector, self.n, self.params, self.mu0, self.sigma)

    @property
    def meets(self):
        """Certified (the rule's guarantee, module docstring); None without a threshold or without draws."""
        if self.h is None or not self.drawn:
            return None
        return bool(self.certified)


def fault_free_runs(samples, mission: float) -> list:
    """[(t, r)] of fault-free draws for a calibration: each (draw, t, estimate) cut before the mission's
    end (the loop takes no sample at its stop) and before its first non-finite sample (what a detector
    in the loop would have seen until then), in draw order; a draw with no finite sample left out."""
    out = []
    for _, t, r in sorted(samples, key=lambda x: x[0]):
        keep = np.asarray(t) < mission - 1e-9 * max(1.0, mission)
        t, r = np.asarray(t, dtype=float)[keep], np.asarray(r, dtype=float)[keep]
        bad = np.flatnonzero(~np.all(np.isfinite(r.reshape(len(r), -1)), axis=1))
        if len(bad):
            t, r = t[:bad[0]], r[:bad[0]]
        if len(t):
            out.append((t, r))
    return out


def _threshold(name, n, params, runs, exposures, rate, level):
    mu0, sigma = normalisation(runs, params["t_enable"])
    b = detector(name, n, params, mu0, sigma)
    return b, mu0, sigma, certify(b, runs, exposures, rate, level, curve_points=0)


def calibrate(detection, name: str, runs: list, T: float, t_enable: float, drawn: bool = True) -> Calibration:
    """The chain's calibration on the fault-free ``runs`` [(t, estimate)] (module docstring); ``drawn``
    False: one deterministic run (ideal hardware), a threshold but no rate."""
    n = runs[0][1].shape[1] if runs else 1
    params = design(detection, name, T, t_enable)
    cal = Calibration(name, n, T, t_enable, params, runs=len(runs), drawn=drawn)
    if not runs:
        cal.reason = "no fault-free draw flown to the end"
        return cal
    exposures = exposure_hours(runs, T, t_enable)
    if not exposures.sum() > 0:
        cal.reason = f"no sample after the start-up ({t_enable:g} s)"
        return cal
    rate, level = detection.false_alarms_per_hour, detection.level
    try:
        b, cal.mu0, cal.sigma, found = _threshold(name, n, params, runs, exposures, rate, level)
    except ValueError as e:
        cal.reason = f"cannot normalise the estimate: {e}"
        return cal
    cal.h, cal.certified = found["h"], found["certified"]
    if cal.h is None:
        cal.reason = "no threshold below the largest statistic"
        return cal
    cal.stats = rate_statistics(found["counts"], exposures, level)
    E = float(exposures.sum())
    grid = np.unique(np.concatenate([np.geomspace(cal.h / 30.0, cal.h * 3.0, CURVE_POINTS), [cal.h]]))
    for h in grid:
        N = int(false_alarm_counts(b, runs, h, found["peaks"]).sum())
        cal.curve.append((float(h), N, N / E, upper_bound(N, E, level)))
    return cal


# -- replaying a run ---------------------------------------------------------------------------------------------
def chain_replay(cal: Calibration, t, r, S=None, isolation_window: float = 0.0) -> dict:
    """The chain as flown (latched, no restart) over one run's samples: ``events`` (K,) 1 at an alarm
    decision, ``isolated`` (K,) the channel named after each sample (0: none), ``statistic``."""
    b = cal.block()
    b.set_decision(cal.h, latch=1.0, restart=0.0)
    stat, events = b.replay(r, t)
    iso = np.zeros(len(t))
    first = np.flatnonzero(events > 0)
    if S is not None and len(first):
        block = isolation(S, cal.mu0, isolation_window, cal.T)
        tail = block._tail
        for k in range(int(first[0]) + 1, len(t)):  # the alarm reaches the isolation at the next sample
            block.sample(float(t[k]), r[k], 1.0, 0.0)
            if block.state[tail] > 0:
                iso[k:] = block.state[tail]
                break
    return {"events": events, "isolated": iso, "statistic": stat}


def replay_matches(replay: dict, recorded: dict) -> bool:
    """Whether the blocks in the loop decided what the replay decides: the loop shows a decision of the
    sample at row k from row k + 1 (no direct feedthrough; rows one sample period apart)."""
    n_alarms = recorded.get("chain_alarms")
    isolated = recorded.get("chain_isolated")
    if n_alarms is None or isolated is None:
        return False
    n_alarms, isolated = np.ravel(n_alarms), np.ravel(isolated)
    K = min(len(n_alarms), len(replay["events"]))
    cum = np.cumsum(replay["events"][:K])
    return bool(np.array_equal(n_alarms[1:K], cum[:K - 1]) and np.array_equal(isolated[1:K], replay["isolated"][:K - 1]))


def _keep(t, row) -> np.ndarray:
    """Which stored instants a chain samples: before the mission's end and, for a run an FMU stopped, not
    after the stop (boolean mask)."""
    t = np.asarray(t, dtype=float)
    mission = float(row["mission"])
    keep = t < mission - 1e-9 * max(1.0, mission)
    stop = row.get("stop_time") if row["outcome"] == "stopped" else None
    if stop is not None and math.isfinite(float(stop)):
        keep &= t <= float(stop) + 1e-9 * max(1.0, abs(float(stop)))
    return keep


def decidable(cal: Calibration, t, onset: float) -> bool:
    """Whether the run's samples ``t`` (s) hold a decision on a fault from ``onset`` (s): at least the
    m = 1 + ceil(persistence / T) samples at or after it that an alarm needs (diagnosis/detectors.py).
    A run that ends earlier (stopped, or a slice) is neither detected nor missed."""
    m = 1 + math.ceil(cal.params["persistence"] / cal.T - 1e-9)
    return int(np.count_nonzero(np.asarray(t) >= onset - 1e-9 * max(1.0, abs(onset)))) >= m


def run_measures(cal: Calibration, row, t, r, S, isolation_window: float, recorded: dict | None = None) -> dict | None:
    """One run's FDIR measures with the chain ``cal`` (module docstring), or None when the run cannot
    score it (failed, no onset, stopped before the fault could show)."""
    if cal.h is None or row["outcome"] == "failed":
        return None
    keep = _keep(t, row)
    t, r = np.asarray(t, dtype=float)[keep], np.asarray(r, dtype=float)[keep]
    if len(t) < 2:
        return None
    if row["fault"] == "none":
        if row["outcome"] == "stopped" or not np.all(np.isfinite(r)):
            return None
        b = cal.block()
        n = int(false_alarm_counts(b, [(t, r)], cal.h)[0])
        e = float(exposure_hours([(t, r)], cal.T, cal.t_enable)[0])
        return {"false_alarms": n, "exposure_hours": e, "false_alarms_per_hour": n / e if e > 0 else None}
    onset = row.get("onset")
    if onset is None or (isinstance(onset, float) and math.isnan(onset)):
        return None
    onset = float(onset)
    if not decidable(cal, t, onset):
        return None  # the fault came after the run's end, or the run ended before a decision on it was possible
    rep = chain_replay(cal, t, r, S, isolation_window)
    channel = None if row.get("sensor_fault") else row.get("channel")
    channel = None if channel is None or (isinstance(channel, float) and math.isnan(channel)) else int(channel)
    reconfigured = None
    if recorded is not None and recorded.get("chain_active") is not None:
        active = np.ravel(recorded["chain_active"])[keep]
        reconfigured = active < 4 - 0.5
    m = fdir_measures(t, n_alarms=np.cumsum(rep["events"]), onset=onset, faulty_channel=channel,
                      isolated=rep["isolated"] if S is not None else None,
                      reconfigured=reconfigured, t_enable=cal.t_enable)
    m["alarms_before_onset"] = m.pop("false_alarms")
    for k in ("exposure_hours", "false_alarms_per_hour"):
        m.pop(k)
    if recorded is not None:
        m["replay_matches_loop"] = replay_matches(rep, recorded)
    return m


# -- the arena's chains ----------------------------------------------------------------------------------------------
def _samples(measured, idx) -> list:
    runs = measured.runs
    return [(int(runs.at[i, "draw"]), *measured.estimates[i][:2]) for i in idx]


def _cell_calibrations(arena, measured, g: pd.DataFrame, T: float) -> dict:
    runs = measured.runs
    free = [i for i in g.index if i in measured.estimates and runs.at[i, "fault"] == "none"
            and runs.at[i, "outcome"] not in ("failed", "stopped")]
    data = fault_free_runs(_samples(measured, free), float(g["mission"].iloc[0]))
    t_enable = float(g["estimate_from"].iloc[0])
    from .cells import deterministic

    drawn = not deterministic(str(g["hardware"].iloc[0]), "none")
    return {name: calibrate(arena.detection, name, data, T, t_enable, drawn) for name in arena.detection.detectors}


def score(arena, measured) -> dict:
    """Every chain of the arena calibrated and scored: {"runs": per run and detector, "chains": per
    chain, "curves": operating curves, "closed": the closed-loop runs, "sensors": sensor classes}."""
    from .plan import sample_period

    runs = measured.runs
    per_run, chains, curves, closed_rows = [], [], [], []
    cals = {}
    if len(runs) and measured.estimates:
        with_est = runs.loc[[i for i in runs.index if i in measured.estimates]]
        for (cell, hw), g in with_est.groupby(["cell", "hardware"], sort=True):
            T = sample_period(arena, float(g["step"].iloc[0]))
            width = measured.estimates[g.index[0]][1].shape[1]
            S = signatures(int(g["catalog_channels"].iloc[0]), width)
            cals[(cell, hw)] = cal_set = _cell_calibrations(arena, measured, g, T)
            for name, cal in cal_set.items():
                scored = []
                for i in g.index:
                    t, r = measured.estimates[i][:2]
                    m = run_measures(cal, runs.loc[i], t, r, S, arena.detection.isolation_window)
                    if m is None:
                        continue
                    per_run.append({"row": i, "cell": cell, "hardware": hw, "detector": name, "loop": "open",
                                    "fault": runs.at[i, "fault"], "draw": int(runs.at[i, "draw"]), "h": cal.h, **m})
                    scored.append((i, m))
                chains.append(_chain_row(arena, runs, g, cal, scored, S))
                curves += _curve_rows(arena, measured, g, cal, cell, hw)
    closed = measured.closed
    if closed is not None and len(closed):
        for i in closed.index:
            cell, hw = closed.at[i, "cell"], closed.at[i, "hardware"]
            cal = cals.get((cell, hw), {}).get(arena.detection.detectors[0])
            if cal is None or i not in measured.closed_samples:
                continue
            t, r, rec = measured.closed_samples[i]
            S = signatures(int(closed.at[i, "catalog_channels"]), r.shape[1])
            m = run_measures(cal, closed.loc[i], t, r, S, arena.detection.isolation_window, recorded=rec)
            if m is not None:
                per_run.append({"row": i, "cell": cell, "hardware": hw, "detector": cal.detector, "loop": "closed",
                                "fault": closed.at[i, "fault"], "draw": int(closed.at[i, "draw"]), "h": cal.h, **m})
        closed_rows = _closed_table(arena, runs, closed, pd.DataFrame(per_run))
    pr = pd.DataFrame(per_run)
    ch = pd.DataFrame(chains)
    if len(ch):
        ch = _rank(ch)
    return {"runs": pr, "chains": ch, "curves": pd.DataFrame(curves), "closed": pd.DataFrame(closed_rows),
            "sensors": _sensor_table(arena, runs, pr), "calibrations": cals}


def _interval(values, arena, *names, share=False):
    st = arena.statistics
    rng = S.generator(arena.seed, *names)
    f = S.share_interval if share else S.median_interval
    return f(values, resamples=st.bootstrap, confidence=st.confidence, rng=rng)


def _chain_row(arena, runs, g, cal: Calibration, scored, Smat) -> dict:
    first = g.iloc[0]
    act = [(i, m) for i, m in scored if runs.at[i, "fault"] != "none" and not runs.at[i, "sensor_fault"]]
    missed = [bool(m["missed_detection"]) for _, m in act]
    delays = [m["detection_delay_s"] for _, m in act if m["detection_delay_s"] is not None]
    named = [m for _, m in act if m.get("isolated_channel")]
    correct = sum(bool(m["isolation_correct"]) for m in named)
    names = (first["cell"], first["hardware"], cal.detector)
    dmed, dlo, dhi = _interval(delays, arena, *names, "delay")
    mshare, mlo, mhi = _interval(missed, arena, *names, "missed", share=True)
    iso = S.wilson(correct, len(named), arena.statistics.confidence) if Smat is not None else (None, None, None)
    st = cal.stats or {}
    free_stopped = int(((g["fault"] == "none") & (g["outcome"] == "stopped")).sum())
    return {"plant": first["plant"], "method": first["method"], "method_label": first["method_label"],
            "cell": first["cell"], "hardware": first["hardware"], "detector": cal.detector,
            "chain": f"{first['method_label']} + {LABELS[cal.detector]}", "h": cal.h, "certified": cal.certified,
            "reason": cal.reason, "fault_free_runs": cal.runs, "fault_free_stopped": free_stopped,
            "exposure_hours": st.get("exposure_hours"), "target_per_hour": arena.detection.false_alarms_per_hour,
            "level": arena.detection.level, "false_alarms": st.get("false_alarms"),
            "rate_per_hour": st.get("rate_per_hour"), "rate_low": (st.get("poisson_interval_per_hour") or [None])[0],
            "rate_high": (st.get("poisson_interval_per_hour") or [None, None])[1],
            "upper_bound_per_hour": st.get("upper_bound_per_hour"),
            "meets_target": cal.meets, "deterministic": not cal.drawn,
            "faulty_runs": len(act), "missed_share": mshare, "missed_low": mlo, "missed_high": mhi,
            "delay_median": dmed, "delay_low": dlo, "delay_high": dhi,
            "isolation": "—" if Smat is None else ("wheels (M)" if Smat.shape[1] == 4 and Smat.shape[0] == 3 else "axes"),
            "isolated_runs": len(named) if Smat is not None else None,
            "isolation_correct": correct if Smat is not None else None, "isolation_share": iso[0],
            "isolation_low": iso[1], "isolation_high": iso[2]}


def _rank(ch: pd.DataFrame) -> pd.DataFrame:
    """Rank the chains within each plant and hardware set by the share of faulty runs missed, the median
    detection delay and the isolation accuracy (certification is the cell's, the same for all its
    chains: it does not rank)."""
    ch = ch.copy()
    ch["rank"] = None
    for _, g in ch.groupby(["plant", "hardware"], sort=False):
        ok = g[g["h"].notna() & (g["faulty_runs"] > 0)]
        key = ok.assign(_x=ok["missed_share"].astype(float).fillna(1.0),
                        _d=ok["delay_median"].astype(float).fillna(math.inf),
                        _i=-ok["isolation_share"].astype(float).fillna(0.0))
        order = key.sort_values(["_x", "_d", "_i"], kind="stable").index
        for r, i in enumerate(order, 1):
            ch.at[i, "rank"] = r
    return ch


def _curve_rows(arena, measured, g, cal: Calibration, cell, hw) -> list:
    if cal.h is None:
        return []
    runs = measured.runs
    faulty = [i for i in g.index if runs.at[i, "fault"] != "none" and not runs.at[i, "sensor_fault"]
              and runs.at[i, "outcome"] != "failed" and runs.at[i, "onset"] is not None
              and not (isinstance(runs.at[i, "onset"], float) and math.isnan(runs.at[i, "onset"]))]
    faulty = [i for i in faulty if decidable(cal, np.asarray(measured.estimates[i][0], dtype=float)[
        _keep(measured.estimates[i][0], runs.loc[i])], float(runs.at[i, "onset"]))]
    grid = [c[0] for c in cal.curve]
    b = cal.block()
    b.set_decision(cal.h, latch=1.0, restart=0.0)
    data, onsets = [], []
    for i in faulty:
        t, r = measured.estimates[i][:2]
        keep = _keep(t, runs.loc[i])
        data.append((np.asarray(t, float)[keep], np.asarray(r, float)[keep]))
        onsets.append(float(runs.at[i, "onset"]))
    fa = first_alarms(b, data, onsets, grid) if data else np.zeros((0, len(grid)))
    out = []
    for j, (h, N, rate, bound) in enumerate(cal.curve):
        d = fa[:, j] - np.array(onsets) if len(onsets) else np.array([])
        hit = d[np.isfinite(d)]
        out.append({"plant": g["plant"].iloc[0], "method": g["method"].iloc[0], "cell": cell, "hardware": hw,
                    "detector": cal.detector, "h": h, "calibrated": bool(h == cal.h), "false_alarms": N,
                    "rate_per_hour": rate, "upper_bound_per_hour": bound, "faulty_runs": len(d),
                    "missed_share": float(np.mean(~np.isfinite(d))) if len(d) else None,
                    "delay_median": float(np.median(hit)) if len(hit) else None})
    return out


def _closed_table(arena, runs, closed, per_run) -> list:
    """The wheel losses flown with the chain closed against the same draws without it (paired)."""
    out = []
    pr = per_run[per_run["loop"] == "closed"] if len(per_run) else per_run
    for (cell, hw), g in closed.groupby(["cell", "hardware"], sort=True):
        open_ = runs[(runs["cell"] == cell) & (runs["hardware"] == hw) & (runs["fault"] == "lost")]
        pairs = g.merge(open_, on="draw", suffixes=("", "_open"))
        m = pr[(pr["cell"] == cell) & (pr["hardware"] == hw)] if len(pr) else pr
        err = pairs[["attitude_error_rms_after", "attitude_error_rms_after_open"]].astype(float).dropna()
        d = (err.iloc[:, 0] - err.iloc[:, 1]).to_numpy()
        p = S.wilcoxon_p(d) if len(d) >= arena.statistics.min_pairs else None
        delays = m["detection_delay_s"].dropna().astype(float) if len(m) else pd.Series(dtype=float)
        ttr = m["time_to_reconfiguration_s"].dropna().astype(float) if len(m) else pd.Series(dtype=float)
        named = m[m["isolated_channel"].notna()] if len(m) else m
        out.append({"plant": g["plant"].iloc[0], "method": g["method"].iloc[0], "cell": cell, "hardware": hw,
                    "detector": arena.detection.detectors[0], "runs": len(g),
                    "detected": int((m["missed_detection"] == False).sum()) if len(m) else 0,  # noqa: E712
                    "isolated_right": int(named["isolation_correct"].astype(bool).sum()) if len(named) else 0,
                    "isolated": len(named), "delay_median": float(delays.median()) if len(delays) else None,
                    "reconfiguration_median": float(ttr.median()) if len(ttr) else None,
                    "flies_fdir": int((pairs["outcome"] == "flies").sum()),
                    "flies_open": int((pairs["outcome_open"] == "flies").sum()), "pairs": len(pairs),
                    "error_fdir": float(err.iloc[:, 0].median()) if len(err) else None,
                    "error_open": float(err.iloc[:, 1].median()) if len(err) else None, "p": p,
                    "replay_matches": int(m["replay_matches_loop"].astype(bool).sum()) if len(m) else 0,
                    "replayed": len(m)})
    return out


def _sensor_table(arena, runs, per_run) -> pd.DataFrame:
    """Per cell and sensor-fault class: flies, and with the first detector the alarms after the onset,
    their delay, and the runs where the chain named an actuator (a sensor fault read as an actuator's)."""
    if not len(runs) or "sensor_fault" not in runs or not runs["sensor_fault"].any():
        return pd.DataFrame()
    first = arena.detection.detectors[0]
    pr = per_run[(per_run["detector"] == first) & (per_run["loop"] == "open")] if len(per_run) else per_run
    out = []
    for (cell, fault), g in runs[runs["sensor_fault"]].groupby(["cell", "fault"], sort=True):
        m = pr[(pr["cell"] == cell) & (pr["fault"] == fault)] if len(pr) else pr
        res = g[g["outcome"] != "failed"]
        delays = m["detection_delay_s"].dropna().astype(float) if len(m) else pd.Series(dtype=float)
        iso = m["isolated_channel"].notna().sum() if len(m) and "isolated_channel" in m else 0
        out.append({"plant": g["plant"].iloc[0], "method": g["method"].iloc[0], "cell": cell, "fault": fault,
                    "runs": len(res), "flies": int((res["outcome"] == "flies").sum()),
                    "chain": LABELS[first] if len(m) else "—", "scored": len(m),
                    "alarmed": int((m["missed_detection"] == False).sum()) if len(m) else None,  # noqa: E712
                    "delay_median": float(delays.median()) if len(delays) else None,
                    "named_actuator": int(iso) if len(m) else None})
    return pd.DataFrame(out)


# -- the closed loop: the second pass -----------------------------------------------------------------------------------
def closed_loop_documents(arena, plans, out: Path) -> list:
    """For each cell that reconfigures: its chain calibrated on its stored fault-free draws (every one
    stored, else the cell waits for a rerun) and the closed-loop scenario and campaign, as the texts of
    ``scenario_fdir.toml`` and ``fdir.toml``: [(plan, {file name: text})] (``arena.app`` writes them).
    Nothing is written here."""
    import tomli_w

    from orchestrator import api

    from . import cells as C
    from .plan import sample_period

    docs = []
    name = arena.detection.detectors[0]
    for p in plans:
        folder = out / "cells" / p.name
        free = []
        for g in p.groups:
            if "none" not in g.faults:
                continue
            summary = folder / g.kind / "summary.parquet"
            if not summary.is_file():
                break
            s = api.read_table(summary)
            s = s[s["variant"] == "none"]
            if len(s) < g.runs:
                break
            for rec in s.to_dict("records"):
                traj = api.trajectory_file(folder / g.kind, rec)
                if rec.get("status") != "ok" or not traj.is_file():
                    continue
                t = api.read_table(traj)
                cols = [c for c in t.columns if c == p.cell.estimate or c.startswith(p.cell.estimate + "[")]
                free.append((int(rec["draw"]), t["time"].to_numpy(), t[cols].to_numpy()))
        else:
            T = sample_period(arena, p.step)
            data = fault_free_runs(free, arena.mission(p.cell))
            cal = calibrate(arena.detection, name, data, T, p.cell.estimate_from, not C.deterministic(p.hardware, "none"))
            if cal.h is None or cal.n != 3:
                continue
            det = {**cal.params, **vector_parameters("mu0", cal.mu0), **vector_parameters("sigma", cal.sigma),
                   "h": cal.h, "latch": 1.0, "restart": 0.0}
            iso = {**vector_parameters("mu0", cal.mu0), "window": arena.detection.isolation_window,
                   "sample_period": T}
            doc = C.closed_loop_scenario(p.scenario, p.cell, name, _grouped(det), _grouped(iso))
            camp = C.closed_loop_campaign_doc(arena, p.cell, p.hardware, "scenario_fdir.toml", doc, arena.draws,
                                              f"{p.name}.fdir", f"Arena cell {p.name} ({p.digest}): its wheel loss with "
                                                            f"the {name} chain closed, h = {cal.h!r}")
            docs.append((p, {"scenario_fdir.toml": tomli_w.dumps(doc), "fdir.toml": tomli_w.dumps(camp)}))
    return docs


def _grouped(values: dict) -> dict:
    """Indexed parameters ``mu0[1]`` ... as one list per base name (a scenario's parameter table)."""
    out, lists = {}, {}
    for k, v in values.items():
        if "[" in k:
            lists.setdefault(k.split("[")[0], []).append(v)
        else:
            out[k] = v
    return {**out, **lists}
