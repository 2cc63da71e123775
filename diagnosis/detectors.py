"""Change detectors on any estimate or residual vector: two-sided CUSUM, window-limited GLR for a step
in the mean, windowed chi-square test; each with a persistence window, a latch and a reset input.

Every detector samples its input r (n channels, any unit) at t_k = t0 + k T (``sample_period``; the
sample clock of ``plant/hardware/sampling.py``), normalises it,

    z_k,i = (r_k,i - mu0_i) / sigma_i                       (mu0, sigma: nominal mean and scale, r's unit)

and updates a test statistic s_k. The statistics (Basseville & Nikiforov, *Detection of Abrupt
Changes: Theory and Application*, Prentice-Hall 1993, "B&N"; cited by section, the equations
written out in full here; their equation numbers are not reproduced):

* :class:`CusumDetector`, B&N section 2.2 (CUSUM algorithm, recursive form g_k = (g_k-1 + s_k)^+,
  alarm at t_a = min{k : g_k >= h}) in its two-sided form for a change in the mean of a Gaussian
  sequence (B&N 2.2, two-sided CUSUM), per channel, in units of sigma::

      g+_k = max(0, g+_k-1 + z_k - drift),   g-_k = max(0, g-_k-1 - z_k - drift),   s_k = max_i max(g+_k,i, g-_k,i)

  ``drift`` = nu / 2 with nu the smallest change of the mean to detect (in sigma). B&N's
  log-likelihood form is this statistic times nu (sigma = 1): the threshold h here is in sigma.
* :class:`GlrDetector`, B&N section 2.4.3 (GLR algorithm, change of unknown magnitude in the
  mean of a Gaussian sequence, the change time and magnitude maximised out), window-limited to the
  last W samples (the finite-memory form B&N discuss for its cost), per channel::

      g_k,i = max_{1 <= L <= min(k, W)} (sum_{j=k-L+1..k} z_j,i)^2 / (2 L),          s_k = max_i g_k,i

  (the log-likelihood ratio of "the mean moved L samples ago" against "no change", sigma = 1).
* :class:`Chi2Detector`, the chi-square test over a sliding window of W samples (B&N chapter 7,
  the chi-square statistic of an additive change in a multidimensional Gaussian mean; its
  fixed-window form). ``form`` 0 (energy): s_k = sum over the window of ||z_j||^2, chi-square with
  nW degrees of freedom under white z ~ N(0, I) (it also sees a change of variance); ``form`` 1
  (mean): s_k = W ||mean of z over the window||^2, chi-square with n degrees of freedom (a change of
  the mean). s_k = 0 until the window is full.

Decision, the same for all three (B&N's stopping rule with a persistence window):

* exceedance at sample k: s_k >= h. An alarm is decided at the sample where the exceedance has held
  for ``persistence`` seconds: m = 1 + ceil(persistence / T) consecutive exceeding samples
  (persistence 0: the first exceedance). ``alarm_time`` is that sample's instant t_a (the first
  alarm since the start or the last reset; -1 before), ``channel`` the channel with the largest
  statistic then (1-based; for chi2 the largest contribution), ``n_alarms`` counts every alarm
  decision since the start (a reset keeps it);
* ``latch`` 1: ``alarm`` stays 1 from the first decision until ``reset``; 0: ``alarm`` is 1 while
  the exceedance lasts (and at the decision sample);
* ``restart`` 1: the statistics restart from zero after each decision (B&N's repeated test: the
  rule the calibration counts false alarms with, ``docs/fdir.md``); 0: they go on;
* ``reset`` input >= 0.5 at a sample: statistics, latch, alarm time and channel cleared, the sample
  ignored; ``t_enable``: samples before it are ignored (an estimator's start-up transient).

Timing: a sample is taken in ``advance`` at its instant (``happened_at``, plant/timing.py); an
instant strictly inside a communication step takes the input held over the step. Outputs at t show
the samples taken before t: no output depends directly on an input (no algebraic loop through an
allocation), and a decision at sample t_k shows from the next communication point. The statistics
run in the kernels of ``diagnosis/kernels/detectors.py``; the numpy code below is the reference
(``tests/diagnosis/test_detectors.py`` compares both).

State (``st``, a float array; rollback saves it with the clock): [run, latched, alarm time,
n_alarms, channel, alarm] then CUSUM: g+ (n), g- (n); GLR: g (n), count, head, ring buffer
(W x n of z); chi2: contributions (n), count, head, ring buffer.
"""
from __future__ import annotations

