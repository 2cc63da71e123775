"""Reaction wheels with torque and momentum limits, speed saturation, friction and a torque-command
bandwidth (issue 26 item 4), N wheels on 3 body axes (or on the pitch axis).

Wheel j spins about column j of M (3 x N; 1 x N on the pitch axis) with relative momentum h_j =
I_w Omega_j (N.m.s) and wheel speed Omega_j. Its command u_c,j is the torque wanted *on the body*
(the convention of 001 (3), where the body torque is M u). Model (Markley & Crassidis 2014,
reaction-wheel model, in its simplest form; Wertz 1978 for the torque and momentum limits):

* torque limit and command bandwidth: the motor torque u_m follows the clipped command,
  u_m' = (clip(u_c, -tau_max, tau_max) - u_m) / T_m (first-order drive loop, time constant
  ``time_constant`` T_m = 1 / (2 pi f_bw); exact exponential over each internal step);
* friction: the bearing drags the wheel with tau_f(Omega) = c_c s(Omega) + c_v Omega (Coulomb
  ``coulomb`` c_c, viscous ``viscous`` c_v; s(Omega) = clip(Omega / omega_eps, -1, 1), a Coulomb
  law smoothed below ``omega_eps`` rad/s so that the wheel comes to rest instead of chattering);
* momentum limit = speed saturation: |h_j| <= h_max (= I_w Omega_max). At the limit, while the
  command would push the wheel further, the drive holds the speed: its motor torque just balances
  the friction (u_m,eff = -tau_f, so h' = 0 and the wheel exerts no torque on the body); the
  wheel leaves the limit as soon as the command turns back; h is clamped to the limit;
* momentum balance: h_j' = -u_m,eff,j - tau_f(Omega_j), and the wheel exerts on the body
  u_b,j = -h_j' = u_m,eff,j + tau_f(Omega_j) (friction reaches the body: a drive without
  friction compensation);
* body torque tau = M u_b - omega x (M h) (the gyroscopic torque of the stored momentum, with the
  body rate input omega; ``gyroscopic`` = 0 leaves it out, and it is absent on the pitch axis).

So |u_b,j| <= tau_max + c_c + c_v h_max / I_w at every instant: the bound the arena checks at the
plant ("torque never exceeds the wheel limit").

Co-simulation: the outputs are the state at the communication point (u_m, h): nothing depends
directly on the command (the drive's bandwidth), only tau on omega (gyroscopic term). Over a
communication step the command is held and the state is integrated with internal steps <= ``h_int``
(exact for the lag, explicit Euler for h with the friction and the cut at the start of each internal
step, then the clamp). The torque the plant receives is held over the step by the master.

Inputs:  u_c[1..N] N.m (commanded body torque per wheel; ``u_c`` for N = 1), omega[1..3] rad/s
         (body rate, 3 axes only)
Outputs: tau[1..3] N.m (body torque; ``tau`` on the pitch axis), u_wheel[1..N] N.m (u_b), h[1..N]
         N.m.s, speed[1..N] rad/s, h_body[1..3] N.m.s (M h; ``h_body`` on the pitch axis),
         saturated[1..N] 1 (1 while the wheel is at its momentum limit)
Parameters: M, I_w (kg.m2), tau_max (N.m), h_max (N.m.s), time_constant (s), coulomb (N.m),
         viscous (N.m.s), omega_eps (rad/s), h_init[1..N] (N.m.s), gyroscopic, h_int (s)
"""
from __future__ import annotations

import math

import numpy as np

from ..block import Block, matrix, scalar, vector
from ..channels import channels
from ..integrate import substeps
from ..rigid_wheels import default_distribution

__all__ = ["ReactionWheels", "torque_bound"]


def torque_bound(tau_max: float, coulomb: float, viscous: float, h_max: float, I_w: float) -> float:
    """The largest |u_b| a wheel can exert on the body: tau_max + c_c + c_v h_max / I_w (N.m)."""
    return tau_max + coulomb + viscous * h_max / I_w


