"""Rigid spacecraft with N reaction wheels through a 3xN distribution matrix, Euler-angle attitude.

Kinematics 001 (1)-(2): sigma' = G(sigma) omega, sigma = [nu, psi, gamma] of the 2-3-1 sequence
(plant/euler231.py; the printed (2,3) entry of G is read as -sin gamma / cos nu).

Dynamics 001 (3), with the time-varying inertia uncertainty and disturbance of 001 section 5:

    (J + Delta J(t)) omega' = -omega x (J + Delta J(t)) omega + M u + T_d(t)
    Delta J(t) = diag(dJ_amp_i sin(dJ_freq_i t)),   T_d,i(t) = Td_amp_i sin(Td_freq_i t)

solved for omega' at every RK4 stage (a 3x3 symmetric solve by cofactors).

Wheel momentum (``wheel_momentum`` = 1; not in 001): the wheels' momenta h_w (N.m.s, about each
spin axis, inertial: I_w (g_j^T omega + Omega_j)) are states of the plant, integrated with the body
in every RK4 stage, so that their gyroscopic torque is never held over a communication step
(Markley & Crassidis 2014, section 3.3.5; Basilisk's reactionWheelStateEffector, balanced wheels):

    (J + Delta J(t)) omega' = -omega x ((J + Delta J(t)) omega + M h_w) + M u + T_d(t),   h_w' = -u

with u the applied wheel torques on the body below and J the craft's inertia without the wheels'
spin inertia about their axes (Basilisk's hub inertia is J + sum_j I_w g_j g_j^T). 001 (3) has no
wheel momentum: ``wheel_momentum`` = 0 (the default, for reproduction) keeps the printed equation,
and h_w stays at ``h_w_init``. A J that no rigid body has (principal moments breaking the triangle
inequality, as 001's do) is accepted with one warning (plant/physical.py). Reading: 001 says it
simulates "(2) and (6)", and (6) hides Delta J omega' inside d; (3) solved for omega' is the same
model without the implicit equation. Like (3), the model has no J-dot omega term of a truly
time-varying inertia (we keep (3) as printed).

Actuator path 001 (5), per wheel j:  u_j = e_j sat(u_c,j) + u_f,j,  with e_j = 1 before
``effectiveness_onset[j]`` and ``effectiveness[j]`` from then on, u_f,j = 0 before
``bias_onset[j]`` and ``bias[j]`` from then on (steps; onsets through plant/timing.py, so a
switch on the communication grid acts at that point in every host). sat is the optional per-wheel
saturation |u_c,j| <= u_max (``u_max`` = 0: none, 001 has none). The equivalent body fault torque
is M((E - I) sat(u_c) + u_f), so that the body torque is M sat(u_c) + fault_torque.

Validity guards (raise ``FloatingPointError``, which the FMU layer reports as an error of the
instance; never NaN): |nu| > ``nu_max`` (the kinematics are singular at nu = +-90 deg),
|omega_i| > ``omega_max``, or any non-finite state.

Integration: fixed-step RK4, internal step <= ``h_max`` (with h_w when ``wheel_momentum`` = 1), u_c held over a communication step,
Delta J, T_d (and E, u_f when an onset falls inside the step) at the stage times.

Inputs:  u_c[1..N]          commanded wheel torques, N.m
Outputs: sigma[1..3]        [nu, psi, gamma], rad
         omega[1..3]        body rate, rad/s
         u_wheel[1..N]      applied wheel torques E sat(u_c) + u_f, N.m
         tau_applied[1..3]  body torque of the wheels M u_wheel (without T_d), N.m
         fault_torque[1..3] true equivalent fault torque M((E - I) sat(u_c) + u_f), N.m
         e[1..N]            effectiveness in force, 1
         u_f[1..N]          bias in force, N.m
         T_d[1..3]          disturbance torque, N.m
         delta_J[1..3]      diagonal of Delta J(t), kg.m2
         h_w[1..N]          wheel momentum about each spin axis (inertial), N.m.s (h_w_init when wheel_momentum = 0)
"""
from __future__ import annotations

import math

import numpy as np

from . import euler231, kernels
from .block import Block, matrix, scalar, vector
from .integrate import h_max_parameter, substeps
from .kernels import rigid_wheels as _kernel
from .linalg3 import solve_sym3
from .timing import StepWindow, happened_at


