"""One arena run measured: its stored trajectory -> the metric set of ``arena/metrics.py`` and what
the run says about the pair ("outcome"), numpy and pandas only.

Outcomes (a method a plant cannot fly is a result; a run that failed is not):

* ``failed``: the run gave no result (bad set-up, a worker error): never ranked;
* ``stopped``: the run started and an FMU stopped it (a guard, a non-finite state): cannot fly;
* ``diverged``: the trajectory holds non-finite values, or the rate ends above ``DIVERGED`` x its
  initial norm (at least 0.01 rad/s): the controller spins the craft up;
* ``saturated``: the actuators sit at their peak torque for at least ``SATURATED_FRACTION`` of the run;
* ``not settled``: the pointing error is outside the plant's band at the end of the run;
* ``flies``: none of the above.

Pointing error: the principal angle between the plant's attitude and its command (000 (4); the
command from the cell's piecewise-constant ``q_d`` source, else the identity), 001's Euler angles
against 0, or |theta| on the pitch axis: the true attitude, never what a sensor reported. Torque:
what the actuators deliver at the plant (the wheels' ``u_wheel`` with realistic hardware, the
catalog's ``u_f`` with ideal actuators).
"""
from __future__ import annotations

import numpy as np

from . import metrics as M

DIVERGED = 2.0  # final rate norm / initial rate norm (>= 0.01 rad/s) above which a run diverged
SATURATED_FRACTION = 0.95
AT_PEAK = 0.98  # |u| >= 0.98 x peak counts as "at the limit"
METRICS = ("time_to_band", "pointing_rms_after", "pointing_max_after", "rate_rms_after", "final_pointing_error",
           "peak_torque_axis", "rms_torque", "control_energy", "momentum_used", "wheel_peak_torque",
           "wheel_momentum_peak", "estimate_rms_error", "detection_delay", "false_alarm")
UNITS = {"time_to_band": "s", "pointing_rms_after": "rad", "pointing_max_after": "rad", "rate_rms_after": "rad/s",
         "final_pointing_error": "rad", "peak_torque_axis": "N.m", "rms_torque": "N.m", "control_energy": "N^2.m^2.s",
         "momentum_used": "N.m.s", "wheel_peak_torque": "N.m", "wheel_momentum_peak": "N.m.s",
         "estimate_rms_error": "N.m", "detection_delay": "s", "false_alarm": "1"}


def columns(df, base: str) -> list:
    return [c for c in df.columns if c == base or c.startswith(base + "[")]


def vec(df, base: str):
    cols = columns(df, base)
    return df[cols].to_numpy(dtype=float) if cols else None


def command_quaternions(t, target) -> np.ndarray:
    """q_d at each time of a piecewise-constant command {times, values} (None: the identity)."""
    if target is None:
        return np.tile([1.0, 0.0, 0.0, 0.0], (len(t), 1))
    times, values = np.asarray(target["times"], float), np.asarray(target["values"], float)
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 1)
    return values[k]


def pointing_error(df, signals: dict, target) -> np.ndarray:
    t = df["time"].to_numpy()
    att = signals["attitude"]
    x = vec(df, att)
    if att == "plant.q":
        return M.pointing_error_between(x, command_quaternions(t, target))
    if att == "plant.sigma":
        return M.pointing_error_euler231(x)
    return np.abs(x[:, 0])


def measure(df, signals: dict, *, band: float, settle_from: float | None, status: str, fault_class: str,
            onset: float | None, target=None, threshold: float | None = None, nominal: float = 0.0,
            estimate_from: float = 5.0) -> dict:
    """Metrics and outcome of one run (``df``: its trajectory, a ``time`` column and the signals)."""
    out = dict.fromkeys(METRICS)
    out["outcome"] = "failed"
    if status == "failed" or df is None or len(df) < 2:
        return out
    t = df["time"].to_numpy(dtype=float)
    err = pointing_error(df, signals, target)
    rate = vec(df, signals["rate"])
    torque = vec(df, signals["wheel_torque"]) if "wheel_torque" in signals else vec(df, signals["delivered"])
    finite = bool(np.all(np.isfinite(err)) and np.all(np.isfinite(rate)) and np.all(np.isfinite(torque)))
    if not finite:
        out["outcome"] = "stopped" if status != "ok" else "diverged"
        return out
    t_start = settle_from if settle_from is not None and t[-1] > settle_from else None
    m = M.metric_set(t, pointing_error=err, rate_error=rate, torque=torque, band=band, t_start=t_start,
                     settle_margin=1.0)
    for k in ("time_to_band", "pointing_rms_after", "pointing_max_after", "rate_rms_after", "peak_torque_axis",
              "rms_torque", "control_energy", "momentum_used"):
        out[k] = m[k]
    out["final_pointing_error"] = float(err[-1])
    if "wheel_torque" in signals:
        out["wheel_peak_torque"] = float(np.abs(torque).max())
        out["wheel_momentum_peak"] = float(np.abs(vec(df, signals["wheel_momentum"])).max())
    if "estimate" in signals and threshold is not None:
        est, truth = vec(df, signals["estimate"]), vec(df, signals["truth"])
        if est is not None and truth is not None and est.shape == truth.shape:
            out["estimate_rms_error"] = M.estimate_rms_error(t, est, truth, estimate_from)
        if est is not None:
            alarm = est - nominal
            if fault_class == "none":
                out["false_alarm"] = M.false_alarm(t, alarm, threshold, estimate_from)
            elif onset is not None:
                td = M.detection_time(t, alarm, threshold, max(onset, estimate_from))
                out["detection_delay"] = None if td is None else td - onset
    peak = np.abs(torque).max(axis=1)
    at_peak = float(np.mean(peak >= AT_PEAK * peak.max())) if peak.max() > 0 else 0.0
    if status != "ok":
        out["outcome"] = "stopped"
    elif np.linalg.norm(np.atleast_2d(rate)[-1]) > DIVERGED * max(np.linalg.norm(np.atleast_2d(rate)[0]), 0.01):
        out["outcome"] = "diverged"
    elif at_peak >= SATURATED_FRACTION:
        out["outcome"] = "saturated"
    elif m["time_to_band"] is None:
        out["outcome"] = "not settled"
    else:
        out["outcome"] = "flies"
    return out
