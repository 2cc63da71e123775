"""Paper 002's reproduction table: every result of its section 4 (Tables 1-2, Figs. 1-2) next to ours.

``rows(runs)``: ``runs`` maps a scenario name to ``(RunResult, [metrics] table, metrics dict)`` (what
``report.make_report`` has); the LMI items are computed here from Table 1's V1, W with
:mod:`papers.p002_zhang2014.design` (small 2x2 LMIs, a few seconds). The verdicts follow from the
numbers with the rules of :mod:`papers.reproduction`.

What each printed item is checked against (002 prints no simulated number):

* Table 1 (V1, W per omega_hat): a solution of (22)? As printed, Lemma 1 with L^T L <= I puts the
  effectiveness 0 in the interval, where the plant has no input and no gain is stabilising, so (22)
  cannot hold (measured: the spectral abscissa of A + B 0 K is 0, not below 0). Under |L| <= j = 0.75
  (a variant: j is chosen below the largest j, 0.78, at which the published V1, W are feasible) they
  satisfy (22), which therefore cannot fail there.
* Table 2 K: K = W V1^-1 from Table 1 (rounding of the printed V1).
* Table 2 J*: (22) is a feasibility problem, so J* = x0^T V1^-T P_hat V1^-1 x0 is whatever P_hat the
  solver returned: the printed value cannot be recomputed, only checked for being certified by the
  published V1, W. As printed nothing is certified; over |L| <= 0.75 the certified J* lie in [min, max]
  and the printed J* is certified only if it is in that range; with L = 0 (no uncertainty) every J*
  from about 0.5 to 18 is certified, so that check cannot discriminate (consistent, not counted). From
  the run, the guaranteed-cost claim J_c <= J* (002 (13)).
* Figs. 1-2: "the response performance can be guaranteed": |theta| at the end of the 100 s run
  within 2 % of theta(0) for each omega_hat; Fig. 2's "control effect" omega u within 10 % across
  omega_hat is our reading of a figure without data (documented reading).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

import lmi
from lmi.search import grid_then_golden
from lmi.verify import spectral_abscissa
from papers.reproduction import PRINTED, READING, VARIANT, Row, at_least, at_most, below, close, fmt, impossible
from plant.pitch_axis import rigid_model

from .design import PUBLISHED_J, lmi22, verify
from .gains import CASES, PUBLISHED
from .parameters import X0, ZHANG2014

SCENARIO = {1.0: "zhang2014_hinf_w1", 0.5: "zhang2014_hinf_w05", 0.2: "zhang2014_hinf_w02"}
KAPPAS = tuple(float(k) for k in np.logspace(-1, 1.5, 6))


def _certified_J(omega_hat, kappa, j, fix=None, sense=1.0):
    """The smallest (``sense`` = 1) or largest (-1) J* over P_hat, delta for Table 1's V1, W at kappa
    (``fix``: is J* == fix feasible? returns it or None); None if no verified point."""
    pub = PUBLISHED[omega_hat]
    p, P, _, _ = lmi22(omega_hat, kappa, j, V1=pub["V1"], W=pub["W"])
    c = np.linalg.inv(np.asarray(pub["V1"])) @ np.asarray(X0, float)
    J = c @ P @ c
    if fix is not None:
        p.constrain(J == fix)
    try:
        sol = p.solve(None if fix is not None else sense * J, solvers=("CLARABEL",))
    except lmi.LMIError:
        return None
    return float(c @ sol["P_hat"] @ c)


def published_certificate(omega_hat, j=PUBLISHED_J, kappas=KAPPAS, refine=6) -> dict:
    """What Table 1's V1, W certify in (22) (P_hat, delta free; kappa: grid, then golden section for the
    minimum): the smallest J* over |L| <= j, the range [min, max] of certified J* over the grid, and
    whether the printed J* is certified, over |L| <= j and with no uncertainty (j = 0: omega = omega_hat,
    as in 002's simulations), each confirmed by a solve with J* fixed to the printed value."""
    seen = {}

    def value(k):
        v = _certified_J(omega_hat, k, j)
        seen[k] = v
        return math.inf if v is None else v

    k_best, J_min, _ = grid_then_golden(value, kappas, iterations=refine)
    printed = float(PUBLISHED[omega_hat]["J_star"])
    J_max = max((v for v in (_certified_J(omega_hat, k, j, sense=-1.0) for k in kappas) if v is not None), default=None)
    J_max0 = max((v for v in (_certified_J(omega_hat, k, 0.0, sense=-1.0) for k in kappas) if v is not None), default=None)

    def certified(jj):
        for k in kappas:  # the certified J* at one kappa form an interval: check it, then confirm with J* fixed
            lo, hi = _certified_J(omega_hat, k, jj), _certified_J(omega_hat, k, jj, sense=-1.0)
            if lo is not None and hi is not None and lo <= printed <= hi:
                v = _certified_J(omega_hat, k, jj, fix=printed)
                if v is not None and abs(v - printed) <= 1e-6 * printed:
                    return float(k)
        return None

    return {"omega_hat": float(omega_hat), "j": float(j), "kappa": float(k_best),
            "J_star_min": J_min if math.isfinite(J_min) else None, "J_star_max_grid": J_max, "J_star_max_nominal": J_max0,
            "printed_J_star": printed, "printed_certified_kappa": certified(j),
            "printed_certified_kappa_nominal": certified(0.0),
            "kappa_search": {f"{k:.6g}": v for k, v in sorted(seen.items())}}


def literal_interval_admits_zero_effectiveness(omega_hat) -> bool:
    """002's Lemma 1 with L^T L <= I: omega = omega_hat (1 + L) reaches 0, where A + B omega K = A is
    not Hurwitz for any K; True when that is so (then (22) as printed cannot hold)."""
    A, B, _ = rigid_model(ZHANG2014["J"], ZHANG2014["F"])
    K = np.asarray(PUBLISHED[omega_hat]["K"], float).reshape(1, 2)
    return bool(spectral_abscissa(A + B * (omega_hat * (1 - 1.0)) @ K) >= 0)


def _k_rounding(omega_hat) -> float:
    p = PUBLISHED[omega_hat]
    K1 = (np.asarray(p["W"]) @ np.linalg.inv(p["V1"])).ravel()
    K2 = np.asarray(p["K"], float).ravel()
    return float(np.max(np.abs(K1 - K2) / np.abs(K2)))


STUDY = Path(__file__).with_name("certificate_study.json")  # written by papers/p002_zhang2014/certificate_study.py


def load_certificates() -> dict | None:
    """omega_hat -> :func:`published_certificate`, from the stored study (None if the file is missing)."""
    if not STUDY.is_file():
        return None
    data = json.loads(STUDY.read_text(encoding="utf-8"))
    return {float(k): v for k, v in data["certificates"].items()}


def _abscissa_at_zero(omega_hat) -> float:
    """The spectral abscissa of A + B omega K at omega = omega_hat (1 + L) with L = -1 (the end of Lemma 1's
    L^T L <= I): 0 for every K (the plant has no input there), so (22) as printed cannot hold."""
    A, B, _ = rigid_model(ZHANG2014["J"], ZHANG2014["F"])
    K = np.asarray(PUBLISHED[omega_hat]["K"], float).reshape(1, 2)
    return float(spectral_abscissa(A + B * (omega_hat * (1 - 1.0)) @ K))


def rows(runs: dict, certificates: dict | None = None) -> list:
    """The reproduction rows (``certificates``: omega_hat -> :func:`published_certificate`; when not given, the
    stored study of :mod:`papers.p002_zhang2014.certificate_study`, computed if it is missing)."""
    if certificates is None:
        certificates = load_certificates() or {w: published_certificate(w) for w in CASES}
    hinf = {w: verify(np.asarray(PUBLISHED[w]["K"]), PUBLISHED[w]["J_star"], w, PUBLISHED_J, simulate_cost=False)
            for w in CASES}
    literal = "as printed: L^T L <= I (omega in [0, 2 omega_hat])"
    zero_note = ("The abscissa of A + B omega K at omega = 0, the end of the interval Lemma 1's L^T L <= I allows: the "
                 "plant has no input there, so no gain is stabilising and (22) as printed cannot hold.")
    j_label = f"|L| <= j = {PUBLISHED_J:g} (j chosen below 0.78, the largest j at which Table 1 is feasible)"
    out = []
    for w in CASES:
        cert = certificates[w]
        a0 = _abscissa_at_zero(w)
        out.append(Row(f"Table 1: (V1, W), omega_hat = {w:g}, solve (22)", 0.0, a0, below(), literal, zero_note, PRINTED,
                       unit="1/s", paper_text="a solution of (22) (ours: abscissa < 0 over the interval)"))
        out.append(Row(f"Table 1: (V1, W), omega_hat = {w:g}, solve (22)", 0.0, cert["J_star_min"], below(), j_label,
                       f"P_hat, delta free, kappa searched: feasible at kappa = {cert['kappa']:.3g} (ours: the smallest "
                       f"certified J*, {fmt(cert['J_star_min'])}; None: infeasible).", VARIANT,
                       paper_text="a solution of (22)", ours_text="feasible" if cert["J_star_min"] is not None else "infeasible",
                       consistent="j was chosen so that Table 1 is feasible"))
    for w in CASES:
        K1 = (np.asarray(PUBLISHED[w]["W"]) @ np.linalg.inv(PUBLISHED[w]["V1"])).ravel()
        out.append(Row(f"Table 2: K, omega_hat = {w:g}", 1.0, 1.0 + _k_rounding(w), close(),
                       "as printed: K = W V1^-1 of Table 1", f"W V1^-1 = [{K1[0]:.4f}, {K1[1]:.4f}] against K = "
                       f"{PUBLISHED[w]['K'][0]}; ours = 1 + max relative entry difference (V1 printed with 4 decimals).",
                       PRINTED))
    for w in CASES:
        cert = certificates[w]
        kp, kn = cert["printed_certified_kappa"], cert["printed_certified_kappa_nominal"]
        item = f"Table 2: J*, omega_hat = {w:g}"
        out.append(Row(item, 0.0, _abscissa_at_zero(w), below(), literal,
                       zero_note + " So it certifies no J* (the printed one is the output of a feasibility problem and "
                       "cannot be recomputed, only checked for being certified).", PRINTED, unit="1/s",
                       paper_text=f"J* = {cert['printed_J_star']:g} (ours: (22) feasible, abscissa < 0)",
                       ours_text="no J* certified (abscissa 0)"))
        out.append(Row(item, cert["printed_J_star"], cert["J_star_max_grid"], at_least(0.0, 1.0), j_label,
                       f"With Table 1's V1, W and |L| <= {cert['j']:g} the certified J* lie in [{fmt(cert['J_star_min'])}, "
                       f"{fmt(cert['J_star_max_grid'])}] (kappa searched); the printed J* is certified only if it is at most "
                       "the largest: " + ("not certified." if kp is None else f"certified (kappa = {kp:.3g})."), VARIANT,
                       paper_text=f"{cert['printed_J_star']:g} (ours: the largest certified J*)"))
        out.append(Row(item, cert["printed_J_star"], cert.get("J_star_max_nominal"), at_least(0.0, 1.0),
                       "L = 0: omega = omega_hat, no uncertainty (as simulated)",
                       "Solve of (22) with J* fixed to the printed value: " +
                       (f"feasible at kappa = {kn:.3g}" if kn is not None else "infeasible at every kappa of the grid") +
                       f". With L = 0 every J* up to {fmt(cert.get('J_star_max_nominal'))} is certified, so the check cannot "
                       "tell a right J* from a wrong one.", VARIANT,
                       paper_text=f"{cert['printed_J_star']:g} (ours: the largest certified J*)",
                       consistent="at L = 0 Table 1's V1, W certify any J* from about 0.5 to 18"))
    for w in CASES:
        name = SCENARIO[w]
        run = runs.get(name)
        m = run[2] if run else None
        cert = certificates[w]
        jc = m["J_c"] if m else None
        txt = None if jc is None else (f"J_c = {jc:.4g}: J_c/J*(printed) = {jc / cert['printed_J_star']:.3g}"
                                       + (f", J_c/J*(min) = {jc / cert['J_star_min']:.3g}" if cert["J_star_min"] else ""))
        out.append(Row(f"Table 2 / (13): J_c <= J*, omega_hat = {w:g}", cert["printed_J_star"], jc, at_most(0.0, 1.0),
                       "as printed: plant effectiveness = omega_hat from t = 0",
                       f"J_c of 002 (11) summed along {name} (100 s)." if m else f"Run {name} is not among the report's inputs.",
                       PRINTED, ours_text=txt, paper_text=f"J* = {cert['printed_J_star']:g}"))
    for w in CASES:
        name = SCENARIO[w]
        run = runs.get(name)
        ours = None
        note = f"Run {name} is not among the report's inputs."
        if run:
            res, cfg, m = run
            th = res.column(cfg["theta"]) if cfg["theta"] in res.columns else res.vector(cfg["theta"])
            ours = float(abs(th[-1]) / abs(th[0]))
            note = (f"theta(0) = {th[0]:.3g} rad, peak {m['peak_theta']:.4g} rad at {m['t_peak']:.3g} s, |theta| <= 2 % "
                    f"of theta(0) from {m['settling_time_2pct']} s; theta({res.time[-1]:.0f} s) = {th[-1]:.2e} rad. Ours: "
                    "|theta(end)| / |theta(0)|.")
        out.append(Row(f"Fig. 1: theta, theta' converge, omega_hat = {w:g}", 0.02, ours, at_most(0.0, 1.0),
                       "as printed", note, PRINTED, paper_text="response guaranteed (ours: within 2 % of theta(0) at the end)"))
    for w in CASES:
        v = hinf[w]
        item = f"section 4: H-infinity level gamma = 2.5, omega_hat = {w:g}"
        out.append(Row(item, 2.5, np.inf, at_most(0.0, 1.0), literal,
                       "The interval reaches omega = 0, where no gain is stabilising (abscissa of A is 0): ||G||_inf is "
                       "unbounded there.", PRINTED, ours_text="unbounded"))
        out.append(Row(item, 2.5, v["worst"]["hinf"], at_most(0.0, 1.0), f"|L| <= j = {v['j']:g}",
                       f"Worst ||G||_inf of the Table 2 gain over omega in [{v['interval'][0]:.3g}, {v['interval'][1]:.3g}] "
                       f"(rigid (8), C = I, frequency sweep + Hamiltonian bisection); < 2.5 down to omega = "
                       f"{v['omega_min_for_hinf']:.3g}.", VARIANT))
    present = [SCENARIO[w] for w in CASES if SCENARIO[w] in runs]
    ours, note = None, "Needs the runs of all three omega_hat."
    if len(present) == len(CASES):
        tau0 = [runs[n][2]["tau0"] for n in present]
        u0 = [runs[n][2]["u0"] for n in present]
        ours = (max(tau0) - min(tau0)) / abs(np.mean(tau0))
        note = (f"u(0) = {', '.join(f'{x:.4g}' for x in u0)} N.m scales as 1/omega_hat; the applied torque omega u(0) = "
                f"{', '.join(f'{x:.4g}' for x in tau0)} N.m: ours is their spread over the mean (omega_hat K is the same "
                "loop).")
    item = "Fig. 2: control effect for omega_hat = 0.2, 0.5, 1"
    out.append(impossible(item, "figure", "figure data not in the published text",
                          "002 prints the figure's curves, not their values, and states no number for them."))
    out.append(Row(item, 0.10, ours, at_most(0.0, 1.0), "applied torque omega u within 10 % across omega_hat (our reading "
                   "of the figure)", note, READING, paper_text="response guaranteed (ours: spread <= 10 %)"))
    return out


__all__ = ["rows", "published_certificate", "literal_interval_admits_zero_effectiveness"]
