"""FAFEO observer design of 000 Theorem 1, (23)-(24), and independent checks of a gain set.

Augmented error system 000 (19)-(20), e = [e_x (3), e_f (3), e_w (2n = 8)]:
    M e' = (A_i - K_i C) e + B_d d_o,   M = [[I, 0, 0], [th1 F2 C, I, 0], [th2 G2 C, 0, I]],
    A_i = [[A_i, B Gamma, D_2i], [0, 0, 0], [0, 0, A_d2]],  K_i = [K_i; F_1i; G_1i],
    C = [C 0 0],  B_d = [[B, 0], [0, I], [0, 0]],  d_o = [d_1; f'].
Performance output: e itself (the "+ I" of (23)); ||G_ed||_inf < gamma_1 (000 (21), (28)).

Reading of (23)-(24) (000 prints (24) with Q and M mixed; the proof says "(33) and
M zeta M^T with M = diag(M^-1, I)"): (33) is Lemma 3 for M^-1(A_i - K_i C) with the Lyapunov
matrix P = M^T Q M; the congruence T^T (33) T with T = diag(M^-1, I) gives exactly (24) as
printed, so (24) is right and the printed congruence is the wrong way round (M zeta M^T would
not produce -Q in the (1,1) block). We solve the equivalent, better scaled form obtained with
P = M^T Q M and Y = M^T Y_1i = P L_i, L_i = M^-1 K_i (standard observer LMIs for
A~_i = M^-1 A_i, B~ = M^-1 B_d), in coordinates e = T e^ with T = diag(s_x I, I, s_w I)
(a similarity: poles and H-infinity norm unchanged; without it P spans 1e-1..1e5 and the
solver stalls). Afterwards Q = M^-T P M^-1 and Y_1i = Q K_i are formed and the paper's own
(23) and (24) are evaluated numerically as an extra check.

Gamma = I (000 section 5). 000 section 5.2 also mentions "gamma_1^2 <= 0.1" and a
"feasibility radius 1e7"; gamma_1^2 <= 0.1 contradicts the published gamma_1 = 1.6563 and is
not used; the radius is irrelevant after scaling.
"""
from __future__ import annotations

import numpy as np

import lmi
from lmi.verify import disk_excess, hinf_norm, spectral_abscissa, summarize
from plant.block import structured_values
from plant.ts_fuzzy import fuzzy_model

from . import gains as published
from .parameters import LI2023, OMEGA_BOX

FMU_MODEL = "FAFEO"
PHI_1, EPS_1 = -10.0, 10.0  # 000 section 5.2, disk O(-10, 10)


def error_system(fm, F2, G2, theta_1, theta_2, Gamma=np.eye(3)):
    """(M, [A_i], C, B_d) of 000 (20) for a fuzzy model ``fm``; C = I (000 (9))."""
    C = np.eye(3)
    nw = fm.Ad2.shape[0]
    N = 6 + nw
    M = np.eye(N)
    M[3:6, 0:3] = theta_1 * np.asarray(F2) @ C
    M[6:, 0:3] = theta_2 * np.asarray(G2) @ C
    Abar = []
    for i in range(fm.n_rules):
        Ai = np.zeros((N, N))
        Ai[0:3, 0:3] = fm.A[i]
        Ai[0:3, 3:6] = fm.B @ Gamma
        Ai[0:3, 6:] = fm.D2[i]
        Ai[6:, 6:] = fm.Ad2
        Abar.append(Ai)
    Cbar = np.hstack([C, np.zeros((3, N - 3))])
    Bd = np.zeros((N, 6))
    Bd[0:3, 0:3] = fm.B
    Bd[3:6, 3:6] = np.eye(3)
    return M, Abar, Cbar, Bd


def closed_loops(K, F1, G1, F2, G2, theta_1, theta_2, params=LI2023):
    """Per rule: A_cl = M^-1 (A_i - K_i C) and the input matrix M^-1 B_d (000 (19), (21))."""
    fm = fuzzy_model(**params, box=OMEGA_BOX)
    M, Abar, Cbar, Bd = error_system(fm, F2, G2, theta_1, theta_2)
    Mi = np.linalg.inv(M)
    out = []
    for i in range(fm.n_rules):
        Kb = np.vstack([K[i], F1[i], G1[i]])
        out.append(Mi @ (Abar[i] - Kb @ Cbar))
    return out, Mi @ Bd


