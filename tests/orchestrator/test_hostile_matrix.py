"""The hostile matrix (issue 35 item 8): every command of the CLI (enumerated from the parser) and the API
entry points, tried against every class of hostile input, asserting one line on stderr, the right exit
status, nothing written anywhere in the sandbox (beside the target, behind a link, in a folder a link
points to) and a previous result unchanged.

A command is one line of :data:`ROWS`: its arguments with good inputs (placeholders), which of them are
files the input classes replace, and what ``--out`` is. ``test_every_command_has_a_row`` fails when a
command is added to the parser without its row. The classes:

* inputs (:data:`INPUT_CLASSES`): a FIFO, a link to /dev/zero, bytes that are not UTF-8, tables nested
  200 deep, a loop of links, a folder, and for files that extend others a NUL byte and a link out of the
  folder; a run or campaign folder gets them in its metrics.json / manifest.json;
* outputs (:data:`OUTPUT_CLASSES`): /proc, a 255-byte name, a path below a file, a symbolic link, a NUL,
  a read-only folder (not as root: root writes anyway), a full disk (RLIMIT_FSIZE) with the previous
  result kept; names of any bytes and of 241 bytes are written and read back;
* every command: a --log-file that is a FIFO, /dev/full or a folder;
* values (:data:`VALUE_CASES`): NaN, inf, 1e308, runs of no step, limits beyond a year, seeds beyond
  int64, through options, files, grid points and the API (numpy numbers accepted);
* a Ctrl-C at start-up (subprocesses), store folders that are links, hostile strings in pages (Chromium).

In-process calls of ``orchestrator.cli.main.main`` share one import; a subprocess only where a signal
needs one. The defects of issue 35 map to cases in /work/coord/notes/35.md (docs: the closing note).
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import resource
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

import ftcsim
from orchestrator import api
from orchestrator.cli.main import main, parser
from orchestrator.common.errors import InputError

pytestmark = pytest.mark.fmu
ROOT = Path(__file__).resolve().parents[2]
ROOT_USER = os.geteuid() == 0

SCENARIO = '[scenario]\nextends = "li2023_pd"\nname = "tiny"\n\n[timing]\nstop = 0.05\n'
CAMPAIGN = ('[campaign]\nname = "tinyc"\nscenario = "scenario.toml"\nmode = "inprocess"\nruns = 2\nstop = 0.05\n'
            'trajectories = ["ctrl.q_e"]\n\n[dispersions."plant.fault_scale"]\ndistribution = "uniform"\n'
            'low = 0.2\nhigh = 1.5\n')
ARENA = """
[arena]
name = "tinyarena"
draws = 1
seed = 7
mode = "inprocess"
hardware = ["ideal"]
faults = ["none"]
stop = 0.2
trajectory_step = 0.02

[statistics]
bootstrap = 100

[plants.hang2023]
mission = 60.0
band = 0.02
fault_torque = 0.05

[methods.hinf]
label = "002 robust H-infinity"
paper = "002"
claims = ["loe_step"]
claims_source = "002 (3)-(7)"

