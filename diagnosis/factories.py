"""Factories of the decision-layer FMUs listed in ``diagnosis/catalog.py`` (the FMU build embeds what
this module imports)."""
from __future__ import annotations

from plant.rigid_wheels import default_distribution

from .detectors import Chi2Detector, CusumDetector, GlrDetector
from .isolation import FaultIsolation


def _named(block, model: str):
    block.model_name = model
    return block


def cusum_detector_3() -> CusumDetector:
    return _named(CusumDetector(3, "N.m"), "CusumDetector3")


def glr_detector_3() -> GlrDetector:
    return _named(GlrDetector(3, "N.m"), "GlrDetector3")


def chi2_detector_3() -> Chi2Detector:
    return _named(Chi2Detector(3, "N.m"), "Chi2Detector3")


def fault_isolation_4() -> FaultIsolation:
    """Four wheels, signatures the columns of 001's layout M (three orthogonal, one skew)."""
    return _named(FaultIsolation(3, 4, "N.m", default_distribution(4)), "FaultIsolation4")
