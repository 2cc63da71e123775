"""The arena's one metric set (issue 26 item 5): pure functions over one trajectory (numpy arrays
sampled at the run's rows), so that every method on every plant is measured the same way.

Conventions:

* ``t`` is the row times (s), strictly increasing; signals are arrays with one row per time
  (shape (n,) or (n, k)).
* Commands and torques are held from one row to the next (the zero-order hold of the co-simulation),
  so integrals are the held sums sum_k v_k (t_k+1 - t_k) (:func:`held_integral`, the rule
  ``orchestrator/results.py`` uses for 000's energy), exact for a fixed- or multi-rate run.
* Attitude errors are principal angles (rad): :func:`pointing_error_quaternion` for an error
  quaternion (000 (4)), :func:`pointing_error_between` for a quaternion and its target,
  :func:`pointing_error_euler231` for 001's Euler angles and their target, ``abs(theta - theta_d)``
  on the pitch axis. Rate errors are norms of the rate error (rad/s).
* A metric that a run cannot define (never reaches the band, no fault) is ``None``: the JSON
  writers keep it as null, never NaN.

Functions: :func:`time_to_band` (settling into a pointing band), :func:`error_after` (pointing /
rate error statistics after settling), :func:`peak_torque`, :func:`rms_torque`,
:func:`control_energy`, :func:`momentum_used`, :func:`peak_wheel_momentum`,
:func:`estimate_rms_error`, :func:`detection_time`, :func:`detection_delay`,
:func:`false_alarm`, :func:`false_alarm_rate`; :func:`metric_set` computes them all for one run.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = [
    "held_integral", "pointing_error_quaternion", "pointing_error_between", "pointing_error_euler231",
    "time_to_band", "error_after", "peak_torque", "rms_torque", "control_energy", "momentum_used",
    "peak_wheel_momentum", "estimate_rms_error", "detection_time", "detection_delay", "false_alarm",
    "false_alarm_rate", "metric_set",
]


def _t(t) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size == 0:
        raise ValueError(f"t: a non-empty 1-D array of times is needed, got shape {t.shape}")
    if t.size > 1 and not np.all(np.diff(t) > 0):
        raise ValueError("t: times must be strictly increasing")
    return t


def _rows(t, x, name: str) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.shape[0] != t.shape[0]:
        raise ValueError(f"{name}: {x.shape[0]} rows for {t.shape[0]} times")
    return x


def _norm(x) -> np.ndarray:
    """Row norms of an (n, k) array; |x| of an (n,) array."""
    return np.abs(x) if x.ndim == 1 else np.linalg.norm(x, axis=1)


def held_integral(t, v) -> float:
    """int v dt for v held from each row to the next: sum_k v_k (t_k+1 - t_k) (the last row holds
    for no time)."""
    t = _t(t)
    v = _rows(t, v, "v")
    if t.size < 2:
        return 0.0
    return float(np.sum(v[:-1] * np.diff(t)))


def _cumulative(t, v) -> np.ndarray:
    """Held integrals from t_0 to each row: rows (n, k) of int_0^t_i v dt."""
    out = np.zeros_like(v, dtype=float)
    out[1:] = np.cumsum(v[:-1] * np.diff(t).reshape((-1,) + (1,) * (v.ndim - 1)), axis=0)
    return out


# -- attitude errors -------------------------------------------------------------------------------
def pointing_error_quaternion(q_e) -> np.ndarray:
    """Principal angle 2 atan2(||q_ev||, |q_e0|) (rad, in [0, pi]) of error quaternions (n, 4),
    scalar first; q and -q give the same angle."""
    q = np.atleast_2d(np.asarray(q_e, dtype=float))
    return 2.0 * np.arctan2(np.linalg.norm(q[:, 1:4], axis=1), np.abs(q[:, 0]))


def pointing_error_between(q, q_d) -> np.ndarray:
    """Principal angle of the rotation between attitudes q and q_d (rows (n, 4) or one q_d):
    2 acos(|q . q_d|) for unit quaternions, computed as 2 atan2(||q_d^* (x) q||_v, |q . q_d|)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    qd = np.broadcast_to(np.atleast_2d(np.asarray(q_d, dtype=float)), q.shape)
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    qd = qd / np.linalg.norm(qd, axis=1, keepdims=True)
    dot = np.abs(np.sum(q * qd, axis=1))
    # vector part of q_d^* (x) q (000 (4)): q_d0 q_v - q_dv x q_v - q_dv q0
    ev = qd[:, :1] * q[:, 1:] - np.cross(qd[:, 1:], q[:, 1:]) - qd[:, 1:] * q[:, :1]
    return 2.0 * np.arctan2(np.linalg.norm(ev, axis=1), dot)


