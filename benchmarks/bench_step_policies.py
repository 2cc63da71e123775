"""Work-precision of the step policies on li2023_fasmc (``make bench``).

Error against a 0.1 ms fixed-step reference versus work (FMU doSteps, summed over the three
components) for fixed steps of 10, 5, 2, 1 and 0.5 ms and for the adaptive policy (step
doubling with rollback) at rtol = 1e-4, 1e-6, 3e-7, 1e-8 (atol = rtol, output grid 10 ms, first
step 10 ms, max step 10 ms). Error: the largest deviation from the reference on the 10 ms grid
over the window, of the attitude quaternion (plant.q, dimensionless) and of the body rate
(plant.omega, rad/s).

The runs are in-process by default (``--mode fmu`` for the FMUs): the blocks are the FMUs'
blocks and give the same rows bit for bit (tests/orchestrator/test_step_policies.py checks it
for the adaptive policy), and the same doStep counts. Writes ``build/bench/step_policies.json``
and ``build/bench/step_policies.png``.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from orchestrator.cosim.runner import run_scenario  # noqa: E402
from orchestrator.scenario.checks import validate  # noqa: E402
from orchestrator.scenario.overrides import with_overrides  # noqa: E402
from orchestrator.scenario.toml import load  # noqa: E402

FIXED = (0.01, 0.005, 0.002, 0.001, 0.0005)
RTOLS = (1e-4, 1e-6, 3e-7, 1e-8)  # the three, and 3e-7 where the adaptive curve crosses the 1 ms accuracy
GRID = 0.01


def scenario(step, stop, mode, adaptive=None):
    from papers.registry import scenario_files

    sc = with_overrides(load(scenario_files()["li2023_fasmc"], in_process=(mode == "inprocess"), step=step), stop=stop)
    if adaptive is not None:
        timing = dataclasses.replace(sc.timing, policy="adaptive", rtol=adaptive, atol=adaptive, output_step=GRID,
                                     max_step=GRID, given=("step_policy", "rtol", "atol", "output_step", "max_step"))
        sc = validate("bench", dataclasses.replace(sc, timing=timing))
    return sc


def on_grid(r, stop):
    """Rows of ``r`` at the 10 ms grid points."""
    n = int(round(stop / GRID))
    k = np.round(r.time / GRID)
    keep = np.isclose(r.time, k * GRID, rtol=0, atol=1e-9) & (k >= 0)
    rows = np.nonzero(keep)[0]
    assert len(rows) == n + 1, (len(rows), n + 1)
    return r.data[rows]


def run(label, sc, mode, ref=None, stop=None):
    t0 = time.perf_counter()
    r = run_scenario(sc)
    wall = time.perf_counter() - t0
    if not r.complete:
        raise SystemExit(f"{label}: {r.error}")
    st = r.info["step_statistics"]
    row = {"label": label, "policy": st["policy"], "do_steps": st["do_steps_total"],
           "accepted_steps": st["accepted_steps"], "rejected_steps": st["rejected_steps"],
           "rollbacks": st["rollbacks"], "smallest_step": st["smallest_step"], "largest_step": st["largest_step"],
           "wall_s": round(wall, 2)}
    if ref is not None:
        d = on_grid(r, stop)
        q = [r.columns.index(f"plant.q[{i}]") for i in range(4)]
        w = [r.columns.index(f"plant.omega[{i}]") for i in (1, 2, 3)]
        eq = np.abs(d[:, q] - ref["q"]).max(axis=1)
        ew = np.abs(d[:, w] - ref["omega"]).max(axis=1)
        row["error_q"], row["error_omega"] = float(eq.max()), float(ew.max())
        # where the error peaks, and the largest error after the initial transient (t >= 20 s)
        row["t_max_error_q"] = float(eq.argmax() * GRID)
        late = np.arange(len(eq)) * GRID >= 20.0
        row["error_q_after_20s"] = float(eq[late].max()) if late.any() else None
    return r, row


def plot(rows, out, stop):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, key, what in ((axes[0], "error_q", "attitude ||q - q_ref||_max"), (axes[1], "error_omega",
                                                                                "rate ||omega - omega_ref||_max [rad/s]")):
        for pol, style in (("fixed", "o-"), ("adaptive", "s--")):
            pts = [r for r in rows if r["policy"] == pol]
            ax.loglog([r["do_steps"] for r in pts], [r[key] for r in pts], style, label=pol)
            for r in pts:
                ax.annotate(r["label"].split(" ", 1)[1], (r["do_steps"], r[key]), fontsize=7,
                            textcoords="offset points", xytext=(4, 4))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())  # decades only: no crowded labels
        ax.set_xlabel("FMU doSteps (3 components)")
        ax.set_ylabel(what)
        ax.grid(True, which="both", lw=0.3)
        ax.legend()
    fig.suptitle(f"li2023_fasmc, 0-{stop:g} s: error against a 0.1 ms fixed-step reference")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stop", type=float, default=50.0, help="end of the window [s] (default 50: past the fault onset at 40 s)")
    ap.add_argument("--mode", choices=["inprocess", "fmu"], default="inprocess")
    ap.add_argument("--out", default=str(ROOT / "build" / "bench"))
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    import os

    load_avg = os.getloadavg()
    ref_sc = scenario(1e-4, args.stop, args.mode)
    ref_sc = dataclasses.replace(ref_sc, record=[(i, v) for i, v in ref_sc.record if v.startswith(("q[", "omega["))
                                                 and i == "plant"])
    ref_run, ref_row = run("fixed 0.1 ms (reference)", ref_sc, args.mode)
    d = on_grid(ref_run, args.stop)
    ref = {"q": d[:, [ref_run.columns.index(f"plant.q[{i}]") for i in range(4)]],
           "omega": d[:, [ref_run.columns.index(f"plant.omega[{i}]") for i in (1, 2, 3)]]}
    del ref_run
    print(f"reference: fixed 0.1 ms, {ref_row['do_steps']} doSteps, {ref_row['wall_s']} s", flush=True)
    print(f"{'run':22s} {'doSteps':>9s} {'err q':>10s} {'err omega':>10s} {'acc':>7s} {'rej':>5s} {'h_min':>9s} "
          f"{'h_max':>9s} {'wall s':>7s} {'t(max)':>7s} {'err q>20s':>10s}", flush=True)
    rows = []
    for h in FIXED:
        _, row = run(f"fixed {h * 1e3:g} ms", scenario(h, args.stop, args.mode), args.mode, ref, args.stop)
        rows.append(row)
        _print(row)
    for rtol in RTOLS:
        _, row = run(f"adaptive rtol={rtol:g}", scenario(GRID, args.stop, args.mode, rtol), args.mode, ref, args.stop)
        rows.append(row)
        _print(row)
    one_ms = next(r for r in rows if r["label"] == "fixed 1 ms")
    better = [r for r in rows if r["policy"] == "adaptive" and r["error_q"] <= one_ms["error_q"]
              and r["error_omega"] <= one_ms["error_omega"]]
    cheaper = [r for r in better if r["do_steps"] < one_ms["do_steps"]]
    if cheaper:
        best = min(cheaper, key=lambda r: r["do_steps"])
        verdict = (f"adaptive reaches the 1 ms fixed-step accuracy (q {one_ms['error_q']:.2e}, omega "
                   f"{one_ms['error_omega']:.2e} rad/s, {one_ms['do_steps']} doSteps) with fewer doSteps: "
                   f"{best['label']} gives q {best['error_q']:.2e}, omega {best['error_omega']:.2e} with {best['do_steps']}")
    elif better:
        best = min(better, key=lambda r: r["do_steps"])
        verdict = (f"adaptive reaches the 1 ms fixed-step accuracy only with more doSteps: {best['label']} needs "
                   f"{best['do_steps']} against {one_ms['do_steps']}")
    else:
        verdict = "no adaptive run reaches the 1 ms fixed-step accuracy"
    print(verdict)
    png = out / "step_policies.png"
    plot(rows, png, args.stop)
    report = {"scenario": "li2023_fasmc", "window_s": [0.0, args.stop], "mode": args.mode, "grid_s": GRID,
              "reference": ref_row, "runs": rows, "verdict": verdict, "loadavg": load_avg}
    (out / "step_policies.json").write_text(json.dumps(report, indent=2) + "\n")
    print(f"written {out / 'step_policies.json'}, {png}")


def _print(r):
    print(f"{r['label']:22s} {r['do_steps']:9d} {r['error_q']:10.3e} {r['error_omega']:10.3e} {r['accepted_steps']:7d} "
          f"{r['rejected_steps']:5d} {r['smallest_step']:9.2e} {r['largest_step']:9.2e} {r['wall_s']:7.1f} "
          f"{r['t_max_error_q']:7.2f} {r['error_q_after_20s'] if r['error_q_after_20s'] is not None else float('nan'):10.3e}",
          flush=True)


if __name__ == "__main__":
    main()
