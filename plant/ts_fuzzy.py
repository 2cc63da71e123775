"""T-S fuzzy model of the flexible spacecraft dynamics, 000 (8)-(10).

Premise variables: z = omega (rad/s). 8 rules at the corners of [-w, w]^3 (000: w = 0.7 rad/s),
in the order 000 section 5 lists them: (+,+,+), (+,+,-), (+,-,+), (+,-,-), (-,+,+), ...

Memberships (000 Figure 2 is not in our text; reading chosen here): for each axis j,
M_+(omega_j) = (omega_j + w) / (2 w) and M_-(omega_j) = 1 - M_+, both saturated to [0, 1]
outside [-w, w]; b_i is the product over the axes (normalisation is automatic). With this
reading the blend is multilinear interpolation between the corners, and because A(omega)
and D_2(omega) are affine in omega, sum_i b_i A_i = A(omega) and sum_i b_i D_2i = D_2(omega)
exactly inside the box: the fuzzy model equals the nonlinear model (6)-(7) there.

Rule matrices (000 (9)), with B = (J - delta^T delta)^-1:
  A_i = -B omega_i^x J,  D_2i = B [delta^T K_eta, delta^T C_eta - omega_i^x delta^T],
  A_d1 = I, B_d1 = [0; -delta], A_d2 = [[0, I], [-K_eta, -C_eta]], B_d2 = [-delta; C_eta delta].
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from .flexible import modal_matrices
from .so3 import skew


def rule_points(box: float) -> np.ndarray:
    """8 x 3 operating points, 000 section 5 order (first axis varies slowest, + first)."""
    return np.array([[s * box for s in signs] for signs in itertools.product((1, -1), repeat=3)])


def memberships(omega, box: float) -> np.ndarray:
    """Normalised firing strengths b_i(omega), shape (8,), sum 1: the products of
    [M_+, M_-] over the three axes, first axis slowest (the rule order above). Written
    with Python floats: it runs every communication step in the observer and controllers."""
    p0 = min(max((omega[0] + box) / (2.0 * box), 0.0), 1.0)
    p1 = min(max((omega[1] + box) / (2.0 * box), 0.0), 1.0)
    p2 = min(max((omega[2] + box) / (2.0 * box), 0.0), 1.0)
    a, b, c = (p0, 1.0 - p0), (p1, 1.0 - p1), (p2, 1.0 - p2)
    return np.array([a[i] * b[j] * c[k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])


@dataclass
class FuzzyModel:
    """The matrices of 000 (9)-(10) for one spacecraft parameter set."""

    A: np.ndarray  # (8, 3, 3)
    B: np.ndarray  # (3, 3)
    D2: np.ndarray  # (8, 3, 2n)
    Ad1: np.ndarray  # (2n, 2n)
    Bd1: np.ndarray  # (2n, 3)
    Ad2: np.ndarray  # (2n, 2n)
    Bd2: np.ndarray  # (2n, 3)
    points: np.ndarray  # (8, 3)
    box: float

    @property
    def n_rules(self) -> int:
        return self.A.shape[0]

    def blend(self, omega):
        """(b, sum_i b_i A_i, sum_i b_i D_2i) at omega."""
        b = memberships(omega, self.box)
        return b, np.tensordot(b, self.A, 1), np.tensordot(b, self.D2, 1)


def fuzzy_model(J, delta, omega_n, zeta, box: float) -> FuzzyModel:
    """Build the T-S model from the plant parameters (nothing typed in)."""
    J = np.asarray(J, float)
    delta = np.asarray(delta, float)
    C, K = modal_matrices(omega_n, zeta)
    n = delta.shape[0]
    B = np.linalg.inv(J - delta.T @ delta)
    pts = rule_points(box)
    A = np.array([-B @ skew(w) @ J for w in pts])
    D2 = np.array([B @ np.hstack([delta.T @ K, delta.T @ C - skew(w) @ delta.T]) for w in pts])
    Z = np.zeros((n, n))
    I = np.eye(n)
    return FuzzyModel(
        A=A,
        B=B,
        D2=D2,
        Ad1=np.eye(2 * n),
        Bd1=np.vstack([np.zeros((n, 3)), -delta]),
        Ad2=np.block([[Z, I], [-K, -C]]),
        Bd2=np.vstack([-delta, C @ delta]),
        points=pts,
        box=box,
    )
