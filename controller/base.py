"""What the attitude controllers of paper 000 share: interface, spacecraft model, saturation.

Inputs:  q[0..3], omega[1..3] (rad/s), q_d[0..3], omega_d[1..3] (rad/s),
         omega_d_dot[1..3] (rad/s²), f_hat[1..3] (N·m), d2_hat[1..2n] ([eta; eta_dot])
Outputs: u[1..3] (N·m), q_e[0..3] attitude error 000 (4), omega_e[1..3] rate error 000 (5)
Parameters (every controller): the spacecraft model J, delta, omega_n, zeta (placeholder
values; ``papers/p000_li2023/blocks.py`` sets 000's), u_max, saturation_mode, omega_box, plus the law's own (``law_parameters``).
"""
import numpy as np

from plant import kernels
from plant.actuator import saturate
from plant.block import StatelessBlock, matrix, scalar, vector
from plant.flexible import N_MODES, modal_matrices, placeholder_model

ERROR_INPUTS = ("q", "omega", "q_d", "omega_d")


def spacecraft_parameters(n: int):
    """Parameters describing the spacecraft model the controller is built on (placeholder
    values; a paper's factory sets its own through ``set_defaults``)."""
    model = placeholder_model(n)
    return (
        matrix("J", model["J"], "kg.m2", "hub inertia (model)")
        + matrix("delta", model["delta"], "1", "coupling matrix (model)")
        + vector("omega_n", n, "rad/s", "modal natural frequency (model)", model["omega_n"])
        + vector("zeta", n, "1", "modal damping ratio (model)", model["zeta"])
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


class AttitudeController(StatelessBlock):
    """Base of PD, FASMC and AISMC. Subclasses give ``law_parameters(n)``, ``law_inputs``
    (input groups the command depends on directly) and ``initialize_law()``."""

    law_inputs = ("q", "omega", "q_d", "omega_d", "omega_d_dot", "f_hat", "d2_hat")

    def __init__(self, n_modes: int = N_MODES):
        n = self.n = n_modes
        inputs = attitude_inputs(n)
        outputs = attitude_outputs()
        params = spacecraft_parameters(n) + self.law_parameters(n) + (
            scalar("u_max", 5.0, "N.m", "saturation level of the command")
            + scalar("saturation_mode", 0, "1", "0: per axis, 1: 1-norm")
            + scalar("omega_box", 1.0, "rad/s", "T-S operating box half-width")
        )
        law_in = [v.name for v in inputs if v.name.split("[")[0] in self.law_inputs]
        err_in = [v.name for v in inputs if v.name.split("[")[0] in ERROR_INPUTS]
        feed = {v.name: law_in for v in outputs[:3]}
        feed.update({v.name: err_in for v in outputs[3:]})
        super().__init__(inputs, outputs, params, feed)

    def law_parameters(self, n: int) -> list:  # pragma: no cover - abstract
        raise NotImplementedError

    def initialize(self, t0: float) -> None:
        self.J = self.p_matrix("J")
        self.delta = self.p_matrix("delta")
        self.C, self.K = modal_matrices(self.p_vector("omega_n"), self.p_vector("zeta"))
        self.Jm = self.J - self.delta.T @ self.delta  # B^+ = B^- = B^-1, 000 (40), (69)
        self.B = np.linalg.inv(self.Jm)
        self.u_max = self.p("u_max")
        self.sat_mode = int(round(self.p("saturation_mode")))
        self.box = self.p("omega_box")
        self._sl = input_slices(self.n)
        self.initialize_law()
        # the law's compiled kernel (controller/kernels/attitude.py), if it has one and kernels are on
        self._kernels = kernels.enabled() and type(self).kernel_outputs is not AttitudeController.kernel_outputs

    def initialize_law(self) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def saturate(self, cmd: np.ndarray) -> np.ndarray:
        """The command saturated like the actuator (plant/actuator.py)."""
        return saturate(cmd, self.u_max, self.sat_mode)

    def law(self, u: np.ndarray) -> tuple:  # pragma: no cover - abstract
        """(command before saturation, q_e0, q_ev, omega_e, ...) from the input vector."""
        raise NotImplementedError

    def kernel_outputs(self, u: np.ndarray) -> np.ndarray:  # pragma: no cover - optional
        """[sat(u), q_e0, q_ev, omega_e] from the law's compiled kernel (same as the reference)."""
        raise NotImplementedError

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        if self._kernels:
            return self.kernel_outputs(np.asarray(u, dtype=float))
        cmd, qe0, qev, omega_e = self.law(u)[:4]
        return np.concatenate((self.saturate(cmd), [qe0], qev, omega_e))

