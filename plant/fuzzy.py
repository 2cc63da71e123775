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
* :class:`TriangularProduct`: one triangle per premise variable and rule (peak at -b, 0 or +b of
  a domain [-b, b]), the rule weight the product over the variables, normalised (004 section 4,
  Figs. 2-3), with a stated fallback where every product vanishes.

Papers with other memberships add their class here, with the same
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

TRIANGLE_PEAKS = (-1, 0, 1)  # the three triangles of TriangularProduct: peak at -b, 0, +b


class TriangularProduct(Memberships):
    """Product of triangular memberships, one triangle per premise variable and rule.

    Premise variable j has the domain [-b_j, b_j] (``half_widths``) and the slope s_j
    (``slopes``, default 1/b_j). Its three memberships are

        M^0(x) = max(0, 1 - s |x|)       (peak at 0)
        M^+(x) = min(1, max(0,  s x))    (peak at +b)
        M^-(x) = min(1, max(0, -s x))    (peak at -b)

    evaluated at x clipped to [-b_j, b_j] (outside the domain the edge value holds; a reading
    where a paper is silent). ``rule_peaks[i, j]`` in {-1, 0, +1} names the triangle rule i
    uses for variable j; psi_i = prod_j M^{peak[i,j]}(x_j) and h_i = psi_i / sum_k psi_k.

    Fallback: the products vanish together (sum psi < ``degenerate_tol``) at states that sit
    on a domain edge while having components of both signs (rule 0 needs every |x_j| < b_j, a
    +/- rule needs every x_j on its side). There h_i = mean_j M^{peak[i,j]}(x_j), renormalised:
    defined everywhere and a partition of unity, but NOT continuous across that set (the
    product weights near it tend to a vertex, the means do not). ``degenerate`` tells whether
    a state is in it.

    With s_j = 1/b_j and the three rules (0, +, -) the per-variable memberships sum to 1, so
    the fallback needs no renormalisation; with a printed slope such as 1.818 for b = 0.55 the
    sum is 1 to within 1e-4 (004 prints 1.818, not 1/0.55).
    """

    def __init__(self, half_widths, rule_peaks, slopes=None, degenerate_tol: float = 1e-12):
        b = np.asarray(half_widths, dtype=float).ravel()
        if b.size == 0 or not np.all(np.isfinite(b)) or np.any(b <= 0):
            raise ValueError(f"TriangularProduct: half_widths must be > 0, got {b.tolist()}")
        s = 1.0 / b if slopes is None else np.asarray(slopes, dtype=float).ravel()
        if s.shape != b.shape or not np.all(np.isfinite(s)) or np.any(s <= 0):
            raise ValueError(f"TriangularProduct: slopes must be > 0, one per premise variable, got {np.ravel(slopes).tolist()}")
        peaks = np.asarray(rule_peaks, dtype=float)
        if peaks.ndim != 2 or peaks.shape[1] != b.size:
            raise ValueError(f"TriangularProduct: rule_peaks must be (n_rules, {b.size}), got shape {peaks.shape}")
        if not np.all(np.isin(peaks, TRIANGLE_PEAKS)):
            raise ValueError(f"TriangularProduct: rule_peaks entries must be -1, 0 or +1, got {peaks.tolist()}")
        self.b, self.s = b, s
        self.peaks = peaks.astype(int)
        self.n_rules = peaks.shape[0]
        self.dims = b.size
        self.tol = float(degenerate_tol)
        # per rule and variable: index into the stacked (M^-, M^0, M^+) rows
        self._row = self.peaks + 1
        self._peaks_list = self._row.tolist()
        self._b_list, self._s_list = b.tolist(), s.tolist()

    def per_variable(self, z) -> np.ndarray:
        """(3, d) array: rows M^-, M^0, M^+ of each premise variable at z (clipped)."""
        x = np.clip(np.asarray(z, dtype=float)[: self.dims], -self.b, self.b)
        sx = self.s * x
        return np.vstack([np.clip(-sx, 0.0, 1.0), np.maximum(0.0, 1.0 - np.abs(sx)), np.clip(sx, 0.0, 1.0)])

    def _rule_memberships(self, z) -> np.ndarray:
        """(n_rules, d): M^{peak[i,j]}(x_j)."""
        m = self.per_variable(z)
        return m[self._row, np.arange(self.dims)]

    def products(self, z) -> np.ndarray:
        """Unnormalised psi_i(z)."""
        return np.prod(self._rule_memberships(z), axis=1)

    def degenerate(self, z) -> bool:
        return float(self.products(z).sum()) < self.tol

    def weights(self, z) -> np.ndarray:
        # Python floats: this runs at every RK4 stage of a plant and every sample of a controller
        pk = self._peaks_list
        per = []
        for x, bj, sj in zip(z.tolist() if hasattr(z, "tolist") else z, self._b_list, self._s_list):
            x = bj if x > bj else (-bj if x < -bj else x)
            sx = sj * x
            if sx >= 0.0:
                per.append((0.0, 1.0 - sx if sx < 1.0 else 0.0, sx if sx < 1.0 else 1.0))
            else:
                per.append((-sx if sx > -1.0 else 1.0, 1.0 + sx if sx > -1.0 else 0.0, 0.0))
        psi = []
        for row in pk:
            v = 1.0
            for mj, k in zip(per, row):
                v *= mj[k]
            psi.append(v)
        total = sum(psi)
        if total >= self.tol:
            return np.array(psi) / total
        mean = [sum(mj[k] for mj, k in zip(per, row)) / self.dims for row in pk]
        m = sum(mean)  # the stated fallback (see the class docstring)
        return np.array(mean) / m if m > 0.0 else np.full(self.n_rules, 1.0 / self.n_rules)

    def weights_batch(self, Z) -> np.ndarray:
        """``weights`` for every row of Z (N, d) -> (N, n_rules), the same arithmetic."""
        x = np.minimum(np.maximum(np.asarray(Z, dtype=float)[:, : self.dims], -self.b), self.b)
        sx = self.s * x
        m = np.empty(sx.shape + (3,))
        m[..., 0] = np.minimum(np.maximum(-sx, 0.0), 1.0)
        m[..., 1] = np.maximum(1.0 - np.abs(sx), 0.0)
        m[..., 2] = np.minimum(np.maximum(sx, 0.0), 1.0)
        cols = np.arange(self.dims)
        mi = np.stack([m[:, cols, row] for row in self._row], axis=1)  # (N, n_rules, d)
        psi = np.prod(mi, axis=2)
        total = psi.sum(axis=1)
        ok = total >= self.tol
        if np.all(ok):
            return psi / total[:, None]
        out = np.empty_like(psi)
        out[ok] = psi[ok] / total[ok, None]
        mean = mi[~ok].mean(axis=2)
        ms = mean.sum(axis=1)
        out[~ok] = np.where(ms[:, None] > 0, mean / np.where(ms > 0, ms, 1.0)[:, None], 1.0 / self.n_rules)
        return out


