"""Kernels of diagnosis/detectors.py: the three change detectors and their decision logic over a
sequence of samples, compiled (plant/jit.py). Same formulas, same order of operations as the
reference functions of ``diagnosis/detectors.py`` (``cusum_update``, ``glr_update``, ``chi2_update``,
``decide``); ``tests/diagnosis/test_detectors.py`` compares both to 1e-12.

One call processes K samples: ``r`` (K, n) the raw input vectors, ``t`` (K,) their instants (s),
``reset`` (K,) the reset input; ``mu0``, ``inv_sigma`` (n,) the normalisation z = (r - mu0) / sigma;
``st`` the state (updated in place, layout in ``diagnosis/detectors.py``); ``prm`` the named pack
:data:`PARAMS`. Outputs per sample: ``stat`` (K,) the decision statistic and ``event`` (K,) 1.0
at an alarm decision. The block calls it with K = 1 (or the samples of one step), the calibration
(``orchestrator/campaign/calibrate.py``) with a whole run.
"""
from __future__ import annotations

import numpy as np

from plant.jit import jit, pack

PARAMS = ("h", "persist", "latch", "restart", "t_enable", "drift", "window", "form")
H, PERSIST, LATCH, RESTART, T_ENABLE, DRIFT, WINDOW, FORM = range(len(PARAMS))
# decision state at the head of ``st``: consecutive exceeding samples, latched, alarm time (s, -1 none),
# alarms since the start, channel of the first alarm since the last reset (1-based, 0 none), alarm output
RUN, LATCHED, ALARM_TIME, N_ALARMS, CHANNEL, ALARM = range(6)
N_DECISION = 6


def params(**values):
    """The pack ``prm`` by name (:data:`PARAMS`); entries a test does not use are 0."""
    return pack(PARAMS, values)


@jit
def _enabled(t, t_enable):
    """t at or after t_enable, with the communication-point tolerance of plant/timing.py."""
    return t_enable <= t + 1e-9 * max(1.0, abs(t))


@jit
def _decide(st, s, channel, t, prm):
    """The decision of one sample (reference ``decide``): persistence, latch, restart. Returns True
    at an alarm decision (the caller then restarts the statistics if ``restart``)."""
    exceed = s >= prm[H]
    if exceed:
        st[RUN] += 1.0
    else:
        st[RUN] = 0.0
    event = exceed and st[RUN] == prm[PERSIST]
    if event:
        st[N_ALARMS] += 1.0
        if st[ALARM_TIME] < 0.0:
            st[ALARM_TIME] = t
            st[CHANNEL] = channel
        if prm[LATCH] != 0.0:
            st[LATCHED] = 1.0
        if prm[RESTART] != 0.0:
            st[RUN] = 0.0
    st[ALARM] = 1.0 if (st[LATCHED] != 0.0 or st[RUN] >= prm[PERSIST] or event) else 0.0
    return event


@jit
def _clear(st, n_stat):
    """Reset input: statistics, latch and the alarm cleared; the alarm count kept."""
    st[RUN] = 0.0
    st[LATCHED] = 0.0
    st[ALARM_TIME] = -1.0
    st[CHANNEL] = 0.0
    st[ALARM] = 0.0
    for i in range(N_DECISION, N_DECISION + n_stat):
        st[i] = 0.0


@jit
def cusum(r, t, reset, mu0, inv_sigma, st, prm, stat, event):
    """Two-sided CUSUM per channel: g+ = max(0, g+ + z - drift), g- = max(0, g- - z - drift);
    statistic max_i max(g+_i, g-_i). ``st`` = [decision (6), g+ (n), g- (n)]."""
    K, n = r.shape
    gp = N_DECISION
    gm = N_DECISION + n
    for k in range(K):
        stat[k] = 0.0
        event[k] = 0.0
        if reset[k] >= 0.5:
            _clear(st, 2 * n)
            continue
        if not _enabled(t[k], prm[T_ENABLE]):
            continue
        s = 0.0
        ch = 0
        for i in range(n):
            z = (r[k, i] - mu0[i]) * inv_sigma[i]
            a = st[gp + i] + z - prm[DRIFT]
            st[gp + i] = a if a > 0.0 else 0.0
            b = st[gm + i] - z - prm[DRIFT]
            st[gm + i] = b if b > 0.0 else 0.0
            g = st[gp + i] if st[gp + i] >= st[gm + i] else st[gm + i]
            if g > s or ch == 0:
                s = g
                ch = i + 1
        stat[k] = s
        if _decide(st, s, float(ch), t[k], prm):
            event[k] = 1.0
            if prm[RESTART] != 0.0:
                for i in range(2 * n):
                    st[gp + i] = 0.0


