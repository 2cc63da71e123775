"""Reproduction tables: each published result of a paper next to ours, with a verdict computed from
our numbers against a stated tolerance (never typed).

A paper's ``reproduction.py`` builds :class:`Row` objects from its runs and studies; its report
renders them with :func:`render_markdown` (the counts first, then the table) and stores
:func:`to_json` in ``report.json``. A row holds:

* ``item``: the paper's figure, table entry or claim ("Table 1, nu accuracy [deg]");
* ``paper``: the printed value (a number, or the printed claim as text);
* ``ours``: our number (or ``True``/``False`` for a claim we checked); ``None`` when the run or
  study that gives it was not among the report's inputs;
* ``rule``: how the verdict follows from (paper, ours), see :func:`close`, :func:`at_most`,
  :func:`at_least`, :func:`claim`, :func:`toward`; ``None`` for an item not attempted;
* ``reading``: the reading the number was obtained under ("as printed", "sat(s/0.01)", ...);
  ``literal`` says whether that is the paper's text taken as printed;
* ``note``: the measured reason (why it differs) or where the number comes from.

Verdicts: ``reproduced``, ``partly``, ``not reproduced``, ``not attempted``. The counts are given
per paper item: an item's verdict is the best over its rows (the shipped readings), and again over
its literal rows only ("as printed"); items without a literal row keep their rows in both counts.

Default tolerances are those of the issue that asked for the tables (issue 21): a printed number
is reproduced within +-10 % and partly within a factor of 3.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["REPRODUCED", "PARTLY", "NOT", "NOT_ATTEMPTED", "VERDICTS", "Rule", "Row", "close", "at_most",
           "at_least", "claim", "toward", "not_attempted", "summarize", "counts_text", "render_markdown", "to_json", "fmt",
           "missing", "insert_after_title", "frame", "add_to", "headline"]

REPRODUCED, PARTLY, NOT, NOT_ATTEMPTED = "reproduced", "partly", "not reproduced", "not attempted"
VERDICTS = (REPRODUCED, PARTLY, NOT, NOT_ATTEMPTED)  # best first
TOL, FACTOR = 0.10, 3.0


def _number(x) -> float | None:
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return None
    x = float(x)
    return x if math.isfinite(x) else None


@dataclass(frozen=True)
class Rule:
    """A tolerance rule: ``kind`` in close | at_most | at_least | claim | toward (see the factories)."""

    kind: str
    tol: float = TOL
    factor: float = FACTOR
    start: float | None = None  # toward: where the quantity started

    def describe(self) -> str:
        t, f = f"{100 * self.tol:.3g} %", f"{self.factor:g}"
        partly = self.factor > 1.0 + self.tol
        if self.kind == "close":
            return f"±{t}" + (f"; partly within ×{f}" if partly else "")
        if self.kind == "at_most":
            return ("≤ paper" if self.tol == 0 else f"≤ paper + {t}") + (f"; partly ≤ ×{f}" if partly else "")
        if self.kind == "at_least":
            return ("≥ paper" if self.tol == 0 else f"≥ paper − {t}") + (f"; partly ≥ paper/{f}" if partly else "")
        if self.kind == "claim":
            return "claim checked: holds / fails"
        return f"within ±{t} of the paper; partly if closer than the start {fmt(self.start)}"

    def verdict(self, paper, ours) -> str:
        if ours is None:
            return NOT_ATTEMPTED
        if self.kind == "claim":
            if not isinstance(ours, (bool,)) and ours not in (0, 1):
                raise TypeError(f"claim rule needs True/False, got {ours!r}")
            return REPRODUCED if ours else NOT
        p, o = _number(paper), _number(ours)
        if p is None:
            raise TypeError(f"{self.kind} rule needs a numeric paper value, got {paper!r}")
        if o is None:  # a number that could not be computed (NaN, inf: diverged)
            return NOT
        if self.kind == "close":
            if abs(o - p) <= self.tol * abs(p):
                return REPRODUCED
            if p != 0 and o / p > 0 and 1 / self.factor <= o / p <= self.factor:
                return PARTLY
            return NOT
        if self.kind == "at_most":
            if o <= p * (1 + self.tol):
                return REPRODUCED
            return PARTLY if o <= p * self.factor else NOT
        if self.kind == "at_least":
            if o >= p * (1 - self.tol):
                return REPRODUCED
            return PARTLY if o >= p / self.factor else NOT
        if self.kind == "toward":
            if abs(o - p) <= self.tol * abs(p):
                return REPRODUCED
            s = _number(self.start)
            return PARTLY if s is not None and abs(o - p) < abs(s - p) else NOT
        raise ValueError(f"unknown rule kind {self.kind!r}")


def close(tol: float = TOL, factor: float = FACTOR) -> Rule:
    """A printed number: reproduced if |ours - paper| <= tol |paper|, partly if ours / paper lies in
    [1/factor, factor]."""
    return Rule("close", tol, factor)


def at_most(tol: float = TOL, factor: float = FACTOR) -> Rule:
    """A printed bound "<= paper" (an error bound, an accuracy): reproduced if ours <= paper (1 + tol),
    partly if ours <= factor paper."""
    return Rule("at_most", tol, factor)


def at_least(tol: float = TOL, factor: float = FACTOR) -> Rule:
    """A printed lower bound ">= paper": reproduced if ours >= paper (1 - tol), partly if >= paper / factor."""
    return Rule("at_least", tol, factor)


def claim() -> Rule:
    """A printed claim checked on our runs: ``ours`` is True (holds) or False (fails)."""
    return Rule("claim")


def toward(start: float, tol: float = TOL) -> Rule:
    """A printed target that an estimate should reach from ``start``: reproduced within tol |paper|,
    partly if ours is closer to the paper's value than ``start`` was."""
    return Rule("toward", tol, FACTOR, float(start))


