"""The index page over a results folder (orchestrator.results.report.write_index, printed last by
`make demo`): every run and report linked, the run's status and metrics from its metrics.json,
a foreign index.html never replaced, the page checked in headless Chromium."""
import json

import pytest

from orchestrator.cli.main import main
from orchestrator.common.errors import InputError
from orchestrator.results.report import write_index
from orchestrator.tools.index import main as index_main
from tests.browser import Browser, require_browser
from tests.unit_spelling import misspelt


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """A results folder: one short in-process run, its paper report, and a folder ftcsim did not write."""
    out = tmp_path_factory.mktemp("results")
    short = out.parent / "short.toml"
    short.write_text('[scenario]\nextends = "li2023_pd"\nname = "li2023_pd"\n\n[timing]\nstop = 1.0\n', encoding="utf-8")
    assert main(["run", str(short), "--mode", "inprocess", "--out", str(out / "li2023_pd"), "--no-plots", "--quiet"]) == 0
    assert main(["report", str(out / "li2023_pd"), "--out", str(out / "report_li2023")]) == 0
    (out / "notes").mkdir()
    return out


def test_index_links_every_run_and_report(results, capsys):
    assert index_main([str(results)]) == 0
    page = results / "index.html"
    assert capsys.readouterr().out.strip() == str(page.resolve())
    text = page.read_text(encoding="utf-8")
    assert 'href="./report_li2023/report.html"' in text and 'href="./li2023_pd/"' in text and "notes" not in text
    m = json.loads((results / "li2023_pd" / "metrics.json").read_text())
    assert f"{m['metrics']['control_energy']:.4g}" in text  # the metric as the run stored it
    assert f"{m['info']['t_end']:.4g}" in text and "t_end [s]" in text  # and its info (scenario, complete, t_end)
    assert "E [N²·m²·s]" in text and "attitude error (end) [rad]" in text  # units from metrics.json, the page's spelling
    assert misspelt(text, page=True) == []
    write_index(results)  # its own page is replaced


def test_a_foreign_index_is_not_replaced(tmp_path, capsys):
    (tmp_path / "index.html").write_text("<html>mine</html>")
    with pytest.raises(InputError, match="not written by ftcsim"):
        write_index(tmp_path)
    assert index_main([str(tmp_path)]) == 2 and "not replaced" in capsys.readouterr().err
    assert (tmp_path / "index.html").read_text() == "<html>mine</html>"


def test_index_page_in_headless_chromium(results):
    require_browser()
    page = write_index(results)
    with Browser() as b:
        seen = b.check(page)
        report = b.check(results / "report_li2023" / "report.html")
    assert seen.console_errors == [] and seen.broken_images == []
    assert set(seen.links) == {"./report_li2023/report.html", "./li2023_pd/"}
    assert report.console_errors == [] and report.broken_images == [] and report.images > 0
