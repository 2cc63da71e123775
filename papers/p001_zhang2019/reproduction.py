"""Paper 001's reproduction table: Table 1 and Figs. 2-8 of its section 5 next to our runs.

``rows(runs)``: ``runs`` maps a scenario name to ``(RunResult, [metrics] table, metrics dict)`` (the
report's). Each row uses one run (one reading, :data:`READINGS`):

* ``zhang2019_fontsm``: as printed (sign(s), full Grünwald-Letnikov memory, printed observer gains,
  the sampled form of (14) with U(t_k); each body rate paired with the angle it drives, which changes
  no printed number, see README);
* variants: ``zhang2019_fontsm_paired`` (observer command_pairing = 1, U(t_k-1) in (14)),
  ``zhang2019_fontsm_smooth`` (boundary layer phi = 0.01 rad/s and 2 s memory, both chosen),
  ``zhang2019_fontsm_fast_observer`` (as _smooth with lambda_1 = lambda_2 = 2000 chosen),
  ``zhang2019_fontsm_accurate`` (phi = 0.005 rad/s, 2 s memory, fast observer, paired).

Table 1's column of this paper is judged under one reading at a time: a row holds its six accuracies
and the verdict is that of the worst entry (no per-axis best-of). 001 defines neither the window of its
"accuracy" nor the band of its "stabilization time" (our definitions: papers/p001_zhang2019/metrics.py):
the accuracy window [30, 60] s is our reading; without a band the 28 s cannot be placed (impossible).
"Accurate estimation" (Fig. 5) is read as an RMS error of the torque-level estimate at most 10 % of the
RMS fault torque over [30, 60] s, and for the effectiveness estimates as |e_hat_j - e_j| at the end at
most 10 % of the 0.4 loss to estimate (our thresholds). Fig. 1 is a block diagram (no result).
"""
from __future__ import annotations

import numpy as np

from papers.reproduction import PRINTED, VARIANT, Row, at_most, close_all, fmt, impossible, missing

AS_PRINTED = "zhang2019_fontsm"
READINGS = {  # scenario -> (reading label, kind)
    "zhang2019_fontsm": ("as printed: sign(s), full memory, printed gains", PRINTED),
    "zhang2019_fontsm_paired": ("as printed + observer command_pairing = 1 (U(t_k-1) in (14), chosen)", VARIANT),
    "zhang2019_fontsm_smooth": ("sat(s/phi), phi = 0.01 rad/s chosen; 2 s memory chosen", VARIANT),
    "zhang2019_fontsm_fast_observer": ("phi = 0.01 rad/s, 2 s memory, lambda_1 = lambda_2 = 2000 chosen", VARIANT),
    "zhang2019_fontsm_accurate": ("phi = 0.005 rad/s, 2 s memory, lambda_1 = lambda_2 = 2000, command_pairing = 1, "
                                  "all chosen", VARIANT),
}
SIGN_RUNS = ("zhang2019_fontsm", "zhang2019_fontsm_paired")  # sign(s) as printed: the chatter notes apply to these only
TABLE1 = {"attitude": [2.6e-6, 2.3e-6, 1.2e-6], "rate": [4.4e-6, 2.0e-6, 3.5e-6], "stabilization": 28.0}
TABLE1_21 = {"attitude": [0.412, 0.008, 0.264], "rate": [0.055, 0.067, 0.089]}
ANGLES, RATES = ("nu", "psi", "gamma"), ("omega_1", "omega_2", "omega_3")
ESTIMATE_OK = 0.10  # our threshold for "accurate estimation": RMS error <= 10 % of RMS fault torque
FACTOR_EST = 3.0  # "partly": RMS error within 30 %
E_TRUE, E_ONSET, LOSS = np.array([1.0, 0.6, 1.0, 1.0]), 20.0, 0.4  # 001 section 5: e_2 = 0.6 from 20 s
CONVERGED_DEG = 0.01  # deg: "converges and stays near zero" (ours, the band of our stabilisation time)
NO_21 = ("001's ref. [21] (Shen, Wang, Zhu, Finite-time fault-tolerant attitude stabilization for spacecraft with "
         "actuator saturation, IEEE Trans. Aerosp. Electron. Syst. 51(3), 2015) is given neither equations nor gains in "
         "001, and the public material we searched holds its title only; zhang2019_passive is a stand-in (FONTSM without "
         "estimates), not [21].")