[[cells]]
method = "hinf"
plant = "hang2023"
scenario = "arena_hinf_on_hang2023.toml"
gains = "redesigned"
"""
GAINS = {"design": "hang2023-tsfdo", "gains": {"L1": [[0.0, -10.0], [0.0, -5.0]]},
         "fmu_parameters": {"Hang2023TSFDO": {"L1[1,1]": 0.0, "L1[1,2]": -10.0, "L1[2,1]": 0.0, "L1[2,2]": -5.0}}}
BLOCK = "import numpy as np\nfrom plant.block import Block\n\nclass Block(Block):\n    pass\n"


# -- the rows: one per command ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Row:
    """A command with good inputs: ``argv`` with placeholders ``{name}`` (files and folders of the world,
    ``{out}`` the output); ``reads``: placeholder -> kind of file the input classes replace; ``out``: what
    ``--out`` is ("folder", or the file suffix); ``rc``: exit statuses other than 2 for some classes (the
    command reports a problem of its input as its result); ``full_disk``: how the command is brought to
    write on a full disk (None: it writes nothing)."""

    argv: tuple
    reads: dict = field(default_factory=dict)
    out: str | None = None
    rc: dict = field(default_factory=dict)
    full_disk: str | None = None


ROWS = {
    "build": Row(("build", "--block", "hostile_block:Block", "--path", "{blocks}", "--out", "{out}"),
                 reads={"blocks": "module"}, out=".fmu", full_disk="patched"),
    "host-env": Row(("host-env",)),
    "validate": Row(("validate", "{fmu}"), reads={"fmu": "zip"}, rc={"non-utf8": 1}),
    "scenarios": Row(("scenarios",)),
    "run": Row(("run", "{scenario}", "--out", "{out}", "--mode", "inprocess", "-q", "--no-plots"),
               reads={"scenario": "toml"}, out="folder", full_disk="real"),
    "design": Row(("design", "hang2023-tsfdo", "--out", "{out}"), out=".json", full_disk="patched"),
    "verify": Row(("verify", "hang2023-tsfdo", "--gains", "{gains}"), reads={"gains": "json"}),
    "report": Row(("report", "{run}", "--out", "{out}"), reads={"run": "run folder"}, out="folder",
                  full_disk="patched"),
    "export-ssp": Row(("export-ssp", "{scenario}", "--out", "{out}", "--quiet"), reads={"scenario": "toml"},
                      out=".ssp", full_disk="real"),
    "campaign-report": Row(("campaign-report", "{campaign_dir}", "--out", "{out}"),
                           reads={"campaign_dir": "campaign folder"}, out="folder", full_disk="patched"),
    "campaign": Row(("campaign", "{campaign}", "--out", "{out}", "--workers", "0", "-q"),
                    reads={"campaign": "toml", "scheduler": "json"}, out="folder", full_disk="real"),
    "compare": Row(("compare", "{fmu}", "--campaign", "{campaign}", "--out", "{out}", "--workers", "0", "--runs", "1",
                    "-q"), reads={"fmu": "zip", "campaign": "toml", "scheduler": "json"}, out="folder",
                   full_disk="real"),
    "arena": Row(("arena", "{arena}", "--out", "{out}", "--workers", "0", "--quiet"), reads={"arena": "toml"},
                 out="folder", full_disk="real"),
    "params": Row(("params", "{scenario}", "--mode", "inprocess"), reads={"scenario": "toml"}),
    "completion": Row(("completion", "bash")),  # reads no file, writes nothing (the script on stdout)
    # the draws take minutes (200 runs of 60 s): no full disk here; the calibration file goes through OutputFile
    "schema": Row(("schema", "scenario", "--out", "{out}"), out=".json", full_disk="real"),  # issue 36: writes a file
    "fdir": Row(("fdir", "calibrate", "{fdir_campaign}", "--detector", "det", "--rate", "1", "--draws", "{draws}",
                 "--out", "{out}"), reads={"fdir_campaign": "toml"}, out=".json"),
}


def _subcommands() -> set:
    import argparse

    sub = next(a for a in parser()._actions if isinstance(a, argparse._SubParsersAction))
    return set(sub.choices)


def test_every_command_has_a_row():
    """A command added to the parser without its row in the matrix fails here."""
    assert _subcommands() == set(ROWS), (f"commands without a row: {sorted(_subcommands() - set(ROWS))}; rows of no "
                                         f"command: {sorted(set(ROWS) - _subcommands())}")


# -- the world: good inputs and previous results, made once ---------------------------------------------------------
@pytest.fixture(scope="module")
def world(tmp_path_factory, fmu_dir):
    root = tmp_path_factory.mktemp("world")
    (root / "scenario.toml").write_text(SCENARIO)
    (root / "campaign.toml").write_text(CAMPAIGN)
    arena = root / "arena"
    arena.mkdir()
    (arena / "arena.toml").write_text(ARENA)
    shutil.copy(ROOT / "arena" / "scenarios" / "arena_hinf_on_hang2023.toml", arena)
    (root / "gains.json").write_text(json.dumps(GAINS))
    (root / "blocks").mkdir()
    (root / "blocks" / "hostile_block.py").write_text(BLOCK)
    (root / "scheduler.json").write_text(json.dumps({"address": "tcp://127.0.0.1:9"}))
    assert main(["run", str(root / "scenario.toml"), "--out", str(root / "run"), "--mode", "inprocess", "-q",
                 "--no-plots"]) == 0
    assert main(["campaign", str(root / "campaign.toml"), "--out", str(root / "campaign_dir"), "--workers", "0",
                 "-q"]) == 0
    return {"root": root, "scenario": root / "scenario.toml", "campaign": root / "campaign.toml",
            "arena": arena / "arena.toml", "gains": root / "gains.json", "blocks": root / "blocks",
            "scheduler": root / "scheduler.json", "fmu": fmu_dir / "PDController.fmu", "run": root / "run",
            "fdir_campaign": ROOT / "campaigns" / "zhang2019_fdir_calibration.toml",
            "campaign_dir": root / "campaign_dir"}


def _place(world, sandbox: Path, name: str) -> Path:
    """A private copy, in the sandbox, of the world's input ``name`` (files next to what they name)."""
    src = world[name]
    if name == "arena":
        shutil.copytree(src.parent, sandbox / "arena")
        return sandbox / "arena" / src.name
    if name == "campaign":
        shutil.copy(world["scenario"], sandbox / "scenario.toml")
    if name == "blocks":
        shutil.copytree(src, sandbox / "blocks")
        return sandbox / "blocks"
    if src.is_dir():
        shutil.copytree(src, sandbox / name, symlinks=True)
        return sandbox / name
    dst = sandbox / src.name
    shutil.copy(src, dst)
    return dst


def _argv(row: Row, world, sandbox: Path, out=None, replace=None) -> list:
    """The row's arguments in ``sandbox``: inputs copied there (or replaced: {placeholder: path}), ``out``."""
    replace = replace or {}
    argv = []
    skip = False
    for a in row.argv:
        if skip:
            skip = False
            continue
        if "scheduler" in replace and a == "--workers":  # a scheduler file instead of local workers
            skip = True
            argv += ["--scheduler-file", str(replace["scheduler"])]
            continue
        m = re.fullmatch(r"\{(\w+)\}", a)
        if m is None:
            argv.append(a)
        elif m[1] == "out":
            argv.append(str(out if out is not None else sandbox / ("out" + ("" if row.out == "folder" else row.out))))
        elif m[1] == "draws":  # a second output (a campaign folder): always a fresh one in the sandbox
            argv.append(str(sandbox / "draws"))
        elif m[1] in replace:
            argv.append(str(replace[m[1]]))
        else:
            argv.append(str(_place(world, sandbox, m[1])))
    return argv


