"""One generic adapter from a block (plant/block.py) to a pythonfmu FMI 2.0 slave.

Value references: inputs first, then outputs, then parameters, each in the block's
declared order. Parameters are ``fixed``: they are read when the FMU leaves
initialisation mode (or at the first output read during initialisation). Outputs are
recomputed lazily after an input change or a step. The FMU state (get/set/serialise)
holds the inputs, the parameters, the time and every internal state of the block, as
JSON-safe floats, so that rollback is exact.
"""
import sys

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real


# pythonfmu 0.7's native findClass() takes the slave module's __dict__ with the borrowed
# PyModule_GetDict() and then Py_DECREFs it: every fmi2Instantiate drops one reference the
# module owns. After a few instantiations in one process the dict is freed and the next
# one fails ("[ctor] findClass ... bad argument to internal function") or crashes.
# The slave module's dict may own a single reference, so it would be freed during the very
# first instantiation. We hold one reference when the slave class is defined (a cushion)
# and give one back with each instance constructed, which balances the books.
_MODULE_DICT_REFS = []


def _hold_module_dict(cls) -> None:
    module = sys.modules.get(cls.__module__)
    if module is not None:
        _MODULE_DICT_REFS.append(module.__dict__)


class BlockSlave(Fmi2Slave):
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
        for i, v in enumerate(block.inputs):
            self.register_variable(
                Real(
                    v.name,
                    causality=Fmi2Causality.input,
                    variability=Fmi2Variability.continuous,
                    description=v.description,
                    getter=lambda i=i: float(self._u[i]),
                    setter=lambda x, i=i: self._set_input(i, x),
                )
            )
        for i, v in enumerate(block.outputs):
            self.register_variable(
                Real(
                    v.name,
                    causality=Fmi2Causality.output,
                    variability=Fmi2Variability.continuous,
                    description=v.description,
                    getter=lambda i=i: float(self._outputs()[i]),
                )
            )
        for i, v in enumerate(block.parameters):
            self.register_variable(
                Real(
                    v.name,
                    causality=Fmi2Causality.parameter,
                    variability=Fmi2Variability.fixed,
                    initial=Fmi2Initial.exact,
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

    def get_real(self, vrs):
        n_in = self._n_in
        n_io = n_in + self._n_out
        y = self._outputs() if any(n_in <= vr < n_io for vr in vrs) else None
        out = []
        for vr in vrs:
            if n_in <= vr < n_io:
                out.append(float(y[vr - n_in]))
            else:
                out.append(float(self.vars[vr].getter()))
        return out

    def set_real(self, vrs, values):
        n_in = self._n_in
        for vr, x in zip(vrs, values):
            if vr < n_in:
                self._u[vr] = x
            else:
                self.vars[vr].setter(x)
        self._dirty = True

    # -- life cycle ----------------------------------------------------------------------
    def setup_experiment(self, start_time, stop_time, tolerance):
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
