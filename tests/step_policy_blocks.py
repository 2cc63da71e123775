"""Small blocks for the step-policy tests (tests/orchestrator/test_step_policies.py).

* :class:`IrregularSampler`: announces seeded irregular instants through ``t_next`` and changes
  its output ``y`` only there (a sample-and-hold of a seeded random sequence). It refuses a step
  that crosses an instant, and logs every ``advance`` as (t, h).
* :class:`HeldIntegrator`: z' = x with x held over each step (z advances by x h exactly, a
  rounding aside), logging (t, h, x): whoever feeds it a value late changes z by (late time) x.
"""
from __future__ import annotations

import numpy as np

from plant.block import Block, scalar
from plant.timing import StepWindow, happened_at


def irregular_instants(seed: int, t0: float, t1: float, mean: float) -> list[float]:
    """The instants of :class:`IrregularSampler` with this seed up to t1 (first after t0)."""
    rng = np.random.default_rng(seed)
    out, t = [], t0
    while True:
        t = t + float(rng.uniform(0.3, 1.7)) * mean
        out.append(t)
        if t > t1:
            return out


class IrregularSampler(Block):
    model_name = "IrregularSampler"
    description = "announces seeded irregular instants; output changes only there"
    announced_instants = ("t_next",)

    def __init__(self, seed: int = 7, mean: float = 0.0037, t1: float = 10.0):
        super().__init__([], scalar("y", 0.0) + scalar("t_next", 0.0, "s") + scalar("n", 0.0),
                         scalar("dummy", 0.0), {})
        self.seed, self.mean, self.t1 = seed, mean, t1
        self.log = []

    def initialize(self, t0):
        self.times = irregular_instants(self.seed, t0, self.t1 + 1.0, self.mean)
        self.values = np.random.default_rng(self.seed + 1).standard_normal(len(self.times) + 1)
        self.j = 0  # instants taken

    def outputs_at(self, t, u):
        return np.array([self.values[self.j], self.times[self.j], float(self.j)])

    def advance(self, t, h, u):
        self.log.append((t, h))
        if StepWindow(t, h).contains(self.times[self.j]):
            raise ValueError(f"instant {self.times[self.j]!r} lies inside the step ({t!r}, {t + h!r})")
        if happened_at(self.times[self.j], t + h):
            self.j += 1

    def get_state(self):
        return [float(self.j)]

    def set_state(self, state):
        self.j = int(state[0])


class HeldIntegrator(Block):
    model_name = "HeldIntegrator"
    description = "z' = x, x held over the step"

    def __init__(self):
        super().__init__(scalar("x", 0.0), scalar("z", 0.0), scalar("dummy", 0.0), {})
        self.log = []

    def initialize(self, t0):
        self.z = 0.0

    def outputs_at(self, t, u):
        return np.array([self.z])

    def advance(self, t, h, u):
        self.log.append((t, h, float(u[0])))
        self.z += float(u[0]) * h

    def get_state(self):
        return [self.z]

    def set_state(self, state):
        self.z = float(state[0])
