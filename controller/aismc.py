"""Adaptive integral sliding-mode controller (AISMC), the baseline (b) of 000 section 5.3, 000 (70)-(71).

    u     = - sum_i b_i Gamma^+ {||K_c^i s||_2 + sigma + d_m_hat} s / (||s||_2 + sigma') - Gamma^+ B^+ g(s)   000 (70)
    S     = s - int_0^t sum_i b_i (A_i + B K_c^i) s dt,     d_m_hat = ||S||_2                               000 (71)

with s = omega_e + beta q_ev (000 (39)), g(s) of 000 (36), A_i = -B omega_i^x J and
B^+ = B^-1 = J - delta^T delta, Gamma = I. beta = 2, sigma = 0.002, sigma' = 0.01 (000 section 5.3).

Readings chosen:
* 000 takes K_c^i "from Theorem 1 in ref. [21]", which we do not have: we use the K_c^i of
  000 Appendix A.2 (as the issue asks), so this is AISMC with 000's own gains.
* Premise variables: the measured omega; sum_i b_i A_i = A(clip(omega)) exactly.
* The AISMC law does not use the estimator: its outputs do not depend on f_hat, d2_hat
  (declared in ``feedthrough``), it treats faults and disturbances as one lumped disturbance.
* State: the integral I(t) = int_0^t sum_i b_i (A_i + B K_c^i) s dt. Its integrand depends only on
  the inputs, which are held over a communication step, so the block integrates it exactly for
  held inputs: I(t + h) = I(t) + h (A(omega) + B K_c(b)) s, all evaluated from the inputs.
* The command is saturated to u_max like the actuator (``plant.actuator.saturate``).

RAFTSMC, 000's third baseline (c), is the controller of 000 ref. [35] (Esmailzadeh et al. 2021);
000 lists its parameters but not its equations, and we do not have that paper. It is left out.

Kernels: ``outputs_at`` and ``advance`` run ``controller/kernels/attitude.py`` (``aismc_outputs``,
``aismc_integral``) when kernels are on; ``law`` and the numpy code of ``advance`` are the reference.

Inputs and outputs: controller/base.py.
"""
import numpy as np

from controller.kernels import attitude as _kernel
from plant.block import rule_tensor, scalar
from plant.flexible import N_MODES
from plant.ts_fuzzy import memberships

from .attitude import skew, sliding_terms
from .base import AttitudeController


class AISMC(AttitudeController):
    model_name = "AISMC"
    description = "Adaptive integral sliding-mode controller, baseline of 000 (70)-(71)"
    law_inputs = ("q", "omega", "q_d", "omega_d", "omega_d_dot")  # no estimates: lumped disturbance

    def __init__(self, n_modes: int = N_MODES):
        super().__init__(n_modes)
        self.integral = np.zeros(3)

    def law_parameters(self, n: int) -> list:
        return (
            rule_tensor("K_c", np.zeros((8, 3, 3)), "N.m.s", "gain K_c^i (000 A.2 stands in for ref. [21])")
            + scalar("beta", 1.0, "1/s", "sliding variable s = omega_e + beta q_ev")
            + scalar("sigma", 0.0, "N.m", "constant switching gain, 000 (70)")
            + scalar("sigma_p", 0.01, "rad/s", "smoothing width sigma', 000 (70)")
        )

    def initialize_law(self) -> None:
        self.Kc3 = self.p_tensor("K_c")  # (rules, 3, 3)
        self.Kc = self.Kc3.reshape(self.Kc3.shape[0], 9)
        self.beta = self.p("beta")
        self.sigma, self.sigma_p = self.p("sigma"), self.p("sigma_p")
        if not self.sigma_p > 0:
            raise ValueError("AISMC: sigma_p must be > 0")
        self.integral = np.zeros(3)
        self._prm = _kernel.params(_kernel.AISMC, beta=self.beta, omega_box=self.box, u_max=self.u_max,
                                   saturation_mode=self.sat_mode, sigma=self.sigma, sigma_p=self.sigma_p)
        self.Kc3 = np.ascontiguousarray(self.Kc3)

    def kernel_outputs(self, u: np.ndarray) -> np.ndarray:
        return _kernel.aismc_outputs(u, self.B, self.J, self.Jm, self.Kc3, self.integral, self._prm)

    def _terms(self, u: np.ndarray):
        sl = self._sl
        omega = u[sl["omega"]]
        qe0, qev, omega_e, s, g = sliding_terms(
            u[sl["q"]], omega, u[sl["q_d"]], u[sl["omega_d"]], u[sl["omega_d_dot"]], self.beta, self.B, self.J
        )
        return omega, qe0, qev, omega_e, s, g, memberships(omega, self.box)

    def law(self, u: np.ndarray) -> tuple:
        omega, qe0, qev, omega_e, s, g, b = self._terms(u)
        S = s - self.integral  # 000 (71)
        dm = float(np.sqrt(S @ S))
        ks = np.sqrt(((self.Kc3 @ s) ** 2).sum(axis=1))  # ||K_c^i s||_2, i = 1..8
        gain = float(b @ ks) + self.sigma + dm
        cmd = -(gain / (float(np.sqrt(s @ s)) + self.sigma_p)) * s - self.Jm @ g  # 000 (70)
        return cmd, qe0, qev, omega_e

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        if self._kernels:
            self.integral = _kernel.aismc_integral(np.asarray(u, dtype=float), h, self.B, self.J, self.Kc3,
                                                   self.integral, self._prm)
            return
        omega, _, _, _, s, _, b = self._terms(u)
        w = np.clip(omega, -self.box, self.box)
        A = -self.B @ skew(w) @ self.J  # sum_i b_i A_i
        Kcb = (b @ self.Kc).reshape(3, 3)
        self.integral = self.integral + h * ((A + self.B @ Kcb) @ s)  # 000 (71), exact for held inputs

    def get_state(self) -> list:
        return self.integral.tolist()

    def set_state(self, state) -> None:
        self.integral = np.array(state, dtype=float)
