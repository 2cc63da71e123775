"""``ftcsim report`` (what ``make demo`` runs) over every registered paper's demo scenarios:
short in-process runs of each (a scenario file that extends the shipped one with a shorter
stop), then one report per paper from the result folders, as the command line passes them; its
report.md keeps every table a table and its report.html opens in headless Chromium with every
figure rendered and no console error."""
import json

import pytest
from markdown_it import MarkdownIt

from orchestrator.cli.main import main
from papers.registry import papers
from tests.browser import Browser, missing
from tests.unit_spelling import misspelt, misspelt_units

REPORTED = [p for p in papers() if p.report and p.demo]
STOP = 3.0  # s: past every paper's start-up transient, short enough for the suite


def _not_json(constant):
    raise ValueError(f"report.json holds {constant}: not strict JSON")


@pytest.fixture(scope="module")
def browser():
    """One headless Chromium for the module's pages (None where it is missing: the check is skipped)."""
    if missing():
        yield None
        return
    with Browser() as b:
        yield b


def _table_rows_agree(md: str) -> list:
    """Per table found by markdown-it: (columns in the header, set of cell counts of the rows)."""
    out, cur, n = [], None, 0
    for t in MarkdownIt("commonmark").enable("table").parse(md):
        if t.type == "table_open":
            cur = []
        elif t.type == "tr_open":
            n = 0
        elif t.type in ("th_open", "td_open"):
            n += 1
        elif t.type == "tr_close":
            cur.append(n)
        elif t.type == "table_close":
            out.append((cur[0], set(cur[1:])))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("paper", REPORTED, ids=[p.key for p in REPORTED])
def test_report_of_every_papers_demo_runs(paper, tmp_path, capsys, browser):
    folders = []
    for name in paper.demo:
        short = tmp_path / f"{name}.toml"
        short.write_text(f'[scenario]\nextends = "{name}"\nname = "{name}"\n\n[timing]\nstop = {STOP}\n',
                         encoding="utf-8")
        folder = tmp_path / "runs" / name
        assert main(["run", str(short), "--mode", "inprocess", "--out", str(folder), "--no-plots", "--quiet"]) == 0, \
            capsys.readouterr().err
        folders.append(str(folder))
    out = tmp_path / "report"
    rc = main(["report", *folders, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 0, err
    text = (out / "report.md").read_text(encoding="utf-8")
    data = json.loads((out / "report.json").read_text(encoding="utf-8"), parse_constant=_not_json)
    assert text.strip() and data
    pngs = list(out.glob("*.png"))
    assert pngs and all(p.stat().st_size > 1000 for p in pngs)
    tables = _table_rows_agree(text)  # a cell with an unescaped | would add a cell to its row
    assert tables and all(counts <= {head} for head, counts in tables), tables
    for p in pngs:
        assert f"]({p.name})" in text  # every figure embedded in the Markdown
    # one spelling per unit: the file's (N.m, N2.m2.s) in report.md and metrics.json, the page's in report.html
    assert misspelt(text, page=False) == []
    assert misspelt((out / "report.html").read_text(encoding="utf-8"), page=True) == []
    for f in folders:
        assert misspelt_units(json.loads((tmp_path / "runs" / f.rsplit("/", 1)[-1] / "metrics.json").read_text())["units"]) == []
    if browser is None:
        pytest.skip(missing())
    seen = browser.check(out / "report.html")
    assert seen.console_errors == [], seen.console_errors
    assert seen.broken_images == [] and seen.images == len(pngs)
    assert len(seen.tables) >= 2  # the reproduction table and the runs


def test_declare_derives_every_reference_from_the_folder_layout():
    from papers.paper import declare, resolve

    for p in REPORTED:  # each reference of a shipped paper resolves to a callable
        for ref in (p.metrics, p.report, *(f.factory for f in p.fmus)):
            assert callable(resolve(ref)), ref
    q = declare("009", "new2026", "a paper without a report yet", fmus=(("M", "plant", "d"),), parameters="P",
                report=False)
    assert q.package == "papers.p009_new2026" and q.report is None
    assert q.fmus[0].factory == "papers.p009_new2026.blocks:plant"
    assert q.parameter_sets == {"new2026": "papers.p009_new2026.parameters:P"}
