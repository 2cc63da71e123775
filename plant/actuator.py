"""Actuator path from commanded torque to applied torque, with faults and disturbance.

All torques in N·m, times in s. Each function implements one formula so that it can be
tested against it directly.
"""
import math

import numpy as np

from .timing import happened_at

SATURATE_PER_AXIS = 0  # |u_i| <= u_max for each axis
SATURATE_ONE_NORM = 1  # ||u||_1 <= u_max, 000 section 2 ("0 <= ||u||_1 < u_max"), scaled


def saturate(u: np.ndarray, u_max: float, mode: int = SATURATE_PER_AXIS) -> np.ndarray:
    """Input saturation. Per-axis clipping, or scaling of the whole vector onto the
    1-norm ball of radius ``u_max`` (direction preserved), as 000 writes the constraint."""
    if mode == SATURATE_ONE_NORM:
        n1 = float(np.abs(u).sum())
        return u * (u_max / n1) if n1 > u_max else u.copy()
    return np.clip(u, -u_max, u_max)


def misalignment(a_deg, b_deg) -> np.ndarray:
    """Delta Gamma of 000 section 5: column j holds Delta a_j cos(Delta b_j) off the diagonal.

    Reading chosen: Delta a (deg) is the small misalignment angle, used in radians, so the
    off-diagonal entries are rad(Delta a_j) * cos(rad(Delta b_j)) (about 3.5e-3 for 0.2 deg)."""
    a = np.radians(np.asarray(a_deg, dtype=float))
    b = np.radians(np.asarray(b_deg, dtype=float))
    col = a * np.cos(b)
    dg = np.tile(col, (3, 1))
    np.fill_diagonal(dg, 0.0)
    return dg


def switched(T: float, t: float, window=None) -> bool:
    """Has the event at ``T`` happened at time ``t``? Inside a step (``window``, a
    ``plant.timing.StepWindow``) by the one-sided rule of ``plant/timing.py``; at a communication
    point (``window`` None) from the right. Host time arithmetic cannot change the answer."""
    return window.active(T, t) if window is not None else happened_at(T, t)


def li2023_fault(t: float, scale: float = 1.0, onset: float = 40.0, window=None) -> tuple:
    """Additive actuator fault f(t) of 000 (66), times shifted so that ``onset`` = 40 s.

    f1 = 0.5 (t-40)^0.2 sin(0.2 (t-40)) for t > 40; f2 = 1 from 40 to 70 s, 0 from 70 to 100 s,
    1.5 after 100 s; f3 = 0. ``scale`` = 0.2 gives 000's weak faults, 0 disables the fault.
    The switches at 40, 70 and 100 s follow :func:`switched` (at a switch instant on the
    communication grid the new value holds from that instant on; 000 (66) leaves the value at
    the instant itself open). ``window``: the step being integrated, None at a point."""
    if scale == 0.0 or not switched(onset, t, window):
        return 0.0, 0.0, 0.0
    after_60 = switched(onset + 60.0, t, window)
    f1, f2 = li2023_fault_values(t, scale, onset, after_60, not after_60 and switched(onset + 30.0, t, window))
    return f1, f2, 0.0


def li2023_fault_values(t: float, scale: float, onset: float, after_60: bool, after_30: bool) -> tuple:
    """(f1, f2) of 000 (66) once the fault has started: ``after_60`` / ``after_30``, whether the
    switches at onset + 60 s / onset + 30 s have happened (:func:`li2023_fault` decides by
    :func:`switched`). Plain float arithmetic: the kernels compile this very function
    (``plant/kernels/common.py``)."""
    tau = max(t - onset, 0.0)
    f1 = 0.5 * tau**0.2 * math.sin(0.2 * tau)
    if after_60:
        f2 = 1.5
    elif after_30:
        f2 = 0.0
    else:
        f2 = 1.0
    return scale * f1, scale * f2


def li2023_disturbance(t: float, scale: float = 1.0) -> tuple:
    """External disturbance u_d(t) of 000 section 5 (N·m), times ``scale``. The kernels compile
    this very function (``plant/kernels/common.py: disturbance``): keep it plain float arithmetic."""
    if scale == 0.0:
        return 0.0, 0.0, 0.0
    a = 0.2 * math.pi * t
    b = 0.4 * math.pi * t
    k = 1e-4 * scale
    return (
        k * (-3.0 + 4.0 * math.cos(a) - math.cos(b)),
        k * (4.0 + 3.0 * math.sin(a) - 2.0 * math.cos(b)),
        k * (-3.0 + 4.0 * math.sin(a) - 3.0 * math.sin(b)),
    )


def effectiveness_and_bias(t, e, e_onset, bias, bias_onset, window=None):
    """001 (5): u = E u_c + u_f. Returns (diag of E, u_f) in force at time t: E = I before
    ``e_onset``, u_f = 0 before ``bias_onset`` (onsets by :func:`switched`)."""
    e_now = e if switched(e_onset, t, window) else np.ones_like(e)
    uf_now = bias if switched(bias_onset, t, window) else np.zeros_like(bias)
    return e_now, uf_now
