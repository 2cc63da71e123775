"""Premise memberships of Takagi-Sugeno models: one small interface for every paper's rules.

A membership set maps the premise vector z to normalised firing strengths h_i(z) >= 0 with
sum_i h_i = 1 (one per rule, in the rule order of its paper). Observers and controllers take
one of these instead of hard-coding a paper's rules:

* :class:`BoxCorners`: 000 (8)-(10): 2^d rules at the corners of [-w, w]^d, memberships linear
  in each premise variable and saturated outside the box (the reading of 000 Fig. 2, see
  ``plant/ts_fuzzy.py``).
* :class:`Gaussian`: Gaussian grades mu_ij(z_i) = exp(-(z_i - c_ji)^2 / (2 sigma_ji^2)), rule
  strength Upsilon_j = prod_i mu_ij, h_j = Upsilon_j / sum_j Upsilon_j (003 (2.7) and the A11, A21
  of 003 section 4).

Papers with other memberships (004 triangular on [omega, q]) add their class here, with the same
two members: ``n_rules`` and ``weights(z)``.
"""
from __future__ import annotations

import itertools
import math

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


class Gaussian(Memberships):
    """Normalised Gaussian memberships, 003 (2.7): h_j(z) = Upsilon_j / sum_k Upsilon_k with
    Upsilon_j = prod_i exp(-(z_i - c_ji)^2 / (2 sigma2_ji)).

    ``centers`` and ``sigma2`` (variances sigma^2, not standard deviations) are (r,) for one premise
    variable or (r, d) for d of them. The normalisation is done in the log domain, so a premise far
    from every centre still gives finite weights summing to 1 (the nearest rule wins), never 0/0.

    003 section 4: r = 2, one premise z1, A11 (rule 1): centre 1.5, sigma_1^2 = 0.5; A21 (rule 2):
    centre 1, sigma_2^2 = 1."""

    def __init__(self, centers, sigma2):
        c = np.asarray(centers, dtype=float)
        v = np.asarray(sigma2, dtype=float)
        if c.ndim == 1:
            c = c[:, None]
        if v.ndim == 1:
            v = v[:, None]
        if c.shape != v.shape or c.ndim != 2 or c.shape[0] < 1:
            raise ValueError(f"Gaussian: centers {c.shape} and sigma2 {v.shape} must have the same shape (r,) or (r, d)")
        if not np.all(np.isfinite(c)):
            raise ValueError(f"Gaussian: centers must be finite, got {c.tolist()}")
        if not np.all(v > 0) or not np.all(np.isfinite(v)):
            raise ValueError(f"Gaussian: every variance sigma2 must be > 0, got {v.tolist()}")
        self.centers, self.sigma2 = c, v
        self.n_rules, self.dims = c.shape
        self._inv2v = 0.5 / v
        self._scalar = [(float(c[j, 0]), float(self._inv2v[j, 0])) for j in range(self.n_rules)] if self.dims == 1 else []

    def weights(self, z) -> np.ndarray:
        if self.dims == 1 and len(z) == 1:  # fast path (one premise variable, e.g. 003)
            z0 = float(z[0])
            logs = [-(z0 - c) * (z0 - c) * k for c, k in self._scalar]
            top = max(logs)
            e = [math.exp(v - top) for v in logs]
            tot = sum(e)
            return np.array([v / tot for v in e])
        z = np.asarray(z, dtype=float).reshape(-1)
        if z.size != self.dims:
            raise ValueError(f"Gaussian: premise has {z.size} entries, the memberships have {self.dims}")
        d = z[None, :] - self.centers
        logs = -(d * d * self._inv2v).sum(axis=1)  # log Upsilon_j
        e = np.exp(logs - logs.max())
        return e / e.sum()
