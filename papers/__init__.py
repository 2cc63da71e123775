"""One folder per paper: everything that is one paper's set-up (parameter sets, published
gains, design entry points, metrics, report, scenarios, README of readings).

The algorithms themselves are paper-agnostic and live in ``plant/``, ``estimator/`` and
``controller/``. Papers are registered in :mod:`papers.registry`. This package and every
paper's ``__init__`` stay import-light (no cvxpy, no matplotlib): FMUs embed the numpy-only
data modules (``parameters.py``, ``gains.py``, ``blocks.py``) of their paper.
"""
