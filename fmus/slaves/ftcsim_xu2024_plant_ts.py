"""FMU slave: Xu2024TSPlant (papers/p004_xu2024/blocks.py:ts_plant)."""
from fmus.adapter import BlockSlave
from papers.p004_xu2024.blocks import ts_plant as _factory


class Xu2024TSPlant(BlockSlave):
    block_factory = _factory
