"""FMU slave: fuzzy adaptive fault-estimation observer FAFEO (estimator/fafeo.py)."""
from estimator.fafeo import FAFEO as _Block
from fmus.adapter import BlockSlave


class FAFEO(BlockSlave):
    block_factory = _Block
