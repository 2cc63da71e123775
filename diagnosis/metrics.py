"""Per-run FDIR measures from recorded signals (numpy only): what a campaign, a study or the arena
computes from one run of a decision chain. Definitions (docs/fdir.md):

* an alarm *event* is a rise of the alarm flag (0 -> 1 between two recorded rows) or, with a
  detector's ``n_alarms`` output, every increment of it (alarms that restart the test);
* false alarms: events before the fault onset (every event of a fault-free run); their rate per
  hour is over the exposure, the recorded time at or after ``t_enable`` (and before the onset);
* detection delay: first event at or after the onset minus the onset (s); a missed detection when
  there is none (delay None);
* isolation: the isolated channel at the end of the run (0 or None: none), correct when it is the
  faulty channel; isolation time (s) the first row it is named;
* time to reconfiguration: the first row where the reconfiguration signal shows (the allocation's
  ``n_active`` below its healthy count, or any boolean series) minus the onset; a reconfiguration
  before the onset (after a false alarm) gives none and ``reconfigured_before_onset`` True.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["alarm_events", "fdir_measures"]


def alarm_events(t, alarm=None, n_alarms=None) -> np.ndarray:
    """Instants (s) of the alarm events of a run: increments of ``n_alarms`` if given, else rises of
    ``alarm`` (>= 0.5). A flag already up at the first row counts as an event there."""
    t = np.asarray(t, dtype=float)
    if n_alarms is not None:
        n = np.round(np.asarray(n_alarms, dtype=float))
        steps = np.diff(np.concatenate(([0.0], n)))
        return np.repeat(t, np.maximum(steps, 0).astype(int))
    a = np.asarray(alarm, dtype=float) >= 0.5
    rise = a & ~np.concatenate(([False], a[:-1]))
    return t[rise]


def fdir_measures(t, alarm=None, *, n_alarms=None, onset=None, faulty_channel=None, isolated=None, reconfigured=None,
                  t_enable: float = 0.0) -> dict:
    """The measures of one run (module docstring). ``t`` (s) the recorded instants; ``alarm`` the
    detector's flag and/or ``n_alarms`` its count; ``onset`` (s) the fault onset (None: fault-free);
    ``faulty_channel`` the true channel (1-based); ``isolated`` the isolation's output series;
    ``reconfigured`` a boolean series (e.g. ``n_active < 4``). Values are JSON-safe (None, never NaN)."""
    t = np.asarray(t, dtype=float)
    if alarm is None and n_alarms is None:
        raise ValueError("give the alarm flag or the alarm count")
    events = alarm_events(t, alarm, n_alarms)
    fault_free = onset is None
    end = t[-1] if fault_free else min(float(onset), t[-1])
    armed = t[(t >= t_enable - 1e-9 * max(1.0, abs(t_enable))) & (t < end - 1e-12)]
    exposure_h = (len(armed) * float(np.median(np.diff(t))) / 3600.0) if len(t) > 1 and len(armed) else 0.0
    early = events[events < end - 1e-12] if not fault_free else events
    out = {"false_alarms": int(len(early)), "exposure_hours": exposure_h,
           "false_alarms_per_hour": (len(early) / exposure_h) if exposure_h > 0 else None,
           "detection_delay_s": None, "missed_detection": None, "isolated_channel": None, "isolation_correct": None,
           "isolation_time_s": None, "time_to_reconfiguration_s": None}
    if not fault_free:
        late = events[events >= onset - 1e-9 * max(1.0, abs(onset))]
        out["detection_delay_s"] = float(late[0] - onset) if len(late) else None
        out["missed_detection"] = not len(late)
    if isolated is not None:
        iso = np.round(np.asarray(isolated, dtype=float)).astype(int)
        named = np.flatnonzero(iso > 0)
        if len(named):
            out["isolated_channel"] = int(iso[-1])
            out["isolation_time_s"] = float(t[named[0]])
            if faulty_channel is not None:
                out["isolation_correct"] = int(iso[-1]) == int(faulty_channel)
    if reconfigured is not None and not fault_free:
        rec = np.flatnonzero(np.asarray(reconfigured, dtype=bool))
        early = bool(len(rec) and t[rec[0]] < onset - 1e-9 * max(1.0, abs(onset)))
        out["reconfigured_before_onset"] = early  # after a false alarm: no time to reconfiguration
        out["time_to_reconfiguration_s"] = float(t[rec[0]] - onset) if len(rec) and not early else None
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in out.items()}
