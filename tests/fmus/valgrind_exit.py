"""Run tests/fmus/exit_probe.py under valgrind and sort its memory errors.

    python tests/fmus/valgrind_exit.py [--log FILE] [exit_probe arguments...]

Prints one JSON line: the probe's exit status and the invalid accesses (``Invalid read``,
``Invalid write``, ``Invalid free`` ...) by where they happen: ``at_exit`` (a frame in glibc's
exit path: ``exit``, ``__run_exit_handlers``, ``_dl_fini``, ``__cxa_finalize``), ``in_fmu`` (a
frame in an FMU binary) and ``other``, with the first frame of each. CPython's and ld.so's own
known reports (uninitialised values in ``int.from_bytes``, ``strncmp`` reading a word past an
rpath string in ``dl-load.c``) are not invalid accesses of ours and are counted apart
(``known_other``). Slow: about 2.5 min per process on this machine."""
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
EXIT_FRAMES = ("exit.c", "__run_exit_handlers", "_dl_fini", "__cxa_finalize", "dl-fini.c", "dl-call_fini.c")
KNOWN = ("is_dst (dl-load.c",)  # glibc's strncmp over-read of an rpath string under valgrind (dlopen, not exit)


def blocks(log: str):
    """(kind, frames) of every error report in a valgrind log."""
    current = None
    for line in log.splitlines():
        m = re.match(r"==\d+== (.*)$", line)
        if not m:
            continue
        text = m.group(1)
        if not text.strip():
            if current:
                yield current
            current = None
        elif current is None and re.match(r"(Invalid|Mismatched|Conditional|Use of|Syscall|Source and)", text):
            current = (text.strip(), [])
        elif current is not None:
            current[1].append(text.strip())
    if current:
        yield current


def summarise(log: str, rc: int) -> dict:
    out = {"rc": rc, "at_exit": [], "in_fmu": [], "other": [], "known_other": 0}
    for kind, frames in blocks(log):
        if not kind.startswith(("Invalid", "Mismatched", "Source and")):
            continue
        stack = " | ".join(frames)
        first = frames[0] if frames else ""
        if any(k in stack for k in KNOWN):
            out["known_other"] += 1
        elif any(k in stack for k in EXIT_FRAMES):
            out["at_exit"].append(f"{kind}: {first}")
        elif "/binaries/" in stack:
            out["in_fmu"].append(f"{kind}: {first}")
        else:
            out["other"].append(f"{kind}: {first}")
    return out


def main() -> int:
    args = sys.argv[1:]
    log_file = None
    if args[:1] == ["--log"]:
        log_file, args = args[1], args[2:]
    env = dict(os.environ, PYTHONMALLOC="malloc")  # valgrind sees every Python allocation
    with tempfile.NamedTemporaryFile("r", suffix=".log") as fh:
        p = subprocess.run(["valgrind", f"--log-file={fh.name}", "--leak-check=no", "--num-callers=16",
                            sys.executable, str(HERE / "exit_probe.py"), *args], env=env)
        log = Path(fh.name).read_text()
    if log_file:
        Path(log_file).write_text(log)
    print(json.dumps(summarise(log, p.returncode)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