def verify(K, F1, G1, F2, G2, theta_1, theta_2, gamma_1, phi=PHI_1, eps=EPS_1, params=LI2023) -> dict:
    """Independent checks: each rule's error matrix Hurwitz, inside O(phi, eps), H-inf < gamma_1."""
    Acls, Bt = closed_loops(K, F1, G1, F2, G2, theta_1, theta_2, params)
    rules, holds = [], []
    for r, A in enumerate(Acls, start=1):
        h = hinf_norm(A, Bt, np.eye(A.shape[0]))
        row = {"rule": r, "abscissa": spectral_abscissa(A), "disk_excess": disk_excess(A, phi, eps),
               "hinf": h["norm"], "hinf_peak_frequency": h["peak_frequency"]}
        rules.append(row)
        holds += [(f"rule {r}: Hurwitz", row["abscissa"] < 0), (f"rule {r}: in disk O({phi:g},{eps:g})",
                  row["disk_excess"] < 0), (f"rule {r}: hinf < {gamma_1:g}", row["hinf"] < gamma_1)]
    rep = {"gamma_1": float(gamma_1), "disk": [phi, eps], "rules": rules,
           "max_hinf": max(r["hinf"] for r in rules), "max_abscissa": max(r["abscissa"] for r in rules),
           "max_disk_excess": max(r["disk_excess"] for r in rules), "holds": dict(holds)}
    rep.update(summarize(holds))
    return rep


def lmi_certificate(K, F1, G1, F2, G2, theta_1, theta_2, gamma_1, phi=PHI_1, eps=EPS_1, which=("23", "24"),
                    params=LI2023, scale=(3e-3, 0.1), margin=1e-7, rules=None):
    """Is there a common P > 0 making (23) [with gamma_1] and/or (24) hold for these fixed gains?

    ``rules``: subset of rule numbers (1-based), default all.
    Returns {"feasible": bool, "message": str}. (A per-rule failure of the disk or the
    H-infinity bound makes it infeasible; feasibility is stronger than the per-rule checks.)
    """
    Acls, Bt = closed_loops(K, F1, G1, F2, G2, theta_1, theta_2, params)
    N = Acls[0].shape[0]
    T = np.diag([scale[0]] * 3 + [1.0] * 3 + [scale[1]] * (N - 6))
    Ti = np.linalg.inv(T)
    p = lmi.LMIProblem(f"000 Theorem 1 ({', '.join(which)}) with fixed gains")
    P = p.symmetric("P", N)
    p.positive_definite("P > 0", P, margin)
    for r, A in enumerate(Acls, start=1):
        if rules is not None and r not in rules:
            continue
        Ah, Bh = Ti @ A @ T, Ti @ Bt
        S = P @ Ah
        if "23" in which:
            p.negative_definite("(23)", lmi.sym_blocks([[S + S.T + T.T @ T, P @ Bh],
                                                        [None, -gamma_1**2 * np.eye(Bh.shape[1])]]), margin, rule=r)
        if "24" in which:
            p.negative_definite("(24)", lmi.sym_blocks([[-P, S - phi * P], [None, -eps**2 * P]]), margin, rule=r)
    return lmi.feasibility(p, "common P found")


def published_gains():
    g = published
    return {"K": g.K, "F1": g.F1, "G1": g.G1, "F2": g.F2, "G2": g.G2, "theta_1": g.THETA_1,
            "theta_2": g.THETA_2, "gamma_1": g.GAMMA_1}


