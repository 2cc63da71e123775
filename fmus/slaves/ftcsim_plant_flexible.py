"""FMU slave: flexible spacecraft plant (plant/flexible.py)."""
from fmus.adapter import BlockSlave
from plant.flexible import FlexibleSpacecraft as _Block


class FlexibleSpacecraft(BlockSlave):
    block_factory = _Block
