"""LMI layer shared by the designs (cvxpy; Clarabel first, SCS fallback; mandatory checks).

See :mod:`lmi.core` for the rules (float margins only, symmetric blocks, eigenvalue checks)
and :mod:`lmi.verify` for independent checks of gain sets (poles, disks, H-infinity norms).
"""
from .core import (
    LMI,
    CheckResult,
    LMIError,
    LMIInfeasible,
    LMIProblem,
    LMISolution,
    LMIUnverified,
    check_lmi,
    check_lmis,
    evaluate,
    feasibility,
    sym_blocks,
    versions,
)

__all__ = [
    "LMI", "CheckResult", "LMIError", "LMIInfeasible", "LMIProblem", "LMISolution", "LMIUnverified",
    "check_lmi", "check_lmis", "evaluate", "feasibility", "sym_blocks", "versions",
]
