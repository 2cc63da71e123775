"""The documents as a reader meets them (issue 36 item 2): every shell, console and Python block of
README.md and docs/*.md runs in order in ONE working folder (tests/docs/reader.py), and every
output a page shows is compared with what was printed: text exactly, ``…`` for what depends on the
machine (wall times, paths), numbers within the block's tolerance (default 1e-6 relative: the
printed digits; tests/docs/blocks.py). A changed default that changes a documented number fails
here; ``python -m tests.docs.update`` writes the printed numbers into the pages.

* ``make test`` (:func:`test_fast_blocks_as_documented`): the blocks that take seconds and need
  no ``make demo`` (tens of seconds together);
* ``make test-long`` (:func:`test_docs_in_full`, tests/conftest.py LONG): every block, ``make demo``
  where the README runs it, the blocks marked ``<!-- cost: ... -->`` (minutes each, the cost on the
  page) and ``<!-- needs: make demo -->``; and the README's reproduction table against the
  reports the demo wrote.

Measurements of time (benchmarks, wall times) are quoted with their command and date and are
machine-dependent: a shown wall time is elided as ``…``; every other number a page prints comes from
a block run here.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.docs.blocks import blocks
from tests.docs.reader import DOCS, ROOT, Reader, project_files


def _all_blocks():
    return [b for d in DOCS for b in blocks(ROOT / d, d)]


def test_every_fenced_block_says_its_language():
    unnamed = [b.where for b in _all_blocks() if not b.lang]
    assert unnamed == [], "give these blocks a language (sh, console, python, toml, text...)"


def test_not_run_markers_give_a_reason():
    bare = [b.where for b in _all_blocks() if b.skip is not None and len(b.skip) < 10]
    assert bare == []


def _paragraph(text: list[str], k: int, step: int) -> str:
    """The paragraph met from line ``k`` walking by ``step`` (-1 up, +1 down), markers and blank lines
    before it skipped; stops at a fence."""
    para = []
    while 0 <= k < len(text) and not text[k].lstrip().startswith(("```", "~~~")):
        if text[k].strip() and not text[k].strip().startswith("<!--"):
            para.append(text[k])
        elif para:
            break
        k += step
    return " ".join(para)


def test_costly_blocks_say_their_cost_on_the_page():
    """A block marked ``<!-- cost: 3 min -->`` shows "3 min" to the reader next to it: in the block (a
    command's trailing comment), in the paragraph right above it or in the one right after it."""
    missing = []
    for d in DOCS:
        text = (ROOT / d).read_text(encoding="utf-8").split("\n")
        for b in blocks(ROOT / d, d):
            if b.cost is None:
                continue
            end = b.first + len(b.text.rstrip("\n").split("\n"))  # the closing fence
            near = b.text + _paragraph(text, b.line - 2, -1) + _paragraph(text, end + 1, +1)
            if b.cost not in near:
                missing.append(f"{b.where}: marked cost {b.cost!r}, not said on the page")
    assert missing == []


def test_the_first_campaign_command_a_reader_meets_is_short():
    """The first ``ftcsim campaign`` / ``compare`` command of the pages, in reading order, is cut short
    (``--runs`` and ``--stop``); the full one comes after it."""
    for b in _all_blocks():
        for c in b.commands:
            if re.search(r"\bftcsim (campaign|compare) ", c.text) and "--replay" not in c.text:
                assert "--runs" in c.text and "--stop" in c.text, f"{b.where}: {c.text.strip()}"
                return
    pytest.fail("no campaign command in the pages")


def _report(outcomes) -> list[str]:
    out = []
    for o in outcomes:
        out += o.problems
        out += [f"{o.block.where}: printed:\n{text}" for text in o.printed]
        out += [f"{o.block.where}: {c} took {s:.0f} s of CPU: mark the block <!-- cost: ... --> and say so on the page"
                for c, s in o.slow]
    return out


@pytest.mark.slow
def test_fast_blocks_as_documented(tmp_path, fmu_dir, fmi3_dir):
    reader = Reader(tmp_path, fmu_dir, long=False)
    problems = []
    for doc in DOCS:
        problems += _report(reader.run_doc(doc))
    assert problems == [], "\n\n".join(problems)
    assert reader.new_at_root() == [], "the pages' commands wrote into the project root"


def test_docs_in_full(tmp_path, fmu_dir, fmi3_dir):
    reader = Reader(tmp_path, fmu_dir, long=True)
    problems = []
    for doc in DOCS:
        problems += _report(reader.run_doc(doc))
    problems += readme_reproduction_table(reader.copy)
    assert problems == [], "\n\n".join(problems)
    assert reader.new_at_root() == [], "the pages' commands wrote into the project root"


def readme_reproduction_table(copy: Path) -> list[str]:
    """The README's "What reproduces" table equals the counts of the reports ``make demo`` wrote
    (``python -m papers.reproduction_counts results --check README.md``, run in the reader's folder)."""
    p = subprocess.run([str(copy / ".venv" / "bin" / "python"), "-m", "papers.reproduction_counts", "results", "--check",
                        "README.md"], cwd=copy, capture_output=True, text=True, timeout=600,
                       env={**os.environ, "PYTHONPATH": str(copy)})
    return [] if p.returncode == 0 else [f"README.md: the reproduction table differs from the demo's reports:\n"
                                         f"{p.stdout[-3000:]}{p.stderr[-2000:]}"]


@pytest.mark.slow
def test_a_changed_default_fails_the_docs_test(tmp_path, fmu_dir):
    """The README's Python block prints numbers of li2023_fasmc; in a copy where FASMC's default gain
    in the shipped scenario is changed, the block's comparison fails and names the number."""
    from tests.docs.blocks import blocks as read_blocks

    reader = Reader(tmp_path, fmu_dir, long=False)
    (block,) = [b for b in read_blocks(ROOT / "README.md", "README.md") if b.lang == "python" and b.expected]
    ok = reader.run_block(block)
    assert ok.problems == [], ok.problems
    scenario = reader.copy / "papers" / "p000_li2023" / "scenarios" / "li2023_fasmc.toml"
    text = scenario.read_text(encoding="utf-8")
    changed = re.sub(r"(?m)^(u_max\s*=\s*)5\.0", r"\g<1>4.0", text)
    assert changed != text, "li2023_fasmc.toml: its u_max default moved; choose another default here"
    scenario.write_text(changed, encoding="utf-8")
    bad = reader.run_block(block)
    assert any("printed with other numbers" in p and "final_attitude_error" in p for p in bad.problems), bad.problems
    assert bad.fixes, "the comparison names the corrected line"


def test_the_reader_copies_what_git_ships():
    files = project_files()
    assert "README.md" in files and not any(f.startswith((".venv/", "build/", "results/")) for f in files)
    assert shutil.which("bash") and shutil.which("awk")
