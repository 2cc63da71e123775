"""Premise memberships of Takagi-Sugeno models: one small interface for every paper's rules.

A membership set maps the premise vector z to normalised firing strengths h_i(z) >= 0 with
sum_i h_i = 1 (one per rule, in the rule order of its paper). Observers and controllers take
one of these instead of hard-coding a paper's rules:

* :class:`BoxCorners`: 000 (8)-(10): 2^d rules at the corners of [-w, w]^d, memberships linear
  in each premise variable and saturated outside the box (the reading of 000 Fig. 2, see
  ``plant/ts_fuzzy.py``).

Papers with other memberships (003 Gaussian on 2 rules, 004 triangular on [omega, q]) add
their class here, with the same two members: ``n_rules`` and ``weights(z)``.
"""
from __future__ import annotations

import itertools

import numpy as np


class Memberships:
    """Base: ``n_rules`` and ``weights(z) -> (n_rules,)`` array, normalised (sum 1)."""

    n_rules: int = 0

    def weights(self, z) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError


class BoxCorners(Memberships):
    """2^d rules at the corners of [-w, w]^d (first premise varies slowest, + before -), 000 (10).

    For each premise j: M_+(z_j) = clip((z_j + w) / (2 w), 0, 1), M_- = 1 - M_+; the rule
    weight is the product over the premises (normalised by construction)."""

    def __init__(self, half_width: float, dims: int = 3):
        if not half_width > 0:
            raise ValueError(f"BoxCorners: half_width must be > 0, got {half_width}")
        self.w = float(half_width)
        self.dims = int(dims)
        self.n_rules = 2**self.dims

    def points(self) -> np.ndarray:
        """(n_rules, d) operating points, rule order."""
        return np.array([[s * self.w for s in signs] for signs in itertools.product((1, -1), repeat=self.dims)])

    def weights(self, z) -> np.ndarray:
        w = self.w
        pairs = []
        for j in range(self.dims):
            p = min(max((float(z[j]) + w) / (2.0 * w), 0.0), 1.0)
            pairs.append((p, 1.0 - p))
        return np.array([float(np.prod(c)) for c in itertools.product(*pairs)])
