"""The files of a run: results.csv, metrics.json and PNG plots, written atomically
(:func:`write_results`), and read back (:class:`Run`)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import write_json_atomic
from orchestrator.common.outputs import is_result_folder
from orchestrator.cosim.master import RunResult
from orchestrator.results.metrics import base_metrics, compute_metrics


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


class Run:
    """One result folder of ``ftcsim run``, checked: readable CSV with a ``time`` column and numbers,
    a metrics object, signals that name columns. The one reader of a run folder (reports, papers):
    ``metrics`` (metrics.json), ``metrics_config`` (the scenario's [metrics] table), ``header`` and
    ``data`` (results.csv), ``t``, ``signals``, :attr:`result` (a RunResult)."""

    def __init__(self, folder: Path):
        folder = Path(folder)
        self.folder = folder
        if not folder.is_dir():
            raise InputError(folder, "-", "result folder not found")
        for f in ("results.csv", "metrics.json"):
            if not (folder / f).is_file():
                raise InputError(folder, f, "missing: not a result folder of `ftcsim run`")
        try:
            self.metrics = json.loads((folder / "metrics.json").read_text(encoding="utf-8"),
                                      parse_constant=lambda c: None)
        except (ValueError, UnicodeDecodeError) as e:
            raise InputError(folder / "metrics.json", "-", f"not valid JSON: {e}") from None
        if not isinstance(self.metrics, dict):
            raise InputError(folder / "metrics.json", "-", "not a JSON object")
        try:
            self.header, self.data = read_csv(folder / "results.csv")
        except (ValueError, UnicodeDecodeError, OSError) as e:
            raise InputError(folder / "results.csv", "-", f"unreadable: {' '.join(str(e).split())[:200]}") from None
        if not self.header or self.header[0] != "time" or self.data.shape[1] != len(self.header):
            raise InputError(folder / "results.csv", "header", "expected 'time' then one column per signal")
        if self.data.shape[0] == 0:
            raise InputError(folder / "results.csv", "-", "no rows")
        self.name = str(self.metrics.get("scenario") or folder.name)
        self.paper = self.metrics.get("paper")
        signals = self.metrics.get("signals", {})
        if not isinstance(signals, dict) or not all(isinstance(v, str) for v in signals.values()):
            raise InputError(folder / "metrics.json", "signals", "expected an object of 'instance.variable' names")
        self.signals = signals
        self.t = self.data[:, 0]
        config = self.metrics.get("metrics_config", {})
        self.metrics_config = dict(config) if isinstance(config, dict) else {}
        self.ftcsim_folder = is_result_folder(folder, "run")

    @property
    def result(self):
        """The run as a :class:`orchestrator.cosim.master.RunResult` (what the metrics functions take)."""
        m = self.metrics
        return RunResult(self.header[1:], self.t, self.data[:, 1:], bool(m.get("complete", True)), m.get("error"),
                         float(m.get("wall_time_s") or 0.0), int(m.get("steps") or len(self.t) - 1),
                         str(m.get("exchange", "ordered")), str(m.get("mode", "fmu")))

    def has(self, key) -> bool:
        return key in self.signals and any(h.startswith(self.signals[key] + "[") for h in self.header)

    def vec(self, key) -> np.ndarray:
        base = self.signals[key] + "["
        return self.data[:, [i for i, h in enumerate(self.header) if h.startswith(base)]]
