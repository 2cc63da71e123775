"""One arena run measured: its stored trajectory -> the metric set of ``arena/metrics.py``, what the
run says about the pair ("outcome"), whether any data-sheet wheel could fly it ("buildable") and
the detector statistic of its estimate (numpy and pandas only).

Outcomes (a method a plant cannot fly is a result; a run that produced nothing is not):

* ``failed``: the run produced nothing (no trajectory: a set-up or import error, a worker lost) or
  hit the wall-time limit (the machine's limit, not the method's): never ranked, listed with its error;
* ``stopped``: the run started and an FMU stopped it (a guard, a singular allocation, a non-finite
  state): a result, with its reason (the error) and the time it stopped; it counts as not flying and
  not keeping accuracy;
* ``diverged``: the trajectory holds non-finite values, or the rate ends above ``DIVERGED`` x its
  initial norm (at least 0.01 rad/s): the controller spins the craft up;
* ``saturated``: the actuators sit at their peak torque for at least ``SATURATED_FRACTION`` of the run;
* ``not settled``: the attitude error is outside the plant's band at the end of the run;
* ``flies``: none of the above.

``attitude_error`` (rad) is the shared metric of ``orchestrator.results.metrics.attitude_error_rad``:
2 asin ||q_ev|| of the error quaternion q_e = q_d^* (x) q of the true attitude (never what a sensor
reported) against the command (the cell's piecewise-constant ``q_d`` source, else the identity);
001's Euler angles are turned into that quaternion first (Shepperd's method on C(sigma)); on the
pitch axis it is |theta - theta_d| (theta_d = 0). Time to band counts from the later of the last
manoeuvre (a switch of the command) and the fault onset.

Torque and momentum per actuator channel (N.m, N.m.s): what the actuators deliver at the plant (the
wheels' ``u_wheel`` and momenta ``h`` with realistic hardware; with ideal actuators the delivered torque
of ``arena.cells.delivered`` and its held integral from rest: the momentum a wheel on that channel
would have stored).
"""
from __future__ import annotations

import numpy as np

from orchestrator.results.metrics import attitude_error_rad

from . import metrics as M

DIVERGED = 2.0  # final rate norm / initial rate norm (>= 0.01 rad/s) above which a run diverged
SATURATED_FRACTION = 0.95
AT_PEAK = 0.98  # |u| >= 0.98 x peak counts as "at the limit"
SETTLE_MARGIN = 1.0  # s after entering the band before the after-settling statistics start
METRICS = ("time_to_band", "attitude_error_rms_after", "attitude_error_max_after", "rate_rms_after",
           "final_attitude_error", "peak_torque", "peak_momentum", "rms_torque", "control_energy",
           "estimate_rms_error")
UNITS = {"time_to_band": "s", "attitude_error_rms_after": "rad", "attitude_error_max_after": "rad",
         "rate_rms_after": "rad/s", "final_attitude_error": "rad", "peak_torque": "N.m", "peak_momentum": "N.m.s",
         "rms_torque": "N.m", "control_energy": "N^2.m^2.s", "estimate_rms_error": "N.m", "detection_delay": "s",
         "stop_time": "s", "onset": "s", "settle_from": "s", "threshold": "N.m", "fault_free_peak": "N.m",
         "mission": "s"}


def columns(df, base: str) -> list:
    """The columns of signal ``base`` (``base`` or ``base[i]``) of a trajectory: a DataFrame or a
    mapping of column name to array."""
    return [c for c in df.keys() if c == base or c.startswith(base + "[")]


def vec(df, base: str):
    """Signal ``base`` as rows (n, k) of floats, or None."""
    cols = columns(df, base)
    return np.column_stack([np.asarray(df[c], dtype=float) for c in cols]) if cols else None


def rows(df) -> int:
    """Samples in a trajectory (0 for None)."""
    return 0 if df is None else len(np.asarray(df["time"]))


def command_quaternions(t, target) -> np.ndarray:
    """q_d at each time of a piecewise-constant command {times, values} (None: the identity)."""
    if target is None:
        return np.tile([1.0, 0.0, 0.0, 0.0], (len(t), 1))
    times, values = np.asarray(target["times"], float), np.asarray(target["values"], float)
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 1)
    return values[k]


def error_vector(q, q_d) -> np.ndarray:
    """Vector parts of q_e = q_d^* (x) q (000 (4)), rows (n, 3), both normalised first."""
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    qd = q_d / np.linalg.norm(q_d, axis=1, keepdims=True)
    return qd[:, :1] * q[:, 1:] - np.cross(qd[:, 1:], q[:, 1:]) - qd[:, 1:] * q[:, :1]


