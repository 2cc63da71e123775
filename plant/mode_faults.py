"""Mode-dependent actuator faults: u_f = F_r u + G_r v, driven by a mode signal r(t).

004 (9): u_f(t) = F_{r(t)} u(t) + G_{r(t)} v(t), with F_r = diag{f_r1..f_rn} (effectiveness,
0 <= f <= 1) and G_r = diag{g_r1..g_rn} (g in {0, 1}: which channels carry the bias fault v).
The mode comes from a mode source (``plant/markov.py``) as a Real holding 1.0, 2.0, ...

This block sits between a controller and a plant, so that the fault process is a component of
its own (swap the mode source, keep the plant): the plant applies what it receives. It also adds
an external disturbance torque d (its input; 0 if unconnected) to what it delivers, because in
004 (3) u + d enter the hub equation together and the FMI master connects one output to one
input (there is no summing junction): the plant's torque input receives tau = u_f + d.

Inputs:  u[1..3] commanded torque (N·m); mode (1, 1..N); d[1..3] external disturbance torque (N·m)
Outputs: tau[1..3] = u_f + d (N·m, to the plant); u_f[1..3] = F_r u + G_r v (N·m, 004 (9));
         fault[1..3] = u_f - u (N·m, the fault's additive equivalent)
Parameters: F[r,i] (1, default 1), G[r,i] (1, default 0), v[1..3] (N·m, bias fault, constant)
No state. A mode outside 1..N is an error naming the value.
"""
from __future__ import annotations

import numpy as np

from .block import StatelessBlock, Variable, vector


class ModeFaultActuator(StatelessBlock):
    model_name = "ModeFaultActuator"
    description = "Mode-dependent actuator faults u_f = F_r u + G_r v (004 (9)) plus external disturbance"

    def __init__(self, n_modes: int = 3, n_inputs: int = 3):
        N, m = self.N, self.m = int(n_modes), int(n_inputs)
        inputs = (vector("u", m, "N.m", "commanded torque") + [Variable("mode", "1", "fault mode r(t), 1..N", 1.0)]
                  + vector("d", m, "N.m", "external disturbance torque, added to the delivered torque"))
        outputs = (vector("tau", m, "N.m", "delivered torque u_f + d (to the plant)")
                   + vector("u_f", m, "N.m", "faulty actuator output F_r u + G_r v, 004 (9)")
                   + vector("fault", m, "N.m", "additive fault equivalent u_f - u"))
        params = ([Variable(f"F[{r + 1},{i + 1}]", "1", "effectiveness f_ri in mode r, 004 (9)", 1.0)
                   for r in range(N) for i in range(m)]
                  + [Variable(f"G[{r + 1},{i + 1}]", "1", "bias-fault input g_ri in mode r, 004 (9)", 0.0)
                     for r in range(N) for i in range(m)]
                  + vector("v", m, "N.m", "bias fault v (constant), 004 (9)"))
        feed = {}
        for i in range(m):
            feed[f"tau[{i + 1}]"] = [f"u[{i + 1}]", "mode", f"d[{i + 1}]"]
            feed[f"u_f[{i + 1}]"] = [f"u[{i + 1}]", "mode"]
            feed[f"fault[{i + 1}]"] = [f"u[{i + 1}]", "mode"]
        super().__init__(inputs, outputs, params, feed)
        self._u, self._d = slice(0, m), slice(m + 1, 2 * m + 1)

    def initialize(self, t0: float) -> None:
        F, G = self.p_array("F"), self.p_array("G")
        if np.any(F < 0) or np.any(F > 1):
            r, i = np.argwhere((F < 0) | (F > 1))[0]
            raise ValueError(f"{self.model_name}: F[{r + 1},{i + 1}] = {F[r, i]:g} outside [0, 1] "
                             "(004 (9): 0 <= f_r <= 1)")
        self.F, self.G, self.v = F, G, self.p_vector("v")
        self.Gv = G * self.v  # (N, m): G_r v for every mode

    def mode_index(self, x: float) -> int:
        r = int(round(x))
        if not 1 <= r <= self.N or abs(x - r) > 1e-9:
            raise ValueError(f"{self.model_name}: input mode = {x:g} is not one of the modes 1..{self.N}")
        return r - 1

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        r = self.mode_index(u[self.m])
        uc = u[self._u]
        uf = self.F[r] * uc + self.Gv[r]
        return np.concatenate((uf + u[self._d], uf, uf - uc))