def pointing_error_euler231(sigma, sigma_d=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Principal angle between the attitudes of 2-3-1 Euler angles sigma (n, 3) and sigma_d:
    acos((trace(C(sigma) C(sigma_d)^T) - 1) / 2), C of plant/euler231.py."""
    from plant.euler231 import dcm

    s = np.atleast_2d(np.asarray(sigma, dtype=float))
    Cd = dcm(np.asarray(sigma_d, dtype=float))
    out = np.empty(s.shape[0])
    for i, row in enumerate(s):
        c = (np.trace(dcm(row) @ Cd.T) - 1.0) / 2.0
        out[i] = math.acos(min(1.0, max(-1.0, c)))
    return out


# -- pointing ------------------------------------------------------------------------------------------
def time_to_band(t, err, band: float, t_start: float | None = None):
    """Time (s, from ``t_start``, default t_0) after which the error stays within ``band`` to the
    end of the run: the crossing of the band after the last row outside it, linearly interpolated
    between that row and the next. 0 if the error is inside from ``t_start`` on; None if the last
    row is outside the band (never settles)."""
    t = _t(t)
    e = _norm(_rows(t, err, "err"))
    t0 = t[0] if t_start is None else float(t_start)
    sel = t >= t0
    ts, es = t[sel], e[sel]
    if ts.size == 0:
        return None
    out = np.nonzero(es > band)[0]
    if out.size == 0:
        return 0.0
    k = int(out[-1])
    if k == ts.size - 1:
        return None
    e0, e1 = es[k], es[k + 1]
    frac = (e0 - band) / (e0 - e1) if e0 != e1 else 1.0
    return float(ts[k] + frac * (ts[k + 1] - ts[k]) - t0)


def error_after(t, err, t_from: float | None) -> dict:
    """Statistics of an error's norm over t >= t_from (after settling): ``rms`` (held, over the
    window's duration), ``max``, ``final``; all None if t_from is None or the window is empty."""
    t = _t(t)
    e = _norm(_rows(t, err, "err"))
    if t_from is None:
        return {"rms": None, "max": None, "final": None}
    sel = t >= t_from
    if not sel.any():
        return {"rms": None, "max": None, "final": None}
    ts, es = t[sel], e[sel]
    dur = ts[-1] - ts[0]
    rms = math.sqrt(held_integral(ts, es**2) / dur) if dur > 0 else float(es[0])
    return {"rms": rms, "max": float(es.max()), "final": float(es[-1])}


# -- effort -----------------------------------------------------------------------------------------------
def peak_torque(u) -> dict:
    """``axis``: max_t max_i |u_i| (the per-actuator peak, N.m), ``norm``: max_t ||u|| (N.m)."""
    u = np.atleast_1d(np.asarray(u, dtype=float))
    a = np.abs(u)
    return {"axis": float(a.max()), "norm": float(_norm(u).max())}


def rms_torque(t, u) -> float:
    """sqrt(int ||u||^2 dt / T) over the run (held), N.m."""
    t = _t(t)
    u = _rows(t, u, "u")
    T = t[-1] - t[0]
    n2 = _norm(u) ** 2
    return math.sqrt(held_integral(t, n2) / T) if T > 0 else float(math.sqrt(n2[0]))


def control_energy(t, u) -> float:
    """E = int ||u||^2 dt (000 section 5), held, N^2.m^2.s."""
    t = _t(t)
    return held_integral(t, _norm(_rows(t, u, "u")) ** 2)


def momentum_used(t, tau) -> float:
    """max_t ||int_0^t tau dt|| (N.m.s): the momentum ideal wheels would have stored delivering the
    body torque ``tau`` (held) from rest; for a plant without wheels the momentum the manoeuvre
    needs."""
    t = _t(t)
    tau = _rows(t, tau, "tau")
    return float(_norm(_cumulative(t, tau)).max())


def peak_wheel_momentum(h, h_max: float | None = None) -> dict:
    """From wheel momenta h (n, N): ``peak`` max_t max_j |h_j| (N.m.s) and, with ``h_max``, the
    ``fraction`` of the capacity used."""
    a = float(np.abs(np.asarray(h, dtype=float)).max())
    return {"peak": a, "fraction": None if not h_max else a / float(h_max)}


# -- fault estimation ------------------------------------------------------------------------------------
def estimate_rms_error(t, f_hat, f, t_from: float | None = None, t_to: float | None = None):
    """sqrt(int ||f_hat - f||^2 dt / T) over [t_from, t_to] (held); None for an empty window."""
    t = _t(t)
    d = _rows(t, f_hat, "f_hat") - _rows(t, f, "f")
    sel = np.ones(t.size, dtype=bool)
    if t_from is not None:
        sel &= t >= t_from
    if t_to is not None:
        sel &= t <= t_to
    if not sel.any():
        return None
    ts, n2 = t[sel], _norm(d[sel]) ** 2
    T = ts[-1] - ts[0]
    return math.sqrt(held_integral(ts, n2) / T) if T > 0 else float(math.sqrt(n2[0]))


def detection_time(t, signal, threshold: float, t_from: float | None = None):
    """First row time >= ``t_from`` at which ||signal|| > ``threshold`` (s); None if never."""
    t = _t(t)
    s = _norm(_rows(t, signal, "signal"))
    sel = (s > threshold) & ((t >= t_from) if t_from is not None else True)
    k = np.nonzero(sel)[0]
    return float(t[k[0]]) if k.size else None


def detection_delay(t, signal, threshold: float, onset: float):
    """Time from the fault ``onset`` until the estimate's norm first exceeds ``threshold`` at or
    after it (s); None if it never does."""
    td = detection_time(t, signal, threshold, onset)
    return None if td is None else td - float(onset)


def false_alarm(t, signal, threshold: float, t_from: float | None = None, t_to: float | None = None) -> bool:
    """Does ||signal|| exceed ``threshold`` anywhere in [t_from, t_to] (a fault-free draw: an alarm
    is false)? ``t_from`` skips the estimator's start-up transient."""
    t = _t(t)
    s = _norm(_rows(t, signal, "signal"))
    sel = np.ones(t.size, dtype=bool)
    if t_from is not None:
        sel &= t >= t_from
    if t_to is not None:
        sel &= t <= t_to
    return bool(np.any(s[sel] > threshold))


def false_alarm_rate(alarms, z: float = 1.959963984540054) -> dict:
    """Rate of false alarms over fault-free draws with the Wilson score interval (95 % by default):
    ``rate``, ``low``, ``high``, ``draws``. Empty: all None, 0 draws."""
    a = [bool(x) for x in alarms]
    n = len(a)
    if n == 0:
        return {"rate": None, "low": None, "high": None, "draws": 0}
    p = sum(a) / n
    d = 1.0 + z * z / n
    c = (p + z * z / (2 * n)) / d
    w = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return {"rate": p, "low": max(0.0, c - w), "high": min(1.0, c + w), "draws": n}


# -- all of them for one run ----------------------------------------------------------------------------
def metric_set(t, *, pointing_error, rate_error, torque, band: float, t_start: float | None = None,
               settle_margin: float = 0.0, body_torque=None, wheel_momentum=None, h_max: float | None = None,
               fault=None, fault_hat=None, onset: float | None = None, threshold: float | None = None,
               estimate_from: float | None = None) -> dict:
    """The arena's metrics of one run (JSON-safe: floats, bools or None).

    ``pointing_error`` (rad) and ``rate_error`` (rad/s, rows or norms), ``torque`` (the commands
    or per-actuator torques at the plant, N.m), ``band`` (rad) the pointing band, ``t_start`` the
    start of the manoeuvre, ``settle_margin`` (s) added to the settling time before the after-
    settling statistics; ``body_torque`` (default ``torque``) for the momentum used;
    ``wheel_momentum`` (n, N) with ``h_max`` for the wheels' peak; ``fault``/``fault_hat`` the
    true equivalent fault and its estimate (same shape), ``onset`` and the detection ``threshold``
    (N.m) for the detection delay (after the onset) or the false alarm (no onset: a fault-free draw,
    judged from ``estimate_from``)."""
    t = _t(t)
    ts = time_to_band(t, pointing_error, band, t_start)
    t_settled = None if ts is None else (t[0] if t_start is None else t_start) + ts + settle_margin
    p = error_after(t, pointing_error, t_settled)
    w = error_after(t, rate_error, t_settled)
    pk = peak_torque(torque)
    m = {
        "time_to_band": ts, "settled": ts is not None,
        "pointing_rms_after": p["rms"], "pointing_max_after": p["max"], "pointing_final": p["final"],
        "rate_rms_after": w["rms"], "rate_max_after": w["max"],
        "peak_torque_axis": pk["axis"], "peak_torque_norm": pk["norm"], "rms_torque": rms_torque(t, torque),
        "control_energy": control_energy(t, torque),
        "momentum_used": momentum_used(t, torque if body_torque is None else body_torque),
    }
    if wheel_momentum is not None:
        wm = peak_wheel_momentum(wheel_momentum, h_max)
        m["wheel_momentum_peak"], m["wheel_momentum_fraction"] = wm["peak"], wm["fraction"]
    if fault is not None and fault_hat is not None:
        m["estimate_rms_error"] = estimate_rms_error(t, fault_hat, fault, estimate_from)
        if threshold is not None:
            if onset is not None:
                m["detection_delay"] = detection_delay(t, fault_hat, threshold, onset)
            else:
                m["false_alarm"] = false_alarm(t, fault_hat, threshold, estimate_from)
    return m
