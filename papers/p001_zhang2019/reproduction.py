"""Paper 001's reproduction table: Table 1 and Figs. 2-8 of its section 5 next to our runs.

``rows(runs)``: ``runs`` maps a scenario name to ``(RunResult, [metrics] table, metrics dict)`` (the
report's). Each row uses one run (one reading):

* ``zhang2019_fontsm``: as printed (sign(s), full Grünwald-Letnikov memory, printed observer gains,
  the literal sampled form of (14));
* ``zhang2019_fontsm_paired``: as printed with the observer's command_pairing = 1 (U(t_k-1) in (14));
* ``zhang2019_fontsm_smooth``: boundary layer 0.01 rad/s, 2 s memory;
* ``zhang2019_fontsm_fast_observer``: as _smooth with lambda_1 = lambda_2 = 2000;
* ``zhang2019_fontsm_accurate``: boundary layer 0.005 rad/s, 2 s memory, fast observer, paired.

001 defines neither the window of its "accuracy" nor the band of its "stabilization time" (our
definitions: papers/p001_zhang2019/metrics.py). "Accurate estimation" (Fig. 5) is read as an RMS
error of the torque-level estimate at most 10 % of the RMS fault torque over [30, 60] s (our
threshold). Fig. 1 is a block diagram (no result) and is not a row.
"""
from __future__ import annotations

import numpy as np

from papers.reproduction import Row, at_most, claim, close, fmt, missing, not_attempted, toward

AS_PRINTED = "zhang2019_fontsm"
READINGS = {  # scenario -> (reading label, literal?)
    "zhang2019_fontsm": ("as printed: sign(s), full memory, printed gains", True),
    "zhang2019_fontsm_paired": ("as printed + observer command_pairing = 1", False),
    "zhang2019_fontsm_smooth": ("sat(s/0.01), 2 s memory", False),
    "zhang2019_fontsm_fast_observer": ("sat(s/0.01), 2 s memory, lambda_1 = lambda_2 = 2000", False),
    "zhang2019_fontsm_accurate": ("sat(s/0.005), 2 s memory, lambda_1 = lambda_2 = 2000, command_pairing = 1", False),
}
TABLE1 = {"attitude": [2.6e-6, 2.3e-6, 1.2e-6], "rate": [4.4e-6, 2.0e-6, 3.5e-6], "stabilization": 28.0}
TABLE1_21 = {"attitude": [0.412, 0.008, 0.264], "rate": [0.055, 0.067, 0.089]}
ANGLES, RATES = ("nu", "psi", "gamma"), ("omega_1", "omega_2", "omega_3")
ESTIMATE_OK = 0.10  # our threshold for "accurate estimation": RMS error <= 10 % of RMS fault torque
FACTOR_EST = 3.0  # "partly": RMS error within 30 %
E2_TRUE, E2_START = 0.6, 1.0


def _runs(runs, names):
    return [(n, runs.get(n)) for n in names]


