"""Paper 004's reproduction table: section 4 (c2 values, gains, Figs. 1-6) next to ours.

``rows(runs, study)``: ``runs`` maps a scenario name to a run with ``column``/``vector`` (the report's),
``study`` is the c2 study (:mod:`papers.p004_xu2024.c2_study`: Theorem 2 minimised under the readings
of the averaging factor of (45) and alpha, one and three modes; stored in ``c2_study.json`` with its
command, recomputed in part by the tests). Readings:

* c2: "printed /2" is (45) with the printed averaging factor, "rigorous /4" the average of the four
  Omega terms (ours, R10). alpha is not printed in 004 (ours 0.1, chosen; 0.02 is fitted: the value that
  brings c2 to the printed order). eps2 = +0.1 (the printed -0.1 is infeasible by a proof, R13), so every
  c2 is a variant and the literal reading gives no c2 at all.
* state responses: the printed network (M_s = 0, no feedback), the published gains as printed and
  with the documented sign fix (R8b), our Theorem-2 gains on the T-S plant (004's figures) and on the
  nonlinear flexible plant.
"""
from __future__ import annotations

import numpy as np

from papers.reproduction import PRINTED, VARIANT, Row, above, at_most, below, close, fmt, impossible, missing

from . import parameters as P

PRINTED_C2 = {"one_mode": P.PUBLISHED_C2["one_mode"], "three_homogeneous": P.PUBLISHED_C2["three_modes"]}
C2_READINGS = (  # (study label, how alpha was set): every one with eps2 = +0.1, a variant
    ("printed /2, alpha = 0.1", "alpha = 0.1 chosen"), ("printed /2, alpha = 0.02", "alpha = 0.02 fitted to the printed c2"),
    ("rigorous /4, alpha = 0.1", "alpha = 0.1 chosen"), ("rigorous /4, alpha = 0.02", "alpha = 0.02 fitted to the printed c2"),
)
EPS2_PRINTED = -0.1  # 004 section 4
DECREASE = -1e-3  # "lower": a relative change of c2 below -0.1 % (the LMI solves agree to ~1e-6 relative)
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


