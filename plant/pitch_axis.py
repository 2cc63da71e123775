"""Single-axis (pitch) flexible spacecraft: rigid hub + n bending modes, 002 (1)-(2), (8) / 003 (2.1)-(2.5).

002 (1) / 003 (2.1):  J theta'' + F eta'' = T,   eta'' + C_m eta' + Lambda eta + F^T theta'' = 0,
solved for the accelerations (002 (2), 003 (2.2)):
          (J - F F^T) theta'' = F (C_m eta' + Lambda eta) + T,
          eta'' = -C_m eta' - Lambda eta - F^T theta''.
C_m = diag(2 xi_i w_i), Lambda = diag(w_i^2); F is the 1 x n rigid-elastic coupling row (002 F,
003 H). The torque is T = rho(t) u + u_d(t): actuator effectiveness rho (002 (3) omega,
003 (2.4) rho(t)) times the command, plus the external torque u_d (003 T_d, (4.2)).

Model functions (used by the designs and their checks):

* :func:`rigid_model`: 002 (8) / 003 (2.4), x = [theta, theta'], A = [[0, 1], [0, 0]],
  B = [0; (J - F F^T)^-1], C = I; the vibration torque w = F (C_m eta' + Lambda eta) (002 w,
  003 d0 of (2.3)) enters through B as a disturbance.
* :func:`flexible_model`: the full (2 + 2n)-state model, z = [theta, theta', eta, eta'].
* :class:`PitchAxisSpacecraft`: the plant as a block (FMU ``Zhang2014Plant`` / ``Hang2023Plant``
  with the papers' parameter sets, ``papers/p00N_*/blocks.py``).

Parameter sets (numpy only, SI) are the papers' own: ``papers/p002_zhang2014/parameters.py``
and ``papers/p003_hang2023/parameters.py``; a set is a dict with ``J`` (kg m^2), ``F`` (coupling
row), ``omega`` (rad/s) and ``xi`` (1).
"""
from __future__ import annotations

import math

import numpy as np

from .block import Block, scalar, vector
from .integrate import h_max_parameter, substeps
from .modal import modal_state
from .timing import StepWindow, happened_at


def effective_inertia(J, F) -> float:
    """J - F F^T, 002 (2)."""
    F = np.asarray(F, float).reshape(-1)
    return float(J - F @ F)


def rigid_model(J, F):
    """(A, B, C) of 002 (8) with x = [theta, theta']."""
    A = np.array([[0.0, 1.0], [0.0, 0.0]])
    B = np.array([[0.0], [1.0 / effective_inertia(J, F)]])
    return A, B, np.eye(2)


def modal(omega, xi):
    """C_m = diag(2 xi_i w_i), Lambda = diag(w_i^2), 002 (1)."""
    omega, xi = np.asarray(omega, float), np.asarray(xi, float)
    return np.diag(2.0 * xi * omega), np.diag(omega**2)


def flexible_model(J, F, omega, xi):
    """(A, B, Cw) of the full model, z = [theta, theta', eta, eta']; w = Cw z is the vibration torque."""
    F = np.asarray(F, float).reshape(1, -1)
    n = F.shape[1]
    Cm, Lam = modal(omega, xi)
    je = effective_inertia(J, F.ravel())
    A = np.zeros((2 + 2 * n, 2 + 2 * n))
    B = np.zeros((2 + 2 * n, 1))
    A[0, 1] = 1.0
    A[2 : 2 + n, 2 + n :] = np.eye(n)
    # theta'' = (u + F (Cm eta' + Lam eta)) / je
    row_th = np.zeros(2 + 2 * n)
    row_th[2 : 2 + n] = (F @ Lam).ravel() / je
    row_th[2 + n :] = (F @ Cm).ravel() / je
    A[1] = row_th
    B[1, 0] = 1.0 / je
    # eta'' = -Cm eta' - Lam eta - F^T theta''
    A[2 + n :, 2 : 2 + n] = -Lam - F.T @ row_th[2 : 2 + n].reshape(1, -1)
    A[2 + n :, 2 + n :] = -Cm - F.T @ row_th[2 + n :].reshape(1, -1)
    B[2 + n :, 0] = -F.ravel() / je
    Cw = np.zeros((1, 2 + 2 * n))
    Cw[0, 2 : 2 + n] = (F @ Lam).ravel()
    Cw[0, 2 + n :] = (F @ Cm).ravel()
    return A, B, Cw


