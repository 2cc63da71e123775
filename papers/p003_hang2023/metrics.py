"""Paper 003's metrics of one run (Figs. 3-12 quantities), JSON-safe (None for empty windows, never NaN).

``metrics(result, cfg)``: ``result`` a RunResult, ``cfg`` the scenario's [metrics] table naming the
signals ``theta``, ``theta_dot``, ``command`` (u), ``torque`` (rho u), ``vibration`` (d0 of 003 (2.3)),
``external`` (T_d), optionally ``estimate`` (d0_hat; absent without observer), and the numbers
``onset`` (fault time, 20 s), ``settle`` (observer transient, 1 s), ``band`` (attitude band, 1e-3 rad),
``chatter_window`` ([from, to], default [onset + 5, end]).

* Disturbance estimation (Figs. 5-6): e_d0 = d0 - d0_hat (what 003 plots) and the lumped error
  e_lumped = d0 + T_d - (1 - rho) u - d0_hat (what the observer estimates, 003 (3.3); d0 + T_d - d0_hat
  when ``observer_delivered`` = 1, the observer fed the delivered torque rho u); max |e| over
  [settle, onset] and [onset + settle, end], against the peak |d0| of the same window.
* Attitude (Figs. 9-12): theta at the onset, max |theta| after the onset, over the last 10 s, theta at the
  end, RMS theta after the onset, the time after which |theta| stays within ``band``.
* Control (Figs. 7-8): max |u|, max |u| after the onset, chattering as RMS(du/dt) and total variation
  per second of u over the chatter window (u is held over each step: du/dt = (u_k+1 - u_k) / h).
"""
from __future__ import annotations

import numpy as np

# [metrics] keys of 003's scenarios (checked by the scenario loader)
KEYS = {"theta": "signal", "theta_dot": "signal", "command": "signal", "torque": "signal", "vibration": "signal",
        "external": "signal", "estimate": "signal", "modes": "signal", "onset": "time", "settle": "time",
        "band": "number", "chatter_window": "window", "observer_delivered": "number"}


def _col(result, ref):
    return result.column(ref) if ref in result.columns else result.vector(ref)


def _max(x):
    return float(np.abs(x).max()) if len(x) else None


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x)))) if len(x) else None


def settle_time(t, y, band):
    out = np.nonzero(np.abs(y) > band)[0]
    if len(out) == 0:
        return float(t[0])
    return None if out[-1] == len(y) - 1 else float(t[out[-1] + 1])


def chattering(t, u, window):
    """(RMS du/dt, total variation per second) of the held command u over ``window``."""
    w = (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)
    tt, uu = t[w], u[w]
    if len(tt) < 3:
        return None, None
    du = np.diff(uu)
    return float(np.sqrt(np.mean((du / np.diff(tt)) ** 2))), float(np.abs(du).sum() / (tt[-1] - tt[0]))


def metrics(result, cfg) -> dict:
    t = result.time
    m = {"paper": "003", "complete": bool(result.complete)}
    if len(t) < 3:
        return m
    onset = float(cfg.get("onset", 20.0))
    settle = float(cfg.get("settle", 1.0))
    band = float(cfg.get("band", 1e-3))
    end = float(t[-1])
    th, thd = _col(result, cfg["theta"]), _col(result, cfg["theta_dot"])
    u, tau = _col(result, cfg["command"]), _col(result, cfg["torque"])
    d0, td = _col(result, cfg["vibration"]), _col(result, cfg["external"])
    pre = (t >= settle - 1e-9) & (t <= onset + 1e-9)
    post = t >= onset + settle - 1e-9
    after = t >= onset - 1e-9
    m.update(onset=onset, settle=settle, band=band, t_end=end)
    m["d0_peak"] = _max(d0)
    m["d0_peak_pre_fault"], m["d0_peak_post_fault"] = _max(d0[pre]), _max(d0[post])
    m["external_peak"] = _max(td)
    if "estimate" in cfg:
        dh = _col(result, cfg["estimate"])
        e_d0 = d0 - dh
        if float(cfg.get("observer_delivered", 0)):  # fed the delivered torque rho u: the fault is not in (3.3)
            e_lump = d0 + td - dh
        else:
            e_lump = d0 + td + (tau - u) - dh  # 003 (3.3): d0_hat -> d0 + d1 - (1 - rho) u
        for key, e in (("d0", e_d0), ("lumped", e_lump)):
            m[f"estimation_error_{key}_max_pre_fault"] = _max(e[pre])
            m[f"estimation_error_{key}_max_post_fault"] = _max(e[post])
            m[f"estimation_error_{key}_rms_post_fault"] = _rms(e[post])
        pk = m["d0_peak_pre_fault"]
        m["estimation_error_d0_ratio_pre_fault"] = (m["estimation_error_d0_max_pre_fault"] / pk) if pk else None
        pk2 = m["d0_peak_post_fault"]
        m["estimation_error_lumped_ratio_post_fault"] = (m["estimation_error_lumped_max_post_fault"] / pk2
                                                         if pk2 else None)
    m["theta_at_onset"] = float(np.interp(onset, t, th)) if end >= onset else None
    m["theta_max_after_onset"] = _max(th[after])
    m["theta_rms_after_onset"] = _rms(th[after])
    m["theta_max_last_10s"] = _max(th[t >= end - 10.0])
    m["theta_dot_max_last_10s"] = _max(thd[t >= end - 10.0])
    m["theta_final"] = float(th[-1])
    for T in (5.0, 10.0, 20.0, 40.0, 60.0):
        m[f"theta_at_{T:g}s"] = float(np.interp(T, t, th)) if end >= T else None
    m["settling_time_band"] = settle_time(t, th, band)
    m["max_abs_u"], m["max_abs_u_after_onset"] = _max(u), _max(u[after])
    m["max_abs_tau"] = _max(tau)
    win = cfg.get("chatter_window", [min(onset + 5.0, end), end])
    m["chatter_window"] = [float(win[0]), float(win[1])]
    m["du_dt_rms"], m["u_total_variation_per_s"] = chattering(t, u, win)
    return m
