"""A PD attitude controller that can fail on purpose (tests of issue 20 items 3 and 4): the law of
docs/examples/pd_block.py (u = sat(-k_p q_ev - k_d omega - f_hat), 000 (4) for q_e), and

* ``raise_at`` (s): its step raises from that time on (a controller that crashes part way);
* ``hang_at`` (s): its step sleeps for an hour from that time on (a component that hangs), after
  touching the file named by ``$FTCSIM_TEST_HANG_MARKER`` (so a test knows it hangs).

Built into an FMU by tests/orchestrator/test_time_and_failures.py."""
import os
import time

import numpy as np

from plant.block import Block, scalar, vector


class FaultyPD(Block):
    model_name = "FaultyPD"
    description = "PD attitude law that raises or hangs at a given time (tests)"

    def __init__(self):
        q = vector("q", 4, "1", "attitude", [1, 0, 0, 0], first=0)
        q_d = vector("q_d", 4, "1", "desired attitude", [1, 0, 0, 0], first=0)
        inputs = q + vector("omega", 3, "rad/s", "body rate") + q_d + vector("f_hat", 3, "N.m", "fault estimate")
        outputs = (vector("u", 3, "N.m", "torque command") + vector("q_e", 4, "1", "attitude error", first=0)
                   + vector("omega_e", 3, "rad/s", "rate error"))
        params = (scalar("k_p", 20.0, "N.m", "proportional gain") + scalar("k_d", 60.0, "N.m.s", "rate gain")
                  + scalar("u_max", 5.0, "N.m", "saturation")
                  + scalar("raise_at", 1e9, "s", "time from which a step raises")
                  + scalar("hang_at", 1e9, "s", "time from which a step hangs"))
        att = [v.name for v in q + q_d]
        feed = {f"q_e[{i}]": att for i in range(4)}
        for i in (1, 2, 3):
            feed[f"u[{i}]"], feed[f"omega_e[{i}]"] = att + [f"omega[{i}]", f"f_hat[{i}]"], [f"omega[{i}]"]
        super().__init__(inputs, outputs, params, feed)

    def initialize(self, t0):
        self.kp, self.kd, self.u_max = self.p("k_p"), self.p("k_d"), self.p("u_max")
        self.raise_at, self.hang_at = self.p("raise_at"), self.p("hang_at")

    def outputs_at(self, t, u):
        q, omega, q_d, f_hat = u[0:4], u[4:7], u[7:11], u[11:14]
        q_ev = q_d[0] * q[1:] - np.cross(q_d[1:], q[1:]) - q[0] * q_d[1:]  # 000 (4)
        cmd = np.clip(-self.kp * q_ev - self.kd * omega - f_hat, -self.u_max, self.u_max)
        return np.concatenate((cmd, [q_d @ q], q_ev, omega))

    def advance(self, t, h, u):
        if t >= self.raise_at - 1e-9:
            raise RuntimeError(f"controller crashed at t = {t:g} s")
        if t >= self.hang_at - 1e-9:
            marker = os.environ.get("FTCSIM_TEST_HANG_MARKER")
            if marker:
                open(marker, "w").close()
            time.sleep(3600)

    def get_state(self):
        return []

    def set_state(self, state):
        pass
