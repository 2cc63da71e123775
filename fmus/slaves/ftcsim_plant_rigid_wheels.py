"""FMU slave: paper 001's RigidSpacecraftWheels (papers/p001_zhang2019/blocks.py:plant)."""
from fmus.adapter import BlockSlave
from papers.p001_zhang2019.blocks import plant as _factory


class RigidSpacecraftWheels(BlockSlave):
    block_factory = _factory
