"""T-S fuzzy disturbance observer gain L1 of 003 Theorem 1, (3.4), and independent checks.

003's text lost most minus signs, square roots and sub/superscripts in extraction. Readings:

* Plant (003 (2.4)): pitch axis, x = [theta, theta'], B0 = B1 = [0; (J - H H^T)^-1] with
  J = 6.14 kg m^2 (middle entry of 003 (4.1), read as diag(5.5, 6.14, 2.18)) and
  H = [1.27806, 0.91758] (so J - H H^T = 3.665 kg m^2); see ``papers/p003_hang2023/parameters.py``.
* Exosystem (003 (4.x), printed "W1=[1250], W2=[0640], V1=[40], V2=[30]"):
  W1 = [[-1, 2], [-5, 0]], W2 = [[0, 6], [-4, 0]], V1 = [4, 0], V2 = [3, 0].
  The signs are ours: W1 then has eigenvalues -0.5 +- 3.12j, |lambda| = sqrt(10) = 3.16 rad/s,
  the first bending mode n1 = 3.17 rad/s of 003 section 4 (a strong hint that this is meant);
  W2 is an undamped oscillator at sqrt(24) = 4.9 rad/s.
* Observer (003 (3.1)): ew' = (W_j + L1 B0 V_j) ew + ... (003 (3.3)), the standard
  disturbance-observer form (it follows from (3.1) with w^ = eps - L1 x).
* LMI (003 (3.4), printed "[sym(P1WjRB1Vj) 2RB0; 2B0^TR^T I]"): with R = P1 L1,
      Omega_j = [[sym(P1 W_j + R B0 V_j), sqrt(2) R B0], [*, -I]] < 0,
  the "2" being sqrt(2) that lost its radical: the Schur complement is then exactly the
  Gamma_j < 0 of 003 (3.6)-(3.8), sym(P1 (W_j + L1 B0 V_j)) + 2 P1 L1 B0 B0^T L1^T P1 < 0
  (B0 = B1, so "R B1 V_j" as printed is the same matrix).
* Gain: "L1 = R P1^-1" as printed is inconsistent with R = P1 L1; we use L1 = P1^-1 R.
* Published gain (printed "L1=[01.54x10^3 02.35x10^4]"): L1 = [[0, -1.54e3], [0, -2.35e4]]; the
  negative signs are the only ones that make W_j + L1 B0 V_j Hurwitz with V_j as read above.
* Design objective: 003 gives none ((3.4) alone is feasible for any tiny P1, so it does not
  fix a gain). With the decay term, Omega_j + diag(2 alpha P1, 0) < 0 gives
  V1' <= -2 alpha V1 + Psi_a (003 (3.6)-(3.7)), hence ultimately
  ||ew||^2 <= Psi_a / (2 alpha beta) with beta <= lambda_min(P1). For fixed alpha the LMIs
  are linear in (P1, R, beta): we maximise beta, and search alpha (log grid + golden section)
  for the largest alpha * beta, i.e. the smallest ultimate bound per unit Psi_a.
  R's first column is fixed to 0 (it does not enter (3.4) since B0 = [0; b]); this gives the
  published structure L1 = [[0, *], [0, *]].
"""
from __future__ import annotations

import math

import cvxpy as cp
import numpy as np

import lmi
from lmi.search import grid_then_golden
from lmi.verify import spectral_abscissa, summarize
from plant.block import structured_values
from plant.pitch_axis import rigid_model

from .gains import L1_PUBLISHED
from .parameters import HANG2023, V, W

FMU_MODEL = "Hang2023TSFDO"  # no FMU of 003 exists yet: provisional model name


def b0(params=HANG2023):
    return rigid_model(params["J"], params["F"])[1]


def _problem(alpha, L1=None, params=HANG2023, margin=1e-6):
    """(3.4) with decay rate alpha; unknowns P1, R (or P1 only with L1 given) and beta <= lambda_min(P1)."""
    B0 = b0(params)
    p = lmi.LMIProblem(f"003 Theorem 1 (3.4), alpha={alpha:g}")
    P1 = p.symmetric("P1", 2)
    beta = p.scalar("beta")
    if L1 is None:
        Rv = p.matrix("R2", 2, 1)
        R = cp.hstack([np.zeros((2, 1)), Rv])  # first column 0 (does not enter (3.4))
    else:
        R = P1 @ np.asarray(L1, float)
    p.positive_definite("P1 > beta I", P1 - beta * np.eye(2), margin)
    p.constrain(beta >= 0)
    for j, (Wj, Vj) in enumerate(zip(W, V), start=1):
        S = P1 @ Wj + R @ B0 @ Vj
        p.negative_definite("(3.4)", lmi.sym_blocks([[S + S.T + 2 * alpha * P1, np.sqrt(2.0) * (R @ B0)],
                                                     [None, -np.eye(1)]]), margin, rule=j)
    return p, beta


