"""Multisine signal source: y_i(t) = s (c_i + sum_k a_ik cos(w_ik t) + b_ik sin(w_ik t)).

Used for disturbance torques given as a bias plus sinusoids (004 section 4 d(t)). A pure
function of time (no state): the value at the communication point is what the connected block
holds over the next step (zero-order hold by the master).

Inputs:  none
Outputs: y[1..n] (N·m)
Parameters: bias[i] (N·m), a_cos[i,k], a_sin[i,k] (N·m), freq[i,k] (rad/s), scale (1)
"""
from __future__ import annotations

import numpy as np

from .block import StatelessBlock, Variable, scalar, vector


def multisine(t, bias, a_cos, a_sin, freq, scale=1.0) -> np.ndarray:
    """The signal at time(s) t: shape (n,) for a scalar t, (len(t), n) for an array."""
    t = np.asarray(t, dtype=float)
    wt = np.multiply.outer(t, freq)  # (..., n, K)
    y = bias + (a_cos * np.cos(wt) + a_sin * np.sin(wt)).sum(axis=-1)
    return scale * y


def multisine_energy(t0, t1, bias, a_cos, a_sin, freq, scale=1.0) -> float:
    """int_{t0}^{t1} ||y||^2 dt (N^2 m^2 s), by adaptive quadrature."""
    from scipy.integrate import quad

    f = lambda t: float(np.sum(multisine(t, bias, a_cos, a_sin, freq, scale) ** 2))  # noqa: E731
    return float(quad(f, t0, t1, limit=500, epsabs=1e-12, epsrel=1e-12)[0])


class MultisineSource(StatelessBlock):
    model_name = "MultisineSource"
    description = "Bias plus sinusoids per output (disturbance torque source)"

    def __init__(self, n_outputs: int = 3, n_terms: int = 2):
        n, K = self.n, self.K = int(n_outputs), int(n_terms)

        def mat(base, unit, desc):
            return [Variable(f"{base}[{i + 1},{k + 1}]", unit, desc) for i in range(n) for k in range(K)]

        params = (vector("bias", n, "N.m", "constant part c_i")
                  + mat("a_cos", "N.m", "amplitude of cos(w_ik t)") + mat("a_sin", "N.m", "amplitude of sin(w_ik t)")
                  + mat("freq", "rad/s", "angular frequency w_ik") + scalar("scale", 1.0, "1", "overall scale s"))
        super().__init__([], vector("y", n, "N.m", "signal value"), params, {})

    def initialize(self, t0: float) -> None:
        self.args = (self.p_vector("bias"), self.p_array("a_cos").reshape(self.n, self.K),
                     self.p_array("a_sin").reshape(self.n, self.K), self.p_array("freq").reshape(self.n, self.K),
                     self.p("scale"))

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        return multisine(t, *self.args)

    def energy(self, t0: float, t1: float) -> float:
        return multisine_energy(t0, t1, *self.args)

