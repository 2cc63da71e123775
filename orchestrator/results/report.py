"""``ftcsim report DIR... --out DIR``: a paper's figures and tables from result folders.

Each folder is one ``ftcsim run`` (results.csv + metrics.json, with the marker ftcsim writes).
Every folder is read and checked before anything is written; the runs are grouped by the
paper their scenario names (``metrics.json: paper``) and each group goes to its paper's report
(``Paper.report`` in ``papers/registry.py``): into ``--out`` itself when all runs are of one
paper, else into ``--out/<paper key>/``. The output folder is written atomically and follows the
rules of :mod:`orchestrator.common.outputs` (never replaces a folder ftcsim did not write).

Helpers for the papers' report modules: :func:`figure`, :func:`save_figure`, :func:`write_table`
(the runs are :class:`orchestrator.results.files.Run`) and :class:`Document`, which writes
``report.md`` and the self-contained ``report.html`` beside it from the same parts (Markdown
prose, DataFrame tables with units, figures).
"""
from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from orchestrator.common.errors import InputError
from orchestrator.results.files import write_json
from orchestrator.results.html import Page, markdown_table, write_text_atomic
from papers.paper import resolve
from papers.registry import paper


class Document:
    """``report.md`` and ``report.html`` of a report folder from the same parts, in order:
    :meth:`text` (Markdown), :meth:`heading`, :meth:`table` (a DataFrame: a Markdown table with
    escaped cells, an HTML table through pandas' Styler; units in the headers), :meth:`figure`
    (a PNG in the folder: ``![caption](file.png)`` and an embedded image). :meth:`write` writes
    both files atomically."""

    def __init__(self, title: str, folder):
        self.title = str(title)
        self.folder = Path(folder)
        self.md: list[str] = [f"# {self.title}", ""]
        self.page = Page(self.title, base=self.folder)

    def text(self, md: str) -> Document:
        md = str(md).strip("\n")
        if md:
            self.md += [md, ""]
            self.page.add_markdown(md)
        return self

    def heading(self, text: str, level: int = 2) -> Document:
        self.md += [f"{'#' * level} {text}", ""]
        self.page.add_heading(text, level)
        return self

    def table(self, df: pd.DataFrame, caption: str | None = None, units: dict | None = None, digits: int = 4,
              failed_rows=None) -> Document:
        if caption:
            self.md += [f"*{caption}*", ""]
        self.md += [markdown_table(df, units, digits)]
        self.page.add_table(df, caption=caption, units=units, digits=digits, failed_rows=failed_rows)
        return self

    def figure(self, name: str, caption: str | None = None) -> Document:
        self.md += [f"![{caption or name}]({name})", ""]
        self.page.add_figure(name, caption=caption or name)
        return self

    def write(self) -> tuple[Path, Path]:
        md, html = self.folder / "report.md", self.folder / "report.html"
        write_text_atomic(md, "\n".join(self.md).rstrip("\n") + "\n")
        self.page.write(html)
        return md, html


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


def runs_frame(runs, keys) -> pd.DataFrame:
    """One row per run: its name (marked when incomplete) and the metrics ``keys`` [(key, label)]
    under their labels (missing or non-numeric values as NaN)."""
    def num(x):
        return float(x) if isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) else math.nan

    rows = [{"run": r.name + ("" if r.metrics.get("complete", True) else " (incomplete)"),
             **{label: num(r.metrics.get(k)) for k, label in keys}} for r in runs]
    return pd.DataFrame(rows, columns=["run", *(label for _, label in keys)])


def write_table(out: Path, runs, keys, files, title="ftcsim report", extra_md="", doc: Document | None = None) -> dict:
    """report.json, and the runs table with the metrics ``keys`` [(key, label)], ``extra_md`` and the
    figures ``files`` into ``doc`` (a new :class:`Document` of ``title``, written here, when None)."""
    table = {r.name: {k: r.metrics.get(k) for k, _ in keys} for r in runs}
    for r in runs:
        table[r.name]["complete"] = r.metrics.get("complete")
        table[r.name]["folder"] = str(r.folder)
    write_json(out / "report.json", {"runs": table, "figures": files})
    own = doc is None
    doc = Document(title, out) if own else doc
    doc.heading("Runs").table(runs_frame(runs, keys), caption="Metrics of each run (metrics.json)")
    doc.text(extra_md)
    add_figures(doc, files)
    if own:
        doc.write()
    return {"figures": files, "table": table}


def add_figures(doc: Document, files, heading: str = "Figures") -> None:
    """Every figure file of ``files`` into ``doc`` under ``heading``."""
    if files:
        doc.heading(heading)
        for f in files:
            doc.figure(f)


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
