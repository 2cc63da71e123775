"""Paper 004's reproduction table: section 4 (c2 values, gains, Figs. 1-6) next to ours.

``rows(runs, study)``: ``runs`` maps a scenario name to a run with ``column``/``vector`` (the report's),
``study`` is the c2 study (:mod:`papers.p004_xu2024.c2_study`: Theorem 2 minimised under the readings
of the averaging factor of (45) and alpha, one and three modes; stored in ``c2_study.json`` with its
command, recomputed in part by the tests). Readings:

* c2: "printed /2" is (45) with the printed averaging factor, "rigorous /4" the average of the four
  Omega terms (ours, R10). alpha is not printed in 004 (ours 0.1; 0.02 is the value that brings c2 to
  the printed order). eps2 = +0.1 (the printed -0.1 is infeasible by a proof, R13).
* state responses: the printed network (M_s = 0, no feedback), the published gains as printed and
  with the documented sign fix (R8b), our Theorem-2 gains on the T-S plant (004's figures) and on the
  nonlinear flexible plant.
"""
from __future__ import annotations

import numpy as np

from papers.reproduction import Row, claim, close, fmt, missing, not_attempted

from . import parameters as P

PRINTED_C2 = {"one_mode": P.PUBLISHED_C2["one_mode"], "three_homogeneous": P.PUBLISHED_C2["three_modes"]}
C2_READINGS = (  # (study label, literal?)
    ("printed /2, alpha = 0.02", True), ("printed /2, alpha = 0.1", True),
    ("rigorous /4, alpha = 0.1", False), ("rigorous /4, alpha = 0.02", False),
)
CONVERGED = 0.01  # |x(end)| <= 1 % of |x(0)| (ours)


def printed_disturbance(t):
    """004's d(t), section 4, written out independently of plant/multisine.py (N.m)."""
    t = np.asarray(t, float)
    return np.column_stack([-0.2 + 0.1 * np.cos(0.06 * t) - 0.1 * np.cos(0.8 * t),
                            0.2 + 0.2 * np.sin(0.6 * t) - 0.1 * np.cos(0.4 * t),
                            -0.2 + 0.15 * np.sin(0.5 * t) - 0.1 * np.sin(0.8 * t)])


def state_norm(r):
    return np.linalg.norm(np.hstack([r.vector("plant.omega"), r.vector("plant.q")[:, 1:4]]), axis=1)


def initial_torques() -> dict:
    """|K x(0)| for the published (sign-fixed) and our gains, mode 1, rule 1, on the printed x(0) (T-S
    plant, x in R^6) and on the flexible plant's x(0) (Gibbs reading of the q part), with the initial
    momentum |J omega(0)|."""
    from .gains import DESIGNED, published_tensor

    x_ts = P.X0_PRINTED
    q = P.x0_gibbs_quaternion()
    x_fl = np.concatenate([P.X0_PRINTED[:3], q[1:4]])
    out = {"momentum_J_omega0": float(np.linalg.norm(P.XU2024["J"] @ P.X0_PRINTED[:3]))}
    for label, K in (("published (sign fix)", published_tensor(sign_fix=True)), ("ours (Theorem 2)", np.asarray(DESIGNED["K"]))):
        out[label] = {"ts": float(np.linalg.norm(K[0, 0] @ x_ts)), "flexible": float(np.linalg.norm(K[0, 0] @ x_fl)),
                      "ts_max_abs": float(np.abs(K[0, 0] @ x_ts).max()), "flexible_max_abs": float(np.abs(K[0, 0] @ x_fl).max())}
    return out