def snapshot(root: Path) -> dict:
    """Every entry below ``root`` (links not followed, FIFOs not opened): path -> kind and content digest."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root, followlinks=False):
        for name in dirnames + filenames:
            p = Path(dirpath, name)
            st = os.lstat(p)
            if stat.S_ISLNK(st.st_mode):
                out[str(p.relative_to(root))] = "link->" + os.readlink(p)
            elif stat.S_ISREG(st.st_mode):
                out[str(p.relative_to(root))] = hashlib.sha256(p.read_bytes()).hexdigest()
            elif stat.S_ISDIR(st.st_mode):
                out[str(p.relative_to(root))] = "dir"
            else:
                out[str(p.relative_to(root))] = "special"
    return out


def cli(argv, capsys) -> tuple[int, list, str]:
    rc = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return rc, cap.err.strip().splitlines(), cap.out


def refused(argv, capsys, sandbox, words=(), rc=2) -> str:
    """Exit ``rc``, one line on stderr (``ftcsim: error: ...`` holding ``words``), nothing in the sandbox changed."""
    before = snapshot(sandbox)
    got, err, out = cli(argv, capsys)
    assert got == rc, (argv, err, out[-300:])
    if rc == 2:
        assert len(err) == 1 and err[0].startswith("ftcsim: error: "), (argv, err)
        assert "Traceback" not in err[0] and "internal error" not in err[0]
        for w in words:
            assert w in err[0], (w, err[0])
    assert snapshot(sandbox) == before, f"{argv} wrote: {set(snapshot(sandbox).items()) ^ set(before.items())}"
    return err[0] if err else out


# -- input classes --------------------------------------------------------------------------------------------------
def _deep(kind: str) -> bytes:
    if kind == "json":
        return ('{"a": ' * 200 + "1" + "}" * 200).encode()
    return ("a = " + "[" * 200 + "]" * 200 + "\n").encode()


INPUT_CLASSES = {  # class -> how to make the hostile file at path p (kind: what the good file is)
    "fifo": lambda p, kind: os.mkfifo(p),
    "dev-zero": lambda p, kind: os.symlink("/dev/zero", p),
    "non-utf8": lambda p, kind: p.write_bytes(b"\xff\xfe not text \x80\x81"),
    "deep": lambda p, kind: p.write_bytes(_deep(kind)),
    "link-loop": lambda p, kind: (os.symlink(p.name + ".b", p), os.symlink(p.name, str(p) + ".b")),
    "directory": lambda p, kind: p.mkdir(),
}
NOT_APPLICABLE = {("deep", "zip"), ("deep", "module")}  # no nesting in a zip archive or a Python module


def input_cases():
    for command, row in ROWS.items():
        for placeholder, kind in row.reads.items():
            for klass in INPUT_CLASSES:
                if (klass, kind) not in NOT_APPLICABLE:
                    yield pytest.param(command, placeholder, klass, id=f"{command}-{placeholder}-{klass}")


@pytest.mark.parametrize("command,placeholder,klass", list(input_cases()))
def test_hostile_input(command, placeholder, klass, world, tmp_path, capsys, monkeypatch):
    """Every file a command reads, replaced by every class of hostile file: one line naming it, exit 2 (or the
    command's own verdict), nothing written, and never a hang (a FIFO or /dev/zero is refused unopened)."""
    monkeypatch.chdir(tmp_path)
    row = ROWS[command]
    kind = row.reads[placeholder]
    if kind in ("run folder", "campaign folder"):
        folder = _place(world, tmp_path, placeholder)
        member = folder / ("metrics.json" if kind == "run folder" else "manifest.json")
        member.unlink()
        INPUT_CLASSES[klass](member, "json")
        replace = {placeholder: folder}
        name = member.name
    elif kind == "module":
        folder = _place(world, tmp_path, placeholder)
        (folder / "hostile_block.py").unlink()
        INPUT_CLASSES[klass](folder / "hostile_block.py", kind)
        replace = {placeholder: folder}
        name = "hostile_block"
    else:
        suffix = {"toml": ".toml", "json": ".json", "zip": ".fmu"}[kind]
        p = tmp_path / f"hostile{suffix}"
        INPUT_CLASSES[klass](p, kind)
        replace = {placeholder: p}
        name = p.name
    argv = _argv(row, world, tmp_path, replace=replace)
    t0 = time.monotonic()
    text = refused(argv, capsys, tmp_path, rc=row.rc.get(klass, 2))
    assert name in text or (kind == "run folder" and "results" in text), text
    assert time.monotonic() - t0 < 30


EXTENDS_CLASSES = {  # the file an ``extends`` names: a NUL byte, a link out of the folder, a loop of links
    "nul": lambda folder: 'extends = "base\\u0000.toml"',
    "link-out": lambda folder: (os.symlink(folder.parent / "outside.toml", folder / "base.toml"),
                                'extends = "base.toml"')[1],
    "link-loop": lambda folder: (os.symlink("base.toml.b", folder / "base.toml"),
                                 os.symlink("base.toml", folder / "base.toml.b"), 'extends = "base.toml"')[2],
}


@pytest.mark.parametrize("klass", sorted(EXTENDS_CLASSES))
@pytest.mark.parametrize("command", ["run", "params", "export-ssp", "campaign", "compare"])
def test_hostile_extends(command, klass, world, tmp_path, capsys, monkeypatch):
    """``extends`` of a scenario (run, params, export-ssp) or of a campaign (campaign, compare): one line."""
    monkeypatch.chdir(tmp_path)
    folder = tmp_path / "in"
    folder.mkdir()
    (tmp_path / "outside.toml").write_text(SCENARIO)
    line = EXTENDS_CLASSES[klass](folder)
    if command in ("campaign", "compare"):
        shutil.copy(world["scenario"], folder / "scenario.toml")
        p = folder / "campaign.toml"
        p.write_text(CAMPAIGN.replace('[campaign]\n', f"[campaign]\n{line}\n"))
        key = "campaign.extends"
    else:
        p = folder / "scenario.toml"
        p.write_text(SCENARIO.replace('extends = "li2023_pd"', line))
        key = "scenario.extends"
    argv = _argv(ROWS[command], world, tmp_path, replace={"scenario": p, "campaign": p})
    refused(argv, capsys, tmp_path, words=(key,))


# -- output classes -------------------------------------------------------------------------------------------------
def _name(row, n):
    suffix = "" if row.out == "folder" else row.out
    return "x" * (n - len(suffix)) + suffix


OUTPUT_CLASSES = {  # class -> (the --out path, given the sandbox and the row; what the message names)
    "proc": lambda s, row: Path("/proc/ftcsim-matrix") / _name(row, 8),
    "name-255": lambda s, row: s / _name(row, 255),
    "below-a-file": lambda s, row: (s.joinpath("afile").write_text("x"), s / "afile" / _name(row, 8))[1],
    "symlink": lambda s, row: (s.joinpath("elsewhere").mkdir(), os.symlink(s / "elsewhere", s / _name(row, 8)),
                               s / _name(row, 8))[2],
    "nul": lambda s, row: s / ("a\x00" + _name(row, 8)),
    "read-only": lambda s, row: (s.joinpath("ro").mkdir(), os.chmod(s / "ro", 0o555), s / "ro" / _name(row, 8))[2],
}


def output_cases():
    for command, row in ROWS.items():
        if row.out is None:
            continue
        for klass in OUTPUT_CLASSES:
            yield pytest.param(command, klass, id=f"{command}-{klass}")


@pytest.mark.parametrize("command,klass", list(output_cases()))
def test_hostile_output(command, klass, world, tmp_path, capsys, monkeypatch):
    """Every command that writes, given every class of output path it must not (or cannot) write: one line
    naming --out, exit 2, before any work; nothing written (not beside it, not behind the link)."""
    if klass == "read-only" and ROOT_USER:
        pytest.skip("root writes into a read-only folder: the refusal is the kernel's, not testable as root")
    monkeypatch.chdir(tmp_path)
    row = ROWS[command]
    out = OUTPUT_CLASSES[klass](tmp_path, row)
    argv = _argv(row, world, tmp_path, out=out)
    try:
        refused(argv, capsys, tmp_path, words=("--out",))
    finally:
        if klass == "read-only":
            os.chmod(tmp_path / "ro", 0o755)


@contextlib.contextmanager
def file_size_limit(limit: int):
    """A full disk for this process: files cannot grow beyond ``limit`` bytes (RLIMIT_FSIZE, SIGXFSZ
    ignored so that write() fails with EFBIG); restored afterwards."""
    old_handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    old = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, old[1]))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, old)
        signal.signal(signal.SIGXFSZ, old_handler)


