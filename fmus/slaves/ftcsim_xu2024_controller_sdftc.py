"""FMU slave: Xu2024SampledFTC (papers/p004_xu2024/blocks.py:controller)."""
from fmus.adapter import BlockSlave
from papers.p004_xu2024.blocks import controller as _factory


class Xu2024SampledFTC(BlockSlave):
    block_factory = _factory
