"""FMU slave: paper 001's FONTSM (papers/p001_zhang2019/blocks.py:controller)."""
from fmus.adapter import BlockSlave
from papers.p001_zhang2019.blocks import controller as _factory


class FONTSM(BlockSlave):
    block_factory = _factory
