"""The FMUs of the decision layer and of the sensor faults, as the registry (``papers/registry.py``)
lists them: (model name, "module:factory", description). Factories return a configured block
(``diagnosis/factories.py``, numpy only: the FMUs embed their modules). This module imports
nothing: the registry reads it on every command.

Shipped widths: the detectors test a 3-vector in N.m (the body fault-torque estimates of 000's
FAFEO ``f_hat``, 001's ASMFEO ``fault_torque_hat``); the isolation names one of four wheels from
such a vector, with 001's wheel layout M as signatures (``plant/rigid_wheels.py:
default_distribution``). Another width or unit is a two-line factory and ``ftcsim build --block``
(docs/fdir.md)."""
from __future__ import annotations

FMUS = (
    ("CusumDetector3", "diagnosis.factories:cusum_detector_3",
     "two-sided CUSUM change detector on a 3-vector (N.m), persistence, latch, reset (Basseville & Nikiforov 2.2)"),
    ("GlrDetector3", "diagnosis.factories:glr_detector_3",
     "window-limited GLR detector of a step in the mean of a 3-vector (N.m) (Basseville & Nikiforov 2.4.3)"),
    ("Chi2Detector3", "diagnosis.factories:chi2_detector_3", "windowed chi-square detector on a 3-vector (N.m)"),
    ("FaultIsolation4", "diagnosis.factories:fault_isolation_4",
     "names the failed wheel of four from the direction of a body fault-torque estimate (signatures: the columns of M)"),
    ("GyroFault3", "plant.sensor_faults:gyro_fault_3", "3-axis gyro faults: bias step, drift ramp, stuck, with ground truth"),
    ("StarTrackerFault", "plant.sensor_faults:star_tracker_fault",
     "star-tracker faults: outage (invalid, stale) and frozen output, with ground truth"),
)
