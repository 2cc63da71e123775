"""FMU slave: PD attitude controller with feed-forward (controller/pd.py)."""
from controller.pd import PDController as _Block
from fmus.adapter import BlockSlave


class PDController(BlockSlave):
    block_factory = _Block
