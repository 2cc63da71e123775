"""Ground floor of the orchestrator: errors, safe file reading and writing, output folders, zip
archives, signals and process exit. Standard library and numpy only; imports nothing of ours."""
