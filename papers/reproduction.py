"""Reproduction tables: each published result of a paper next to ours, with a verdict computed from
our numbers against a stated threshold (never typed), and three counts that are never mixed.

A paper's ``reproduction.py`` builds :class:`Row` objects from its runs and studies; its report
renders them with :func:`add_to` (the counts first, then the table) and stores :func:`to_json` in
``report.json``. A row holds:

* ``item``: the paper's figure, table entry or claim ("Table 1, nu accuracy [deg]");
* ``paper``: the printed value, or the threshold a printed claim is tested against (then
  ``paper_text`` prints the claim);
* ``ours``: our measured number (a float, or a list for :func:`close_all`); ``None`` when the run or
  study that gives it was not among the report's inputs. Never a bare True/False: a claim is a number
  against a threshold (a ratio below 1, an error below a band), so that every check can fail;
* ``rule``: how the verdict follows from (paper, ours), see :func:`close`, :func:`at_most`,
  :func:`at_least`, :func:`below`, :func:`above`, :func:`toward`, :func:`close_all`; ``None`` for an
  item not attempted;
* ``reading`` and ``kind``: the reading the number was obtained under, and what it is:

  - :data:`PRINTED` ("as printed"): every value and equation used is printed in the paper (the
    simulation settings it does not give, such as the exchange step, are stated in the scenario);
  - :data:`READING` ("documented reading"): fills a gap the paper leaves (a value it does not print,
    chosen a priori and named in the row) or resolves a garble, without departing from anything printed;
  - :data:`VARIANT` ("variant"): departs from a printed value or equation, or uses a value fitted to
    the printed result (named in the row). A success under a variant counts as **partly**.

* ``impossible``: why the item cannot be checked from the published text (one of :data:`WHY`, with the
  citation or the measurement in the note): verdict :data:`IMPOSSIBLE`;
* ``consistent``: why the check cannot fail (true by construction, or it cannot discriminate):
  verdict :data:`CONSISTENT`, never counted as reproduced.

Counts (:func:`summarize`, the one function every report, report.json and the README print), per
paper item (an item's rows are its readings):

* **literal**: the best verdict over the item's as-printed rows (every item has at least one);
* **best documented reading**: the best verdict over all its rows, a variant's success counted as
  partly;
* **impossible** and **consistent**: items whose every row is impossible from the published text, or
  whose only checks cannot fail, counted apart (they are not in the n of the first two counts).

"Not attempted" is kept for what could be done and was not (a run missing from the report's inputs).
Default tolerances are those of issue 21: a printed number is reproduced within +-10 % and partly within a
factor of 3.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["REPRODUCED", "PARTLY", "NOT", "NOT_ATTEMPTED", "IMPOSSIBLE", "CONSISTENT", "VERDICTS", "PRINTED", "READING",
           "VARIANT", "KINDS", "WHY", "Rule", "Row", "close", "at_most", "at_least", "below", "above", "toward",
           "close_all", "not_attempted", "impossible", "summarize", "counts_text", "headline", "render_markdown",
           "to_json", "fmt", "missing", "insert_after_title", "frame", "add_to", "readme_table", "PAPER_TITLES"]

REPRODUCED, PARTLY, NOT, NOT_ATTEMPTED = "reproduced", "partly", "not reproduced", "not attempted"
CONSISTENT, IMPOSSIBLE = "consistent (cannot fail)", "impossible from the published text"
VERDICTS = (REPRODUCED, PARTLY, NOT, NOT_ATTEMPTED, CONSISTENT, IMPOSSIBLE)  # best first
JUDGED = (REPRODUCED, PARTLY, NOT, NOT_ATTEMPTED)
PRINTED, READING, VARIANT = "as printed", "documented reading", "variant"
KINDS = (PRINTED, READING, VARIANT)
WHY = ("missing law or baseline", "unprinted parameter", "non-unique LMI output", "provable invariance",
       "figure data not in the published text")
TOL, FACTOR = 0.10, 3.0


def _number(x) -> float | None:
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _unit(p: float) -> float:
    """|p|, or 1 where p = 0: the scale of a threshold's bands."""
    return abs(p) if p != 0 else 1.0


