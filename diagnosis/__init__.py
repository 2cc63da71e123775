"""Decisions from estimates (FDIR): change detectors (CUSUM, GLR, chi-square window) with persistence,
latch and reset, fault isolation from the direction of a fault estimate, and the per-run FDIR
measures (detection delay, false alarms, isolation, reconfiguration). Blocks like the estimators and
controllers (``plant/block.py``), numpy only, no FMI; ``docs/fdir.md``."""
