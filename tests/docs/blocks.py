"""The runnable blocks of the project's Markdown (README.md, docs/*.md) and what each expects.

Every fenced block carries a language. Blocks in ``sh``/``bash``/``shell`` (one command per line,
``\\`` continues; a following comment line ``#   ...`` is that command's shown output),
``console`` (``$ command`` lines, the other lines its output) and ``python`` are run; other
languages (``toml``, ``text``, ``c``, ...) are data. An HTML comment right before a block
(its last non-blank line before the fence, on one line) changes that:

* ``<!-- not-run: REASON -->``: the block is not run (illustrative, needs the network, takes
  minutes...); the reason is required and shown in the test's skip list;
* ``<!-- file: PATH -->``: the block is the content of the file PATH (relative to the project
  root): it is written there before any block of the document runs.

A command is expected to exit 0, except: a following ``$ echo $?`` prints its status; its shown
output has ``(rc N)``; its own trailing comment says ``exit N``; its shown output starts with
``ftcsim: error:`` (bad input: 2).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

SHELL = ("sh", "bash", "shell")
RUN = (*SHELL, "console", "python")
_FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|~{3,})(?P<info>[^\n`]*)$")
_MARKER = re.compile(r"^<!--\s*(not-run|file):\s*(.*?)\s*-->$")


@dataclass
class Command:
    text: str
    output: str = ""
    expect: int = 0


@dataclass
class Block:
    doc: str
    line: int
    lang: str
    text: str
    skip: str | None = None
    file: str | None = None
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
        b = Block(name, start + 1, m.group("info").strip().split(" ")[0].lower(), body)
        prev = next((ln.strip() for ln in reversed(lines[:start]) if ln.strip()), "")
        mk = _MARKER.match(prev)  # the marker is the last non-blank line before the block
        if mk:
            if mk.group(1) == "not-run":
                b.skip = mk.group(2)
            else:
                b.file = mk.group(2)
        if b.lang in SHELL:
            b.commands = shell_commands(body)
        elif b.lang == "console":
            b.commands = console_commands(body)
        out.append(b)
        i = j + 1
    return out


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


def shell_commands(body: str) -> list[Command]:
    cmds: list[Command] = []
    cont = None
    for ln in body.split("\n"):
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
            continue
        cmds.append(Command(ln))
        if ln.rstrip().endswith("\\"):
            cont = cmds[-1]
    return _finish(cmds)


def console_commands(body: str) -> list[Command]:
    cmds: list[Command] = []
    cont = False
    for ln in body.split("\n"):
        if cont:
            cmds[-1].text += "\n" + ln
            cont = ln.rstrip().endswith("\\")
        elif ln.startswith("$ "):
            cmds.append(Command(ln[2:]))
            cont = ln.rstrip().endswith("\\")
        elif cmds:
            cmds[-1].output += ln + "\n"
    return _finish(cmds)