def closed_loop_cost(K, effectiveness, params, Z, R, flexible: bool = True):
    """(A_cl, Q) of the loop u = K [theta, theta'] with torque omega*u: z' = A_cl z, and the
    cost density z^T Q z = x^T Z x + u^T omega R omega u of 002 (11) (x = [theta, theta'])."""
    K = np.asarray(K, float).reshape(1, 2)
    om = float(effectiveness)
    if flexible:
        A, B, _ = flexible_model(params["J"], params["F"], params["omega"], params["xi"])
    else:
        A, B, _ = rigid_model(params["J"], params["F"])
    n = A.shape[0]
    Kz = np.zeros((1, n))
    Kz[0, :2] = K
    Q = np.zeros((n, n))
    Q[:2, :2] = np.asarray(Z, float) + om * om * K.T @ np.asarray(R, float) @ K
    return A + om * B @ Kz, Q


def simulate(K, effectiveness, x0, params, Z, R, t_final: float = 300.0, h: float = 0.01,
             flexible: bool = True):
    """Closed loop u = K [theta, theta'], torque omega*u, fixed-step RK4 from rest modes.

    Returns a dict with ``t``, ``z`` (states), ``u`` and ``J_c`` = int_0^t_final
    x^T Z x + u^T omega R omega u dt (002 (11)), integrated as an extra RK4 state.
    ``flexible=False`` simulates the rigid design model (8) with w = 0.
    """
    K = np.asarray(K, float).reshape(1, 2)
    Acl, Q = closed_loop_cost(K, effectiveness, params, Z, R, flexible)
    n = Acl.shape[0]

    def f(y):
        z = y[:n]
        return np.concatenate([Acl @ z, [z @ Q @ z]])

    steps = int(round(t_final / h))
    y = np.zeros(n + 1)
    y[:2] = x0
    zs = np.empty((steps + 1, n))
    zs[0] = y[:n]
    for k in range(steps):
        k1 = f(y)
        k2 = f(y + 0.5 * h * k1)
        k3 = f(y + 0.5 * h * k2)
        k4 = f(y + h * k3)
        y = y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        zs[k + 1] = y[:n]
    t = np.arange(steps + 1) * h
    return {"t": t, "z": zs, "u": (zs[:, :2] @ K.T).ravel(), "J_c": float(y[n])}


# ---------------------------------------------------------------------------------------
# the plant block


def pitch_parameters(n: int, note: str = "") -> list:
    """Parameters J (kg.m2, start 1) and F[1..n] (1) of 002 (1) / 003 (2.1); ``note`` (e.g.
    "model") marks a controller's or observer's copy of them in the descriptions."""
    tag = f" ({note})" if note else ""
    return (scalar("J", 1.0, "kg.m2", "pitch-axis inertia of the hub" + tag)
            + vector("F", n, "1", "rigid-elastic coupling row, 002 F / 003 H" + tag))


def pitch_inputs(target: bool = True) -> list:
    """Inputs of a pitch-axis controller or observer: theta (rad), theta_dot (rad/s) measured on
    the plant and, with ``target``, the desired theta_d (rad), theta_d_dot (rad/s)."""
    measured = scalar("theta", 0.0, "rad", "measured pitch angle") + scalar("theta_dot", 0.0, "rad/s", "measured pitch rate")
    if not target:
        return measured
    return measured + scalar("theta_d", 0.0, "rad", "desired pitch angle") + scalar("theta_d_dot", 0.0, "rad/s", "desired pitch rate")


