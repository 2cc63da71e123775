"""papers/reproduction.py: the verdict rules at and around their thresholds, each rule's probe on both sides,
the three counts per item (literal, best documented reading with a variant's success counted partly,
impossible and cannot-fail apart), the headline, the markdown / JSON / README renderings."""
import json
import math

import pytest

from papers.reproduction import (
    CONSISTENT,
    IMPOSSIBLE,
    NOT,
    NOT_ATTEMPTED,
    PARTLY,
    PRINTED,
    READING,
    REPRODUCED,
    VARIANT,
    Row,
    above,
    at_least,
    at_most,
    below,
    close,
    close_all,
    headline,
    impossible,
    insert_after_title,
    not_attempted,
    readme_row,
    readme_table,
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


def test_thresholds_at_zero_and_below_zero():
    r = at_most(0.0, 1.0)
    assert r.verdict(5.0, 5.0) == REPRODUCED and r.verdict(5.0, 5.0 + 1e-9) == NOT
    assert r.verdict(0.0, 0.0) == REPRODUCED and r.verdict(0.0, 1e-12) == NOT  # a disk excess, an LMI bound
    assert at_most().verdict(-1.0, -0.95) == REPRODUCED and at_most().verdict(-1.0, -0.85) == PARTLY
    assert "partly" not in r.describe()
    assert below().verdict(0.0, -1e-12) == REPRODUCED and below().verdict(0.0, 0.0) == NOT  # strict: abscissa 0 fails
    assert above().verdict(1.0, 1.0 + 1e-12) == REPRODUCED and above().verdict(1.0, 1.0) == NOT


def test_at_least_toward_close_all():
    assert at_least().verdict(10.0, 9.0) == REPRODUCED and at_least().verdict(10.0, 8.9) == PARTLY
    assert at_least().verdict(10.0, 3.3) == NOT
    t = toward(1.0)
    assert t.verdict(0.6, 0.62) == REPRODUCED and t.verdict(0.6, 0.99) == PARTLY
    assert t.verdict(0.6, 1.007) == NOT and t.verdict(0.6, 0.1) == NOT  # overshoot beyond the start distance
    c = close_all()
    assert c.verdict([1.0, 2.0], [1.05, 2.1]) == REPRODUCED
    assert c.verdict([1.0, 2.0], [1.05, 5.0]) == PARTLY  # the worst entry decides: one reading per column
    assert c.verdict([1.0, 2.0], [1.05, 7.0]) == NOT and c.verdict([1.0, 2.0], [None, 2.0]) == NOT
    with pytest.raises(TypeError):
        c.verdict([1.0, 2.0], [1.0])


def test_a_claim_is_a_number_not_a_bool():
    with pytest.raises(TypeError):
        below().verdict(1.0, True)
    with pytest.raises(TypeError):
        close().verdict("text", 1.0)


@pytest.mark.parametrize("rule, paper", [(close(), 10.0), (close(), -2.0), (close(), 0.0), (at_most(), 4e-7),
                                         (at_most(0.0, 1.0), 0.0), (at_most(), -1.0), (at_least(), 10.0),
                                         (at_least(0.0, 1.0), 0.5), (below(), 1.0), (below(), 0.0), (above(), 1.0),
                                         (above(), 0.0), (toward(1.0), 0.6), (close_all(), [2.6e-6, 4.4e-6])])
def test_every_rule_probes_both_sides_of_its_threshold(rule, paper):
    good, bad = rule.probe(paper)
    assert rule.verdict(paper, good) == REPRODUCED and rule.verdict(paper, bad) == NOT


def test_rows_impossible_consistent_and_the_variant_demotion():
    assert Row("a", 1.0, None, close()).verdict == NOT_ATTEMPTED
    row = not_attempted("b", "claim", "run missing")
    assert row.verdict == NOT_ATTEMPTED and row.ours_display() == "—"
    imp = impossible("c", "claim", "missing law or baseline", "ref. [9] gives it")
    assert imp.verdict == IMPOSSIBLE and imp.note.startswith("missing law or baseline: ")
    with pytest.raises(ValueError):
        impossible("c", "claim", "we did not feel like it", "")
    with pytest.raises(ValueError):
        Row("d", 1.0, 1.0, close(), kind="literal")
    cons = Row("e", 1.0, 5.0, close(), consistent="true by construction")
    assert cons.verdict == CONSISTENT  # whatever the number
    v = Row("f", 1.0, 1.0, close(), "alpha fitted", kind=VARIANT)
    assert v.rule_verdict == REPRODUCED and v.verdict == PARTLY and "variant" in v.verdict_text()
    assert Row("g", 1.0, 1.0, close(), "alpha chosen", kind=READING).verdict == REPRODUCED


def _rows():
    return [
        Row("item 1", 1.0, 5.0, close(), "as printed"),  # not
        Row("item 1", 1.0, 1.05, close(), "fitted", kind=VARIANT),  # reproduced under a variant: partly
        Row("item 2", 1.0, 2.0, close(), "as printed"),  # partly
        Row("item 2", 1.0, 1.01, close(), "gap filled", kind=READING),  # reproduced under a documented reading
        impossible("item 3", "x", "unprinted parameter", "alpha not printed"),
        Row("item 3", 1.0, 1.0, close(), "alpha chosen", kind=READING),  # judged: literal impossible, best reproduced
        impossible("item 4", "x", "missing law or baseline", "ref. [35]"),
        Row("item 5", 1.0, 9.0, close(), consistent="an input checked against itself"),
        Row("item 6", 1.0, None, close(), "as printed"),  # not attempted (run missing)
    ]


def test_three_counts_never_mixed():
    s = summarize(_rows())
    assert s["items"] == 6 and s["rows"] == 9 and s["judged"] == 4
    assert s["impossible"] == 1 and s["consistent"] == 1
    lit, best = s["literal"], s["best"]
    assert (lit[REPRODUCED], lit[PARTLY], lit[NOT], lit[NOT_ATTEMPTED], lit[IMPOSSIBLE]) == (0, 1, 1, 1, 1)
    assert (best[REPRODUCED], best[PARTLY], best[NOT], best[NOT_ATTEMPTED]) == (2, 1, 0, 1)
    assert s["per_item"]["item 1"] == {"literal": NOT, "best": PARTLY, "best_reading": "variant: fitted", "rows": 2}
    assert headline(s) == "literal 0/4, best reading 2/4, impossible 1, cannot fail 1"
    data = json.loads(json.dumps(to_json(_rows())))  # report.json: the same counts, the headline from it
    assert headline(data["summary"]) == headline(s)


def test_an_item_needs_an_as_printed_row():
    with pytest.raises(ValueError, match="as-printed"):
        summarize([Row("only a variant", 1.0, 1.0, close(), kind=VARIANT)])


def test_markdown_json_and_readme_renderings(tmp_path):
    md = render_markdown(_rows(), "T")
    line = md.splitlines()[2]
    assert line.startswith("**Literal readings (as printed): reproduced 0 of 4**")
    assert "**Best documented reading: reproduced 2 of 4**" in line and "consistent (cannot fail): 1 item**" in line
    assert md.count("\n| ") == 10  # header + 9 rows
    data = json.loads(json.dumps(to_json(_rows()), allow_nan=False))
    assert [r["verdict"] for r in data["rows"]] == [NOT, PARTLY, PARTLY, REPRODUCED, IMPOSSIBLE, REPRODUCED, IMPOSSIBLE,
                                                    CONSISTENT, NOT_ATTEMPTED]
    assert data["rows"][1]["rule_verdict"] == REPRODUCED and data["rows"][1]["kind"] == VARIANT
    row = readme_row("000", summarize(_rows()))
    assert row == ("| 000 Li, Xu, Chang 2023 | 4 | 0 / 1 / 1 (+1 not attempted; +1 impossible as printed) | 2 / 1 / 0 "
                   "(+1 not attempted) | 1 | 1 |")
    assert readme_table({"000": summarize(_rows())}).splitlines()[2] == row
    rows = [Row("||u||_1 <= 5", 5.0, math.nan, at_most(), "a | b")]
    md = render_markdown(rows)
    assert "\\|\\|u\\|\\|_1" in md and "a \\| b" in md
    assert '"verdict": "not reproduced"' in json.dumps(to_json(rows), allow_nan=False)
    f = tmp_path / "report.md"
    f.write_text("# Title\n\nbody\n", encoding="utf-8")
    insert_after_title(f, "## Counts\n")
    assert f.read_text(encoding="utf-8").splitlines()[:4] == ["# Title", "", "## Counts", ""]
    assert PRINTED == "as printed"
