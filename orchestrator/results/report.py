"""``ftcsim report DIR... --out DIR``: a paper's figures and tables from result folders.

Each folder is one ``ftcsim run`` (results.parquet or results.csv + metrics.json, with the marker ftcsim writes).
Every folder is read and checked before anything is written; the runs are grouped by the
paper their scenario names (``metrics.json: paper``) and each group goes to its paper's report
(``Paper.report`` in ``papers/registry.py``): into ``--out`` itself when all runs are of one
paper, else into ``--out/<paper key>/``. The output folder is written atomically and follows the
rules of :mod:`orchestrator.common.outputs` (never replaces a folder ftcsim did not write).

Helpers for the papers' report modules: :func:`figure`, :func:`save_figure`, :func:`write_table`
(the runs are :class:`orchestrator.results.files.Run`).
"""
from __future__ import annotations

import math
from pathlib import Path

from orchestrator.common.errors import InputError
from orchestrator.results.files import write_json
from papers.paper import resolve
from papers.registry import paper


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
    table = {r.name: {k: r.metrics.get(k) for k, _ in keys} for r in runs}
    for r in runs:
        table[r.name]["complete"] = r.info.get("complete")
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
