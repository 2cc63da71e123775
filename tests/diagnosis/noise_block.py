"""A fault-free residual for the calibration tests: a seeded first-order autoregressive noise in N.m
on three channels, y_k+1 = phi y_k + sigma sqrt(1 - phi^2) w_k (stationary, standard deviation
sigma), one value per communication step. Registered in-process by the tests only."""
import math

import numpy as np

from plant.block import Block, scalar, vector
from plant.hardware.sampling import NormalStream


class NoiseTorque(Block):
    model_name = "NoiseTorque3"
    description = "seeded AR(1) noise torque (tests)"

    def __init__(self):
        super().__init__([], vector("y", 3, "N.m", "noise"),
                         scalar("sigma", 0.01, "N.m", "standard deviation") + scalar("phi", 0.5, "1", "AR coefficient")
                         + scalar("seed", 0, "1", "seed"), {})

    def initialize(self, t0):
        self.stream = NormalStream(int(self.p("seed")))
        self.s, self.phi = self.p("sigma"), self.p("phi")
        self.y = self.s * self.stream.draw(3)

    def outputs_at(self, t, u):
        return self.y.copy()

    def advance(self, t, h, u):
        self.y = self.phi * self.y + self.s * math.sqrt(1 - self.phi ** 2) * self.stream.draw(3)

    def get_state(self):
        return self.y.tolist() + self.stream.get_state()

    def set_state(self, s):
        self.y = np.array(s[:3])
        self.stream.set_state(s[3:])


def noise_torque_3():
    return NoiseTorque()
