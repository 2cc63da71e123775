"""The command line ``ftcsim`` (floor 6): argparse only, each command a few lines over the API
(:mod:`orchestrator.api`) and the library. ``main`` holds the parser and build, validate, scenarios
and run; the other modules each ``register(subparsers)`` their commands."""
import os as _os
import signal as _signal
import sys as _sys


def _interrupted_while_starting(signum, frame):  # pragma: no cover - a signal in a fresh process
    """Ctrl-C while ``ftcsim`` imports its modules (about 2 s): nothing was read or written yet, so
    one line and exit 130, not a traceback from inside an import. :func:`orchestrator.cli.main.main`
    puts Python's own handler back as soon as it starts."""
    try:
        _sys.stderr.write("ftcsim: interrupted\n")
        _sys.stderr.flush()
    finally:
        _os._exit(128 + signum)


# only in the ftcsim process itself (the console script, or python -m orchestrator.cli), never in a
# program that imports the package (a notebook, pytest): its own SIGINT handling is left alone
if _sys.argv[:1] and (_os.path.basename(_sys.argv[0]) == "ftcsim" or _sys.argv[0] == "-m") \
        and _signal.getsignal(_signal.SIGINT) is _signal.default_int_handler:
    _signal.signal(_signal.SIGINT, _interrupted_while_starting)
