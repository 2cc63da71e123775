"""Fault isolation from the direction of a fault estimate: names the faulty channel (a wheel, an axis,
a sensor) and says how sure it is.

Each candidate channel j has a signature s_j, column j of ``S`` (m x N): the direction the fault
estimate f (m components) takes when channel j is faulty. For wheels, S = M (001 (3)): a fault of
wheel j (lost, stuck, biased) adds a body torque along its spin axis m_j, with a sign and size that
follow the command, so only the direction is a signature. For a bank of dedicated structured
residuals (residual j sensitive to channel j only: r_j = 1 - e_hat_j of 001's ASMFEO, per-axis
residuals), S = I: the same rule then names the residual carrying the energy.

From the alarm on (input ``alarm`` >= 0.5 at a sample), the block accumulates over the samples of
the isolation window, with x_k = f_k - mu0,

    E_j = sum_k (s_j . x_k)^2 / |s_j|^2,        F = sum_k |x_k|^2,        share_j = E_j / F   (in [0, 1])

share_j is the fraction of the estimate's energy along s_j (1: every sample along s_j; for two
signatures at an angle a, a fault along one gives cos^2 a to the other: 1/3 between 001's skew
wheel and an orthogonal one). Once ``window`` seconds have passed since the first alarm sample
(window 0: at that sample), the block names j* = argmax share_j if share_j* >= ``min_confidence``
(else it keeps accumulating) and latches it until ``reset``: ``isolated`` = j* (1-based; 0 before),
``confidence`` = share_j*, ``margin`` = share_j* minus the second largest share (how distinct the
decision is), ``isolation_time`` its instant (-1 before), ``healthy`` 1 on every channel and 0 on
the isolated one (what a controller with an effectiveness input reads: 001's FONTSM allocation
001 (33) drops wheel j when e_hat_j = 0). ``min_confidence`` 0 (the default) names
the best direction at the end of the window, whatever its share: no threshold to tune. Signatures
with |s_j| = 0 are refused. An estimate that stays zero names nothing.

Timing as the detectors' (diagnosis/detectors.py): samples at t_k = t0 + k T taken in ``advance``;
outputs at t show the samples before t (no direct feedthrough). With a detector upstream, an alarm
decided at t_a shows at t_a + T, is sampled here then, and with window 0 the isolation shows at
t_a + 2T: what an allocation reading ``isolated`` sees (time to reconfiguration, docs/fdir.md).

State: [k, accumulating, t_start, F, E (N), isolated, confidence, margin, isolation time].
"""
from __future__ import annotations

import numpy as np

from diagnosis.sampling import SampleClock, next_sample
from plant.block import Block, matrix, scalar, vector
from plant.channels import channels

__all__ = ["FaultIsolation", "shares"]


