"""Paper 000's report: the comparisons of 000 section 5 from result folders (``ftcsim report``).

Each folder is one ``ftcsim run`` (results.csv + metrics.json). Signals are found through
the ``signals`` map that ``metrics.json`` carries (the scenario's [metrics] table). Figures
(PNG), numbered as in 000:
  fig4_modes.png               vibration modes eta (Fig. 4)
  fig5_vibration_torque.png    vibration torque T_d and its estimate from d2_hat (Fig. 5)
  fig6_omega_estimate.png      omega, omega_hat and ||omega - omega_hat|| (Fig. 6)
  fig7_8_faults_<run>.png      fault estimates against the true faults (Figs. 7-8)
  fig9_control.png             FASMC's torque per channel and ||u||_1 against u_max = 5 N.m (Fig. 9)
  fig10_rate_errors.png        omega_e per channel and its norm (Fig. 10)
  fig11_attitude_errors.png    q_ev per channel and its norm, with the 2 % settling band (Fig. 11)
  fig12abc_control.png         control torque per channel (Fig. 12(a-c))
  fig12d_energy.png            E(t) = int_0^t ||u||^2 dt (Fig. 12(d))
Figs. 10-12 draw only the three controllers 000 compares, as printed (li2023_pd_fe: PD (69) with FAFEO,
li2023_aismc, li2023_fasmc), when the report has any of them; the weak-fault, per-axis and estimator-free runs are
then in the tables only (a report of other runs draws the runs it was given).
and ``report.md`` / ``report.json`` with the numbers of every run.

The estimated vibration torque uses the 000 parameter set (J, delta, modes): T_d_hat =
delta^T K eta_hat + delta^T C eta_dot_hat - omega x delta^T eta_dot_hat (000 (6)).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from orchestrator.results.files import write_json
from orchestrator.results.report import Document, write_table
from orchestrator.results.report import figure as _fig
from orchestrator.results.report import save_figure as _save
from papers.reproduction import add_to, fmt, to_json

from .parameters import U_MAX
from .reproduction import BAND, PD, PRINTED_RUN, WINDOWS, observer_errors, vibration_errors, vibration_torque_estimate
from .reproduction import rows as reproduction_rows

COMPARED = ((PD, "PD (69) with FAFEO"), ("li2023_aismc", "AISMC"), (PRINTED_RUN, "FASMC"))
LABELS = dict(COMPARED)

TABLE_KEYS = [
    ("final_attitude_error", "attitude error (end)"),  # units: the runs' metrics.json (write_table)
    ("final_rate_error", "‖ω_e‖(end)"),
    ("control_energy", "E"),
    ("max_abs_u", "max|u_i|"),
    ("observer_error_max_settled_before_faults", "‖ω−ω̂‖ 15-40 s"),
    ("observer_error_max_after_faults", "‖ω−ω̂‖ after 40 s"),
    ("fault_estimate_rms_error_ratio", "RMS(f̂−f)/RMS(f)"),
    ("vibration_estimate_error_max", "max‖d̂2−d2‖"),
    ("real_time_factor", "RTF"),
]


def make_report(runs, out: Path) -> dict:
    """Figures and table of 000 section 5 for result folders ``runs`` (orchestrator.results.files.Run)."""
    files: list[str] = []
    est = sorted((r for r in runs if r.has("omega_hat")), key=lambda r: r.name != PRINTED_RUN)  # 000's run first
    ctrl = [r for r in runs if r.has("attitude_error")]
    first = est[0] if est else (runs[0] if runs else None)

    if first is not None and first.has("eta"):
        plt, fig, ax = _fig(1, f"Vibration modes eta ({first.name}), 000 Fig. 4")
        for i, c in enumerate(first.vec("eta").T):
            ax[0].plot(first.t, c, lw=0.8, label=f"eta_{i + 1}")
        ax[0].legend(fontsize=7)
        _save(plt, fig, ax, out, "fig4_modes.png", files)
    if est and est[0].has("d2_hat") and est[0].has("omega"):
        r = est[0]
        td_hat = vibration_torque_estimate(r.vec("omega"), r.vec("d2_hat"))
        plant = r.signals["omega"].split(".")[0]
        td = r.data[:, [i for i, h in enumerate(r.header) if h.startswith(f"{plant}.d_vib[")]]
        plt, fig, ax = _fig(3, f"Vibration torque T_d and its estimate ({r.name}), 000 Fig. 5")
        for i in range(3):
            if td.shape[1] == 3:
                ax[i].plot(r.t, td[:, i], lw=0.8, label="T_d (plant)")
            ax[i].plot(r.t, td_hat[:, i], "--", lw=0.8, label="from d2_hat")
            ax[i].set_ylabel(f"axis {i + 1} [N·m]")
        ax[0].legend(fontsize=7)
        _save(plt, fig, ax, out, "fig5_vibration_torque.png", files)
    if est:
        r = est[0]
        w, wh = r.vec("omega"), r.vec("omega_hat")
        plt, fig, ax = _fig(2, f"Angular-rate estimate ({r.name}), 000 Fig. 6")
        for i in range(3):
            ax[0].plot(r.t, w[:, i], lw=0.8, label=f"omega_{i + 1}")
            ax[0].plot(r.t, wh[:, i], "--", lw=0.8, label=f"omega_hat_{i + 1}")
        ax[0].legend(fontsize=6, ncol=3)
        ax[1].semilogy(r.t, np.maximum(np.linalg.norm(w - wh, axis=1), 1e-16), lw=0.8)
        ax[1].set_ylabel("||omega - omega_hat|| [rad/s]")
        _save(plt, fig, ax, out, "fig6_omega_estimate.png", files)
    for r in runs:
        if r.has("f") and r.has("f_hat"):
            f, fh = r.vec("f"), r.vec("f_hat")
            plt, fig, ax = _fig(3, f"Fault estimates ({r.name}), 000 Figs. 7-8")
            for i in range(3):
                ax[i].plot(r.t, f[:, i], lw=0.9, label="f (true)")
                ax[i].plot(r.t, fh[:, i], "--", lw=0.9, label="f_hat")
                ax[i].set_ylabel(f"f_{i + 1} [N·m]")
            ax[0].legend(fontsize=7)
            _save(plt, fig, ax, out, f"fig7_8_faults_{r.name}.png", files)
    # Figs. 10-12 compare 000's three controllers when the report has them (its runs as printed, faults 1 f; the weak-
    # fault, per-axis and estimator-free runs stay in the tables); a report of other runs draws the runs it was given
    compared = [r for name, _ in COMPARED for r in ctrl if r.name == name] or ctrl
    printed = next((r for r in ctrl if r.name == PRINTED_RUN), None)
    if printed is not None:  # Fig. 9: the proposed controller's torque and its 1-norm against u_max
        u = printed.vec("control")
        plt, fig, ax = _fig(2, f"Control input torque ({printed.name}), 000 Fig. 9")
        for i in range(3):
            ax[0].plot(printed.t, u[:, i], lw=0.7, label=f"u_{i + 1}")
        ax[0].set_ylabel("u_i [N·m]")
        ax[0].legend(fontsize=7)
        ax[1].plot(printed.t, np.abs(u).sum(axis=1), lw=0.8, label="||u||_1")
        ax[1].axhline(U_MAX, color="k", ls=":", lw=0.8, label=f"u_max = {U_MAX:g} N·m (000 5.3)")
        ax[1].set_ylabel("||u||_1 [N·m]")
        ax[1].legend(fontsize=7)
        _save(plt, fig, ax, out, "fig9_control.png", files)
    if compared:
        plt, fig, ax = _fig(3, "Control torque per channel: " + ", ".join(LABELS.get(r.name, r.name) for r in compared)
                            + ", 000 Fig. 12(a-c)")
        for r in compared:
            u = r.vec("control")
            for i in range(3):
                ax[i].plot(r.t, u[:, i], lw=0.7, label=LABELS.get(r.name, r.name))
                ax[i].set_ylabel(f"u_{i + 1} [N·m]")
        ax[0].legend(fontsize=7)
        _save(plt, fig, ax, out, "fig12abc_control.png", files)
        for key, fname, title, sl in (
            ("rate_error", "fig10_rate_errors.png", "Rate tracking errors omega_e, 000 Fig. 10", slice(0, 3)),
            ("attitude_error", "fig11_attitude_errors.png", "Attitude tracking errors q_ev, 000 Fig. 11", slice(1, 4)),
        ):
            plt, fig, ax = _fig(4, title)
            for r in compared:
                e = r.vec(key)[:, sl]
                for i in range(3):
                    ax[i].plot(r.t, e[:, i], lw=0.7, label=LABELS.get(r.name, r.name))
                    ax[i].set_ylabel(f"channel {i + 1}")
                ax[3].semilogy(r.t, np.maximum(np.linalg.norm(e, axis=1), 1e-16), lw=0.7, label=LABELS.get(r.name, r.name))
            if key == "attitude_error":
                ax[3].axhline(BAND, color="k", ls=":", lw=0.8, label=f"2 % band of the 80 s step ({BAND:.2g})")
            ax[3].set_ylabel("norm")
            ax[0].legend(fontsize=7)
            ax[3].legend(fontsize=7)
            _save(plt, fig, ax, out, fname, files)
        plt, fig, ax = _fig(1, "Control energy E(t) = int ||u||^2 dt, 000 Fig. 12(d)", height=3.0)
        for r in compared:
            u = r.vec("control")
            dt = np.diff(r.t)
            energy = np.concatenate([[0.0], np.cumsum((u[:-1] ** 2).sum(axis=1) * dt)])
            ax[0].plot(r.t, energy, lw=0.9, label=f"{LABELS.get(r.name, r.name)}: E = {energy[-1]:.1f}")
        ax[0].axvspan(80.0, 100.0, color="0.9", label="manoeuvre 80-100 s")
        ax[0].legend(fontsize=7)
        _save(plt, fig, ax, out, "fig12d_energy.png", files)

    by_name = {r.name: r for r in runs}
    repro = reproduction_rows(by_name)
    doc = Document("Paper 000 (Li, Xu, Chang 2023): reproduction of section 5", out)
    add_to(doc, repro, "Reproduction table (computed from this report's runs)", REPRO_INTRO)
    details(doc, by_name)
    rep = write_table(out, runs, TABLE_KEYS, files, doc=doc)
    doc.write()
    data = json.loads((out / "report.json").read_text(encoding="utf-8"))
    data["reproduction"] = to_json(repro)
    data["vibration_estimate"] = {n: vibration_errors(r) for n, r in by_name.items() if r.has("d2_hat") and r.has("omega")}
    data["observer"] = {n: observer_errors(r) for n, r in by_name.items() if r.has("omega_hat")}
    write_json(out / "report.json", data)
    rep["reproduction"] = data["reproduction"]
    return rep


REPRO_INTRO = ("As printed: li2023_fasmc, li2023_fasmc_weak and li2023_pd_fe (000's PD: (69) with the FAFEO feed-forwards), "
               "||u||_1 <= 5 N.m, 10 ms exchange. AISMC (li2023_aismc) is a documented reading: its K_c^i come from ref. "
               "[21] and are not printed, so every comparison with it is impossible as printed. Variants: li2023_pd (PD "
               "without estimator) and li2023_fasmc_peraxis (per-axis saturation). Where 000 claims without a number, the "
               "threshold is stated in the row: a ratio against 1 for a comparison, the 2 % settling band of the 80 s "
               "manoeuvre for 'converge', the last 50 s for 'steady state'. Appendix A's numbers are checked against "
               "Theorems 1-2 (stored LMI solves: papers/p000_li2023/appendix_study.json).")


def details(doc: Document, runs: dict) -> None:
    """Per-window vibration-torque errors (Fig. 5) and the observer error (Fig. 6), with the leak."""
    vib = {n: vibration_errors(r) for n, r in runs.items() if r.has("d2_hat") and r.has("omega")}
    if vib:
        doc.heading("Fig. 5: vibration torque estimate per window")
        doc.text("RMS ||T_d_hat - T_d|| / RMS ||T_d|| (T_d from the plant, T_d_hat from d2_hat by 000 (6)), with the RMS "
                 "error [N.m] in brackets; R^2: share of the variance of T_d_hat - T_d after 40 s explained by "
                 "f_hat - f (least squares, a 3 x 3 gain).")
        cols = [f"{a:g}-{b:g} s" for a, b, _ in WINDOWS]
        rows = [[n, *[("—" if w["ratio"] is None else f"{100 * w['ratio']:.3g} % ({fmt(w['rms_error'])})")
                      for w in v["windows"]], v.get("leak_R2")] for n, v in vib.items()]
        doc.table(pd.DataFrame(rows, columns=["run", *cols, "R^2 leak"]))
        if "li2023_fasmc" in vib and "li2023_fasmc_weak" in vib:
            ratios = [(b["rms_error"] / a["rms_error"]) if a["rms_error"] and b["rms_error"] is not None else None
                      for a, b in zip(vib["li2023_fasmc"]["windows"], vib["li2023_fasmc_weak"]["windows"])]
            doc.text("Weak faults (0.2 f) against li2023_fasmc, RMS error ratio per window: "
                     + ", ".join(f"{a:g}-{b:g} s {fmt(x)}" for (a, b, _), x in zip(WINDOWS, ratios))
                     + ". After the faults the error scales with the fault (0.2): it is the fault-estimate lag leaking "
                     "into d2_hat, not the manoeuvre.")
    obs = {n: observer_errors(r) for n, r in runs.items() if r.has("omega_hat")}
    if obs:
        doc.heading("Fig. 6: observer error ||omega - omega_hat||")
        doc.table(pd.DataFrame([[n, o["max_15_40"], o["max_after_40"], o["max_after_40_outside_2s_of_f2_steps"],
                                 o["share_above_3e-5_after_40"]] for n, o in obs.items()],
                               columns=["run", "max 15-40 s (000: 4e-7)", "max after 40 s (000: 3e-5)",
                                        "after 40 s, outside 2 s after each f2 step", "share of t >= 40 s above 3e-5"]),
                  units={"max 15-40 s (000: 4e-7)": "rad/s", "max after 40 s (000: 3e-5)": "rad/s",
                         "after 40 s, outside 2 s after each f2 step": "rad/s"})
