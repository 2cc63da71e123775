"""FMU slave: piecewise-constant signal source (plant/signals.py), used by SSP export."""
from fmus.adapter import BlockSlave
from plant.signals import PiecewiseConstantSource as _Block


class PiecewiseConstantSource(BlockSlave):
    block_factory = _Block
