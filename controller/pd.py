"""PD attitude controller with feed-forward compensation, 000 (69).

    u = -k_p q_ev - k_d omega_e - f_hat - B^+ D_2(omega) d2_hat - B^+ g(s),   s = omega_e + beta q_ev

with the attitude error of 000 (4)-(5) and g(s) of 000 (36); B^+ = B^-1 = J - delta^T delta.
D_2 is evaluated at omega clipped to the T-S operating box [-omega_box, omega_box]^3: the
fuzzy blend sum_i b_i D_2i of 000 (10) equals that, because D_2 is affine in omega and the
memberships interpolate linearly. beta (for s) is not given with (69): we use beta = 2 of
000 Appendix A.2. The command is saturated to u_max like the actuator.

Inputs:  q[0..3], omega[1..3] (rad/s), q_d[0..3], omega_d[1..3] (rad/s),
         omega_d_dot[1..3] (rad/s²), f_hat[1..3] (N·m), d2_hat[1..2n] ([eta; eta_dot])
Outputs: u[1..3] (N·m), q_e[0..3] attitude error, omega_e[1..3] rate error (rad/s)
"""
import numpy as np

from plant.actuator import saturate
from plant.block import Block, matrix, scalar, vector
from plant.flexible import N_MODES, modal_matrices
from plant.parameters import LI2023

from .attitude import sliding_terms, vibration_torque


def spacecraft_parameters(n: int):
    """Parameters describing the spacecraft model the controller is built on."""
    return (
        matrix("J", LI2023["J"], "kg.m2", "hub inertia (model)")
        + matrix("delta", LI2023["delta"], "1", "coupling matrix (model)")
        + vector("omega_n", n, "rad/s", "modal natural frequency (model)", LI2023["omega_n"])
        + vector("zeta", n, "1", "modal damping ratio (model)", LI2023["zeta"])
    )


def attitude_inputs(n: int):
    return (
        vector("q", 4, "1", "measured attitude quaternion", [1, 0, 0, 0], first=0)
        + vector("omega", 3, "rad/s", "measured body rate")
        + vector("q_d", 4, "1", "desired attitude quaternion", [1, 0, 0, 0], first=0)
        + vector("omega_d", 3, "rad/s", "desired body rate")
        + vector("omega_d_dot", 3, "rad/s2", "desired angular acceleration")
        + vector("f_hat", 3, "N.m", "fault estimate (0 without estimator)")
        + vector("d2_hat", 2 * n, "1", "vibration state estimate [eta; eta_dot]")
    )


def attitude_outputs():
    """Outputs shared by the attitude controllers of 000: command, attitude and rate errors."""
    return (
        vector("u", 3, "N.m", "commanded control torque")
        + vector("q_e", 4, "1", "attitude error quaternion 000 (4)", first=0)
        + vector("omega_e", 3, "rad/s", "rate error 000 (5)")
    )


def input_slices(n: int) -> dict:
    """Name -> slice of each group of ``attitude_inputs(n)`` in the input vector."""
    sl, i = {}, 0
    for name, size in (("q", 4), ("omega", 3), ("q_d", 4), ("omega_d", 3), ("omega_d_dot", 3), ("f_hat", 3), ("d2_hat", 2 * n)):
        sl[name] = slice(i, i + size)
        i += size
    return sl


class PDController(Block):
    model_name = "PDController"
    description = "PD attitude controller with feed-forward, 000 (69)"

    def __init__(self, n_modes: int = N_MODES):
        n = self.n = n_modes
        inputs = attitude_inputs(n)
        outputs = attitude_outputs()
        params = spacecraft_parameters(n) + (
            scalar("k_p", 20.0, "N.m", "proportional gain")
            + scalar("k_d", 60.0, "N.m.s", "derivative gain")
            + scalar("beta", 2.0, "1/s", "sliding variable s = omega_e + beta q_ev")
            + scalar("u_max", 5.0, "N.m", "saturation level of the command")
            + scalar("saturation_mode", 0, "1", "0: per axis, 1: 1-norm")
            + scalar("omega_box", 0.7, "rad/s", "T-S operating box half-width")
        )
        all_in = [v.name for v in inputs]
        err_in = [v.name for v in inputs if v.name.split("[")[0] in ("q", "omega", "q_d", "omega_d")]
        feed = {v.name: all_in for v in outputs[:3]}
        feed.update({v.name: err_in for v in outputs[3:]})
        super().__init__(inputs, outputs, params, feed)

    def initialize(self, t0: float) -> None:
        self.J = self.p_matrix("J")
        self.delta = self.p_matrix("delta")
        self.C, self.K = modal_matrices(self.p_vector("omega_n"), self.p_vector("zeta"))
        self.Jm = self.J - self.delta.T @ self.delta
        self.B = np.linalg.inv(self.Jm)
        self.kp, self.kd, self.beta = self.p("k_p"), self.p("k_d"), self.p("beta")
        self.u_max = self.p("u_max")
        self.sat_mode = int(round(self.p("saturation_mode")))
        self.box = self.p("omega_box")
        self._dK, self._dC, self._dT = self.delta.T @ self.K, self.delta.T @ self.C, self.delta.T
        self._sl = input_slices(self.n)

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
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
        cmd = saturate(cmd, self.u_max, self.sat_mode)
        return np.concatenate((cmd, [qe0], qev, omega_e))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        pass  # static law, no state

    def get_state(self) -> list:
        return []

    def set_state(self, state) -> None:
        pass