def check_distribution(M: np.ndarray, name: str = "M") -> None:
    """Raise ``ValueError`` naming ``name`` if M (3xN) cannot be a wheel distribution matrix."""
    if M.shape[0] != 3 or M.shape[1] < 3:
        raise ValueError(f"{name}: a 3xN distribution matrix with N >= 3 wheels is needed, got {M.shape}")
    zero = [j + 1 for j in range(M.shape[1]) if not np.any(M[:, j])]
    if zero:
        raise ValueError(
            f"{name}: column {zero[0]} is zero, so wheel {zero[0]} of the N = {M.shape[1]} declared wheels "
            f"produces no torque (N is inconsistent with {name}: build the block with the wheels {name} uses)"
        )
    sv = np.linalg.svd(M, compute_uv=False)
    if sv[-1] <= 1e-9 * sv[0]:
        raise ValueError(
            f"{name}: rank {int(np.sum(sv > 1e-9 * sv[0]))} < 3 (singular values {np.array2string(sv, precision=3)}): "
            f"the wheels cannot produce every body torque"
        )


def check_inertia(J: np.ndarray, name: str = "J") -> None:
    """Raise ``ValueError`` naming ``name`` unless J is symmetric positive definite."""
    if not np.allclose(J, J.T, rtol=0.0, atol=1e-12 * max(1.0, float(np.abs(J).max()))):
        raise ValueError(f"{name}: the inertia matrix must be symmetric, got {J.tolist()}")
    lam = np.linalg.eigvalsh(J)
    if not lam[0] > 0:
        raise ValueError(f"{name}: the inertia matrix must be positive definite (eigenvalues {np.array2string(lam, precision=4)})")


def wheel_count(n_wheels) -> int:
    """``n_wheels`` as an int; ``ValueError`` unless it is a whole number >= 3 (three axes)."""
    if int(n_wheels) != n_wheels or n_wheels < 3:
        raise ValueError(f"n_wheels must be an integer >= 3, got {n_wheels}")
    return int(n_wheels)


def default_distribution(n: int) -> np.ndarray:
    """The 3 x n default wheel distribution: one wheel on each body axis, every further wheel
    skewed along (1, 1, 1)/sqrt(3) (001's four-wheel layout, parameters.py ``M``)."""
    m0 = np.zeros((3, n))
    m0[:, :3] = np.eye(3)
    m0[:, 3:] = 1.0 / math.sqrt(3.0)
    return m0


def wheel_parameters(n: int, model: bool = False) -> list:
    """Parameters J (kg.m2, default I) and M (3 x n, :func:`default_distribution`) of the rigid
    spacecraft with n wheels; ``model``: a controller's or observer's copy of them."""
    if model:
        j, m = "nominal inertia (model)", "wheel distribution matrix (model)"
    else:
        j, m = "nominal inertia", "wheel distribution matrix (column j: spin axis of wheel j)"
    return matrix("J", np.eye(3), "kg.m2", j) + matrix("M", default_distribution(n), "1", m)