def _big_writer(staging):
    """What a report, design or build writes, quickly: a file larger than the limit (the commands' own
    work is covered elsewhere; here their publishing of it)."""
    Path(staging, "big.bin").write_bytes(b"x" * 100_000)
    return {"runs": 1, "plots": [], "figures": []}


def _patch_heavy_work(command, monkeypatch):
    """Replace the command's minutes of work (LMIs, plots, an FMU build) by :func:`_big_writer`."""
    if command == "report":
        monkeypatch.setattr("orchestrator.cli.report.make_reports", lambda runs, staging: {"x": _big_writer(staging)})
    elif command == "campaign-report":
        monkeypatch.setattr("orchestrator.cli.report.make_report", lambda folder, staging: _big_writer(staging))
    elif command == "design":
        from types import SimpleNamespace

        monkeypatch.setitem(sys.modules, "lmi", SimpleNamespace(LMIError=RuntimeError))  # cvxpy not imported for this
        fake = SimpleNamespace(run_design=lambda **kw: ({"design": "hang2023-tsfdo", "blob": "x" * 100_000}, "fake"))
        monkeypatch.setattr("orchestrator.cli.design.resolve", lambda module: fake)
    elif command == "build":
        from fmus.build import BlockBuild

        def build_block(ref, out, **kw):
            path = Path(out) if str(out).endswith(".fmu") else Path(out) / "Block.fmu"
            path.write_bytes(b"x" * 100_000)
            return BlockBuild(path=path, model="Block", embedded=[], warnings=[])

        monkeypatch.setattr("orchestrator.cli.main.build_block", build_block)


def full_disk_cases():
    for command, row in ROWS.items():
        if row.full_disk:
            yield pytest.param(command, id=command)


@pytest.mark.parametrize("command", list(full_disk_cases()))
def test_full_disk_keeps_the_previous_result(command, world, tmp_path, capsys, monkeypatch):
    """A disk that fills while a command publishes: one line naming --out, exit 2, nothing published, the
    previous result (written by the command itself) byte for byte as it was, no staging or lock left."""
    monkeypatch.chdir(tmp_path)
    row = ROWS[command]
    if row.full_disk == "patched":
        _patch_heavy_work(command, monkeypatch)
    argv = _argv(row, world, tmp_path)
    out = tmp_path / ("out" + ("" if row.out == "folder" else row.out))
    if command in ("run", "campaign", "export-ssp"):  # a previous result the command wrote itself
        assert cli(argv, capsys)[0] == 0
        argv = argv + ["--overwrite"]
    before = snapshot(tmp_path)
    with file_size_limit(1024):
        rc, err, _ = cli(argv, capsys)
    assert rc == 2 and len(err) == 1 and ("--out" in err[0] or str(out) in err[0] or "TMPDIR" in err[0]
                                          or tempfile.gettempdir() in err[0]), err
    assert "Traceback" not in err[0] and "internal error" not in err[0], err
    after = snapshot(tmp_path)
    assert after == before, f"changed: {set(after.items()) ^ set(before.items())}"


# -- every command: the log file -----------------------------------------------------------------------------------
LOG_CLASSES = {"fifo": lambda p: os.mkfifo(p), "dev-full": lambda p: os.symlink("/dev/full", p),
               "directory": lambda p: p.mkdir()}


@pytest.mark.parametrize("klass", sorted(LOG_CLASSES))
@pytest.mark.parametrize("command", sorted(ROWS))
def test_hostile_log_file(command, klass, world, tmp_path, capsys, monkeypatch):
    """``--log-file`` (an option of every command) that is a FIFO, /dev/full or a folder: one line, exit 2,
    before the command does anything (a FIFO never waited on)."""
    monkeypatch.chdir(tmp_path)
    log = tmp_path / "log"
    LOG_CLASSES[klass](log)
    refused(_argv(ROWS[command], world, tmp_path) + ["--log-file", str(log)], capsys, tmp_path, words=("--log-file",))


# -- names of any bytes and length: written, then read back by every command that reads them ----------------------
def test_outputs_are_read_back_whatever_their_names(world, tmp_path, capsys, monkeypatch):
    """A run and a campaign written under a name that is not UTF-8 (with an escape sequence in it) and under
    the longest name allowed are read back by ftcsim.open, report (the first name: its plots take seconds),
    campaign (resumed) and ftcsim.campaign; never an escape sequence printed to the terminal."""
    monkeypatch.chdir(tmp_path)
    names = [os.fsdecode(b"r\xff\xfe-\x1b[31m"), "L" * (255 - 14)]  # not UTF-8 (and an escape); the longest allowed
    for k, name in enumerate(names):
        run = tmp_path / name
        assert cli(["run", world["scenario"], "--out", run, "--mode", "inprocess", "-q", "--no-plots"], capsys)[0] == 0
        assert len(ftcsim.open(run).df) == 6  # 0.05 s at 10 ms
        camp = tmp_path / (name[:-1] + "c")
        assert cli(["campaign", world["campaign"], "--out", camp, "--workers", "0", "-q"], capsys)[0] == 0
        assert len(ftcsim.campaign(world["campaign"], camp, workers=0)) == 2  # resumed: all stored
        if k == 0:  # campaign-report reads such a name in hostile_pages; the paper's figures here are not the point
            monkeypatch.setattr("orchestrator.cli.report.make_reports", lambda runs, staging: {"li2023": {}})
            rc, err, out = cli(["report", run, "--out", tmp_path / "rep"], capsys)
            assert rc == 0 and "\x1b" not in out, err
    rc, err, _ = cli(["run", world["scenario"], "--out", tmp_path / ("L" * (255 - 13)), "-q"], capsys)
    assert rc == 2 and "at most 241" in err[0]  # one byte more: no room for the lock beside it