class ReactionWheels(Block):
    model_name = "ReactionWheels"
    description = "Reaction wheels: torque and momentum limits, speed saturation, friction, torque-command bandwidth"

    def __init__(self, n_wheels: int = 4, n_axes: int = 3):
        n, a = self.n, self.a = int(n_wheels), int(n_axes)
        if a not in (1, 3):
            raise ValueError(f"n_axes must be 3 (3-axis body) or 1 (pitch axis), got {n_axes}")
        if n < 1 or (a == 3 and n < 3):
            raise ValueError(f"n_wheels = {n_wheels}: at least {a} wheels are needed on {a} axes")
        M0 = default_distribution(n) if a == 3 else np.ones((1, n))
        inputs = channels("u_c", n, "N.m", "commanded torque on the body, per wheel")
        if a == 3:
            inputs += vector("omega", 3, "rad/s", "body rate (gyroscopic torque of the wheel momentum)")
        outputs = (channels("tau", a, "N.m", "body torque of the wheels")
                   + channels("u_wheel", n, "N.m", "torque each wheel exerts on the body")
                   + channels("h", n, "N.m.s", "wheel momentum about its spin axis")
                   + channels("speed", n, "rad/s", "wheel speed")
                   + channels("h_body", a, "N.m.s", "momentum stored in the wheels, body components")
                   + channels("saturated", n, "1", "1 while the wheel is at its momentum limit"))
        params = (matrix("M", M0, "1", "spin axes (column j: wheel j)")
                  + scalar("I_w", 0.01, "kg.m2", "wheel spin inertia")
                  + scalar("tau_max", 0.2, "N.m", "largest motor torque")
                  + scalar("h_max", 10.0, "N.m.s", "momentum capacity I_w Omega_max")
                  + scalar("time_constant", 0.05, "s", "torque-command time constant T_m")
                  + scalar("coulomb", 0.0, "N.m", "Coulomb friction c_c")
                  + scalar("viscous", 0.0, "N.m.s", "viscous friction c_v")
                  + scalar("omega_eps", 0.1, "rad/s", "speed below which the Coulomb friction is smoothed")
                  + channels("h_init", n, "N.m.s", "initial wheel momentum")
                  + scalar("gyroscopic", 1.0 if a == 3 else 0.0, "1", "1: tau includes -omega x (M h) (3 axes)")
                  + scalar("h_int", 0.005, "s", "largest internal step"))
        feed = {}
        if a == 3:
            # -omega x (M h): component i depends on the two other rates
            feed = {f"tau[{i}]": [f"omega[{j}]" for j in (1, 2, 3) if j != i] for i in (1, 2, 3)}
        super().__init__(inputs, outputs, params, feed)
        self.um = np.zeros(n)
        self.hw = np.zeros(n)

    def initialize(self, t0: float) -> None:
        n, a = self.n, self.a
        M = self.p_matrix("M").reshape(a, n)
        if np.any(np.linalg.norm(M, axis=0) == 0):
            raise ValueError(f"{self.model_name}: a column of M is zero (a wheel without a spin axis)")
        for name in ("I_w", "tau_max", "h_max", "time_constant", "omega_eps", "h_int"):
            if not self.p(name) > 0:
                raise ValueError(f"{self.model_name}: {name} = {self.p(name):g} must be > 0")
        for name in ("coulomb", "viscous"):
            if self.p(name) < 0:
                raise ValueError(f"{self.model_name}: {name} = {self.p(name):g} must be >= 0")
        g = self.p("gyroscopic")
        if g not in (0.0, 1.0) or (a == 1 and g == 1.0):
            raise ValueError(f"{self.model_name}: gyroscopic = {g:g} must be 0 or 1 (0 on the pitch axis)")
        self.M, self.Iw = M, self.p("I_w")
        self.tau_max, self.h_max, self.Tm = self.p("tau_max"), self.p("h_max"), self.p("time_constant")
        self.cc, self.cv, self.weps = self.p("coulomb"), self.p("viscous"), self.p("omega_eps")
        self.gyro, self.h_int = g == 1.0, self.p("h_int")
        h0 = self.p_vector("h_init") if n > 1 else np.array([self.p("h_init")])
        if np.any(np.abs(h0) > self.h_max):
            raise ValueError(f"{self.model_name}: h_init {h0.tolist()} exceeds h_max = {self.h_max:g} N.m.s")
        self.um = np.zeros(n)
        self.hw = h0.astype(float)

    # -- the wheel model --------------------------------------------------------------------------------
    def friction(self, h: np.ndarray) -> np.ndarray:
        """tau_f(Omega) = c_c s(Omega) + c_v Omega (drags the wheel; reaches the body with this sign)."""
        w = h / self.Iw
        return self.cc * np.clip(w / self.weps, -1.0, 1.0) + self.cv * w

    def at_limit(self, h: np.ndarray, um: np.ndarray) -> np.ndarray:
        """Wheels at the momentum limit whose motor torque would push them further (h' = -u_m)."""
        return (np.abs(h) >= self.h_max * (1.0 - 1e-12)) & (-um * np.sign(h) > 0.0)

    def wheel_torques(self, h: np.ndarray, um: np.ndarray) -> tuple:
        """(u_b, saturated) for the state (h, u_m): at the limit the drive holds the speed (u_b = 0)."""
        cut = self.at_limit(h, um)
        return np.where(cut, 0.0, um + self.friction(h)), cut

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        """The internal steps in Python floats, wheel by wheel (the same arithmetic as
        :meth:`wheel_torques`, a few microseconds per wheel instead of numpy's per-call overhead)."""
        steps, dt = substeps(h, self.h_int)
        decay = math.exp(-dt / self.Tm)
        hmax, lim, Iw, cc, cv, weps = self.h_max, self.h_max * (1.0 - 1e-12), self.Iw, self.cc, self.cv, self.weps
        tm = self.tau_max
        um_out, hw_out = self.um.copy(), self.hw.copy()
        for j in range(self.n):
            target = min(max(float(u[j]), -tm), tm)
            um, hw = float(self.um[j]), float(self.hw[j])
            for _ in range(steps):
                if abs(hw) >= lim and -um * hw > 0.0:  # at the limit and pushed further: the speed is held
                    ub = 0.0
                else:
                    w = hw / Iw
                    ub = um + cc * min(max(w / weps, -1.0), 1.0) + cv * w
                um = target + (um - target) * decay
                hw = min(max(hw - dt * ub, -hmax), hmax)
            um_out[j], hw_out[j] = um, hw
        self.um, self.hw = um_out, hw_out

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        if self.n == 1 and self.a == 1:  # one wheel on the pitch axis: the same arithmetic in Python floats
            return self._outputs_one()
        ub, cut = self.wheel_torques(self.hw, self.um)
        hb = self.M @ self.hw
        tau = self.M @ ub
        if self.gyro:
            w = u[self.n:self.n + 3]
            tau = tau - np.array([w[1] * hb[2] - w[2] * hb[1], w[2] * hb[0] - w[0] * hb[2], w[0] * hb[1] - w[1] * hb[0]])
        return np.concatenate((tau, ub, self.hw, self.hw / self.Iw, hb, cut.astype(float)))

    def _outputs_one(self) -> np.ndarray:
        """:meth:`outputs_at` of one wheel on one axis (M a 1 x 1 matrix): the operations of
        :meth:`wheel_torques`, ``M @ ub`` and ``M @ hw`` on floats, without numpy's per-call overhead
        (a 0.5 ms loop calls it 2000 times per simulated second)."""
        hw, um, m = float(self.hw[0]), float(self.um[0]), float(self.M[0, 0])
        cut = abs(hw) >= self.h_max * (1.0 - 1e-12) and -um * (1.0 if hw > 0 else -1.0 if hw < 0 else 0.0) > 0.0
        if cut:
            ub = 0.0
        else:
            w = hw / self.Iw
            ub = um + (self.cc * min(max(w / self.weps, -1.0), 1.0) + self.cv * w)
        return np.array([m * ub, ub, hw, hw / self.Iw, m * hw, 1.0 if cut else 0.0])

    def get_state(self) -> list:
        return self.um.tolist() + self.hw.tolist()

    def set_state(self, state) -> None:
        s = np.array(state, dtype=float)
        self.um, self.hw = s[: self.n].copy(), s[self.n:].copy()
