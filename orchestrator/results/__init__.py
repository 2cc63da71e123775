"""What a run leaves (floor 4.3): ``metrics`` (from the recorded signals), ``files`` (results.parquet or .csv,
metrics.json, plots; :class:`~orchestrator.results.files.Run`, the one reader of a run folder) and
``report`` (a paper's figures and tables from run folders, through its registry entry)."""
