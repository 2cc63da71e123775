"""FMU slave: Xu2024Disturbance (papers/p004_xu2024/blocks.py:disturbance)."""
from fmus.adapter import BlockSlave
from papers.p004_xu2024.blocks import disturbance as _factory


class Xu2024Disturbance(BlockSlave):
    block_factory = _factory
