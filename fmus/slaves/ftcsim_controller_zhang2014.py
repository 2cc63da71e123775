"""FMU slave: robust H-infinity state feedback of paper 002 (papers.p002_zhang2014.blocks:controller)."""
from fmus.adapter import BlockSlave
from papers.p002_zhang2014.blocks import controller as _factory


class Zhang2014Hinf(BlockSlave):
    block_factory = _factory
