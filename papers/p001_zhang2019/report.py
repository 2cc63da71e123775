"""Paper 001's report: Figs. 2-8 equivalents (PNG) and Table 1 side by side with ours (report.md,
report.json), from result folders of ``ftcsim run`` (results.csv + metrics.json).

    python -m papers.p001_zhang2019.report results/zhang2019_* --out results/report_001

Each folder's scenario is looked up by name in this paper's ``scenarios/`` (for its [metrics]
table: signals, fault onset, windows); ``metrics.py`` computes the numbers. Figures:

  fig2_4_<run>.png   attitude (deg), body rate (deg/s), wheel commands (N.m) of a run without
                     fault estimation (001 Figs. 2-4: the passive FTC of [21]; ours is the
                     stand-in of zhang2019_passive*, NOT [21])
  fig5_<run>.png     true and estimated e_j, u_f,j per wheel and the equivalent fault torque
                     M((E - I) u_c + u_f) with its estimate (001 Fig. 5)
  fig6_8_<run>.png   attitude, rate, wheel commands of an FE/FTC run (001 Figs. 6-8)
  accuracy.png       max_i |sigma_i| and max_i |omega_i| on a log scale for every run (where the
                     Table 1 accuracies come from)
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from orchestrator.api import InputError
from orchestrator.results.files import Run
from orchestrator.results.report import Document, add_figures
from papers.reproduction import add_to, to_json

from .metrics import metrics
from .reproduction import READINGS, SIGN_RUNS, e_hat_drift
from .reproduction import rows as reproduction_rows

SCENARIOS = Path(__file__).resolve().parent / "scenarios"

REPRO_INTRO = ("Each row is one run (one reading); 'as printed' is zhang2019_fontsm, every other run is a variant "
               "(its chosen values named in the row). Table 1's column is judged under one reading at a time (the worst "
               "of its six entries). Fig. 1 is a block diagram (no result). Definitions 001 does not give: accuracy = "
               "max |x_i| over [30, 60] s; 'accurate estimation' = RMS error of the torque-level estimate <= 10 % of the "
               "RMS fault torque over [30, 60] s, and |e_hat_j - e_j| <= 10 % of the 0.4 loss at the end; without a band "
               "001's 28 s stabilization time cannot be placed.")

# 001 Table 1, verbatim ("+-" dropped): attitude (deg) nu, psi, gamma; rates (deg/s); stabilisation
TABLE1 = {
    "FTC in [21]": {"attitude": [0.412, 0.008, 0.264], "rate": [0.055, 0.067, 0.089], "stabilization": "Infinity"},
    "FTC in this paper": {"attitude": [2.6e-6, 2.3e-6, 1.2e-6], "rate": [4.4e-6, 2.0e-6, 3.5e-6], "stabilization": "28 s"},
}


def load_run(folder) -> tuple:
    """(RunResult, the scenario's [metrics] table as run, scenario name) of a result folder."""
    run = folder if isinstance(folder, Run) else Run(Path(folder))
    if not (SCENARIOS / f"{run.name}.toml").is_file():
        raise InputError(run.folder / "metrics.json", "scenario",
                         f"{run.name!r} is not a scenario of paper 001 ({SCENARIOS})")
    return run.result, run.metrics_config, run.name


def _thin(n: int, target: int = 6000) -> slice:
    return slice(None, None, max(1, n // target))


def _band(t, y, n=3000):
    """Per-bin min and max of y (n bins): a chattering signal keeps its true extent (plain
    thinning would alias a 2-step chatter onto one of its two levels)."""
    n = min(n, len(t))
    idx = np.minimum((np.arange(len(t)) * n) // len(t), n - 1)
    lo, hi = np.full(n, np.inf), np.full(n, -np.inf)
    np.minimum.at(lo, idx, y)
    np.maximum.at(hi, idx, y)
    tc = np.bincount(idx, weights=t, minlength=n) / np.maximum(np.bincount(idx, minlength=n), 1)
    return tc, lo, hi


def _plot_band(ax, t, y, label, color):
    tc, lo, hi = _band(t, y)
    ax.fill_between(tc, lo, hi, color=color, lw=0.6, alpha=0.8, label=label)


def _fig_motion(plt, r, cfg, title, path):
    t = r.time
    fig, ax = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
    sig = np.degrees(r.vector(cfg["euler"]))
    for i, lab in enumerate(("nu", "psi", "gamma")):
        _plot_band(ax[0], t, sig[:, i], lab, f"C{i}")
    ax[0].set_ylabel("attitude [deg]")
    w = np.degrees(r.vector(cfg["rate"]))
    for i in range(3):
        _plot_band(ax[1], t, w[:, i], f"omega_{i + 1}", f"C{i}")
    ax[1].set_ylabel("body rate [deg/s]")
    u = r.vector(cfg["control"])
    for j in range(u.shape[1]):
        _plot_band(ax[2], t, u[:, j], f"u_c{j + 1}", f"C{j}")
    ax[2].set_ylabel("wheel command [N.m]")
    ax[2].set_xlabel("time [s]")
    for a in ax:
        a.grid(True, lw=0.3)
        a.legend(fontsize=7, loc="upper right", ncol=4)
    fig.suptitle(title + ("" if r.complete else " (INCOMPLETE)") + "\n(bands: min-max per 1/3000 of the run)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _fig_faults(plt, r, cfg, title, path, sign=False):
    t = r.time
    k = _thin(len(t))
    fig, ax = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
    e, eh = r.vector("plant.e"), r.vector("est.e_hat")
    uf, ufh = r.vector("plant.u_f"), r.vector("est.uf_hat")
    for j in range(e.shape[1]):
        c = f"C{j}"
        ax[0].plot(t[k], e[k, j], c, lw=1.2, label=f"e_{j + 1}")
        ax[0].plot(t[k], eh[k, j], c, lw=0.8, ls="--", label=f"e_hat_{j + 1}")
        ax[1].plot(t[k], uf[k, j], c, lw=1.2, label=f"u_f{j + 1}")
        ax[1].plot(t[k], ufh[k, j], c, lw=0.8, ls="--", label=f"uf_hat_{j + 1}")
    ax[0].set_ylabel("effectiveness")
    ax[1].set_ylabel("bias [N.m]")
    f, fh = r.vector(cfg["fault_torque"]), r.vector(cfg["fault_torque_hat"])
    lim = 1.5 * max(0.05, float(np.abs(r.vector("plant.u_f")).max()))
    for i in range(3):
        c = f"C{i}"
        _plot_band(ax[2], t, f[:, i], f"fault torque {i + 1}", c)
        tc, lo, hi = _band(t, fh[:, i])
        ax[2].plot(tc, 0.5 * (lo + hi), c, lw=0.9, ls="--", label=f"estimate {i + 1}")
    ax[2].set_ylim(-lim, lim)
    ax[2].set_ylabel("M((E-I)u_c+u_f) [N.m]")
    ax[2].set_xlabel("time [s]")
    for a in ax:
        a.grid(True, lw=0.3)
        a.legend(fontsize=6, loc="upper left", ncol=4)
    fig.suptitle(title + "\ndashed: estimates; torque axis clipped" + (" (with sign(s) the LOE part of the fault torque "
                                                                     "chatters)" if sign else ""), fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _envelope(t, y, n=3000):
    """Max of |y| in n bins: a log plot that keeps the peaks of a chattering signal."""
    n = min(n, len(t))
    edges = np.linspace(t[0], t[-1], n + 1)
    idx = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, n - 1)
    env = np.full(n, -np.inf)
    np.maximum.at(env, idx, y)
    env[~np.isfinite(env)] = np.nan  # empty bins are not drawn
    return 0.5 * (edges[:-1] + edges[1:]), env


def _fig_accuracy(plt, runs, path):
    fig, ax = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True)
    for name, (r, cfg, _) in runs.items():
        t = r.time
        s = np.degrees(np.abs(r.vector(cfg["euler"]))).max(axis=1)
        w = np.degrees(np.abs(r.vector(cfg["rate"]))).max(axis=1)
        for a, y in ((ax[0], s), (ax[1], w)):
            tc, env = _envelope(t, y)
            a.semilogy(tc, np.maximum(env, 1e-12), lw=0.8, label=name + ("" if r.complete else " (stopped)"))
    for a, lab, tab in ((ax[0], "max_i |sigma_i| [deg]", 2.6e-6), (ax[1], "max_i |omega_i| [deg/s]", 4.4e-6)):
        a.axhline(tab, color="k", lw=0.6, ls=":", label="Table 1 (this paper)")
        a.set_ylabel(lab)
        a.grid(True, lw=0.3, which="both")
        a.legend(fontsize=6, loc="upper right")
    ax[1].set_xlabel("time [s]")
    fig.suptitle("Attitude and rate envelopes (log scale) against Table 1's accuracy", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _fmt(x):
    if x is None:
        return "-"
    if isinstance(x, str):
        return x
    return f"{x:.2g}" if abs(x) < 1e-2 or abs(x) >= 1e3 else f"{x:.3g}"


def _table(rows: dict):
    """Table 1 side by side: one row per quantity (units in its name), one column per run."""
    import pandas as pd

    names = list(rows)
    labels = [("attitude", i, f"attitude accuracy {a} [deg]") for i, a in enumerate(("nu", "psi", "gamma"))]
    labels += [("rate", i, f"rate accuracy omega_{i + 1} [deg/s]") for i in range(3)]
    out = [[label, *(rows[n][key][i] if rows[n].get(key) else None for n in names)] for key, i, label in labels]
    for key, label in (("stabilization", "stabilisation time"), ("stab_1e-4", "time to stay within 1e-4 deg [s]"),
                       ("stab_3e-6", "time to stay within 3e-6 deg [s]"), ("before", "max_i abs(sigma_i) 5 s before the fault [deg]"),
                       ("excursion", "max_i abs(sigma_i) 5 s after the fault [deg]"),
                       ("fe_ratio", "RMS(fault torque est. error) / RMS(fault torque)"),
                       ("bias_ratio", "same, bias part M u_f only"), ("u_rms", "RMS norm(u_c) in the window [N.m]")):
        out.append([label, *(rows[n].get(key) for n in names)])
    return pd.DataFrame(out, columns=["quantity", *names])


# one published reaction-wheel rating, for scale (not from 001): max torque 0.1 N.m (Sci. Rep. 14 (2024),
# doi 10.1038/s41598-024-65807-6, Table 3 "Actuator specifications")
WHEEL_TORQUE_REF = 0.1


def observer_section(runs: dict) -> list[str]:
    """Time constants of the printed and chosen observer gains, and the LOE drift as measured."""
    from . import analysis
    from . import gains as G
    from .parameters import ZHANG2019
    from .reproduction import e_hat_drift

    J, M = ZHANG2019["J"], ZHANG2019["M"]
    md = ["## Observer: time constants and the effectiveness drift", "",
          "Slow modes of the linearised bias-error system (001 (13)-(14), U = 0; `analysis.bias_modes`):", "",
          "| gains | lambda_2 | slowest time constants [s] |", "|---|---|---|"]
    for label, l2 in (("printed (001 section 5)", G.LAMBDA_2), ("chosen (fast observer, ours)", G.FAST_OBSERVER["lambda_2"])):
        tc = analysis.bias_modes(G.LAMBDA, J, M, l2)["slowest_time_constants_s"]
        md.append(f"| {label} | {l2:g} | {', '.join(f'{x:.4g}' for x in sorted(tc, reverse=True))} |")
    drift = e_hat_drift(runs)
    if drift:
        md += ["", "Effectiveness estimate e_hat_2 (true e_2 = 1 before 20 s, 0.6 after; e_hat_2(0) = 1) and the command "
               "it is correlated with. With sign(s) at a fixed step u_c2 changes sign at almost every step, so the "
               "innovation at t_k (which answers u_c(t_k-1)) multiplied by U(t_k) in the literal sampled form of (14) "
               "has the wrong sign: e_hat_2 moves away from e_2. `command_pairing = 1` multiplies it by U(t_k-1):", "",
               "| run | reading | e_hat_2(20 s) | e_hat_2(end) | u_c2 sign changes per step, 30-60 s | RMS u_c2, 30-60 s [N.m] |",
               "|---|---|---|---|---|---|"]
        for d in drift:
            md.append(f"| {d['run']} | {d['reading']} | {d['e_hat_2_at_20s']:.5g} | {d['e_hat_2_end']:.5g} | "
                      f"{_fmt(d['u_c2_sign_changes_per_step_30_60s'])} | {_fmt(d['u_c2_rms_30_60s'])} |")
    return md + [""]


def chatter_and_torque_section(loaded: dict, numbers: dict) -> list[str]:
    """The chatter amplitude eps_1 h / 2 against the measured rates (sign(s) runs only: a boundary layer does not
    chatter), and the torque levels, over the whole run and over the window, against a reaction wheel."""
    from . import gains as G
    from .parameters import OMEGA0, ZHANG2019
    from .reproduction import SIGN_RUNS

    md = ["## Chatter and torque levels", ""]
    sign = [n for n in loaded if n in SIGN_RUNS]
    for name in sign:
        r = loaded[name][0]
        h = float(r.time[1] - r.time[0])
        m = numbers[name]
        md.append(f"* {name} (sign(s) as printed): eps_1 h / 2 = {np.degrees(G.EPS_1[0] * h / 2):.3g} deg/s at h = "
                  f"{1e3 * h:g} ms is the amplitude at which a sign(s) law chatters omega; the measured max |omega_i| over "
                  f"the accuracy window is {', '.join(_fmt(x) for x in (m.get('rate_accuracy_deg_s') or []))} deg/s.")
    others = [n for n in loaded if n not in SIGN_RUNS]
    if others:
        md.append(f"* {', '.join(others)}: a boundary layer sat(s/phi) replaces sign(s), so the chatter bound above does "
                  "not apply to them.")
    h0 = float(np.linalg.norm(ZHANG2019["J"] @ OMEGA0))
    md += ["", f"Torque levels (J = 30 / 27 / 19 kg.m^2): eps_1 sign(s) alone is J eps_1 ~ {1.5 * 30:.0f} N.m on an axis; "
           f"the initial momentum |J omega(0)| = {h0:.3g} N.m.s. For scale, one published reaction-wheel rating: "
           f"{WHEEL_TORQUE_REF:g} N.m maximum torque (Sci. Rep. 14 (2024), doi 10.1038/s41598-024-65807-6, Table 3). "
           "Every run commands its largest torque at t ~ 0 (the initial tumble), where the wheel comparison matters most.",
           "", "| run | max abs(u_c) over the run [N.m] | at t [s] | max over the run / "
           f"{WHEEL_TORQUE_REF:g} N.m | max abs(u_c) over the window [N.m] | max over the window / {WHEEL_TORQUE_REF:g} N.m | "
           "RMS norm(u_c) window [N.m] |", "|---|---|---|---|---|---|---|"]
    for name, (r, cfg, _) in loaded.items():
        m = numbers[name]
        w, full = m.get("max_abs_u_c_window"), m.get("max_abs_u_c")
        t_peak = None
        if "control" in cfg:
            u = np.abs(r.vector(cfg["control"])).max(axis=1)
            t_peak = float(r.time[int(np.argmax(u))]) if len(u) else None
        md.append(f"| {name} | {_fmt(full)} | {_fmt(t_peak)} | {_fmt(None if full is None else full / WHEEL_TORQUE_REF)} | "
                  f"{_fmt(w)} | {_fmt(None if w is None else w / WHEEL_TORQUE_REF)} | {_fmt(m.get('rms_u_c_window'))} |")
    return md + [""]


def make_report(runs, out) -> dict:
    """``runs``: result folders (paths) of this paper's scenarios. Writes the figures, report.md
    and report.json into ``out``; returns the report dictionary."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    loaded = {}
    for folder in runs:
        r, cfg, name = load_run(folder)  # a path or an orchestrator.results.files.Run
        loaded[name] = (r, cfg, folder)
    files, rows, numbers = [], {}, {}
    for name, (r, cfg, _) in loaded.items():
        m = metrics(r, cfg)
        numbers[name] = m
        fe = "fault_torque_hat" in cfg
        reading = READINGS.get(name, (None,))[0]
        tag = f"{name} ({reading})" if reading else name
        if fe:
            p = f"fig5_{name}.png"
            _fig_faults(plt, r, cfg, f"{tag}: faults and their estimates (001 Fig. 5)", out / p, sign=name in SIGN_RUNS)
            files.append(p)
        p = f"{'fig6_8' if fe else 'fig2_4'}_{name}.png"
        what = "FE/FTC (001 Figs. 6-8)" if fe else "no fault estimation: stand-in, NOT 001's [21] (001 Figs. 2-4)"
        _fig_motion(plt, r, cfg, f"{tag}: {what}", out / p)
        files.append(p)
        rows[name] = {
            "attitude": m.get("attitude_accuracy_deg"),
            "rate": m.get("rate_accuracy_deg_s"),
            "stabilization": m.get("stabilization_time_s", {}).get("0.01"),
            "stab_1e-4": m.get("stabilization_time_s", {}).get("0.0001"),
            "stab_3e-6": m.get("stabilization_time_s", {}).get("3e-06"),
            "before": m.get("max_attitude_before_fault_deg"),
            "excursion": m.get("max_attitude_after_fault_deg"),
            "fe_ratio": m.get("fault_torque_estimate_rms_error_ratio"),
            "bias_ratio": m.get("bias_torque_estimate_rms_error_ratio"),
            "u_rms": m.get("rms_u_c_window"),
        }
        if not r.complete:
            rows[name]["stabilization"] = f"stopped at {r.time[-1]:.3g} s"
    _fig_accuracy(plt, {n: v for n, v in loaded.items()}, out / "accuracy.png")
    files.append("accuracy.png")
    by_name = {name: (r, cfg, numbers[name]) for name, (r, cfg, _) in loaded.items()}
    repro = reproduction_rows(by_name)
    paper_rows = {k + " (001)": {"attitude": v["attitude"], "rate": v["rate"], "stabilization": v["stabilization"]}
                  for k, v in TABLE1.items()}
    any_m = next(iter(numbers.values()), {})
    d = any_m.get("definitions", {})
    doc = Document("Paper 001 (Zhang, Gao, Qian, Bai 2019): reproduction of section 5 (Table 1, Figs. 2-8)", out)
    add_to(doc, repro, "Reproduction table (computed from this report's runs)", REPRO_INTRO)
    doc.heading("Table 1 and our runs")
    doc.text("Definitions (001 states none): accuracy = max |x_i| over the window "
             f"{d.get('accuracy_window_s')} s; stabilisation time = first time after which every |sigma_i| "
             "stays below 0.01 deg until the end of the run (also given for 1e-4 and 3e-6 deg); "
             f"fault onset {d.get('fault_onset_s')} s; fault-estimate RMS over {d.get('estimate_window_s')} s.\n"
             "The runs without fault estimation are our stand-in (FONTSM with the estimates disconnected), NOT 001's ref. [21].")
    doc.table(_table({**paper_rows, **rows}), digits=3)
    doc.text("\n".join(observer_section(by_name) + chatter_and_torque_section(loaded, numbers)))
    add_figures(doc, files)
    report = {"table1_paper": TABLE1, "ours": rows, "metrics": numbers, "figures": files,
              "reproduction": to_json(repro), "e_hat_drift": e_hat_drift(by_name)}
    doc.write()
    (out / "report.json").write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    return report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m papers.p001_zhang2019.report", description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", help="result folders of `ftcsim run` on paper 001's scenarios")
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    try:
        make_report(args.runs, args.out)
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print((Path(args.out) / "report.md").read_text())
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
