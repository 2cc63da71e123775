"""T-S fuzzy model of flexible-spacecraft attitude dynamics on x = [omega; q_v], 004 (5)-(6).

From 004 (5) (J - delta^T delta) w' = -S(w) J w + u + d~ and the kinematics (1)-(2) with
q0 = sqrt(1 - ||q_v||^2), q_v' = 1/2 q0 w - 1/2 S(w) q_v, the local model at an operating point
(chi_w, chi_q) is (004, after (5))

    A_i = [[ -(J - delta^T delta)^-1 S(chi_w) J ,        0        ],
           [ 1/2 sqrt(1 - ||chi_q||^2) I        , -1/2 S(chi_w)   ]],
    B_i = [ (J - delta^T delta)^-1 ; 0 ],  C_i = I,  H_i = B_i,

and the fuzzy model is x' = sum_i h_i(x) (A_i x + B_i u + H_i d~) (004 (6)). Readings:

* 004 prints the (2,1) block as "1/2 (1 - ||x_qi||^2) I" (no square root); the kinematics
  (q0 = sqrt(1 - ||q||^2)) give the root. ``sqrt_reading = 1`` (default) uses the root,
  0 the printed form (0.152069 against 0.04625 at ||chi_q||^2 = 3 * 0.55^2).
* H_i is not printed; d~ enters (5) exactly like u, so H_i = B_i.
* The flexible modes are lumped into d~ (004 (5)); this model has no modal states. As a plant
  block it is driven by the total torque u + d~ on its input.

:class:`TSAttitudePlant` is this model as a plant (004's "closed-loop fuzzy system", Figs. 5-6):
x is a vector in R^6, so the printed x(0) (whose q part has norm 3) can be used as is.

Inputs:  u[1..3] torque entering through B (N·m: control plus disturbance)
Outputs: omega[1..3] (rad/s) = x[1..3]; q[0..3] with q[1..3] = x[4..6] and
         q[0] = sqrt(max(0, 1 - ||q_v||^2)) (1); h[1..p] memberships at x (1)
Parameters: J (kg.m2), delta (mode coupling), points[i,1..6] (operating points), sqrt_reading,
         memberships (``plant.fuzzy.triangular_parameters``), x_init[1..6], h_max (s), x_max
Integration: RK4, internal step <= h_max, memberships at every stage (compiled,
``plant/kernels/ts_attitude.py``, when kernels are on; the numpy code is the reference).
"""
from __future__ import annotations

import math

import numpy as np

from . import kernels
from .block import Block, Variable, matrix, scalar, vector
from .fuzzy import triangular_from_parameters, triangular_parameters
from .kernels import ts_attitude as _kernel
from .so3 import skew

NX, NU = 6, 3


def local_model(J, delta, points, sqrt_reading: bool = True):
    """(A (p,6,6), B (6,3)) of 004 (6) at the operating points (p, 6) = [chi_w, chi_q]."""
    J = np.asarray(J, dtype=float)
    delta = np.asarray(delta, dtype=float)
    Jm = J - delta.T @ delta
    if np.any(np.linalg.eigvalsh(0.5 * (Jm + Jm.T)) <= 0):
        raise ValueError("J - delta^T delta must be positive definite")
    Jm_inv = np.linalg.inv(Jm)
    P = np.atleast_2d(np.asarray(points, dtype=float))
    if P.shape[1] != NX:
        raise ValueError(f"operating points must have 6 entries [omega, q_v], got shape {P.shape}")
    A = np.zeros((P.shape[0], NX, NX))
    for i, (w, q) in enumerate(zip(P[:, :3], P[:, 3:])):
        s = 1.0 - float(q @ q)
        if s < 0:
            raise ValueError(f"operating point {i + 1}: ||q_v||^2 = {float(q @ q):g} > 1")
        A[i, :3, :3] = -Jm_inv @ skew(w) @ J
        A[i, 3:, :3] = 0.5 * (math.sqrt(s) if sqrt_reading else s) * np.eye(3)
        A[i, 3:, 3:] = -0.5 * skew(w)
    B = np.vstack([Jm_inv, np.zeros((3, 3))])
    return A, B


