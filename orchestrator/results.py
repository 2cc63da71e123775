"""Results of a run: results.csv, metrics.json and PNG plots, written atomically."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from orchestrator.common.jsonio import strict_json, write_json_atomic  # noqa: F401 (strict_json re-exported)


def quaternion_vector_norm(q_e: np.ndarray) -> np.ndarray:
    """||q_ev|| for rows of [q_e0, q_ev]."""
    return np.linalg.norm(q_e[:, 1:4], axis=1)


def base_metrics(result, scenario) -> dict:
    """What every run reports: scenario, completeness, timing, and the step policy's
    ``step_statistics`` (accepted / rejected steps, smallest / largest step, rollbacks, doSteps
    per instance, wall time; ``orchestrator/cosim/policies.py``)."""
    t_end = float(result.time[-1]) if len(result.time) else None
    simulated = t_end - float(result.time[0]) if len(result.time) else 0.0
    m = {
        "scenario": scenario.name,
        "complete": result.complete,
        "error": result.error,
        "mode": result.mode,
        "exchange": result.exchange,
        "t_end": t_end,
        "steps": result.steps,
        "step": scenario.step,
        "step_policy": result.info.get("policy") or getattr(scenario, "step_policy", "fixed"),
        "wall_time_s": round(result.wall_time, 4),
        # simulated time over wall time (steps * step is wrong for variable steps)
        "real_time_factor": (simulated / result.wall_time) if result.wall_time > 0 and simulated > 0 else None,
        "paper": scenario.paper or None,
        "signals": {k: v for k, v in scenario.metrics.items() if isinstance(v, str)},
        "metrics_config": dict(scenario.metrics),  # the whole [metrics] table, for the reports
    }
    if "step_statistics" in result.info:
        m["step_statistics"] = result.info["step_statistics"]
    return m


def held_integral(time: np.ndarray, values: np.ndarray) -> float:
    """int v(t) dt for a signal held from each row to the next (zero-order hold), over rows
    at any times: sum_k v_k (t_{k+1} - t_k). Exact when the signal changes only at rows (fixed
    and multirate runs, announced instants recorded); for an adaptive run whose command changes
    at every accepted step but is recorded on the output grid, the left Riemann sum on the grid."""
    if len(time) < 2:
        return 0.0
    return float(np.sum(values[:-1] * np.diff(time)))


def compute_metrics(result, scenario) -> dict:
    """Run metrics from the recorded signals named in the scenario's [metrics] table.

    E = int ||u||^2 dt is summed exactly for a command held over each row interval (000 section
    5), with the intervals between the recorded times (:func:`held_integral`)."""
    m = base_metrics(result, scenario)
    cfg = scenario.metrics
    if len(result.time) == 0:
        return m
    if "attitude_error" in cfg:
        qe = result.vector(cfg["attitude_error"])
        nq = quaternion_vector_norm(qe)
        m["final_attitude_error"] = float(nq[-1])
        m["max_attitude_error_last_10s"] = float(nq[result.time >= result.time[-1] - 10.0].max())  # never empty
    if "rate_error" in cfg:
        we = np.linalg.norm(result.vector(cfg["rate_error"]), axis=1)
        m["final_rate_error"] = float(we[-1])
    if "control" in cfg:
        u = result.vector(cfg["control"])
        m["control_energy"] = held_integral(result.time, np.sum(u**2, axis=1))
        m["max_abs_u"] = float(np.abs(u).max())
        if "u_max" in cfg:
            m["u_max"] = float(cfg["u_max"])
            m["saturation_respected"] = bool(m["max_abs_u"] <= float(cfg["u_max"]) + 1e-12)
    m.update(paper_metrics(result, scenario))
    return m


def paper_metrics(result, scenario) -> dict:
    """The metrics the scenario's paper defines (``Paper.metrics``), if it names a known paper."""
    from papers.paper import resolve
    from papers.registry import paper

    try:
        p = paper(scenario.paper)
    except KeyError:
        return {}
    return resolve(p.metrics)(result, scenario.metrics) if p.metrics else {}


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


def write_json(path: Path, data) -> None:
    """Strict JSON (``orchestrator.common.jsonio``), written atomically."""
    write_json_atomic(path, data)


def write_results(folder, result, scenario, plots: bool = True) -> tuple[dict, list[str]]:
    """Write a run into ``folder`` (an :class:`orchestrator.common.outputs.OutputFolder`, checked before
    the run) and publish it. ``results.csv`` is written first; a failure of any later step
    (metrics, plots) is recorded in ``metrics.json`` (``post_processing_errors``) and returned,
    never allowed to lose the CSV. Returns (metrics, errors)."""
    tmp = folder.staging()
    errors = []
    try:
        write_csv(tmp / "results.csv", result)
        if not result.complete:
            (tmp / "INCOMPLETE").write_text((result.error or "run did not finish") + "\n", encoding="utf-8")
        try:
            metrics = compute_metrics(result, scenario)
        except Exception as e:  # a bug or an unforeseen signal shape: keep the run, say what failed
            metrics = base_metrics(result, scenario)
            errors.append(f"metrics: {type(e).__name__}: {e}")
        if plots and len(result.time) > 1:
            try:
                metrics["plots"] = plot(result, scenario, tmp)
            except Exception as e:
                errors.append(f"plots: {type(e).__name__}: {e}")
        if errors:
            metrics["post_processing_errors"] = errors
        write_json(tmp / "metrics.json", metrics)
    except BaseException:
        if (tmp / "results.csv").is_file():
            folder.publish()  # the rows are safe on disk: publish what there is
        else:
            folder.discard()
        raise
    folder.publish()
    return metrics, errors
