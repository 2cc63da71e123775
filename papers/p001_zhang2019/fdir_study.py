"""FDIR on 001's four-wheel craft with a wheel lost (issue 34): detect, isolate, reconfigure, and the
same run without FDIR. A study report (Markdown, one figure, JSON)::

    python -m papers.p001_zhang2019.fdir_study --out results/fdir_study              # 3 runs, about 15 s
    python -m papers.p001_zhang2019.fdir_study --out results/fdir_study_w4 --wheel 4  # another wheel

Runs (in-process by default; ``--mode fmu`` through the FMUs):

* ``fdir``: zhang2019_fdir_wheel_loss, the chain closed (the allocation drops the isolated wheel);
* ``open``: zhang2019_fdir_wheel_loss_open, the same chain logged but read by nothing (no FDIR);
* ``healthy``: the open scenario without the fault (what the mission looks like with four wheels).

Measures (attitude error e(t) = 2 asin ||q_ev|| of the controller's error quaternion, rad):

* alarm time (the detector's ``alarm_time``), isolated wheel, its confidence and margin, isolation
  time, reconfiguration time (the first instant the allocation uses three wheels);
* attitude error at the fault onset, at the alarm, just before the reconfiguration and 5 s and 10 s
  after it (the FDIR run's reconfiguration instant, read in every run: the same instants compared);
* the stated measure of the improvement: the RMS of e over the slew window [30 s, end] and the
  settling time (the first instant after 30 s from which e stays below 0.01 rad to the end). FDIR
  improves on the run without it when both are smaller (``improved``).

The lost wheel stops producing torque at the onset (20 s), but the craft is at rest and the wheel
was only trimming the disturbance: the fault shows in f_hat when the wheels work, at the slew
(30 s). The alarm comes then; the delay from the onset says so and is not a detector's lag.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from orchestrator import api
from orchestrator.api import InputError

SCENARIO, OPEN = "zhang2019_fdir_wheel_loss", "zhang2019_fdir_wheel_loss_open"
SLEW = 30.0  # s, the q_d step of both scenarios
BAND = 0.01  # rad, the settling band
AFTER = 10.0  # s after the reconfiguration: the attitude error is read 5 s and 10 s after it


def attitude_error(df) -> np.ndarray:
    """e = 2 asin ||q_ev|| (rad) from the recorded ctrl.q_e."""
    qv = df[[f"ctrl.q_e[{i}]" for i in (1, 2, 3)]].to_numpy()
    return 2.0 * np.arcsin(np.minimum(1.0, np.linalg.norm(qv, axis=1)))


def _at(t, x, when):
    if when is None or not math.isfinite(when):
        return None
    return float(x[min(len(t) - 1, int(np.searchsorted(t, when - 1e-9)))])


def settling(t, e, start=SLEW, band=BAND):
    """First instant >= start from which e stays below band to the end (None if it never does, or if
    the run ends before ``start``)."""
    m = t >= start - 1e-9
    if not m.any():
        return None
    above = np.flatnonzero(e[m] >= band)
    if len(above) == 0:
        return float(t[m][0])
    last = above[-1]
    return float(t[m][last + 1]) if last + 1 < m.sum() else None


def measures(r, onset: float, t_ref: float | None = None) -> dict:
    """The measures of one run; ``t_ref`` (s): the FDIR run's reconfiguration time, at which (and 5 s
    and 10 s after which) every run's attitude error is read, so the three runs compare at the same instants."""
    df = r.df
    t = df.index.to_numpy()
    e = attitude_error(df)
    alarm = float(df["det.alarm_time"].iloc[-1])
    alarm = alarm if alarm >= 0 else None
    iso = df["iso.isolated"].to_numpy()
    named = np.flatnonzero(iso > 0)
    n_active = df["alloc.n_active"].to_numpy()
    reconf = np.flatnonzero(n_active < 4)
    t_reconf = float(t[reconf[0]]) if len(reconf) else None
    window = (t >= SLEW - 1e-9)
    ref = t_reconf if t_ref is None else t_ref
    return {
        "complete": bool(r.complete),
        "alarm_time_s": alarm,
        "delay_from_onset_s": None if alarm is None else alarm - onset,
        "isolated_wheel": int(iso[-1]) if len(named) else None,
        "isolation_time_s": float(df["iso.isolation_time"].iloc[-1]) if len(named) else None,
        "confidence": float(df["iso.confidence"].iloc[-1]) if len(named) else None,
        "margin": float(df["iso.margin"].iloc[-1]) if len(named) else None,
        "reconfiguration_time_s": t_reconf,
        "attitude_error_at_onset_rad": _at(t, e, onset),
        "attitude_error_at_alarm_rad": _at(t, e, alarm),
        "attitude_error_before_reconfiguration_rad": _at(t, e, None if ref is None else ref - 0.5 * r.scenario.step),
        "attitude_error_5s_after_reconfiguration_rad": _at(t, e, None if ref is None else ref + 0.5 * AFTER),
        "attitude_error_10s_after_reconfiguration_rad": _at(t, e, None if ref is None else ref + AFTER),
        "rms_attitude_error_slew_rad": float(np.sqrt(np.mean(e[window] ** 2))) if window.any() else None,
        "settling_time_s": settling(t, e) if window.any() else None,
        "final_attitude_error_rad": float(e[-1]),
    }


