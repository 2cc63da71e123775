"""FMU slave: paper 001's ASMFEO (papers/p001_zhang2019/blocks.py:observer)."""
from fmus.adapter import BlockSlave
from papers.p001_zhang2019.blocks import observer as _factory


class ASMFEO(BlockSlave):
    block_factory = _factory
