"""Paper 003's reproduction table: Figs. 3-12 of its section 4 next to our runs.

003 prints no number in its results, only claims about its figures; each row turns one claim into a
test on the runs, with the threshold stated (ours). Figs. 1-2 are a schematic and a block diagram.
``rows(R)``: ``R`` maps a scenario name to its RunResult. Readings:

* as printed: ``hang2023_asmftc_f04`` / ``_f08`` / ``_f10`` (published L1, observer fed the command u,
  gamma3 = 1, (3.21) with (3.19)-(3.20)), ``_sign_f04`` ((3.10) with (3.11), (3.13)), ``_noobs_f04``;
* delivered-torque variant: ``hang2023_asmftc_delivered_f04`` / ``_f08`` / ``_f10`` (the observer is fed
  the torque rho u the actuator delivers, gamma3 = 0.1 chosen instead of the printed 1),
  ``_noobs_g01_f04`` (its comparator);
* gamma3 = 0.01 (a thinner boundary layer, variant): the stored study :mod:`papers.p003_hang2023.gamma3_study`,
  both observer inputs, for the failure-factor ordering.

The ordering of Figs. 9-10 is judged on the steady-state accuracy the text speaks of ("the control accuracy
of failure factor 0.4 is the worst"): max |theta| over the last 10 s; the peak over [20, 25] s is in the note.
"""
from __future__ import annotations

import numpy as np

from papers.reproduction import PRINTED as AS_PRINTED
from papers.reproduction import VARIANT, Row, above, at_most, below, fmt, impossible, missing

ONSET = 20.0
EFFECTIVE = 0.01  # "effectively estimate": RMS(d0 - d0_hat) <= 1 % of RMS d0 (ours; issue 21's threshold)
BAND = 1e-3  # rad: "high accuracy" / "stabilized quickly" (ours)
PRINTED = {0.4: "hang2023_asmftc_f04", 0.8: "hang2023_asmftc_f08", 1.0: "hang2023_asmftc_f10"}
DELIVERED = {0.4: "hang2023_asmftc_delivered_f04", 0.8: "hang2023_asmftc_delivered_f08", 1.0: "hang2023_asmftc_delivered_f10"}
READINGS = {
    "printed": ("as printed: observer fed the command u, gamma3 = 1", AS_PRINTED),
    "delivered": ("delivered torque rho u to the observer, gamma3 = 0.1 chosen (printed: 1)", VARIANT),
}


def _win(t, a, b):
    return (t >= a - 1e-9) & (t <= b + 1e-9)


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x)))) if len(x) else None


def estimate_errors(r) -> dict:
    """RMS(d0 - d0_hat) / RMS(d0) before the fault ([1, 20] s) and after it ([21 s, end])."""
    t = r.time
    d0, dh = r.column("plant.d_vib"), r.column("est.d0_hat")
    out = {}
    for key, w in (("pre", _win(t, 1.0, ONSET)), ("post", t >= ONSET + 1.0 - 1e-9)):
        rd = _rms(d0[w])
        out[f"rms_ratio_{key}"] = (_rms((d0 - dh)[w]) / rd) if rd else None
        out[f"rms_error_{key}"] = _rms((d0 - dh)[w])
    return out


def attitude(r) -> dict:
    t, th = r.time, r.column("plant.theta")
    w = _win(t, ONSET, ONSET + 5.0)
    return {"peak_20_25": float(np.abs(th[w]).max()) if w.any() else None,
            "theta_20": float(np.interp(ONSET, t, th)) if t[-1] >= ONSET else None,
            "max_after_onset": float(np.abs(th[t >= ONSET - 1e-9]).max()) if t[-1] >= ONSET else None,
            "max_last_10": float(np.abs(th[t >= t[-1] - 10.0]).max())}


def ordering_ratio(values) -> float | None:
    """Figs. 9-10's ordering as one number: min(m(0.4) / m(0.8), m(0.8) / m(1.0)) for a measure m of the
    factors 0.4, 0.8, 1.0 (> 1: strictly worse for a smaller factor, as 003 claims)."""
    a, b, c = values
    if a is None or b is None or c is None:
        return None
    return min(a / b if b > 0 else np.inf, b / c if c > 0 else np.inf)


ORDER_ITEM = "Figs. 9-10: the smaller the failure factor, the worse the accuracy (0.4 worst, 1.0 best)"