def rk4_affine(A, B, dt):
    """One RK4 step of z' = A z + B tau(t) as an affine map: z(t + dt) = P z + Q0 tau(t) +
    Qm tau(t + dt/2) + Q1 tau(t + dt) (exactly the classical RK4 stages, precomputed)."""
    A = np.asarray(A, float)
    b = np.asarray(B, float).reshape(-1)
    n = A.shape[0]
    Z = np.hstack([np.eye(n), np.zeros((n, 3))])  # columns: z, tau0, taum, tau1
    T0, Tm, T1 = (np.zeros((n, n + 3)) for _ in range(3))
    T0[:, n], Tm[:, n + 1], T1[:, n + 2] = b, b, b
    k1 = A @ Z + T0
    k2 = A @ (Z + 0.5 * dt * k1) + Tm
    k3 = A @ (Z + 0.5 * dt * k2) + Tm
    k4 = A @ (Z + dt * k3) + T1
    M = Z + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return M[:, :n].copy(), M[:, n].copy(), M[:, n + 1].copy(), M[:, n + 2].copy()


PER_MODE = ("F", "omega_n", "zeta", "eta_init", "eta_dot_init")


class PitchAxisSpacecraft(Block):
    """Pitch axis of a flexible spacecraft, rigid hub + ``n_modes`` bending modes.

    Dynamics 002 (1)-(2) / 003 (2.1)-(2.2) with the torque T = rho(t) sat(u) + u_d(t):

    * effectiveness rho(t) = ``effectiveness_before`` before ``effectiveness_onset`` and
      ``effectiveness`` from it on (002: omega = omega_hat from t = 0, i.e. onset 0; 003: 1 until
      20 s, then 0.4 / 0.8 / 1.0), evaluated through ``plant/timing.py``;
    * external torque u_d(t) = a (c_cos cos(n0 t) + c_sin sin(n0 t) + c_0) (003 (4.2); pitch:
      T_2y = 4.5e-5 (3 cos n0 t + 1.5 sin n0 t) N.m), evaluated at the RK4 stage times;
    * saturation |u| <= ``u_max`` (0: none; neither paper saturates).

    State z = [theta, theta', eta, eta'] (rad, rad/s, 1, 1/s); fixed-step RK4 with internal step
    <= ``h_max``, u held over the communication step (the stages are precomputed as an affine
    map, :func:`rk4_affine`).

    Inputs:  u            commanded control torque, N.m
    Outputs: theta, theta_dot          pitch angle (rad) and rate (rad/s), measured = true
             eta[i], eta_dot[i]        modal coordinates (1) and rates (1/s)
             tau_applied               rho(t) sat(u): 002 u^F = omega u, 003 T_c, N.m (feedthrough from u)
             d_vib                     F (C_m eta' + Lambda eta): 002 w, 003 d0 (2.3), N.m
             u_d                       external torque T_d (003 d1 in the simulation), N.m
             effectiveness_now         rho(t) in force, 1
    """

    model_name = "PitchAxisSpacecraft"
    description = "Pitch-axis flexible spacecraft, 002 (1)-(2) / 003 (2.1)-(2.5), with effectiveness and disturbance"

    def __init__(self, n_modes: int = 2):
        n = int(n_modes)
        if n < 0 or n != n_modes:
            raise ValueError(f"PitchAxisSpacecraft: n_modes must be a whole number >= 0, got {n_modes}")
        self.n = n
        inputs = scalar("u", 0.0, "N.m", "commanded control torque")
        outputs = (
            scalar("theta", 0.0, "rad", "pitch angle")
            + scalar("theta_dot", 0.0, "rad/s", "pitch rate")
            + modal_state(n, "modal coordinate")
            + scalar("tau_applied", 0.0, "N.m", "torque delivered by the actuator, rho(t) sat(u)")
            + scalar("d_vib", 0.0, "N.m", "vibration torque F (C_m eta' + Lambda eta) (002 w, 003 d0)")
            + scalar("u_d", 0.0, "N.m", "external disturbance torque (003 T_d)")
            + scalar("effectiveness_now", 1.0, "1", "actuator effectiveness rho(t) in force")
        )
        params = (
            pitch_parameters(n)
            + vector("omega_n", n, "rad/s", "modal frequency", [1.0] * n)
            + vector("zeta", n, "1", "modal damping ratio")
            + scalar("theta_init", 0.0, "rad", "initial pitch angle")
            + scalar("theta_dot_init", 0.0, "rad/s", "initial pitch rate")
            + modal_state(n, "modal coordinate", initial=True)
            + scalar("effectiveness", 1.0, "1", "actuator effectiveness from the onset on, in [0, 1]")
            + scalar("effectiveness_before", 1.0, "1", "actuator effectiveness before the onset, in [0, 1]")
            + scalar("effectiveness_onset", 0.0, "s", "time at which the effectiveness changes")
            + scalar("dist_amplitude", 0.0, "N.m", "external torque amplitude a")
            + scalar("dist_n0", 0.0011, "rad/s", "external torque frequency n0 (orbit rate)")
            + scalar("dist_cos", 0.0, "1", "coefficient of cos(n0 t)")
            + scalar("dist_sin", 0.0, "1", "coefficient of sin(n0 t)")
            + scalar("dist_const", 0.0, "1", "constant coefficient")
            + scalar("u_max", 0.0, "N.m", "saturation |u| <= u_max (0: none)")
            + h_max_parameter(1e-3)
            + scalar("theta_dot_max", 10.0, "rad/s", "model validity guard: |theta'| above it stops the run")
        )
        super().__init__(inputs, outputs, params, {"tau_applied": ("u",)})
        self.z = np.zeros(2 + 2 * n)
        self._maps = {}

    def set_defaults(self, values: dict) -> None:
        """As :meth:`Block.set_defaults`, with the per-mode arrays checked against ``n_modes``."""
        for base in PER_MODE:
            if base in values and np.size(values[base]) != self.n:
                raise ValueError(f"{self.model_name}: '{base}' has {np.size(values[base])} entries but the plant has "
                                 f"n_modes = {self.n} (F, omega_n, zeta, eta_init, eta_dot_init need one per mode)")
        super().set_defaults(values)

    # -- set-up -------------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        name = self.model_name
        J = self.p("J")
        if not J > 0:
            raise ValueError(f"{name}: J (pitch inertia) must be > 0 kg.m2, got {J:g}")
        F = self.p_vector("F")
        w, xi = self.p_vector("omega_n"), self.p_vector("zeta")
        for base, a in (("F", F), ("omega_n", w), ("zeta", xi)):
            if a.size != self.n:
                raise ValueError(f"{name}: '{base}' has {a.size} entries, n_modes = {self.n}")
        if np.any(w <= 0):
            raise ValueError(f"{name}: omega_n must be > 0 rad/s, got {w.tolist()}")
        if np.any(xi < 0):
            raise ValueError(f"{name}: zeta must be >= 0, got {xi.tolist()}")
        je = effective_inertia(J, F)
        if not je > 0:
            raise ValueError(f"{name}: J - F F^T = {je:g} kg.m2 must be > 0 (J = {J:g}, F F^T = {F @ F:g})")
        for k in ("effectiveness", "effectiveness_before"):
            if not 0.0 <= self.p(k) <= 1.0:
                raise ValueError(f"{name}: {k} must be in [0, 1], got {self.p(k):g}")
        self.h_max = self.p("h_max")
        if not self.h_max > 0:
            raise ValueError(f"{name}: h_max must be > 0 s, got {self.h_max:g}")
        self.u_max = self.p("u_max")
        if self.u_max < 0:
            raise ValueError(f"{name}: u_max must be >= 0 N.m (0: no saturation), got {self.u_max:g}")
        self.rate_max = self.p("theta_dot_max")
        if not self.rate_max > 0:
            raise ValueError(f"{name}: theta_dot_max must be > 0 rad/s, got {self.rate_max:g}")
        self.A, B, Cw = flexible_model(J, F, w, xi) if self.n else rigid_model(J, F)[:2] + (None,)
        self.B = B.reshape(-1)
        self.Cw = Cw.reshape(-1) if Cw is not None else np.zeros(2)
        self.J, self.F, self.Lam = J, F, w**2
        self.rho1, self.rho0 = self.p("effectiveness"), self.p("effectiveness_before")
        self.onset = self.p("effectiveness_onset")
        a = self.p("dist_amplitude")
        self.dist = (a * self.p("dist_cos"), a * self.p("dist_sin"), a * self.p("dist_const"), self.p("dist_n0"))
        self.has_dist = a != 0.0 and any(self.dist[:3])
        self._maps = {}
        self.z = np.concatenate([[self.p("theta_init"), self.p("theta_dot_init")],
                                 self.p_vector("eta_init"), self.p_vector("eta_dot_init")])

    # -- signals ------------------------------------------------------------------------------
    def disturbance(self, t: float) -> float:
        """u_d(t) = a (c_cos cos(n0 t) + c_sin sin(n0 t) + c_0), N.m (003 (4.2))."""
        if not self.has_dist:
            return 0.0
        c, s, k, n0 = self.dist
        return c * math.cos(n0 * t) + s * math.sin(n0 * t) + k

    def saturate(self, u: float) -> float:
        m = self.u_max
        return u if m == 0.0 else min(max(u, -m), m)

    def effectiveness_at(self, t: float) -> float:
        """rho at the communication point t (from the right, plant/timing.py)."""
        return self.rho1 if happened_at(self.onset, t) else self.rho0

    # -- the contract -----------------------------------------------------------------------
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        z = self.z
        rho = self.effectiveness_at(t)
        return np.concatenate((z, [rho * self.saturate(float(u[0])), float(self.Cw @ z), self.disturbance(t), rho]))

    def feedthrough_outputs(self, t: float, u: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``y`` from ``outputs_at`` with tau_applied recomputed for a new command u (the only
        output that depends on u): the state outputs are evaluated once per exchange."""
        y[2 + 2 * self.n] = self.effectiveness_at(t) * self.saturate(float(u[0]))
        return y

    def _map(self, dt):
        m = self._maps.get(dt)
        if m is None:
            m = self._maps[dt] = rk4_affine(self.A, self.B, dt)
        return m

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        steps, dt = substeps(h, self.h_max)
        P, Q0, Qm, Q1 = self._map(dt)
        us = self.saturate(float(u[0]))
        win = StepWindow(t, h)
        onset, r0, r1 = self.onset, self.rho0, self.rho1
        varying = self.has_dist or win.contains(onset)
        z = self.z
        if not varying:
            tau = (r1 if win.active(onset, t) else r0) * us
            Q = (Q0 + Qm + Q1) * tau
            for _ in range(steps):
                z = P @ z + Q
        else:
            def torque(tau_t):
                return (r1 if win.active(onset, tau_t) else r0) * us + self.disturbance(tau_t)

            for k in range(steps):
                tk = t + k * dt
                z = P @ z + Q0 * torque(tk) + Qm * torque(tk + 0.5 * dt) + Q1 * torque(tk + dt)
        if not abs(z[1]) <= self.rate_max:  # also catches NaN
            raise FloatingPointError(f"{self.model_name}: |theta_dot| = {abs(z[1]):.4g} rad/s exceeds theta_dot_max = "
                                     f"{self.rate_max:g} rad/s at t = {t + h:.6g} s (the closed loop diverged)")
        self.z = z

    def get_state(self) -> list:
        return self.z.tolist()

    def set_state(self, state) -> None:
        self.z = np.array(state, dtype=float)

    # -- evaluation helpers -----------------------------------------------------------------------
    def energy(self) -> float:
        """Mechanical energy of 002 (1): 1/2 J theta'^2 + theta' F eta' + 1/2 |eta'|^2 + 1/2 eta^T Lambda eta
        (conserved for u = 0, u_d = 0, zeta = 0), J."""
        n, z = self.n, self.z
        th_d, eta, eta_d = z[1], z[2:2 + n], z[2 + n:]
        return float(0.5 * self.J * th_d**2 + th_d * (self.F @ eta_d) + 0.5 * eta_d @ eta_d
                     + 0.5 * eta @ (self.Lam * eta))