def effectiveness_errors(run) -> dict | None:
    """|e_hat_j - e_j| / 0.4 at the end of the run (the fault to estimate is a 0.4 loss) for the faulty wheel 2 and
    the largest over the healthy wheels 1, 3, 4; e_hat_2 just before the fault (the pre-fault drift)."""
    r = run[0]
    t = np.asarray(r.time)
    if t[-1] < E_ONSET + 1.0:
        return None
    eh = r.vector("est.e_hat")
    err = np.abs(eh[-1] - E_TRUE) / LOSS
    before = t < E_ONSET - 1e-9
    return {"faulty": float(err[1]), "healthy": float(max(err[0], err[2], err[3])), "e_hat_end": eh[-1].tolist(),
            "e_hat_2_before_fault": float(eh[before][-1, 1]) if before.any() else None,
            "healthy_worst_wheel": int(1 + [0, 2, 3][int(np.argmax([err[0], err[2], err[3]]))]), "t_end": float(t[-1])}


def rows(runs: dict) -> list:
    out = []
    table1_runs = ("zhang2019_fontsm", "zhang2019_fontsm_smooth", "zhang2019_fontsm_fast_observer",
                   "zhang2019_fontsm_accurate")
    paper = TABLE1["attitude"] + TABLE1["rate"]
    item = "Table 1 (FTC in this paper): attitude accuracy nu, psi, gamma [deg] and rate accuracy omega_1-3 [deg/s]"
    for n in table1_runs:
        run = runs.get(n)
        label, kind = READINGS[n]
        m = run[2] if run else None
        acc = None
        note = missing(n)
        if m:
            att, rate = m.get("attitude_accuracy_deg"), m.get("rate_accuracy_deg_s")
            acc = None if att is None or rate is None else list(att) + list(rate)
            note = ("Max |x_i| over [30, 60] s of one run for all six entries (our window); the verdict is the worst entry's"
                    + ("" if acc is None else ": ratios ours / printed " + ", ".join(f"{o / p:.3g}" for o, p in zip(acc, paper)))
                    + ".")
            if n in SIGN_RUNS:
                note += (" With sign(s) at the 1 ms step omega chatters by eps_1 h / 2 = 0.043 deg/s, and the full-memory GL "
                         "tails of D^0.01, I^0.01 keep the angles near 1e-4 deg.")
        out.append(Row(item, paper, acc, close_all(), label, note, kind, paper_text="±[2.6e-6, 2.3e-6, 1.2e-6] deg, "
                       "±[4.4e-6, 2.0e-6, 3.5e-6] deg/s", ours_text=None if acc is None else
                       f"[{', '.join(fmt(x) for x in acc[:3])}] deg, [{', '.join(fmt(x) for x in acc[3:])}] deg/s"))
    st = {}
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_accurate"):
        m = runs[n][2] if n in runs else None
        if m:
            st[n] = m.get("stabilization_time_s", {})
    out.append(impossible("Table 1 (FTC in this paper): stabilization time 28 s", 28.0, "unprinted parameter",
                          "001 gives no band for its stabilization time, nor whether it counts from 0 or from the 20 s "
                          "fault. Ours, first time after which max_i |sigma_i| stays within a band: "
                          + ("; ".join(f"{n}: 0.01 deg from {fmt(v.get('0.01'))} s, 1e-4 deg from {fmt(v.get('0.0001'))} "
                                       f"s, 3e-6 deg from {fmt(v.get('3e-06'))} s" for n, v in st.items()) or "no run")
                          + " ('—': not within the run); the 20 s faults leave no excursion at these levels."))
    out.append(impossible("Table 1 (FTC of [21]): accuracies and stabilization time", TABLE1_21["attitude"] +
                          TABLE1_21["rate"], "missing law or baseline", NO_21))
    out.append(impossible("Figs. 2-4: attitude, angular velocity and control torque under the passive FTC of [21]",
                          "figures", "missing law or baseline", NO_21))
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_paired", "zhang2019_fontsm_fast_observer", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        label, kind = READINGS[n]
        m = run[2] if run else None
        v = m.get("fault_torque_estimate_rms_error_ratio") if m else None
        note = missing(n) if run is None else (
            f"RMS ||M((E_hat - I) u_c + uf_hat) - M((E - I) u_c + u_f)|| / RMS ||M((E - I) u_c + u_f)|| over [30, 60] s "
            f"(RMS fault torque {fmt(m.get('fault_torque_rms'))} N.m).")
        if run and n in ("zhang2019_fontsm", "zhang2019_fontsm_paired"):
            note += " The printed lambda_1, lambda_2 give bias-error time constants of 1.2e3-6.8e3 s (see 'Observer')."
        out.append(Row("Fig. 5: fault estimate, torque level", ESTIMATE_OK, v, at_most(0.0, FACTOR_EST), label, note,
                       kind, paper_text="accurate (ours: RMS error <= 10 %)"))
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_paired", "zhang2019_fontsm_fast_observer", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        label, kind = READINGS[n]
        e = effectiveness_errors(run) if run else None
        note = missing(n) if run is None else ("The run ends before 21 s." if e is None else (
            f"|e_hat_2 - 0.6| / |1 - 0.6| at {e['t_end']:.0f} s (e_hat = [{', '.join(f'{x:.4g}' for x in e['e_hat_end'])}]); "
            f"before the fault e_hat_2 had drifted from 1 to {fmt(e['e_hat_2_before_fault'])} (a move that is not "
            "an estimate of the fault). e and u_f per wheel are not identifiable from omega alone (null(M), U e with a "
            "small steady command): the torque-level row is the meaningful one."))
        out.append(Row("Fig. 5: effectiveness estimates e_hat -> e (e_2 = 0.6 from 20 s, wheels 1, 3, 4 healthy)",
                       ESTIMATE_OK, None if e is None else max(e["faulty"], e["healthy"]), at_most(0.0, FACTOR_EST), label,
                       note if e is None else note + (f" Healthy wheels: max |e_hat_j - 1| / 0.4 = {fmt(e['healthy'])} "
                                                      f"(wheel {e['healthy_worst_wheel']}); ours: the larger of the two."),
                       kind, paper_text="accurate (ours: max_j |e_hat_j - e_j| / |1 - e_2| <= 10 %)"))
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_fast_observer", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        label, kind = READINGS[n]
        m = run[2] if run else None
        v = m.get("bias_torque_estimate_rms_error_ratio") if m else None
        note = missing(n) if run is None else (
            "RMS ||M uf_hat - M u_f|| / ||M u_f|| over [30, 60] s (M u_f = [0.04, 0, 0] N.m; uf_hat itself tends to the "
            "minimum-norm [0.0333, -0.0067, -0.0067, 0.0115] N.m, not [0.04, 0, 0, 0]).")
        out.append(Row("Fig. 5: bias estimate (u_f1 = 0.04 N.m), torque level", ESTIMATE_OK, v, at_most(0.0, FACTOR_EST),
                       label, note, kind, paper_text="accurate (ours: RMS error <= 10 %)"))
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        label, kind = READINGS[n]
        ours, note = None, missing(n)
        if run:
            r, m = run[0], run[2]
            t = np.asarray(r.time)
            w = t >= 15.0 - 1e-9
            ours = float(np.degrees(np.abs(r.vector("plant.sigma")[w])).max()) if w.any() and t[-1] >= 25.0 else None
            note = ("The run ends before 25 s." if ours is None else
                    f"Max_i |sigma_i| from 15 s to the end ({t[-1]:.0f} s), across the 20 s faults; within 0.01 deg from "
                    f"{fmt(m.get('stabilization_time_s', {}).get('0.01'))} s; max over the 5 s after the faults "
                    f"{fmt(m.get('max_attitude_after_fault_deg'))} deg.")
        out.append(Row("Figs. 6-7: FE/FTC converges and stays near zero after the faults", CONVERGED_DEG, ours,
                       at_most(0.0, 1.0), label, note, kind, unit="deg",
                       paper_text="converges, stays near 0 (ours: |sigma_i| <= 0.01 deg from 15 s on)"))
    out.append(impossible("Fig. 8: control torque under FE/FTC", "figure", "figure data not in the published text",
                          "001 prints the curves without values or a claim; drawn as fig6_8_<run>.png, levels against a "
                          "real reaction wheel in 'Chatter and torque levels'."))
    out.append(impossible("section 5: FE/FTC better than the passive FTC of [21]", "claim", "missing law or baseline",
                          NO_21 + " The stand-in gives the same numbers as FE/FTC with the printed observer gains."))
    return out


def e_hat_drift(runs: dict) -> list:
    """The LOE drift, measured: e_hat_2 at 20 s and at the end, with the fraction of steps over
    [30, 60] s where u_c2 changes sign (the chatter that reverses the literal gradient)."""
    out = []
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_paired", "zhang2019_fontsm_fast_observer", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        if run is None:
            continue
        r = run[0]
        t, eh, u = r.time, r.vector("est.e_hat"), r.vector("ctrl.u_c")
        w = (t >= 30.0 - 1e-9) & (t <= 60.0 + 1e-9)
        flips = float(np.mean(np.sign(u[w, 1][1:]) != np.sign(u[w, 1][:-1]))) if w.sum() > 2 else None
        out.append({"run": n, "reading": READINGS[n][0], "e_hat_2_at_20s": float(np.interp(20.0, t, eh[:, 1])),
                    "e_hat_2_end": float(eh[-1, 1]), "u_c2_sign_changes_per_step_30_60s": flips,
                    "u_c2_rms_30_60s": float(np.sqrt(np.mean(u[w, 1] ** 2))) if w.any() else None})
    return out
