"""FMU slave: Xu2024FlexiblePlant (papers/p004_xu2024/blocks.py:flexible_plant)."""
from fmus.adapter import BlockSlave
from papers.p004_xu2024.blocks import flexible_plant as _factory


class Xu2024FlexiblePlant(BlockSlave):
    block_factory = _factory