def rows(runs: dict, study: dict | None) -> list:
    from .design import case_setup, eps2_certificate, local_abscissae
    from .gains import DESIGNED, published_tensor

    out = []
    # Fig. 1: Remark 3's rates under a random alpha (12)-(13)
    from plant.markov import ALPHA_RANDOM, AlphaProfile

    prof = AlphaProfile(ALPHA_RANDOM, 2, grid=0.1, seed=0)
    a = np.array([prof(x) for x in np.linspace(0, 10, 2001)])
    p12, p21 = 3 * a[:, 0] + 4 * a[:, 1], 2 * a[:, 0] + 3 * a[:, 1]
    ok = bool(np.all((p12 >= 3 - 1e-12) & (p12 <= 4 + 1e-12) & (p21 >= 2 - 1e-12) & (p21 <= 3 + 1e-12)))
    out.append(Row("Fig. 1: transition rates pi_12(t), pi_21(t) of Remark 3 under a random alpha", "in [3, 4], [2, 3]",
                   ok, claim(), "alpha_1 uniform on [0, 1] per 0.1 s cell, seed 0 (004: 'generated using MATLAB')",
                   f"pi_12 in [{fmt(p12.min())}, {fmt(p12.max())}], pi_21 in [{fmt(p21.min())}, {fmt(p21.max())}]; the "
                   "random alpha itself cannot be reproduced", literal=False))
    # Figs. 2-3: memberships
    from plant.fuzzy import TriangularProduct

    m = TriangularProduct(P.MEMBERSHIP["z_half_width"], P.RULE_PEAKS["matched"], P.MEMBERSHIP["z_slope"])
    worst = 0.0
    for j, b in ((0, 1.0), (3, 0.55)):
        for xi in np.linspace(-b, b, 401):
            worst = max(worst, abs(float(m.per_variable(np.full(6, xi))[:, j].sum()) - 1.0))
    out.append(Row("Figs. 2-3: triangular memberships on [-1, 1] and [-0.55, 0.55]", "M^1 + M^2 + M^3 = 1", worst <= 1e-12,
                   claim(), "as printed (slope 1.818)", f"max |sum - 1| over the domains {worst:.2g}; M^1(+-0.55) = "
                   f"{1 - 1.818 * 0.55:.1g} (1.818 printed, 1/0.55 = 1.8181...)"))
    # Fig. 4: d(t)
    ok, note = None, missing("xu2024_ts")
    if "xu2024_ts" in runs:
        r = runs["xu2024_ts"]
        diff = float(np.abs(r.vector("dist.y") - printed_disturbance(r.time)).max())
        ok = diff <= 1e-12
        note = f"max |d recorded (Xu2024Disturbance FMU) - d printed| over the run {diff:.2g} N.m"
    out.append(Row("Fig. 4: disturbance d(t)", "printed formula", ok, claim(), "as printed (cos(0.06 t) kept)", note))
    # Figs. 5-6: state responses
    s = case_setup("three_homogeneous")
    ab = float(local_abscissae(published_tensor(), s).max())
    out.append(Row("Figs. 5-6: the closed loop converges", "converges", ab < 0, claim(),
                   "as printed: published K_rj (K23 read as K32, rule 3 copied from rule 2), M_s = I",
                   f"largest real part over the local loops A_j + B F_r K_rj: {ab:+.3g} 1/s (K21, K31 destabilise A_1; "
                   "every rule-2 gain is unstable at P2)"))
    for name, label, literal, what in (
            ("xu2024_network_printed", "as printed: Theta, L of section 4 (M_s = I^T (Theta x I) L = 0)", True,
             "the printed network applies no feedback"),
            ("xu2024_ts_published", "published K_rj with the documented sign fix (R8b)", False, "sign-fixed published gains"),
            ("xu2024_ts", "our Theorem-2 gains (alpha = 0.1, /4, eps2 = +0.1), T-S plant", False, "our gains"),
            ("xu2024_flexible", "our Theorem-2 gains, nonlinear flexible plant, Gibbs q(0)", False, "our gains")):
        ok, note = None, missing(name)
        if name in runs:
            r = runs[name]
            n = state_norm(r)
            ok = bool(n[-1] <= CONVERGED * n[0])
            u = np.abs(r.vector("ctrl.u")).max()
            note = f"|x| {fmt(n[0])} -> {fmt(n[-1])} at {r.time[-1]:.0f} s ({what}); max |u| {fmt(u)} N.m"
        out.append(Row("Figs. 5-6: the closed loop converges", "converges", ok, claim(), label, note, literal))
    # the published gains themselves
    Kp, Kd = published_tensor(sign_fix=True), np.asarray(DESIGNED["K"])
    ratio = float(np.linalg.norm(Kd[0, 0]) / np.linalg.norm(Kp[0, 0]))
    out.append(Row("Theorem 2 gains K_11 (section 4)", 1.0, ratio, close(), "our Theorem-2 design, nonhomogeneous case",
                   "||K_11 ours|| / ||K_11 published|| (Frobenius); 004 does not print alpha, T, c1, H, tau_M, w_bar "
                   "(ours: README), so the gains cannot match", literal=False))
    # printed scalars: eps2 = -0.1
    out.append(Row("Theorem 2 feasible with the printed gamma = 0.1, eps1 = 1, eps2 = -0.1", "feasible", False, claim(),
                   "as printed", eps2_certificate(-0.1)))
    # c2
    for case, item in (("one_mode", "c2 = 6.0114 (Case I, one mode)"), ("three_homogeneous", "c2 = 5.7741 (three modes)")):
        for label, literal in C2_READINGS:
            d = (study or {}).get("designs", {}).get(f"{label} | {case}")
            note = ("c2 study not stored (python -m papers.p004_xu2024.c2_study)" if d is None else
                    f"min c2 of (45)-(50) (eps2 = +0.1), every LMI verified ({d['n_lmi']}), gains verified: "
                    f"{d['verify_all_hold']}; mu = {', '.join(f'{x:.3g}' for x in d['mu'])}; lower bound "
                    f"e^(alpha T)(c1 + gamma^2 w_bar) = {d['c2_lower_bound']:.3g}")
            if d is not None and literal:
                note += "; alpha is not printed (0.02 brings c2 to the printed order); the '/2' is not a rigorous relaxation"
            out.append(Row(f"Theorem 2: {item}", PRINTED_C2[case], None if d is None else d["c2"], close(),
                           f"{label} (eps2 = +0.1)", note, literal))
    # mode-count invariance (5.7741 < 6.0114)
    diffs = []
    for label, _ in C2_READINGS:
        c1_, c3_ = ((study or {}).get("designs", {}).get(f"{label} | {c}") for c in ("one_mode", "three_homogeneous"))
        if c1_ and c3_:
            diffs.append((label, (c3_["c2"] - c1_["c2"]) / c1_["c2"]))
    out.append(Row("Theorem 2: three modes lower c2 (5.7741 < 6.0114)", "lower", None if not diffs else
                   bool(all(dd < -1e-3 for _, dd in diffs)), claim(), "every reading of the study",
                   "relative change of c2 from one to three modes: " + "; ".join(f"{lab}: {dd:+.1e}" for lab, dd in diffs)
                   + " (the mode-dependent gains give B F_r K_r = B K_1 for every f > 0, and the bias of mode 3 only enters "
                   "gamma^2 w_bar)", literal=False))
    out.append(not_attempted("section 4: c2 = 6.0114 > 5.4 of ref. [24] shows superiority", 5.4,
                             "ref. [24]'s theorem is not available; and c2 is an upper bound that (50) lets grow freely "
                             "above its minimum, so a larger c2 is a weaker guarantee (R21)"))
    return out
