"""The host process made ready for our FMUs, once, before the first one loads.

A pythonfmu FMU puts its resources folder first on ``sys.path`` when it is instantiated, and runs
its slave script, which imports the packages of ours the FMU embeds. Any of those packages not yet
imported would then come from the FMU's temporary folder for the rest of the process (a partial
copy, removed when the process ends). :func:`prepare_process` imports them from this installation
first: the names are the FMI layer's (``fmus.runtime.HOST_IMPORTS``), so the engine names no
package above it. :meth:`orchestrator.cosim.fmu.FMUComponent.setup` calls it, which covers the
command line, the API, campaign workers and every other user of the master; code that loads FMUs
through fmpy directly (benchmarks, tests) calls it itself."""
from __future__ import annotations

import importlib

from fmus.runtime import HOST_IMPORTS

_READY = False


def prepare_process() -> None:
    """Import ``fmus.runtime.HOST_IMPORTS`` from this installation (once per process)."""
    global _READY
    if not _READY:
        for name in HOST_IMPORTS:
            importlib.import_module(name)
        _READY = True
