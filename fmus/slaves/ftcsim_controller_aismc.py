"""FMU slave: adaptive integral sliding-mode controller, 000's AISMC baseline (controller/aismc.py)."""
from controller.aismc import AISMC as _Block
from fmus.adapter import BlockSlave


class AISMC(BlockSlave):
    block_factory = _Block