def rows(runs: dict, study: dict | None = None) -> list:
    """The reproduction rows; ``study``: the c2 study (default: the stored ``c2_study.json``)."""
    from .c2_study import load
    from .design import case_setup, eps2_certificate, local_abscissae
    from .gains import DESIGNED, published_tensor

    study = load() if study is None else study

    out = []
    # Fig. 1: Remark 3's rates under a random alpha (12)-(13)
    from plant.markov import ALPHA_RANDOM, AlphaProfile

    prof = AlphaProfile(ALPHA_RANDOM, 2, grid=0.1, seed=0)
    a = np.array([prof(x) for x in np.linspace(0, 10, 2001)])
    p12, p21 = 3 * a[:, 0] + 4 * a[:, 1], 2 * a[:, 0] + 3 * a[:, 1]
    excursion = float(max((3 - p12).max(), (p12 - 4).max(), (2 - p21).max(), (p21 - 3).max()))
    item = "Fig. 1: transition rates pi_12(t), pi_21(t) of Remark 3 under a random alpha"
    out.append(impossible(item, "in [3, 4], [2, 3]", "unprinted parameter",
                          "004's random alpha was 'generated using MATLAB': its draws are not printed."))
    out.append(Row(item, 0.0, excursion, at_most(0.0, 1.0),
                   "alpha_1 uniform on [0, 1] per 0.1 s cell, seed 0 (004: 'generated using MATLAB')",
                   f"pi_12 in [{fmt(p12.min())}, {fmt(p12.max())}], pi_21 in [{fmt(p21.min())}, {fmt(p21.max())}]; ours: the "
                   "largest excursion outside the bands.", VARIANT, paper_text="in [3, 4], [2, 3]",
                   consistent="true by construction: any alpha in [0, 1] gives rates in the bands"))
    # Figs. 2-3: memberships
    from plant.fuzzy import TriangularProduct

    m = TriangularProduct(P.MEMBERSHIP["z_half_width"], P.RULE_PEAKS["matched"], P.MEMBERSHIP["z_slope"])
    worst = 0.0
    for j, b in ((0, 1.0), (3, 0.55)):
        for xi in np.linspace(-b, b, 401):
            worst = max(worst, abs(float(m.per_variable(np.full(6, xi))[:, j].sum()) - 1.0))
    out.append(Row("Figs. 2-3: triangular memberships on [-1, 1] and [-0.55, 0.55]", 1e-9, worst, at_most(0.0, 1.0),
                   "as printed (slope 1.818)", f"Max |M^1 + M^2 + M^3 - 1| over the domains {worst:.2g}; M^1(+-0.55) = "
                   f"{1 - 1.818 * 0.55:.1g} (1.818 printed, 1/0.55 = 1.8181...).", PRINTED,
                   paper_text="M^1 + M^2 + M^3 = 1"))
    # Fig. 4: d(t)
    diff, note = None, missing("xu2024_ts")
    if "xu2024_ts" in runs:
        r = runs["xu2024_ts"]
        diff = float(np.abs(r.vector("dist.y") - printed_disturbance(r.time)).max())
        note = (f"Max |d recorded (Xu2024Disturbance FMU) - d printed| over the run {diff:.2g} N.m: an input the scenario "
                "defines from the printed formula.")
    out.append(Row("Fig. 4: disturbance d(t)", 1e-12, diff, at_most(0.0, 1.0), "as printed (cos(0.06 t) kept)", note,
                   PRINTED, paper_text="printed formula", consistent="an input defined from the printed formula"))
    # Figs. 5-6: state responses
    s = case_setup("three_homogeneous")
    ab = float(local_abscissae(published_tensor(), s).max())
    item = "Figs. 5-6: the closed loop converges"
    out.append(Row(item, 0.0, ab, below(), "as printed: published K_rj (K23 read as K32, rule 3 copied from rule 2), M_s = I",
                   f"Largest real part over the local loops A_j + B F_r K_rj: {ab:+.3g} 1/s (K21, K31 destabilise A_1; "
                   "every rule-2 gain is unstable at P2); ours: that real part.", PRINTED, unit="1/s",
                   paper_text="converges (ours: local abscissa < 0)"))
    for name, label, kind, what in (
            ("xu2024_network_printed", "as printed: Theta, L of section 4 (M_s = I^T (Theta x I) L = 0)", PRINTED,
             "the printed network applies no feedback"),
            ("xu2024_ts_published", "published K_rj with the documented sign fix (R8b)", VARIANT, "sign-fixed published gains"),
            ("xu2024_ts", "our Theorem-2 gains (alpha = 0.1, /4, eps2 = +0.1), T-S plant", VARIANT, "our gains"),
            ("xu2024_flexible", "our Theorem-2 gains, nonlinear flexible plant, Gibbs q(0)", VARIANT, "our gains")):
        ratio, note = None, missing(name)
        if name in runs:
            r = runs[name]
            n = state_norm(r)
            ratio = float(n[-1] / n[0])
            u = np.abs(r.vector("ctrl.u")).max()
            note = (f"|x| {fmt(n[0])} -> {fmt(n[-1])} at {r.time[-1]:.0f} s ({what}); max |u| {fmt(u)} N.m. Ours: "
                    "|x(end)| / |x(0)|, converged read as at most 1 %.")
        out.append(Row(item, CONVERGED, ratio, at_most(0.0, 1.0), label, note, kind,
                       paper_text="converges (ours: |x(end)| <= 1 % of |x(0)|)"))
    # the published gains themselves
    Kp, Kd = published_tensor(sign_fix=True), np.asarray(DESIGNED["K"])
    ratio = float(np.linalg.norm(Kd[0, 0]) / np.linalg.norm(Kp[0, 0]))
    item = "Theorem 2 gains K_11 (section 4)"
    out.append(impossible(item, "printed K_11", "unprinted parameter",
                          "004 does not print alpha, T, c1, H, tau_M, w_bar (ours: README), and (45)-(50) is a feasibility "
                          "problem (non-unique output): the gains cannot be recomputed."))
    out.append(Row(item, 1.0, ratio, close(), "our Theorem-2 design, nonhomogeneous case",
                   "||K_11 ours|| / ||K_11 published|| (Frobenius).", VARIANT))
    # printed scalars: eps2 = -0.1
    out.append(Row("Theorem 2 feasible with the printed gamma = 0.1, eps1 = 1, eps2 = -0.1", 0.0, EPS2_PRINTED, above(),
                   "as printed", eps2_certificate(EPS2_PRINTED) + ". Ours: the printed eps2; (45)-(47) need eps2 > 0.",
                   PRINTED, paper_text="feasible (ours: eps2 > 0)"))
    # c2, one mode
    literal_c2 = ("The printed eps2 = -0.1 makes (45)-(47) infeasible (a proof, see the row above), so the printed "
                  "parameters give no c2; ours: the printed eps2, against the eps2 > 0 that any c2 needs.")
    for case, item in (("one_mode", "Theorem 2: c2 = 6.0114 (Case I, one mode)"),):
        out.append(Row(item, 0.0, EPS2_PRINTED, above(), "as printed: eps2 = -0.1, alpha not printed", literal_c2, PRINTED,
                       paper_text="6.0114 (ours: a c2 exists, eps2 > 0)", ours_text="no c2 (eps2 = -0.1)"))
        for label, how in C2_READINGS:
            d = (study or {}).get("designs", {}).get(f"{label} | {case}")
            note = ("The c2 study is not stored (python -m papers.p004_xu2024.c2_study)." if d is None else
                    f"Min c2 of (45)-(50) (eps2 = +0.1), every LMI verified ({d['n_lmi']}), gains verified: "
                    f"{d['verify_all_hold']}; mu = {', '.join(f'{x:.3g}' for x in d['mu'])}; lower bound "
                    f"e^(alpha T)(c1 + gamma^2 w_bar) = {d['c2_lower_bound']:.3g}.")
            if d is not None and "/2" in label:
                note += " The '/2' is printed but is not a rigorous relaxation (README R10)."
            out.append(Row(item, PRINTED_C2[case], None if d is None else d["c2"], close(),
                           f"{label.split(',')[0]}, {how}, eps2 = +0.1 (printed -0.1)", note, VARIANT))
    # mode-count claim (5.7741 < 6.0114): a claimed decrease
    item = "Theorem 2: three modes lower c2 (5.7741 < 6.0114, a 3.9 % decrease)"
    out.append(Row(item, DECREASE, 0.0, below(), "as printed: eps2 = -0.1",  # no c2 to compare: no decrease
                   literal_c2.replace("give no c2", "give no c2 to compare") + " Ours: a relative change of 0.", PRINTED,
                   paper_text="lower (ours: relative change < -0.1 %)", ours_text="no c2 (eps2 = -0.1)"))
    for label, how in C2_READINGS:
        c1_, c3_ = ((study or {}).get("designs", {}).get(f"{label} | {c}") for c in ("one_mode", "three_homogeneous"))
        change = None if not (c1_ and c3_) else (c3_["c2"] - c1_["c2"]) / c1_["c2"]
        out.append(Row(item, DECREASE, change, below(), f"{label.split(',')[0]}, {how}, eps2 = +0.1 (printed -0.1)",
                       ("The c2 study is not stored." if change is None else
                        f"Relative change of c2 from one to three modes: {change:+.1e} (c2 = {fmt(c1_['c2'])} -> "
                        f"{fmt(c3_['c2'])}); 'lower' read as below -0.1 %. The mode-dependent gains give B F_r K_r = B K_1 "
                        "for every f > 0 and the bias of mode 3 only enters gamma^2 w_bar, so c2 does not depend on the "
                        "number of modes."), VARIANT, paper_text="lower (ours: relative change < -0.1 %)"))
    out.append(impossible("section 4: c2 = 6.0114 > 5.4 of ref. [24] shows superiority", 5.4, "missing law or baseline",
                          "ref. [24]'s theorem is not available; and c2 is an upper bound that (50) lets grow freely above "
                          "its minimum, so a larger c2 is a weaker guarantee (README R21)."))
    return out
