"""One actuator-fault catalog for any plant (issue 26 item 3): N actuator channels, body torquers
(000/004: N = 3), wheels (001: N = 4) or the pitch axis (002/003: N = 1).

The block sits between the command and the plant (like ``plant/mode_faults.py``): the plant's own
fault models stay off and it receives u_f, the torque the faulty actuators deliver:

    u_f,j = e_j(t) u_j + b_j(t)       on a faulty channel j (``channel`` = j, or every channel: 0)
    u_f,j = u_j                       on the others

with, by ``fault_class`` (onset T = ``onset``, loss fraction l = ``loss`` in [0, 1], magnitude
m = ``magnitude`` in N.m):

====  =====================  ==================================================================
 0    none                   e = 1, b = 0
 1    loss of effectiveness  e = 1 - l from T on (001 (5)'s E, 002/003's rho = 1 - l)
      (step)
 2    loss of effectiveness  e = 1 - l min(1, (t - T) / ``ramp_time``) from T on
      (ramp)
 3    additive bias          b = m from T on (001 (5)'s u_f)
 4    intermittent           e = 1 - l while (t - T) mod ``period`` < ``duty`` ``period``, else 1
 5    time-varying           b = m sin(2 pi (t - T) / ``period``) from T on (the form of 000
                             (66)'s f1 with a fixed amplitude)
 6    stuck                  u_f,j frozen from T on: at the command of the first communication point
                             at or after T (``stuck_mode`` = 0, lock-in-place), or at m (1);
                             e = 0 and b = the frozen value in the ground truth
 7    actuator lost          e = 0 from T on (one wheel lost: ``channel`` = j)
 8    Markov switching       004 (9)-(11): u_f = F_r u + G_r v with the mode r(t) of a nonhomogeneous
                             Markov chain (``plant/markov.py``: rates Pi[l,i,j], alpha profile, r0,
                             seed) and the tables F[r,j], G[r,j], v[j] (004's three cases by
                             default in the arena's factories)
====  =====================  ==================================================================

Onset, loss, magnitude, faulty channel, ramp time, period, duty and the Markov seed are parameters: a
campaign disperses them per draw.

Ground truth (outputs, for logging and for the estimators' errors): ``u_f`` (delivered),
``fault`` = u_f - u (the additive equivalent, 000 (6)'s f_eq; body-level for body torquers, per
wheel otherwise: ``controller/allocation.py: WheelsToBody`` maps it to the body), ``e`` and ``b``
in force, ``active`` (1 while any channel is faulty), ``mode`` (Markov mode r(t); 1 for the other
classes: a mode-dependent controller then uses its healthy-mode gains, it is not told the
fault) and ``t_next_event`` (announced instant: the next time u_f switches, 1e300 if none).

Timing: the block is static between its events; its output changes at communication points only
(the master holds it over a step). An event at T acts from the first communication point t with
``happened_at(T, t)`` (plant/timing.py); a master that lands on ``t_next_event`` makes it exact.

State: the frozen values of class 6 and the Markov chain of class 8 (mode, next jump, PCG64 state:
rollback and reruns are bit for bit). Every other class is a pure function of time.
"""
from __future__ import annotations

import math

import numpy as np

from .block import Block, Variable, scalar, vector
from .channels import channels
from .markov import ALPHA_CONSTANT, ALPHA_PROFILES, T_NEVER, AlphaProfile, MarkovChain, check_vertices
from .timing import happened_at

NONE, LOE_STEP, LOE_RAMP, BIAS, INTERMITTENT, TIME_VARYING, STUCK, LOST, MARKOV = range(9)
FAULT_CLASSES = {
    NONE: "none", LOE_STEP: "loss of effectiveness (step)", LOE_RAMP: "loss of effectiveness (ramp)",
    BIAS: "additive bias", INTERMITTENT: "intermittent loss of effectiveness", TIME_VARYING: "time-varying additive",
    STUCK: "stuck actuator", LOST: "actuator lost", MARKOV: "Markov switching (004 (9)-(11))",
}
N_MARKOV_MODES = 3  # 004's cases I-III
N_VERTICES = 2  # 004 (52)


