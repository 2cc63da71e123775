"""``ftcsim report DIR... --out DIR``: a paper's figures and tables from result folders.

Each folder is one ``ftcsim run`` (results.parquet or results.csv + metrics.json, with the marker ftcsim writes).
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
from orchestrator.common.reading import read_json
from orchestrator.results.files import write_json
from orchestrator.results.html import Page, markdown_table, plain_text, relative_href, spell_units, write_text_atomic
from papers.paper import resolve
from papers.registry import paper


class Document:
    """``report.md`` and ``report.html`` of a report folder from the same parts, in order:
    :meth:`text` (Markdown), :meth:`heading`, :meth:`table` (a DataFrame: a Markdown table with
    escaped cells, an HTML table through pandas' Styler; units in the headers), :meth:`figure`
    (units given as ``units={column: unit}`` or as :func:`orchestrator.results.html.unit_tag` in
    text are spelled ``N2.m2.s`` in report.md and ``N²·m²·s`` in report.html), :meth:`figure`
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
            self.md += [spell_units(md, pretty=False), ""]
            self.page.add_markdown(md)
        return self

    def heading(self, text: str, level: int = 2) -> Document:
        self.md += [f"{'#' * level} {spell_units(text, pretty=False)}", ""]
        self.page.add_heading(text, level)
        return self

    def table(self, df: pd.DataFrame, caption: str | None = None, units: dict | None = None, digits: int = 4,
              failed_rows=None) -> Document:
        if caption:
            self.md += [f"*{spell_units(caption, pretty=False)}*", ""]
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
    plain_text(fig).savefig(out / name, dpi=110)  # labels from data as plain text (no mathtext)
    plt.close(fig)
    files.append(name)


def runs_frame(runs, keys) -> pd.DataFrame:
    """One row per run: its name (marked when incomplete) and the metrics ``keys`` [(key, label)]
    under their labels (missing or non-numeric values as NaN)."""
    def num(x):
        return float(x) if isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) else math.nan

    rows = [{"run": r.name + ("" if r.complete else " (incomplete)"),
             **{label: num(r.metrics.get(k)) for k, label in keys}} for r in runs]
    return pd.DataFrame(rows, columns=["run", *(label for _, label in keys)])


def runs_units(runs, keys) -> dict:
    """{label: unit} of the metrics ``keys`` [(key, label)] whose unit every run that has the metric
    gives alike (metrics.json's "units")."""
    out = {}
    for k, label in keys:
        seen = {(r.metric_units or {}).get(k) for r in runs if r.metrics.get(k) is not None}
        if len(seen) == 1 and None not in seen:
            out[label] = next(iter(seen))
    return out


def write_table(out: Path, runs, keys, files, title="ftcsim report", extra_md="", doc: Document | None = None) -> dict:
    """report.json, and the runs table with the metrics ``keys`` [(key, label)], ``extra_md`` and the
    figures ``files`` into ``doc`` (a new :class:`Document` of ``title``, written here, when None)."""
    table = {r.name: {k: r.metrics.get(k) for k, _ in keys} for r in runs}
    for r in runs:
        table[r.name]["complete"] = r.info.get("complete")
        table[r.name]["folder"] = str(r.folder)
    write_json(out / "report.json", {"runs": table, "figures": files})
    own = doc is None
    doc = Document(title, out) if own else doc
    doc.heading("Runs").table(runs_frame(runs, keys), caption="Metrics of each run (metrics.json)",
                              units=runs_units(runs, keys))
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


def reproduction_headline(report_folder) -> str | None:
    """The one-line reproduction counts of a paper's report folder
    (``papers.reproduction.headline`` of its ``report.json``'s ``reproduction.summary``): items
    reproduced under the literal readings and under the best documented reading; None if the
    report has no reproduction table."""
    from papers.reproduction import headline

    try:
        summary = read_json(Path(report_folder) / "report.json", "report.json", strict=False)["reproduction"]["summary"]
        return headline(summary)
    except (InputError, KeyError, TypeError):
        return None


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