# -- values: one numeric gate for every path -----------------------------------------------------------------------
def _file(tmp_path, text, name="case.toml"):
    p = tmp_path / name
    p.write_text(text)
    if "scenario.toml" in text:  # a campaign names the scenario beside it
        (tmp_path / "scenario.toml").write_text(SCENARIO)
    return p


VALUE_CASES = {  # id -> (argv builder (tmp_path, world), source, key): each refused with the key named
    "run --stop NaN": (lambda t, w: ["run", w["scenario"], "--stop", "nan"], "command line", "--stop"),
    "run --stop 1e-12 (no step)": (lambda t, w: ["run", w["scenario"], "--stop", "1e-12"], "command line", "--stop"),
    "run --stop 1e308": (lambda t, w: ["run", w["scenario"], "--stop", "1e308"], "command line", "--stop"),
    "run --step inf": (lambda t, w: ["run", w["scenario"], "--step", "inf"], "command line", "--step"),
    "run --step 1e-308": (lambda t, w: ["run", w["scenario"], "--step", "1e-308"], "command line", "--step"),
    "run --time-limit 1e300": (lambda t, w: ["run", w["scenario"], "--time-limit", "1e300"], "command line",
                               "--time-limit"),
    "run --record-step 1e308": (lambda t, w: ["run", w["scenario"], "--record-step", "1e308"], "command line",
                                "--record-step"),
    "run --set NaN": (lambda t, w: ["run", w["scenario"], "--set", "ctrl.k_p=nan"], "command line", "--set ctrl.k_p"),
    "run --set two statements": (lambda t, w: ["run", w["scenario"], "--set", "ctrl.k_p=1\nz = 2"], "command line",
                                 "--set ctrl.k_p"),
    "run --set deep": (lambda t, w: ["run", w["scenario"], "--set", "ctrl.k_p=" + "[" * 500 + "]" * 500],
                       "command line", "--set ctrl.k_p"),
    "run --set a block's refusal": (lambda t, w: ["run", ROOT / "arena/scenarios/arena_aismc_on_xu2024.toml",
                                                  "--set", "faults.fault_class=8", "--set", "faults.r0=7"],
                                    "command line", "--set faults.r0"),
    "params --set inf": (lambda t, w: ["params", w["scenario"], "--set", "ctrl.k_p=inf"], "command line",
                         "--set ctrl.k_p"),
    "scenario file stop NaN": (lambda t, w: ["run", _file(t, SCENARIO.replace("0.05", "nan"))], None, "timing.stop"),
    "scenario file time_limit 1e300": (lambda t, w: ["run", _file(t, SCENARIO + "time_limit = 1e300\n")], None,
                                       "timing.time_limit"),
    "export-ssp file stop 1e-12": (lambda t, w: ["export-ssp", _file(t, SCENARIO.replace("0.05", "1e-12")), "--out",
                                                 t / "x.ssp"], None, "timing.stop"),
    "campaign --stop 1e-12": (lambda t, w: ["campaign", w["campaign"], "--stop", "1e-12", "--workers", "0"],
                              "command line", "--stop"),
    "campaign --time-limit 1e308": (lambda t, w: ["campaign", w["campaign"], "--time-limit", "1e308"], "command line",
                                    "--time-limit"),
    "campaign --connect-timeout NaN": (lambda t, w: ["campaign", w["campaign"], "--connect-timeout", "nan"],
                                       "command line", "--connect-timeout"),
    "campaign --workers -1": (lambda t, w: ["campaign", w["campaign"], "--workers", "-1"], "command line", "--workers"),
    "campaign file stop 1e-12": (lambda t, w: ["campaign", _file(t, CAMPAIGN.replace("0.05", "1e-12")), "--workers",
                                               "0"], None, "campaign.stop"),
    "campaign file seed 2**63": (lambda t, w: ["campaign", _file(t, CAMPAIGN.replace("runs = 2", "runs = 2\nseed = "
                                                                                     "9223372036854775808"))],
                                 None, "campaign.seed"),
    "campaign grid point 1e308 inertia": (lambda t, w: ["campaign", _file(t, CAMPAIGN + '\n[grid]\n"plant.J[1,1]" = '
                                                                          '[350.0, 1e308]\n'), "--workers", "0"],
                                          None, "grid (point 1"),
    "campaign grid point NaN": (lambda t, w: ["campaign", _file(t, CAMPAIGN + '\n[grid]\n"ctrl.k_p" = [nan]\n'),
                                              "--workers", "0"], None, "grid.ctrl.k_p"),
    "compare --stop 1e-12": (lambda t, w: ["compare", w["fmu"], "--campaign", w["campaign"], "--stop", "1e-12",
                                           "--workers", "0", "--runs", "1"], "command line", "--stop"),
    "arena stop 1e300": (lambda t, w: ["arena", _arena(t, "stop = 0.2", "stop = 1e300"), "--workers", "0"], None,
                         "arena.stop"),
    "arena seed 2**63": (lambda t, w: ["arena", _arena(t, "seed = 7", "seed = 9223372036854775808"), "--workers", "0"],
                         None, "arena.seed"),
    "arena malformed cell": (lambda t, w: ["arena", _arena(t, 'method = "hinf"', 'method = ["hinf"]'), "--workers",
                                           "0"], None, "cells[0].method"),
    "design option NaN": (lambda t, w: ["design", "hang2023-tsfdo", "--out", t / "d.json", "--alpha", "nan"],
                          "command line", "--alpha"),
    "build --probe-step inf": (lambda t, w: ["build", "--block", "hostile_block:Block", "--path", w["blocks"],
                                             "--probe-step", "inf"], "command line", "--probe-step"),
    "build --block empty": (lambda t, w: ["build", "--block", "", "--out", t / "x.fmu"], "command line", "--block"),
    "params --set two statements": (lambda t, w: ["params", w["scenario"], "--set", "ctrl.k_p=1\nz = 2"],
                                    "command line", "--set ctrl.k_p"),
    "build: control characters in the block's description": (
        lambda t, w: ["build", "--block", "ctl_block:Ctl", "--path", _block(t, CTL_BLOCK), "--out", t / "x.fmu"],
        "command line", "--block"),
    "verify: applied gains differ from the verified ones": (
        lambda t, w: ["verify", "hang2023-tsfdo", "--gains", _gains(t, {"L1[2,2]": -500.0})], None,
        "fmu_parameters.Hang2023TSFDO.L1"),
    "run: a misspelt model in a gains file": (
        lambda t, w: ["run", w["scenario"], "--gains", _gains(t, model="PDControler")], None,
        "fmu_parameters.PDControler"),
    "campaign: a misspelt model in a variant's gains file": (
        lambda t, w: ["campaign", _file(t, CAMPAIGN.replace("runs = 2", f'runs = 2\ngains = ["{_gains(t, model="PDControler")}"]')),
                      "--workers", "0"], None, "PDControler"),
    "run: an FMI 1.0 FMU": (lambda t, w: (_fmi1(t, w), ["run", _file(t, SCENARIO + '\n[instances.ctrl]\nfmu = "v1.fmu"\n'),
                                                         "--out", t / "o"])[1], None, "FMI 1.0"),
    "compare: an FMI 1.0 FMU": (lambda t, w: ["compare", _fmi1(t, w), "--campaign", w["campaign"], "--workers", "0",
                                              "--runs", "1"], None, "FMI 1.0"),
}
CTL_BLOCK = """import numpy as np
from plant.block import Block, scalar


class Ctl(Block):
    model_name = "CtlChars"
    description = "a description with \\x01 and an escape \\x1b[31m"

    def __init__(self):
        super().__init__(scalar("u", 0.0, "1", "in"), scalar("y", 0.0, "1", "out"), scalar("k", 1.0, "1", "gain"),
                         {"y": ("u",)})

    def initialize(self, t0):
        pass

    def default_inputs(self):
        return np.zeros(1)

    def outputs_at(self, t, u):
        return np.array([self.p("k") * u[0]])

    def advance(self, t, h, u):
        pass

    def get_state(self):
        return []

    def set_state(self, state):
        pass
"""


