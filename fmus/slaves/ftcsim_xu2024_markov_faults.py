"""FMU slave: Xu2024MarkovFaults (papers/p004_xu2024/blocks.py:mode_source)."""
from fmus.adapter import BlockSlave
from papers.p004_xu2024.blocks import mode_source as _factory


class Xu2024MarkovFaults(BlockSlave):
    block_factory = _factory
