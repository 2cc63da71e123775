"""Progress on stderr (issue 36): a tqdm bar only on a terminal; to a file or a pipe plain log lines
and never a carriage return, for every command (one door: orchestrator/common/progress.py)."""
import ast
import fcntl
import logging
import os
import pty
import select
import struct
import subprocess
import sys
import termios
from pathlib import Path

from orchestrator.common.progress import Progress

ROOT = Path(__file__).resolve().parents[2]


def _drive(every):
    p = Progress(50, "demo-run", unit="step", delay=0.0, every=every, logger="ftcsim.progress")
    for _ in range(50):
        p.update(1)
    p.close()


def test_a_file_gets_plain_lines_without_carriage_returns(tmp_path, monkeypatch, caplog):
    log = tmp_path / "log"
    with open(log, "w") as fh:
        monkeypatch.setattr(sys, "stderr", fh)
        with caplog.at_level(logging.INFO, logger="ftcsim.progress"):
            _drive(every=1e-9)
    assert "\r" not in log.read_text()
    lines = [r.getMessage() for r in caplog.records if r.name == "ftcsim.progress"]
    assert lines and lines[-1].startswith("demo-run: 50 of 50 steps done"), lines


def test_a_terminal_gets_a_bar(tmp_path):
    """The same calls with stderr on a pseudo-terminal draw tqdm's bar (carriage returns)."""
    code = (f"import sys; sys.path.insert(0, {str(ROOT)!r})\n"
            "from orchestrator.common.progress import Progress\n"
            "p = Progress(50, 'demo-run', delay=0.0, every=1e-9)\n"
            "[p.update(1) for _ in range(50)]\np.close()\n")
    main, sub = pty.openpty()
    fcntl.ioctl(sub, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # 100 columns (tqdm draws none in 0)
    proc = subprocess.Popen([sys.executable, "-c", code], stderr=sub, stdout=subprocess.DEVNULL)
    out = b""
    while True:  # the terminal end stays open here until the child is gone: nothing it wrote is lost
        ready, _, _ = select.select([main], [], [], 0.2)
        if ready:
            out += os.read(main, 65536)
        elif proc.poll() is not None:
            break
    os.close(sub)
    os.close(main)
    assert proc.returncode == 0 and b"\r" in out and b"demo-run:" in out and b"/50 [" in out, out


def test_ftcsim_run_into_a_log_leaves_no_carriage_return(tmp_path):
    """``ftcsim run ... 2>log``: stepping long enough for a bar (over 2 s of 200 s of li2023_fasmc in
    process) writes no ``\\r`` into the log."""
    log = tmp_path / "log"
    with open(log, "w") as err:
        p = subprocess.run([sys.executable, "-m", "orchestrator.cli.main", "run", "li2023_fasmc", "--mode", "inprocess",
                            "--no-plots", "--out", str(tmp_path / "run")], stderr=err, stdout=subprocess.PIPE,
                           cwd=ROOT, timeout=600, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert p.returncode == 0, log.read_text()
    assert "\r" not in log.read_text()


def test_only_the_progress_module_imports_tqdm():
    found = []
    for f in sorted(ROOT.glob("*/**/*.py")):
        if ".venv" in f.parts or "tests" in f.parts[len(ROOT.parts):len(ROOT.parts) + 1]:
            continue
        try:
            tree = ast.parse(f.read_text(encoding="utf-8"))
        except (SyntaxError, UnicodeDecodeError):
            continue
        for node in ast.walk(tree):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            if any(n.split(".")[0] == "tqdm" for n in names):
                found.append(str(f.relative_to(ROOT)))
    assert found == ["orchestrator/common/progress.py"], found
