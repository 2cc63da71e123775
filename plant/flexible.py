"""Flexible spacecraft: rigid hub + n flexible modes, unit-quaternion kinematics.

Dynamics 000 (2):  J w' = -w x (J w + delta^T eta') - delta^T eta'' + tau + u_d,
                   eta'' = -C eta' - K eta - delta w'
solved for the accelerations (000 (6)-(7)):
                   (J - delta^T delta) w' = -w x (J w + delta^T eta') + delta^T (C eta' + K eta) + tau + u_d
Kinematics 000 (3): q_v' = 1/2 (q0 I + q_v^x) w,  q0' = -1/2 q_v^T w   (q = [q0, q_v], scalar first).

Wheel momentum (``wheel_momentum`` = 1; not in 000 or 004): the three actuators are reaction wheels
spinning about the columns of Gamma + Delta Gamma, whose momenta h_w (N.m.s, inertial) are states
integrated with the body, so that their gyroscopic torque is never held over a communication step:

                   J w' = -w x (J w + delta^T eta' + (Gamma + Delta Gamma) h_w) - delta^T eta'' + tau + u_d,
                   h_w' = -(sat(u) + f_eq)     (the wheels take the reaction of the torque they apply)

J is then the craft's inertia without the wheels' spin inertia about their axes. The default (0)
keeps 000 (2) as printed, and h_w stays at ``h_w_init``.

Actuator path (plant/actuator.py): commanded u -> saturation -> effectiveness E and bias u_f
(001 (5)) -> additive fault f (000 (66)) -> (Gamma + Delta Gamma) -> applied torque tau.
The true equivalent additive fault f_eq = (E - I) sat(u) + u_f + f is an output, so that
tau = (Gamma + Delta Gamma)(sat(u) + f_eq) as in 000 (6).

Integration: fixed-step RK4, internal step <= ``h_max``; the quaternion is renormalised
after every internal step. ``advance``, ``outputs_at`` and ``feedthrough_outputs`` run the
compiled kernels of ``plant/kernels/flexible.py`` when kernels are on (``plant/kernels``);
the methods below are the reference they are tested against. u is held over a communication step; u_d(t) and f(t) are
evaluated at the RK4 stage times; fault onsets and switches follow the one-sided rule of
``plant/timing.py`` (a switch on the communication grid acts at that point in every host).

Inputs:  u[1..3]           commanded torque, N·m
Outputs: q[0..3]           attitude quaternion (body w.r.t. inertial), 1
         omega[1..3]       body rate, rad/s
         eta[1..n]         modal displacements
         eta_dot[1..n]     modal rates
         tau_applied[1..3] torque delivered by the actuators (without u_d), N·m
         f[1..3]           true equivalent additive actuator fault f_eq, N·m
         d_vib[1..3]       vibration torque T_d = delta^T (C eta' + K eta) - w x delta^T eta' (000 (6)), N·m
         u_d[1..3]         external disturbance torque, N·m
         h_w[1..3]         wheel momentum about each actuator axis (inertial), N·m·s (h_w_init when wheel_momentum = 0)
"""
from __future__ import annotations

import math

import numpy as np

from . import kernels
from .actuator import (
    effectiveness_and_bias,
    li2023_disturbance,
    li2023_fault,
    misalignment,
    saturate,
)
from .block import Block, matrix, scalar, vector
from .integrate import h_max_parameter, rk4_step, substeps
from .kernels import flexible as _kernel
from .modal import modal_state
from .so3 import cross, rotation_matrix
from .timing import StepWindow

N_MODES = 4  # default number of modes (000 and 004 use four)


def placeholder_model(n: int) -> dict:
    """Stand-in spacecraft parameters (unit inertia, no coupling, 1 rad/s modes, 1 % damping):
    valid numbers for a block built without a paper's set. Papers pass theirs through
    ``Block.set_defaults`` (``papers/p000_li2023/blocks.py``) or the scenario's ``parameter_set``."""
    return {"J": np.eye(3), "delta": np.zeros((n, 3)), "omega_n": np.ones(n), "zeta": np.full(n, 0.01)}