def run_study(out, *, wheel: int | None = None, mode: str = "inprocess", stop: float | None = None,
              overwrite: bool = False, source: str = "api", key: str = "out") -> dict:
    """The three runs, their measures, the figure and the report in ``out`` (a folder, created; a folder
    ftcsim did not write is refused before anything runs, a previous study replaced only with
    ``overwrite``)."""
    folder = api.output_folder(out, "fdir-study", overwrite=overwrite, source=source, key=key)
    return folder.fill(lambda staging: _study(staging, wheel, mode, stop))


def _study(out: Path, wheel, mode, stop) -> dict:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fault = {} if wheel is None else {"faults.channel": float(wheel)}
    runs = {"fdir": api.run(SCENARIO, mode=mode, stop=stop, parameters=fault),
            "open": api.run(OPEN, mode=mode, stop=stop, parameters=fault),
            "healthy": api.run(OPEN, mode=mode, stop=stop, parameters={**fault, "faults.fault_class": 0.0})}
    sc = runs["fdir"].scenario
    onset = float(sc.instances["faults"].parameters.get("onset", 20.0))
    lost = int(sc.instances["faults"].parameters.get("channel", 2))
    t_ref = measures(runs["fdir"], onset)["reconfiguration_time_s"]
    m = {name: measures(r, onset, t_ref) for name, r in runs.items()}
    f, o = m["fdir"], m["open"]
    evaluated = f["rms_attitude_error_slew_rad"] is not None  # a run stopped before the slew compares nothing
    improved = evaluated and (f["rms_attitude_error_slew_rad"] < o["rms_attitude_error_slew_rad"]
                              and (o["settling_time_s"] is None or (f["settling_time_s"] is not None
                                                                    and f["settling_time_s"] < o["settling_time_s"])))
    verdict = {
        "lost_wheel": lost, "onset_s": onset,
        "detected": f["alarm_time_s"] is not None and f["alarm_time_s"] >= onset,
        "isolated_right_wheel": f["isolated_wheel"] == lost,
        "reconfigured": f["reconfiguration_time_s"] is not None,
        "false_alarm_without_fault": m["healthy"]["alarm_time_s"] is not None,
        "improved": bool(improved),
        "measure": f"RMS attitude error over [{SLEW:g} s, end] and settling time to {BAND:g} rad after {SLEW:g} s, "
                   "both smaller with FDIR than without",
        "rms_ratio_fdir_over_open": f["rms_attitude_error_slew_rad"] / o["rms_attitude_error_slew_rad"] if evaluated else None,
    }
    fig, ax = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    for name, style in (("open", "C3"), ("fdir", "C0"), ("healthy", "0.5")):
        df = runs[name].df
        ax[0].semilogy(df.index, np.maximum(attitude_error(df), 1e-9), color=style, label={
            "fdir": "FDIR (detect, isolate, drop the wheel)", "open": "no FDIR (allocation keeps M^+)",
            "healthy": "no fault"}[name])
    df = runs["fdir"].df
    ax[1].plot(df.index, df["det.statistic"], color="C0", label="CUSUM statistic")
    h = float(runs["fdir"].scenario.instances["det"].parameters["h"])
    ax[1].axhline(h, color="k", ls="--", lw=0.8, label=f"calibrated h = {h:.4g}")
    for j in range(1, 5):
        ax[2].plot(df.index, df[f"iso.share[{j}]"], label=f"share of wheel {j}'s axis")
    marks = [(onset, "onset", "k"), (f["alarm_time_s"], "alarm", "C1"), (f["reconfiguration_time_s"], "reconfiguration", "C2")]
    for a in ax:
        for when, label, c in marks:
            if when is not None:
                a.axvline(when, color=c, ls=":", lw=1, label=label if a is ax[0] else None)
        a.legend(loc="best", fontsize=7)
    ax[0].set_ylabel("attitude error, rad")
    ax[1].set_ylabel("statistic (sigma)")
    ax[2].set_ylabel("share, 1")
    ax[2].set_xlabel("time, s")
    ax[0].set_title(f"001's craft, wheel {lost} lost at {onset:g} s, 60 deg slew at {SLEW:g} s")
    fig.tight_layout()
    fig.savefig(out / "fdir_wheel_loss.png", dpi=110)
    plt.close(fig)
    report = {"scenario": SCENARIO, "comparison": OPEN, "mode": mode, "wheel": lost, "verdict": verdict, "runs": m}
    (out / "report.json").write_text(json.dumps(report, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    (out / "report.md").write_text(_markdown(report), encoding="utf-8")
    return report


def _fmt(x, unit=""):
    if x is None:
        return "none"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    return f"{x:.4g}{unit}"


def _markdown(rep) -> str:
    v, m = rep["verdict"], rep["runs"]
    rows = [("alarm time", "alarm_time_s", " s"), ("delay from the onset", "delay_from_onset_s", " s"),
            ("isolated wheel", "isolated_wheel", ""), ("isolation confidence (share)", "confidence", ""),
            ("isolation margin", "margin", ""), ("reconfiguration time", "reconfiguration_time_s", " s"),
            ("attitude error at the onset", "attitude_error_at_onset_rad", " rad"),
            ("attitude error at the alarm", "attitude_error_at_alarm_rad", " rad"),
            ("attitude error just before the reconfiguration", "attitude_error_before_reconfiguration_rad", " rad"),
            ("attitude error 5 s after the reconfiguration", "attitude_error_5s_after_reconfiguration_rad", " rad"),
            ("attitude error 10 s after the reconfiguration", "attitude_error_10s_after_reconfiguration_rad", " rad"),
            (f"RMS attitude error over [{SLEW:g} s, end]", "rms_attitude_error_slew_rad", " rad"),
            (f"settling time to {BAND:g} rad", "settling_time_s", " s"),
            ("final attitude error", "final_attitude_error_rad", " rad")]
    lines = [f"# FDIR on 001's four-wheel craft: wheel {v['lost_wheel']} lost at {v['onset_s']:g} s", "",
             f"Scenario `{rep['scenario']}` (FDIR) against `{rep['comparison']}` (the same chain, not connected to the "
             f"allocation) and the same run without the fault; {rep['mode']} runs. Measure of the improvement: "
             f"{v['measure']}.", "",
             f"* detected: {_fmt(v['detected'])}; isolated the lost wheel: {_fmt(v['isolated_right_wheel'])}; "
             f"reconfigured: {_fmt(v['reconfigured'])}; improved: **{_fmt(v['improved'])}** (RMS ratio FDIR / no FDIR "
             f"{_fmt(v['rms_ratio_fdir_over_open'])}); false alarm in the fault-free run: {_fmt(v['false_alarm_without_fault'])}",
             "", "| | FDIR | no FDIR | no fault |", "|---|---|---|---|"]
    for label, key, unit in rows:
        lines.append(f"| {label} | " + " | ".join(_fmt(m[r][key], unit) for r in ("fdir", "open", "healthy")) + " |")
    lines += ["", "The lost wheel was trimming the disturbance at rest: its loss shows in f_hat once the wheels work, "
                  "at the slew; the delay from the onset is that wait, not the detector's lag.", "",
              "![attitude error, detector statistic, isolation shares](fdir_wheel_loss.png)", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m papers.p001_zhang2019.fdir_study", description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="report folder (created)")
    ap.add_argument("--wheel", type=int, choices=[1, 2, 3, 4], help="the lost wheel (default: the scenario's, 2)")
    ap.add_argument("--mode", choices=["inprocess", "fmu"], default="inprocess")
    ap.add_argument("--stop", type=float, help="stop time instead of the scenarios' (s)")
    ap.add_argument("--overwrite", action="store_true", help="replace a previous study in --out")
    args = ap.parse_args(argv)
    try:
        rep = run_study(args.out, wheel=args.wheel, mode=args.mode, stop=args.stop, overwrite=args.overwrite,
                        source="command line", key="--out")
    except InputError as e:
        print(f"ftcsim: error: {' '.join(str(e).split())}", file=sys.stderr)
        return 2
    v = rep["verdict"]
    f = rep["runs"]["fdir"]
    print(f"wheel {v['lost_wheel']} lost at {v['onset_s']:g} s: alarm at {_fmt(f['alarm_time_s'], ' s')}, isolated wheel "
          f"{_fmt(f['isolated_wheel'])}, reconfigured at {_fmt(f['reconfiguration_time_s'], ' s')}; improved: "
          f"{_fmt(v['improved'])} (RMS attitude error over the slew {_fmt(f['rms_attitude_error_slew_rad'], ' rad')} with "
          f"FDIR, {_fmt(rep['runs']['open']['rms_attitude_error_slew_rad'], ' rad')} without); report in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
