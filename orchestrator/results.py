"""Results of a run: results.csv, metrics.json and PNG plots, written atomically."""
from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

import numpy as np


def quaternion_vector_norm(q_e: np.ndarray) -> np.ndarray:
    """||q_ev|| for rows of [q_e0, q_ev]."""
    return np.linalg.norm(q_e[:, 1:4], axis=1)


def compute_metrics(result, scenario) -> dict:
    """Run metrics from the recorded signals named in the scenario's [metrics] table.

    E = int ||u||^2 dt is summed exactly for a command held over each step (000 section 5)."""
    m = {
        "scenario": scenario.name,
        "complete": result.complete,
        "error": result.error,
        "mode": result.mode,
        "exchange": result.exchange,
        "t_end": float(result.time[-1]) if len(result.time) else None,
        "steps": result.steps,
        "step": scenario.step,
        "wall_time_s": round(result.wall_time, 4),
        "real_time_factor": (result.steps * scenario.step / result.wall_time) if result.wall_time > 0 else None,
    }
    cfg = scenario.metrics
    m["signals"] = {k: v for k, v in cfg.items() if isinstance(v, str)}
    if len(result.time) == 0:
        return m
    h = scenario.step
    if "attitude_error" in cfg:
        qe = result.vector(cfg["attitude_error"])
        nq = quaternion_vector_norm(qe)
        m["final_attitude_error"] = float(nq[-1])
        m["max_attitude_error_last_10s"] = float(nq[result.time >= result.time[-1] - 10.0].max())
    if "rate_error" in cfg:
        we = np.linalg.norm(result.vector(cfg["rate_error"]), axis=1)
        m["final_rate_error"] = float(we[-1])
    if "control" in cfg:
        u = result.vector(cfg["control"])
        m["control_energy"] = float(np.sum(np.sum(u[:-1] ** 2, axis=1)) * h)
        m["max_abs_u"] = float(np.abs(u).max())
        if "u_max" in cfg:
            m["u_max"] = float(cfg["u_max"])
            m["saturation_respected"] = bool(m["max_abs_u"] <= float(cfg["u_max"]) + 1e-12)
    m.update(estimation_metrics(result, cfg))
    return m


def _window(t, a, b):
    return (t >= a - 1e-9) & (t <= b + 1e-9)


def estimation_metrics(result, cfg) -> dict:
    """Observer metrics (000 section 5.2) when the [metrics] table names the signals:
    ``omega`` / ``omega_hat`` (state estimate), ``f`` / ``f_hat`` (fault estimate),
    ``d2`` = [eta, eta_dot] pair via ``eta`` / ``eta_dot`` and ``d2_hat``.
    Windows: ``settle_time`` (15 s), ``fault_onset`` (40 s), ``fault_window`` ([50, end])."""
    t = result.time
    m = {}
    settle = float(cfg.get("settle_time", 15.0))
    onset = float(cfg.get("fault_onset", 40.0))
    win = cfg.get("fault_window", [50.0, float(t[-1])])
    if "omega" in cfg and "omega_hat" in cfg:
        e = np.linalg.norm(result.vector(cfg["omega"]) - result.vector(cfg["omega_hat"]), axis=1)
        m["observer_error_max_settled_before_faults"] = float(e[_window(t, settle, onset)].max(initial=0.0))
        m["observer_error_max_after_faults"] = float(e[t >= onset].max(initial=0.0))
        m["observer_error_final"] = float(e[-1])
        pre = np.nonzero((e > 1e-5) & (t < onset))[0]
        # first time after which the error stays below 1e-5 rad/s until the faults start
        if len(pre) == 0:
            m["observer_settling_time_1e-5"] = float(t[0])
        elif t[pre[-1]] + result.time[1] - result.time[0] < onset:
            m["observer_settling_time_1e-5"] = float(t[pre[-1] + 1])
        else:
            m["observer_settling_time_1e-5"] = None
    if "f" in cfg and "f_hat" in cfg:
        w = _window(t, float(win[0]), float(win[1]))
        f, fh = result.vector(cfg["f"])[w], result.vector(cfg["f_hat"])[w]
        rms_f = float(np.sqrt(np.mean(np.sum(f**2, axis=1))))
        rms_e = float(np.sqrt(np.mean(np.sum((fh - f) ** 2, axis=1))))
        m["fault_rms"] = rms_f
        m["fault_estimate_rms_error"] = rms_e
        m["fault_estimate_rms_error_ratio"] = rms_e / rms_f if rms_f > 0 else None
        for i in range(f.shape[1]):
            ri = float(np.sqrt(np.mean(f[:, i] ** 2)))
            m[f"fault_estimate_rms_error_{i + 1}"] = float(np.sqrt(np.mean((fh[:, i] - f[:, i]) ** 2)))
            m[f"fault_rms_{i + 1}"] = ri
    if "eta" in cfg and "eta_dot" in cfg and "d2_hat" in cfg:
        d2 = np.hstack([result.vector(cfg["eta"]), result.vector(cfg["eta_dot"])])
        e = np.linalg.norm(result.vector(cfg["d2_hat"]) - d2, axis=1)
        w = t >= settle
        m["vibration_estimate_error_max"] = float(e[w].max(initial=0.0))
        m["vibration_state_max"] = float(np.linalg.norm(d2, axis=1)[w].max(initial=0.0))
    return m