import math

import numpy as np

from diagnosis.kernels import detectors as _kernel
from diagnosis.sampling import SampleClock, next_sample
from plant import kernels
from plant.block import Block, scalar
from plant.channels import channels

__all__ = ["ChangeDetector", "CusumDetector", "GlrDetector", "Chi2Detector", "decide", "cusum_update", "glr_update",
           "chi2_update", "MAX_WINDOW"]

RUN, LATCHED, ALARM_TIME, N_ALARMS, CHANNEL, ALARM = range(6)

N_DECISION = 6
MAX_WINDOW = 100_000  # samples in a GLR / chi2 window (the state holds W x n floats)


# -- the reference statistics (numpy), one sample at a time, on the state layout of the module docstring --
def decide(st: np.ndarray, s: float, channel: int, t: float, p: dict) -> bool:
    """Persistence, latch and restart for the statistic ``s`` of the sample at ``t`` (module
    docstring); True at an alarm decision. ``p``: h, persist (samples m), latch, restart."""
    exceed = s >= p["h"]
    st[RUN] = st[RUN] + 1.0 if exceed else 0.0
    event = bool(exceed and st[RUN] == p["persist"])
    if event:
        st[N_ALARMS] += 1.0
        if st[ALARM_TIME] < 0.0:
            st[ALARM_TIME], st[CHANNEL] = t, float(channel)
        if p["latch"]:
            st[LATCHED] = 1.0
        if p["restart"]:
            st[RUN] = 0.0
    st[ALARM] = 1.0 if (st[LATCHED] or st[RUN] >= p["persist"] or event) else 0.0
    return event


def _window(st: np.ndarray, base: int, n: int, W: int) -> np.ndarray:
    """The samples in the ring buffer at ``base``, oldest first, as a (count, n) array."""
    count, head = int(st[base]), int(st[base + 1])
    buf = st[base + 2: base + 2 + W * n].reshape(W, n)
    return buf[(head - count + np.arange(count)) % W]


def _push(st: np.ndarray, base: int, n: int, W: int, z: np.ndarray) -> None:
    head = int(st[base + 1])
    st[base + 2 + head * n: base + 2 + (head + 1) * n] = z
    st[base + 1] = (head + 1) % W
    st[base] = min(st[base] + 1.0, W)


def cusum_update(st, z, n, p) -> tuple:
    """Two-sided CUSUM of B&N 2.2 on the normalised sample z: (statistic, channel)."""
    gp, gm = st[N_DECISION:N_DECISION + n], st[N_DECISION + n:N_DECISION + 2 * n]
    gp[:] = np.maximum(0.0, gp + z - p["drift"])
    gm[:] = np.maximum(0.0, gm - z - p["drift"])
    g = np.maximum(gp, gm)
    i = int(np.argmax(g))
    return float(g[i]), i + 1


def glr_update(st, z, n, p) -> tuple:
    """Window-limited GLR of B&N 2.4.3 on the normalised sample z: (statistic, channel)."""
    W, base = p["W"], N_DECISION + n
    _push(st, base, n, W, z)
    win = _window(st, base, n, W)
    S = np.cumsum(win[::-1], axis=0)  # row L-1: sum of the last L samples
    L = np.arange(1, len(win) + 1)[:, None]
    g = (S * S / (2.0 * L)).max(axis=0)
    st[N_DECISION:N_DECISION + n] = g
    i = int(np.argmax(g))
    return float(g[i]), i + 1


def chi2_update(st, z, n, p) -> tuple:
    """Windowed chi-square statistic on the normalised sample z: (statistic, channel)."""
    W, base = p["W"], N_DECISION + n
    _push(st, base, n, W, z)
    if int(st[base]) < W:
        c = np.zeros(n)
    else:
        win = _window(st, base, n, W)
        c = win.sum(axis=0) ** 2 / W if p["form"] else (win * win).sum(axis=0)
    st[N_DECISION:N_DECISION + n] = c
    i = int(np.argmax(c))
    return float(c.sum()), i + 1


