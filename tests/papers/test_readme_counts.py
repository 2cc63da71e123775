"""README's "What reproduces" table and each paper README's counts are what the demo's runs give (issue 31): every
paper's demo scenarios run in process at full length, its report written as `make demo` writes it, and the counts
of its report.json (papers.reproduction.summarize) compared with the READMEs. Minutes (the demo's runs): make
test-long; make test checks paper 000's line from its own full runs (tests/papers/p000_li2023/)."""
import json
import re
from pathlib import Path

import pytest

from orchestrator.cli.main import main
from papers.registry import folder, papers
from papers.reproduction import readme_row
from papers.reproduction_counts import readme_block

ROOT = Path(__file__).resolve().parents[2]
REPORTED = [p for p in papers() if p.report and p.demo]


def _flat(text: str) -> str:
    return re.sub(r"\s+", " ", text)


@pytest.mark.slow
@pytest.mark.parametrize("paper", REPORTED, ids=[p.key for p in REPORTED])
def test_readme_counts_are_the_demos(paper, tmp_path, capsys):
    folders = []
    for name in paper.demo:
        out = tmp_path / name
        assert main(["run", name, "--mode", "inprocess", "--out", str(out), "--no-plots", "--quiet"]) == 0, \
            capsys.readouterr().err
        folders.append(str(out))
    report = tmp_path / "report"
    assert main(["report", *folders, "--out", str(report)]) == 0, capsys.readouterr().err
    s = json.loads((report / "report.json").read_text(encoding="utf-8"))["reproduction"]["summary"]
    assert readme_row(paper.id, s) in readme_block((ROOT / "README.md").read_text(encoding="utf-8")).splitlines()
    own = _flat((folder(paper) / "README.md").read_text(encoding="utf-8"))
    lit, best = s["literal"], s["best"]
    assert f"**Literal readings (as printed): reproduced {lit['reproduced']} of {s['judged']}**" in own
    assert f"**Best documented reading: reproduced {best['reproduced']} of {s['judged']}**" in own
    assert f"(partly {best['partly']}, not reproduced {best['not reproduced']}" in own
    assert f"**Impossible from the published text: {s['impossible']} item" in own
    assert f"**Consistent (cannot fail): {s['consistent']} item" in own
