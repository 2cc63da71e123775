"""What a campaign folder holds: one Parquet file per finished run (written atomically), the
trajectories, the summary table combined from the runs, and the manifest (versions, FMUs, sessions)."""
from __future__ import annotations

import json
import sys
from importlib import metadata
from pathlib import Path

import numpy as np

from orchestrator.campaign.expand import file_digest
from orchestrator.common.parquet import write_table

SUMMARY = "summary.parquet"
MANIFEST = "manifest.json"
CAMPAIGN_COPY = "campaign.toml"
RUNS = "runs"
TRAJECTORIES = "trajectories"
EXECUTION_COLUMNS = ("wall_time_s", "cpu_time_s", "sim_time_s", "worker")


def run_file(spec_or_row) -> str:
    run_id = spec_or_row.run_id if hasattr(spec_or_row, "run_id") else spec_or_row["run_id"]
    key = spec_or_row.key if hasattr(spec_or_row, "key") else spec_or_row["key"]
    return f"{run_id:07d}-{key}.parquet"


def store(folder: Path, result: dict) -> None:
    """Write one finished run durably: its trajectory, then its summary row."""
    import pyarrow as pa

    row = result["row"]
    if result.get("trajectory"):
        tr = result["trajectory"]
        write_table(folder / TRAJECTORIES / f"run_id={row['run_id']}" / "part-0.parquet",
                    pa.table({k: np.asarray(v, dtype=float) for k, v in tr.items()}))
    write_table(folder / RUNS / run_file(row), pa.Table.from_pylist([row]))


def stored(folder: Path) -> dict:
    """{(run_id, key): file} of the runs stored in a campaign folder."""
    out = {}
    for p in (folder / RUNS).glob("*.parquet"):
        rid, _, key = p.stem.partition("-")
        if rid.isdigit() and key:
            out[(int(rid), key)] = p
    return out


def combine(folder: Path, plan) -> int:
    """Write summary.parquet from the stored runs of ``plan`` (run-id order); returns the row count."""
    import pandas as pd

    have = stored(folder)
    files = [have[(s.run_id, s.key)] for s in plan if (s.run_id, s.key) in have]
    frames = [pd.read_parquet(f) for f in files]
    df = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame({"run_id": []})
    if len(df):
        df = df.sort_values("run_id", kind="stable").reset_index(drop=True)
        first = ["run_id", "key", "variant", "point", "draw", "seed"]
        tail = ["status", "error", *EXECUTION_COLUMNS]
        middle = [c for c in df.columns if c not in first and c not in tail]
        df = df[[c for c in first + middle + tail if c in df.columns]]
    write_table(folder / SUMMARY, df)
    return len(df)


def _versions() -> dict:
    out = {"python": sys.version.split()[0]}
    for pkg in ("ftcsim", "numpy", "scipy", "fmpy", "pythonfmu", "pythonfmu3", "dask", "distributed", "pyarrow",
                "pandas"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def _fmus(c) -> list:
    seen = {}
    for sc in c.bases:
        for inst in sc.instances.values():
            if inst.fmu is None or str(inst.fmu) in seen:
                continue
            md = inst.model_description
            seen[str(inst.fmu)] = {"path": str(inst.fmu), "sha256": file_digest(inst.fmu), "model": md.modelName,
                                   "fmi_version": md.fmiVersion, "guid": md.guid, "generation_tool": md.generationTool,
                                   "generated": md.generationDateAndTime}
    return list(seen.values())


def manifest(c, plan) -> dict:
    return {
        "campaign": c.name, "description": c.description, "campaign_file": str(c.path.resolve()),
        "campaign_sha256": c.digest, "runs": len(plan), "draws": c.runs, "seed": c.seed, "mode": c.mode,
        "variants": [{"name": v.name, "scenario": v.scenario, "fmus": v.fmus, "gains": v.gains,
                      "parameters": v.parameters, "dropped_parameters": v.dropped} for v in c.variants],
        "grid": [{"parameter": r, "values": vals} for r, vals in c.grid],
        "dispersions": [{"parameter": d.ref, "distribution": d.distribution, "apply": d.apply, "shared": d.shared,
                         "elements": [f"{d.inst}.{n}" for n in d.names]} for d in c.dispersions],
        "settling": c.settling, "requirements": c.requirements,
        "trajectories": c.trajectories, "trajectory_step": c.trajectory_step,
        "versions": _versions(), "fmus": _fmus(c), "sessions": [], "status": "running",
    }


def read_manifest(folder: Path) -> dict:
    try:
        data = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        return data if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}