def euler231_quaternions(sigma) -> np.ndarray:
    """Unit quaternions (scalar first, q0 >= 0) of C(sigma) = R1(gamma) R3(nu) R2(psi) for rows of
    001's [nu, psi, gamma] (plant/euler231.py ``dcm``), by Shepperd's method (accurate at every angle)."""
    s = np.atleast_2d(np.asarray(sigma, dtype=float))
    nu, psi, gam = s[:, 0], s[:, 1], s[:, 2]
    sn, cn, sp, cp, sg, cg = np.sin(nu), np.cos(nu), np.sin(psi), np.cos(psi), np.sin(gam), np.cos(gam)
    c11, c12, c13 = cn * cp, sn, -cn * sp
    c21, c22, c23 = -cg * sn * cp + sg * sp, cg * cn, cg * sn * sp + sg * cp
    c31, c32, c33 = sg * sn * cp + cg * sp, -sg * cn, -sg * sn * sp + cg * cp
    tr = c11 + c22 + c33
    cand = np.stack([1 + tr, 1 + 2 * c11 - tr, 1 + 2 * c22 - tr, 1 + 2 * c33 - tr], axis=1)
    k = np.argmax(cand, axis=1)
    r = np.sqrt(np.maximum(cand[np.arange(len(k)), k], 0.0))  # 2 |q_k|
    q = np.empty((len(k), 4))
    # C(q) = (q0^2 - qv.qv) I + 2 qv qv^T - 2 q0 [qv x]: C23 - C32 = 4 q0 q1, C31 - C13 = 4 q0 q2, C12 - C21 = 4 q0 q3
    d1, d2, d3 = c23 - c32, c31 - c13, c12 - c21
    s12, s13, s23 = c12 + c21, c13 + c31, c23 + c32
    rows = [np.array([r / 2, d1 / (2 * r), d2 / (2 * r), d3 / (2 * r)]),
            np.array([d1 / (2 * r), r / 2, s12 / (2 * r), s13 / (2 * r)]),
            np.array([d2 / (2 * r), s12 / (2 * r), r / 2, s23 / (2 * r)]),
            np.array([d3 / (2 * r), s13 / (2 * r), s23 / (2 * r), r / 2])]
    with np.errstate(divide="ignore", invalid="ignore"):
        for j in range(4):
            sel = k == j
            q[sel] = rows[j].T[sel]
    q *= np.where(q[:, :1] < 0, -1.0, 1.0)
    return q


def attitude_error(df, signals: dict, target) -> np.ndarray:
    """``attitude_error`` (rad) at every row (module docstring)."""
    t = np.asarray(df["time"], dtype=float)
    att = signals["attitude"]
    x = vec(df, att)
    if att == "plant.q":
        return attitude_error_rad(error_vector(x, command_quaternions(t, target)))
    if att == "plant.sigma":
        return attitude_error_rad(euler231_quaternions(x)[:, 1:])
    return np.abs(x[:, 0])


def held_momentum(t, u) -> np.ndarray:
    """Per channel, max_t |int_0^t u dt| (held): the momentum a wheel on that channel would store."""
    u = np.atleast_2d(u.T).T if u.ndim == 1 else u
    cum = np.zeros_like(u)
    cum[1:] = np.cumsum(u[:-1] * np.diff(t)[:, None], axis=0)
    return np.abs(cum).max(axis=0)


def buildable(peak_torque: float, peak_momentum: float, wheels: dict):
    """The smallest data-sheet wheel (by momentum, then torque) that delivers ``peak_torque`` (N.m)
    and stores ``peak_momentum`` (N.m.s) on every channel, or None: no wheel of ``wheels``
    ({name: {"tau_max", "h_max", ...}}) can."""
    fits = [(w["h_max"], w["tau_max"], name) for name, w in wheels.items()
            if peak_torque <= w["tau_max"] * (1 + 1e-9) and peak_momentum <= w["h_max"] * (1 + 1e-9)]
    return min(fits)[2] if fits else None


def fault_onset(t, active, requested_onset, fault_class: str):
    """When the fault starts (s): the drawn onset of a class that has one, the first sample where the
    catalog reports a faulty channel for the Markov class (its chain decides), None for no fault or
    a fault that never became active."""
    if fault_class == "none":
        return None
    if fault_class != "markov" and requested_onset is not None and np.isfinite(requested_onset):
        return float(requested_onset)
    if active is None:
        return None
    k = np.nonzero(np.asarray(active, float).ravel() > 0.5)[0]
    return float(t[k[0]]) if k.size else None