def write_csv(path: Path, result) -> None:
    header = ",".join(["time"] + result.columns)
    table = np.column_stack([result.time, result.data]) if len(result.time) else np.zeros((0, 1 + len(result.columns)))
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.17g")


def read_csv(path) -> tuple[list[str], np.ndarray]:
    path = Path(path)
    with open(path, encoding="utf-8") as fh:
        header = fh.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return header, data


def plot(result, scenario, out_dir: Path) -> list[str]:
    """One PNG per instance: every recorded vector signal of it in its own panel."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = []
    groups: dict[str, dict[str, list[int]]] = {}
    for k, col in enumerate(result.columns):
        inst, var = col.split(".", 1)
        groups.setdefault(inst, {}).setdefault(var.split("[")[0], []).append(k)
    for inst, sigs in groups.items():
        n = len(sigs)
        fig, axes = plt.subplots(n, 1, figsize=(8, 2.0 * n + 0.5), sharex=True, squeeze=False)
        for ax, (base, cols) in zip(axes[:, 0], sigs.items()):
            for k in cols:
                ax.plot(result.time, result.data[:, k], lw=0.8, label=result.columns[k].split(".", 1)[1])
            ax.set_ylabel(base)
            ax.grid(True, lw=0.3)
            if len(cols) <= 8:
                ax.legend(fontsize=6, loc="upper right", ncol=min(4, len(cols)))
        axes[-1, 0].set_xlabel("time [s]")
        fig.suptitle(f"{scenario.name}: {inst}" + ("" if result.complete else " (INCOMPLETE)"))
        fig.tight_layout()
        name = f"{inst}.png"
        fig.savefig(out_dir / name, dpi=110)
        plt.close(fig)
        files.append(name)
    return files


def write_results(out: Path, result, scenario, plots: bool = True) -> dict:
    """Write everything into a temporary folder beside ``out``, then move it into place."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    try:
        write_csv(tmp / "results.csv", result)
        metrics = compute_metrics(result, scenario)
        if plots and len(result.time) > 1:
            metrics["plots"] = plot(result, scenario, tmp)
        (tmp / "metrics.json").write_text(json.dumps(metrics, indent=2) + "\n", encoding="utf-8")
        if not result.complete:
            (tmp / "INCOMPLETE").write_text((result.error or "run did not finish") + "\n", encoding="utf-8")
        if out.exists():
            shutil.rmtree(out)
        tmp.rename(out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return metrics
