"""Compiled kernels of the diagnosis blocks (``detectors.py``); how kernels are written, switched and
cached: ``plant/jit.py``."""
