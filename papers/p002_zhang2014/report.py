"""Paper 002's figures and table from runs of its scenarios (``zhang2014_hinf_w1``, ``_w05``, ``_w02``).

``make_report(runs, out)``: ``runs`` is a list of result folders (``orchestrator.results.files.Run``)
or maps a scenario name to its RunResult (or to (RunResult, cfg) with
the [metrics] table; by default the table of the shipped scenario of that name); ``out`` a folder.
Writes
  fig1_attitude.png   theta(t) and theta'(t), one curve per omega_hat (002 Fig. 1)
  fig2_control.png    command u(t) and applied torque omega u(t) per omega_hat (002 Fig. 2)
  report.md / report.json   per run: Table 2 gain, u(0), peak, settling times, J_c against J*,
                      closed-loop poles fitted from the run against the model's with the Table 2 K
                      (a run with --gains differs by design) (sampled-data and
                      continuous), and the Table 1 / Table 2 rounding difference.
Returns the report dict.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from orchestrator.results.report import Document, add_figures
from papers.reproduction import add_to, fmt, to_json

from .gains import CASES, PUBLISHED
from .metrics import metrics
from .parameters import ZHANG2014

SCENARIOS = Path(__file__).parent / "scenarios"


def scenario_cfg(name: str) -> dict:
    """The [metrics] table of this paper's shipped scenario ``name``, as a run of it uses it."""
    from orchestrator import api

    return dict(api.load(SCENARIOS / f"{name}.toml", mode="inprocess").metrics)


def model_poles(K, omega, h=None):
    """Closed-loop poles of the 6-state model with u = K x, torque omega u: continuous, or of the
    sampled-data loop (command held over h) as log(eig) / h."""
    import scipy.linalg as sla

    from plant.pitch_axis import flexible_model

    A, B, _ = flexible_model(ZHANG2014["J"], ZHANG2014["F"], ZHANG2014["omega"], ZHANG2014["xi"])
    Kz = np.zeros((1, A.shape[0]))
    Kz[0, :2] = np.asarray(K, float).reshape(-1)
    if h is None:
        lam = np.linalg.eigvals(A + omega * B @ Kz)
    else:
        n = A.shape[0]
        E = sla.expm(np.block([[A, B], [np.zeros((1, n + 1))]]) * h)
        lam = np.log(np.linalg.eigvals(E[:n, :n] + omega * E[:n, n:] @ Kz).astype(complex)) / h
    return sorted(lam, key=lambda z: (round(z.imag, 9), z.real))


def table1_rounding() -> dict:
    """|W V1^-1| (Table 1) against |K| (Table 2): relative difference of the magnitudes, per entry."""
    out = {}
    for w in CASES:
        p = PUBLISHED[w]
        K1 = (np.asarray(p["W"]) @ np.linalg.inv(p["V1"])).ravel()
        K2 = np.asarray(p["K"]).ravel()
        out[w] = {"W_V1inv": K1.tolist(), "K": K2.tolist(), "rel_diff": ((np.abs(K1) - np.abs(K2)) / np.abs(K2)).tolist()}
    return out


def _fmt_poles(poles):
    return ", ".join(f"{re:.5f}" if abs(im) < 1e-12 else f"{re:.5f}{im:+.4f}j" for re, im in poles if im >= 0)


REPRO_INTRO = ("002 prints Tables 1-2 (LMI results) and two figures without numbers. The Table 1 / J* rows solve (22) "
               "with the published V1, W (P_hat, delta free, kappa searched; stored in "
               "papers/p002_zhang2014/certificate_study.json with its command). As printed, Lemma 1 with L^T L <= I lets the "
               "effectiveness reach 0, where (22) cannot hold; |L| <= j = 0.75 is a variant (j is chosen below 0.78, the "
               "largest j at which Table 1 is feasible); L = 0 certifies almost any J* and is reported as a check that "
               "cannot fail. The runs: zhang2014_hinf_w1 / _w05 / _w02 (effectiveness = omega_hat from t = 0).")


