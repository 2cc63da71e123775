"""What a run is, and every check before anything runs (floor 4.1 of the orchestrator).

``model`` (the data), ``values`` and ``refs`` (single values, variable references), ``interfaces``
(FMU or block), ``checks`` (timing, size, step policy), ``overrides`` (parameters, gains),
``shipped`` (the one door to the paper registry and the repository's folders) and the two file
formats, ``toml`` and ``ssp``, plus ``fmu_checks`` (can an FMU load here)."""
