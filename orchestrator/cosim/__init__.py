"""The co-simulation engine (floor 4.2): takes a validated scenario (``orchestrator.scenario.model``) and
runs it; knows no file format, no paper and no command line.

``component`` (the one interface), ``fmu`` and ``block`` (its two kinds), ``host`` (the process
made ready for our FMUs), ``plan`` (who reads and writes what, built once), ``policies`` (when to
exchange and step), ``recorder``, ``sources``, ``master`` (the three put together) and ``runner``
(scenario -> components -> master -> result)."""