def _ordering_row(R, runs, label, kind):
    names = [runs[f] for f in (0.4, 0.8, 1.0)]
    if not all(n in R for n in names):
        miss = [n for n in names if n not in R]
        return Row(ORDER_ITEM, 1.0, None, above(), label, missing(miss[0]), kind, paper_text="ordered (ratio > 1)")
    at = [attitude(R[n]) for n in names]
    ss, pk = [a["max_last_10"] for a in at], [a["peak_20_25"] for a in at]
    ours = ordering_ratio(ss)
    note = ("Max |theta| over the last 10 s for 0.4 / 0.8 / 1.0: " + " / ".join(fmt(x) for x in ss) + " rad; ours: "
            "min(0.4 / 0.8, 0.8 / 1.0). Peak |theta| over [20, 25] s: " + " / ".join(fmt(x) for x in pk) + " rad.")
    if kind == AS_PRINTED:
        note += (" With the command fed to the observer d0_hat absorbs -(1 - rho) u (003 (3.3)), so u grows by 1/rho, "
                 "the applied torque is unchanged and the larger |d0_hat| raises Phi.")
    return Row(ORDER_ITEM, 1.0, ours, above(), label, note, kind, paper_text="ordered (ratio > 1)")


def _study_ordering_rows(study) -> list:
    out = []
    for reading, label in (("command", "observer fed the command u, gamma3 = 0.01 chosen (printed: 1)"),
                           ("delivered", "delivered torque rho u to the observer, gamma3 = 0.01 chosen (printed: 1)")):
        d = (study or {}).get("runs", {}).get(reading)
        if d is None:
            out.append(Row(ORDER_ITEM, 1.0, None, above(), label, "The gamma3 study is not stored "
                           "(python -m papers.p003_hang2023.gamma3_study).", VARIANT, paper_text="ordered (ratio > 1)"))
            continue
        ss = [d[k]["theta_max_last_10s"] for k in ("0.4", "0.8", "1")]
        pk = [d[k]["theta_peak_20_25s"] for k in ("0.4", "0.8", "1")]
        out.append(Row(ORDER_ITEM, 1.0, ordering_ratio(ss), above(), label,
                       "Stored study (papers/p003_hang2023/gamma3_study.json): max |theta| over the last 10 s for 0.4 / 0.8 "
                       "/ 1.0: " + " / ".join(fmt(x) for x in ss) + " rad; peak |theta| over [20, 25] s: "
                       + " / ".join(fmt(x) for x in pk) + " rad.", VARIANT, paper_text="ordered (ratio > 1)"))
    return out


