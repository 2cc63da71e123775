"""A reader working through the documents: every runnable block of README.md and docs/*.md, in the
order a reader meets them (:data:`DOCS`), in ONE working folder, a copy of the project, each shown
output compared with what was printed (tests/docs/blocks.py says how).

The copy: the project's files (git's list: tracked and untracked, not ignored), the built FMUs (one
symbolic link per file, in real folders, so a command writing into build/fmus writes into the
copy), ``.venv`` (linked; the copy's modules come first on PYTHONPATH, ``.venv/bin`` first on PATH:
what ``source .venv/bin/activate`` does). ``make demo`` in a block runs what it runs after the
install and the FMU build (``python -m orchestrator.tools.demo --out results``); ``make test`` and
``make bench`` are not run from inside (this suite; the benchmarks).

``long=False`` (``make test``) leaves out the blocks marked ``<!-- cost: ... -->`` or
``<!-- needs: make demo -->``; ``long=True`` (``make test-long``) runs every block. Nothing may be
written into the copy's root but ``results/`` and ``build/`` (checked at the end).
"""
from __future__ import annotations

import os
import re
import resource
import shutil
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from tests.docs.blocks import RUN, blocks, compare

ROOT = Path(__file__).resolve().parents[2]
# the reader's order: the README, then the pages it sends a newcomer to; any other page after them
READING_ORDER = ["README.md", "docs/own-controller.md", "docs/campaigns.md", "docs/step-policies.md",
                 "docs/external-tools.md", "docs/performance.md", "docs/arena-design.md"]
DOCS = READING_ORDER + sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md")
                              if str(p.relative_to(ROOT)) not in READING_ORDER)
RC = "__ftcsim_doc_rc__"
MAKE = {"make demo": ".venv/bin/python -m orchestrator.tools.demo --out results"}
NOT_FROM_INSIDE = ("make test", "make bench")  # this suite itself; the benchmarks (minutes)
SLOW = 60.0  # s of CPU: a block costing more must be marked with its cost (CPU, not wall time: the load does not count)
TIMEOUT = 3600  # s per block
ALLOWED_AT_ROOT = {"results", "build"}


@dataclass
class Outcome:
    """What running one block gave."""

    block: object
    seconds: float = 0.0
    cpu: float = 0.0  # s of CPU of the block's processes (user + system, every process it waited for)
    problems: list = field(default_factory=list)
    fixes: dict = field(default_factory=dict)  # document line (0-based) -> corrected shown line
    slow: list = field(default_factory=list)  # (what, CPU seconds) over SLOW without a cost marker
    printed: list = field(default_factory=list)  # what the commands whose output differs printed


def project_files() -> list[str]:
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT, capture_output=True,
                         check=True).stdout.decode()
    return [f for f in out.split("\0") if f and (ROOT / f).is_file()]


def make_copy(dest: Path, fmu_dir: Path) -> Path:
    """The working folder: the project's files copied, each built FMU linked (see the module docstring)."""
    for f in project_files():
        (dest / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, dest / f)
    native = ROOT / "build" / "native"  # the compiled export libraries the install built (fmus/export_library.py)
    if native.is_dir():
        shutil.copytree(native, dest / "build" / "native", symlinks=True)
    for fmu in sorted(Path(fmu_dir).rglob("*.fmu")):
        target = dest / "build" / "fmus" / fmu.relative_to(fmu_dir)
        target.parent.mkdir(parents=True, exist_ok=True)
        target.symlink_to(fmu.resolve())
    (dest / ".venv").symlink_to(ROOT / ".venv")
    return dest


def environment(copy: Path, tmp: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("FTCSIM_", "PYTEST", "COV_"))}
    env.update(PATH=f"{copy / '.venv' / 'bin'}{os.pathsep}{env.get('PATH', '')}", PYTHONPATH=str(copy),
               MPLBACKEND="Agg", TMPDIR=str(tmp), PYTHONDONTWRITEBYTECODE="1", VIRTUAL_ENV=str(copy / ".venv"))
    env.pop("PYTHONHOME", None)
    return env


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