@dataclass(frozen=True)
class Rule:
    """A threshold rule: ``kind`` in close | at_most | at_least | below | above | toward | close_all (see the
    factories). :meth:`verdict` maps (paper, ours) to a verdict; :meth:`probe` gives a value of ``ours`` on
    each side of the threshold (the test that every check can fail flips each row with it)."""

    kind: str
    tol: float = TOL
    factor: float = FACTOR
    start: float | None = None  # toward: where the quantity started

    def describe(self) -> str:
        t, f = f"{100 * self.tol:.3g} %", f"{self.factor:g}"
        partly = self.factor > 1.0 + self.tol
        if self.kind == "close":
            return f"±{t}" + (f"; partly within ×{f}" if partly else "")
        if self.kind == "close_all":
            return f"every entry ±{t}" + (f"; partly every entry within ×{f}" if partly else "")
        if self.kind == "at_most":
            return ("≤ threshold" if self.tol == 0 else f"≤ threshold + {t}") + (f"; partly ≤ ×{f}" if partly else "")
        if self.kind == "at_least":
            return ("≥ threshold" if self.tol == 0 else f"≥ threshold − {t}") + (f"; partly ≥ /{f}" if partly else "")
        if self.kind == "below":
            return "< threshold (strict)"
        if self.kind == "above":
            return "> threshold (strict)"
        return f"within ±{t} of the paper; partly if closer than the start {fmt(self.start)}"

    def _one(self, p: float, o: float | None) -> str:
        if o is None:  # a number that could not be computed (NaN, inf: diverged)
            return NOT
        if self.kind in ("close", "close_all"):
            if abs(o - p) <= self.tol * abs(p):
                return REPRODUCED
            if p != 0 and o / p > 0 and 1 / self.factor <= o / p <= self.factor:
                return PARTLY
            return NOT
        if self.kind == "at_most":
            if o <= p + self.tol * _unit(p) * (p != 0):
                return REPRODUCED
            return PARTLY if o <= p + (self.factor - 1.0) * _unit(p) * (p != 0) else NOT
        if self.kind == "at_least":
            if o >= p - self.tol * _unit(p) * (p != 0):
                return REPRODUCED
            return PARTLY if o >= p - (1.0 - 1.0 / self.factor) * _unit(p) * (p != 0) else NOT
        if self.kind == "below":
            return REPRODUCED if o < p else NOT
        if self.kind == "above":
            return REPRODUCED if o > p else NOT
        if self.kind == "toward":
            if abs(o - p) <= self.tol * abs(p):
                return REPRODUCED
            s = _number(self.start)
            return PARTLY if s is not None and abs(o - p) < abs(s - p) else NOT
        raise ValueError(f"unknown rule kind {self.kind!r}")

    def verdict(self, paper, ours) -> str:
        if ours is None:
            return NOT_ATTEMPTED
        if isinstance(ours, bool):
            raise TypeError(f"{self.kind} rule needs a measured number, got {ours!r}: a claim is a number against a "
                            "threshold")
        if self.kind == "close_all":
            ps, os_ = list(paper), list(ours)
            if len(ps) != len(os_) or not ps:
                raise TypeError(f"close_all needs equal-length lists, got {paper!r} and {ours!r}")
            vs = []
            for p, o in zip(ps, os_):
                pn = _number(p)
                if pn is None:
                    raise TypeError(f"close_all needs numeric paper values, got {p!r}")
                vs.append(self._one(pn, None if o is None else _number(o)))
            return max(vs, key=VERDICTS.index)  # the worst entry
        p = _number(paper)
        if p is None:
            raise TypeError(f"{self.kind} rule needs a numeric paper value or threshold, got {paper!r}")
        if isinstance(ours, (list, tuple)):
            raise TypeError(f"{self.kind} rule needs one number, got {ours!r}")
        return self._one(p, _number(ours))

    def probe(self, paper) -> tuple:
        """(a value of ``ours`` that reproduces, one that does not): the threshold crossed both ways."""
        if self.kind == "close_all":
            ps = [float(p) for p in paper]
            return ps, [p * 2 * self.factor if p else 1.0 for p in ps]
        p = float(paper)
        u = _unit(p)
        if self.kind == "close":
            return p, (p * 2 * self.factor if p else 1.0)
        if self.kind == "at_most":
            return p, p + 2 * max(self.factor, 1.0) * u
        if self.kind == "at_least":
            return p, p - 2 * u
        if self.kind == "below":
            return p - 0.5 * u, p + 0.5 * u
        if self.kind == "above":
            return p + 0.5 * u, p - 0.5 * u
        if self.kind == "toward":
            s = float(self.start)
            return p, 2 * s - p  # twice as far from the paper as the start
        raise ValueError(f"unknown rule kind {self.kind!r}")