def rows(R: dict, study: dict | None = None) -> list:
    from .design import verify
    from .gains import L1_PUBLISHED
    from .gamma3_study import load

    study = load() if study is None else study
    out = []
    out.append(impossible("Figs. 3-4: first and second elastic modes", "figure", "figure data not in the published text",
                          "003 prints neither the curves nor a claim about them; drawn as fig3_4_modes.png."))
    for key, runs in (("printed", PRINTED), ("delivered", DELIVERED)):
        label, kind = READINGS[key]
        n = runs[0.4]
        e = estimate_errors(R[n]) if n in R else None
        out.append(Row("Fig. 5: the TSFDO estimates d0 effectively (before the fault)", EFFECTIVE,
                       None if e is None else e["rms_ratio_pre"], at_most(0.0), label,
                       missing(n) if e is None else f"RMS(d0 - d0_hat) / RMS(d0) over [1, 20] s of {n} "
                       f"(RMS error {fmt(e['rms_error_pre'])} N.m).", kind,
                       paper_text="effective (ours: RMS error <= 1 %)"))
        out.append(Row("Figs. 5-6: the TSFDO estimates d0 effectively (after the fault)", EFFECTIVE,
                       None if e is None else e["rms_ratio_post"], at_most(0.0), label,
                       missing(n) if e is None else (
                           f"RMS(d0 - d0_hat) / RMS(d0) over [21, 60] s of {n} (RMS error {fmt(e['rms_error_post'])} N.m)."
                           + (" Fed the command, d0_hat estimates the lumped d0 + T_d - (1 - rho) u of (3.3)."
                              if key == "printed" else "")), kind,
                       paper_text="effective (ours: RMS error <= 1 %)"))
    sign, base = "hang2023_asmftc_sign_f04", PRINTED[0.4]
    a = attitude(R[sign]) if sign in R else None
    out.append(Row("Fig. 7: under (3.10) the system remains stable after the fault", BAND,
                   None if a is None else a["max_last_10"], at_most(0.0, 1.0), "as printed: (3.10) with (3.11), (3.13)",
                   missing(sign) if a is None else
                   f"Factor 0.4: max |theta| over the last 10 s of {sign} (stable read as within 1e-3 rad, ours).",
                   AS_PRINTED, unit="rad", paper_text="stable (ours: |theta| <= 1e-3 rad in the last 10 s)"))
    ours, note = None, missing(sign if sign not in R else base)
    if sign in R and base in R:
        from .metrics import chattering

        win = (25.0, float(R[base].time[-1]))
        a = chattering(R[sign].time, R[sign].column("ctrl.u"), win)[0]
        b = chattering(R[base].time, R[base].column("ctrl.u"), win)[0]
        ours = a / b if (a is not None and b) else None
        note = (f"RMS du/dt over [25, 60] s: (3.10) {fmt(a)} N.m/s, (3.21) {fmt(b)} N.m/s; ours: their ratio, 'greatly' "
                "read as at least 10. (3.10) at a 0.5 ms exchange chatters at the exchange rate.")
    out.append(Row("Figs. 7-8: (3.21) greatly reduces the chattering of (3.10)", 10.0, ours, above(), "as printed", note,
                   AS_PRINTED, paper_text="greatly reduced (ours: ratio > 10)"))
    for key, runs in (("printed", PRINTED), ("delivered", DELIVERED)):
        out.append(_ordering_row(R, runs, *READINGS[key]))
    out += _study_ordering_rows(study)
    for key, runs in (("printed", PRINTED), ("delivered", DELIVERED)):
        label, kind = READINGS[key]
        n = runs[1.0]
        a = attitude(R[n]) if n in R else None
        out.append(Row("Figs. 9-10: factor 1.0 maintains high accuracy after 20 s", BAND,
                       None if a is None else a["max_after_onset"], at_most(0.0, 1.0), label,
                       missing(n) if a is None else f"Max |theta| over [20, 60] s of {n}.", kind, unit="rad",
                       paper_text="high accuracy (ours: |theta| <= 1e-3 rad)"))
    for key, runs in (("printed", PRINTED), ("delivered", DELIVERED)):
        label, kind = READINGS[key]
        n = runs[0.4]
        a = attitude(R[n]) if n in R else None
        if a is not None and a["theta_20"] is None:
            a = None  # the run ends before 20 s
        out.append(Row("Figs. 11-12: with ASMFTC + TSFDO the attitude is stabilized quickly", BAND,
                       None if a is None else abs(a["theta_20"]), at_most(0.0, 1.0), label,
                       missing(n) if a is None else f"|theta(20 s)| of {n} (before the fault; 'quickly' = within 20 s, ours).",
                       kind, unit="rad", paper_text="quickly (ours: |theta(20 s)| <= 1e-3 rad)"))
    for key, with_, without in (("printed", PRINTED[0.4], "hang2023_asmftc_noobs_f04"),
                                ("delivered", DELIVERED[0.4], "hang2023_asmftc_noobs_g01_f04")):
        label, kind = READINGS[key]
        ours, note = None, missing(with_ if with_ not in R else without)
        if with_ in R and without in R:
            a, b = attitude(R[with_])["max_last_10"], attitude(R[without])["max_last_10"]
            ours = a / b if b > 0 else np.inf
            note = (f"Max |theta| over the last 10 s: with the TSFDO {fmt(a)} rad, without {fmt(b)} rad ({without}; 003 "
                    "does not name its second method: ours is the same ASMFTC without observer); ours: their ratio.")
        out.append(Row("Figs. 11-12: better anti-disturbance with the TSFDO than without", 1.0, ours, below(), label, note,
                       kind, paper_text="better (ratio < 1)"))
    ver = verify(L1_PUBLISHED)
    ab = ver["best_alpha_beta_on_grid"]
    out.append(Row("section 4: the printed L1 = [[0, -1.54e3], [0, -2.35e4]] is a gain of Theorem 1 (3.4)", 0.0,
                   -np.inf if ab is None else ab, above(), "as printed (signs restored, see README)",
                   "Ours: the best decay-rate certificate alpha * beta of (3.4) with L1 fixed (P1 free), > 0 when (3.4) "
                   f"holds: (3.4) feasible {ver['lmi_3_4_feasible']}, error poles' abscissa "
                   + ", ".join(f"{x:.4g}" for x in ver["abscissa"]) + " 1/s. The value of L1 itself is the output of a "
                   "feasibility LMI that does not fix it (any fast enough gain passes) and cannot be recomputed.", AS_PRINTED,
                   paper_text="a solution of (3.4) (ours: certificate > 0)"))
    return out