def _block(tmp_path, text):
    folder = tmp_path / "blocks"
    folder.mkdir(exist_ok=True)
    (folder / "ctl_block.py").write_text(text)
    return folder


def _gains(tmp_path, change=None, model="Hang2023TSFDO"):
    """A design file of hang2023-tsfdo: fmu_parameters changed by ``change`` (verify must see it), or
    filed under another ``model`` name (a run must refuse it, not ignore it)."""
    doc = json.loads(json.dumps(GAINS))
    doc["fmu_parameters"] = {model: {**doc["fmu_parameters"]["Hang2023TSFDO"], **(change or {})}}
    p = tmp_path / "design.json"
    p.write_text(json.dumps(doc))
    return p


def _fmi1(tmp_path, world):
    """PDController.fmu rewritten as fmiVersion 1.0 (what an old tool exports), beside the case."""
    import zipfile

    target = tmp_path / "v1.fmu"
    with zipfile.ZipFile(world["fmu"]) as zin, zipfile.ZipFile(target, "w") as zout:
        for info in zin.infolist():
            data = zin.read(info.filename)
            if info.filename == "modelDescription.xml":
                data = data.replace(b'fmiVersion="2.0"', b'fmiVersion="1.0"')
            zout.writestr(info, data)
    return target


def _arena(tmp_path, old, new):
    shutil.copy(ROOT / "arena" / "scenarios" / "arena_hinf_on_hang2023.toml", tmp_path)
    return _file(tmp_path, ARENA.replace(old, new, 1), "arena.toml")


