"""Make targets: ``python -m orchestrator.tools.demo`` (make demo), ``python -m orchestrator.tools.warm`` (make warm)."""
