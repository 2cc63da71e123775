"""Fuzzy adaptive sliding-mode fault-tolerant controller (FASMC), 000 (39)-(40) with (64).

    s     = omega_e + beta q_ev                                                    000 (39)
    u     = u_eq + u_vs                                                            000 (40)
    u_eq  = sum_i b_i {v - f_hat - Gamma^+ B^- D_2i d2_hat - Gamma^+ B^- g(s)}
    v     = sum_j b_j K_c^j s,     ||v||_2 <= varsigma
    u_vs  = -Gamma^+ sigma_1 s - Gamma^+ sigma_2 s / (||s||_2 + sigma_2')         000 (64)

with the attitude error of 000 (4)-(5), g(s) of 000 (36), B^- = B^-1 = J - delta^T delta and
Gamma = I (000 section 5), so Gamma^+ = I. Gains K_c^i, beta, sigma_1, sigma_2, sigma_2',
varsigma are parameters; 000 Appendix A.2's values come from papers/p000_li2023/gains.py.

Readings chosen:
* Premise variables: b_i uses the measured omega (the T-S model (37) shares the rules of (10)).
  sum_i b_i D_2i is blended from the rule matrices of plant/ts_fuzzy.py; it equals D_2(clip(omega))
  of the PD law (controller/pd.py) exactly (D_2 affine in omega, multilinear memberships).
* Saturated virtual control: Theorem 2 guarantees ||v||_2 < varsigma only for ||s(0)||_2 < mu
  (43); 000 section 5.3 says the virtual controller is saturated. We scale v onto the 2-norm
  ball of radius varsigma when it leaves it (direction kept).
* The command is saturated to u_max like the actuator (``plant.actuator.saturate``; per axis by
  default, ``saturation_mode`` = 1 for the 1-norm of 000 section 5.3), so the estimator receives
  exactly the torque the actuator is asked for.

The law is static (no state). ``outputs_at`` runs ``controller/kernels/attitude.py: fasmc_outputs``
when kernels are on; ``law`` is the reference. Inputs and outputs are those of controller/pd.py.
"""
import numpy as np

from controller.kernels import attitude as _kernel
from plant.block import rule_tensor, scalar
from plant.ts_fuzzy import fuzzy_model, memberships

from .attitude import sliding_terms
from .base import AttitudeController


class FASMC(AttitudeController):
    model_name = "FASMC"
    description = "Fuzzy adaptive sliding-mode FTC, 000 (39)-(40) with the smoothed switching term (64)"

    def law_parameters(self, n: int) -> list:
        return (
            rule_tensor("K_c", np.zeros((8, 3, 3)), "N.m.s", "virtual-control gain K_c^i, 000 (40)")
            + scalar("beta", 1.0, "1/s", "sliding variable s = omega_e + beta q_ev, 000 (39)")
            + scalar("sigma_1", 0.0, "N.m.s", "linear switching gain, 000 (64)")
            + scalar("sigma_2", 0.0, "N.m", "smoothed switching gain, 000 (64)")
            + scalar("sigma_2p", 1e-4, "rad/s", "smoothing width sigma_2', 000 (64)")
            + scalar("varsigma", 1.0, "N.m", "bound on ||v||_2, 000 (44)")
        )

    def initialize_law(self) -> None:
        fm = fuzzy_model(self.J, self.delta, self.p_vector("omega_n"), self.p_vector("zeta"), self.box)
        # per rule: [K_c^i, Gamma^+ B^- D_2i] flattened, blended with one product per call
        self._rules = np.hstack(
            [self.p_tensor("K_c").reshape(fm.n_rules, 9), np.einsum("ab,rbc->rac", self.Jm, fm.D2).reshape(fm.n_rules, -1)]
        )
        self.beta = self.p("beta")
        self.sigma_1, self.sigma_2, self.sigma_2p = self.p("sigma_1"), self.p("sigma_2"), self.p("sigma_2p")
        self.varsigma = self.p("varsigma")
        if not (self.sigma_2p > 0 and self.varsigma > 0):
            raise ValueError("FASMC: sigma_2p and varsigma must be > 0")
        self._prm = _kernel.params(_kernel.FASMC, beta=self.beta, omega_box=self.box, u_max=self.u_max,
                                   saturation_mode=self.sat_mode, sigma_1=self.sigma_1, sigma_2=self.sigma_2,
                                   sigma_2p=self.sigma_2p, varsigma=self.varsigma)

    def kernel_outputs(self, u: np.ndarray) -> np.ndarray:
        return _kernel.fasmc_outputs(u, self.B, self.J, self.Jm, self._rules, self._prm)

    def law(self, u: np.ndarray):
        """(command before saturation, q_e0, q_ev, omega_e, s, v) from the input vector."""
        sl = self._sl
        omega = u[sl["omega"]]
        qe0, qev, omega_e, s, g = sliding_terms(
            u[sl["q"]], omega, u[sl["q_d"]], u[sl["omega_d"]], u[sl["omega_d_dot"]], self.beta, self.B, self.J
        )
        blend = memberships(omega, self.box) @ self._rules
        v = blend[0:9].reshape(3, 3) @ s  # 000 (40): v = sum_j b_j K_c^j s
        nv = float(np.sqrt(v @ v))
        if nv > self.varsigma:  # saturated virtual controller, ||v||_2 <= varsigma
            v = v * (self.varsigma / nv)
        JmD2 = blend[9:].reshape(3, -1)  # sum_i b_i Gamma^+ B^- D_2i
        ns = float(np.sqrt(s @ s))
        cmd = (
            v
            - u[sl["f_hat"]]
            - JmD2 @ u[sl["d2_hat"]]  # 000 (40)
            - self.Jm @ g  # 000 (40): Gamma^+ B^- g(s)
            - self.sigma_1 * s
            - (self.sigma_2 / (ns + self.sigma_2p)) * s  # 000 (64)
        )
        return cmd, qe0, qev, omega_e, s, v

