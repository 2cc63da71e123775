"""FMU slave: pitch-axis plant of paper 003 (papers.p003_hang2023.blocks:plant)."""
from fmus.adapter import BlockSlave
from papers.p003_hang2023.blocks import plant as _factory


class Hang2023Plant(BlockSlave):
    block_factory = _factory