@dataclass
class Row:
    item: str
    paper: object
    ours: object
    rule: Rule | None
    reading: str = "as printed"
    note: str = ""
    literal: bool = True
    unit: str = ""
    ours_text: str | None = None  # how to print ours (default: fmt(ours) with the unit)
    paper_text: str | None = None  # how to print the paper's value (default: fmt(paper) with the unit)

    @property
    def verdict(self) -> str:
        return NOT_ATTEMPTED if self.rule is None else self.rule.verdict(self.paper, self.ours)

    def ours_display(self) -> str:
        if self.ours_text is not None:
            return self.ours_text
        if self.rule is None:
            return "—"
        if self.ours is None:
            return "not run"
        if isinstance(self.ours, bool):
            return "holds" if self.ours else "fails"
        return fmt(self.ours) + (f" {self.unit}" if self.unit else "")

    def paper_display(self) -> str:
        if self.paper_text is not None:
            return self.paper_text
        return fmt(self.paper) + (f" {self.unit}" if self.unit and _number(self.paper) is not None else "")


def not_attempted(item: str, paper, reason: str, reading: str = "—") -> Row:
    """An item we do not attempt, with the reason (measured or sourced)."""
    return Row(item, paper, None, None, reading, reason)


def missing(name: str) -> str:
    """The note of a row whose run was not among the report's inputs."""
    return f"run {name} not among this report's inputs (make demo runs it)"


def fmt(x) -> str:
    """Numbers with 4 significant digits; lists element-wise; text as is."""
    if x is None:
        return "—"
    if isinstance(x, bool):
        return "holds" if x else "fails"
    if isinstance(x, (int, float)):
        if not math.isfinite(float(x)):
            return str(x)
        return f"{x:.4g}"
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(fmt(v) for v in x) + "]"
    return str(x)


def _best(verdicts) -> str:
    return min(verdicts, key=VERDICTS.index)


