"""Other FMI engines (libcosim, Ecos, the toolbox container, OMSimulator) on our SSP packages, each in
its own process: ``python -m orchestrator.interop.engines`` and ``python -m orchestrator.interop.libcosim``."""