@pytest.mark.parametrize("case", sorted(VALUE_CASES))
def test_hostile_values(case, world, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    build, source, key = VALUE_CASES[case]
    argv = [str(a) for a in build(tmp_path, world)]
    if argv[0] in ("run", "campaign", "compare", "arena") and "--out" not in argv:
        argv += ["--out", str(tmp_path / "out")]
    line = refused(argv, capsys, tmp_path, words=(key,))
    if source is not None:
        assert line.startswith(f"ftcsim: error: {source}: {key}"), line


API_CASES = {  # id -> (call, what the one InputError names)
    "run stop NaN": (lambda w: ftcsim.run(w["scenario"], mode="inprocess", stop=np.nan), "stop"),
    "run stop of no step (numpy)": (lambda w: ftcsim.run(w["scenario"], mode="inprocess", stop=np.float64(1e-12)),
                                    "stop"),
    "run parameter inf (numpy)": (lambda w: ftcsim.run(w["scenario"], mode="inprocess",
                                                       parameters={"ctrl.k_p": np.float32(np.inf)}), "ctrl"),
    "run parameters not a dict": (lambda w: ftcsim.run(w["scenario"], mode="inprocess", parameters=[1, 2]),
                                  "parameters"),
    "run gains not files": (lambda w: ftcsim.run(w["scenario"], mode="inprocess", gains=5), "gains"),
    "run fmu_dir not a path": (lambda w: ftcsim.run(w["scenario"], fmu_dir=3), "fmu_dir"),
    "run time_limit 1e300": (lambda w: ftcsim.run(w["scenario"], mode="inprocess", time_limit=1e300), "time_limit"),
    "run record_step 1e308": (lambda w: ftcsim.run(w["scenario"], mode="inprocess", record_step=np.float64(1e308)),
                              "record_step"),
    "load step 0 (numpy)": (lambda w: ftcsim.load(w["scenario"], mode="inprocess", step=np.float32(0.0)), "step"),
    "open not a path": (lambda w: ftcsim.open(5), "folder"),
    "campaign workers -1": (lambda w: ftcsim.campaign(w["campaign"], "unused", workers=-1), "workers"),
    "campaign stop of no step": (lambda w: ftcsim.campaign(w["campaign"], "unused", workers=0, stop=1e-12), "stop"),
    "campaign connect_timeout NaN": (lambda w: ftcsim.campaign(w["campaign"], "unused", scheduler="tcp://127.0.0.1:9",
                                                               connect_timeout=float("nan")), "connect_timeout"),
    "plan_campaign of a FIFO": (lambda w: api.plan_campaign(_fifo(w)), "FIFO"),
}


def _fifo(world):
    p = world["root"] / "fifo.toml"
    if not p.exists():
        os.mkfifo(p)
    return p


@pytest.mark.parametrize("case", sorted(API_CASES))
def test_hostile_api_arguments(case, world, tmp_path, monkeypatch):
    """The API: wrong types and values are one InputError naming the argument (never TypeError or a hang);
    numpy numbers are numbers."""
    monkeypatch.chdir(tmp_path)
    call, key = API_CASES[case]
    with pytest.raises(InputError) as e:
        call(world)
    assert key in str(e.value), str(e.value)
    assert not any(tmp_path.iterdir())


def test_numpy_numbers_are_numbers(world):
    r = ftcsim.run(world["scenario"], mode="inprocess", stop=np.int64(0) + np.float64(0.03), step=np.float64(0.01),
                   parameters={"ctrl.k_p": np.int64(20)}, time_limit=np.int32(60), record_step=np.float64(0.01))
    assert r.complete and len(r.df) == 4


# -- ftcsim.open checks the results against metrics.json ------------------------------------------------------------
def _other_run(world, tmp_path):
    other = tmp_path / "other"
    assert main(["run", str(world["scenario"]), "--out", str(other), "--mode", "inprocess", "-q", "--no-plots",
                 "--stop", "0.03"]) == 0
    return other


OPEN_CASES = {
    "another run's results": (lambda f, w, t: shutil.copy(_other_run(w, t) / "results.parquet", f), "results.parquet"),
    "complete is a string": (lambda f, w, t: _edit_info(f, complete="false"), "info.complete"),
    "t_end not where the rows end": (lambda f, w, t: _edit_info(f, t_end=99.0, results_sha256=None), "time"),
    "metrics.json nested deep": (lambda f, w, t: (f / "metrics.json").write_text(_deep("json").decode()),
                                 "metrics.json"),
}


def _edit_info(folder, **changes):
    doc = json.loads((folder / "metrics.json").read_text())
    for k, v in changes.items():
        if v is None:
            doc["info"].pop(k, None)
        else:
            doc["info"][k] = v
    (folder / "metrics.json").write_text(json.dumps(doc))


@pytest.mark.parametrize("case", sorted(OPEN_CASES))
def test_open_and_report_check_results_against_metrics(case, world, tmp_path, capsys):
    damage, where = OPEN_CASES[case]
    folder = _place(world, tmp_path, "run")
    damage(folder, world, tmp_path)
    with pytest.raises(InputError, match=re.escape(where)):
        ftcsim.open(folder)
    refused(["report", folder, "--out", tmp_path / "rep"], capsys, tmp_path, words=(where,))


# -- store folders that are links, and runs/ replaced by a file ----------------------------------------------------
STORE_CASES = {
    "runs/ a link to another campaign": lambda c, t: (shutil.move(c / "runs", t / "elsewhere"),
                                                      os.symlink(t / "elsewhere", c / "runs")),
    "trajectories/ a link": lambda c, t: (shutil.move(c / "trajectories", t / "elsewhere"),
                                          os.symlink(t / "elsewhere", c / "trajectories")),
    "runs/ replaced by a file": lambda c, t: (shutil.rmtree(c / "runs"), (c / "runs").write_text("x")),
}


@pytest.mark.parametrize("case", sorted(STORE_CASES))
def test_store_folders_are_never_written_through(case, world, tmp_path, capsys):
    """A resume never writes through a link inside its own folder (into another campaign), and a runs/ that
    is not a folder is refused before summary.parquet is rewritten with 0 rows."""
    camp = _place(world, tmp_path, "campaign_dir")
    first = sorted((camp / "runs").iterdir())[0]
    first.unlink()  # one run to compute again on resume
    STORE_CASES[case](camp, tmp_path)
    refused(["campaign", world["campaign"], "--out", camp, "--workers", "0", "-q"], capsys, tmp_path,
            words=("runs" if "runs" in case else "trajectories",))


def test_campaign_report_into_a_linked_report_folder(world, tmp_path, capsys):
    camp = _place(world, tmp_path, "campaign_dir")
    (tmp_path / "elsewhere").mkdir()
    os.symlink(tmp_path / "elsewhere", camp / "report")
    refused(["campaign-report", camp], capsys, tmp_path, words=("--out", "symbolic link"))


# -- a resume verifies what it resumes ------------------------------------------------------------------------------
def test_a_campaign_resumed_after_its_base_scenario_changed_is_refused(world, tmp_path, capsys):
    """The step policy and the timing decide a run: a resume after either changed refuses the stored runs
    (computed from other inputs) instead of mixing them in; the folder is untouched."""
    camp_file = _place(world, tmp_path, "campaign")
    out = tmp_path / "c"
    assert cli(["campaign", camp_file, "--out", out, "--workers", "0", "-q"], capsys)[0] == 0
    (tmp_path / "scenario.toml").write_text(SCENARIO + 'exchange = "jacobi"\n')
    refused(["campaign", camp_file, "--out", out, "--workers", "0", "-q"], capsys, tmp_path,
            words=("computed from other inputs",))


# -- hostile strings in the pages ----------------------------------------------------------------------------------
HOSTILE = "javascript:void(document.title='PWNED')%2F%2F"


@pytest.fixture(scope="module")
def hostile_pages(world, tmp_path_factory):
    """The results index over a run folder named like a javascript: URL, and the campaign report of a
    campaign folder whose name is not UTF-8 (and holds an escape), whose description holds an absolute
    image path, a javascript: link, raw HTML and a link out, and whose summary gives a metric a unit
    mathtext cannot parse: (the pages, campaign-report's exit status and stdout)."""
    from orchestrator.results.report import write_index

    tmp_path = tmp_path_factory.mktemp("pages")
    results = tmp_path / "results"
    results.mkdir()
    secret = tmp_path / "secret.png"
    secret.write_bytes((ROOT / "README.md").read_bytes()[:100])
    shutil.copytree(world["run"], results / HOSTILE)
    camp = results / os.fsdecode(b"c\xff-\x1b[2J")  # not UTF-8, an escape: campaign-report reads it back
    shutil.copytree(world["campaign_dir"], camp)  # the world's campaign, its description (as the report reads it)
    manifest = json.loads((camp / "manifest.json").read_text())
    manifest["description"] = (f"![x]({secret}) [a](javascript:alert(1)) [b](/etc/passwd) "
                               "<script>document.title=1</script> [c](../../x)")
    (camp / "manifest.json").write_text(json.dumps(manifest))
    import pyarrow as pa
    import pyarrow.parquet as pq

    with open(camp / "summary.parquet", "rb") as f:  # a unit mathtext cannot parse, in the summary's metadata
        table = pq.read_table(f)
    fields = [f.with_metadata({b"unit": b"$\\frac{N"}) if f.name == "control_energy" else f for f in table.schema]
    with open(camp / "summary.parquet", "wb") as f:
        pq.write_table(table.cast(pa.schema(fields)), f)
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        rc = main(["campaign-report", str(camp)])
    return [write_index(results), camp / "report" / "report.html"], rc, out.getvalue()


def test_pages_hold_no_link_or_image_from_data(hostile_pages):
    """Every href of every page is relative and inside the folder, every image one ftcsim drew (not
    secret.png), no raw HTML from the data, and the mathtext unit is drawn (the report is written)."""
    pages, rc, out = hostile_pages
    assert rc == 0 and "\x1b" not in out, out
    for p in pages:
        html = p.read_text()
        hrefs = re.findall(r'href="([^"]*)"', html)
        assert all(h.startswith(("./", "#")) for h in hrefs), hrefs
        assert "javascript:" not in " ".join(hrefs) and "<script>" not in html
        srcs = re.findall(r'src="([^"]*)"', html)
        assert all(s.startswith("data:image/png;base64,") for s in srcs), [s[:40] for s in srcs]
    assert pages[1].read_text().count("<img ") == 2  # metrics.png and envelopes.png, drawn by ftcsim; not secret.png
    assert any(HOSTILE.split(":")[0] in h for h in re.findall(r'href="([^"]*)"', pages[0].read_text()))


def test_hostile_pages_in_headless_chromium(hostile_pages):
    """The same pages opened in headless Chromium (tests/browser.py): nothing runs, every image renders,
    every link the browser sees is relative."""
    from tests.browser import Browser, require_browser

    require_browser()
    pages, _, _ = hostile_pages
    with Browser() as b:
        for p in pages:
            seen = b.check(p)
            assert seen.title != "PWNED" and seen.title != "1" and seen.broken_images == [], seen
            assert all(h.startswith(("./", "#")) for h in seen.links), seen.links


# -- Ctrl-C at start-up ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("command,delay", [("campaign", 0.5), ("campaign", 2.5), ("run", 0.5)])
def test_ctrl_c_at_start_up_is_honoured(command, delay, world, tmp_path):
    """SIGINT while ftcsim imports (0.5 s, any command) or while its LocalCluster starts (2.5 s): one line,
    exit 130, no result folder, nothing left in TMPDIR (the cluster's scratch space included)."""
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    env = dict(os.environ, TMPDIR=str(tmp))
    argv = {"campaign": ["campaign", str(world["campaign"]), "--out", str(tmp_path / "c"), "--workers", "1", "-q"],
            "run": ["run", str(world["scenario"]), "--out", str(tmp_path / "c"), "--mode", "inprocess", "-q"]}[command]
    p = subprocess.Popen([sys.executable, "-m", "orchestrator.cli", *argv], cwd=world["root"], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=120)
    lines = err.strip().splitlines()
    assert p.returncode == 130 and len(lines) == 1 and "Traceback" not in err, err
    c = tmp_path / "c"  # on a fast machine the signal may land later: then a resumable or incomplete result
    assert not c.exists() or (c / "manifest.json").is_file() or (c / "INCOMPLETE").is_file()
    assert list(tmp.iterdir()) == []


# -- a scheduler that is not one -------------------------------------------------------------------------------------
def _peer(kind):
    import socket
    import threading

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)

    def handle(c):
        with contextlib.suppress(OSError):
            if kind == "one byte":
                c.sendall(b"\x05")
            elif kind == "drip":
                for _ in range(100):
                    c.sendall(b"\x01")
                    time.sleep(0.05)
            elif kind == "garbage":
                c.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n")
            elif kind == "huge length":
                c.sendall((2**60).to_bytes(8, "little"))
            time.sleep(10)

    def loop():
        while True:
            try:
                c, _ = srv.accept()
            except OSError:
                return
            threading.Thread(target=handle, args=(c,), daemon=True).start()

    threading.Thread(target=loop, daemon=True).start()
    return srv


