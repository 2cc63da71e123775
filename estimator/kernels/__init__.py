"""Compiled kernels of the estimators (``plant/jit.py`` says how kernels are written, switched and cached)."""
