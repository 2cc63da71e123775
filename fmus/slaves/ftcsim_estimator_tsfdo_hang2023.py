"""FMU slave: T-S fuzzy disturbance observer of paper 003 (papers.p003_hang2023.blocks:observer)."""
from fmus.adapter import BlockSlave
from papers.p003_hang2023.blocks import observer as _factory


class Hang2023TSFDO(BlockSlave):
    block_factory = _factory