def rows(runs: dict) -> list:
    out = []
    table1_runs = ("zhang2019_fontsm", "zhang2019_fontsm_smooth", "zhang2019_fontsm_fast_observer", "zhang2019_fontsm_accurate")
    for key, names, unit in (("attitude", ANGLES, "deg"), ("rate", RATES, "deg/s")):
        for i, ax in enumerate(names):
            for n, run in _runs(runs, table1_runs):
                label, literal = READINGS[n]
                m = run[2] if run else None
                v = m.get(f"{key}_accuracy_deg" if key == "attitude" else "rate_accuracy_deg_s") if m else None
                ours = None if v is None else v[i]
                note = missing(n) if run is None else f"max |{ax}| over [30, 60] s of {n}"
                if ours is not None and ours < TABLE1[key][i] / 3:
                    note += f" (smaller than printed by x{TABLE1[key][i] / ours:.2g})"
                if run and key == "rate" and literal:
                    note += "; sign(s) at a 1 ms step chatters omega by eps_1 h / 2 = 0.043 deg/s"
                if run and key == "attitude" and literal:
                    note += "; the full-memory GL tails of D^0.01, I^0.01 and the sign(s) chatter keep ~1e-4 deg"
                out.append(Row(f"Table 1 (this paper): {ax} accuracy", TABLE1[key][i], ours, close(), label, note, literal,
                               unit=unit))
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        label, literal = READINGS[n]
        m = run[2] if run else None
        st = m.get("stabilization_time_s", {}) if m else {}
        ours = st.get("0.01") if m else None
        note = missing(n) if run is None else (
            "first time after which max_i |sigma_i| <= 0.01 deg to the end; "
            f"1e-4 deg from {fmt(st.get('0.0001'))} s, "
            f"3e-6 deg from {fmt(st.get('3e-06'))} s ('—': not within the run); the 20 s faults leave no excursion at "
            f"these levels (max over 5 s after / before: {fmt(m.get('fault_excursion_ratio'))}); 001 gives no band, so "
            "its 28 s cannot be placed")
        out.append(Row("Table 1 (this paper): stabilization time", TABLE1["stabilization"], ours, close(), label, note,
                       literal, unit="s"))
    for key, names in (("attitude", ANGLES), ("rate", RATES)):
        for i, ax in enumerate(names):
            out.append(not_attempted(f"Table 1 (FTC of [21]): {ax} accuracy", TABLE1_21[key][i],
                                     "001's ref. [21] (passive FTC) is given neither equations nor gains; "
                                     "zhang2019_passive is a stand-in (FONTSM without estimates), not [21]"))
    out.append(not_attempted("Table 1 (FTC of [21]): stabilization time", "Infinity", "[21] not defined in 001"))
    for fig, what in (("Fig. 2", "attitude"), ("Fig. 3", "angular velocity"), ("Fig. 4", "control torque")):
        out.append(not_attempted(f"{fig}: {what} under the passive FTC of [21]", "figure",
                                 "[21] not defined in 001; zhang2019_passive is a stand-in, not [21]"))
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_paired", "zhang2019_fontsm_fast_observer", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        label, literal = READINGS[n]
        m = run[2] if run else None
        v = m.get("fault_torque_estimate_rms_error_ratio") if m else None
        note = missing(n) if run is None else (
            f"RMS ||M((E_hat - I) u_c + uf_hat) - M((E - I) u_c + u_f)|| / RMS ||M((E - I) u_c + u_f)|| over [30, 60] s "
            f"(RMS fault torque {fmt(m.get('fault_torque_rms'))} N.m)")
        if run and literal:
            note += "; printed lambda_1, lambda_2: bias-error time constants 1.2e3-6.8e3 s (see 'Observer')"
        out.append(Row("Fig. 5: fault estimate, torque level", ESTIMATE_OK, v, at_most(0.0, FACTOR_EST), label, note,
                       literal, paper_text="accurate (ours: RMS error <= 10 %)"))
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_paired", "zhang2019_fontsm_fast_observer", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        label, literal = READINGS[n]
        v = None if run is None else float(run[0].vector("est.e_hat")[-1, 1])
        note = missing(n) if run is None else (
            f"e_hat_2 at {run[0].time[-1]:.0f} s (e_2 = 0.6 from 20 s, e_hat_2(0) = 1); e and u_f per wheel are not "
            "identifiable from omega (null(M), U e with a small steady command): the torque is")
        out.append(Row("Fig. 5: effectiveness estimate e_hat_2 -> e_2", E2_TRUE, v, toward(E2_START), label, note, literal))
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_fast_observer", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        label, literal = READINGS[n]
        m = run[2] if run else None
        v = m.get("bias_torque_estimate_rms_error_ratio") if m else None
        note = missing(n) if run is None else (
            "RMS ||M uf_hat - M u_f|| / ||M u_f|| over [30, 60] s (M u_f = [0.04, 0, 0] N.m; uf_hat itself tends to the "
            "minimum-norm [0.0333, -0.0067, -0.0067, 0.0115] N.m, not [0.04, 0, 0, 0])")
        out.append(Row("Fig. 5: bias estimate (u_f1 = 0.04 N.m), torque level", ESTIMATE_OK, v, at_most(0.0, FACTOR_EST),
                       label, note, literal, paper_text="accurate (ours: RMS error <= 10 %)"))
    for n in ("zhang2019_fontsm", "zhang2019_fontsm_accurate"):
        run = runs.get(n)
        label, literal = READINGS[n]
        ok, note = None, missing(n)
        if run:
            m = run[2]
            st = m.get("stabilization_time_s", {}).get("0.01")
            after = m.get("max_attitude_after_fault_deg")
            ok = bool(st is not None and st < 20.0 and after is not None and after <= 0.01)
            note = f"within 0.01 deg from {fmt(st)} s; max_i |sigma_i| over the 5 s after the 20 s faults {fmt(after)} deg"
        out.append(Row("Figs. 6-7: FE/FTC converges and stays after the faults", "converges, stays near 0", ok, claim(),
                       label, note, literal))
    out.append(not_attempted("Fig. 8: control torque under FE/FTC", "figure (no value, no claim)",
                             "drawn (fig6_8_<run>.png); levels against real reaction wheels in 'Torque levels'"))
    out.append(not_attempted("section 5: FE/FTC better than the passive FTC of [21]", "claim",
                             "[21] not defined in 001; the stand-in (zhang2019_passive) gives the same numbers as FE/FTC "
                             "with the printed observer gains"))
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