def triangular_parameters(n_rules: int, dims: int):
    """Block parameters describing a :class:`TriangularProduct` (generic defaults: unit
    domains; rules 1, 2, 3 peaking at 0, +b, -b; further rules at 0)."""
    from .block import Variable, vector

    peaks = [0.0, 1.0, -1.0] + [0.0] * max(0, n_rules - 3)
    return (
        vector("z_half_width", dims, "1", "premise domain half-width b_j (unit of premise j)", [1.0] * dims)
        + vector("z_slope", dims, "1", "membership slope s_j (0: 1/b_j)", [0.0] * dims)
        + [Variable(f"rule_peak[{i + 1},{j + 1}]", "1", "triangle of rule i on premise j: -1, 0 or +1", peaks[i])
           for i in range(n_rules) for j in range(dims)]
    )


def triangular_from_parameters(block) -> TriangularProduct:
    """The :class:`TriangularProduct` that a block's ``triangular_parameters`` describe."""
    b = block.p_vector("z_half_width")
    s = block.p_vector("z_slope")
    s = np.where(s == 0.0, 1.0 / np.where(b > 0, b, 1.0), s)
    try:
        return TriangularProduct(b, block.p_array("rule_peak"), s)
    except ValueError as e:
        raise ValueError(f"{block.model_name}: {e}") from None
