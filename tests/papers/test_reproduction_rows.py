"""Every reproduction row of every registered paper can fail (tests/papers/flip.py), built without runs (the
rows that need a run are then 'not attempted' but keep their rule and threshold) and with the stored LMI
studies; the report tests do the same on the rows of real runs (tests/papers/p000_li2023/...). Seconds."""
import pytest

from papers.paper import resolve
from papers.registry import papers
from tests.papers.flip import assert_every_check_can_fail

PAPERS = [p for p in papers() if p.report]


@pytest.mark.parametrize("paper", PAPERS, ids=[p.key for p in PAPERS])
def test_every_row_of_every_paper_can_fail(paper):
    rows = resolve(f"{paper.package}.reproduction:rows")({})
    seen = assert_every_check_can_fail(rows)
    assert seen["flipped"] >= 3, seen  # each paper has real checks, not only impossible or cannot-fail rows