class ChangeDetector(Block):
    """Base of the three detectors: interface, parameters, sample clock, decision (module docstring).

    Inputs:  r[1..n] (the unit given; a scalar ``r`` for n = 1), reset (1)
    Outputs: statistic (1), the test's per-channel statistics (1), alarm (1), alarm_time (s),
             channel (1), n_alarms (1), t_next_sample (s)
    Parameters: mu0[1..n], sigma[1..n] (r's unit), the test's own, h (1), persistence (s), latch (1),
             restart (1), t_enable (s), sample_period (s)
    """

    announced_instants = ("t_next_sample",)
    kernel = None  # the kernel function of diagnosis/kernels/detectors.py
    update = None  # the reference update function

    def __init__(self, n_channels: int = 3, unit: str = "N.m"):
        n = self.n = int(n_channels)
        if n < 1 or n != n_channels:
            raise ValueError(f"n_channels must be an integer >= 1, got {n_channels}")
        self.unit = unit
        inputs = channels("r", n, unit, "estimate or residual to test") + scalar(
            "reset", 0.0, "1", "reset (>= 0.5 at a sample): statistics, latch and alarm cleared")
        outputs = (scalar("statistic", 0.0, "1", "decision statistic of the last sample")
                   + self.statistic_outputs(n)
                   + scalar("alarm", 0.0, "1", "alarm (after persistence; held until reset if latched)")
                   + scalar("alarm_time", -1.0, "s", "instant of the first alarm decision since start or reset (-1: none)")
                   + scalar("channel", 0.0, "1", "channel with the largest statistic at that alarm (0: none)")
                   + scalar("n_alarms", 0.0, "1", "alarm decisions since the start")
                   + scalar("t_next_sample", 0.0, "s", "announced instant: next sample"))
        params = (channels("mu0", n, unit, "nominal mean of r (subtracted)")
                  + channels("sigma", n, unit, "nominal scale of r (divides), > 0", [1.0] * n)
                  + self.test_parameters()
                  + scalar("h", 5.0, "1", "threshold on the statistic (a calibration sets it: docs/fdir.md)")
                  + scalar("persistence", 0.0, "s", "time the exceedance must last before an alarm")
                  + scalar("latch", 1.0, "1", "1: the alarm holds until reset; 0: it follows the exceedance")
                  + scalar("restart", 0.0, "1", "1: the statistics restart after each alarm decision")
                  + scalar("t_enable", 0.0, "s", "samples before this instant are ignored")
                  + scalar("sample_period", 0.01, "s", "time between samples T"))
        super().__init__(inputs, outputs, params, {})
        self.clock = None
        self.st = np.zeros(N_DECISION)
        self.last = 0.0  # statistic of the last sample

    # -- what the tests declare ------------------------------------------------------------------------
    def statistic_outputs(self, n: int) -> list:  # pragma: no cover - abstract
        raise NotImplementedError

    def test_parameters(self) -> list:  # pragma: no cover - abstract
        raise NotImplementedError

    def state_size(self) -> int:  # pragma: no cover - abstract
        raise NotImplementedError

    def statistics(self) -> np.ndarray:
        """The per-channel statistic outputs from the state."""
        return self.st[N_DECISION:N_DECISION + self.n]

    # -- set-up ------------------------------------------------------------------------------------------
    def _flag(self, name: str) -> float:
        x = self.p(name)
        if x not in (0.0, 1.0):
            raise ValueError(f"{self.model_name}: {name} = {x:g} must be 0 or 1")
        return x

    def _samples(self, name: str, T: float) -> int:
        """A duration parameter (s) as a whole number of sample periods >= 1."""
        x = self.p(name)
        W = round(x / T)
        if not (x > 0 and math.isfinite(x)) or W < 1 or abs(x / T - W) > 1e-6 * max(1.0, W):
            raise ValueError(f"{self.model_name}: {name} = {x:g} s must be a whole multiple >= 1 of sample_period = {T:g} s")
        if W > MAX_WINDOW:
            raise ValueError(f"{self.model_name}: {name} = {x:g} s is {W} samples, more than {MAX_WINDOW}")
        return int(W)

    def initialize(self, t0: float) -> None:
        n = self.n
        T = self.p("sample_period")
        self.clock = SampleClock(t0, T, self.model_name)
        sigma = self.p_vector("sigma") if n > 1 else np.array([self.p("sigma")])
        if not np.all(sigma > 0) or not np.all(np.isfinite(sigma)):
            raise ValueError(f"{self.model_name}: sigma must be > 0, got {sigma.tolist()}")
        self.mu0 = self.p_vector("mu0") if n > 1 else np.array([self.p("mu0")])
        self.inv_sigma = 1.0 / sigma
        h, persistence = self.p("h"), self.p("persistence")
        if not h > 0:
            raise ValueError(f"{self.model_name}: h = {h:g} must be > 0")
        if not persistence >= 0:
            raise ValueError(f"{self.model_name}: persistence = {persistence:g} s must be >= 0")
        self.prm = {"h": h, "persist": 1 + math.ceil(persistence / T - 1e-9), "latch": self._flag("latch"),
                    "restart": self._flag("restart"), "t_enable": self.p("t_enable")}
        self.prm.update(self.test_values(T))
        self._pack_parameters()
        self.st = _kernel.empty_state(self.state_size())
        self.last = 0.0
        self._kernels = kernels.enabled()

    def test_values(self, T: float) -> dict:  # pragma: no cover - abstract
        raise NotImplementedError

    def _pack_parameters(self) -> None:
        self._pack = _kernel.params(**{k: float(self.prm.get(k, 0.0)) for k in _kernel.PARAMS if k != "window"},
                                    window=float(self.prm.get("W", 0)))

    def set_decision(self, h: float, **flags) -> None:
        """Replace the threshold (and ``latch``/``restart``, 0 or 1) of an initialised detector: what an
        offline replay over thresholds changes (diagnosis/calibration.py)."""
        if not (h > 0 and math.isfinite(h)):
            raise ValueError(f"{self.model_name}: h = {h:g} must be a finite number > 0")
        unknown = set(flags) - {"latch", "restart"}
        if unknown:
            raise ValueError(f"{self.model_name}: set_decision takes latch and restart, not {sorted(unknown)}")
        self.prm = {**self.prm, "h": float(h), **{k: float(v) for k, v in flags.items()}}
        self._pack_parameters()

    # -- the samples -----------------------------------------------------------------------------------
    def process(self, r: np.ndarray, t: np.ndarray, reset: np.ndarray) -> tuple:
        """Feed samples (r (K, n), t (K,), reset (K,)) to the statistics: (statistic (K,), event (K,)).
        Kernel or reference, the same state either way. What the block does at its sample instants
        and what the calibration replays over a whole run."""
        r = np.ascontiguousarray(r, dtype=float).reshape(-1, self.n)
        t = np.ascontiguousarray(t, dtype=float).reshape(-1)
        reset = np.ascontiguousarray(reset, dtype=float).reshape(-1)
        K = len(t)
        stat, event = np.zeros(K), np.zeros(K)
        if self._kernels:
            type(self).kernel(r, t, reset, self.mu0, self.inv_sigma, self.st, self._pack, stat, event)
            return stat, event
        p, n = self.prm, self.n
        for k in range(K):
            if reset[k] >= 0.5:
                self._clear()
                continue
            if not p["t_enable"] <= t[k] + 1e-9 * max(1.0, abs(t[k])):
                continue
            z = (r[k] - self.mu0) * self.inv_sigma
            s, ch = type(self).update(self.st, z, n, p)
            stat[k] = s
            if decide(self.st, s, ch, t[k], p):
                event[k] = 1.0
                if p["restart"]:
                    self.st[N_DECISION:] = 0.0
        return stat, event

    def replay(self, r: np.ndarray, t: np.ndarray) -> tuple:
        """A whole run from a fresh state (no reset input): (statistic (K,), event (K,)). The
        calibration's and the FDIR measures' offline replay of recorded inputs (diagnosis/calibration.py)."""
        self.st = _kernel.empty_state(self.state_size())
        self.last = 0.0
        return self.process(r, t, np.zeros(len(t)))

    def _clear(self) -> None:
        st = self.st
        st[RUN] = st[LATCHED] = st[CHANNEL] = st[ALARM] = 0.0
        st[ALARM_TIME] = -1.0
        st[N_DECISION:] = 0.0

    def _sample(self, t: float, u) -> None:
        n = self.n
        stat, _ = self.process(np.asarray(u[0:n], dtype=float)[None, :], np.array([t]), np.array([float(u[n])]))
        self.last = float(stat[0])
        self.clock.k += 1

    # -- the contract ------------------------------------------------------------------------------------
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        st = self.st
        return np.concatenate(((self.last,), self.statistics(),
                               (st[ALARM], st[ALARM_TIME], st[CHANNEL], st[N_ALARMS], next_sample(self.clock, t))))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        if self.clock.due(t):
            self._sample(t, u)
        while self.clock.inside(t, h):  # an instant inside the step: the input held over it
            self._sample(self.clock.t_next, u)

    def get_state(self) -> list:
        return [float(self.clock.k), self.last] + self.st.tolist()

    def set_state(self, state) -> None:
        s = list(state)
        self.clock.k = int(s[0])
        self.last = float(s[1])
        self.st = np.array(s[2:], dtype=float)