def close(tol: float = TOL, factor: float = FACTOR) -> Rule:
    """A printed number: reproduced if |ours - paper| <= tol |paper|, partly if ours / paper lies in
    [1/factor, factor]."""
    return Rule("close", tol, factor)


def close_all(tol: float = TOL, factor: float = FACTOR) -> Rule:
    """A printed column (a list): the worst of :func:`close` over its entries (one reading per column)."""
    return Rule("close_all", tol, factor)


def at_most(tol: float = TOL, factor: float = FACTOR) -> Rule:
    """A bound "<= threshold" (an error bound, a band): reproduced if ours <= threshold + tol |threshold|,
    partly if ours <= threshold + (factor - 1) |threshold| (factor x threshold for a positive one)."""
    return Rule("at_most", tol, factor)


def at_least(tol: float = TOL, factor: float = FACTOR) -> Rule:
    """A lower bound ">= threshold": reproduced if ours >= threshold - tol |threshold|, partly if >=
    threshold / factor (for a positive one)."""
    return Rule("at_least", tol, factor)


def below() -> Rule:
    """A strict comparison "ours < threshold" (a ratio below 1, a spectral abscissa below 0); no partly."""
    return Rule("below", 0.0, 1.0)


def above() -> Rule:
    """A strict comparison "ours > threshold"; no partly."""
    return Rule("above", 0.0, 1.0)


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
    kind: str = PRINTED
    unit: str = ""
    ours_text: str | None = None  # how to print ours (default: fmt(ours) with the unit)
    paper_text: str | None = None  # how to print the paper's value (default: fmt(paper) with the unit)
    impossible: str | None = None  # one of WHY: the item cannot be checked from the published text
    consistent: str | None = None  # why this check cannot fail (true by construction, cannot discriminate)

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"row {self.item!r}: kind {self.kind!r} is not one of {KINDS}")
        if self.impossible is not None and self.impossible not in WHY:
            raise ValueError(f"row {self.item!r}: impossible reason {self.impossible!r} is not one of {WHY}")

    @property
    def literal(self) -> bool:
        return self.kind == PRINTED

    @property
    def rule_verdict(self) -> str:
        """The rule's verdict on (paper, ours), before a variant's success is counted as partly."""
        if self.impossible is not None:
            return IMPOSSIBLE
        if self.rule is None:
            return NOT_ATTEMPTED
        if self.consistent is not None:
            return CONSISTENT
        return self.rule.verdict(self.paper, self.ours)

    @property
    def verdict(self) -> str:
        """What the row counts as: a success under a variant counts as partly."""
        v = self.rule_verdict
        return PARTLY if (v == REPRODUCED and self.kind == VARIANT) else v

    def verdict_text(self) -> str:
        if self.rule_verdict == REPRODUCED and self.kind == VARIANT:
            return "partly (reproduced only under this variant)"
        return self.verdict

    def reading_text(self) -> str:
        r = self.reading
        return r if r.lower().startswith(self.kind) else f"{self.kind}: {r}"

    def ours_display(self) -> str:
        if self.ours_text is not None:
            return self.ours_text
        if self.impossible is not None or self.rule is None:
            return "—"
        if self.ours is None:
            return "not run"
        return fmt(self.ours) + (f" {self.unit}" if self.unit else "")

    def paper_display(self) -> str:
        if self.paper_text is not None:
            return self.paper_text
        return fmt(self.paper) + (f" {self.unit}" if self.unit and (_number(self.paper) is not None
                                                                     or isinstance(self.paper, list)) else "")


def not_attempted(item: str, paper, reason: str, reading: str = "as printed", kind: str = PRINTED) -> Row:
    """An item that could be checked and was not, with the reason."""
    return Row(item, paper, None, None, reading, reason, kind)


