"""State feedback with a bank of gains, one per design case: u = K_c [theta - theta_d, theta' - theta_d'].

002 (9): u(t) = K x(t), x = [theta, theta'], with K = W V1^-1 from 002 Theorem 2 for a design
effectiveness omega_hat (002 Table 2 gives one K per omega_hat = 1, 0.5, 0.2). The block holds up to
``n_cases`` gains K[c, 1..2] with their design effectiveness ``case_omega_hat[c]`` and applies the one
whose ``case_omega_hat`` equals the parameter ``omega_hat``. So one design file (``ftcsim design
zhang2014-hinf --out FILE``, every case's K and omega_hat) overrides every case at once, and each
scenario picks its case by ``omega_hat``. A slot with ``case_omega_hat = 0`` is empty.

Regulation (002): theta_d = theta_d' = 0 (the default inputs); with a reference the law acts on the
errors e = theta - theta_d, e' = theta' - theta_d' (for a constant theta_d that is 002 (9) on the
shifted state: the plant (8) is a double integrator).

Inputs:  theta (rad), theta_dot (rad/s), theta_d (rad), theta_d_dot (rad/s)
Outputs: u (N.m) = K_c [e, e'] (no saturation, 002 has none), e_theta (rad), e_theta_dot (rad/s)
The law is static: no state.
"""
from __future__ import annotations

import numpy as np

from plant.block import StatelessBlock, Variable, scalar
from plant.pitch_axis import pitch_inputs

MATCH_TOL = 1e-9


class ScheduledStateFeedback(StatelessBlock):
    model_name = "ScheduledStateFeedback"
    description = "State feedback u = K x with one gain per design effectiveness, 002 (9)"

    def __init__(self, n_cases: int = 3):
        self.n_cases = int(n_cases)
        if self.n_cases < 1:
            raise ValueError(f"{self.model_name}: n_cases must be >= 1, got {n_cases}")
        inputs = pitch_inputs()
        outputs = (
            scalar("u", 0.0, "N.m", "commanded control torque K_c [e, e']")
            + scalar("e_theta", 0.0, "rad", "angle error theta - theta_d")
            + scalar("e_theta_dot", 0.0, "rad/s", "rate error theta' - theta_d'")
        )
        params = []
        for c in range(1, self.n_cases + 1):
            params += [Variable(f"K[{c},1]", "N.m", f"gain on the angle error, case {c}"),
                       Variable(f"K[{c},2]", "N.m.s", f"gain on the rate error, case {c}")]
        params += [Variable(f"case_omega_hat[{c}]", "1", f"design effectiveness of case {c} (0: empty slot)")
                   for c in range(1, self.n_cases + 1)]
        params += scalar("omega_hat", 1.0, "1", "design effectiveness of the case to apply")
        ins = [v.name for v in inputs]
        feed = {"u": ins, "e_theta": ("theta", "theta_d"), "e_theta_dot": ("theta_dot", "theta_d_dot")}
        super().__init__(inputs, outputs, params, feed)
        self.K = np.zeros(2)

    def cases(self) -> dict:
        """{design effectiveness: (K1, K2)} of the non-empty slots."""
        K = self.p_matrix("K")
        return {float(w): tuple(K[c]) for c, w in enumerate(self.p_vector("case_omega_hat")) if w != 0.0}

    def initialize(self, t0: float) -> None:
        name = self.model_name
        w = self.p_vector("case_omega_hat")
        K = self.p_matrix("K")
        used = [c for c in range(self.n_cases) if w[c] != 0.0]
        if not used:
            raise ValueError(f"{name}: no gain case defined (every case_omega_hat is 0)")
        for c in used:
            if not 0.0 < w[c] <= 1.0:
                raise ValueError(f"{name}: case_omega_hat[{c + 1}] = {w[c]:g} must be in (0, 1] (or 0 for an empty slot)")
        sel = self.p("omega_hat")
        hits = [c for c in used if abs(w[c] - sel) <= MATCH_TOL]
        if len(hits) != 1:
            have = ", ".join(f"{w[c]:g}" for c in used)
            problem = "no gain" if not hits else f"{len(hits)} gains"
            raise ValueError(f"{name}: {problem} for omega_hat = {sel:g} (cases defined: {have})")
        self.case = hits[0]
        self.K = K[self.case].copy()

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        e, ed = u[0] - u[2], u[1] - u[3]
        return np.array([self.K[0] * e + self.K[1] * ed, e, ed])  # 002 (9)