INDEX = "index.html"
INDEX_METRICS = (("final_attitude_error", "attitude error (end)"), ("final_rate_error", "‖ω_e‖(end)"),
                 ("control_energy", "E"), ("max_abs_u", "max|u_i|"))


def _marker_kind(folder: Path) -> str | None:
    try:
        info = read_json(folder / ".ftcsim.json", "marker file")
    except InputError:
        return None
    return info.get("kind") if isinstance(info, dict) and info.get("tool") == "ftcsim" else None


def _load_metrics(folder: Path) -> dict:
    """A run folder's metrics.json as one flat dict (info, then metric values), either layout;
    {} when it is unreadable (the index lists the run without its metrics)."""
    try:
        m = read_json(folder / "metrics.json", "metrics.json", strict=False)
    except InputError:
        return {}
    if not isinstance(m, dict):
        return {}
    if isinstance(m.get("metrics"), dict) and isinstance(m.get("info"), dict):  # {"metrics", "units", "info"}
        units = m.get("units") if isinstance(m.get("units"), dict) else {}
        return {**m["info"], **m["metrics"], UNITS_KEY: units}
    return m  # the flat metrics.json of earlier versions


UNITS_KEY = "\0units"  # where _load_metrics keeps metrics.json's "units" (no metric is named so)


def write_index(folder) -> Path:
    """``folder/index.html``: one page linking every report (paper and campaign), campaign and run
    folder ftcsim wrote directly below ``folder``, with each run's status and key metrics. An
    ``index.html`` that ftcsim did not write is never replaced (InputError)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(folder, "-", "results folder not found")
    target = folder / INDEX
    if target.is_symlink() or target.exists() and (not target.is_file() or 'content="ftcsim' not in
                                                     target.read_text(encoding="utf-8", errors="replace")[:2000]):
        raise InputError(target, "-", "exists and was not written by ftcsim: not replaced")
    reports, campaigns, runs = [], [], []
    seen_units: dict = {}  # metric -> the units the runs give it
    for sub in sorted(p for p in folder.iterdir() if p.is_dir() and not p.name.startswith(".")):
        kind = _marker_kind(sub)
        if (sub / "report.html").is_file() and kind in ("report", "campaign-report", None):
            reports.append((sub.name, relative_href(sub.name, "report.html")))
        elif kind == "campaign":  # links from folder names: each name percent-encoded (javascript: is a name here)
            campaigns.append((sub.name, relative_href(sub.name, "report", "report.html")
                              if (sub / "report" / "report.html").is_file() else relative_href(sub.name, folder=True)))
        elif kind == "run" or (sub / "metrics.json").is_file():
            m = _load_metrics(sub)
            for k, _ in INDEX_METRICS:
                if m.get(k) is not None:
                    seen_units.setdefault(k, set()).add((m.get(UNITS_KEY) or {}).get(k))
            runs.append({"run": sub.name, "scenario": m.get("scenario"), "paper": m.get("paper"),
                         "complete": m.get("complete"), "t_end": m.get("t_end"),
                         **{label: m.get(k) for k, label in INDEX_METRICS},
                         "error": m.get("error")})
    page = Page(f"ftcsim results: {folder.resolve().name}", base=folder)
    page.add_text(f"{len(reports)} report(s), {len(campaigns)} campaign(s) and {len(runs)} run(s) in {folder.resolve()}.")
    if reports:
        page.add_heading("Reports")
        page.add_links(reports)
    if campaigns:
        page.add_heading("Campaigns")
        page.add_links(campaigns)
    if runs:
        page.add_heading("Runs")
        page.add_links([(r["run"], relative_href(r["run"], folder=True)) for r in runs],
                       caption="Result folders (files of each run):")
        df = pd.DataFrame(runs)
        df = df.drop(columns=[c for c in df.columns if df[c].isna().all()])
        page.add_table(df, caption="Status and key metrics of each run (metrics.json)",
                       # a column's unit when every run gives it the same one (metrics.json "units")
                       units={"t_end": "s", **{label: next(iter(seen_units[k])) for k, label in INDEX_METRICS
                                               if len(seen_units.get(k, ())) == 1}},
                       failed_rows=[r.get("complete") is False or bool(r.get("error")) for r in runs])
    return page.write(target)
