"""orchestrator/results/html.py: one self-contained report page; tables from DataFrames with units,
figures embedded, Markdown tables that stay tables, atomic writes; the page checked in headless
Chromium (tests/browser.py)."""
import os

import matplotlib
import numpy as np
import pandas as pd
import pytest
from markdown_it import MarkdownIt

from orchestrator.results.html import Page, markdown_table
from tests.browser import Browser, require_browser

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def _table_cells(md: str) -> list[list[str]]:
    """The cells of the first table markdown-it finds in ``md`` (a GFM parser, not ours)."""
    tokens = MarkdownIt("commonmark").enable("table").parse(md)
    rows, row = [], None
    for t in tokens:
        if t.type == "tr_open":
            row = []
        elif t.type == "inline" and row is not None:
            row.append(t.content)
        elif t.type == "tr_close":
            rows.append(row)
            row = None
    return rows


def _frame():
    return pd.DataFrame({"run": ["a|b", "c\nd", "<script>x</script>"], "energy": [1.23456789, np.nan, 3.0],
                         "ok": [True, False, True]})


def test_markdown_table_escapes_pipes_and_line_breaks_and_carries_units():
    md = markdown_table(_frame(), units={"energy": "N²m²s"})
    rows = _table_cells(md)
    assert rows[0] == ["run", "energy [N²m²s]", "ok"]
    assert [len(r) for r in rows] == [3, 3, 3, 3]  # one table, three columns in every row
    assert rows[1][0] == "a|b"  # the escaped pipe is text again after parsing
    assert rows[2][:2] == ["c d", "—"]  # line break flattened, NaN as a dash
    assert rows[1][1] == "1.235"


def test_page_embeds_figures_and_escapes_text(tmp_path):
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    fig.savefig(tmp_path / "f.png")
    (tmp_path / "g.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="20" height="10">'
                                    '<rect width="20" height="10"/></svg>')
    page = Page("T <b>", base=tmp_path)
    page.add_text("a <i>b</i>").add_table(_frame(), caption="runs", units={"energy": "J"}).add_figure(fig, caption="live")
    page.add_figure("f.png").add_figure("g.svg").add_markdown("| x | y |\n|---|---|\n| 1 \\| 2 | <b>3</b> |\n\n![c](f.png)")
    plt.close(fig)
    out = page.write(tmp_path / "sub" / "page.html")
    text = out.read_text(encoding="utf-8")
    assert text.count('<img src="data:image/') == 4 and page.figures == 4
    assert "<script>x" not in text and "&lt;script&gt;x" in text
    assert "<b>3</b>" not in text and "<i>b</i>" not in text
    assert "<title>T &lt;b&gt;</title>" in text
    assert "energy [J]" in text
    assert [p.name for p in out.parent.iterdir()] == ["page.html"]  # no temporary file left


def test_page_refuses_a_figure_outside_its_folder(tmp_path):
    (tmp_path / "x.png").write_bytes(b"\x89PNG")
    page = Page("t", base=tmp_path / "rep")
    (tmp_path / "rep").mkdir()
    with pytest.raises(ValueError, match="leaves the report folder"):
        page.add_figure("../x.png")
    page.add_markdown("![x](../x.png)")  # a Markdown image outside: shown as missing, not read
    assert "base64" not in page.render() and "not found" in page.render()


def test_write_keeps_the_old_page_when_rendering_fails(tmp_path, monkeypatch):
    target = tmp_path / "p.html"
    Page("old").write(target)
    before = target.read_text()

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr(os, "fsync", boom)
    with pytest.raises(OSError):
        Page("new").write(target)
    assert target.read_text() == before and sorted(p.name for p in tmp_path.iterdir()) == ["p.html"]


def test_page_renders_in_headless_chromium(tmp_path):
    require_browser()
    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    page = Page("browser check", base=tmp_path)
    page.add_table(_frame(), caption="runs", units={"energy": "J"}, failed_rows=[False, True, False])
    page.add_figure(fig, caption="a line")
    plt.close(fig)
    (tmp_path / "bad.html").write_text('<html><body><img src="nope.png" alt="gone"><script>nope()</script></body></html>')
    with Browser() as b:
        seen = b.check(page.write(tmp_path / "p.html"))
        bad = b.check(tmp_path / "bad.html")
    assert seen.console_errors == []
    assert seen.images == 1 and seen.broken_images == []
    assert seen.tables == ["runs"]
    # the checker itself sees a missing image and a script error
    assert bad.broken_images == ["gone"] and len(bad.console_errors) == 2