def impossible(item: str, paper, why: str, note: str, reading: str = "as printed", kind: str = PRINTED) -> Row:
    """An item that cannot be checked from the published text: ``why`` is one of :data:`WHY`, ``note``
    the citation or the measurement behind it."""
    return Row(item, paper, None, None, reading, f"{why}: {note}", kind, impossible=why)


def missing(name: str) -> str:
    """The note of a row whose run was not among the report's inputs."""
    return f"Run {name} is not among this report's inputs (make demo runs it)."


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
    """The three counts, per paper item (see the module docstring): ``literal`` and ``best`` over the
    ``judged`` items (those with a row that is neither impossible nor consistent), ``impossible`` and
    ``consistent`` apart; ``per_item`` gives each item's literal and best verdict and the best reading.
    Raises ``ValueError`` for an item without an as-printed row (its literal status would be unstated)."""
    items: dict[str, list[Row]] = {}
    for r in rows:
        items.setdefault(r.item, []).append(r)
    literal = {v: 0 for v in VERDICTS}
    best = {v: 0 for v in JUDGED}
    apart = {IMPOSSIBLE: 0, CONSISTENT: 0}
    per_item = {}
    for item, rs in items.items():
        lit_rows = [r for r in rs if r.kind == PRINTED]
        if not lit_rows:
            raise ValueError(f"item {item!r} has no as-printed row: add one (impossible or not reproduced, with why)")
        lit = _best([r.verdict for r in lit_rows])
        top = _best([r.verdict for r in rs])
        row = next(r for r in rs if r.verdict == top)
        per_item[item] = {"literal": lit, "best": top, "best_reading": row.reading_text(), "rows": len(rs)}
        if top in apart:
            apart[top] += 1
            continue
        literal[lit] += 1
        best[top] += 1
    judged = sum(best.values())
    return {"items": len(items), "rows": len(rows), "judged": judged, "literal": literal, "best": best,
            "impossible": apart[IMPOSSIBLE], "consistent": apart[CONSISTENT], "per_item": per_item}


def _parts(counts: dict, keys) -> str:
    return ", ".join(f"{k} {counts.get(k, 0)}" for k in keys if counts.get(k, 0) or k in (PARTLY, NOT))


def _items(n: int) -> str:
    return f"{n} item" + ("" if n == 1 else "s")


def counts_text(summary: dict) -> str:
    """The three counts as one paragraph (what a report opens with)."""
    n, lit, best = summary["judged"], summary["literal"], summary["best"]
    extra = [k for k in (NOT_ATTEMPTED, IMPOSSIBLE, CONSISTENT) if lit.get(k)]
    lit_rest = _parts(lit, (PARTLY, NOT, *extra))
    names = {IMPOSSIBLE: "impossible as printed", CONSISTENT: "cannot fail as printed"}
    for k, v in names.items():
        lit_rest = lit_rest.replace(f"{k} ", f"{v} ")
    return (f"**Literal readings (as printed): reproduced {lit[REPRODUCED]} of {n}** ({lit_rest}). "
            f"**Best documented reading: reproduced {best[REPRODUCED]} of {n}** ({_parts(best, (PARTLY, NOT, NOT_ATTEMPTED))}; "
            "a success only under a variant counts as partly). "
            f"**Impossible from the published text: {_items(summary['impossible'])}**; "
            f"**consistent (cannot fail): {_items(summary['consistent'])}**, not counted as reproduced. "
            f"{summary['items']} paper items in all, {summary['rows']} rows (one per reading).")


def headline(summary: dict) -> str:
    """One short line of a paper's counts for terminals and index pages (``make demo``'s closing table):
    items reproduced under the literal readings, then under the best documented reading, of the items
    that can be judged; then the items impossible from the published text and those whose check cannot fail."""
    n = summary["judged"]
    out = f"literal {summary['literal'][REPRODUCED]}/{n}, best reading {summary['best'][REPRODUCED]}/{n}"
    if summary.get("impossible"):
        out += f", impossible {summary['impossible']}"
    if summary.get("consistent"):
        out += f", cannot fail {summary['consistent']}"
    return out


