"""FMU slave: adaptive terminal sliding-mode FTC of paper 003 (papers.p003_hang2023.blocks:controller)."""
from fmus.adapter import BlockSlave
from papers.p003_hang2023.blocks import controller as _factory


class Hang2023ASMFTC(BlockSlave):
    block_factory = _factory
