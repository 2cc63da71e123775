"""Virtual-control gains K_c^i of 000 Theorem 2, (41)-(44), and independent checks.

Sliding dynamics 000 (50): s' = sum_i b_i {(A_i + B Gamma K_c^i) s + B_ci d_c},
B_ci = [B Gamma, D_2i, B] (3 x 14), performance output s (the X column of (41)).
LMIs, for every rule i (X > 0, Y_i = K_c^i X):
  (41) [[<A_i X + B Gamma Y_i>_S, B_ci, X], [*, -gamma_2^2 I, 0], [*, *, -I]] < 0
  (42) [[-X, A_i X + B Gamma Y_i - phi_2 X], [*, -eps_2^2 X]] < 0
  (43) -X + mu^2 I < 0
  (44) [[-X, -Y_i^T], [*, -varsigma^2 I]] < 0
Settings of 000 A.2: mu = 0.1, varsigma = 5 sqrt(3), (phi_2, eps_2) = (20, 20) as printed.

Readings:
* Disk. O(20, 20) is centred at +20: every point of it has Re > 0, so (42) with phi_2 = +20
  would force A_i + B Gamma K_c^i to be anti-stable, contradicting "Hurwitz" in the proof of
  Theorem 2. We read phi_2 = -20 (disk O(-20, 20), the left half plane near the origin) and
  test that the designed A_i + B Gamma K_c^i are Hurwitz and inside it.
* Gain. Theorem 2 prints K_c^i = X^-1 Y_2i, but its proof defines Y_2i = K_c^i X, so
  K_c^i = Y_2i X^-1 (the printed order is a slip; they agree only if K and X commute).
* (44) prints zeta^2 for varsigma^2 (the bound ||v||_2 < varsigma); the proof (61)-(63) uses varsigma.
* Gamma = I (000 section 5).
"""
from __future__ import annotations

import math

import numpy as np

import lmi
from lmi.verify import disk_excess, hinf_norm, spectral_abscissa, summarize
from plant.block import structured_values
from plant.ts_fuzzy import fuzzy_model

from . import gains as published
from .parameters import LI2023, OMEGA_BOX

FMU_MODELS = ("FASMC", "AISMC")
MU = 0.1
VARSIGMA = 5.0 * math.sqrt(3.0)
PHI_2, EPS_2 = -20.0, 20.0  # reading of 000 A.2 "(20, 20)": centre -20


def _bc(fm, i, Gamma=np.eye(3)):
    return np.hstack([fm.B @ Gamma, fm.D2[i], fm.B])  # 000 B_ci


def verify(K_c, gamma_2, phi=PHI_2, eps=EPS_2, varsigma=VARSIGMA, mu=MU, params=LI2023) -> dict:
    """Per rule: A_i + B K_c^i Hurwitz, inside O(phi, eps), ||(sI - A_cl)^-1 B_ci||_inf < gamma_2.

    Also reports max_i ||K_c^i|| * mu-ball bound: ||v|| <= ||K_c^i|| ||s|| (informative only).
    """
    fm = fuzzy_model(**params, box=OMEGA_BOX)
    K_c = np.asarray(K_c, float)
    rules, holds = [], []
    for r in range(fm.n_rules):
        A = fm.A[r] + fm.B @ K_c[r]
        h = hinf_norm(A, _bc(fm, r), np.eye(3))
        row = {"rule": r + 1, "abscissa": spectral_abscissa(A), "disk_excess": disk_excess(A, phi, eps),
               "hinf": h["norm"], "K_norm": float(np.linalg.norm(K_c[r], 2))}
        rules.append(row)
        holds += [(f"rule {r + 1}: Hurwitz", row["abscissa"] < 0),
                  (f"rule {r + 1}: in disk O({phi:g},{eps:g})", row["disk_excess"] < 0),
                  (f"rule {r + 1}: hinf < {gamma_2:g}", row["hinf"] < gamma_2)]
    rep = {"gamma_2": float(gamma_2), "disk": [phi, eps], "rules": rules,
           "max_hinf": max(r["hinf"] for r in rules), "max_abscissa": max(r["abscissa"] for r in rules),
           "max_disk_excess": max(r["disk_excess"] for r in rules), "holds": dict(holds)}
    rep.update(summarize(holds))
    return rep


