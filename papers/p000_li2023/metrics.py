"""Paper 000's own metrics (000 section 5.2): observer, fault-estimation and vibration-estimation
errors over the windows the scenario's ``[metrics]`` table names.

Every statistic over a window that holds no sample (a run shorter than the window, a window
outside the run) is ``None`` (``null`` in metrics.json), never 0 or NaN.
"""
import numpy as np

# [metrics] keys this paper understands (checked by the scenario loader): signals are
# 'instance.variable' names, times in s, windows [from, to] in s.
KEYS = {
    "omega": "signal", "omega_hat": "signal", "f": "signal", "f_hat": "signal",
    "eta": "signal", "eta_dot": "signal", "d2_hat": "signal",
    "settle_time": "time", "fault_onset": "time", "fault_window": "window",
}
SETTLING_LEVEL = 1e-5  # rad/s: the observer "settles" when ||omega - omega_hat|| stays below it


def _window(t, a, b):
    return (t >= a - 1e-9) & (t <= b + 1e-9)


def _max(x):
    return float(x.max()) if x.size else None


def _rms(x):
    return float(np.sqrt(np.mean(x))) if x.size else None


def metrics(result, cfg) -> dict:
    """Observer metrics (000 section 5.2) when the [metrics] table names the signals:
    ``omega`` / ``omega_hat`` (state estimate), ``f`` / ``f_hat`` (fault estimate),
    ``eta`` / ``eta_dot`` with ``d2_hat`` (vibration state). Windows: ``settle_time``
    (default 15 s), ``fault_onset`` (40 s), ``fault_window`` ([50 s, end])."""
    t = result.time
    m = {}
    if len(t) == 0:
        return m
    settle = float(cfg.get("settle_time", 15.0))
    onset = float(cfg.get("fault_onset", 40.0))
    win = cfg.get("fault_window", [50.0, float(t[-1])])
    if "omega" in cfg and "omega_hat" in cfg:
        e = np.linalg.norm(result.vector(cfg["omega"]) - result.vector(cfg["omega_hat"]), axis=1)
        m["observer_error_max_settled_before_faults"] = _max(e[_window(t, settle, onset)])
        m["observer_error_max_after_faults"] = _max(e[t >= onset])
        m["observer_error_final"] = float(e[-1])
        # first time after which the error stays below the level until the faults start (None if
        # it never does before the faults, or the run ends before them)
        before = t < onset
        above = np.nonzero((e > SETTLING_LEVEL) & before)[0]
        if t[-1] < onset or not before.any():
            m["observer_settling_time_1e-5"] = None
        elif len(above) == 0:
            m["observer_settling_time_1e-5"] = float(t[0])
        elif above[-1] + 1 < len(t) and t[above[-1] + 1] < onset:
            m["observer_settling_time_1e-5"] = float(t[above[-1] + 1])
        else:
            m["observer_settling_time_1e-5"] = None
    if "f" in cfg and "f_hat" in cfg:
        w = _window(t, float(win[0]), float(win[1]))
        f, fh = result.vector(cfg["f"])[w], result.vector(cfg["f_hat"])[w]
        rms_f = _rms(np.sum(f**2, axis=1))
        rms_e = _rms(np.sum((fh - f) ** 2, axis=1))
        m["fault_rms"] = rms_f
        m["fault_estimate_rms_error"] = rms_e
        m["fault_estimate_rms_error_ratio"] = rms_e / rms_f if rms_f else None
        for i in range(f.shape[1]):
            m[f"fault_estimate_rms_error_{i + 1}"] = _rms((fh[:, i] - f[:, i]) ** 2)
            m[f"fault_rms_{i + 1}"] = _rms(f[:, i] ** 2)
    if "eta" in cfg and "eta_dot" in cfg and "d2_hat" in cfg:
        d2 = np.hstack([result.vector(cfg["eta"]), result.vector(cfg["eta_dot"])])
        e = np.linalg.norm(result.vector(cfg["d2_hat"]) - d2, axis=1)
        w = t >= settle
        m["vibration_estimate_error_max"] = _max(e[w])
        m["vibration_state_max"] = _max(np.linalg.norm(d2, axis=1)[w])
    return m