def modal_matrices(omega_n, zeta):
    """C_eta = diag(2 zeta_i omega_ni), K_eta = diag(omega_ni^2) (000 section 2.1)."""
    omega_n = np.asarray(omega_n, dtype=float)
    zeta = np.asarray(zeta, dtype=float)
    return np.diag(2.0 * zeta * omega_n), np.diag(omega_n**2)


class FlexibleSpacecraft(Block):
    model_name = "FlexibleSpacecraft"
    description = "Flexible spacecraft, 000 (2)-(3), (6)-(7), with actuator faults, saturation, misalignment"

    def __init__(self, n_modes: int = N_MODES):
        n = self.n = int(n_modes)
        if n < 0:
            raise ValueError(f"n_modes must be >= 0, got {n_modes}")
        model = placeholder_model(n)
        inputs = vector("u", 3, "N.m", "commanded control torque")
        outputs = (
            vector("q", 4, "1", "attitude quaternion, scalar first", first=0)
            + vector("omega", 3, "rad/s", "body angular rate")
            + modal_state(n)
            + vector("tau_applied", 3, "N.m", "torque delivered by the actuators")
            + vector("f", 3, "N.m", "true equivalent additive actuator fault")
            + vector("d_vib", 3, "N.m", "vibration torque T_d of 000 (6)")
            + vector("u_d", 3, "N.m", "external disturbance torque")
            + vector("h_w", 3, "N.m.s", "wheel momentum about each actuator axis, inertial (h_w_init when wheel_momentum = 0)")
        )
        params = (
            matrix("J", model["J"], "kg.m2", "hub inertia")
            + matrix("delta", model["delta"], "1", "rigid-flexible coupling matrix")
            + vector("omega_n", n, "rad/s", "modal natural frequency", model["omega_n"])
            + vector("zeta", n, "1", "modal damping ratio", model["zeta"])
            + matrix("Gamma", np.eye(3), "1", "actuator distribution matrix")
            + vector("q_init", 4, "1", "initial quaternion (normalised)", [1, 0, 0, 0], first=0)
            + vector("omega_init", 3, "rad/s", "initial body rate")
            + modal_state(n, initial=True)
            + scalar("u_max", 5.0, "N.m", "actuator saturation level")
            + scalar("saturation_mode", 0, "1", "0: per axis |u_i|<=u_max, 1: ||u||_1<=u_max (000)")
            + vector("misalign_a", 3, "deg", "misalignment Delta a of 000 section 5")
            + vector("misalign_b", 3, "deg", "misalignment Delta b of 000 section 5")
            + scalar("fault_scale", 0.0, "1", "000 (66) fault amplitude: 1 normal, 0.2 weak, 0 none")
            + scalar("fault_onset", 40.0, "s", "time at which the 000 (66) faults start")
            + vector("effectiveness", 3, "1", "001 (5) diagonal of E after its onset", [1, 1, 1])
            + scalar("effectiveness_onset", 0.0, "s", "time from which E applies")
            + vector("bias", 3, "N.m", "001 (5) bias fault u_f after its onset")
            + scalar("bias_onset", 0.0, "s", "time from which u_f applies")
            + scalar("disturbance_scale", 0.0, "1", "scale of 000's external disturbance u_d")
            + h_max_parameter(0.01)
            + scalar("omega_max", 10.0, "rad/s", "model validity guard: |omega_i| above it stops the run")
            + scalar("wheel_momentum", 0.0, "1", "1: the actuators are wheels whose momenta h_w are plant states "
                     "(gyroscopic torque -w x (Gamma + Delta Gamma) h_w); 0: 000 (2) as printed")
            + vector("h_w_init", 3, "N.m.s", "initial wheel momentum about each actuator axis, inertial (wheel_momentum = 1)")
        )
        feed = {f"tau_applied[{i}]": [f"u[{j}]" for j in (1, 2, 3)] for i in (1, 2, 3)}
        feed.update({f"f[{i}]": [f"u[{j}]" for j in (1, 2, 3)] for i in (1, 2, 3)})
        super().__init__(inputs, outputs, params, feed)
        self.y = np.zeros(7 + 2 * n)
        self.momentum = False

    # -- set-up -------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        n = self.n
        J = self.p_matrix("J")
        delta = self.p_matrix("delta")
        C, K = modal_matrices(self.p_vector("omega_n"), self.p_vector("zeta"))
        Jm = J - delta.T @ delta
        if np.any(np.linalg.eigvalsh(0.5 * (Jm + Jm.T)) <= 0):
            raise ValueError("J - delta^T delta must be positive definite")
        Jm_inv = np.linalg.inv(Jm)
        m = 3 + 2 * n
        # x = [omega, eta, eta_dot];  x' = A x + Bn (tau_total - w x h),  h = H x
        A = np.zeros((m, m))
        A[0:3, 3 : 3 + n] = Jm_inv @ delta.T @ K
        A[0:3, 3 + n :] = Jm_inv @ delta.T @ C
        A[3 : 3 + n, 3 + n :] = np.eye(n)
        A[3 + n :, 3 : 3 + n] = -K - delta @ A[0:3, 3 : 3 + n]
        A[3 + n :, 3 + n :] = -C - delta @ A[0:3, 3 + n :]
        Bn = np.vstack([Jm_inv, np.zeros((n, 3)), -delta @ Jm_inv])
        H = np.hstack([J, np.zeros((3, n)), delta.T])
        self.J, self.delta, self.C, self.K = J, delta, C, K
        self._A, self._Bn, self._H = A, Bn, H
        self._dC, self._dK = delta.T @ C, delta.T @ K
        self.G_eff = self.p_matrix("Gamma") + misalignment(
            self.p_vector("misalign_a"), self.p_vector("misalign_b")
        )
        self.u_max = self.p("u_max")
        self.sat_mode = int(round(self.p("saturation_mode")))
        self.fault_scale = self.p("fault_scale")
        self.fault_onset = self.p("fault_onset")
        self.dist_scale = self.p("disturbance_scale")
        self.e = self.p_vector("effectiveness")
        self.e_onset = self.p("effectiveness_onset")
        self.bias = self.p_vector("bias")
        self.bias_onset = self.p("bias_onset")
        self.h_max = self.p("h_max")
        self.omega_max = self.p("omega_max")
        if not self.h_max > 0:
            raise ValueError("h_max must be > 0")
        q = self.p_vector("q_init")
        nq = np.linalg.norm(q)
        if nq == 0:
            raise ValueError("q_init must not be zero")
        self._kernels = kernels.enabled()
        self._prm = _kernel.params(fault_scale=self.fault_scale, fault_onset=self.fault_onset,
                                   disturbance_scale=self.dist_scale, effectiveness_onset=self.e_onset,
                                   bias_onset=self.bias_onset, u_max=self.u_max, saturation_mode=self.sat_mode)
        self._dT = np.ascontiguousarray(delta.T)
        wm = self.p("wheel_momentum")
        if wm not in (0.0, 1.0):
            raise ValueError(f"wheel_momentum: must be 0 (000 (2), no wheel momentum) or 1 (wheel momenta as states), got {wm:g}")
        self.momentum = wm == 1.0
        self.h_w_init = self.p_vector("h_w_init")
        self.y = np.concatenate(
            [
                q / nq,
                self.p_vector("omega_init"),
                self.p_vector("eta_init"),
                self.p_vector("eta_dot_init"),
            ]
            + ([self.h_w_init] if self.momentum else [])
        )

    # -- actuator path ---------------------------------------------------------------
    def actuator(self, t: float, u: np.ndarray):
        """Return (applied torque tau, equivalent additive fault f_eq) for command u."""
        us = saturate(u, self.u_max, self.sat_mode)
        e, uf = effectiveness_and_bias(t, self.e, self.e_onset, self.bias, self.bias_onset)
        f = np.array(li2023_fault(t, self.fault_scale, self.fault_onset))
        f_eq = (e - 1.0) * us + uf + f
        return self.G_eff @ (us + f_eq), f_eq

    # -- dynamics -----------------------------------------------------------------------
    def _deriv(self, y: np.ndarray, torque: np.ndarray) -> np.ndarray:
        q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
        x = y[4:]
        w1, w2, w3 = x[0], x[1], x[2]
        h1, h2, h3 = self._H @ x
        gyro = np.array([w2 * h3 - w3 * h2, w3 * h1 - w1 * h3, w1 * h2 - w2 * h1])
        xd = self._A @ x + self._Bn @ (torque - gyro)
        qd = np.array(
            [
                -0.5 * (q1 * w1 + q2 * w2 + q3 * w3),
                0.5 * (q0 * w1 + q2 * w3 - q3 * w2),
                0.5 * (q0 * w2 + q3 * w1 - q1 * w3),
                0.5 * (q0 * w3 + q1 * w2 - q2 * w1),
            ]
        )
        return np.concatenate((qd, xd))

    def _stage_torque(self, t: float, us: np.ndarray, window) -> np.ndarray:
        """Applied + disturbance torque at stage time t of the step ``window`` for the saturated
        command us (switches by plant/timing.py)."""
        e, uf = effectiveness_and_bias(t, self.e, self.e_onset, self.bias, self.bias_onset, window)
        f1, f2, f3 = li2023_fault(t, self.fault_scale, self.fault_onset, window)
        tau = self.G_eff @ (e * us + uf + np.array((f1, f2, f3)))
        if self.dist_scale != 0.0:
            d1, d2, d3 = li2023_disturbance(t, self.dist_scale)
            tau += np.array((d1, d2, d3))
        return tau

    def _deriv_momentum(self, y: np.ndarray, a) -> np.ndarray:
        """dy/dt with the wheel momenta y[-3:] (wheel_momentum = 1); ``a`` = (total torque, wheel torques v)."""
        torque, v = a
        q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
        m = 3 + 2 * self.n
        x = y[4 : 4 + m]
        w1, w2, w3 = x[0], x[1], x[2]
        h1, h2, h3 = self._H @ x + self.G_eff @ y[4 + m :]
        gyro = np.array([w2 * h3 - w3 * h2, w3 * h1 - w1 * h3, w1 * h2 - w2 * h1])
        xd = self._A @ x + self._Bn @ (torque - gyro)
        qd = np.array(
            [
                -0.5 * (q1 * w1 + q2 * w2 + q3 * w3),
                0.5 * (q0 * w1 + q2 * w3 - q3 * w2),
                0.5 * (q0 * w2 + q3 * w1 - q1 * w3),
                0.5 * (q0 * w3 + q1 * w2 - q2 * w1),
            ]
        )
        return np.concatenate((qd, xd, -v))

    def _stage_wheels(self, t: float, us: np.ndarray, window) -> tuple:
        """(applied + disturbance torque, wheel torques v = E us + u_f + f) at stage time t
        (wheel_momentum = 1; the torque is G_eff v + u_d, as :meth:`_stage_torque`)."""
        e, uf = effectiveness_and_bias(t, self.e, self.e_onset, self.bias, self.bias_onset, window)
        f1, f2, f3 = li2023_fault(t, self.fault_scale, self.fault_onset, window)
        v = e * us + uf + np.array((f1, f2, f3))
        tau = self.G_eff @ v
        if self.dist_scale != 0.0:
            d1, d2, d3 = li2023_disturbance(t, self.dist_scale)
            tau += np.array((d1, d2, d3))
        return tau, v

    def _constant_torque(self, window) -> bool:
        """True if nothing in the torque changes inside the step: no disturbance, no fault
        active during it, no effectiveness/bias onset inside it."""
        if self.dist_scale != 0.0 or (self.fault_scale != 0.0 and window.active(self.fault_onset, window.t + window.h)):
            return False
        return not any(window.contains(onset) for onset in (self.e_onset, self.bias_onset))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        steps, _ = substeps(h, self.h_max)
        if self.momentum:
            if self._kernels:
                y = _kernel.advance_momentum(self.y, t, h, steps, np.asarray(u, dtype=float), self._A, self._Bn, self._H,
                                             self.G_eff, self.e, self.bias, self._prm)
            else:
                y = self._advance_reference(t, h, steps, u)
        elif self._kernels:
            y = _kernel.advance(self.y, t, h, steps, np.asarray(u, dtype=float), self._A, self._Bn, self._H, self.G_eff, self.e, self.bias,
                                self._prm)
        else:
            y = self._advance_reference(t, h, steps, u)
        w_abs = max(abs(y[4]), abs(y[5]), abs(y[6]))
        if not w_abs <= self.omega_max:  # also catches NaN
            raise FloatingPointError(
                f"|omega| = {w_abs:.4g} rad/s exceeds omega_max = {self.omega_max:g} rad/s at t = {t + h:.6g} s"
            )
        self.y = y

    def _advance_reference(self, t: float, h: float, steps: int, u: np.ndarray) -> np.ndarray:
        dt = h / steps
        us = saturate(u, self.u_max, self.sat_mode)  # u is held over the step
        window = StepWindow(t, h)
        const = self._constant_torque(window)
        tau_c = self._stage_torque(t, us, window) if const else None
        y = self.y
        if self.momentum:
            for k in range(steps):
                tk = t + k * dt
                stages = [self._stage_wheels(tau, us, window) for tau in (tk, tk + 0.5 * dt, tk + dt)]
                y = rk4_step(self._deriv_momentum, y, dt, *stages)
                y[0:4] /= math.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3])
            return y
        for k in range(steps):
            tk = t + k * dt
            if const:
                t0 = tm = t1 = tau_c
            else:
                t0 = self._stage_torque(tk, us, window)
                tm = self._stage_torque(tk + 0.5 * dt, us, window)
                t1 = self._stage_torque(tk + dt, us, window)
            y = rk4_step(self._deriv, y, dt, t0, tm, t1)
            y[0:4] /= math.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3])
        return y

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        m = 7 + 2 * self.n
        hw = self.y[m:] if self.momentum else self.h_w_init
        if self._kernels:
            out = _kernel.outputs(t, self.y[:m], np.asarray(u, dtype=float), self.G_eff, self.e, self.bias, self._prm,
                                  self._dC, self._dK, self._dT)
            return np.concatenate((out, hw))
        n = self.n
        y = self.y[:m]
        w = y[4:7]
        eta = y[7 : 7 + n]
        eta_dot = y[7 + n :]
        tau, f_eq = self.actuator(t, u)
        dte = self.delta.T @ eta_dot
        d_vib = self._dC @ eta_dot + self._dK @ eta - cross(w, dte)
        u_d = li2023_disturbance(t, self.dist_scale)
        return np.concatenate((y, tau, f_eq, d_vib, u_d, hw))

    def feedthrough_outputs(self, t: float, u: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``y`` from ``outputs_at`` with tau_applied and f recomputed for a new command u
        (the only outputs that depend on u); the state outputs are not evaluated again."""
        k = 7 + 2 * self.n
        if self._kernels:
            _kernel.actuator(t, np.asarray(u, dtype=float), self.G_eff, self.e, self.bias, self._prm, y, k)
            return y
        tau, f_eq = self.actuator(t, u)
        y[k : k + 3] = tau
        y[k + 3 : k + 6] = f_eq
        return y

    def get_state(self) -> list:
        return self.y.tolist()

    def set_state(self, state) -> None:
        self.y = np.array(state, dtype=float)

    # -- evaluation helpers ---------------------------------------------------------------
    def angular_momentum_inertial(self) -> np.ndarray:
        """Total angular momentum J w + delta^T eta' (+ G_eff h_w with wheel momentum) rotated to the inertial
        frame, N·m·s."""
        n = self.n
        y = self.y
        h_body = self.J @ y[4:7] + self.delta.T @ y[7 + n : 7 + 2 * n]
        if self.momentum:
            h_body = h_body + self.G_eff @ y[7 + 2 * n :]
        return rotation_matrix(y[0:4]).T @ h_body