class FaultCatalog(Block):
    """The fault catalog on N channels (module docstring).

    Inputs:  u[1..N] N.m (commanded torques)
    Outputs: u_f[1..N] N.m, fault[1..N] N.m, e[1..N] 1, b[1..N] N.m, active 1, mode 1, t_next_event s
    """

    model_name = "FaultCatalog"
    description = "Actuator fault catalog: loss of effectiveness, bias, intermittent, time-varying, stuck, lost, Markov"
    announced_instants = ("t_next_event",)

    def __init__(self, n_channels: int = 3):
        n = self.n = int(n_channels)
        if n < 1 or n != n_channels:
            raise ValueError(f"n_channels must be an integer >= 1, got {n_channels}")
        R, Z = N_MARKOV_MODES, N_VERTICES
        inputs = channels("u", n, "N.m", "commanded torque")
        outputs = (channels("u_f", n, "N.m", "torque delivered by the faulty actuators")
                   + channels("fault", n, "N.m", "additive fault equivalent u_f - u (ground truth)")
                   + channels("e", n, "1", "effectiveness in force (ground truth)", [1.0] * n)
                   + channels("b", n, "N.m", "additive fault in force (ground truth)")
                   + scalar("active", 0, "1", "1 while a channel is faulty")
                   + scalar("mode", 1, "1", "Markov fault mode r(t) (1 for the other classes)")
                   + scalar("t_next_event", T_NEVER, "s", "announced instant: next switch of u_f"))
        params = (
            scalar("fault_class", NONE, "1", "0 none, 1 LOE step, 2 LOE ramp, 3 bias, 4 intermittent, "
                                              "5 time-varying, 6 stuck, 7 lost, 8 Markov")
            + scalar("channel", 0, "1", f"faulty channel 1..{n} (0: every channel)")
            + scalar("onset", 0.0, "s", "fault onset T")
            + scalar("loss", 0.0, "1", "classes 1, 2, 4: lost fraction of effectiveness, in [0, 1]")
            + scalar("magnitude", 0.0, "N.m", "classes 3, 5: bias / amplitude; class 6 with stuck_mode 1: stuck value")
            + scalar("ramp_time", 10.0, "s", "class 2: time from onset to the full loss")
            + scalar("period", 10.0, "s", "classes 4, 5: period")
            + scalar("duty", 0.5, "1", "class 4: fraction of each period the fault is on")
            + scalar("stuck_mode", 0, "1", "class 6: 0 lock-in-place (command at onset), 1 stuck at magnitude")
            + [Variable(f"F[{r + 1},{j + 1}]", "1", "class 8: effectiveness f_rj in mode r, 004 (9)", 1.0)
               for r in range(R) for j in range(n)]
            + [Variable(f"G[{r + 1},{j + 1}]", "1", "class 8: bias input g_rj in mode r, 004 (9)", 0.0)
               for r in range(R) for j in range(n)]
            + vector("v", n, "N.m", "class 8: bias fault v, 004 (9)")
        )
        params += (
            [Variable(f"Pi[{l + 1},{i + 1},{j + 1}]", "1/s", "class 8: transition rate, vertex l, from i to j")
             for l in range(Z) for i in range(R) for j in range(R)]
            + scalar("alpha_profile", ALPHA_CONSTANT, "1", "class 8: 0 constant alpha, 1 004 (52), 2 random")
            + vector("alpha_const", Z, "1", "class 8: alpha for alpha_profile = 0", [1.0] + [0.0] * (Z - 1))
            + scalar("alpha_grid", 0.1, "s", "class 8: cell length of alpha_profile = 2")
            + scalar("alpha_seed", 0, "1", "class 8: seed of alpha_profile = 2")
            + scalar("r0", 1, "1", "class 8: initial mode")
            + scalar("seed", 0, "1", "class 8: seed of the mode path (PCG64)")
        )
        u_names = [v.name for v in inputs]
        feed = {}
        for k in range(n):
            for base in ("u_f", "fault", "e", "b"):
                name = base if n == 1 else f"{base}[{k + 1}]"
                feed[name] = [u_names[k]]  # e, b depend on u only for the stuck class (the frozen command)
        super().__init__(inputs, outputs, params, feed)
        self.cls = NONE
        self.chain = None
        self.frozen = np.zeros(n)
        self.latched = False
        self._segment = None

    # -- set-up --------------------------------------------------------------------------------------
    def _int(self, name: str, lo: int, hi: int) -> int:
        x = self.p(name)
        if x != round(x) or not lo <= x <= hi:
            raise ValueError(f"{self.model_name}: parameter '{name}' = {x:g} must be an integer in {lo}..{hi}")
        return int(round(x))

    def initialize(self, t0: float) -> None:
        n = self.n
        self.cls = self._int("fault_class", 0, MARKOV)
        ch = self._int("channel", 0, n)
        self.mask = np.ones(n, dtype=bool) if ch == 0 else np.arange(n) == ch - 1
        self.onset, self.loss, self.magnitude = self.p("onset"), self.p("loss"), self.p("magnitude")
        self.ramp, self.period, self.duty = self.p("ramp_time"), self.p("period"), self.p("duty")
        self.stuck_mode = self._int("stuck_mode", 0, 1)
        if not 0.0 <= self.loss <= 1.0:
            raise ValueError(f"{self.model_name}: loss = {self.loss:g} is the lost fraction of class "
                             f"{self.cls} ({FAULT_CLASSES[self.cls]}) and must lie in [0, 1]")
        if self.cls == LOE_RAMP and not self.ramp > 0:
            raise ValueError(f"{self.model_name}: ramp_time = {self.ramp:g} s must be > 0")
        if self.cls in (INTERMITTENT, TIME_VARYING) and not self.period > 0:
            raise ValueError(f"{self.model_name}: period = {self.period:g} s must be > 0")
        if self.cls == INTERMITTENT and not 0.0 <= self.duty <= 1.0:
            raise ValueError(f"{self.model_name}: duty = {self.duty:g} must lie in [0, 1]")
        self.frozen = np.zeros(n)
        self.latched = False
        self.chain = None
        self._segment = None  # (from t, next event, e, b, outputs after u_f and fault) of outputs_at
        if self.cls == MARKOV:
            F, G = self.p_array("F").reshape(N_MARKOV_MODES, n), self.p_array("G").reshape(N_MARKOV_MODES, n)
            if np.any(F < 0) or np.any(F > 1):
                raise ValueError(f"{self.model_name}: F entries must lie in [0, 1] (004 (9)), got {F.tolist()}")
            v = self.p_vector("v")
            # channels outside the mask stay healthy in every mode
            self.F = np.where(self.mask, F, 1.0)
            self.Gv = np.where(self.mask, G * v, 0.0)
            try:
                V = check_vertices(self.p_array("Pi"), "Pi")
                prof = AlphaProfile(self._int("alpha_profile", 0, max(ALPHA_PROFILES)), N_VERTICES,
                                    self.p_vector("alpha_const"), self.p("alpha_grid"),
                                    self._int("alpha_seed", 0, 2**63 - 1))
                self.chain = MarkovChain(V, prof, self._int("r0", 1, N_MARKOV_MODES),
                                         self._int("seed", 0, 2**63 - 1), t0)
            except ValueError as e:
                raise ValueError(f"{self.model_name}: {e}") from None
            self.chain.advance_to(t0)

    # -- the fault at a communication point ------------------------------------------------------------
    def _started(self, t: float) -> bool:
        return happened_at(self.onset, t)

    def effect(self, t: float, u) -> tuple:
        """(e, b, active) at the communication point t for the command u (arrays of N)."""
        n, c = self.n, self.cls
        e, b = np.ones(n), np.zeros(n)
        if c == NONE:
            return e, b, False
        if c == MARKOV:
            r = self.chain.r
            e, b = self.F[r].copy(), self.Gv[r].copy()
            return e, b, r != 0
        if not self._started(t):
            return e, b, False
        m = self.mask
        if c == LOE_STEP:
            e[m] = 1.0 - self.loss
        elif c == LOE_RAMP:
            e[m] = 1.0 - self.loss * min(1.0, max(0.0, t - self.onset) / self.ramp)
        elif c == BIAS:
            b[m] = self.magnitude
        elif c == INTERMITTENT:
            if self._phase_on(t):
                e[m] = 1.0 - self.loss
            else:
                return e, b, False
        elif c == TIME_VARYING:
            b[m] = self.magnitude * math.sin(2.0 * math.pi * (t - self.onset) / self.period)
        elif c == STUCK:
            e[m] = 0.0
            if self.stuck_mode == 1:
                b[m] = self.magnitude
            else:
                b[m] = self.frozen[m] if self.latched else np.asarray(u, dtype=float)[m]
        elif c == LOST:
            e[m] = 0.0
        return e, b, True

    def _phase_on(self, t: float) -> bool:
        """Class 4: is the fault on at t (t >= onset)? Cycle k starts at onset + k period."""
        x = (t - self.onset) / self.period
        k = math.floor(x + 1e-9)
        return (x - k) * self.period < self.duty * self.period - 1e-9 * max(1.0, abs(t))

    def next_event(self, t: float) -> float:
        """The next time after t at which u_f switches (T_NEVER if none)."""
        c = self.cls
        if c == NONE:
            return T_NEVER
        if c == MARKOV:
            return self.chain.t_next
        if not self._started(t):
            return self.onset
        if c == LOE_RAMP and t < self.onset + self.ramp and not happened_at(self.onset + self.ramp, t):
            return self.onset + self.ramp
        if c == INTERMITTENT:
            k = math.floor((t - self.onset) / self.period + 1e-9)
            for edge in (self.onset + (k + self.duty) * self.period, self.onset + (k + 1) * self.period):
                if not happened_at(edge, t):
                    return edge
            return self.onset + (k + 1 + self.duty) * self.period
        return T_NEVER

    # -- the contract ----------------------------------------------------------------------------------
    # classes whose (e, b, active, mode) stay constant from one communication point to the next event
    # (``next_event``: the onset, or never), decided by the same ``happened_at``: their outputs between
    # events are e u + b with the same e, b (:meth:`outputs_at` keeps them: the same numbers as
    # recomputed, fewer operations). The others are recomputed at every point: the ramp, the
    # time-varying bias and the stuck command change with t or u, and the intermittent and Markov
    # switches are decided by their own tests (phase, chain), not by ``next_event`` alone
    PIECEWISE_CONSTANT = (NONE, LOE_STEP, BIAS, LOST)

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        n = self.n
        uc = np.asarray(u[0:n], dtype=float)
        seg = self._segment
        if seg is not None and seg[0] <= t and not happened_at(seg[1], t):
            e, b, tail = seg[2], seg[3], seg[4]
            uf = e * uc + b
            return np.concatenate((uf, uf - uc, tail))
        e, b, active = self.effect(t, uc)
        uf = e * uc + b
        mode = float(self.chain.mode) if self.chain is not None else 1.0
        nxt = self.next_event(t)
        tail = np.concatenate((e, b, (1.0 if active else 0.0, mode, nxt)))
        if self.cls in self.PIECEWISE_CONSTANT:
            self._segment = (t, nxt, e, b, tail)
        return np.concatenate((uf, uf - uc, tail))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        if self.cls == STUCK and self.stuck_mode == 0 and not self.latched and self._started(t):
            self.frozen = np.array(u[0:self.n], dtype=float)  # the command at the first point at or after onset
            self.latched = True
        if self.chain is not None:
            self.chain.advance_to(t + h)

    def get_state(self) -> list:
        s = [1.0 if self.latched else 0.0] + self.frozen.tolist()
        return s + (self.chain.get_state() if self.chain is not None else [])

    def set_state(self, state) -> None:
        s = list(state)
        n = self.n
        self._segment = None
        self.latched = s[0] == 1.0
        self.frozen = np.array(s[1:1 + n], dtype=float)
        if self.chain is not None:
            self.chain.set_state(s[1 + n:])