class RigidSpacecraftWheels(Block):
    model_name = "RigidSpacecraftWheels"
    description = "Rigid spacecraft, Euler-angle kinematics 001 (1)-(2), dynamics 001 (3), N wheels with faults 001 (5)"

    def __init__(self, n_wheels: int = 4):
        n = self.n = wheel_count(n_wheels)
        inputs = vector("u_c", n, "N.m", "commanded wheel torque")
        outputs = (
            vector("sigma", 3, "rad", "Euler angles [nu, psi, gamma] of the 2-3-1 sequence")
            + vector("omega", 3, "rad/s", "body angular rate")
            + vector("u_wheel", n, "N.m", "applied wheel torque E sat(u_c) + u_f")
            + vector("tau_applied", 3, "N.m", "body torque of the wheels M u_wheel (without T_d)")
            + vector("fault_torque", 3, "N.m", "true equivalent fault torque M((E - I) sat(u_c) + u_f)")
            + vector("e", n, "1", "wheel effectiveness in force")
            + vector("u_f", n, "N.m", "wheel bias in force")
            + vector("T_d", 3, "N.m", "external disturbance torque")
            + vector("delta_J", 3, "kg.m2", "diagonal of the inertia uncertainty Delta J(t)")
            + vector("h_w", n, "N.m.s", "wheel momentum about each spin axis, inertial (h_w_init when wheel_momentum = 0)")
        )
        params = (
            wheel_parameters(n)
            + vector("dJ_amp", 3, "kg.m2", "Delta J_ii = dJ_amp_i sin(dJ_freq_i t)")
            + vector("dJ_freq", 3, "rad/s", "angular frequency of Delta J_ii")
            + vector("Td_amp", 3, "N.m", "T_d,i = Td_amp_i sin(Td_freq_i t)")
            + vector("Td_freq", 3, "rad/s", "angular frequency of T_d,i")
            + vector("sigma_init", 3, "rad", "initial Euler angles [nu, psi, gamma]")
            + vector("omega_init", 3, "rad/s", "initial body rate")
            + vector("effectiveness", n, "1", "diagonal of E after its onset (1 healthy, 0 failed)", [1.0] * n)
            + vector("effectiveness_onset", n, "s", "time from which effectiveness[j] applies")
            + vector("bias", n, "N.m", "bias u_f after its onset")
            + vector("bias_onset", n, "s", "time from which bias[j] applies")
            + scalar("u_max", 0.0, "N.m", "per-wheel saturation |u_c,j| <= u_max (0: none)")
            + h_max_parameter(0.001)
            + scalar("omega_max", 20.0, "rad/s", "validity guard: |omega_i| above it stops the run")
            + scalar("nu_max", 1.55334303427495, "rad", "singularity guard (89 deg): |nu| above it stops the run")
            + scalar("wheel_momentum", 0.0, "1", "1: the wheel momenta h_w are plant states (gyroscopic torque "
                     "-omega x M h_w); 0: 001 (3) as printed, no wheel momentum")
            + vector("h_w_init", n, "N.m.s", "initial wheel momentum about each spin axis, inertial (wheel_momentum = 1)")
        )
        all_u = [f"u_c[{j + 1}]" for j in range(n)]
        feed = {f"u_wheel[{j + 1}]": [f"u_c[{j + 1}]"] for j in range(n)}
        feed.update({f"tau_applied[{i}]": all_u for i in (1, 2, 3)})
        feed.update({f"fault_torque[{i}]": all_u for i in (1, 2, 3)})
        super().__init__(inputs, outputs, params, feed)
        self.x = [0.0] * 6

    # -- set-up -------------------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        n = self.n
        J = self.p_matrix("J")
        check_inertia(J, "J")
        M = self.p_matrix("M")
        check_distribution(M, "M")
        amp = self.p_vector("dJ_amp")
        lam = np.linalg.eigvalsh(J - np.diag(np.abs(amp)))
        if not lam[0] > 0:
            raise ValueError(
                f"dJ_amp: J + Delta J(t) can lose positive definiteness (lambda_min(J - diag|dJ_amp|) = {lam[0]:.4g} kg.m2)"
            )
        e = self.p_vector("effectiveness")
        if np.any(e < 0) or np.any(e > 1):
            raise ValueError(f"effectiveness: each e_j must lie in [0, 1] (001 (5)), got {e.tolist()}")
        for name in ("h_max", "omega_max", "nu_max"):
            if not self.p(name) > 0:
                raise ValueError(f"{name}: must be > 0, got {self.p(name):g}")
        if not self.p("nu_max") < math.pi / 2:
            raise ValueError(f"nu_max: must be below pi/2 = {math.pi / 2:.6f} rad (the singularity), got {self.p('nu_max'):g}")
        if self.p("u_max") < 0:
            raise ValueError(f"u_max: must be >= 0 (0: no saturation), got {self.p('u_max'):g}")
        self.J, self.M = J, M
        self._J = tuple(float(v) for v in (J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2]))
        self._Mrows = [tuple(M[i].tolist()) for i in range(3)]
        self.dJ_amp, self.dJ_freq = amp.tolist(), self.p_vector("dJ_freq").tolist()
        self.Td_amp, self.Td_freq = self.p_vector("Td_amp").tolist(), self.p_vector("Td_freq").tolist()
        self.e = e
        self.e_onset = self.p_vector("effectiveness_onset").tolist()
        self.bias = self.p_vector("bias")
        self.bias_onset = self.p_vector("bias_onset").tolist()
        self.u_max = self.p("u_max")
        self.h_max = self.p("h_max")
        self.omega_max = self.p("omega_max")
        self.nu_max = self.p("nu_max")
        sigma0 = self.p_vector("sigma_init")
        if abs(sigma0[0]) > self.nu_max:
            raise ValueError(f"sigma_init: |nu(0)| = {abs(sigma0[0]):.4g} rad exceeds nu_max = {self.nu_max:.4g} rad")
        wm = self.p("wheel_momentum")
        if wm not in (0.0, 1.0):
            raise ValueError(f"wheel_momentum: must be 0 (001 (3), no wheel momentum) or 1 (wheel momenta as states), got {wm:g}")
        self.momentum = wm == 1.0
        self.h_w_init = self.p_vector("h_w_init")
        self.x = sigma0.tolist() + self.p_vector("omega_init").tolist() + (self.h_w_init.tolist() if self.momentum else [])
        self._ones, self._zeros = np.ones(n), np.zeros(n)
        self._kernels = kernels.enabled()  # plant/kernels/rigid_wheels.py: advance, actuator outputs
        self._prm = _kernel.params(self._J, self.dJ_amp, self.dJ_freq, self.Td_amp, self.Td_freq, self.nu_max,
                                   self.omega_max)
        self._k_arrays = (np.asarray(e, dtype=float), np.array(self.e_onset), np.asarray(self.bias, dtype=float),
                          np.array(self.bias_onset), np.ascontiguousarray(M, dtype=float))

    # -- actuator path ------------------------------------------------------------------------
    def _saturate(self, u_c) -> np.ndarray:
        u = np.array(u_c, dtype=float)
        return np.clip(u, -self.u_max, self.u_max) if self.u_max > 0 else u

    def faults_at(self, t: float):
        """(e, u_f) in force at the communication point t (from the right, plant/timing.py)."""
        e = np.array([self.e[j] if happened_at(T, t) else 1.0 for j, T in enumerate(self.e_onset)])
        uf = np.array([self.bias[j] if happened_at(T, t) else 0.0 for j, T in enumerate(self.bias_onset)])
        return e, uf

    def _faults_in_step(self, w: StepWindow, tau: float):
        e = np.array([self.e[j] if w.active(T, tau) else 1.0 for j, T in enumerate(self.e_onset)])
        uf = np.array([self.bias[j] if w.active(T, tau) else 0.0 for j, T in enumerate(self.bias_onset)])
        return e, uf

    def _stage_torque(self, win: StepWindow, tau: float, us) -> tuple:
        e, uf = self._faults_in_step(win, tau)
        return self._torque(e * us + uf)

    def _stage_wheels(self, win: StepWindow, tau: float, us) -> list:
        """Applied wheel torques E sat(u_c) + u_f at stage time tau (wheel_momentum = 1)."""
        e, uf = self._faults_in_step(win, tau)
        return (e * us + uf).tolist()

    def _torque(self, u_wheel) -> tuple:
        uw = u_wheel.tolist()
        return tuple(sum([a * b for a, b in zip(row, uw)]) for row in self._Mrows)

    # -- dynamics -------------------------------------------------------------------------------
    def _deriv(self, x, t, tau):
        """[sigma', omega'] at time t for body wheel torque tau (3-tuple)."""
        nu, gamma = x[0], x[2]
        w1, w2, w3 = x[3], x[4], x[5]
        j11, j12, j13, j22, j23, j33 = self._J
        a, f = self.dJ_amp, self.dJ_freq
        j11 += a[0] * math.sin(f[0] * t)
        j22 += a[1] * math.sin(f[1] * t)
        j33 += a[2] * math.sin(f[2] * t)
        h1 = j11 * w1 + j12 * w2 + j13 * w3
        h2 = j12 * w1 + j22 * w2 + j23 * w3
        h3 = j13 * w1 + j23 * w2 + j33 * w3
        ta, tf = self.Td_amp, self.Td_freq
        b1 = -(w2 * h3 - w3 * h2) + tau[0] + ta[0] * math.sin(tf[0] * t)
        b2 = -(w3 * h1 - w1 * h3) + tau[1] + ta[1] * math.sin(tf[1] * t)
        b3 = -(w1 * h2 - w2 * h1) + tau[2] + ta[2] * math.sin(tf[2] * t)
        wd1, wd2, wd3 = solve_sym3(j11, j12, j13, j22, j23, j33, b1, b2, b3)
        sg, cg = math.sin(gamma), math.cos(gamma)
        c = w2 * cg - w3 * sg
        return (w2 * sg + w3 * cg, c / math.cos(nu), w1 - math.tan(nu) * c, wd1, wd2, wd3)

    def _deriv_momentum(self, x, t, uw):
        """[sigma', omega', h_w'] at time t for the applied wheel torques uw (list of N), with the
        wheel momenta h_w = x[6:] in the gyroscopic term (wheel_momentum = 1)."""
        nu, gamma = x[0], x[2]
        w1, w2, w3 = x[3], x[4], x[5]
        hw = x[6:]
        m1, m2, m3 = self._Mrows
        g1 = sum([a * b for a, b in zip(m1, hw)])
        g2 = sum([a * b for a, b in zip(m2, hw)])
        g3 = sum([a * b for a, b in zip(m3, hw)])
        tau = self._torque_list(uw)
        j11, j12, j13, j22, j23, j33 = self._J
        a, f = self.dJ_amp, self.dJ_freq
        j11 += a[0] * math.sin(f[0] * t)
        j22 += a[1] * math.sin(f[1] * t)
        j33 += a[2] * math.sin(f[2] * t)
        h1 = j11 * w1 + j12 * w2 + j13 * w3 + g1
        h2 = j12 * w1 + j22 * w2 + j23 * w3 + g2
        h3 = j13 * w1 + j23 * w2 + j33 * w3 + g3
        ta, tf = self.Td_amp, self.Td_freq
        b1 = -(w2 * h3 - w3 * h2) + tau[0] + ta[0] * math.sin(tf[0] * t)
        b2 = -(w3 * h1 - w1 * h3) + tau[1] + ta[1] * math.sin(tf[1] * t)
        b3 = -(w1 * h2 - w2 * h1) + tau[2] + ta[2] * math.sin(tf[2] * t)
        wd1, wd2, wd3 = solve_sym3(j11, j12, j13, j22, j23, j33, b1, b2, b3)
        sg, cg = math.sin(gamma), math.cos(gamma)
        c = w2 * cg - w3 * sg
        return (w2 * sg + w3 * cg, c / math.cos(nu), w1 - math.tan(nu) * c, wd1, wd2, wd3, *[-v for v in uw])

    def _torque_list(self, uw) -> tuple:
        return tuple(sum([a * b for a, b in zip(row, uw)]) for row in self._Mrows)

    def _advance_momentum(self, t: float, h: float, steps: int, dt: float, us) -> None:
        """The reference RK4 of [sigma, omega, h_w] over [t, t + h] (wheel_momentum = 1)."""
        win = StepWindow(t, h)
        x = self.x
        deriv = self._deriv_momentum
        for k in range(steps):
            tk = t + k * dt
            tm, t1 = tk + 0.5 * dt, tk + dt
            ua, ub, uc = (self._stage_wheels(win, tau, us) for tau in (tk, tm, t1))
            k1 = deriv(x, tk, ua)
            x2 = [a + 0.5 * dt * b for a, b in zip(x, k1)]
            k2 = deriv(x2, tm, ub)
            x3 = [a + 0.5 * dt * b for a, b in zip(x, k2)]
            k3 = deriv(x3, tm, ub)
            x4 = [a + dt * b for a, b in zip(x, k3)]
            k4 = deriv(x4, t1, uc)
            x = [a + (dt / 6.0) * (b1 + 2.0 * (b2 + b3) + b4) for a, b1, b2, b3, b4 in zip(x, k1, k2, k3, k4)]
            self._guard(x, t1)
        self.x = x

    def _guard(self, x, t):
        nu = x[0]
        w = max(abs(x[3]), abs(x[4]), abs(x[5]))
        if not all(math.isfinite(v) for v in x):
            raise FloatingPointError(f"non-finite plant state at t = {t:.6g} s: {x}")
        if abs(nu) > self.nu_max:
            raise FloatingPointError(
                f"Euler-angle singularity: |nu| = {math.degrees(abs(nu)):.3f} deg exceeds nu_max = "
                f"{math.degrees(self.nu_max):.3f} deg at t = {t:.6g} s (the 2-3-1 kinematics 001 (1) are singular at nu = +-90 deg)"
            )
        if w > self.omega_max:
            raise FloatingPointError(f"|omega| = {w:.4g} rad/s exceeds omega_max = {self.omega_max:g} rad/s at t = {t:.6g} s")

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        steps, dt = substeps(h, self.h_max)
        us = self._saturate(u[: self.n])
        if self.momentum:
            if not self._kernels:
                return self._advance_momentum(t, h, steps, dt, us)
            x, k = _kernel.advance_momentum(np.array(self.x), t, h, steps, us, *self._k_arrays, self._prm)
            if k >= 0:
                self._guard(x.tolist(), t + k * dt + dt)
            self.x = x.tolist()
            return
        if self._kernels:
            x, k = _kernel.advance(np.array(self.x), t, h, steps, us, *self._k_arrays, self._prm)
            if k >= 0:
                self._guard(x.tolist(), t + k * dt + dt)  # raises the reference's message
            self.x = x.tolist()
            return
        win = StepWindow(t, h)
        onsets = self.e_onset + self.bias_onset
        switching = any(win.contains(T) for T in onsets)
        if not switching:
            tau_c = self._stage_torque(win, t, us)
        x = self.x
        deriv = self._deriv
        for k in range(steps):
            tk = t + k * dt
            tm, t1 = tk + 0.5 * dt, tk + dt
            if switching:
                ta, tb, tc = (self._stage_torque(win, tau, us) for tau in (tk, tm, t1))
            else:
                ta = tb = tc = tau_c
            k1 = deriv(x, tk, ta)
            x2 = [a + 0.5 * dt * b for a, b in zip(x, k1)]
            k2 = deriv(x2, tm, tb)
            x3 = [a + 0.5 * dt * b for a, b in zip(x, k2)]
            k3 = deriv(x3, tm, tb)
            x4 = [a + dt * b for a, b in zip(x, k3)]
            k4 = deriv(x4, t1, tc)
            x = [a + (dt / 6.0) * (b1 + 2.0 * (b2 + b3) + b4) for a, b1, b2, b3, b4 in zip(x, k1, k2, k3, k4)]
            self._guard(x, t1)
        self.x = x

    def _actuator_outputs(self, t: float, u: np.ndarray):
        """(u_wheel, tau_applied, fault_torque, e, u_f) at the point t for the command in u."""
        if self._kernels:
            n = self.n
            y = _kernel.actuator(t, np.asarray(u, dtype=float), n, self.u_max, *self._k_arrays)
            return y[:n], y[n : n + 3], y[n + 3 : n + 6], y[n + 6 : 2 * n + 6], y[2 * n + 6 :]
        us = self._saturate(u[: self.n])
        e, uf = self.faults_at(t)
        u_wheel = e * us + uf
        tau = self.M @ u_wheel
        f = self.M @ ((e - 1.0) * us + uf)
        return u_wheel, tau, f, e, uf

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        u_wheel, tau, f, e, uf = self._actuator_outputs(t, u)
        td = [a * math.sin(w * t) for a, w in zip(self.Td_amp, self.Td_freq)]
        dj = [a * math.sin(w * t) for a, w in zip(self.dJ_amp, self.dJ_freq)]
        hw = self.x[6:] if self.momentum else self.h_w_init
        return np.concatenate((self.x[:6], u_wheel, tau, f, e, uf, td, dj, hw))

    def feedthrough_outputs(self, t: float, u: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``y`` from ``outputs_at`` with the outputs that depend on u_c (u_wheel, tau_applied,
        fault_torque) recomputed for a new command, the same arithmetic: the state outputs are
        evaluated once per exchange (BlockSession)."""
        u_wheel, tau, f = self._actuator_outputs(t, u)[:3]
        n = self.n
        y[6 : 6 + n] = u_wheel
        y[6 + n : 9 + n] = tau
        y[9 + n : 12 + n] = f
        return y

    def get_state(self) -> list:
        return list(self.x)

    def set_state(self, state) -> None:
        self.x = [float(v) for v in state]

    # -- evaluation helpers ---------------------------------------------------------------------
    def angular_momentum_inertial(self, t: float = 0.0) -> np.ndarray:
        """(J + Delta J(t)) omega (+ M h_w with wheel momentum) in inertial components, N.m.s (conserved
        for T_d = 0, Delta J = 0, and u = 0 without wheel momentum)."""
        dj = [a * math.sin(w * t) for a, w in zip(self.dJ_amp, self.dJ_freq)]
        Jt = self.J + np.diag(dj)
        H = Jt @ np.array(self.x[3:6]) + (self.M @ np.array(self.x[6:]) if self.momentum else 0.0)
        return euler231.dcm(self.x[0:3]).T @ H
