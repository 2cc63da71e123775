"""Result folders of ``ftcsim run`` (results.csv + metrics.json) as RunResults, for the papers' reports.

A paper's ``report.make_report(runs, out)`` takes ``{scenario name: RunResult}``; :func:`load_runs`
builds that mapping from result folders (the scenario name is the one recorded in metrics.json).
"""
from __future__ import annotations

import json
from pathlib import Path

from orchestrator.errors import InputError
from orchestrator.master import RunResult
from orchestrator.results import read_csv


def load_run(folder) -> tuple[str, RunResult]:
    folder = Path(folder)
    for f in ("results.csv", "metrics.json"):
        if not (folder / f).is_file():
            raise InputError(folder, f, "missing: not a result folder of `ftcsim run`")
    try:
        meta = json.loads((folder / "metrics.json").read_text())
    except json.JSONDecodeError as e:
        raise InputError(folder / "metrics.json", "-", f"not valid JSON: {e}") from None
    try:
        header, data = read_csv(folder / "results.csv")
    except ValueError as e:
        raise InputError(folder / "results.csv", "-", f"unreadable: {e}") from None
    res = RunResult(header[1:], data[:, 0], data[:, 1:], bool(meta.get("complete", True)), meta.get("error"),
                    float(meta.get("wall_time_s") or 0.0), int(meta.get("steps") or len(data) - 1),
                    meta.get("exchange", "ordered"), meta.get("mode", "fmu"))
    return str(meta.get("scenario", folder.name)), res


def load_runs(folders) -> dict:
    return dict(load_run(f) for f in folders)
