"""A PD attitude controller written from scratch against the block contract (docs/own-controller.md).

u = sat(-k_p q_ev - k_d omega - f_hat), |u_i| <= u_max; q_e = q_d^-1 (x) q as in 000 (4); omega_e = omega
(the desired rate is zero). Interface of paper 000's controllers, without omega_d and d2_hat."""
import numpy as np

from plant.block import Block, scalar, vector


class MinimalPD(Block):
    model_name = "MinimalPD"
    description = "PD attitude law with fault-estimate feed-forward, written from scratch"

    def __init__(self):
        q = vector("q", 4, "1", "attitude", [1, 0, 0, 0], first=0)
        q_d = vector("q_d", 4, "1", "desired attitude", [1, 0, 0, 0], first=0)
        inputs = q + vector("omega", 3, "rad/s", "body rate") + q_d + vector("f_hat", 3, "N.m", "fault estimate")
        outputs = (vector("u", 3, "N.m", "torque command") + vector("q_e", 4, "1", "attitude error", first=0)
                   + vector("omega_e", 3, "rad/s", "rate error"))
        params = (scalar("k_p", 20.0, "N.m", "proportional gain") + scalar("k_d", 60.0, "N.m.s", "rate gain")
                  + scalar("u_max", 5.0, "N.m", "saturation"))
        att = [v.name for v in q + q_d]  # exact dependences: u_i on q, q_d, omega_i, f_hat_i; q_e on q, q_d; omega_e_i on omega_i
        feed = {f"q_e[{i}]": att for i in range(4)}
        for i in (1, 2, 3):
            feed[f"u[{i}]"], feed[f"omega_e[{i}]"] = att + [f"omega[{i}]", f"f_hat[{i}]"], [f"omega[{i}]"]
        super().__init__(inputs, outputs, params, feed)

    def initialize(self, t0):
        self.kp, self.kd, self.u_max = self.p("k_p"), self.p("k_d"), self.p("u_max")
        if not self.u_max > 0:
            raise ValueError(f"u_max = {self.u_max:g} N.m must be > 0")

    def outputs_at(self, t, u):
        q, omega, q_d, f_hat = u[0:4], u[4:7], u[7:11], u[11:14]
        q_ev = q_d[0] * q[1:] - np.cross(q_d[1:], q[1:]) - q[0] * q_d[1:]  # 000 (4)
        cmd = np.clip(-self.kp * q_ev - self.kd * omega - f_hat, -self.u_max, self.u_max)
        return np.concatenate((cmd, [q_d @ q], q_ev, omega))

    def advance(self, t, h, u):  # a static law: no state
        pass

    def get_state(self):
        return []

    def set_state(self, state):
        pass
