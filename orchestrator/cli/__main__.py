"""``python -m orchestrator.cli ...``: the ``ftcsim`` command."""
from orchestrator.cli.main import entry

entry()
