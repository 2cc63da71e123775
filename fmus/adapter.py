"""One generic adapter from a block (plant/block.py) to a pythonfmu FMI 2.0 slave.

Value references: inputs first, then outputs, then parameters, each in the block's
declared order. Behaviour (fixed parameters, lazy outputs, complete FMU state) lives in
``fmus/block_runtime.py``, shared with the FMI 3.0 adapter.
"""
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real

from .block_runtime import BlockRuntime


class BlockSlave(BlockRuntime, Fmi2Slave):
    """Subclasses set ``block_factory`` to a callable returning a fresh block."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._init_block()
        self._register_block_variables(Real, Fmi2Causality, Fmi2Variability, Fmi2Initial)

    def get_real(self, vrs):
        return self._get_values(vrs, first_input=0)

    def set_real(self, vrs, values):
        self._set_values(vrs, values, first_input=0)

    def setup_experiment(self, start_time, stop_time, tolerance):
        self._start(start_time)
