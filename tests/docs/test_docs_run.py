"""Every shell, console and Python block of README.md and docs/*.md runs as written (issue 23
item 5), in a temporary copy of the project, so a drifting doc fails the suite.

The copy: the project's files (git's list: tracked and untracked, not ignored), the built FMUs
(copied), ``.venv`` (linked; the copy's modules come first on PYTHONPATH, ``.venv/bin`` first
on PATH). To keep the suite short, every shipped scenario, campaign and example scenario in the
copy stops after at most :data:`STOP` s and a campaign has at most :data:`RUNS` draws: the
commands run as written on shorter runs; the numbers the docs quote come from full runs (each
doc says with which command). ``make demo`` in a block runs what it runs after the install and
the FMU build (``python -m orchestrator.tools.demo --out results --paper 000``: the blocks read
paper 000's runs only; the copy has the install and the FMUs); ``make test`` is this suite and is not run from inside it. Conventions for the blocks, the markers
``<!-- not-run: reason -->`` and ``<!-- file: path -->`` and the expected exit statuses:
tests/docs/blocks.py.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.docs.blocks import RUN, blocks

ROOT = Path(__file__).resolve().parents[2]
DOCS = ["README.md", *sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md"))]
STOP = 2.0  # s: longest run in the copy
RUNS = 2  # draws per campaign in the copy
TIMEOUT = 600  # s per block
RC = "__ftcsim_doc_rc__"
# `make demo` after its install and FMU build, for paper 000 only: the blocks read only its runs
# (results/li2023_*); every paper's demo and report are tested by tests/orchestrator/test_paper_reports.py
MAKE = {"make demo": ".venv/bin/python -m orchestrator.tools.demo --out results --paper 000"}
NOT_FROM_INSIDE = ("make test", "make bench")  # this suite itself; the benchmarks (minutes)


def project_files() -> list[str]:
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT, capture_output=True,
                         check=True).stdout.decode()
    return [f for f in out.split("\0") if f and (ROOT / f).is_file()]


def shorten(copy: Path) -> None:
    """At most STOP s per scenario and RUNS draws per campaign, in the copy's TOML files."""
    for f in copy.rglob("*.toml"):
        if ".venv" in f.parts or "build" in f.parts:
            continue
        text = f.read_text(encoding="utf-8")
        new = re.sub(r"(?m)^(\s*stop\s*=\s*)([0-9.eE+-]+)", lambda m: m.group(1) + repr(min(float(m.group(2)), STOP)), text)
        if "[campaign]" in new:
            new = re.sub(r"(?m)^(\s*runs\s*=\s*)(\d+)", lambda m: m.group(1) + str(min(int(m.group(2)), RUNS)), new)
        if new != text:
            f.write_text(new, encoding="utf-8")


@pytest.fixture
def project(tmp_path, fmu_dir, fmi3_dir) -> Path:
    copy = tmp_path / "project"
    for f in project_files():
        (copy / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, copy / f)
    shutil.copytree(fmu_dir, copy / "build" / "fmus", ignore=shutil.ignore_patterns(".test-build-lock"))
    (copy / ".venv").symlink_to(ROOT / ".venv")
    shorten(copy)
    return copy


def environment(copy: Path, tmp: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("FTCSIM_", "PYTEST", "COV_"))}
    env.update(PATH=f"{copy / '.venv' / 'bin'}{os.pathsep}{env.get('PATH', '')}", PYTHONPATH=str(copy),
               MPLBACKEND="Agg", TMPDIR=str(tmp), PYTHONDONTWRITEBYTECODE="1")
    return env


def script(commands) -> str:
    """One bash script: each command, then its status on a marker line (and the status restored
    for a following ``echo $?``)."""
    lines = []
    for c in commands:
        text = c.text.strip()
        for make, instead in MAKE.items():
            text = re.sub(rf"^{make}\b", instead, text)
        if text.startswith(NOT_FROM_INSIDE):
            text = "true  # " + text
        lines += [text, f'__rc=$?; echo "{RC} $__rc"; (exit $__rc)']
    return "\n".join(lines) + "\n"


def run_block(b, copy: Path, env: dict) -> str | None:
    """Run block ``b`` in ``copy``; None if it did what it shows, else what went wrong."""
    if b.file:
        target = (copy / b.file).resolve()
        assert copy.resolve() in target.parents, f"{b.where}: file marker leaves the project: {b.file}"
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(b.text, encoding="utf-8")
        return None
    if b.lang == "python":
        src = Path(env["TMPDIR"]) / f"block_{b.line}.py"
        src.write_text(b.text, encoding="utf-8")
        p = subprocess.run([str(copy / ".venv" / "bin" / "python"), str(src)], cwd=copy, env=env, capture_output=True,
                           text=True, timeout=TIMEOUT)
        return None if p.returncode == 0 else f"{b.where}: python block exit {p.returncode}:\n{p.stderr[-3000:]}"
    p = subprocess.run(["bash", "-c", script(b.commands)], cwd=copy, env=env, capture_output=True, text=True,
                       timeout=TIMEOUT)
    got = [int(m) for m in re.findall(rf"^{RC} (\d+)$", p.stdout, re.M)]
    for c, rc in zip(b.commands, got):
        if rc != c.expect:
            return (f"{b.where}: `{c.text.strip()}` exit {rc}, the doc shows {c.expect}:\n"
                    f"{p.stderr[-3000:]}\n{p.stdout[-1500:]}")
    if len(got) != len(b.commands):
        return f"{b.where}: the block stopped after {len(got)} of {len(b.commands)} commands:\n{p.stderr[-3000:]}"
    return None


def test_every_fenced_block_says_its_language():
    unnamed = [f"{b.where}" for d in DOCS for b in blocks(ROOT / d, d) if not b.lang]
    assert unnamed == [], "give these blocks a language (sh, console, python, toml, text...)"


def test_not_run_markers_give_a_reason():
    bare = [b.where for d in DOCS for b in blocks(ROOT / d, d) if b.skip is not None and len(b.skip) < 10]
    assert bare == []


@pytest.mark.slow
@pytest.mark.parametrize("doc", DOCS)
def test_doc_blocks_run_as_written(doc, project, tmp_path):
    todo = [b for b in blocks(ROOT / doc, doc) if (b.lang in RUN or b.file) and b.skip is None]
    if not todo:
        pytest.skip(f"{doc}: no runnable block")
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    env = environment(project, tmp)
    todo.sort(key=lambda b: b.file is None)  # the files a doc shows first: a command may use one shown after it
    for b in todo:
        problem = run_block(b, project, env)
        assert problem is None, problem