def measure(df, signals: dict, *, band: float, status: str, error: str | None, t_end, fault_class: str,
            onset: float | None, manoeuvres=(), target=None, nominal: float = 0.0, estimate_from: float = 5.0,
            wheels: dict | None = None, ideal: bool = True) -> dict:
    """Metrics, outcome, feasibility and detector statistic of one run (``df``: its trajectory, a
    ``time`` column and the signals; None when nothing was stored). ``onset``: the drawn onset
    (None if the class has none); ``manoeuvres``: the command's switch instants; ``wheels``: the
    data-sheet catalog (plant/hardware/datasheets.py WHEELS) for the buildable verdict of an ideal run."""
    out = dict.fromkeys(METRICS)
    out.update(outcome="failed", stop_reason=None, stop_time=None, onset=None, settle_from=None, buildable=None,
               wheel=None, statistic=None)
    started = rows(df) >= 1
    if status == "timeout" or not started:
        out["stop_reason"] = ("the wall-time limit per run" if status == "timeout" else None) or error
        return out
    t = np.asarray(df["time"], dtype=float)
    err = attitude_error(df, signals, target)
    rate = vec(df, signals["rate"])
    torque = vec(df, signals["wheel_torque"]) if "wheel_torque" in signals else vec(df, signals["delivered"])
    active = vec(df, signals["active"]) if "active" in signals and columns(df, signals["active"]) else None
    out["onset"] = fault_onset(t, active, onset, fault_class)
    finite_torque = np.all(np.isfinite(torque))
    if finite_torque and len(t) >= 1:
        out["peak_torque"] = float(np.abs(torque).max())
        mom = (np.abs(vec(df, signals["wheel_momentum"])).max(axis=0) if "wheel_momentum" in signals
               else held_momentum(t, torque))
        out["peak_momentum"] = float(np.max(mom))
        if ideal and wheels is not None:
            out["wheel"] = buildable(out["peak_torque"], out["peak_momentum"], wheels)
            out["buildable"] = out["wheel"] is not None
    if "estimate" in signals:
        est = vec(df, signals["estimate"])
        truth = vec(df, signals["truth"]) if "truth" in signals else None
        if est is not None:
            stat = np.abs(est[:, 0] - nominal) if est.shape[1] == 1 else np.linalg.norm(est - nominal, axis=1)
            out["statistic"] = (t, stat)  # the detector's (arena/detector.py); not stored in the table
            if truth is not None and truth.shape == est.shape and len(t) > 1 and np.all(np.isfinite(est)):
                out["estimate_rms_error"] = M.estimate_rms_error(t, est, truth, estimate_from)
    if status != "ok":  # started, then an FMU stopped the run: a result
        out["outcome"] = "stopped"
        out["stop_reason"] = error or "stopped"
        out["stop_time"] = float(t_end) if t_end is not None and np.isfinite(t_end) else float(t[-1])
        return out
    if len(t) < 2 or not (np.all(np.isfinite(err)) and np.all(np.isfinite(rate)) and finite_torque):
        out["outcome"] = "diverged"
        return out
    t_ref = max([t[0], *[m for m in manoeuvres if m < t[-1]], *([out["onset"]] if out["onset"] is not None
                                                                    and out["onset"] < t[-1] else [])])
    out["settle_from"] = float(t_ref)
    m = M.metric_set(t, pointing_error=err, rate_error=rate, torque=torque, band=band, t_start=t_ref,
                     settle_margin=SETTLE_MARGIN)
    out["time_to_band"] = m["time_to_band"]
    out["attitude_error_rms_after"] = m["pointing_rms_after"]
    out["attitude_error_max_after"] = m["pointing_max_after"]
    out["rate_rms_after"] = m["rate_rms_after"]
    out["rms_torque"] = m["rms_torque"]
    out["control_energy"] = m["control_energy"]
    out["final_attitude_error"] = float(err[-1])
    peak = np.abs(torque).max(axis=1)
    at_peak = float(np.mean(peak >= AT_PEAK * peak.max())) if peak.max() > 0 else 0.0
    r = np.atleast_2d(rate.T).T if rate.ndim == 1 else rate
    if np.linalg.norm(r[-1]) > DIVERGED * max(np.linalg.norm(r[0]), 0.01):
        out["outcome"] = "diverged"
    elif at_peak >= SATURATED_FRACTION:
        out["outcome"] = "saturated"
    elif m["time_to_band"] is None:
        out["outcome"] = "not settled"
    else:
        out["outcome"] = "flies"
    return out