def make_report(runs, out) -> dict:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    items = []
    if isinstance(runs, (list, tuple)):  # result folders (orchestrator.results.files.Run), from `ftcsim report`
        runs = {r.name: (r.result, r.metrics_config or scenario_cfg(r.name)) for r in runs}
    for name, val in runs.items():
        res, cfg = val if isinstance(val, tuple) else (val, scenario_cfg(name))
        items.append((name, res, cfg, metrics(res, cfg)))
    items.sort(key=lambda x: -x[3].get("omega_hat", 0))

    fig, ax = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    fig2, ax2 = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    for _name, res, cfg, m in items:
        lab = f"omega_hat = {m['omega_hat']:g}"
        ax[0].plot(res.time, res.column(cfg["theta"]), lw=1, label=lab)
        ax[1].plot(res.time, res.column(cfg["theta_dot"]), lw=1, label=lab)
        ax2[0].plot(res.time, res.column(cfg["command"]), lw=1, label=lab)
        ax2[1].plot(res.time, res.column(cfg["torque"]), lw=1, label=lab)
    for a, yl in zip(list(ax) + list(ax2), ["theta [rad]", "theta_dot [rad/s]", "u [N.m]", "omega u [N.m]"]):
        a.set_ylabel(yl)
        a.grid(True, lw=0.3)
        a.legend(fontsize=7)
    ax[1].set_xlabel("time [s]")
    ax2[1].set_xlabel("time [s]")
    fig.suptitle("002 Fig. 1: pitch angle and rate under partial actuator failure (ours)")
    fig2.suptitle("002 Fig. 2: control effect, command u and applied torque omega u (ours)")
    for f, fname in ((fig, "fig1_attitude.png"), (fig2, "fig2_control.png")):
        f.tight_layout()
        f.savefig(out / fname, dpi=110)
        plt.close(f)

    from papers.p002_zhang2014.design import cost_exact

    rows = []
    for name, res, _cfg, m in items:
        w = m["omega_hat"]
        K = PUBLISHED[w]["K"] if w in PUBLISHED else None
        h = float(res.time[1] - res.time[0])
        row = {"scenario": name, **m}
        if K is not None:
            row["K"] = K[0]
            row["poles_model_sampled"] = [(float(z.real), float(z.imag)) for z in model_poles(K, w, h)]
            row["poles_model_continuous"] = [(float(z.real), float(z.imag)) for z in model_poles(K, w)]
            row["J_c_lyapunov_flexible"] = cost_exact(np.asarray(K), w, flexible=True)
            fit, mod = np.array(m["poles_fit"]), np.array(row["poles_model_sampled"])
            row["poles_fit_vs_model_max_rel"] = (float(np.max(np.abs((fit - mod)[:, 0] + 1j * (fit - mod)[:, 1])
                                                               / np.abs(mod[:, 0] + 1j * mod[:, 1])))
                                                 if fit.shape == mod.shape else None)
        rows.append(row)
    from .reproduction import load_certificates, published_certificate
    from .reproduction import rows as reproduction_rows

    certificates = load_certificates() or {w: published_certificate(w) for w in CASES}  # stored LMI solves (certificate_study.py)
    repro = reproduction_rows({name: (res, cfg, m) for name, res, cfg, m in items}, certificates)
    rep = {"paper": "002", "runs": rows, "table1_vs_table2": table1_rounding(),
           "figures": ["fig1_attitude.png", "fig2_control.png"], "reproduction": to_json(repro),
           "published_certificates": certificates}
    doc = Document("Paper 002 (Zhang, Qiao, Li, Guo 2014): reproduction of section 4 (Tables 1-2, Figs. 1-2)", out)
    add_to(doc, repro, "Reproduction table (computed from this report's runs and LMIs)", REPRO_INTRO)
    doc.heading("Smallest J* certified by the published gains")
    jc = {r["omega_hat"]: r["J_c"] for r in rows}
    cert = []
    for w in CASES:
        c = certificates[w]
        jm, j_run = c["J_star_min"], jc.get(w)
        yes = lambda k: "no" if k is None else f"yes (kappa {k:.3g})"  # noqa: E731
        cert.append([w, c["printed_J_star"], f"{fmt(jm)} ({c['kappa']:.3g})", c["J_star_max_grid"],
                     f"{yes(c['printed_certified_kappa'])} / {yes(c['printed_certified_kappa_nominal'])}", j_run,
                     None if j_run is None else j_run / c["printed_J_star"],
                     None if j_run is None or jm is None else j_run / jm])
    doc.table(pd.DataFrame(cert, columns=[
        "omega_hat", "J* printed", "J* certified by Table 1's V1, W, j = 0.75: smallest (kappa)",
        "largest on the kappa grid", "printed J* certified, j = 0.75 / L = 0", "J_c (run)", "J_c / J* printed",
        "J_c / J* smallest"]))
    doc.heading("Runs")
    runs_df = pd.DataFrame([{
        "omega_hat": r["omega_hat"], "K (Table 2)": r.get("K"), "u(0)": r["u0"], "omega u(0)": r["tau0"],
        "peak theta": r["peak_theta"], "t(peak theta)": r["t_peak"], "2 % settling": r["settling_time_2pct"],
        "5 % settling": r["settling_time_5pct"], "J_c (run)": r["J_c"],
        "J_c (Lyapunov)": r.get("J_c_lyapunov_flexible"), "J* (Table 2)": r["J_star_printed"]} for r in rows])
    doc.table(runs_df, units={"u(0)": "N.m", "omega u(0)": "N.m", "peak theta": "rad", "t(peak theta)": "s",
                              "2 % settling": "s", "5 % settling": "s"}, digits=5)
    poles = ["Closed-loop poles [1/s] (upper half plane): fitted from the run / sampled-data model / continuous model", ""]
    for r in rows:
        poles.append(f"* omega_hat = {r['omega_hat']:g}: fit {_fmt_poles(r['poles_fit'])}")
        if "poles_model_sampled" in r:
            poles.append(f"  model (ZOH {1e3 * (res.time[1] - res.time[0]):.0f} ms) {_fmt_poles(r['poles_model_sampled'])}; "
                         f"max relative difference to the fit {r['poles_fit_vs_model_max_rel']:.2e}")
            poles.append(f"  continuous {_fmt_poles(r['poles_model_continuous'])}")
    doc.text("\n".join(poles))
    t1 = ["Table 1 W V1^-1 against Table 2 K (|W V1^-1| / |K| - 1, entries K1 / K2):", ""]
    for w, d in rep["table1_vs_table2"].items():
        t1.append(f"* omega_hat = {w:g}: W V1^-1 = [{d['W_V1inv'][0]:.4f}, {d['W_V1inv'][1]:.4f}], "
                  f"{100 * d['rel_diff'][0]:+.2f} % / {100 * d['rel_diff'][1]:+.2f} %")
    doc.text("\n".join(t1))
    add_figures(doc, rep["figures"])
    doc.write()
    (out / "report.json").write_text(json.dumps(rep, indent=2, default=float) + "\n", encoding="utf-8")
    return rep
