"""FMU slave: pitch-axis plant of paper 002 (papers.p002_zhang2014.blocks:plant)."""
from fmus.adapter import BlockSlave
from papers.p002_zhang2014.blocks import plant as _factory


class Zhang2014Plant(BlockSlave):
    block_factory = _factory
