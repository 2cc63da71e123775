"""Small blocks for fast engine tests (no spacecraft, no FMU build): the master, the exchange plan,
the recorder and BlockSession can be tested on systems whose answers are known in closed form.

* :class:`Gain`: y = k u (direct feedthrough), no state;
* :class:`Integrator`: x' = u, y = x (no feedthrough), exact for held inputs;
* :class:`Clock`: no inputs, y = t (the time it is evaluated at).

Each counts how often its outputs were evaluated (``evaluations``).
"""
import numpy as np

from plant.block import Block, scalar, vector


class _Counting(Block):
    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.evaluations = 0

    def get_state(self):
        return list(self._state())

    def _state(self):
        return []


class Gain(_Counting):
    model_name = "MockGain"

    def __init__(self, n: int = 1, k: float = 2.0):
        super().__init__(vector("u", n), vector("y", n), scalar("k", k),
                         {f"y[{i}]": [f"u[{i}]"] for i in range(1, n + 1)})

    def initialize(self, t0):
        self.k = self.p("k")

    def outputs_at(self, t, u):
        self.evaluations += 1
        return self.k * np.asarray(u, float)

    def advance(self, t, h, u):
        pass

    def set_state(self, state):
        pass


class Integrator(_Counting):
    model_name = "MockIntegrator"

    def __init__(self, n: int = 1, x0: float = 0.0):
        super().__init__(vector("u", n), vector("y", n), vector("x0", n, start=[x0] * n), {})
        self.x = np.zeros(n)

    def initialize(self, t0):
        self.x = self.p_vector("x0").copy()

    def outputs_at(self, t, u):
        self.evaluations += 1
        return self.x.copy()

    def advance(self, t, h, u):
        self.x = self.x + h * np.asarray(u, float)

    def _state(self):
        return self.x.tolist()

    def set_state(self, state):
        self.x = np.array(state, float)


class Clock(_Counting):
    model_name = "MockClock"

    def __init__(self):
        super().__init__([], vector("y", 1), [], {})

    def initialize(self, t0):
        pass

    def outputs_at(self, t, u):
        self.evaluations += 1
        return np.array([t])

    def advance(self, t, h, u):
        pass

    def set_state(self, state):
        pass