def summarize(rows) -> dict:
    """Counts per paper item: ``shipped`` (best verdict over an item's rows) and ``as_printed`` (best
    over its literal rows; an item without a literal row counts with all its rows)."""
    items: dict[str, list[Row]] = {}
    for r in rows:
        items.setdefault(r.item, []).append(r)
    shipped = {v: 0 for v in VERDICTS}
    printed = {v: 0 for v in VERDICTS}
    per_item = {}
    for item, rs in items.items():
        best = _best([r.verdict for r in rs])
        lit = [r.verdict for r in rs if r.literal] or [r.verdict for r in rs]
        best_lit = _best(lit)
        shipped[best] += 1
        printed[best_lit] += 1
        per_item[item] = {"shipped": best, "as_printed": best_lit}
    return {"items": len(items), "rows": len(rows), "shipped": shipped, "as_printed": printed, "per_item": per_item}


def counts_text(summary: dict) -> str:
    s, p = summary["shipped"], summary["as_printed"]
    return (f"**{summary['items']} paper items: reproduced {s[REPRODUCED]}, partly {s[PARTLY]}, not reproduced "
            f"{s[NOT]}, not attempted {s[NOT_ATTEMPTED]}** (best shipped reading per item); as printed (literal "
            f"readings only): reproduced {p[REPRODUCED]}, partly {p[PARTLY]}, not reproduced {p[NOT]}, not attempted "
            f"{p[NOT_ATTEMPTED]}.")


def headline(summary: dict) -> str:
    """One short line of a paper's counts for terminals and index pages (``make demo``'s closing table):
    items reproduced under the literal readings, then under the best documented reading."""
    s, p, n = summary["shipped"], summary["as_printed"], summary["items"]
    return f"literal {p[REPRODUCED]}/{n}, best reading {s[REPRODUCED]}/{n}"


REPRO_COLUMNS = ["#", "paper item", "paper", "ours", "verdict", "tolerance", "reading used", "measured reason / source"]


def frame(rows):
    """The rows as a DataFrame, one row per (item, reading), numbers already printed with their
    units (the cells are text)."""
    import pandas as pd

    return pd.DataFrame([[str(i), r.item, r.paper_display(), r.ours_display(), r.verdict,
                          r.rule.describe() if r.rule else "—", r.reading + ("" if r.literal else " (not as printed)"),
                          r.note] for i, r in enumerate(rows, 1)], columns=REPRO_COLUMNS)


def render_markdown(rows, title: str = "Reproduction table", intro: str = "") -> str:
    """The counts, then one table row per (item, reading)."""
    from orchestrator.results.html import markdown_table

    out = [f"## {title}", "", counts_text(summarize(rows)), ""]
    if intro:
        out += [intro, ""]
    return "\n".join(out) + "\n" + markdown_table(frame(rows))


def add_to(doc, rows, title: str = "Reproduction table", intro: str = "") -> None:
    """The counts, the intro and the table into a report :class:`orchestrator.results.report.Document`."""
    doc.heading(title)
    doc.text(counts_text(summarize(rows)) + ("\n\n" + intro if intro else ""))
    doc.table(frame(rows), failed_rows=[r.verdict == NOT for r in rows])


def to_json(rows) -> dict:
    """JSON-safe rows and counts (``report.json``)."""
    def js(x):
        if isinstance(x, bool) or x is None or isinstance(x, str):
            return x
        if isinstance(x, (int, float)):
            return float(x) if math.isfinite(float(x)) else str(x)
        if isinstance(x, (list, tuple)):
            return [js(v) for v in x]
        return str(x)

    return {
        "summary": summarize(rows),
        "rows": [{"item": r.item, "paper": js(r.paper), "paper_text": r.paper_display(), "ours": js(r.ours),
                  "ours_text": r.ours_display(),
                  "verdict": r.verdict, "tolerance": r.rule.describe() if r.rule else None, "reading": r.reading,
                  "literal": r.literal, "note": r.note, "unit": r.unit} for r in rows],
    }


def insert_after_title(path, block: str) -> None:
    """Insert ``block`` into the markdown file ``path`` right after its first line (the title), so that a
    report opens with its reproduction counts."""
    from pathlib import Path

    p = Path(path)
    lines = p.read_text(encoding="utf-8").split("\n")
    p.write_text("\n".join(lines[:1] + ["", block.rstrip("\n")] + lines[1:]), encoding="utf-8")