class CusumDetector(ChangeDetector):
    """Two-sided CUSUM per channel, B&N 2.2 (module docstring). Statistic outputs g_pos[1..n],
    g_neg[1..n] (sigma); parameter ``drift`` (sigma, nu / 2)."""

    model_name = "CusumDetector"
    description = "Two-sided CUSUM change detector (Basseville & Nikiforov 2.2): persistence, latch, reset"
    kernel = staticmethod(_kernel.cusum)
    update = staticmethod(cusum_update)

    def statistic_outputs(self, n: int) -> list:
        return (channels("g_pos", n, "1", "upward CUSUM statistic g+ (sigma)")
                + channels("g_neg", n, "1", "downward CUSUM statistic g- (sigma)"))

    def test_parameters(self) -> list:
        return scalar("drift", 0.5, "1", "drift nu/2 (sigma): half the smallest mean change to detect")

    def test_values(self, T: float) -> dict:
        d = self.p("drift")
        if not d >= 0:
            raise ValueError(f"{self.model_name}: drift = {d:g} must be >= 0")
        return {"drift": d}

    def state_size(self) -> int:
        return N_DECISION + 2 * self.n

    def statistics(self) -> np.ndarray:
        return self.st[N_DECISION:N_DECISION + 2 * self.n]


class GlrDetector(ChangeDetector):
    """Window-limited GLR for a step in the mean per channel, B&N 2.4.3 (module docstring).
    Statistic outputs g[1..n]; parameter ``window`` (s, W samples)."""

    model_name = "GlrDetector"
    description = "Window-limited GLR detector of a step in the mean (Basseville & Nikiforov 2.4.3): persistence, latch, reset"
    kernel = staticmethod(_kernel.glr)
    update = staticmethod(glr_update)

    def statistic_outputs(self, n: int) -> list:
        return channels("g", n, "1", "GLR statistic of the channel (log-likelihood ratio)")

    def test_parameters(self) -> list:
        return scalar("window", 0.5, "s", "window W T: the change is looked for in the last W samples")

    def test_values(self, T: float) -> dict:
        return {"W": self._samples("window", T)}

    def state_size(self) -> int:
        return N_DECISION + self.n + 2 + self.prm["W"] * self.n


class Chi2Detector(ChangeDetector):
    """Windowed chi-square test (module docstring). Statistic outputs g[1..n] (each channel's part of
    the statistic); parameters ``window`` (s, W samples) and ``form`` (0 energy, 1 mean)."""

    model_name = "Chi2Detector"
    description = "Windowed chi-square detector (energy or mean over a sliding window): persistence, latch, reset"
    kernel = staticmethod(_kernel.chi2)
    update = staticmethod(chi2_update)

    def statistic_outputs(self, n: int) -> list:
        return channels("g", n, "1", "the channel's part of the chi-square statistic")

    def test_parameters(self) -> list:
        return (scalar("window", 0.5, "s", "window W T of the test")
                + scalar("form", 0.0, "1", "0: energy sum ||z||^2 (nW dof); 1: W ||mean z||^2 (n dof)"))

    def test_values(self, T: float) -> dict:
        return {"W": self._samples("window", T), "form": self._flag("form")}

    def state_size(self) -> int:
        return N_DECISION + self.n + 2 + self.prm["W"] * self.n

    def degrees_of_freedom(self) -> int:
        """Degrees of freedom of the statistic under white z ~ N(0, I)."""
        return self.n if self.prm["form"] else self.n * self.prm["W"]
