"""Zero-order hold at a controller's sample rate: the command a flight computer sends at t_k = t0 + k T
is held until t_k+1 (issue 26 item 4: "a controller sample rate").

Placed between a controller and the actuators, it samples the command at the sample instants and
holds it: for the static laws of 000 (PD, FASMC) this is exactly the sampled-data controller; for
a controller with state (AISMC's integral, FONTSM's fractional memory, the observers) the state
still evolves at the communication rate, only the command is sampled (the scenario can give the
controller instance its own ``step`` in a multirate run as well).

Timing as the sensors' (``plant/hardware/sensors.py``): at a communication point that is a sample
instant the output is the input there (direct feedthrough); between instants the held value; an
instant strictly inside a communication step takes the input held over the step; the output
``t_next_sample`` announces the next instant.

Inputs:  u[1..n] N.m (``u`` for n = 1)
Outputs: y[1..n] N.m (held command), t_next_sample s
Parameters: sample_period (s)
State:   the sample count and the held command.
"""
from __future__ import annotations

import numpy as np

from ..block import Block, scalar
from ..channels import channels
from .sampling import SampleClock

__all__ = ["ZeroOrderHold"]


class ZeroOrderHold(Block):
    model_name = "ZeroOrderHold"
    description = "Zero-order hold of a command at a controller sample rate"
    announced_instants = ("t_next_sample",)

    def __init__(self, n_channels: int = 3):
        n = self.n = int(n_channels)
        if n < 1:
            raise ValueError(f"n_channels must be >= 1, got {n_channels}")
        inputs = channels("u", n, "N.m", "command computed by the controller")
        outputs = channels("y", n, "N.m", "command held since the last sample instant") + \
            scalar("t_next_sample", 0.0, "s", "announced instant: next sample")
        names = [v.name for v in inputs]
        super().__init__(inputs, outputs, scalar("sample_period", 0.1, "s", "controller sample period T"),
                         {v.name: [names[i]] for i, v in enumerate(outputs[:n])})
        self.clock = None
        self.held = np.zeros(n)

    def initialize(self, t0: float) -> None:
        self.clock = SampleClock(t0, self.p("sample_period"), self.model_name)
        self.held = self.default_inputs()[: self.n].astype(float)

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        c = self.clock
        if c.due(t):
            return np.concatenate((np.asarray(u[: self.n], dtype=float), (c.t0 + (c.k + 1) * c.T,)))
        return np.concatenate((self.held, (c.t_next,)))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        c = self.clock
        while c.due(t) or c.inside(t, h):
            self.held = np.array(u[: self.n], dtype=float)
            c.k += 1

    def get_state(self) -> list:
        return [float(self.clock.k)] + self.held.tolist()

    def set_state(self, state) -> None:
        self.clock.k = int(state[0])
        self.held = np.array(state[1:], dtype=float)