PEERS = [("campaign", k) for k in ("silent", "one byte", "drip", "garbage", "huge length")] + \
    [("arena", "garbage"), ("arena", "huge length")]  # the arena's timeout is 5 s: its fast refusals only


@pytest.mark.parametrize("command,kind", PEERS)
def test_a_peer_that_is_not_a_scheduler_is_refused_in_the_timeout(kind, command, world, tmp_path, capsys):
    srv = _peer(kind)
    address = f"tcp://127.0.0.1:{srv.getsockname()[1]}"
    argv = {"campaign": ["campaign", world["campaign"], "--out", tmp_path / "c", "--scheduler", address,
                         "--connect-timeout", "0.3"],
            "arena": ["arena", _arena(tmp_path, "seed = 7", "seed = 7"), "--out", tmp_path / "c", "--scheduler",
                      address]}[command]
    t0 = time.monotonic()
    try:
        refused(argv, capsys, tmp_path, words=("--scheduler",))
    finally:
        srv.close()
    assert time.monotonic() - t0 < 20


# -- a run that records no row replaces nothing ----------------------------------------------------------------------
def test_a_run_that_records_no_row_replaces_nothing(world, tmp_path, capsys, monkeypatch):
    """--overwrite with a value a component refuses at initialisation (a third-party FMU's own check, which
    ftcsim cannot run beforehand: simulated by switching the in-process check off): the run fails before its
    first row, exit 1, and the previous result stays byte for byte (it used to be replaced by 0 rows)."""
    prev = _place(world, tmp_path, "run")
    before = snapshot(tmp_path)
    monkeypatch.setattr("orchestrator.scenario.block_checks.block_refuses", lambda inst, values, t0: None)
    rc, err, _ = cli(["run", world["scenario"], "--out", prev, "--overwrite", "--mode", "inprocess", "-q",
                      "--no-plots", "--set", "plant.q_init=[0, 0, 0, 0]"], capsys)
    assert rc == 1 and len(err) == 1 and "no row was recorded" in err[0] and "unchanged" in err[0], err
    assert snapshot(tmp_path) == before
