"""FMU slave: fuzzy adaptive sliding-mode FTC (controller/fasmc.py)."""
from controller.fasmc import FASMC as _Block
from fmus.adapter import BlockSlave


class FASMC(BlockSlave):
    block_factory = _Block
