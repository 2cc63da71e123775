"""``ftcsim report`` (what ``make demo`` runs) over every registered paper's demo scenarios:
short in-process runs of each (a scenario file that extends the shipped one with a shorter
stop), then one report per paper from the result folders, as the command line passes them."""
import json

import pytest

from orchestrator.cli.main import main
from papers.registry import papers

REPORTED = [p for p in papers() if p.report and p.demo]
STOP = 3.0  # s: past every paper's start-up transient, short enough for the suite


def _not_json(constant):
    raise ValueError(f"report.json holds {constant}: not strict JSON")


@pytest.mark.slow
@pytest.mark.parametrize("paper", REPORTED, ids=[p.key for p in REPORTED])
def test_report_of_every_papers_demo_runs(paper, tmp_path, capsys):
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
