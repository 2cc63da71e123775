"""The runnable blocks of the project's Markdown (README.md, docs/*.md) and what each expects.

Every fenced block carries a language. Blocks in ``sh``/``bash``/``shell`` (one command per line,
``\\`` continues; a following comment line ``#   ...`` is that command's shown output),
``console`` (``$ command`` lines, the other lines its output) and ``python`` are run; other
languages (``toml``, ``text``, ``c``, ...) are data. HTML comments right before a block (the
non-blank lines before its fence, one comment a line) change that:

* ``<!-- not-run: REASON -->``: the block is not run (illustrative, needs the network, takes
  hours...); the reason is required and shown in the test's skip list;
* ``<!-- file: PATH -->``: the block is the content of the file PATH (relative to the project
  root): it is written there before any block of the document runs;
* ``<!-- cost: 3 min -->``: the block takes minutes: only ``make test-long`` runs it, and the
  page says its cost (the marker's text) in the block or in the paragraph above it;
* ``<!-- needs: make demo -->``: the block reads what ``make demo`` wrote: only ``make test-long``
  (which runs the demo where the README does) runs it;
* ``<!-- output -->`` on a ``text`` block: what the runnable block above it prints (stdout);
* ``<!-- tolerance: 1e-3 -->``: numbers in the shown output agree within this relative tolerance
  (default :data:`TOLERANCE`).

A command is expected to exit 0, except: a following ``$ echo $?`` prints its status; its shown
output has ``(rc N)``; its own trailing comment says ``exit N``; its shown output starts with
``ftcsim: error:`` (bad input: 2).

Shown output is compared with what the command printed (stdout and stderr): every shown line,
in order, must match a printed line (printed lines the page leaves out are allowed); ``…`` in a
shown line stands for any text (wall times, machine paths), and numbers must agree within the
tolerance, every other character exactly (spaces collapsed).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

SHELL = ("sh", "bash", "shell")
RUN = (*SHELL, "console", "python")
_FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|~{3,})(?P<info>[^\n`]*)$")
_MARKER = re.compile(r"^<!--\s*(not-run|file|cost|needs|output|tolerance)\s*:?\s*(.*?)\s*-->$")
TOLERANCE = 1e-6  # relative, numbers of shown output against the printed ones (printed with 6 digits)


@dataclass
class Command:
    text: str
    output: str = ""
    expect: int = 0
    output_lines: list = field(default_factory=list)  # 0-based line of the document of each shown output line


@dataclass
class Block:
    doc: str
    line: int
    lang: str
    text: str
    skip: str | None = None
    file: str | None = None
    cost: str | None = None  # "3 min": run by make test-long only
    needs: str | None = None  # "make demo": run by make test-long only
    output: bool = False  # a text block: the expected stdout of the runnable block above
    tolerance: float = TOLERANCE
    expected: str | None = None  # a runnable block's expected stdout (the output block after it)
    expected_lines: list = field(default_factory=list)  # the document's lines of ``expected``
    first: int = 0  # 0-based line of the document of the block's first body line
    commands: list = field(default_factory=list)

    @property
    def where(self) -> str:
        return f"{self.doc}:{self.line}"


def blocks(path: Path, name: str | None = None) -> list[Block]:
    """Every fenced block of the Markdown file ``path`` in order, with its marker and commands."""
    lines = Path(path).read_text(encoding="utf-8").split("\n")
    out, i = [], 0
    name = name or Path(path).name
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        fence, start = m.group("fence"), i
        j = i + 1
        while j < len(lines) and not lines[j].strip().startswith(fence):
            j += 1
        body = "\n".join(ln[len(m.group("indent")):] if ln.startswith(m.group("indent")) else ln
                         for ln in lines[i + 1:j]) + "\n"
        b = Block(name, start + 1, m.group("info").strip().split(" ")[0].lower(), body, first=start + 1)
        for kind, value in markers(lines, start):
            if kind == "not-run":
                b.skip = value
            elif kind == "file":
                b.file = value
            elif kind == "cost":
                b.cost = value
            elif kind == "needs":
                b.needs = value
            elif kind == "output":
                b.output = True
            else:
                b.tolerance = float(value)
        if b.lang in SHELL:
            b.commands = shell_commands(body, b.first)
        elif b.lang == "console":
            b.commands = console_commands(body, b.first)
        if b.output:
            runnable = next((r for r in reversed(out) if r.lang in RUN and not r.file), None)
            if runnable is None:
                raise ValueError(f"{b.where}: an output block with no runnable block above it")
            runnable.expected = body
            runnable.expected_lines = list(range(b.first, j))
        out.append(b)
        i = j + 1
    return out


def markers(lines: list[str], start: int) -> list[tuple[str, str]]:
    """The markers of the block whose fence is ``lines[start]``: the ``<!-- kind: value -->`` lines
    right above it (blank lines between them allowed), nearest last."""
    found = []
    k = start - 1
    while k >= 0:
        s = lines[k].strip()
        if not s:
            k -= 1
            continue
        m = _MARKER.match(s)
        if not m:
            break
        found.append((m.group(1), m.group(2)))
        k -= 1
    return found[::-1]


def _expect(cmd: Command, next_cmd: Command | None) -> int:
    if next_cmd is not None and next_cmd.text.strip() == "echo $?" and next_cmd.output.strip().isdigit():
        return int(next_cmd.output.strip())
    rc = re.search(r"\(rc (\d+)\)", cmd.output)
    if rc:
        return int(rc.group(1))
    own = re.search(r"#.*\bexit (\d+)\b", cmd.text)
    if own:
        return int(own.group(1))
    return 2 if cmd.output.lstrip().startswith("ftcsim: error:") else 0


def _finish(cmds: list[Command]) -> list[Command]:
    for k, c in enumerate(cmds):
        c.expect = _expect(c, cmds[k + 1] if k + 1 < len(cmds) else None)
    return cmds


def shell_commands(body: str, first: int = 0) -> list[Command]:
    cmds: list[Command] = []
    cont = None
    for at, ln in enumerate(body.split("\n"), first):
        if cont is not None:
            cont.text += "\n" + ln
            if not ln.rstrip().endswith("\\"):
                cont = None
            continue
        s = ln.strip()
        if not s:
            continue
        if s.startswith("#"):
            if cmds and re.match(r"#\s{2,}", s):  # '#   shown output' of the command above
                cmds[-1].output += s.lstrip("#").strip() + "\n"
                cmds[-1].output_lines.append(at)
            continue
        cmds.append(Command(ln))
        if ln.rstrip().endswith("\\"):
            cont = cmds[-1]
    return _finish(cmds)


def console_commands(body: str, first: int = 0) -> list[Command]:
    cmds: list[Command] = []
    cont = False
    for at, ln in enumerate(body.split("\n"), first):
        if cont:
            cmds[-1].text += "\n" + ln
            cont = ln.rstrip().endswith("\\")
        elif ln.startswith("$ "):
            cmds.append(Command(ln[2:]))
            cont = ln.rstrip().endswith("\\")
        elif cmds:
            cmds[-1].output += ln + "\n"
            cmds[-1].output_lines.append(at)
    return _finish(cmds)


_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_NUM = re.compile(rf"(?<![\w.]){_NUMBER}(?![\w.])")
ELLIPSIS = "…"


def _pattern(shown: str) -> tuple[re.Pattern, list[float]]:
    """A shown line as a regex over a printed line: text exact (runs of spaces as one or more), ``…``
    any text, numbers as captured numbers; and the shown numbers in order."""
    parts, numbers, pos = [], [], 0
    line = " ".join(shown.split())
    for m in _NUM.finditer(line):
        parts.append(_text(line[pos:m.start()]))
        parts.append(f"({_NUMBER})")
        numbers.append(float(m.group(0)))
        pos = m.end()
    parts.append(_text(line[pos:]))
    return re.compile("".join(parts)), numbers


def _text(t: str) -> str:
    return ".*?".join(r"\s+".join(re.escape(w) for w in chunk.split(" ")) for chunk in t.split(ELLIPSIS))


def close(a: float, b: float, tol: float) -> bool:
    return a == b or abs(a - b) <= tol * max(abs(a), abs(b)) or abs(a - b) <= 1e-300


def compare(shown: str, printed: str, tol: float = TOLERANCE) -> tuple[list[str], dict]:
    """(problems, fixes): no problem if every non-blank line of ``shown`` matches a line of
    ``printed``, in order (see the module docstring), else one per shown line that does not; fixes
    maps the index of each shown line (in ``shown.split("\\n")``) whose text matched with other numbers
    to that line with the printed numbers (what tests/docs/update.py writes into the page)."""
    printed_lines = [" ".join(ln.split()) for ln in printed.replace("\r", "\n").split("\n")]
    k, problems, fixes = 0, [], {}
    for i, want in enumerate(shown.split("\n")):
        if not want.strip():
            continue
        pat, numbers = _pattern(want)
        nearest = None
        for j in range(k, len(printed_lines)):
            m = pat.fullmatch(printed_lines[j])
            if m is None:
                continue
            got = [float(x) for x in m.groups()]
            if all(close(a, b, tol) for a, b in zip(numbers, got)):
                k = j + 1
                break
            if nearest is None:
                nearest = (j, m)
        else:
            if nearest is not None:
                j, m = nearest
                fixes[i] = _renumber(want, [m.group(g + 1) for g in range(len(numbers))])
                k = j + 1
                problems.append(f"shown {want.strip()!r}: printed with other numbers: {printed_lines[j]!r} "
                                f"(tolerance {tol:g} relative)")
            else:
                problems.append(f"shown {want.strip()!r}: no printed line matches (below the lines matched so far)")
    return problems, fixes


def _renumber(line: str, numbers: list[str]) -> str:
    """``line`` with its numbers replaced, in order, by ``numbers`` (the text kept as written)."""
    it = iter(numbers)
    return _NUM.sub(lambda m: next(it), line)
