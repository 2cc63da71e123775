"""Small symmetric 3x3 helpers in plain floats (numpy's solve/eigvalsh cost ~20-50 µs a call on
3x3 matrices, these ~2 µs): used on the hot paths of the 001 blocks. The kernels compile these
very functions (``plant/kernels/common.py``), so they stay plain float arithmetic that numba
accepts (math only, no numpy, no Python objects)."""
from __future__ import annotations

import math


def solve_sym3(a11, a12, a13, a22, a23, a33, b1, b2, b3):
    """x = A^-1 b for a symmetric 3x3 A = [[a11, a12, a13], [., a22, a23], [., ., a33]] (cofactors)."""
    c11 = a22 * a33 - a23 * a23
    c12 = a13 * a23 - a12 * a33
    c13 = a12 * a23 - a13 * a22
    c22 = a11 * a33 - a13 * a13
    c23 = a12 * a13 - a11 * a23
    c33 = a11 * a22 - a12 * a12
    det = a11 * c11 + a12 * c12 + a13 * c13
    return (
        (c11 * b1 + c12 * b2 + c13 * b3) / det,
        (c12 * b1 + c22 * b2 + c23 * b3) / det,
        (c13 * b1 + c23 * b2 + c33 * b3) / det,
    )


def min_eig_sym3(a11, a12, a13, a22, a23, a33) -> float:
    """Smallest eigenvalue of a symmetric 3x3 matrix (closed form, trigonometric)."""
    p1 = a12 * a12 + a13 * a13 + a23 * a23
    if p1 == 0.0:
        return min(a11, a22, a33)
    q = (a11 + a22 + a33) / 3.0
    b11, b22, b33 = a11 - q, a22 - q, a33 - q
    p = math.sqrt((b11 * b11 + b22 * b22 + b33 * b33 + 2.0 * p1) / 6.0)
    det_b = b11 * (b22 * b33 - a23 * a23) - a12 * (a12 * b33 - a23 * a13) + a13 * (a12 * a23 - b22 * a13)
    r = max(-1.0, min(1.0, det_b / (2.0 * p**3)))
    phi = math.acos(r) / 3.0
    return q + 2.0 * p * math.cos(phi + 2.0 * math.pi / 3.0)