def design(phi=PHI_1, eps=EPS_1, F2=None, G2=None, theta_1=None, theta_2=None, params=LI2023,
           scale=(3e-3, 0.1), margin=1e-6) -> dict:
    """Minimise gamma_1 subject to 000 (23)-(24) for all rules; verify; returns the result (``ftcsim design``
    writes it)."""
    pub = published_gains()
    F2 = pub["F2"] if F2 is None else np.asarray(F2, float)
    G2 = pub["G2"] if G2 is None else np.asarray(G2, float)
    theta_1 = pub["theta_1"] if theta_1 is None else float(theta_1)
    theta_2 = pub["theta_2"] if theta_2 is None else float(theta_2)
    fm = fuzzy_model(**params, box=OMEGA_BOX)
    M, Abar, Cbar, Bd = error_system(fm, F2, G2, theta_1, theta_2)
    Mi = np.linalg.inv(M)
    N = M.shape[0]
    T = np.diag([scale[0]] * 3 + [1.0] * 3 + [scale[1]] * (N - 6))
    Ti = np.linalg.inv(T)
    Bh, Ch = Ti @ Mi @ Bd, Cbar @ T
    p = lmi.LMIProblem("000 Theorem 1 (23)-(24)")
    P = p.symmetric("P", N)
    g = p.scalar("gamma_1_sq")
    Ys = [p.matrix(f"Y{r}", N, 3) for r in range(1, fm.n_rules + 1)]
    p.positive_definite("Q > 0", P, margin)
    for r in range(fm.n_rules):
        Ah = Ti @ Mi @ Abar[r] @ T
        S = P @ Ah - Ys[r] @ Ch  # = P (A~ - L C) in scaled coordinates
        # 000 (23) (congruent form): output e = T e^, hence T^T T in place of I
        p.negative_definite("(23)", lmi.sym_blocks([[S + S.T + T.T @ T, P @ Bh], [None, -g * np.eye(Bh.shape[1])]]),
                            margin, rule=r + 1)
        # 000 (24) via (33) / Lemma 3
        p.negative_definite("(24)", lmi.sym_blocks([[-P, S - phi * P], [None, -eps**2 * P]]), margin, rule=r + 1)
    sol = p.solve(g)
    Pv = sol["P"]
    Kbar = [M @ T @ np.linalg.solve(Pv, sol[f"Y{r}"]) for r in range(1, fm.n_rules + 1)]  # K_i = M T L^_i
    K = np.array([k[0:3] for k in Kbar])
    F1 = np.array([k[3:6] for k in Kbar])
    G1 = np.array([k[6:] for k in Kbar])
    gamma_1 = float(np.sqrt(sol.objective))
    # the paper's own (23)-(24), evaluated with Q = M^-T P~ M^-1, P~ = T^-T P^ T^-1, Y_1i = Q K_i
    Pt = Ti.T @ Pv @ Ti
    Q = Mi.T @ Pt @ Mi
    paper = []
    for r in range(fm.n_rules):
        Y1 = Q @ Kbar[r]
        S = M.T @ Q @ Abar[r] - M.T @ Y1 @ Cbar
        m23 = np.block([[S + S.T + np.eye(N), M.T @ Q @ Bd], [(M.T @ Q @ Bd).T, -gamma_1**2 * np.eye(6)]])
        R24 = -phi * Q @ M + Q @ Abar[r] - Y1 @ Cbar
        m24 = np.block([[-Q, R24], [R24.T, -eps**2 * M.T @ Q @ M]])
        paper.append({"rule": r + 1, "lambda_max_(23)": float(np.linalg.eigvalsh((m23 + m23.T) / 2)[-1]),
                      "lambda_max_(24)": float(np.linalg.eigvalsh((m24 + m24.T) / 2)[-1])})
    ver = verify(K, F1, G1, F2, G2, theta_1, theta_2, gamma_1 * (1 + 1e-6), phi, eps, params)
    paper_ok = all(x["lambda_max_(23)"] < 0 and x["lambda_max_(24)"] < 0 for x in paper)
    result = {
        "design": "li2023-observer", "source": "000 Theorem 1, (23)-(24)",
        "settings": {"phi_1": phi, "eps_1": eps, "theta_1": theta_1, "theta_2": theta_2, "F2": F2, "G2": G2,
                     "scaling": {"s_x": scale[0], "s_w": scale[1]}, "margin": margin},
        "performance": {"gamma_1": gamma_1}, "published": {"gamma_1": pub["gamma_1"]},
        "gains": {"K": K, "F1": F1, "G1": G1},
        "solver": sol.solver, "status": sol.status, "versions": sol.record["versions"],
        "tolerances": sol.record["tolerances"], "lmi_checks": sol.record["checks"],
        "paper_lmis_(23)_(24)": paper, "verify": ver,
        "checks_passed": bool(ver["all_hold"] and paper_ok),
        "fmu_parameters": {FMU_MODEL: {**structured_values("K", K), **structured_values("F1", F1), **structured_values("G1", G1),
                                       **structured_values("F2", F2), **structured_values("G2", G2),
                                       "theta_1": theta_1, "theta_2": theta_2}},
    }
    if not result["checks_passed"]:
        raise lmi.LMIUnverified("000 Theorem 1 design fails independent verification: "
                                + ", ".join(ver["failed"] or ["paper form of (23)/(24)"]), result)
    return result


# -- `ftcsim design li2023-observer` / `ftcsim verify li2023-observer` -----------------------------
def run_design(phi=None, eps=None):
    """Design with the given disk (defaults 000 section 5.2); returns (result, one-line summary)."""
    kw = {k: v for k, v in (("phi", phi), ("eps", eps)) if v is not None}
    r = design(**kw)
    return r, f"gamma_1 = {r['performance']['gamma_1']:.4f} (000 A.1: {r['published']['gamma_1']}); solver {r['solver']}"


def gains_from_file(get) -> dict:
    """The gain set of a file written by :func:`design`; ``get(dotted, shape)`` reads and checks a field."""
    return {"K": get("gains.K", (8, 3, 3)), "F1": get("gains.F1", (8, 3, 3)), "G1": get("gains.G1", (8, 8, 3)),
            "F2": get("settings.F2", (3, 3)), "G2": get("settings.G2", (8, 3)),
            "theta_1": get("settings.theta_1", ()), "theta_2": get("settings.theta_2", ()),
            "gamma_1": get("performance.gamma_1", ()) * (1 + 1e-6)}


def verify_report(gains=None, source="000 Appendix A.1 (published)"):
    """(all hold, title, {check: holds}) for a gain set (default: the published A.1 gains)."""
    g = published_gains() if gains is None else gains
    rep = verify(**g)
    title = (f"verify li2023-observer ({source}): gamma_1 = {g['gamma_1']:.4f}, max H-inf = {rep['max_hinf']:.4f}, "
             f"max disk excess = {rep['max_disk_excess']:.4g}")
    return rep["all_hold"], title, rep["holds"]
