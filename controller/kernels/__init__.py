"""Compiled kernels of the controllers (``plant/jit.py`` says how kernels are written, switched and cached)."""