def best_bound(alpha, L1=None, params=HANG2023):
    """max beta for a fixed alpha; returns (beta, solution) or (0, None) if infeasible."""
    p, beta = _problem(alpha, L1, params)
    try:
        sol = p.solve(-beta, solvers=("CLARABEL",))
        return float(sol["beta"]), sol
    except lmi.LMIError:
        return 0.0, None


def max_decay(L1=None, params=HANG2023, alphas=tuple(np.logspace(-2, 3, 11)), refine=10):
    """Maximise alpha * beta over alpha (log grid + golden section): the ultimate bound
    ||ew||^2 <= Psi_a / (2 alpha beta). Returns (alpha, beta, solution, table)."""
    table, solutions = [], {}

    def neg_alpha_beta(a):
        b, s = best_bound(a, L1, params)
        table.append({"alpha": float(a), "beta": b, "alpha_beta": a * b})
        solutions[a] = s
        return -(a * b) if s is not None and a * b > 0 else math.inf

    alpha, value, _ = grid_then_golden(neg_alpha_beta, alphas, iterations=refine)
    if not math.isfinite(value):
        return None, None, None, table
    sol = solutions[alpha]
    return alpha, float(sol["beta"]), sol, sorted(table, key=lambda r: r["alpha"])


def error_matrices(L1, params=HANG2023):
    B0 = b0(params)
    return [Wj + np.asarray(L1, float) @ B0 @ Vj for Wj, Vj in zip(W, V)]


def verify(L1, params=HANG2023, n_blend=21, alphas=tuple(np.logspace(-2, 3, 6))) -> dict:
    """Each W_j + L1 B0 V_j Hurwitz, every blend h W_1 + (1-h) W_2 (frozen) Hurwitz, and (3.4)
    feasible with L1 fixed (P1 > 0 free): the theorem's certificate for this gain. Also the best
    alpha * beta on the grid ``alphas`` (the ultimate-bound figure; skipped if a rule is unstable)."""
    Es = error_matrices(L1, params)
    hs = np.linspace(0.0, 1.0, n_blend)
    blend = max(spectral_abscissa(h * Es[0] + (1 - h) * Es[1]) for h in hs)
    abscissa = [spectral_abscissa(E) for E in Es]
    try:
        _problem(0.0, L1, params, margin=1e-9)[0].solve(solvers=("CLARABEL",))
        cert = True
    except lmi.LMIError:
        cert = False
    alpha = beta = None
    if max(abscissa) < 0 and cert:
        alpha, beta, _, _ = max_decay(L1, params, alphas=alphas, refine=0)
    rep = {"L1": np.asarray(L1, float), "abscissa": abscissa,
           "eigenvalues": [np.linalg.eigvals(E).tolist() for E in Es], "blend_abscissa": blend,
           "lmi_3_4_feasible": cert,
           "best_alpha_beta_on_grid": None if alpha is None else alpha * beta}
    holds = [(f"rule {j + 1}: Hurwitz", a < 0) for j, a in enumerate(rep["abscissa"])]
    holds += [("frozen blends Hurwitz", blend < 0), ("(3.4) feasible", cert)]
    rep["holds"] = dict(holds)
    rep.update(summarize(holds))
    return rep


def design(alpha=None, params=HANG2023) -> dict:
    """L1 maximising the decay rate (or for a given ``alpha``); verify; returns the result (``ftcsim design``
    writes it)."""
    table = None
    if alpha is None:
        alpha, beta, sol, table = max_decay(None, params)
        if sol is None:
            raise lmi.LMIInfeasible("003 (3.4): infeasible for every decay rate tried", {"search": table})
    else:
        p, b = _problem(float(alpha), None, params)
        sol = p.solve(-b)
    alpha_used, beta = float(alpha), float(sol["beta"])
    P1 = sol["P1"]
    R = np.hstack([np.zeros((2, 1)), sol["R2"]])
    L1 = np.linalg.solve(P1, R)  # L1 = P1^-1 R (our reading)
    ver = verify(L1, params)
    result = {
        "design": "hang2023-tsfdo", "source": "003 Theorem 1, (3.4)",
        "settings": {"W": list(W), "V": list(V), "B0": b0(params), "objective": "max alpha*beta, beta <= lambda_min(P1)"},
        "performance": {"alpha": alpha_used, "beta": beta, "ultimate_bound_factor": 1.0 / (2 * alpha_used * beta),
                        "error_abscissa": ver["abscissa"]},
        "alpha_search": table,
        "published": {"L1": L1_PUBLISHED},
        "gains": {"L1": L1, "P1": P1},
        "solver": sol.solver, "status": sol.status, "versions": sol.record["versions"],
        "tolerances": sol.record["tolerances"], "lmi_checks": sol.record["checks"], "verify": ver,
        "checks_passed": bool(ver["all_hold"]),
        "fmu_parameters": {FMU_MODEL: structured_values("L1", L1)},
    }
    if not ver["all_hold"]:
        raise lmi.LMIUnverified("003 design fails independent verification: " + ", ".join(ver["failed"]), result)
    return result
