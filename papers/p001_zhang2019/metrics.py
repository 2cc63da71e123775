"""Paper 001's metrics (Table 1 and Fig. 5) from a run: ``metrics(result, cfg) -> dict``.

001 does not say over which window its "accuracy" is taken, nor what band defines its
"stabilization time". Our definitions (stated in every report):

* attitude accuracy (deg): max |sigma_i| over ``accuracy_window`` (default [30 s, end]), per angle
  [nu, psi, gamma]; angular-velocity accuracy (deg/s): max |omega_i| over the same window. Table 1
  prints them as "+-x";
* stabilisation time (s) for a band b (deg): the first time after which max_i |sigma_i| <= b until
  the end of the run (None if the run ends outside the band). Bands: 1e-2, 1e-4 and 3e-6 deg (the
  last is the order of Table 1's accuracies); also the same after the fault onset (the time, after
  ``fault_onset``, from which the band holds to the end);
* fault excursion: max_i |sigma_i| over the 5 s after the onset divided by that over the 5 s before;
* torque-level fault estimate: RMS over ``estimate_window`` (default [30 s, end]) of
  ||fault_torque_hat - fault_torque|| (N.m), with RMS ||fault_torque|| and their ratio; the same for
  the bias part alone (the torque M u_f the bias produces, against the estimate's bias part
  M uf_hat) when the run recorded ``u_f`` and ``uf_hat``;
* command: max |u_c,j| over the run and over the accuracy window, RMS of u_c over that window.

``cfg`` is the scenario's [metrics] table: ``euler``, ``rate`` (signals), ``control``,
``fault_torque``, ``fault_torque_hat``, ``bias``/``bias_hat`` (per-wheel u_f and uf_hat, turned
into torques with 001's M), ``rate_hat`` (observer's omega_hat, optional), ``fault_onset``,
``accuracy_window``, ``estimate_window``. (Not ``omega``/``omega_hat``: orchestrator/results/metrics.py
reads those keys with 000's windows.) Every value is JSON-safe: None for an empty window, never NaN.
"""
from __future__ import annotations

import math

import numpy as np

# [metrics] keys of 001's scenarios (checked by the scenario loader)
KEYS = {"euler": "signal", "rate": "signal", "control": "signal", "fault_torque": "signal",
        "fault_torque_hat": "signal", "bias": "signal", "bias_hat": "signal", "rate_hat": "signal",
        "fault_onset": "time", "accuracy_window": "window", "estimate_window": "window"}

BANDS_DEG = (1e-2, 1e-4, 3e-6)


def _finite(x):
    x = float(x)
    return x if math.isfinite(x) else None


def _window(t, w):
    return (t >= w[0] - 1e-9) & (t <= w[1] + 1e-9)


def _max_abs(x, m):
    return [_finite(v) for v in np.abs(x[m]).max(axis=0)] if m.any() else None


def stabilization_time(t, err, band, t_from=None):
    """First time (>= t_from) after which err <= band until the end; None if err[-1] > band."""
    m = np.ones_like(t, dtype=bool) if t_from is None else t >= t_from - 1e-9
    tt, ee = t[m], err[m]
    if len(tt) == 0 or ee[-1] > band:
        return None
    out = np.nonzero(ee > band)[0]
    return float(tt[0]) if len(out) == 0 else float(tt[out[-1] + 1])


def _rms_norm(x):
    return float(np.sqrt(np.mean(np.sum(x**2, axis=1)))) if len(x) else None


