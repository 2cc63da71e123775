"""FMU slave: Xu2024FaultActuator (papers/p004_xu2024/blocks.py:fault_actuator)."""
from fmus.adapter import BlockSlave
from papers.p004_xu2024.blocks import fault_actuator as _factory


class Xu2024FaultActuator(BlockSlave):
    block_factory = _factory