def _problem(fm, phi, eps, mu, varsigma, margin, K_fixed=None, gamma_fixed=None, which=("41", "42", "43", "44")):
    p = lmi.LMIProblem("000 Theorem 2 (41)-(44)" if K_fixed is None else "000 Theorem 2 with fixed K_c")
    X = p.symmetric("X", 3)
    g = p.scalar("gamma_2_sq") if gamma_fixed is None else gamma_fixed**2
    Ys = []
    for r in range(fm.n_rules):
        Y = p.matrix(f"Y{r + 1}", 3, 3) if K_fixed is None else np.asarray(K_fixed[r]) @ X
        Ys.append(Y)
        AX = fm.A[r] @ X + fm.B @ Y
        Bc = _bc(fm, r)
        if "41" in which:
            p.negative_definite("(41)", lmi.sym_blocks([
                [AX + AX.T, Bc, X],
                [None, -g * np.eye(Bc.shape[1]), np.zeros((Bc.shape[1], 3))],
                [None, None, -np.eye(3)]]), margin, rule=r + 1)
        if "42" in which:
            p.negative_definite("(42)", lmi.sym_blocks([[-X, AX - phi * X], [None, -eps**2 * X]]), margin, rule=r + 1)
        if "44" in which:
            p.negative_definite("(44)", lmi.sym_blocks([[-X, -Y.T], [None, -varsigma**2 * np.eye(3)]]), margin,
                                rule=r + 1)
    if "43" in which:
        p.negative_definite("(43)", -X + mu**2 * np.eye(3), margin)
    else:
        p.positive_definite("X > 0", X, margin)
    return p, g


def lmi_certificate(K_c, gamma_2, phi=PHI_2, eps=EPS_2, mu=MU, varsigma=VARSIGMA, which=("41", "42", "43", "44"),
                    params=LI2023, margin=1e-7) -> dict:
    """Is there X satisfying the chosen LMIs of Theorem 2 for these fixed K_c^i and gamma_2?"""
    fm = fuzzy_model(**params, box=OMEGA_BOX)
    p, _ = _problem(fm, phi, eps, mu, varsigma, margin, K_fixed=K_c, gamma_fixed=gamma_2, which=which)
    return lmi.feasibility(p, "X found")


def published_gains():
    g = published
    return {"K_c": g.K_C, "gamma_2": g.GAMMA_2, "mu": g.MU, "phi_2": g.PHI_2, "eps_2": g.EPS_2}


def design(phi=PHI_2, eps=EPS_2, mu=MU, varsigma=VARSIGMA, params=LI2023, margin=1e-6) -> dict:
    """Minimise gamma_2 subject to 000 (41)-(44); verify; returns the result (``ftcsim design`` writes it)."""
    fm = fuzzy_model(**params, box=OMEGA_BOX)
    p, g = _problem(fm, phi, eps, mu, varsigma, margin)
    sol = p.solve(g)
    X = sol["X"]
    K_c = np.array([np.linalg.solve(X.T, sol[f"Y{r + 1}"].T).T for r in range(fm.n_rules)])  # K = Y X^-1
    gamma_2 = float(np.sqrt(sol.objective))
    ver = verify(K_c, gamma_2 * (1 + 1e-6), phi, eps, varsigma, mu, params)
    pub = published_gains()
    result = {
        "design": "li2023-controller", "source": "000 Theorem 2, (41)-(44)",
        "settings": {"phi_2": phi, "eps_2": eps, "mu": mu, "varsigma": varsigma, "margin": margin},
        "performance": {"gamma_2": gamma_2}, "published": {"gamma_2": pub["gamma_2"]},
        "gains": {"K_c": K_c, "X": X},
        "solver": sol.solver, "status": sol.status, "versions": sol.record["versions"],
        "tolerances": sol.record["tolerances"], "lmi_checks": sol.record["checks"], "verify": ver,
        "checks_passed": bool(ver["all_hold"]),
        "fmu_parameters": {m: structured_values("K_c", K_c) for m in FMU_MODELS},
    }
    if not ver["all_hold"]:
        raise lmi.LMIUnverified("000 Theorem 2 design fails independent verification: " + ", ".join(ver["failed"]),
                                result)
    return result


# -- `ftcsim design li2023-controller` / `ftcsim verify li2023-controller` -------------------------
def run_design(phi=None, eps=None, mu=None, varsigma=None):
    """Design with the given settings (defaults 000 A.2); returns (result, one-line summary)."""
    kw = {k: v for k, v in (("phi", phi), ("eps", eps), ("mu", mu), ("varsigma", varsigma)) if v is not None}
    r = design(**kw)
    return r, f"gamma_2 = {r['performance']['gamma_2']:.4f} (000 A.2: {r['published']['gamma_2']}); solver {r['solver']}"


def gains_from_file(get) -> dict:
    return {"K_c": get("gains.K_c", (8, 3, 3)), "gamma_2": get("performance.gamma_2", ()) * (1 + 1e-6),
            "phi": get("settings.phi_2", ()), "eps": get("settings.eps_2", ())}


def verify_report(gains=None, source="000 Appendix A.2 (published), disk read as O(-20, 20)"):
    if gains is None:
        pub = published_gains()
        gains = {"K_c": pub["K_c"], "gamma_2": pub["gamma_2"]}
    rep = verify(**gains)
    title = f"verify li2023-controller ({source}): gamma_2 = {gains['gamma_2']:.4f}, max H-inf = {rep['max_hinf']:.4f}"
    return rep["all_hold"], title, rep["holds"]