class Reader:
    """One working folder (``folder``, created from the project) and the documents run in it."""

    def __init__(self, folder: Path, fmu_dir: Path, long: bool):
        self.copy = make_copy(Path(folder) / "project", fmu_dir)
        self.tmp = Path(folder) / "tmp"
        self.tmp.mkdir()
        self.env = environment(self.copy, self.tmp)
        self.long = long
        self.root_before = {p.name for p in self.copy.iterdir()}

    def todo(self, doc: str) -> list:
        """The blocks of ``doc`` this reader runs, files first (a command may use a file shown after it)."""
        out = [b for b in blocks(ROOT / doc, doc) if (b.lang in RUN or b.file) and b.skip is None
               and (self.long or (b.cost is None and b.needs is None))]
        return sorted(out, key=lambda b: b.file is None)

    def run_doc(self, doc: str) -> list[Outcome]:
        return [self.run_block(b) for b in self.todo(doc)]

    def new_at_root(self) -> list[str]:
        """What the documents wrote into the copy's root besides results/ and build/."""
        return sorted({p.name for p in self.copy.iterdir()} - self.root_before - ALLOWED_AT_ROOT)

    def run_block(self, b) -> Outcome:
        o = Outcome(b)
        t0, cpu0 = time.monotonic(), _children_cpu()
        try:
            self._run(b, o, t0)
        finally:
            o.seconds, o.cpu = time.monotonic() - t0, _children_cpu() - cpu0
            if b.cost is None and o.cpu > SLOW:
                o.slow.append((f"{len(b.commands) or 1} command(s)", o.cpu))
        return o

    def _run(self, b, o: Outcome, t0: float) -> None:
        if b.file:
            target = (self.copy / b.file).resolve()
            if self.copy.resolve() not in target.parents:
                o.problems.append(f"{b.where}: file marker leaves the project: {b.file}")
                return
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(b.text, encoding="utf-8")
            return
        if b.lang == "python":
            src = self.tmp / f"block_{Path(b.doc).stem}_{b.line}.py"
            src.write_text(b.text, encoding="utf-8")
            p = subprocess.run([str(self.copy / ".venv" / "bin" / "python"), str(src)], cwd=self.copy, env=self.env,
                               capture_output=True, text=True, timeout=TIMEOUT)
            if p.returncode != 0:
                o.problems.append(f"{b.where}: python block exit {p.returncode}:\n{p.stderr[-3000:]}")
            elif b.expected is not None:
                problems, fixes = compare(b.expected, p.stdout, b.tolerance)
                o.problems += [f"{b.where}: output: {x}" for x in problems]
                if problems:
                    o.printed.append(p.stdout[-3000:])
                lines = b.expected.split("\n")
                o.fixes.update({b.expected_lines[i]: (lines[i], new) for i, new in fixes.items()})
            return
        outdir = self.tmp / f"out_{Path(b.doc).stem}_{b.line}"
        outdir.mkdir()
        p = subprocess.run(["bash", "-c", script(b.commands, outdir)], cwd=self.copy, env=self.env,
                           capture_output=True, text=True, timeout=TIMEOUT)
        got = {int(k): (int(rc), float(secs)) for k, rc, secs in re.findall(rf"^{RC} (\d+) (\d+) ([\d.]+)$", p.stdout,
                                                                          re.M)}
        for k, c in enumerate(b.commands):
            if k not in got:
                o.problems.append(f"{b.where}: the block stopped before `{c.text.strip()}`:\n{p.stderr[-3000:]}")
                break
            rc, _secs = got[k]
            printed = (outdir / f"{k}.out").read_text(encoding="utf-8", errors="replace")
            if rc != c.expect:
                o.problems.append(f"{b.where}: `{c.text.strip()}` exit {rc}, the doc shows {c.expect}:\n"
                                  f"{printed[-3000:]}")
                continue
            if c.output.strip():
                shown = re.sub(r"(?m)\s*\(rc \d+\)\s*$", "", c.output)  # the status annotation is no output
                problems, fixes = compare(shown, printed, b.tolerance)
                o.problems += [f"{b.where}: `{c.text.strip()}`: {x}" for x in problems]
                if problems:
                    o.printed.append(printed[-3000:])
                lines = shown.split("\n")
                o.fixes.update({c.output_lines[i]: (lines[i], new) for i, new in fixes.items()})


def script(commands, outdir: Path) -> str:
    """One bash script: each command with its stdout and stderr into ``outdir/K.out``, then its status
    and time on a marker line (the status restored for a following ``echo $?``)."""
    lines = []
    for k, c in enumerate(commands):
        text = c.text.strip()
        for make, instead in MAKE.items():
            text = re.sub(rf"^{make}\b", instead, text)
        if text.startswith(NOT_FROM_INSIDE):
            text = "true  # " + text
        lines += ['__t0=$EPOCHREALTIME; (exit $__rc)', "{ " + text, f'}} > "{outdir}/{k}.out" 2>&1',
                  f'__rc=$?; echo "{RC} {k} $__rc $(awk "BEGIN {{print $EPOCHREALTIME - $__t0}}")"']
    return "__rc=0\n" + "\n".join(lines) + "\n"
