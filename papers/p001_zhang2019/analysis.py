"""Design checks of paper 001 that need no LMI (numpy/scipy): Theorem 3.1's condition and the
linearised observer error system (why the printed lambda_1, lambda_2 cannot estimate the faults
within the run).

Theorem 3.1 asks lambda_min(Lambda) - eps ||J^-1|| >= 0. The symbol printed there is the
boundary epsilon of (15), but in the proof the term comes from the Lipschitz bound (7) in
(17)-(18), so it is the Lipschitz constant of omega x J omega. ``theorem31`` reports both:

* Lipschitz reading (ours): on the ball ||omega|| <= R the Jacobian of omega x J omega is
  omega^x J - (J omega)^x, so eps(R) = R max_{|v|=1} ||v^x J - (J v)^x||_2; the condition holds
  for R <= lambda_min(Lambda) / (||J^-1|| max_v ||.||);
* literal reading: epsilon of (15) <= lambda_min(Lambda) / ||J^-1||.

Linearised error system (001 (13)-(14) with K = 0, constant faults, omega ~ omega_hat so the
gyroscopic difference is dropped), x = [omega~, e~, uf~]:

    omega~' = -Lambda omega~ + J^-1 M U e~ + J^-1 M uf~
    e~'     = -lambda_1 U M^T J^-T omega~,     uf~' = -lambda_2 M^T J^-T omega~

For U = 0 (no command) the bias part alone has, per singular value s_i of J^-1 M, the modes
z^2 + Lambda z + lambda_2 s_i^2 = 0 (Lambda scalar): slow rates ~ lambda_2 s_i^2 / Lambda. The
null space of M (N - 3 directions of uf~) has the eigenvalue 0: it is never estimated.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize


def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def gyro_jacobian_gain(J) -> float:
    """max over unit v of ||v^x J - (J v)^x||_2: the Lipschitz constant of omega x J omega is this
    times the radius of the ball of rates considered."""
    J = np.asarray(J, dtype=float)

    def neg(x):
        v = x / np.linalg.norm(x)
        return -np.linalg.norm(_skew(v) @ J - _skew(J @ v), 2)

    # Fibonacci sphere, then local refinement from the best points
    k = np.arange(2000) + 0.5
    phi, th = np.arccos(1 - 2 * k / 2000), np.pi * (1 + 5**0.5) * k
    pts = np.column_stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)])
    vals = np.array([neg(p) for p in pts])
    best = min(vals)
    for i in np.argsort(vals)[:5]:
        r = minimize(neg, pts[i], method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-12})
        best = min(best, r.fun)
    return float(-best)


def theorem31(Lambda, J, omega_radius: float, epsilon_boundary: float) -> dict:
    """Theorem 3.1's lambda_min(Lambda) - eps ||J^-1|| >= 0 under both readings of eps."""
    lam_min = float(np.min(Lambda))
    ji = float(np.linalg.norm(np.linalg.inv(J), 2))
    g = gyro_jacobian_gain(J)
    eps_lip = g * omega_radius
    return {
        "lambda_min_Lambda": lam_min,
        "norm_J_inv": ji,
        "gyro_jacobian_gain": g,
        "omega_radius": omega_radius,
        "lipschitz_eps": eps_lip,
        "margin_lipschitz": lam_min - eps_lip * ji,
        "omega_radius_max": lam_min / (ji * g),
        "epsilon_boundary": epsilon_boundary,
        "margin_literal": lam_min - epsilon_boundary * ji,
        "epsilon_boundary_max": lam_min / ji,
    }


def error_system(Lambda, J, M, lambda_1, lambda_2, u_c=None) -> np.ndarray:
    """The linearised observer error matrix for x = [omega~ (3), e~ (N), uf~ (N)] at command u_c."""
    J, M = np.asarray(J, dtype=float), np.asarray(M, dtype=float)
    n = M.shape[1]
    B = np.linalg.inv(J) @ M
    U = np.diag(np.zeros(n) if u_c is None else np.asarray(u_c, dtype=float))
    A = np.zeros((3 + 2 * n, 3 + 2 * n))
    A[0:3, 0:3] = -np.diag(np.broadcast_to(np.asarray(Lambda, dtype=float), (3,)))
    A[0:3, 3 : 3 + n] = B @ U
    A[0:3, 3 + n :] = B
    A[3 : 3 + n, 0:3] = -lambda_1 * U @ B.T
    A[3 + n :, 0:3] = -lambda_2 * B.T
    return A


def bias_modes(Lambda, J, M, lambda_2) -> dict:
    """Eigenvalues of the bias-error subsystem [omega~, uf~] (U = 0) and its slow time constants."""
    J, M = np.asarray(J, dtype=float), np.asarray(M, dtype=float)
    n = M.shape[1]
    A = error_system(Lambda, J, M, 0.0, lambda_2)
    keep = list(range(3)) + list(range(3 + n, 3 + 2 * n))
    ev = np.linalg.eigvals(A[np.ix_(keep, keep)])
    ev = ev[np.argsort(-ev.real)]
    nonzero = ev[np.abs(ev) > 1e-12]
    slow = nonzero[np.argsort(-nonzero.real)][:3]
    return {
        "eigenvalues": ev,
        "singular_values_JinvM": np.linalg.svd(np.linalg.inv(J) @ M, compute_uv=False),
        "slowest_rates": -slow.real,
        "slowest_time_constants_s": 1.0 / -slow.real,
        "zero_modes": int(np.sum(np.abs(ev) <= 1e-12)),
    }


def null_space(M) -> np.ndarray:
    """Orthonormal basis of null(M) (columns): the wheel-bias directions no observer can see."""
    _, s, vt = np.linalg.svd(np.asarray(M, dtype=float))
    return vt[np.sum(s > 1e-12) :].T