REPRO_COLUMNS = ["#", "paper item", "paper", "ours", "verdict", "threshold", "reading used", "measured reason / source"]


def frame(rows):
    """The rows as a DataFrame, one row per (item, reading), numbers already printed with their
    units (the cells are text)."""
    import pandas as pd

    return pd.DataFrame([[str(i), r.item, r.paper_display(), r.ours_display(), r.verdict_text(),
                          r.rule.describe() if (r.rule and r.impossible is None) else "—", r.reading_text(), r.note]
                         for i, r in enumerate(rows, 1)], columns=REPRO_COLUMNS)


def render_markdown(rows, title: str = "Reproduction table", intro: str = "") -> str:
    """The counts, then one table row per (item, reading)."""
    from orchestrator.results.html import markdown_table

    out = [f"## {title}", "", counts_text(summarize(rows)), ""]
    if intro:
        out += [intro, ""]
    return "\n".join(out) + "\n" + markdown_table(frame(rows))


KINDS_TEXT = ("Readings: 'as printed' uses only printed values and equations; a 'documented reading' fills a gap the "
              "paper leaves with a value named in the row, chosen a priori; a 'variant' departs from what is printed "
              "or uses a value fitted to the printed result, and its success counts as partly.")


def add_to(doc, rows, title: str = "Reproduction table", intro: str = "") -> None:
    """The counts, the intro and the table into a report :class:`orchestrator.results.report.Document`."""
    doc.heading(title)
    doc.text(counts_text(summarize(rows)) + "\n\n" + KINDS_TEXT + ("\n\n" + intro if intro else ""))
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
                  "ours_text": r.ours_display(), "verdict": r.verdict, "rule_verdict": r.rule_verdict,
                  "threshold": r.rule.describe() if r.rule else None, "reading": r.reading, "kind": r.kind,
                  "literal": r.literal, "impossible": r.impossible, "consistent": r.consistent, "note": r.note,
                  "unit": r.unit} for r in rows],
    }


PAPER_TITLES = {"000": "000 Li, Xu, Chang 2023", "001": "001 Zhang, Gao, Qian, Bai 2019",
                "002": "002 Zhang, Qiao, Li, Guo 2014", "003": "003 Hang, Su, Deng 2023", "004": "004 Xu, Song, Wang 2024"}
README_HEAD = ("| paper | items | literal: reproduced / partly / not | best documented reading: reproduced / partly / not "
               "| impossible from the text | cannot fail |")


def readme_row(paper_id: str, summary: dict) -> str:
    """One line of the README's "What reproduces" table, from :func:`summarize` (or report.json's summary)."""
    n, lit, best = summary["judged"], summary["literal"], summary["best"]
    names = {NOT_ATTEMPTED: "not attempted", IMPOSSIBLE: "impossible as printed", CONSISTENT: "cannot fail as printed"}
    rest = "; ".join(f"+{lit[k]} {v}" for k, v in names.items() if lit.get(k))
    lit_txt = f"{lit[REPRODUCED]} / {lit[PARTLY]} / {lit[NOT]}" + (f" ({rest})" if rest else "")
    best_txt = f"{best[REPRODUCED]} / {best[PARTLY]} / {best[NOT]}" + (
        f" (+{best[NOT_ATTEMPTED]} not attempted)" if best[NOT_ATTEMPTED] else "")
    return (f"| {PAPER_TITLES.get(paper_id, paper_id)} | {n} | {lit_txt} | {best_txt} | {summary['impossible']} | "
            f"{summary['consistent']} |")


def readme_table(summaries: dict) -> str:
    """The README's table: ``summaries`` maps a paper id to its :func:`summarize` result."""
    return "\n".join([README_HEAD, "|---|---|---|---|---|---|",
                      *(readme_row(pid, s) for pid, s in sorted(summaries.items()))]) + "\n"


def insert_after_title(path, block: str) -> None:
    """Insert ``block`` into the markdown file ``path`` right after its first line (the title), so that a
    report opens with its reproduction counts."""
    from pathlib import Path

    p = Path(path)
    lines = p.read_text(encoding="utf-8").split("\n")
    p.write_text("\n".join(lines[:1] + ["", block.rstrip("\n")] + lines[1:]), encoding="utf-8")