def metrics(result, cfg) -> dict:
    t = np.asarray(result.time, dtype=float)
    out = {"complete": bool(result.complete), "t_end": float(t[-1]) if len(t) else None}
    if len(t) == 0:
        return out
    t_end = float(t[-1])
    onset = float(cfg.get("fault_onset", 20.0))
    acc_w = cfg.get("accuracy_window", [30.0, t_end])
    est_w = cfg.get("estimate_window", [30.0, t_end])
    out["definitions"] = {
        "accuracy_window_s": list(map(float, acc_w)),
        "estimate_window_s": list(map(float, est_w)),
        "stabilization": "first time after which max_i |sigma_i| <= band until the end of the run",
        "bands_deg": list(BANDS_DEG),
        "fault_onset_s": onset,
    }
    if "euler" in cfg:
        sig = np.degrees(result.vector(cfg["euler"]))
        m = _window(t, acc_w)
        out["attitude_accuracy_deg"] = _max_abs(sig, m)
        err = np.abs(sig).max(axis=1)
        out["stabilization_time_s"] = {f"{b:g}": stabilization_time(t, err, b) for b in BANDS_DEG}
        out["stabilization_time_after_fault_s"] = {f"{b:g}": stabilization_time(t, err, b, onset) for b in BANDS_DEG}
        before, after = _window(t, [onset - 5.0, onset - 1e-6]), _window(t, [onset, onset + 5.0])
        if before.any() and after.any():
            out["max_attitude_before_fault_deg"] = _finite(err[before].max())
            out["max_attitude_after_fault_deg"] = _finite(err[after].max())
            ref = err[before].max()
            out["fault_excursion_ratio"] = _finite(err[after].max() / ref) if ref > 0 else None
        out["max_attitude_deg"] = _finite(err.max())
    if "rate" in cfg:
        w = np.degrees(result.vector(cfg["rate"]))
        out["rate_accuracy_deg_s"] = _max_abs(w, _window(t, acc_w))
        out["max_rate_norm_rad_s"] = _finite(np.linalg.norm(result.vector(cfg["rate"]), axis=1).max())
    if "control" in cfg:
        u = result.vector(cfg["control"])
        m = _window(t, acc_w)
        out["max_abs_u_c"] = _finite(np.abs(u).max())
        out["max_abs_u_c_window"] = _finite(np.abs(u[m]).max()) if m.any() else None
        out["rms_u_c_window"] = _rms_norm(u[m]) if m.any() else None
    if "fault_torque" in cfg and "fault_torque_hat" in cfg:
        m = _window(t, est_w)
        f, fh = result.vector(cfg["fault_torque"])[m], result.vector(cfg["fault_torque_hat"])[m]
        rf, re = _rms_norm(f), _rms_norm(fh - f)
        out["fault_torque_rms"] = rf
        out["fault_torque_estimate_rms_error"] = re
        out["fault_torque_estimate_rms_error_ratio"] = (re / rf) if (rf and re is not None) else None
        out["fault_torque_estimate_rms_error_axis"] = (
            [_finite(v) for v in np.sqrt(np.mean((fh - f) ** 2, axis=0))] if len(f) else None
        )
        if "fault_torque_mean" not in out and len(f):
            out["fault_torque_mean"] = [_finite(v) for v in f.mean(axis=0)]
            out["fault_torque_hat_mean"] = [_finite(v) for v in fh.mean(axis=0)]
    if "bias" in cfg and "bias_hat" in cfg:
        from .parameters import ZHANG2019

        m = _window(t, est_w)
        M = ZHANG2019["M"]
        b, bh = result.vector(cfg["bias"])[m] @ M.T, result.vector(cfg["bias_hat"])[m] @ M.T
        rb, re = _rms_norm(b), _rms_norm(bh - b)
        out["bias_torque_rms"] = rb
        out["bias_torque_estimate_rms_error"] = re
        out["bias_torque_estimate_rms_error_ratio"] = (re / rb) if (rb and re is not None) else None
    if "rate" in cfg and "rate_hat" in cfg:
        e = np.linalg.norm(result.vector(cfg["rate"]) - result.vector(cfg["rate_hat"]), axis=1)
        m = _window(t, est_w)
        out["observer_rate_error_max_window"] = _finite(e[m].max()) if m.any() else None
    return out
