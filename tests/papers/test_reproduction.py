"""papers/reproduction.py: the verdict rules at and around their bounds, the counts per item (best
shipped reading, literal readings only), missing runs, the markdown and JSON renderings."""
import json
import math

import pytest

from papers.reproduction import (
    NOT,
    NOT_ATTEMPTED,
    PARTLY,
    REPRODUCED,
    Row,
    at_least,
    at_most,
    claim,
    close,
    insert_after_title,
    not_attempted,
    render_markdown,
    summarize,
    to_json,
    toward,
)


@pytest.mark.parametrize("paper, ours, verdict", [
    (10.0, 10.0, REPRODUCED), (10.0, 10.99, REPRODUCED), (10.0, 9.01, REPRODUCED), (10.0, 11.01, PARTLY),
    (10.0, 29.9, PARTLY), (10.0, 3.34, PARTLY), (10.0, 30.1, NOT), (10.0, 3.3, NOT), (10.0, -10.0, NOT),
    (-2.0, -2.1, REPRODUCED), (-2.0, -5.0, PARTLY), (10.0, math.nan, NOT), (10.0, math.inf, NOT),
])
def test_close(paper, ours, verdict):
    assert close().verdict(paper, ours) == verdict


@pytest.mark.parametrize("ours, verdict", [(0.5, REPRODUCED), (4.4, REPRODUCED), (4.41, PARTLY), (12.0, PARTLY),
                                          (12.01, NOT)])
def test_at_most(ours, verdict):
    assert at_most().verdict(4.0, ours) == verdict


def test_at_most_without_slack_or_partly_band():
    r = at_most(0.0, 1.0)
    assert r.verdict(5.0, 5.0) == REPRODUCED and r.verdict(5.0, 5.0 + 1e-9) == NOT
    assert "partly" not in r.describe()


def test_at_least_claim_toward():
    assert at_least().verdict(10.0, 9.0) == REPRODUCED and at_least().verdict(10.0, 8.9) == PARTLY
    assert at_least().verdict(10.0, 3.3) == NOT
    assert claim().verdict("x", True) == REPRODUCED and claim().verdict("x", False) == NOT
    with pytest.raises(TypeError):
        claim().verdict("x", 0.5)
    t = toward(1.0)
    assert t.verdict(0.6, 0.62) == REPRODUCED and t.verdict(0.6, 0.99) == PARTLY
    assert t.verdict(0.6, 1.007) == NOT and t.verdict(0.6, 0.1) == NOT  # overshoot beyond the start distance


def test_missing_run_and_not_attempted():
    assert Row("a", 1.0, None, close()).verdict == NOT_ATTEMPTED
    row = not_attempted("b", "claim", "ref. [9] not available")
    assert row.verdict == NOT_ATTEMPTED and row.ours_display() == "—"
    with pytest.raises(TypeError):
        close().verdict("text", 1.0)


def test_counts_per_item_best_reading_and_as_printed():
    rows = [
        Row("item 1", 1.0, 5.0, close(), "as printed"),  # not
        Row("item 1", 1.0, 1.05, close(), "variant", literal=False),  # reproduced
        Row("item 2", 1.0, 2.0, close(), "as printed"),  # partly
        Row("item 3", 1.0, 2.0, close(), "variant only", literal=False),  # partly, no literal row
        not_attempted("item 4", "x", "why"),
    ]
    s = summarize(rows)
    assert s["items"] == 4 and s["rows"] == 5
    assert s["shipped"] == {REPRODUCED: 1, PARTLY: 2, NOT: 0, NOT_ATTEMPTED: 1}
    assert s["as_printed"] == {REPRODUCED: 0, PARTLY: 2, NOT: 1, NOT_ATTEMPTED: 1}
    md = render_markdown(rows, "T")
    assert md.splitlines()[2].startswith("**4 paper items: reproduced 1, partly 2, not reproduced 0, not attempted 1**")
    assert md.count("\n| ") == 6  # header + 5 rows
    data = json.loads(json.dumps(to_json(rows)))
    assert [r["verdict"] for r in data["rows"]] == [NOT, REPRODUCED, PARTLY, PARTLY, NOT_ATTEMPTED]


def test_markdown_escapes_pipes_and_json_is_strict(tmp_path):
    rows = [Row("||u||_1 <= 5", 5.0, math.nan, at_most(), "a | b")]
    md = render_markdown(rows)
    assert "\\|\\|u\\|\\|_1" in md and "a \\| b" in md
    text = json.dumps(to_json(rows), allow_nan=False)  # NaN would raise
    assert '"verdict": "not reproduced"' in text
    f = tmp_path / "report.md"
    f.write_text("# Title\n\nbody\n", encoding="utf-8")
    insert_after_title(f, "## Counts\n")
    assert f.read_text(encoding="utf-8").splitlines()[:4] == ["# Title", "", "## Counts", ""]
