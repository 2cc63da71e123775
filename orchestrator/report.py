"""``ftcsim report DIR... --out DIR``: a paper's figures and tables from result folders.

Each folder is one ``ftcsim run`` (results.csv + metrics.json, with the marker ftcsim writes).
Every folder is read and checked before anything is written; the runs are grouped by the
paper their scenario names (``metrics.json: paper``) and each group goes to its paper's report
(``Paper.report`` in ``papers/registry.py``): into ``--out`` itself when all runs are of one
paper, else into ``--out/<paper key>/``. The output folder is written atomically and follows the
rules of :mod:`orchestrator.common.outputs` (never replaces a folder ftcsim did not write).

Helpers for the papers' report modules: :class:`Run`, :func:`figure`, :func:`save_figure`.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.outputs import is_result_folder


class Run:
    """One result folder, checked: readable CSV with a ``time`` column and numbers, a metrics
    object, signals that name columns."""

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
        from .results import read_csv

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
        self.ftcsim_folder = is_result_folder(folder, "run")

    @property
    def result(self):
        """The run as a :class:`orchestrator.cosim.master.RunResult` (what the metrics functions take)."""
        from orchestrator.cosim.master import RunResult

        m = self.metrics
        return RunResult(self.header[1:], self.t, self.data[:, 1:], bool(m.get("complete", True)), m.get("error"),
                         float(m.get("wall_time_s") or 0.0), int(m.get("steps") or len(self.t) - 1),
                         str(m.get("exchange", "ordered")), str(m.get("mode", "fmu")))

    def has(self, key) -> bool:
        return key in self.signals and any(h.startswith(self.signals[key] + "[") for h in self.header)

    def vec(self, key) -> np.ndarray:
        base = self.signals[key] + "["
        return self.data[:, [i for i, h in enumerate(self.header) if h.startswith(base)]]


def figure(n, title, height=2.2):
    """(pyplot, figure, n stacked axes sharing the time axis)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(n, 1, figsize=(8, height * n + 0.6), sharex=True, squeeze=False)
    fig.suptitle(title)
    return plt, fig, axes[:, 0]


def save_figure(plt, fig, axes, out: Path, name: str, files: list):
    for ax in axes:
        ax.grid(True, lw=0.3)
    axes[-1].set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(out / name, dpi=110)
    plt.close(fig)
    files.append(name)


def write_table(out: Path, runs, keys, files, title="ftcsim report", extra_md="") -> dict:
    """report.json and report.md: one row per run with the metrics ``keys`` [(key, label)]."""
    from .results import write_json

    table = {r.name: {k: r.metrics.get(k) for k, _ in keys} for r in runs}
    for r in runs:
        table[r.name]["complete"] = r.metrics.get("complete")
        table[r.name]["folder"] = str(r.folder)
    write_json(out / "report.json", {"runs": table, "figures": files})

    def cell(x):
        return "—" if not isinstance(x, (int, float)) or isinstance(x, bool) or not math.isfinite(x) else f"{x:.4g}"

    lines = ["| run | " + " | ".join(label for _, label in keys) + " |", "|---" * (len(keys) + 1) + "|"]
    for name, row in table.items():
        lines.append(f"| {name}{'' if row['complete'] else ' (incomplete)'} | " + " | ".join(cell(row[k]) for k, _ in keys) + " |")
    (out / "report.md").write_text(f"# {title}\n\n" + "\n".join(lines) + "\n\n" + extra_md
                                   + "Figures: " + ", ".join(files) + "\n", encoding="utf-8")
    return {"figures": files, "table": table}


def make_reports(runs, out: Path) -> dict:
    """Each paper's report of its runs into ``out`` (one paper) or ``out/<key>`` (several)."""
    from papers.paper import resolve
    from papers.registry import paper

    groups: dict = {}
    for r in runs:
        try:
            p = paper(str(r.paper))
        except KeyError:
            raise InputError(r.folder / "metrics.json", "paper", f"run of paper {r.paper!r}, which has no report "
                             "(scenarios name their paper in [scenario] paper = \"000\")") from None
        if p.report is None:
            raise InputError(r.folder / "metrics.json", "paper", f"paper {p.id} has no report yet")
        groups.setdefault(p.id, (p, []))[1].append(r)
    done = {}
    for pid, (p, members) in groups.items():
        where = out if len(groups) == 1 else out / p.key
        where.mkdir(parents=True, exist_ok=True)
        done[pid] = resolve(p.report)(members, where)
    return done
