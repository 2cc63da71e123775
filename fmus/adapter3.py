"""One generic adapter from a block (plant/block.py) to a pythonfmu3 FMI 3.0 slave.

The FMI 3.0 twin of ``fmus/adapter.py`` (kept separate because an FMI 3 FMU embeds
``pythonfmu3`` and must not import ``pythonfmu``). Same behaviour, so that an FMI 3 run
gives the same numbers as the FMI 2 run:

* value references: 0 is ``time`` (the independent variable FMI 3 requires), then the
  inputs (from 1), the outputs, the parameters, each in the block's declared order;
* every variable is a scalar ``Float64`` (pythonfmu3's array variables break with
  numpy >= 2.4, and scalars keep the structured names ``q[0]``, ``J[1,2]`` of FMI 2);
* parameters are ``fixed``/``exact``: read when the FMU leaves initialisation mode (or
  at the first output read during initialisation); outputs are recomputed lazily after
  an input change or a step; the FMU state holds inputs, parameters, time and the
  block's internal state as JSON-safe floats, so rollback is exact.
"""
import sys

import numpy as np
from pythonfmu3 import Fmi3Causality, Fmi3Initial, Fmi3Slave, Fmi3Variability, Float64

# The native part of pythonfmu3 shares pythonfmu 0.7's findClass() reference handling
# (see fmus/adapter.py): hold one reference to the slave module's dict when the class is
# defined and one per instance, so that repeated instantiation in one process is safe.
_MODULE_DICT_REFS = []


def _hold_module_dict(cls) -> None:
    module = sys.modules.get(cls.__module__)
    if module is not None:
        _MODULE_DICT_REFS.append(module.__dict__)


class BlockSlave3(Fmi3Slave):
    """Subclasses set ``block_factory`` to a callable returning a fresh block."""

    block_factory = None
    author = "ftcsim"

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        _hold_module_dict(cls)

    def __init__(self, **kwargs):
        _hold_module_dict(type(self))
        super().__init__(**kwargs)
        block = self.block = type(self).block_factory()
        self.modelName = block.model_name
        self.description = block.description
        self._u = block.default_inputs()
        self._y = np.zeros(len(block.outputs))
        self._t = 0.0
        self._t0 = 0.0
        self._dirty = True
        self._stale_params = True
        self._running = False
        self._n_in = len(block.inputs)
        self._n_out = len(block.outputs)
        self.time = 0.0
        self.register_variable(
            Float64("time", causality=Fmi3Causality.independent, variability=Fmi3Variability.continuous,
                    description="simulation time", getter=lambda: self._t)
        )
        for i, v in enumerate(block.inputs):
            self.register_variable(
                Float64(
                    v.name,
                    causality=Fmi3Causality.input,
                    variability=Fmi3Variability.continuous,
                    description=v.description,
                    getter=lambda i=i: float(self._u[i]),
                    setter=lambda x, i=i: self._set_input(i, x),
                )
            )
        for i, v in enumerate(block.outputs):
            self.register_variable(
                Float64(
                    v.name,
                    causality=Fmi3Causality.output,
                    variability=Fmi3Variability.continuous,
                    description=v.description,
                    getter=lambda i=i: float(self._outputs()[i]),
                )
            )
        for i, v in enumerate(block.parameters):
            self.register_variable(
                Float64(
                    v.name,
                    causality=Fmi3Causality.parameter,
                    variability=Fmi3Variability.fixed,
                    initial=Fmi3Initial.exact,
                    description=v.description,
                    getter=lambda i=i: float(self.block.param_values[i]),
                    setter=lambda x, name=v.name: self._set_parameter(name, x),
                )
            )

    # -- variable access ---------------------------------------------------------------
    def _set_input(self, i, x):
        self._u[i] = x
        self._dirty = True

    def _set_parameter(self, name, x):
        if self._running:
            raise RuntimeError(f"parameter {name} is fixed after initialisation")
        self.block.set_parameter(name, x)
        self._stale_params = True
        self._dirty = True

    def _ensure_initialized(self):
        if self._stale_params:
            self.block.initialize(self._t0)
            self._stale_params = False
            self._dirty = True

    def _outputs(self):
        if self._dirty:
            self._ensure_initialized()
            self._y = self.block.outputs_at(self._t, self._u)
            self._dirty = False
        return self._y

    def get_float64(self, vrs):
        lo = 1 + self._n_in
        hi = lo + self._n_out
        y = self._outputs() if any(lo <= vr < hi for vr in vrs) else None
        out = []
        for vr in vrs:
            if lo <= vr < hi:
                out.append(float(y[vr - lo]))
            elif vr == 0:
                out.append(float(self._t))
            else:
                out.append(float(self.vars[vr].getter()))
        return out

    def set_float64(self, vrs, values):
        n_in = self._n_in
        for vr, x in zip(vrs, values):
            if 1 <= vr <= n_in:
                self._u[vr - 1] = x
            else:
                self.vars[vr].setter(x)
        self._dirty = True

    # -- life cycle ----------------------------------------------------------------------
    def setup_experiment(self, start_time):
        self._t0 = self._t = float(start_time)

    def exit_initialization_mode(self):
        self._ensure_initialized()
        self._running = True

    def do_step(self, current_time, step_size):
        self._ensure_initialized()
        self.block.advance(current_time, step_size, self._u)
        self._t = current_time + step_size
        self._dirty = True
        return True

    # -- state ------------------------------------------------------------------------------
    def _get_fmu_state(self):
        return {
            "t": self._t,
            "u": self._u.tolist(),
            "p": self.block.param_values.tolist(),
            "x": self.block.get_state(),
        }

    def _set_fmu_state(self, state):
        self._t = float(state["t"])
        self._u = np.array(state["u"], dtype=float)
        self.block.param_values[:] = state["p"]
        self.block.set_state(state["x"])
        self._dirty = True
