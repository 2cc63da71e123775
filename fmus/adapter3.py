"""One generic adapter from a block (plant/block.py) to a pythonfmu3 FMI 3.0 slave.

The FMI 3.0 twin of ``fmus/adapter.py`` (kept separate because an FMI 3 FMU embeds
``pythonfmu3`` and must not import ``pythonfmu``). The behaviour is the same code,
``fmus/block_runtime.py``, so that an FMI 3 run gives the same numbers as the FMI 2 run:

* value references: 0 is ``time`` (the independent variable FMI 3 requires), then the
  inputs (from 1), the outputs, the parameters, each in the block's declared order;
* every variable is a scalar ``Float64`` (pythonfmu3's array variables break with
  numpy >= 2.4, and scalars keep the structured names ``q[0]``, ``J[1,2]`` of FMI 2);
* parameters are ``fixed``/``exact``: read when the FMU leaves initialisation mode (or
  at the first output read during initialisation); outputs are recomputed lazily after
  an input change or a step; the FMU state holds inputs, parameters, time and the
  block's internal state as JSON-safe floats, so rollback is exact.
"""
from pythonfmu3 import Float64, Fmi3Causality, Fmi3Initial, Fmi3Slave, Fmi3Variability

from .block_runtime import BlockRuntime


class BlockSlave3(BlockRuntime, Fmi3Slave):
    """Subclasses set ``block_factory`` to a callable returning a fresh block."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._init_block()
        self.time = 0.0
        self.register_variable(
            Float64("time", causality=Fmi3Causality.independent, variability=Fmi3Variability.continuous,
                    description="simulation time", getter=lambda: self._t)
        )
        self._register_block_variables(Float64, Fmi3Causality, Fmi3Variability, Fmi3Initial)

    def get_float64(self, vrs):
        return self._get_values(vrs, first_input=1)  # vr 0, time, through its getter

    def set_float64(self, vrs, values):
        self._set_values(vrs, values, first_input=1)

    def setup_experiment(self, start_time):
        self._start(start_time)
