"""PD attitude controller with feed-forward compensation, 000 (69).

    u = -k_p q_ev - k_d omega_e - f_hat - B^+ D_2(omega) d2_hat - B^+ g(s),   s = omega_e + beta q_ev

with the attitude error of 000 (4)-(5) and g(s) of 000 (36); B^+ = B^-1 = J - delta^T delta.
D_2 is evaluated at omega clipped to the T-S operating box [-omega_box, omega_box]^3: the
fuzzy blend sum_i b_i D_2i of 000 (10) equals that, because D_2 is affine in omega and the
memberships interpolate linearly. beta (for s) is not given with (69): we use beta = 2 of
000 Appendix A.2. The command is saturated to u_max like the actuator.

``outputs_at`` runs ``controller/kernels/attitude.py: pd_outputs`` when kernels are on; ``law`` is
the reference. Inputs and outputs: controller/base.py.
"""
import numpy as np

from controller.kernels import attitude as _kernel
from plant.block import scalar

from .attitude import sliding_terms, vibration_torque
from .base import AttitudeController


class PDController(AttitudeController):
    model_name = "PDController"
    description = "PD attitude controller with feed-forward, 000 (69)"

    def law_parameters(self, n: int) -> list:
        return (
            scalar("k_p", 1.0, "N.m", "proportional gain")
            + scalar("k_d", 1.0, "N.m.s", "derivative gain")
            + scalar("beta", 1.0, "1/s", "sliding variable s = omega_e + beta q_ev")
        )

    def initialize_law(self) -> None:
        self.kp, self.kd, self.beta = self.p("k_p"), self.p("k_d"), self.p("beta")
        self._dK, self._dC, self._dT = self.delta.T @ self.K, self.delta.T @ self.C, self.delta.T
        self._dTc = np.ascontiguousarray(self._dT)
        self._prm = _kernel.params(_kernel.PD, beta=self.beta, omega_box=self.box, u_max=self.u_max,
                                   saturation_mode=self.sat_mode, k_p=self.kp, k_d=self.kd)

    def kernel_outputs(self, u: np.ndarray) -> np.ndarray:
        return _kernel.pd_outputs(u, self.B, self.J, self.Jm, self._dK, self._dC, self._dTc, self._prm)

    def law(self, u: np.ndarray) -> tuple:
        sl = self._sl
        omega = u[sl["omega"]]
        qe0, qev, omega_e, _, g = sliding_terms(
            u[sl["q"]], omega, u[sl["q_d"]], u[sl["omega_d"]], u[sl["omega_d_dot"]], self.beta, self.B, self.J
        )
        cmd = -self.kp * qev - self.kd * omega_e - u[sl["f_hat"]] - self.Jm @ g
        d2_hat = u[sl["d2_hat"]]
        if d2_hat.any():
            w_box = np.clip(omega, -self.box, self.box)
            cmd -= vibration_torque(w_box, d2_hat, self._dK, self._dC, self._dT)  # B^+ D_2 d2_hat
        return cmd, qe0, qev, omega_e