@jit
def _push(st, base, n, W, r_k, mu0, inv_sigma):
    """Append the normalised sample to the ring buffer of ``st`` (count at base, head at base + 1,
    W x n values from base + 2)."""
    head = int(st[base + 1])
    for i in range(n):
        st[base + 2 + head * n + i] = (r_k[i] - mu0[i]) * inv_sigma[i]
    st[base + 1] = float((head + 1) % W)
    if st[base] < W:
        st[base] += 1.0


@jit
def glr(r, t, reset, mu0, inv_sigma, st, prm, stat, event):
    """Window-limited GLR for a step in the mean of each channel: g_i = max over L = 1..min(count, W)
    of (sum of the last L z_i)^2 / (2 L); statistic max_i g_i. ``st`` = [decision (6), g (n),
    count, head, buffer (W x n)]."""
    K, n = r.shape
    W = int(prm[WINDOW])
    g0 = N_DECISION
    base = N_DECISION + n
    for k in range(K):
        stat[k] = 0.0
        event[k] = 0.0
        if reset[k] >= 0.5:
            _clear(st, n + 2 + W * n)
            continue
        if not _enabled(t[k], prm[T_ENABLE]):
            continue
        _push(st, base, n, W, r[k], mu0, inv_sigma)
        count = int(st[base])
        newest = (int(st[base + 1]) - 1 + W) % W
        s = 0.0
        ch = 0
        for i in range(n):
            S = 0.0
            g = 0.0
            for L in range(1, count + 1):
                S += st[base + 2 + ((newest - L + 1 + W) % W) * n + i]
                v = S * S / (2.0 * L)
                if v > g:
                    g = v
            st[g0 + i] = g
            if g > s or ch == 0:
                s = g
                ch = i + 1
        stat[k] = s
        if _decide(st, s, float(ch), t[k], prm):
            event[k] = 1.0
            if prm[RESTART] != 0.0:
                for i in range(n + 2 + W * n):
                    st[g0 + i] = 0.0


@jit
def chi2(r, t, reset, mu0, inv_sigma, st, prm, stat, event):
    """Windowed chi-square test over the last W samples (0 until the window is full): ``form`` 0,
    energy, statistic sum_window sum_i z_i^2 (chi2 with nW degrees of freedom under white N(0, I));
    ``form`` 1, mean, statistic sum_i (sum_window z_i)^2 / W (chi2 with n). ``st`` = [decision (6),
    contribution of each channel (n), count, head, buffer (W x n)]."""
    K, n = r.shape
    W = int(prm[WINDOW])
    c0 = N_DECISION
    base = N_DECISION + n
    mean_form = prm[FORM] != 0.0
    for k in range(K):
        stat[k] = 0.0
        event[k] = 0.0
        if reset[k] >= 0.5:
            _clear(st, n + 2 + W * n)
            continue
        if not _enabled(t[k], prm[T_ENABLE]):
            continue
        _push(st, base, n, W, r[k], mu0, inv_sigma)
        full = int(st[base]) == W
        s = 0.0
        ch = 0
        best = -1.0
        for i in range(n):
            c = 0.0
            if full:
                S = 0.0
                for j in range(W):
                    z = st[base + 2 + j * n + i]
                    if mean_form:
                        S += z
                    else:
                        c += z * z
                if mean_form:
                    c = S * S / W
            st[c0 + i] = c
            s += c
            if c > best:
                best = c
                ch = i + 1
        stat[k] = s
        if _decide(st, s, float(ch), t[k], prm):
            event[k] = 1.0
            if prm[RESTART] != 0.0:
                for i in range(n + 2 + W * n):
                    st[c0 + i] = 0.0


def empty_state(size: int) -> np.ndarray:
    """A fresh state vector of ``size`` floats: statistics 0, no alarm (alarm time -1)."""
    st = np.zeros(size)
    st[ALARM_TIME] = -1.0
    return st
