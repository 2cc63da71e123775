"""The check that every reproduction row can fail: each judged row's measured number is moved across its
threshold both ways (:meth:`papers.reproduction.Rule.probe`) and its verdict must flip; a row that cannot
flip must say so (``consistent``: counted apart) or be impossible from the published text."""
from __future__ import annotations

import dataclasses

from papers.reproduction import CONSISTENT, IMPOSSIBLE, NOT, NOT_ATTEMPTED, PARTLY, REPRODUCED, VARIANT, summarize


def judged(row) -> bool:
    return row.rule is not None and row.impossible is None and row.consistent is None


def assert_every_check_can_fail(rows) -> dict:
    """Every judged row flips between reproduced (partly for a variant) and not reproduced; the others are
    impossible, consistent or not attempted (no rule). Every item has an as-printed row, every note is a
    whole sentence. Returns counts by status (for the caller's own assertions)."""
    summarize(rows)  # raises for an item without an as-printed row
    seen = {"flipped": 0, IMPOSSIBLE: 0, CONSISTENT: 0, NOT_ATTEMPTED: 0}
    for r in rows:
        assert r.note.strip(), f"{r.item!r} ({r.reading}): no note"
        assert r.note.rstrip().endswith((".", ".)", "?")), f"{r.item!r} ({r.reading}): note is not a whole sentence: {r.note!r}"
        if r.impossible is not None:
            assert r.verdict == IMPOSSIBLE
            seen[IMPOSSIBLE] += 1
            continue
        if r.rule is None:
            assert r.verdict == NOT_ATTEMPTED
            seen[NOT_ATTEMPTED] += 1
            continue
        good, bad = r.rule.probe(r.paper)
        if r.consistent is not None:
            assert dataclasses.replace(r, ours=good).verdict == CONSISTENT == dataclasses.replace(r, ours=bad).verdict
            seen[CONSISTENT] += 1
            continue
        assert not isinstance(r.ours, bool), f"{r.item!r}: a measured number is needed, not {r.ours!r}"
        up, down = dataclasses.replace(r, ours=good).verdict, dataclasses.replace(r, ours=bad).verdict
        assert up == (PARTLY if r.kind == VARIANT else REPRODUCED), (r.item, r.reading, good, up)
        assert down == NOT, (r.item, r.reading, bad, down)
        seen["flipped"] += 1
    return seen