def shares(S: np.ndarray, x: np.ndarray) -> np.ndarray:
    """share_j of the samples ``x`` (K, m) for the signatures ``S`` (m, N) (module docstring); zeros
    if x is zero."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    S = np.asarray(S, dtype=float)
    F = float((x * x).sum())
    if F == 0.0:
        return np.zeros(S.shape[1])
    P = x @ S
    return (P * P).sum(axis=0) / (S * S).sum(axis=0) / F


class FaultIsolation(Block):
    """Names the faulty channel from the direction of a fault estimate (module docstring).

    Inputs:  f[1..m] (the unit given), alarm (1), reset (1)
    Outputs: isolated (1: 0 none, 1..N), confidence (1), margin (1), isolation_time (s), share[1..N] (1),
             healthy[1..N] (1), t_next_sample (s)
    Parameters: S[m,N] (1, signatures), mu0[1..m] (f's unit), window (s), min_confidence (1),
             sample_period (s)
    """

    model_name = "FaultIsolation"
    description = "Fault isolation: the channel whose signature direction carries the fault estimate's energy"
    announced_instants = ("t_next_sample",)

    def __init__(self, n_components: int = 3, n_channels: int = 4, unit: str = "N.m", signatures=None):
        m, N = self.m, self.N = int(n_components), int(n_channels)
        if m < 1 or N < 2:
            raise ValueError(f"n_components >= 1 and n_channels >= 2 expected, got {n_components}, {n_channels}")
        S = np.eye(m, N) if signatures is None else np.asarray(signatures, dtype=float)
        inputs = (channels("f", m, unit, "fault estimate (or residual bank)")
                  + scalar("alarm", 0.0, "1", "alarm of a detector (>= 0.5: isolate)")
                  + scalar("reset", 0.0, "1", "reset (>= 0.5 at a sample): the isolation cleared"))
        outputs = (scalar("isolated", 0.0, "1", "isolated channel (0: none yet)")
                   + scalar("confidence", 0.0, "1", "share of the estimate's energy along the isolated signature")
                   + scalar("margin", 0.0, "1", "its share minus the second largest share")
                   + scalar("isolation_time", -1.0, "s", "instant of the isolation (-1: none)")
                   + vector("share", N, "1", "share of the estimate's energy along each signature")
                   + vector("healthy", N, "1", "1, and 0 for the isolated channel (an effectiveness input)", [1.0] * N)
                   + scalar("t_next_sample", 0.0, "s", "announced instant: next sample"))
        params = (matrix("S", S, "1", "signature of channel j: column j (e.g. the wheel matrix M)")
                  + channels("mu0", m, unit, "nominal value of f (subtracted)")
                  + scalar("window", 0.0, "s", "time from the first alarm sample to the decision")
                  + scalar("min_confidence", 0.0, "1", "share the best signature needs to be named (0: always)")
                  + scalar("sample_period", 0.01, "s", "time between samples T"))
        super().__init__(inputs, outputs, params, {})
        self.clock = None
        self.state = np.zeros(9 + N)

    ACC, T_START, F, E0 = 0, 1, 2, 3  # state: accumulating, first alarm sample, F, E (N), then the decision

    def initialize(self, t0: float) -> None:
        m, N = self.m, self.N
        self.clock = SampleClock(t0, self.p("sample_period"), self.model_name)
        S = self.p_matrix("S").reshape(m, N)
        norms = (S * S).sum(axis=0)
        if np.any(norms == 0) or not np.all(np.isfinite(S)):
            j = int(np.argmin(norms)) + 1
            raise ValueError(f"{self.model_name}: signature S[:,{j}] is zero (or not finite): every channel needs a direction")
        self.S, self.norms = S, norms
        self.mu0 = self.p_vector("mu0") if m > 1 else np.array([self.p("mu0")])
        self.window = self.p("window")
        if not self.window >= 0:
            raise ValueError(f"{self.model_name}: window = {self.window:g} s must be >= 0")
        self.min_conf = self.p("min_confidence")
        if not 0 <= self.min_conf <= 1:
            raise ValueError(f"{self.model_name}: min_confidence = {self.min_conf:g} must lie in [0, 1]")
        self.state = self._fresh()

    def _fresh(self) -> np.ndarray:
        s = np.zeros(3 + self.N + 4)
        s[-1] = -1.0  # isolation time
        return s

    @property
    def _tail(self) -> int:
        return 3 + self.N  # isolated, confidence, margin, isolation time

    def sample(self, t: float, f, alarm: float, reset: float) -> None:
        """One sample (module docstring)."""
        s, N = self.state, self.N
        if reset >= 0.5:
            self.state = self._fresh()
            return
        iso = self._tail
        if s[iso] > 0:
            return  # latched until reset
        if s[self.ACC] == 0.0:
            if alarm < 0.5:
                return
            s[self.ACC], s[self.T_START] = 1.0, t
        x = np.asarray(f, dtype=float) - self.mu0
        p = self.S.T @ x
        s[self.E0:self.E0 + N] += p * p / self.norms
        s[self.F] += float(x @ x)
        if s[self.F] > 0 and t - s[self.T_START] >= self.window - 1e-9 * max(1.0, abs(t)):
            share = s[self.E0:self.E0 + N] / s[self.F]
            order = np.argsort(-share, kind="stable")
            best = float(share[order[0]])
            if best >= self.min_conf:
                s[iso], s[iso + 1], s[iso + 2], s[iso + 3] = order[0] + 1, best, best - float(share[order[1]]), t

    def shares_now(self) -> np.ndarray:
        s, N = self.state, self.N
        return s[self.E0:self.E0 + N] / s[self.F] if s[self.F] > 0 else np.zeros(N)

    # -- the contract ------------------------------------------------------------------------------------
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        iso = self._tail
        healthy = np.ones(self.N)
        if self.state[iso] > 0:
            healthy[int(self.state[iso]) - 1] = 0.0
        return np.concatenate((self.state[iso:iso + 4], self.shares_now(), healthy, (next_sample(self.clock, t),)))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        m = self.m
        while self.clock.due(t) or self.clock.inside(t, h):
            tk = self.clock.t_next if not self.clock.due(t) else t
            self.sample(tk, u[0:m], float(u[m]), float(u[m + 1]))
            self.clock.k += 1

    def get_state(self) -> list:
        return [float(self.clock.k)] + self.state.tolist()

    def set_state(self, state) -> None:
        s = list(state)
        self.clock.k = int(s[0])
        self.state = np.array(s[1:], dtype=float)
