"""Independent checks of a gain set: poles, pole disks, H-infinity norms (numpy/scipy only).

These do not reuse the LMIs: they look at the closed-loop (or error-system) matrices the
gains produce. The H-infinity norm is a frequency sweep (lower bound, peak location) refined
by bisection on the Hamiltonian matrix (Boyd, Balakrishnan, Bruinsma): for a Hurwitz A and
D = 0, ||C (sI - A)^-1 B||_inf < g iff H(g) = [[A, B B^T / g^2], [-C^T C, -A^T]] has no
eigenvalue on the imaginary axis.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla


def spectral_abscissa(A) -> float:
    """max Re(lambda(A)); < 0 iff A is Hurwitz."""
    return float(np.max(np.linalg.eigvals(np.asarray(A, float)).real))


def disk_excess(A, center: float, radius: float) -> float:
    """max |lambda - center| - radius; < 0 iff every eigenvalue is inside O(center, radius)."""
    lam = np.linalg.eigvals(np.asarray(A, float))
    return float(np.max(np.abs(lam - center)) - radius)


def _freq_response_peak(A, B, C, w):
    n = A.shape[0]
    best, wbest = 0.0, 0.0
    # Hessenberg form makes each solve cheap and well conditioned.
    H, Q = sla.hessenberg(A, calc_q=True)
    Bq, Cq = Q.T @ B, C @ Q
    for wk in w:
        G = Cq @ np.linalg.solve(1j * wk * np.eye(n) - H, Bq)
        s = np.linalg.norm(G, 2)
        if s > best:
            best, wbest = float(s), float(wk)
    return best, wbest


def _has_imag_eig(A, B, C, g, rtol=1e-9):
    H = np.block([[A, B @ B.T / g**2], [-C.T @ C, -A.T]])
    lam = np.linalg.eigvals(H)
    scale = max(1.0, np.abs(lam).max())
    return bool(np.any(np.abs(lam.real) <= rtol * scale * 10 + 1e-12)), lam


def hinf_norm(A, B, C, rtol: float = 1e-6, n_freq: int = 400) -> dict:
    """H-infinity norm of C (sI - A)^-1 B (D = 0) for a Hurwitz A.

    Returns ``norm`` (bisection on the Hamiltonian, upper end of the final bracket),
    ``sweep_peak`` / ``peak_frequency`` (rad/s) from the sweep, and ``bracket``.
    Returns ``norm = inf`` if A is not Hurwitz.
    """
    A, B, C = (np.asarray(x, float) for x in (A, B, C))
    if spectral_abscissa(A) >= 0.0:
        return {"norm": float("inf"), "sweep_peak": float("inf"), "peak_frequency": None, "bracket": None}
    lam = np.linalg.eigvals(A)
    wmax = max(1.0, np.abs(lam).max()) * 100.0
    wmin = max(1e-6, np.abs(lam).min() / 100.0)
    w = np.concatenate([[0.0], np.logspace(np.log10(wmin), np.log10(wmax), n_freq), np.abs(lam.imag)])
    peak, wpk = _freq_response_peak(A, B, C, w)
    lo, hi = peak, max(peak * 2.0, 1e-12)
    while _has_imag_eig(A, B, C, hi)[0]:
        lo, hi = hi, hi * 2.0
    # lo is attained by the sweep (a true lower bound); hi has no imaginary eigenvalue.
    for _ in range(200):
        if hi - lo <= rtol * hi:
            break
        mid = 0.5 * (lo + hi)
        imag, ev = _has_imag_eig(A, B, C, mid)
        if imag:
            # refine the lower bound at the frequencies where H(mid) touches the axis
            wi = np.abs(ev.imag[np.abs(ev.real) <= 1e-6 * max(1.0, np.abs(ev).max())])
            p2, w2 = _freq_response_peak(A, B, C, wi) if wi.size else (mid, wpk)
            if p2 > peak:
                peak, wpk = p2, w2
            lo = max(mid, p2)
        else:
            hi = mid
    return {"norm": float(hi), "sweep_peak": float(peak), "peak_frequency": float(wpk), "bracket": [float(lo), float(hi)]}


def summarize(items) -> dict:
    """{'all_hold': bool, 'failed': [names]} over a list of (name, holds) pairs."""
    failed = [n for n, ok in items if not ok]
    return {"all_hold": not failed, "failed": failed}