class TSAttitudePlant(Block):
    model_name = "TSAttitudePlant"
    description = "T-S fuzzy attitude model x' = sum h_i(x) (A_i x + B u) on x = [omega, q_v] (004 (6))"

    def __init__(self, n_rules: int = 3, n_modes: int = 4):
        p, self.p_rules, self.n_modes = int(n_rules), int(n_rules), int(n_modes)
        outputs = (vector("omega", 3, "rad/s", "body rate x[1..3]")
                   + vector("q", 4, "1", "attitude quaternion: q[1..3] = x[4..6], q[0] = sqrt(max(0, 1-|q_v|^2))", first=0)
                   + vector("h", p, "1", "membership weights h_i(x)"))
        params = (
            matrix("J", np.eye(3), "kg.m2", "hub inertia J_s")
            + matrix("delta", np.zeros((self.n_modes, 3)), "1", "rigid-flexible coupling delta")
            + [Variable(f"points[{i + 1},{j + 1}]", "1", "operating point i: [omega (rad/s), q_v]") for i in range(p) for j in range(NX)]
            + scalar("sqrt_reading", 1, "1", "1: (2,1) block 1/2 sqrt(1-|chi_q|^2) I; 0: as printed 1/2 (1-|chi_q|^2) I")
            + triangular_parameters(p, NX)
            + vector("x_init", NX, "1", "initial state [omega (rad/s), q_v]")
            + scalar("h_max", 0.001, "s", "largest internal RK4 step")
            + scalar("x_max", 1e3, "1", "validity guard: max |x_i| above it stops the run")
        )
        super().__init__(vector("u", NU, "N.m", "torque entering through B (control + disturbance)"), outputs, params, {})
        self.x = np.zeros(NX)

    def initialize(self, t0: float) -> None:
        try:
            self.A, self.B = local_model(self.p_matrix("J"), self.p_matrix("delta"),
                                         self.p_array("points").reshape(self.p_rules, NX), self.p("sqrt_reading") != 0)
        except ValueError as e:
            raise ValueError(f"{self.model_name}: {e}") from None
        self.memb = triangular_from_parameters(self)
        self.h_max, self.x_max = self.p("h_max"), self.p("x_max")
        if not self.h_max > 0:
            raise ValueError(f"{self.model_name}: h_max = {self.h_max:g} s must be > 0")
        self.x = self.p_vector("x_init").copy()
        self._kernels = kernels.enabled()
        m = self.memb
        self._kargs = (np.ascontiguousarray(self.A), np.ascontiguousarray(self.B), m.b.copy(), m.s.copy(),
                       np.ascontiguousarray(m._row, dtype=np.int64), m.tol)

    def deriv(self, x: np.ndarray, bu: np.ndarray) -> np.ndarray:
        return self.memb.weights(x) @ (self.A @ x) + bu  # sum_i h_i(x) A_i x + B u

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        steps = max(1, math.ceil(h / self.h_max - 1e-9))
        if self._kernels:  # plant/kernels/ts_attitude.py, the same step compiled
            x = _kernel.advance(self.x, np.asarray(u, dtype=float), h, steps, *self._kargs)
        else:
            x = self._advance_reference(h, steps, u)
        xa = float(np.max(np.abs(x)))
        if not xa <= self.x_max:  # also NaN
            raise FloatingPointError(f"{self.model_name}: max |x_i| = {xa:.4g} exceeds x_max = {self.x_max:g} at t = {t + h:.6g} s")
        self.x = x

    def _advance_reference(self, h: float, steps: int, u: np.ndarray) -> np.ndarray:
        dt = h / steps
        bu = self.B @ u
        x = self.x
        f = self.deriv
        for _ in range(steps):
            k1 = f(x, bu)
            k2 = f(x + (0.5 * dt) * k1, bu)
            k3 = f(x + (0.5 * dt) * k2, bu)
            k4 = f(x + dt * k3, bu)
            x = x + (dt / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
        return x

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        x = self.x
        qv = x[3:]
        q0 = math.sqrt(max(0.0, 1.0 - float(qv @ qv)))
        return np.concatenate((x[:3], [q0], qv, self.memb.weights(x)))

    def get_state(self) -> list:
        return self.x.tolist()

    def set_state(self, state) -> None:
        self.x = np.array(state, dtype=float)
